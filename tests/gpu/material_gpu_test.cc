// Running what we generate (issue 5). For every example, at its full budget
// and at 48 B, 20 B and full simplification, the generated material and the
// runtime shaders run on lavapipe as compute kernels over a fixed set of
// 4,096 shading points (1,024 geometries — views from head-on to grazing,
// lights above and below the horizon, textures bound to procedural images —
// under 4 sets of input values), and:
//  - every value they write is finite;
//  - the forward path (closures lit inline) matches the double-precision CPU
//    reference within |gpu − ref64| ≤ k·|ref32 − ref64| + abs + rel·|ref64|,
//    closure fields and lit sums alike;
//  - the deferred path (packed, unpacked from the words alone, then lit) gives
//    every stored field within the quantization bound docs/storage.md claims,
//    and its lighting matches the reference applied to the unpacked closures;
//  - GLSL and HLSL (through glslang's HLSL front end) agree;
//  - the same dispatch twice gives identical bits.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "pipeline/generate.h"
#include "material_fixture.h"
#include "../examples.h"

namespace substratec::gputest {
namespace {

namespace fs = std::filesystem;
using namespace kernel;

constexpr int kGeometries = 1024;
constexpr int kInputSets = 4;
constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);

struct Variant {
  const char* name;
  int budget;  // 0: the material's own
  bool full;
};
constexpr Variant kVariants[] = {{"full_budget", 0, false}, {"budget_48", 48, false}, {"budget_20", 20, false},
                                 {"full_simplification", 0, true}};

std::vector<std::string> exampleStems() {
  std::vector<std::string> stems;
  for (const fs::path& e : test::exampleFiles(test::Examples::Surfaces)) stems.push_back(e.stem().string());
  return stems;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Where two runs of a kernel over the same samples differ most, for messages.
struct Worst {
  double excess = -1;  // |difference| minus the allowed difference
  std::string where;
  void consider(double excessHere, const std::string& whereHere) {
    if (excessHere > excess) {
      excess = excessHere;
      where = whereHere;
    }
  }
};

class MaterialOnGpu : public ::testing::TestWithParam<std::tuple<std::string, Variant>> {
 protected:
  void SetUp() override {
    Diagnostics gpuSetup("test");
    ctx_ = sharedContext(gpuSetup);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << gpuSetup.errorMessages();
    const auto& [stem, variant] = GetParam();
    const fs::path path = fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / (stem + ".json");
    CompileOptions o;
    if (variant.budget > 0) o.budgetOverride = variant.budget;
    o.fullSimplification = variant.full;
    Diagnostics diags(path.filename().string());
    auto r = compileText(path.filename().string(), readFile(path), o, diags);
    ASSERT_TRUE(r.has_value()) << diags.formatAll();
    r_ = std::make_unique<CompileResult>(std::move(*r));
    samples_ = makeSamples(kGeometries, 0x5eed0000u + static_cast<uint32_t>(std::hash<std::string>{}(stem) & 0xffffu));
    sampleBytes_ = sampleBuffer(samples_);
    inputSets_ = makeInputSets(r_->material, kInputSets, 0x1a9u);
  }

  /// A kernel of this material: compiled, its pipeline built, run over every input set.
  struct Kernel {
    std::vector<uint32_t> spirv;
    std::unique_ptr<gpu::ComputePipeline> pipeline;
    std::vector<std::vector<float>> results;  // one per input set; empty: it failed (reported)
  };

  /// Runs `mode` in `target` over every input set; the results of each set.
  /// Built and run once per test: the checks below share it (a pipeline is
  /// most of a GPU test's time on lavapipe).
  const std::vector<std::vector<float>>& run(Target target, KernelMode mode) {
    Kernel& k = kernels_[{target, mode}];
    if (k.pipeline) return k.results;
    const auto t0 = std::chrono::steady_clock::now();
    ShaderValidation v = compileKernel(*r_, target, mode);
    EXPECT_TRUE(v.ok) << v.log;
    if (!v.ok) return k.results;
    Diagnostics diags("test");
    auto pipeline = ctx_->createPipeline(v.spirv, diags);
    EXPECT_NE(pipeline, nullptr) << diags.errorMessages();
    if (!pipeline) return k.results;
    std::vector<std::vector<float>> out;
    const std::size_t floats = static_cast<std::size_t>(resultStride(*r_)) * kGeometries;
    for (const auto& inputs : inputSets_) {
      gpu::Resources res = kernelResources(r_->material, pipeline->reflection(), v.spirv, inputs, sampleBytes_, floats);
      const bool ok = ctx_->dispatch(*pipeline, res, kGeometries / kLocalSize, 1, 1, diags);
      EXPECT_TRUE(ok) << diags.errorMessages();
      if (!ok) return k.results;
      out.push_back(floatsOf(res, 0, 7));
    }
    std::printf("[ timing   ] %s %s: %.0f ms (compile, pipeline, %d dispatches)\n",
                target == Target::Glsl ? "GLSL" : "HLSL", mode == KernelMode::Forward ? "forward" : "deferred",
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count(), kInputSets);
    k.spirv = std::move(v.spirv);
    k.pipeline = std::move(pipeline);
    k.results = std::move(out);
    return k.results;
  }

  // The four checks (docs/gpu-tests.md), run by the one test below.
  void forwardMatchesTheCpuReferenceInBothLanguages();
  void glslAndHlslAgree();
  void theSameDispatchTwiceGivesIdenticalBits();
  void deferredAgreesWithForwardWithinTheStorageBounds();

  void expectMatchesReference(const std::vector<std::vector<float>>& results, const char* what);

  /// The reference for input set `set`, sample `i` (computed once).
  const Shaded<double>& reference64(int set, int i) {
    if (ref64_.empty()) fillReferences();
    return ref64_[static_cast<std::size_t>(set) * kGeometries + i];
  }
  const Shaded<float>& reference32(int set, int i) {
    if (ref32_.empty()) fillReferences();
    return ref32_[static_cast<std::size_t>(set) * kGeometries + i];
  }
  void fillReferences() {
    for (int set = 0; set < kInputSets; ++set)
      for (int i = 0; i < kGeometries; ++i) {
        ref64_.push_back(shade<double>(*r_, samples_[i], inputSets_[set], kDiffuseModel));
        ref32_.push_back(shade<float>(*r_, samples_[i], inputSets_[set], kDiffuseModel));
      }
  }

  gpu::Context* ctx_ = nullptr;
  std::map<std::pair<Target, KernelMode>, Kernel> kernels_;
  std::vector<Shaded<double>> ref64_;
  std::vector<Shaded<float>> ref32_;
  std::unique_ptr<CompileResult> r_;
  std::vector<Sample> samples_;
  std::vector<std::byte> sampleBytes_;
  std::vector<reference::InputValues> inputSets_;
};

/// Every value a kernel wrote is finite (outputs start as NaN, so this also
/// proves every value was written).
void expectFinite(const std::vector<std::vector<float>>& results, const char* what) {
  for (std::size_t s = 0; s < results.size(); ++s)
    for (std::size_t i = 0; i < results[s].size(); ++i)
      if (!std::isfinite(results[s][i])) {
        ADD_FAILURE() << what << ": input set " << s << ", float " << i << " is " << results[s][i];
        return;
      }
}

std::string describe(const Sample& s) {
  const auto& g = s.geometry;
  auto d = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  };
  return fmt::format("NoV {:.3g}, NoL {:.3g}, uv0 ({:.4f}, {:.4f}), dither {:.3f}", d(g.N, g.V), d(g.N, s.light),
                     g.uv0[0], g.uv0[1], g.dither);
}

/// Checks a forward kernel's results against the reference: every closure
/// field and every lit sum, |gpu − ref64| ≤ k·|ref32 − ref64| + abs + rel·|ref64|.
void MaterialOnGpu::expectMatchesReference(const std::vector<std::vector<float>>& results, const char* what) {
  const int stride = resultStride(*r_);
  const Tolerance tol;
  Worst worst;
  long checked = 0, failed = 0;
  double margin = 0;  // the largest |gpu − ref64| / allowed
  for (int set = 0; set < kInputSets; ++set)
    for (int i = 0; i < kGeometries; ++i) {
      const Sample& s = samples_[i];
      const auto& ref = reference64(set, i);
      const auto& r32 = reference32(set, i);
      const auto spread = glintSpread(ref, s, kDiffuseModel);
      const float* gpu = &results[set][static_cast<std::size_t>(i) * stride];
      auto check = [&](const char* field, int at, double ref64, double ref32) {
        ++checked;
        double allowed = tol.k * std::abs(ref32 - ref64) + tol.abs + tol.rel * std::abs(ref64);
        margin = std::max(margin, std::abs(gpu[at] - ref64) / allowed);
        if (tol.ok(gpu[at], ref64, ref32)) return;
        ++failed;
        worst.consider(std::abs(gpu[at] - ref64) - allowed,
                       fmt::format("set {}, sample {} ({}): {} gpu {} ref64 {} ref32 {}", set, i, describe(s), field,
                                   gpu[at], ref64, ref32));
      };
      ASSERT_EQ(gpu[kResultCount], static_cast<float>(r_->after.closures.size()));
      for (std::size_t k = 0; k < ref.material.closures.size(); ++k) {
        const auto& c64 = ref.material.closures[k];
        const auto& c32 = r32.material.closures[k];
        const int at = kResultHeaderFloats + kClosureFloats * static_cast<int>(k);
        auto field3 = [&](const char* field, int f, const std::array<double, 3>& a, const std::array<float, 3>& b) {
          for (int c = 0; c < 3; ++c) check(field, at + f + c, a[c], b[c]);
        };
        field3("diffuseAlbedo", kClosureDiffuseAlbedo, c64.diffuseAlbedo, c32.diffuseAlbedo);
        field3("f0", kClosureF0, c64.f0, c32.f0);
        field3("f90", kClosureF90, c64.f90, c32.f90);
        check("roughness", at + kClosureRoughness, c64.roughness, c32.roughness);
        check("anisotropy", at + kClosureAnisotropy, c64.anisotropy, c32.anisotropy);
        field3("N", kClosureN, c64.N, c32.N);
        if (c64.features & (reference::kFeatureAnisotropy | reference::kFeatureHair)) field3("T", kClosureT, c64.T_, c32.T_);
        field3("sssMfp", kClosureSssMfp, c64.sssMfp, c32.sssMfp);
        check("sssPhaseAnisotropy", at + kClosureSssPhase, c64.sssPhaseAnisotropy, c32.sssPhaseAnisotropy);
        check("sssType", at + kClosureSssType, c64.sssType, c64.sssType);
        check("secondRoughness", at + kClosureSecondRoughness, c64.secondRoughness, c32.secondRoughness);
        check("secondRoughnessWeight", at + kClosureSecondRoughnessWeight, c64.secondRoughnessWeight,
              c32.secondRoughnessWeight);
        check("fuzzAmount", at + kClosureFuzzAmount, c64.fuzzAmount, c32.fuzzAmount);
        field3("fuzzColor", kClosureFuzzColor, c64.fuzzColor, c32.fuzzColor);
        check("fuzzRoughness", at + kClosureFuzzRoughness, c64.fuzzRoughness, c32.fuzzRoughness);
        check("glintValue", at + kClosureGlintValue, c64.glintValue, c32.glintValue);
        for (int c = 0; c < 2; ++c) check("glintUv", at + kClosureGlintUv + c, c64.glintUv[c], c32.glintUv[c]);
        for (int c = 0; c < 4; ++c)
          check("glintUvDerivatives", at + kClosureGlintUvDerivatives + c, c64.glintUvDerivatives[c],
                c32.glintUvDerivatives[c]);
        check("specularProfile", at + kClosureSpecularProfile, c64.specularProfile, c64.specularProfile);
        field3("emissive", kClosureEmissive, c64.emissive, c32.emissive);
        check("weight", at + kClosureWeight, c64.weight, c32.weight);
        field3("topTransmittance", kClosureTopTransmittance, c64.topTransmittance, c32.topTransmittance);
        check("coverageAbove", at + kClosureCoverageAbove, c64.coverageAbove, c32.coverageAbove);
        check("features", at + kClosureFeatures, c64.features, c64.features);
        check("isTop", at + kClosureIsTop, c64.isTop ? 1 : 0, c64.isTop ? 1 : 0);
        check("extraInterfaces", at + kClosureExtraInterfaces, c64.extraInterfaces, c64.extraInterfaces);
        check("coatFloor", at + kClosureCoatFloor, c64.coatFloor, c32.coatFloor);
        check("coatInterface", at + kClosureCoatInterface, c64.coatInterface, c32.coatInterface);
        for (int c = 0; c < 2; ++c)
          check("coatStretch", at + kClosureCoatStretch + c, c64.coatStretch[c], c32.coatStretch[c]);
        field3("coatTangent", kClosureCoatTangent, c64.coatTangent, c32.coatTangent);
        check("coatShare", at + kClosureCoatShare, c64.coatShare, c32.coatShare);
        check("coversLayers", at + kClosureCoversLayers, c64.coversLayers ? 1 : 0, c64.coversLayers ? 1 : 0);
        if (c64.features & reference::kFeatureHair)  // the field exists where a hair may be (SUBSTRATE_USE_HAIR)
          for (int c = 0; c < 4; ++c) check("hair", at + kClosureHair + c, c64.hair[c], c32.hair[c]);
        if (c64.features & reference::kFeatureEye) {  // the fields exist where an eye may be (SUBSTRATE_USE_EYE)
          field3("irisN", kClosureIrisN, c64.irisN, c32.irisN);
          field3("irisPlaneN", kClosureIrisPlaneN, c64.irisPlaneN, c32.irisPlaneN);
          for (int c = 0; c < 2; ++c) check("iris", at + kClosureIris + c, c64.iris[c], c32.iris[c]);
        }
      }
      check("coverage", kResultCoverage, ref.material.coverage, r32.material.coverage);
      for (int c = 0; c < 3; ++c) {
        check("transmittance", kResultTransmittance + c, ref.material.transmittance[c], r32.material.transmittance[c]);
        // Glints are discontinuous at float resolution: their spread under
        // float-sized nudges counts as conditioning too.
        const double r32direct =
            std::abs(r32.direct[c] - ref.direct[c]) >= spread[c] ? r32.direct[c] : ref.direct[c] + spread[c];
        check("direct", kResultDirect + c, ref.direct[c], r32direct);
        check("environment", kResultEnvironment + c, ref.environment[c], r32.environment[c]);
        check("emissive", kResultEmissive + c, ref.emissive[c], r32.emissive[c]);
      }
    }
  std::printf("[ margin   ] %s: %ld values, largest |gpu - ref64| / allowed = %.3f\n", what, checked, margin);
  EXPECT_EQ(failed, 0) << what << ": " << failed << " of " << checked << " values outside tolerance; worst: "
                       << worst.where;
}

void MaterialOnGpu::forwardMatchesTheCpuReferenceInBothLanguages() {
  const auto& glsl = run(Target::Glsl, KernelMode::Forward);
  const auto& hlsl = run(Target::Hlsl, KernelMode::Forward);
  ASSERT_FALSE(glsl.empty() || hlsl.empty());
  expectFinite(glsl, "GLSL forward");
  expectFinite(hlsl, "HLSL forward");
  expectMatchesReference(glsl, "GLSL forward");
  expectMatchesReference(hlsl, "HLSL forward");
}

void MaterialOnGpu::glslAndHlslAgree() {
  // Both languages go through glslang to SPIR-V; they may round differently,
  // never by more than the sample's conditioning allows.
  const auto& glsl = run(Target::Glsl, KernelMode::Forward);
  const auto& hlsl = run(Target::Hlsl, KernelMode::Forward);
  ASSERT_FALSE(glsl.empty() || hlsl.empty());
  const int stride = resultStride(*r_);
  const Tolerance tol;
  long differ = 0, identical = 0, total = 0;
  Worst worst;
  for (int set = 0; set < kInputSets; ++set)
    for (int i = 0; i < kGeometries; ++i) {
      const auto& ref = reference64(set, i);
      const auto& r32 = reference32(set, i);
      const auto spread = glintSpread(ref, samples_[i], kDiffuseModel);
      for (int at = 0; at < stride; ++at) {
        const float a = glsl[set][static_cast<std::size_t>(i) * stride + at];
        const float b = hlsl[set][static_cast<std::size_t>(i) * stride + at];
        ++total;
        if (a == b) {
          ++identical;
          continue;
        }
        // Allowed: twice the reference tolerance of the lit sums (the largest
        // conditioning of the sample), or the field tolerance around a.
        double cond = 0;
        for (int c = 0; c < 3; ++c)
          cond = std::max({cond, std::abs(r32.direct[c] - ref.direct[c]), spread[c],
                           std::abs(r32.environment[c] - ref.environment[c])});
        const double allowed = 2 * (tol.k * cond + tol.abs + tol.rel * std::abs(a));
        if (std::abs(a - b) > allowed) {
          ++differ;
          worst.consider(std::abs(a - b) - allowed,
                         fmt::format("set {}, sample {}, float {}: GLSL {} HLSL {}", set, i, at, a, b));
        }
      }
    }
  std::printf("[ agree    ] %ld of %ld floats bit-identical between GLSL and HLSL\n", identical, total);
  EXPECT_EQ(differ, 0) << differ << " floats differ beyond tolerance; worst: " << worst.where;
}

void MaterialOnGpu::theSameDispatchTwiceGivesIdenticalBits() {
  // Twice more on the pipelines the other checks ran: the same bits as each other and as before.
  for (KernelMode mode : {KernelMode::Forward, KernelMode::Deferred}) {
    const auto& before = run(Target::Glsl, mode);
    ASSERT_FALSE(before.empty());
    const Kernel& k = kernels_.at({Target::Glsl, mode});
    Diagnostics diags("test");
    const std::size_t floats = static_cast<std::size_t>(resultStride(*r_)) * kGeometries;
    std::vector<std::vector<float>> runs;
    for (int i = 0; i < 2; ++i) {
      gpu::Resources res =
          kernelResources(r_->material, k.pipeline->reflection(), k.spirv, inputSets_[1], sampleBytes_, floats);
      ASSERT_TRUE(ctx_->dispatch(*k.pipeline, res, kGeometries / kLocalSize, 1, 1, diags)) << diags.errorMessages();
      runs.push_back(floatsOf(res, 0, 7));
    }
    const char* what = mode == KernelMode::Forward ? "forward" : "deferred";
    EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * sizeof(float))) << what;
    EXPECT_EQ(0, std::memcmp(runs[0].data(), before[1].data(), runs[0].size() * sizeof(float))) << what;
  }
}

