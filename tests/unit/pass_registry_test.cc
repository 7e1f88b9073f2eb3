// The pass registry (pipeline/pass_registry.h): its order is the pipeline's,
// its names are unique and found, stopping after any pass leaves the IR the
// whole pipeline had after it, and simplify's re-pricing is the registry's
// analyses.
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/pass_registry.h"
#include "pipeline/pipeline.h"
#include "ir/dump.h"
#include "test_util.h"

namespace substratec {
namespace {

/// An example material that simplify has work on: several slabs, over a
/// small budget.
std::string registryExample() {
  std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/examples/worked_example_72.json");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> registryNames() {
  std::vector<std::string> names;
  for (const Pass& p : passRegistry()) names.emplace_back(p.name);
  return names;
}

TEST(PassRegistry, ListsThePassesInPipelineOrder) {
  EXPECT_EQ(registryNames(), (std::vector<std::string>{"parse", "expand-blocks", "resolve", "build-values", "build-tree", "cull",
                                                       "features", "shared-bases", "price", "simplify"}));
  EXPECT_EQ(passNames(), "parse, expand-blocks, resolve, build-values, build-tree, cull, features, shared-bases, price, simplify");
  for (const Pass& p : passRegistry()) {
    SCOPED_TRACE(std::string(p.name));
    EXPECT_FALSE(p.doc.empty());
    EXPECT_EQ(p.doc.find('\n'), std::string_view::npos) << "one line";
    EXPECT_NE(p.run, nullptr);
  }
}

TEST(PassRegistry, NamesAreUniqueAndFound) {
  std::set<std::string_view> seen;
  for (const Pass& p : passRegistry()) {
    EXPECT_TRUE(seen.insert(p.name).second) << p.name << " twice";
    EXPECT_EQ(findPass(p.name), &p);
  }
  for (const char* unknown : {"", "Parse", "simplify ", "bases", "print-after"}) EXPECT_EQ(findPass(unknown), nullptr);
  std::printf("[ registry ] %zu passes, names unique\n", seen.size());
}

// Stopping after a pass runs exactly the passes up to it, and leaves the IR
// that the whole pipeline dumps after that pass (--print-after-all).
TEST(PassRegistry, StoppingAfterEachPassLeavesTheIrThePipelineHadThere) {
  const std::string text = registryExample();
  CompileOptions all;
  all.printAfterAll = true;
  all.budgetOverride = 24;
  Diagnostics fullDiags("example.json");
  auto full = compileText("example.json", text, all, fullDiags);
  ASSERT_TRUE(full) << fullDiags.formatAll();
  ASSERT_FALSE(full->steps.empty()) << "simplify has work on the example";
  std::size_t stops = 0;
  for (const std::string& name : registryNames()) {
    SCOPED_TRACE(name);
    CompileOptions o;
    o.budgetOverride = 24;
    o.stopAfter = name;
    o.printAfter = name;
    o.timePasses = true;
    Diagnostics d("example.json");
    auto r = compileText("example.json", text, o, d);
    ASSERT_TRUE(r) << d.formatAll();
    // After expand-blocks there is no IR yet: the document is dumped.
    const std::string dump = name == "expand-blocks"
                                 ? "; document after expand-blocks\n" + nlohmann::ordered_json::parse(text).dump(2) + "\n"
                                 : "; IR after " + name + "\n" + dumpMaterial(r->material) + "\n";
    EXPECT_EQ(r->debugLog, dump) << "one dump, of the IR it stopped with";
    EXPECT_NE(full->debugLog.find(dump), std::string::npos) << "the IR the whole pipeline had after " << name;
    ASSERT_FALSE(r->timings.empty());
    EXPECT_EQ(r->timings.back().pass, name);
    EXPECT_EQ(r->timings.size(), static_cast<std::size_t>(findPass(name) - passRegistry().data()) + 1);
    ++stops;
  }
  std::printf("[ registry ] stopped after each of %zu passes\n", stops);
}

TEST(PassRegistry, RunUntilEachNameMatchesTheCompilersStop) {
  const std::string text = registryExample();
  for (const std::string& name : registryNames()) {
    SCOPED_TRACE(name);
    CompileOptions o;
    o.stopAfter = name;
    Diagnostics d("test.json");
    auto r = compileText("test.json", text, o, d);
    ASSERT_TRUE(r) << d.formatAll();
    EXPECT_EQ(dumpMaterial(test::runUntil(text, name)), dumpMaterial(r->material));
  }
}

TEST(PassRegistry, AFailingPassStopsThePipeline) {
  CompileOptions o;
  o.timePasses = true;
  CompileResult result;
  Diagnostics d("test.json");
  const std::string text = R"({"format": "substrate-material/1", "name": "m", "nodes": {}, "output": "nowhere"})";
  PassContext c(text, o, d, result);
  EXPECT_FALSE(runPasses(c));
  EXPECT_TRUE(d.hasErrors());
  ASSERT_EQ(result.timings.size(), 3u) << "parse, expand-blocks (nothing to expand), then resolve fails";
  EXPECT_EQ(result.timings.back().pass, "resolve");
}

// simplify re-prices with the registry's analyses (features, then shared
// bases), which come between cull and price.
TEST(PassRegistry, RepricingRerunsTheAnalysesBetweenCullAndPrice) {
  std::vector<std::string> analyses;
  for (const Pass& p : passRegistry())
    if (p.reanalyze) analyses.emplace_back(p.name);
  EXPECT_EQ(analyses, (std::vector<std::string>{"features", "shared-bases"}));
  const std::string text = registryExample();
  Material m = test::runUntil(text, "cull");
  const StorageLayout repriced = repriceMaterial(m);
  EXPECT_EQ(dumpMaterial(m), dumpMaterial(test::runUntil(text, "shared-bases")));
  Diagnostics d("test.json");
  auto r = compileText("test.json", text, CompileOptions{}, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(repriced.bytes(), r->before.bytes());
  EXPECT_EQ(repriced.closures.size(), r->before.closures.size());
}

}  // namespace
}  // namespace substratec
