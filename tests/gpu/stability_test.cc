// Issue 7: hard cases never give NaN or Inf, on the CPU reference and in the
// generated shaders on lavapipe (`substratec stability`), and layering does
// not make energy from nowhere.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "pipeline/generate.h"
#include "../examples.h"
#include "gpu/sample_run.h"
#include "../stack_furnace.h"
#include "material_fixture.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"
#include "stability/stability.h"
#include "sweep/precision.h"

namespace stability_test {

namespace fs = std::filesystem;
using namespace substratec;

struct CliRun {
  int status;
  std::string out, err;
};

CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  int status = runCli(args, out, err);
  return CliRun{status, out.str(), err.str()};
}

std::string example(const std::string& name) {
  return (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / name).string();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

CompileResult compile(const std::string& text, CompileOptions o = {}) {
  Diagnostics diags("test.json");
  auto r = compileText("test.json", text, o, diags);
  EXPECT_TRUE(r.has_value()) << diags.formatAll();
  return r ? *r : CompileResult{};
}

/// The counts every material must meet: at least 1e5 points on the CPU and
/// on the GPU (each path), none of them non-finite; and no forced
/// configuration returns more than 1.001 of a white furnace.
void expectFinite(const std::string& file) {
  SCOPED_TRACE(file);
  CliRun r = cli({"stability", file, "--json"});
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.err;  // 4: a finding, named below
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(r.status, 0) << r.out;
  if (j["furnace_judged"].get<bool>()) EXPECT_LE(j["furnace_max"].get<double>(), 1.001) << j["furnace_worst"].dump(1);
  EXPECT_GE(j["evaluations"].get<long>(), 100000);
  EXPECT_GE(j["gpu_evaluations"].get<long>(), 200000) << "forward and deferred";
  EXPECT_EQ(j["nonfinite"], 0) << j["worst"].dump(1);
  EXPECT_EQ(j["gpu_nonfinite"], 0) << j["worst"].dump(1);
  EXPECT_TRUE(j.contains("furnace_max"));
  EXPECT_FALSE(j["forced"].empty());
  // The furnace's denominator: evaluations that returned light (textures at rest).
  EXPECT_EQ(j["textures"], "neutral");
  // Not applicable exactly when the material has no closure (unlit only),
  // which the compiler's report says independently.
  CliRun report = cli({"report", file, "--json"});
  ASSERT_EQ(report.status, 0) << report.err;
  const bool closures = nlohmann::json::parse(report.out)["after"]["closures"].get<int>() > 0;
  EXPECT_EQ(j["furnace_applicable"].get<bool>(), closures);
  if (closures) EXPECT_GT(j["furnace_lit"].get<long>(), 0) << "a furnace that saw only black tests nothing";
  EXPECT_TRUE(j["furnace_exercised"].get<bool>());
  // The checker stays a stress case for finiteness (--stress-textures; CPU
  // reference only: the GPU paths read the same texels).
  CliRun stress = cli({"stability", file, "--stress-textures", "--no-gpu", "--evaluations", "20000", "--json"});
  ASSERT_TRUE(stress.status == 0 || stress.status == 4) << stress.err;
  const auto s = nlohmann::json::parse(stress.out);
  EXPECT_EQ(s["textures"], "checker");
  EXPECT_EQ(s["nonfinite"], 0) << s["worst"].dump(1);
}

/// The same grid with the shaders lighting in half precision (`--precision
/// half`): at least 1e5 points on the GPU over the two paths (5e4 each: the
/// CPU reference and the furnace do not depend on the shaders' precision and
/// are checked above), none of them non-finite.
void expectFiniteInHalf(const std::string& file) {
  SCOPED_TRACE(file);
  CliRun r = cli({"stability", file, "--precision", "half", "--gpu-only", "--evaluations", "50000", "--json"});
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(j["gpu_precision"], "half");
  EXPECT_GE(j["gpu_evaluations"].get<long>(), 100000) << "forward and deferred";
  EXPECT_EQ(j["gpu_nonfinite"], 0) << j["worst"].dump(1);
}

class EveryExample : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryExample, IsFiniteOnTheHardCaseGridOnTheCpuAndOnTheGpu) { expectFinite(example(GetParam())); }

