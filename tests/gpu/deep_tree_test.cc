// Deep and wide trees (issue 7, "Numerical stability on hard cases"): trees 64
// levels deep and 256 slabs wide compile, simplify and run; past the documented
// limits (docs/format.md: 1024 tree nodes after instancing, JSON nesting 128
// levels) they stop with the documented error, never a crash; the deepest legal
// tree (a 511-level vertical chain, 1023 nodes) compiles and evaluates on a
// thread with a 1 MiB stack. docs/stability.md, "Deep and wide trees", lists the
// materials and the measured times.
//
// The materials are generated here (substrate-material/1, nlohmann::json):
//  - vertical64:   64 vertical operators in a chain, 65 slabs (129 nodes, depth 64);
//  - horizontal256: a balanced tree of 255 horizontal operators over 256 slabs
//                   (511 nodes, depth 8);
//  - mix64:        64 horizontal mixes in a chain, 65 slabs (129 nodes; the
//                  deepest slab weighs 2^-64);
//  - vertical511:  511 vertical operators in a chain, 512 slabs (1023 nodes);
//  - operator_tops: operators (a mix, a coverage weight, a vertical) as the
//                  tops of verticals, each holding a fuzzy coat (12 nodes).
// Coats are clear (albedo 0, a long mean free path) so nothing below them is
// culled; two inputs (a roughness and a mix weight) vary across input sets.
#include <gtest/gtest.h>
#include <pthread.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "pipeline/generate.h"
#include "material_fixture.h"