/// The bound docs/storage.md claims for a quantized field, around the true value x.
double colourBound(double x, int channel) {
  const double q = channel < 2 ? 1.0 / 127 : 1.0 / 63;
  return 2 * std::sqrt(std::clamp(x, 0.0, 1.0)) * q + q * q;
}
double angleDegrees(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double d = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) /
             std::sqrt((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]));
  return std::acos(std::clamp(d, -1.0, 1.0)) * 180 / M_PI;
}

void MaterialOnGpu::deferredAgreesWithForwardWithinTheStorageBounds() {
  // The base pass packs what the forward pass lights; the deferred pass
  // unpacks it from the words alone. Every stored field comes back within the
  // bound docs/storage.md claims for it (plus float rounding), and the deferred
  // lighting of what came back matches the reference's lighting of it.
  for (Target target : {Target::Glsl, Target::Hlsl}) {
    SCOPED_TRACE(target == Target::Glsl ? "GLSL" : "HLSL");
    const auto& forward = run(target, KernelMode::Forward);
    const auto& deferred = run(target, KernelMode::Deferred);
    ASSERT_FALSE(forward.empty() || deferred.empty());
    expectFinite(deferred, "deferred");
    const StorageLayout& L = r_->after;
    const int stride = resultStride(*r_);
    const int n = static_cast<int>(L.closures.size());
    std::set<std::string> storedStatically;
    for (const LayoutField& f : L.fields) storedStatically.insert(f.name);
    std::map<std::string, double> worstRatio;  // field -> largest error / bound
    long failed = 0;
    Worst worst;
    const Tolerance tol;
    double lightMargin = 0;
    const std::set<std::string> simpleFields = {"closure0.diffuse_albedo", "closure0.f0", "closure0.roughness"};
    long dynamicallySimple = 0;
    for (int set = 0; set < kInputSets; ++set)
      for (int i = 0; i < kGeometries; ++i) {
        // Dynamic simplification: where one plain closure is left, the base
        // pass stores it alone in the SIMPLE layout (tests/gpu/scene_gpu_test.cc).
        const float* px = &deferred[set][static_cast<std::size_t>(i) * stride];
        const bool simpleHere = L.layoutClass != LayoutClass::Simple && px[kResultLayoutClass] == 0.0f;
        ASSERT_EQ(px[kResultCount], simpleHere ? 1.0f : static_cast<float>(n));
        dynamicallySimple += simpleHere;
        std::vector<reference::Closure<double>> unpacked;
        for (int k = 0; k < (simpleHere ? 1 : n); ++k) {
          int kf = k;  // the forward closure stored as closure k: the one left, when simple here
          if (simpleHere)
            for (int j = 0; j < n; ++j)
              if (closureFromResults(forward[set], stride, i, j, *r_).weight > 0) kf = j;
          const auto f = closureFromResults(forward[set], stride, i, kf, *r_);
          const auto d = closureFromResults(deferred[set], stride, i, k, *r_);
          unpacked.push_back(d);
          const std::set<std::string>& stored = simpleHere ? simpleFields : storedStatically;
          const std::string pre = fmt::format("closure{}.", k);
          auto bound = [&](const std::string& field, double error, double limit) {
            const double slop = 2e-6;
            double ratio = error / (limit + slop);
            worstRatio[field] = std::max(worstRatio[field], ratio);
            if (ratio > 1) {
              ++failed;
              worst.consider(ratio, fmt::format("set {}, sample {}: {} off by {} (bound {})", set, i, pre + field,
                                                error, limit));
            }
          };
          auto colour = [&](const std::string& field, const std::array<double, 3>& a, const std::array<double, 3>& b) {
            for (int c = 0; c < 3; ++c) bound(field, std::abs(std::clamp(a[c], 0.0, 1.0) - b[c]), colourBound(a[c], c));
          };
          auto unorm = [&](const std::string& field, double a, double b, int bits) {
            bound(field, std::abs(std::clamp(a, 0.0, 1.0) - b), 1.0 / ((1 << bits) - 1));
          };
          if (stored.count(pre + "diffuse_albedo")) colour("diffuse_albedo", f.diffuseAlbedo, d.diffuseAlbedo);
          if (stored.count(pre + "f0")) colour("f0", f.f0, d.f0);
          if (stored.count(pre + "f90")) colour("f90", f.f90, d.f90);
          if (stored.count(pre + "roughness")) unorm("roughness", f.roughness, d.roughness, 8);
          if (stored.count(pre + "weight")) unorm("weight", f.weight, d.weight, 8);
          if (stored.count(pre + "coverage_above")) unorm("coverage_above", f.coverageAbove, d.coverageAbove, 8);
          if (stored.count(pre + "top_transmittance")) colour("top_transmittance", f.topTransmittance, d.topTransmittance);
          if (stored.count(pre + "anisotropy"))
            bound("anisotropy", std::abs(std::clamp(f.anisotropy, -1.0, 1.0) - d.anisotropy), 1.0 / 127);
          if (stored.count(pre + "haze")) {
            unorm("haze.second_roughness", f.secondRoughness, d.secondRoughness, 8);
            unorm("haze.weight", f.secondRoughnessWeight, d.secondRoughnessWeight, 8);
          }
          if (stored.count(pre + "fuzz")) {
            unorm("fuzz.amount", f.fuzzAmount, d.fuzzAmount, 6);
            colour("fuzz.colour", f.fuzzColor, d.fuzzColor);
            unorm("fuzz.roughness", f.fuzzRoughness, d.fuzzRoughness, 6);
          }
          if (stored.count(pre + "sss")) {
            for (int c = 0; c < 3; ++c) {
              const double x = std::clamp(f.sssMfp[c], std::ldexp(1.0, -24), 256.0);
              if (f.sssMfp[c] > 0) bound("sss.mfp (relative)", std::abs(d.sssMfp[c] / x - 1), std::exp2(32.0 / 255) - 1);
            }
            bound("sss.phase", std::abs(std::clamp(f.sssPhaseAnisotropy, -1.0, 1.0) - d.sssPhaseAnisotropy), 1.0 / 7);
          }
          if (stored.count(pre + "hair")) {  // docs/storage.md, "Hair"
            unorm("hair.azimuthal_roughness", f.hair[0], d.hair[0], 8);
            bound("hair.ior", std::abs(std::clamp(f.hair[1], 1.0, 3.0) - d.hair[1]), 2.0 / 255);
            bound("hair.cuticle_angle (degrees)", std::abs(std::clamp(f.hair[2], -20.0, 20.0) - d.hair[2]), 20.0 / 127);
            unorm("hair.scatter", f.hair[3], d.hair[3], 8);
          }
          if (stored.count(pre + "iris_normal")) {  // docs/storage.md, "Eye"
            bound("iris.normal (degrees)", angleDegrees(f.irisN, d.irisN), 0.0075 + 1e-3);
            bound("iris.plane_normal (degrees)", angleDegrees(f.irisPlaneN, d.irisPlaneN), 1.91 + 1e-3);
            unorm("iris.mask", f.iris[0], d.iris[0], 8);
            unorm("iris.distance", f.iris[1], d.iris[1], 8);
          }
          if (stored.count(pre + "glint")) {
            unorm("glint.density", f.glintValue, d.glintValue, 8);
            for (int c = 0; c < 2; ++c) bound("glint.uv", std::abs(f.glintUv[c] - d.glintUv[c]), 0.0);
            for (int c = 0; c < 4; ++c)
              bound("glint.derivatives (relative)",
                    std::abs(f.glintUvDerivatives[c] - d.glintUvDerivatives[c]) /
                        std::max(std::abs(f.glintUvDerivatives[c]), 6.1e-5),
                    std::ldexp(1.0, -11));
          }
          // The normal: its basis's stored normal, or the top-layer word's when elided.
          const int b = simpleHere ? 0 : L.closures[k].basis;
          const bool normalStored = stored.count(fmt::format("basis{}.normal", b)) > 0;
          const double normalBound = normalStored ? 0.0075 : 0.119;
          bound(normalStored ? "basis.normal (degrees)" : "top_layer.normal (degrees)", angleDegrees(f.N, d.N),
                normalBound + 1e-3);
          if (stored.count(fmt::format("basis{}.tangent_angle", b)) &&
              (f.features & (reference::kFeatureAnisotropy | reference::kFeatureHair)))
            bound("basis.tangent (degrees)", angleDegrees(f.T_, d.T_), 0.022 + normalBound + 1e-3);
        }
        // The deferred lighting is the reference's lighting of the unpacked closures.
        const Sample& s = samples_[i];
        const auto ref = lightClosures<double>(unpacked, s, kDiffuseModel);
        const auto r32 = lightClosures<float>(unpacked, s, kDiffuseModel);
        const auto spread = glintSpread(ref, s, kDiffuseModel);
        const float* gpu = &deferred[set][static_cast<std::size_t>(i) * stride];
        for (int c = 0; c < 3; ++c) {
          auto light = [&](const char* what, int at, double r64, double r32v) {
            double allowed = tol.k * std::abs(r32v - r64) + tol.abs + tol.rel * std::abs(r64);
            lightMargin = std::max(lightMargin, std::abs(gpu[at] - r64) / allowed);
            if (!tol.ok(gpu[at], r64, r32v)) {
              ++failed;
              worst.consider(std::abs(gpu[at] - r64) / allowed,
                             fmt::format("set {}, sample {} ({}): deferred {} gpu {} ref {}", set, i, describe(s), what,
                                         gpu[at], r64));
            }
          };
          light("direct", kResultDirect + c, ref.direct[c],
                std::abs(r32.direct[c] - ref.direct[c]) >= spread[c] ? r32.direct[c] : ref.direct[c] + spread[c]);
          light("environment", kResultEnvironment + c, ref.environment[c], r32.environment[c]);
        }
      }
    std::string summary;
    for (const auto& [field, ratio] : worstRatio) summary += fmt::format(" {} {:.2f};", field, ratio);
    std::printf("[ bounds   ] largest error / bound per field:%s lighting margin %.3f; %ld samples stored SIMPLE "
                "by dynamic simplification\n",
                summary.c_str(), lightMargin, dynamicallySimple);
    EXPECT_EQ(failed, 0) << failed << " values outside their bounds; worst: " << worst.where;
  }
}