/// How far half precision may move what the forward pass writes (docs/stability.md, "Half precision").
constexpr double kHalfAbs = 1e-3, kHalfRel = 5e-3;

/// The forward kernel of example `name` in both precisions over the GPU tests'
/// probe set (material_gpu_test.cc: 1,024 geometries under 4 input sets). The
/// material function is float32 in both, so every closure field is
/// bit-identical; the lit sums (direct light, split-sum environment, emissive
/// through the view throughput) agree within |half - float32| <= kHalfAbs +
/// kHalfRel |float32|. The HLSL kernel in half (its own msaturate and mlerp)
/// meets the same rule on the first input set.
void expectHalfAgreesWithFloat32(const std::string& name) {
  SCOPED_TRACE(name);
  Diagnostics diags("test");
  gpu::Context* ctx = gputest::sharedContext(diags);
  ASSERT_NE(ctx, nullptr) << diags.errorMessages();
  const std::string stem = fs::path(name).stem().string();
  const CompileResult r = compile(readFile(example(name)));
  const auto samples =
      gpu::makeSamples(1024, 0x5eed0000u + static_cast<uint32_t>(std::hash<std::string>{}(stem) & 0xffffu));
  const auto inputSets = gputest::makeInputSets(r.material, 4, 0x1a9u);
  const int stride = gpu::resultStride(r);
  double margin = 0, relMseSum = 0, maxAbs = 0;
  long failed = 0, checked = 0;
  std::string first;
  auto checkLit = [&](const std::vector<float>& float32, const std::vector<float>& half, const char* what) {
    for (std::size_t i = 0; i < samples.size(); ++i)
      for (int at : {kernel::kResultDirect, kernel::kResultEnvironment, kernel::kResultEmissive})
        for (int c = 0; c < 3; ++c) {
          const float f = float32[i * stride + at + c], h = half[i * stride + at + c];
          const double allowed = kHalfAbs + kHalfRel * std::abs(f), d = std::abs(static_cast<double>(h) - f);
          ++checked;
          margin = std::max(margin, d / allowed);
          if (!(d <= allowed) && failed++ == 0)
            first = fmt::format("{}: sample {} float {}: half {} float32 {}", what, i, at + c, h, f);
        }
  };
  for (std::size_t set = 0; set < inputSets.size(); ++set) {
    sweep::BothPrecisions both;
    ASSERT_TRUE(sweep::runBothPrecisions(*ctx, r, Target::Glsl, samples, inputSets[set].values, &both, diags))
        << diags.errorMessages();
    ASSERT_EQ(both.float32.size(), both.half.size());
    const sweep::PrecisionError e = sweep::precisionError(both, stride);
    relMseSum += e.relMse;
    maxAbs = std::max(maxAbs, e.maxAbs);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const float* f = &both.float32[i * stride];
      const float* h = &both.half[i * stride];
      ASSERT_EQ(0, std::memcmp(f + kernel::kResultHeaderFloats, h + kernel::kResultHeaderFloats,
                               sizeof(float) * (stride - kernel::kResultHeaderFloats)))
          << "input set " << set << ", sample " << i << ": the closures differ";
      ASSERT_EQ(f[kernel::kResultCoverage], h[kernel::kResultCoverage]);
    }
    checkLit(both.float32, both.half, "GLSL");
    if (set == 0) {
      EmitOptions half;
      half.precision = Precision::Half;
      std::vector<float> hlsl;
      ASSERT_TRUE(gpu::runSampleKernel(*ctx, r, Target::Hlsl, KernelMode::Forward, half, samples, inputSets[0].values,
                                       &hlsl, diags))
          << diags.errorMessages();
      checkLit(both.float32, hlsl, "HLSL");
    }
  }
  std::printf("[ half     ] %s: rel_mse %.3e (mean of %zu input sets), max abs %.3e; margin %.3f of |d| <= %g + %g |f|\n",
              stem.c_str(), relMseSum / static_cast<double>(inputSets.size()), inputSets.size(), maxAbs, margin,
              kHalfAbs, kHalfRel);
  EXPECT_EQ(failed, 0) << failed << " of " << checked << " lit values outside the tolerance; first: " << first;
}

