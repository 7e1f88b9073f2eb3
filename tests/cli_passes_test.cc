// --print-after=PASS and --stop-after=PASS of `report` and `compile`: the IR
// dump after one pass of the registry on stderr, the pipeline stopped after
// one pass with nothing emitted, and an unknown pass a usage error that lists
// the passes (pipeline/pass_registry.h, docs/pipeline.md).
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "cli_util.h"

namespace substratec::clitest {
namespace {

const std::string kPassesExample = std::string(SUBSTRATEC_SOURCE_DIR) + "/examples/worked_example_72.json";
const std::string kPassesList = "parse, expand-blocks, resolve, build-values, build-tree, cull, features, shared-bases, price, simplify";

/// How many times `what` occurs in `text`.
std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(CliPasses, PrintAfterDumpsThatPassOnStderrAndChangesNothingElse) {
  const CliResult plain = cli({"report", kPassesExample});
  ASSERT_EQ(plain.status, 0) << plain.err;
  std::size_t checked = 0;
  for (const char* pass : {"parse", "build-tree", "cull", "shared-bases", "simplify"}) {
    SCOPED_TRACE(pass);
    const CliResult r = cli({"report", std::string("--print-after=") + pass, kPassesExample});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, plain.out);
    EXPECT_EQ(r.err.rfind(std::string("; IR after ") + pass + "\n", 0), 0u) << r.err;
    EXPECT_EQ(occurrences(r.err, "; IR after "), 1u) << r.err;
    ++checked;
  }
  const CliResult last = cli({"report", "--print-after", "simplify", kPassesExample});
  EXPECT_NE(last.err.find("SLAB"), std::string::npos) << "the tree is dumped\n" << last.err;
  std::printf("[ passes   ] report --print-after: %zu passes dumped\n", checked);
}

TEST(CliPasses, PrintAfterExpandBlocksShowsTheFlatFormOfAnAuthoredMaterial) {
  const std::string blocks = std::string(SUBSTRATEC_SOURCE_DIR) + "/tests/blocks/clear_coat.json";
  const CliResult r = cli({"report", "--print-after=expand-blocks", "--stop-after=expand-blocks", blocks});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "") << "stopped: no report";
  ASSERT_EQ(r.err.rfind("; document after expand-blocks\n", 0), 0u) << r.err;
  const auto doc = nlohmann::ordered_json::parse(r.err.substr(r.err.find('\n') + 1));
  EXPECT_EQ(doc["nodes"]["root"]["kind"], "vertical") << "the clear_coat block's root, under its id";
  EXPECT_EQ(doc["nodes"]["root_slab"]["kind"], "slab");
  EXPECT_EQ(r.err.find("\"clear_coat\""), std::string::npos) << "no block is left";
}

TEST(CliPasses, StopAfterEmitsNothingAndExitsZero) {
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{}, {"--json"}, {"--spirv"}, {"--time-passes"}}) {
    std::vector<std::string> args = {"report", "--stop-after=features", "--print-after=features", kPassesExample};
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = cli(args);
    SCOPED_TRACE(extra.empty() ? "" : extra[0]);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err.rfind("; IR after features\n", 0), 0u) << r.err;
    EXPECT_EQ(occurrences(r.err, "; IR after "), 1u);
    EXPECT_EQ(r.err.find("pass price"), std::string::npos) << "nothing ran after features\n" << r.err;
  }
  // Stopping before the pass that fails: no error; through it: exit 1.
  const std::string bad = std::string(SUBSTRATEC_SOURCE_DIR) + "/tests/bad/052_unknown_node_kind.json";
  const CliResult parsed = cli({"report", "--stop-after=parse", bad});
  EXPECT_EQ(parsed.status, 0) << parsed.err;
  EXPECT_EQ(parsed.err, "");
  const CliResult resolved = cli({"report", "--stop-after=resolve", bad});
  EXPECT_EQ(resolved.status, 1);
  EXPECT_NE(resolved.err.find("error:"), std::string::npos) << resolved.err;
}

TEST(CliPasses, CompileStopAfterWritesNothing) {
  const fs::path dir = freshDir("cli_passes", "stop");
  const fs::path cache = freshDir("cli_passes", "stop_cache");
  const CliResult r = cli({"compile", "-o", dir.string(), "--cache", cache.string(), "--stop-after=price",
                           "--print-after=price", kPassesExample, std::string(SUBSTRATEC_SOURCE_DIR) + "/examples/row12_simple.json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(occurrences(r.err, "; IR after price\n"), 2u) << "one dump per material\n" << r.err;
  EXPECT_FALSE(fs::exists(dir) && !fs::is_empty(dir)) << "no output written";
  EXPECT_FALSE(fs::exists(cache) && !fs::is_empty(cache)) << "no cache entry written";
}

TEST(CliPasses, CompilePrintAfterWritesTheSameOutputs) {
  const fs::path plainDir = freshDir("cli_passes", "plain");
  const fs::path dumpDir = freshDir("cli_passes", "dump");
  const CliResult plain = cli({"compile", "-o", plainDir.string(), kPassesExample});
  ASSERT_EQ(plain.status, 0) << plain.err;
  const CliResult r = cli({"compile", "-o", dumpDir.string(), "--print-after", "cull", kPassesExample});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.rfind("; IR after cull\n", 0), 0u) << r.err;
  EXPECT_EQ(occurrences(r.err, "; IR after "), 1u);
  EXPECT_EQ(filesOf(dumpDir), filesOf(plainDir));
  EXPECT_FALSE(filesOf(plainDir).empty());
}

TEST(CliPasses, AnUnknownPassIsAUsageErrorListingThePasses) {
  std::size_t checked = 0;
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"report", "--print-after=bogus", kPassesExample},
        {"report", "--stop-after", "Parse", kPassesExample},
        {"compile", "-o", freshDir("cli_passes", "bad").string(), "--stop-after=bases", kPassesExample},
        {"compile", "-o", freshDir("cli_passes", "bad").string(), "--print-after=", kPassesExample}}) {
    SCOPED_TRACE(args[1] + " " + args[2]);
    const CliResult r = cli(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.out, "");
    EXPECT_NE(r.err.find("substratec: error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("unknown pass \""), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(the passes: " + kPassesList + ")"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("Run 'substratec --help' for usage."), std::string::npos) << r.err;
    ++checked;
  }
  std::printf("[ passes   ] %zu unknown pass names refused\n", checked);
}

TEST(CliPasses, HelpNamesTheFlagsAndThePasses) {
  for (const char* command : {"report", "compile"}) {
    const CliResult r = cli({command, "--help"});
    EXPECT_EQ(r.status, 0);
    EXPECT_NE(r.out.find("--print-after"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("--stop-after"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(kPassesList), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace substratec::clitest