// One test per material and budget runs the four checks on kernels built once
// (four pipelines: forward and deferred in each language). As four tests they
// built ten, since GoogleTest runs every material's first test before any
// material's second; the checks' own failures name the check (SCOPED_TRACE).
TEST_P(MaterialOnGpu, RunsOnLavapipeAsTheReferenceAndTheStorageBoundsSay) {
  {
    SCOPED_TRACE("ForwardMatchesTheCpuReferenceInBothLanguages");
    forwardMatchesTheCpuReferenceInBothLanguages();
  }
  {
    SCOPED_TRACE("GlslAndHlslAgree");
    glslAndHlslAgree();
  }
  {
    SCOPED_TRACE("DeferredAgreesWithForwardWithinTheStorageBounds");
    deferredAgreesWithForwardWithinTheStorageBounds();
  }
  {
    SCOPED_TRACE("TheSameDispatchTwiceGivesIdenticalBits");
    theSameDispatchTwiceGivesIdenticalBits();
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, MaterialOnGpu,
                         ::testing::Combine(::testing::ValuesIn(exampleStems()), ::testing::ValuesIn(kVariants)),
                         [](const ::testing::TestParamInfo<MaterialOnGpu::ParamType>& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param).name;
                         });

}  // namespace
}  // namespace substratec::gputest