std::vector<std::string> exampleNames() {
  std::vector<std::string> names;
  for (const fs::path& e : test::exampleFiles(test::Examples::Surfaces)) names.push_back(e.filename().string());
  return names;
}

INSTANTIATE_TEST_SUITE_P(Stability, EveryExample, ::testing::ValuesIn(exampleNames()),
                         [](const auto& info) { return fs::path(info.param).stem().string(); });

// The half-precision tests loop over the examples in one test each: every
// test is its own process under ctest, and a GPU test process costs seconds
// before its first kernel (instance, validation layer, lavapipe).
TEST(Stability, EveryExampleIsFiniteOnTheHardCaseGridInHalfPrecision) {
  for (const std::string& name : exampleNames()) expectFiniteInHalf(example(name));
}

TEST(Stability, HalfPrecisionForwardAgreesWithFloat32OnEveryExample) {
  for (const std::string& name : exampleNames()) expectHalfAgreesWithFloat32(name);
}

// Adversarial materials: every operator, every opt-in feature, the helpers
// with their own singularities, thin and translucent surfaces, degenerate
// inputs at their extremes.
const char* kAdversarial[] = {
    // Every feature on one slab under two coats, a coverage weight and a select.
    R"({"format": "substrate-material/1", "name": "every_feature",
        "inputs": {"r": {"type": "float", "default": 0.3, "min": 0, "max": 1},
                   "a": {"type": "float", "default": 0.5, "min": -1, "max": 1},
                   "w": {"type": "float", "default": 0.5, "min": 0, "max": 1}},
        "nodes": {
          "base": {"kind": "slab", "diffuse_albedo": [0.8, 0.4, 0.2], "f0": [0.9, 0.6, 0.3], "f90": [1, 0.8, 0.6],
                   "roughness": "$r", "anisotropy": "$a", "sss_mfp": [0.01, 0.005, 0.002], "sss_type": "diffusion",
                   "second_roughness": 0.9, "second_roughness_weight": 0.4, "fuzz_amount": 0.7,
                   "fuzz_color": [1, 1, 1], "fuzz_roughness": 0.3, "glint_value": 0.3,
                   "emissive": [0.1, 0.2, 0.3]},
          "coat1": {"kind": "slab", "diffuse_albedo": 0.2, "f0": 0.04, "roughness": 0.05, "sss_mfp": 0.3},
          "coat2": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.08, "roughness": 0.2, "sss_mfp": 5},
          "partial": {"kind": "coverage_weight", "a": "coat2", "weight": "$w"},
          "inner": {"kind": "vertical", "top": "coat1", "base": "base", "thickness": 0.002},
          "outer": {"kind": "vertical", "top": "partial", "base": "inner", "thickness": 0.001},
          "other": {"kind": "slab", "diffuse_albedo": 1, "f0": 1, "roughness": 0},
          "root": {"kind": "select", "a": "outer", "b": "other", "value": "$w", "threshold": 0.75}},
        "output": "root"})",
    // Add of two pieces of matter, a horizontal mix, a thin translucent surface.
    R"({"format": "substrate-material/1", "name": "thin_translucent_add",
        "settings": {"thin_surface": true, "blend_mode": "translucent_colored", "surface_thickness": 1e-9},
        "nodes": {
          "a": {"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 1, "sss_mfp": 1e6},
          "b": {"kind": "slab", "diffuse_albedo": 0, "f0": 1, "f90": 0, "roughness": 1e-4, "anisotropy": 1},
          "mix": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": 1e-7},
          "root": {"kind": "add", "a": "mix", "b": {"kind": "slab", "diffuse_albedo": 0.5, "sss_mfp": 1e-9}}},
        "output": "root"})",
    // The helpers at their singular points.
    R"({"format": "substrate-material/1", "name": "helpers_at_the_edges",
        "nodes": {
          "tm": {"kind": "transmittance_to_mfp", "transmittance": [1, 0, 1e-7], "thickness": 0},
          "film": {"kind": "thin_film", "f0": 1, "f90": 0, "thickness": 0, "ior": 1},
          "haze": {"kind": "haziness_to_second_roughness", "roughness": 0, "haziness": 1},
          "metal": {"kind": "metalness_to_diffuse_f0", "base_color": 1, "metallic": 1, "specular": 1},
          "top": {"kind": "slab", "f0": "film.f0", "f90": "film.f90", "roughness": "haze.second_roughness",
                  "second_roughness": "haze.second_roughness", "second_roughness_weight": "haze.second_roughness_weight",
                  "sss_mfp": "tm.mfp", "diffuse_albedo": 0.9},
          "bottom": {"kind": "slab", "diffuse_albedo": "metal.diffuse_albedo", "f0": "metal.f0", "roughness": 0,
                     "tangent": {"kind": "rotation_to_tangent", "angle": 0, "normal": [0, 0, -1]}},
          "root": {"kind": "vertical", "top": "top", "base": "bottom", "thickness": "tm.thickness"}},
        "output": "root"})",
};