namespace substratec::gputest {
namespace deep_tree_test {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using namespace kernel;

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// ---------------------------------------------------------------------------
// The generated materials.

json inputs() {
  return json{{"rough", {{"type", "float"}, {"default", 0.4}, {"min", 0}, {"max", 1}}},
              {"mixw", {{"type", "float"}, {"default", 0.5}, {"min", 0}, {"max", 1}}}};
}

json document(const std::string& name, json nodes, const std::string& output) {
  return json{{"format", "substrate-material/1"}, {"name", name}, {"inputs", inputs()},
              {"nodes", std::move(nodes)},       {"output", output}};
}

/// Slab i of n: its own colour and roughness (every third one the input's);
/// a coat (it has something below) is clear: albedo 0 and a mean free path of
/// a metre, so what is below shows through.
json slab(int i, int n, bool coat) {
  const double t = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
  json s{{"kind", "slab"}, {"f0", {0.02 + 0.5 * t, 0.04, 0.9 - 0.5 * t}}};
  if (i % 3 == 0) s["roughness"] = "$rough";
  else s["roughness"] = 0.1 + 0.8 * t;
  if (coat) {
    s["diffuse_albedo"] = 0.0;
    s["sss_mfp"] = {1.0, 0.8, 0.6};
  } else {
    s["diffuse_albedo"] = {0.2 + 0.7 * t, 0.5, 0.9 - 0.7 * t};
  }
  return s;
}

/// `levels` vertical operators in a chain: v0 = vertical(s0, v1), ...,
/// v{levels-1} = vertical(s{levels-1}, s{levels}).
json verticalChain(int levels) {
  json nodes = json::object();
  for (int i = 0; i <= levels; ++i) nodes[fmt::format("s{}", i)] = slab(i, levels + 1, i < levels);
  for (int i = 0; i < levels; ++i) {
    const std::string base = i + 1 < levels ? fmt::format("v{}", i + 1) : fmt::format("s{}", levels);
    nodes[fmt::format("v{}", i)] = {{"kind", "vertical"}, {"top", fmt::format("s{}", i)}, {"base", base},
                                    {"thickness", 0.0001}};
  }
  return document(fmt::format("vertical{}", levels), std::move(nodes), "v0");
}

/// A balanced tree of horizontal operators over 2^depth slabs.
json horizontalTree(int depth) {
  json nodes = json::object();
  const int leaves = 1 << depth;
  for (int i = 0; i < leaves; ++i) nodes[fmt::format("s{}", i)] = slab(i, leaves, false);
  std::function<std::string(int, int)> build = [&](int level, int index) -> std::string {
    if (level == depth) return fmt::format("s{}", index);
    const std::string id = fmt::format("h{}_{}", level, index);
    const std::string a = build(level + 1, 2 * index), b = build(level + 1, 2 * index + 1);
    json mix = (index % 2 == 0) ? json("$mixw") : json(0.25 + 0.5 * ((level * 7 + index) % 5) / 4.0);
    nodes[id] = {{"kind", "horizontal"}, {"background", a}, {"foreground", b}, {"mix", mix}};
    return id;
  };
  const std::string root = build(0, 0);
  return document(fmt::format("horizontal{}", leaves), std::move(nodes), root);
}

/// `levels` horizontal mixes in a chain: h0 = mix(s0, h1, 0.5), ...
json mixChain(int levels) {
  json nodes = json::object();
  for (int i = 0; i <= levels; ++i) nodes[fmt::format("s{}", i)] = slab(i, levels + 1, false);
  for (int i = 0; i < levels; ++i) {
    const std::string fg = i + 1 < levels ? fmt::format("h{}", i + 1) : fmt::format("s{}", levels);
    nodes[fmt::format("h{}", i)] = {{"kind", "horizontal"}, {"background", fmt::format("s{}", i)},
                                    {"foreground", fg}, {"mix", i % 2 ? json("$mixw") : json(0.5)}};
  }
  return document(fmt::format("mix{}", levels), std::move(nodes), "h0");
}

/// A chain of `levels` vertical operators written as nested inline nodes under
/// one named root, as text (nlohmann's dump would recurse as deep): the root
/// vertical is at JSON depth 3 (document, nodes, root), the i-th inline one at
/// 3 + i, and the last one's slabs (no arrays) at levels + 3: the nesting.
std::string inlineChainText(int levels) {
  std::string text = R"({"format": "substrate-material/1", "name": "inline_chain", "nodes": {"root": )";
  for (int i = 0; i < levels; ++i)
    text += R"({"kind": "vertical", "top": {"kind": "slab", "diffuse_albedo": 0, "sss_mfp": 1}, "base": )";
  text += R"({"kind": "slab", "roughness": 0.3})";
  text.append(static_cast<std::size_t>(levels), '}');
  return text + R"(}, "output": "root"})";
}

/// Operators as the top layers of verticals, each holding a fuzzy coat (issue
/// 19 step 8: the closures under them take what the fuzz lets through, through
/// the operators): root = vertical(mix(clear, fuzzy), vertical(weight(fuzzy),
/// vertical(vertical(fuzzy, clear), base))). 12 nodes, 6 slabs.
json operatorTops() {
  json nodes = json::object();
  auto fuzzy = [&](int i) {
    json s = slab(i, 6, true);
    s["fuzz_amount"] = 0.3 + 0.3 * i / 5.0;
    s["fuzz_color"] = {0.9, 0.8, 1.0};
    s["fuzz_roughness"] = i % 2 ? json("$rough") : json(0.6);
    return s;
  };
  nodes["c1"] = slab(0, 6, true);
  nodes["f1"] = fuzzy(1);
  nodes["f2"] = fuzzy(2);
  nodes["f3"] = fuzzy(3);
  nodes["c3"] = slab(4, 6, true);
  nodes["base"] = slab(5, 6, false);
  nodes["top1"] = {{"kind", "horizontal"}, {"background", "c1"}, {"foreground", "f1"}, {"mix", "$mixw"}};
  nodes["top2"] = {{"kind", "coverage_weight"}, {"a", "f2"}, {"weight", 0.7}};
  nodes["top3"] = {{"kind", "vertical"}, {"top", "f3"}, {"base", "c3"}, {"thickness", 0.0001}};
  nodes["v3"] = {{"kind", "vertical"}, {"top", "top3"}, {"base", "base"}, {"thickness", 0.0001}};
  nodes["v2"] = {{"kind", "vertical"}, {"top", "top2"}, {"base", "v3"}, {"thickness", 0.0001}};
  nodes["root"] = {{"kind", "vertical"}, {"top", "top1"}, {"base", "v2"}, {"thickness", 0.0001}};
  json doc = document("operator_tops", std::move(nodes), "root");
  doc["settings"] = {{"bytes_per_pixel", 256}};  // the default budget keeps every closure
  return doc;
}

struct DeepMaterial {
  std::string name;
  json doc;
  int treeNodes;  // before simplification
  int depth;      // operators on the longest root-to-slab path
};

std::vector<DeepMaterial> legalMaterials() {
  return {{"vertical64", verticalChain(64), 129, 64},
          {"horizontal256", horizontalTree(8), 511, 8},
          {"mix64", mixChain(64), 129, 64},
          {"vertical511", verticalChain(511), 1023, 511},
          {"operator_tops", operatorTops(), 12, 4}};
}

struct Variant {
  const char* name;
  std::optional<int> budget;
  bool full;
};
const Variant kVariants[] = {{"default_budget", std::nullopt, false}, {"budget_20", 20, false},
                             {"full_simplification", std::nullopt, true}};

std::optional<CompileResult> compileDoc(const json& doc, const Variant& v, std::string* diagnostics) {
  CompileOptions o;
  o.budgetOverride = v.budget;
  o.fullSimplification = v.full;
  Diagnostics diags(doc["name"].get<std::string>() + ".json");
  auto r = compileText(doc["name"].get<std::string>() + ".json", doc.dump(), o, diags);
  if (diagnostics) *diagnostics = diags.formatAll();
  return r;
}

// ---------------------------------------------------------------------------
// (a) CPU: compile, simplify, generate, validate.

TEST(DeepTrees, CompileSimplifyAndValidateAtEveryBudget) {
  for (const DeepMaterial& g : legalMaterials()) {
    for (const Variant& v : kVariants) {
      SCOPED_TRACE(g.name + " " + v.name);
      const auto t0 = std::chrono::steady_clock::now();
      std::string diags;
      auto r = compileDoc(g.doc, v, &diags);
      const double compileMs = msSince(t0);
      ASSERT_TRUE(r.has_value()) << diags;
      int slabs = 0;
      for (const auto& node : g.doc["nodes"]) slabs += node["kind"] == "slab" ? 1 : 0;
      EXPECT_EQ(static_cast<int>(r->before.closures.size()), slabs) << "every slab is a closure";
      EXPECT_GE(r->after.closures.size(), 1u);
      EXPECT_LE(r->after.closures.size(), 8u);
      if (v.budget) EXPECT_LE(r->after.bytes(), *v.budget);
      if (v.full) EXPECT_EQ(r->after.closures.size(), 1u);
      const auto t1 = std::chrono::steady_clock::now();
      Generated out = generateFiles(*r, GenerateOptions{});
      validateGenerated(out);
      EXPECT_TRUE(out.valid) << out.failure;
      std::printf("[ deep     ] %-14s %-20s %4d nodes -> %zu closures, %3d B, %3zu steps: compile %.0f ms, "
                  "generate + validate %.0f ms\n",
                  g.name.c_str(), v.name, g.treeNodes, r->after.closures.size(), r->after.bytes(), r->steps.size(),
                  compileMs, msSince(t1));
    }
  }
}

// ---------------------------------------------------------------------------
// (c) The limits, through the CLI (exit status and diagnostics as documented).

struct CliRun {
  int status;
  std::string out, err;
};

CliRun runOnFile(const std::string& text, const std::string& file, std::vector<std::string> args) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("substratec_deep_{}", static_cast<long>(getpid()));
  fs::create_directories(dir);
  const fs::path path = dir / file;
  std::ofstream(path, std::ios::binary) << text;
  args.push_back(path.string());
  std::ostringstream out, err;
  const int status = runCli(args, out, err);
  fs::remove_all(dir);
  return {status, out.str(), err.str()};
}

TEST(DeepTrees, ATreeOfMoreThan1024NodesIsTheDocumentedError) {
  // 512 vertical operators over 513 slabs: 1025 nodes.
  const CliRun r = runOnFile(verticalChain(512).dump(), "vertical512.json", {"report"});
  EXPECT_EQ(r.status, kExitBadInput) << r.err;
  EXPECT_NE(r.err.find("vertical512.json:1:65409: error: the Substrate tree would have more than 1024 nodes after "
                       "instancing"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("this is the tree-size limit [/nodes/v0]\n"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  // One node fewer than the limit allows is the deepest legal chain (next test);
  // 1024 itself cannot be reached: a binary tree has an odd number of nodes.
}

TEST(DeepTrees, JsonNestedDeeperThan128LevelsIsTheDocumentedError) {
  // Inline verticals nested 126 deep: nesting 129 (inlineChainText).
  const CliRun deep = runOnFile(inlineChainText(126), "inline126.json", {"report"});
  EXPECT_EQ(deep.status, kExitBadInput) << deep.err;
  EXPECT_NE(deep.err.find("inline126.json:1:"), std::string::npos) << deep.err;
  EXPECT_NE(deep.err.find("error: nesting is deeper than the limit of 128 levels"), std::string::npos) << deep.err;
  EXPECT_EQ(deep.out, "");
  // Far deeper (100,000 levels): the same error, from the linear pre-scan
  // (compiler/core/format) before the document is parsed.
  const CliRun deeper = runOnFile(inlineChainText(100000), "inline100000.json", {"report"});
  EXPECT_EQ(deeper.status, kExitBadInput) << deeper.err;
  EXPECT_NE(deeper.err.find("error: nesting is deeper than the limit of 128 levels"), std::string::npos);
  // 125 deep, nesting exactly 128: a legal material (251 tree nodes).
  const CliRun legal = runOnFile(inlineChainText(125), "inline125.json", {"report"});
  EXPECT_EQ(legal.status, kExitOk) << legal.err;
  EXPECT_NE(legal.out.find("inline_chain"), std::string::npos);
}

/// Runs `body` on a thread with a `bytes` stack; false if the thread could not start.
bool onSmallStack(std::size_t bytes, std::function<void()> body) {
  pthread_attr_t attr;
  pthread_attr_init(&attr);
  pthread_attr_setstacksize(&attr, bytes);
  pthread_t thread;
  auto* fn = new std::function<void()>(std::move(body));
  const int rc = pthread_create(
      &thread, &attr,
      [](void* p) -> void* {
        auto* f = static_cast<std::function<void()>*>(p);
        (*f)();
        delete f;
        return nullptr;
      },
      fn);
  pthread_attr_destroy(&attr);
  if (rc != 0) {
    delete fn;
    return false;
  }
  pthread_join(thread, nullptr);
  return true;
}

TEST(DeepTrees, TheDeepestLegalTreeCompilesAndEvaluatesOnA1MiBStack) {
  // 511 vertical operators over 512 slabs (1023 nodes): resolve, build-tree
  // (recursive instancing, 512 frames deep), cull, features, bases, the
  // simplifier, the layout, and the reference's tree walk and closure walks,
  // all on a thread whose stack is 1 MiB (the main thread has 8). A stack
  // overflow would crash the test binary.
  const json doc = verticalChain(511);
  for (const Variant& v : kVariants) {
    SCOPED_TRACE(v.name);
    bool compiled = false, finite = true;
    std::size_t closures = 0;
    std::string diags;
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_TRUE(onSmallStack(1u << 20, [&] {
      auto r = compileDoc(doc, v, &diags);
      if (!r) return;
      compiled = true;
      closures = r->after.closures.size();
      reference::Geometry g;
      g.V = {0.3, 0.2, std::sqrt(1 - 0.13)};
      const auto m = reference::evaluateMaterial<double>(*r, g, {}, {});
      for (const auto& c : m.closures)
        finite = finite && std::isfinite(c.weight) && std::isfinite(c.topTransmittance[0]) && std::isfinite(c.roughness);
      finite = finite && std::isfinite(m.coverage);
    }));
    EXPECT_TRUE(compiled) << diags;
    EXPECT_TRUE(finite);
    EXPECT_LE(closures, 8u);
    std::printf("[ deep     ] vertical511 %-20s on a 1 MiB stack: %zu closures, %.0f ms\n", v.name, closures,
                msSince(t0));
  }
}

// ---------------------------------------------------------------------------
// (b) GPU: the forward kernel on lavapipe against the CPU reference.

constexpr int kGeometries = 1024;
constexpr int kInputSets = 2;
constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);

TEST(DeepTrees, ForwardKernelsMatchTheCpuReferenceOnLavapipe) {
  Diagnostics gpuDiags("test");
  gpu::Context* ctx = sharedContext(gpuDiags);
  ASSERT_NE(ctx, nullptr) << "lavapipe is required (GPU tests never skip): " << gpuDiags.errorMessages();
  const Tolerance tol;
  for (const DeepMaterial& g : legalMaterials()) {
    for (const Variant& v : kVariants) {
      SCOPED_TRACE(g.name + " " + v.name);
      const auto t0 = std::chrono::steady_clock::now();
      std::string diags;
      auto r = compileDoc(g.doc, v, &diags);
      ASSERT_TRUE(r.has_value()) << diags;
      const ShaderValidation kernel = compileKernel(*r, Target::Glsl, KernelMode::Forward);
      ASSERT_TRUE(kernel.ok) << kernel.log;
      auto pipeline = ctx->createPipeline(kernel.spirv, gpuDiags);
      ASSERT_NE(pipeline, nullptr) << gpuDiags.errorMessages();
      const auto samples = makeSamples(kGeometries, 0xdee9u + static_cast<uint32_t>(g.treeNodes));
      const auto sampleBytes = sampleBuffer(samples);
      const auto inputSets = makeInputSets(r->material, kInputSets, 0x1a9u);
      const int stride = resultStride(*r);
      const double prepareMs = msSince(t0);
      long checked = 0, failed = 0, nonFinite = 0;
      double margin = 0;
      std::string worst;
      double worstExcess = -1;
      const auto t1 = std::chrono::steady_clock::now();
      for (int set = 0; set < kInputSets; ++set) {
        gpu::Resources res = kernelResources(r->material, pipeline->reflection(), kernel.spirv, inputSets[set],
                                             sampleBytes, static_cast<std::size_t>(stride) * kGeometries);
        ASSERT_TRUE(ctx->dispatch(*pipeline, res, kGeometries / kLocalSize, 1, 1, gpuDiags))
            << gpuDiags.errorMessages();
        const std::vector<float> out = floatsOf(res, 0, 7);
        for (float x : out) nonFinite += std::isfinite(x) ? 0 : 1;
        for (int i = 0; i < kGeometries; ++i) {
          const Shaded<double> ref = shade<double>(*r, samples[i], inputSets[set], kDiffuseModel);
          const Shaded<float> r32 = shade<float>(*r, samples[i], inputSets[set], kDiffuseModel);
          const float* gpu = &out[static_cast<std::size_t>(i) * stride];
          auto check = [&](const char* what, int at, double ref64, double ref32) {
            ++checked;
            const double allowed = tol.k * std::abs(ref32 - ref64) + tol.abs + tol.rel * std::abs(ref64);
            margin = std::max(margin, std::abs(gpu[at] - ref64) / allowed);
            if (tol.ok(gpu[at], ref64, ref32)) return;
            ++failed;
            if (std::abs(gpu[at] - ref64) - allowed > worstExcess) {
              worstExcess = std::abs(gpu[at] - ref64) - allowed;
              worst = fmt::format("set {}, sample {}: {} gpu {} ref64 {} ref32 {}", set, i, what, gpu[at], ref64, ref32);
            }
          };
          ASSERT_EQ(gpu[kResultCount], static_cast<float>(r->after.closures.size()));
          for (std::size_t k = 0; k < ref.material.closures.size(); ++k) {
            const auto& c64 = ref.material.closures[k];
            const auto& c32 = r32.material.closures[k];
            const int at = kResultHeaderFloats + kClosureFloats * static_cast<int>(k);
            for (int c = 0; c < 3; ++c) {
              check("diffuseAlbedo", at + kClosureDiffuseAlbedo + c, c64.diffuseAlbedo[c], c32.diffuseAlbedo[c]);
              check("f0", at + kClosureF0 + c, c64.f0[c], c32.f0[c]);
              check("N", at + kClosureN + c, c64.N[c], c32.N[c]);
              check("topTransmittance", at + kClosureTopTransmittance + c, c64.topTransmittance[c],
                    c32.topTransmittance[c]);
            }
            check("roughness", at + kClosureRoughness, c64.roughness, c32.roughness);
            check("weight", at + kClosureWeight, c64.weight, c32.weight);
            check("coverageAbove", at + kClosureCoverageAbove, c64.coverageAbove, c32.coverageAbove);
          }
          check("coverage", kResultCoverage, ref.material.coverage, r32.material.coverage);
          for (int c = 0; c < 3; ++c) {
            check("transmittance", kResultTransmittance + c, ref.material.transmittance[c],
                  r32.material.transmittance[c]);
            check("direct", kResultDirect + c, ref.direct[c], r32.direct[c]);
            check("environment", kResultEnvironment + c, ref.environment[c], r32.environment[c]);
          }
        }
      }
      EXPECT_EQ(nonFinite, 0);
      EXPECT_EQ(failed, 0) << failed << " of " << checked << " values outside tolerance; worst: " << worst;
      std::printf("[ deep     ] %-14s %-20s GPU: %zu closures, %ld values, margin %.3f; compile + kernel %.0f ms, "
                  "%d dispatches + reference %.0f ms\n",
                  g.name.c_str(), v.name, r->after.closures.size(), checked, margin, prepareMs, kInputSets,
                  msSince(t1));
    }
  }
}

}  // namespace deep_tree_test
}  // namespace substratec::gputest