/// `check` on `text` written to a temporary file (ctest may run two tests at
/// once: `name` keeps their files apart).
void checkFile(const std::string& name, const std::string& text, void (*check)(const std::string&)) {
  const fs::path file = fs::temp_directory_path() / ("substratec_" + name + ".json");
  std::ofstream(file) << text;
  check(file.string());
  fs::remove(file);
}

TEST(Stability, AdversarialMaterialsAreFiniteOnTheCpuAndOnTheGpu) {
  int i = 0;
  for (const char* text : kAdversarial) checkFile(fmt::format("adversarial_{}", i++), text, expectFinite);
}

TEST(Stability, AdversarialMaterialsAreFiniteInHalfPrecision) {
  int i = 0;
  for (const char* text : kAdversarial) checkFile(fmt::format("adversarial_half_{}", i++), text, expectFiniteInHalf);
}

TEST(Stability, AWeightBeyondHalfsRangeStaysFiniteInHalfPrecision) {
  // A coverage weight from an input (expressions are not range-checked) of
  // 1e5 to 1e6: float16 ends at 65,504, so the view throughput converts the
  // weight through SUBSTRATE_M_CLAMPED. Without the clamp: 16,740 of 200,880
  // evaluations non-finite.
  checkFile("heavy_weight_half", R"({"format": "substrate-material/1", "name": "heavy_weight",
    "inputs": {"w": {"type": "float", "default": 100000, "min": 0, "max": 1000000}},
    "nodes": {"s": {"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.5},
              "root": {"kind": "coverage_weight", "a": "s", "weight": "$w"}},
    "output": "root"})",
            expectFiniteInHalf);
}

TEST(Stability, PerSampleInputKernelsValidateInBothLanguages) {
  // `stability` runs GLSL; the per-invocation inputs are emitted for HLSL too
  // (static globals, a StructuredBuffer at binding 8): both must validate.
  // In half precision too (HLSL with glslang's 16-bit types).
  EmitOptions emit;
  emit.inputsPerInvocation = true;
  for (const std::string& name : exampleNames()) {
    SCOPED_TRACE(name);
    const CompileResult r = compile(readFile(example(name)));
    for (Precision precision : {Precision::Float, Precision::Half})
      for (Target target : {Target::Glsl, Target::Hlsl})
        for (KernelMode mode : {KernelMode::Forward, KernelMode::Deferred}) {
          emit.precision = precision;
          const ShaderValidation v = compileKernel(r, target, mode, emit);
          EXPECT_TRUE(v.ok) << precisionName(precision) << "\n" << v.log;
        }
  }
}

TEST(Stability, ForcingInputsLeaveTheMaterialAsItWasWhenOff) {
  // The rewrite p -> p(1 - f) + v f is exact at f = 0: every closure of the
  // rewritten material, at its defaults, equals the original's.
  for (const std::string& name : exampleNames()) {
    SCOPED_TRACE(name);
    const std::string text = readFile(example(name));
    std::string rewritten;
    Diagnostics diags("test");
    std::vector<stability::ForcedKind> kinds;
    ASSERT_TRUE(stability::forceableText(text, &rewritten, &kinds, diags)) << diags.errorMessages();
    EXPECT_FALSE(kinds.empty());
    CompileOptions o;
    o.budgetOverride = 1024;
    o.maxClosuresOverride = 8;
    const CompileResult a = compile(text, o), b = compile(rewritten, o);
    ASSERT_EQ(a.after.closures.size(), b.after.closures.size());
    for (const gpu::Sample& s : gpu::makeSamples(64, 7)) {
      const auto x = reference::evaluateMaterial<double>(a, s.geometry, {}, gpu::sampleTexture);
      const auto y = reference::evaluateMaterial<double>(b, s.geometry, {}, gpu::sampleTexture);
      ASSERT_EQ(x.closures.size(), y.closures.size());
      EXPECT_EQ(x.coverage, y.coverage);
      for (std::size_t k = 0; k < x.closures.size(); ++k) {
        for (int c = 0; c < 3; ++c) {
          EXPECT_EQ(x.closures[k].diffuseAlbedo[c], y.closures[k].diffuseAlbedo[c]);
          EXPECT_EQ(x.closures[k].f0[c], y.closures[k].f0[c]);
          EXPECT_EQ(x.closures[k].topTransmittance[c], y.closures[k].topTransmittance[c]);
        }
        EXPECT_EQ(x.closures[k].roughness, y.closures[k].roughness);
        EXPECT_EQ(x.closures[k].weight, y.closures[k].weight);
      }
    }
  }
}

/// Directional albedo of a whole material (every closure, white environment)
/// at the view of cosine mu: what a white furnace returns.
double materialAlbedo(const CompileResult& r, double mu) {
  reference::Geometry g;
  g.V = {std::sqrt(1 - mu * mu), 0, mu};
  const auto m = reference::evaluateMaterial<double>(r, g, {}, {});
  double sum = 0;
  for (const auto& c : m.closures) {
    const double NoV = c.N[0] * g.V[0] + c.N[1] * g.V[1] + c.N[2] * g.V[2];
    const auto t = reference::viewThroughput<double>(c, NoV, reference::V3<double>{g.V[0], g.V[1], g.V[2]});
    const auto e = reference::envIntegrated(
        c, g.V, [](const reference::V3<double>&) { return reference::V3<double>{1, 1, 1}; },
        reference::kDiffuseLambert, 4096, 3);
    sum += t[0] * e[0];
  }
  return sum;
}

TEST(LayeringEnergy, AClearCoatDoesNotBrightenAWhiteBaseAtGrazingViews) {
  // The coat reflects F(mu), which grows toward grazing; what reaches the base
  // must shrink with it (substrate_coat_transmission). Without it: 1.10
  // at NoV 0.2 and 1.21 at 0.1.
  const CompileResult r = compile(R"({"format": "substrate-material/1", "name": "white_coat",
    "nodes": {"coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.05, "sss_mfp": 10},
              "base": {"kind": "slab", "diffuse_albedo": 1, "f0": 0.04, "roughness": 0.5},
              "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0.001}},
    "output": "root"})");
  for (double mu : {1.0, 0.5, 0.2, 0.1, 0.02}) {
    SCOPED_TRACE(mu);
    EXPECT_LE(materialAlbedo(r, mu), 1.001);
  }
}

TEST(LayeringEnergy, ACoatThatLetsLightThroughDoesNotAlsoScatterItAllBack) {
  // A white coat of no thickness (T = 1) over a white base: the coat's medium
  // scatters back a(1 - T^2) = 0 (substrate_layer_scattering). Without it: 2.0.
  for (const char* thickness : {"0", "1e-9", "0.001"}) {
    SCOPED_TRACE(thickness);
    const CompileResult r = compile(fmt::format(R"({{"format": "substrate-material/1", "name": "white_on_white",
      "nodes": {{"coat": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 0.5, "sss_mfp": 0.01}},
                "base": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 0.5}},
                "root": {{"kind": "vertical", "top": "coat", "base": "base", "thickness": {}}}}},
      "output": "root"}})",
                                                thickness));
    for (double mu : {1.0, 0.5, 0.1}) EXPECT_LE(materialAlbedo(r, mu), 1.001) << mu;
  }
}

TEST(LayeringEnergy, APartialCoatsInterfaceKeepsWhatItReflects) {
  // A coat under a coverage weight (an operator on top of the vertical): its
  // interface's 1 - F0 still reaches the base through the operator (TI). A
  // mirror coat (F0 1) of full coverage over a white base returned 2.0.
  for (const char* f0 : {"1", "0.5", "0.04"}) {
    SCOPED_TRACE(f0);
    const CompileResult r = compile(fmt::format(R"({{"format": "substrate-material/1", "name": "partial_mirror",
      "inputs": {{"w": {{"type": "float", "default": 1, "min": 0, "max": 1}}}},
      "nodes": {{"coat": {{"kind": "slab", "diffuse_albedo": 0, "f0": {}, "roughness": 0.3, "sss_mfp": 1e6}},
                "partial": {{"kind": "coverage_weight", "a": "coat", "weight": "$w"}},
                "base": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 0.5}},
                "root": {{"kind": "vertical", "top": "partial", "base": "base", "thickness": 0.001}}}},
      "output": "root"}})",
                                                f0));
    for (double mu : {1.0, 0.5, 0.1}) EXPECT_LE(materialAlbedo(r, mu), 1.001) << mu;
  }
}

TEST(LayeringEnergy, RandomStacksNeverGainEnergyInTheGeneratedShaders) {
  // Issue 16, the lavapipe twin of Furnace.RandomStacksOfTwoToEightSlabsNeverGainEnergy
  // (unit_tests): the closures the forward kernel writes for random stacks
  // (tests/stack_furnace.h), integrated under a white furnace on the CPU. One
  // kernel per stack shape, every case an input set of one dispatch (CI time:
  // three pipelines).
  using namespace stackfurnace;
  Diagnostics diags("test");
  gpu::Context* ctx = gputest::sharedContext(diags);
  ASSERT_NE(ctx, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
  constexpr int kCasesPerStack = 12;
  const std::pair<int, Shape> stacks[] = {{3, Shape::NestedBases}, {5, Shape::CoveredNestedBases}, {8, Shape::NestedTops}};
  // The views, padded to one work group with head-on views.
  std::vector<gpu::Sample> samples(kernel::kLocalSize);
  for (std::size_t i = 0; i < samples.size(); ++i)
    samples[i].geometry.V = viewAt(i < std::size(kNoV) ? kNoV[i] : 1.0);
  const auto sampleBytes = gpu::sampleBuffer(samples);
  long cases = 0, views = 0, closures = 0;
  double worst = 0, largestGap = 0;
  std::string where;
  for (const auto& [depth, shape] : stacks) {
    CompileOptions o;
    o.budgetOverride = 4096;
    o.maxClosuresOverride = 8;
    const CompileResult r = compile(stackMaterial(depth, shape), o);
    ASSERT_EQ(r.after.closures.size(), static_cast<std::size_t>(depth));
    const ShaderValidation shader = compileKernel(r, Target::Glsl, KernelMode::Forward);
    ASSERT_TRUE(shader.ok) << shader.log;
    auto pipeline = ctx->createPipeline(shader.spirv, diags);
    ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
    const int stride = gpu::resultStride(r);
    Rng rng{0x6e0000u + static_cast<std::uint64_t>(depth)};
    for (int k = 0; k < kCasesPerStack; ++k) {
      // The issue's white stack first, then random ones.
      const Case c = k == 0 ? whiteStack(depth, shape) : randomCase(depth, shape, rng);
      ++cases;
      gpu::Resources res = gputest::kernelResources(r.material, pipeline->reflection(), shader.spirv, c.inputs,
                                                    sampleBytes, static_cast<std::size_t>(stride) * samples.size());
      ASSERT_TRUE(ctx->dispatch(*pipeline, res, static_cast<uint32_t>(samples.size()) / kernel::kLocalSize, 1, 1,
                                diags))
          << diags.errorMessages();
      const std::vector<float> out = gpu::floatsOf(res, 0, 7);
      for (std::size_t i = 0; i < std::size(kNoV); ++i) {
        std::vector<reference::Closure<double>> gpuClosures;
        for (int q = 0; q < depth; ++q)
          gpuClosures.push_back(
              gputest::closureFromResults(out, stride, static_cast<int>(i), q, r));
        closures += depth;
        const auto seed = static_cast<std::uint32_t>(101 + views++);
        const double a = furnace(gpuClosures, samples[i].geometry.V, seed);
        const double cpu =
            furnace(reference::evaluateMaterial<double>(r, samples[i].geometry, c.inputs, {}).closures,
                    samples[i].geometry.V, seed);
        const std::string what =
            fmt::format("depth {} ({}), NoV {}: {}", depth, shapeName(shape), kNoV[i], c.text);
        EXPECT_TRUE(std::isfinite(a)) << what;
        EXPECT_LE(a, kTolerance) << what;
        EXPECT_NEAR(a, cpu, 2e-3) << "the shader's layering and the CPU reference's differ: " << what;
        largestGap = std::max(largestGap, std::abs(a - cpu));
        if (a > worst) worst = a, where = what;
      }
    }
  }
  std::printf("[ layering ] random stacks on lavapipe: %ld cases, %ld views, %ld closures; largest %.5f at %s; "
              "largest |gpu - cpu| %.2e\n",
              cases, views, closures, worst, where.c_str(), largestGap);
  ASSERT_GT(cases, 0);
  ASSERT_GT(closures, cases);
}

TEST(LayeringEnergy, StacksLightTheSameForwardDeferredAndOnTheCpu) {
  // The stored interface count on lavapipe: stacks whose closures lie under
  // 2, 3, 4 and 5 interfaces (extraInterfaces 1 .. 3, and one interface folded
  // at depth 6), lit by the forward kernel (compared with the reference's
  // lighting of the material) and by the deferred one (its unpacker must read
  // the count from closure header bits 14-15: compared with the reference's
  // lighting of the closures it unpacked, and the count with the reference's).
  // HLSL and GLSL share the runtime; GLSL only (CI time).
  using namespace stackfurnace;
  constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);
  Diagnostics diags("test");
  gpu::Context* ctx = gputest::sharedContext(diags);
  ASSERT_NE(ctx, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
  const std::vector<gpu::Sample> samples = gpu::makeSamples(kernel::kLocalSize, 0x57ac);
  const auto sampleBytes = gpu::sampleBuffer(samples);
  const gputest::Tolerance tol;
  long compared = 0, stacked = 0, failed = 0;
  double margin = 0;
  std::string worst;
  const std::pair<int, Shape> stacks[] = {{4, Shape::NestedBases}, {6, Shape::NestedBases}, {5, Shape::CoveredNestedBases}};
  for (const auto& stack : stacks) {
    // Plain names, not a structured binding: the lambda below captures them (clang 14, the asan build).
    const int depth = stack.first;
    const Shape shape = stack.second;
    CompileOptions o;
    o.budgetOverride = 4096;
    o.maxClosuresOverride = 8;
    const CompileResult r = compile(stackMaterial(depth, shape), o);
    ASSERT_EQ(r.after.closures.size(), static_cast<std::size_t>(depth));
    const int stride = gpu::resultStride(r);
    ShaderValidation shaders[2];
    decltype(ctx->createPipeline(shaders[0].spirv, diags)) pipelines[2];
    for (int mode = 0; mode < 2; ++mode) {
      shaders[mode] = compileKernel(r, Target::Glsl, mode == 0 ? KernelMode::Forward : KernelMode::Deferred);
      ASSERT_TRUE(shaders[mode].ok) << shaders[mode].log;
      pipelines[mode] = ctx->createPipeline(shaders[mode].spirv, diags);
      ASSERT_NE(pipelines[mode], nullptr) << diags.errorMessages();
    }
    std::vector<float> out[2];
    Rng rng{0x7a0000u + static_cast<std::uint64_t>(depth)};
    std::vector<Case> cases{whiteStack(depth, shape)};
    for (int k = 0; k < 3; ++k) cases.push_back(randomCase(depth, shape, rng));
    for (const Case& c : cases) {
      for (int mode = 0; mode < 2; ++mode) {
        gpu::Resources res = gputest::kernelResources(r.material, pipelines[mode]->reflection(), shaders[mode].spirv,
                                                      c.inputs, sampleBytes,
                                                      static_cast<std::size_t>(stride) * samples.size());
        ASSERT_TRUE(ctx->dispatch(*pipelines[mode], res, static_cast<uint32_t>(samples.size()) / kernel::kLocalSize, 1,
                                  1, diags))
            << diags.errorMessages();
        out[mode] = gpu::floatsOf(res, 0, 7);
      }
      for (std::size_t i = 0; i < samples.size(); ++i) {
        const gpu::Sample& s = samples[i];
        const auto ref = gputest::shade<double>(r, s, c.inputs, kDiffuseModel);
        const auto r32 = gputest::shade<float>(r, s, c.inputs, kDiffuseModel);
        const float* fwd = &out[0][i * static_cast<std::size_t>(stride)];
        const float* def = &out[1][i * static_cast<std::size_t>(stride)];
        std::vector<reference::Closure<double>> unpacked;
        const int count = static_cast<int>(def[kernel::kResultCount]);
        for (int k = 0; k < count; ++k) {
          const auto f = gputest::closureFromResults(out[0], stride, static_cast<int>(i), k, r);
          const auto d = gputest::closureFromResults(out[1], stride, static_cast<int>(i), k, r);
          const std::uint32_t want = ref.material.closures[static_cast<std::size_t>(k)].extraInterfaces;
          EXPECT_EQ(f.extraInterfaces, want) << "forward closure " << k;
          if (count == depth) EXPECT_EQ(d.extraInterfaces, want) << "deferred closure " << k;  // not dynamically simple
          stacked += want > 0;
          unpacked.push_back(d);
        }
        const auto dref = gputest::lightClosures<double>(unpacked, s, kDiffuseModel);
        const auto d32 = gputest::lightClosures<float>(unpacked, s, kDiffuseModel);
        auto check = [&](const char* what, double gpuValue, double r64, double r32v) {
          ++compared;
          const double allowed = tol.k * std::abs(r32v - r64) + tol.abs + tol.rel * std::abs(r64);
          const double m = std::abs(gpuValue - r64) / allowed;
          if (m > margin) margin = m, worst = fmt::format("depth {} ({}), {}, sample {}: {} gpu {} ref {}", depth,
                                                          shapeName(shape), c.text, i, what, gpuValue, r64);
          if (!tol.ok(gpuValue, r64, r32v)) ++failed;
        };
        for (int ch = 0; ch < 3; ++ch) {
          check("forward direct", fwd[kernel::kResultDirect + ch], ref.direct[ch], r32.direct[ch]);
          check("forward environment", fwd[kernel::kResultEnvironment + ch], ref.environment[ch], r32.environment[ch]);
          check("deferred direct", def[kernel::kResultDirect + ch], dref.direct[ch], d32.direct[ch]);
          check("deferred environment", def[kernel::kResultEnvironment + ch], dref.environment[ch], d32.environment[ch]);
        }
      }
    }
  }
  std::printf("[ layering ] stacks forward and deferred on lavapipe: %ld values compared, %ld closures with extra "
              "interfaces; largest error / allowed %.3f at %s\n",
              compared, stacked, margin, worst.c_str());
  EXPECT_EQ(failed, 0) << "largest at " << worst;
  ASSERT_GT(compared, 0);
  ASSERT_GT(stacked, 0);
}

}  // namespace stability_test
