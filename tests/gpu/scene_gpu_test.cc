// Scenes on lavapipe (docs/scenes.md).
//
//  - Dynamic simplification: the same material with run-time inputs (and a
//    texture mask) that leave one plain closure at a pixel is stored by its
//    base pass's pack function in the SIMPLE layout, and lights identically
//    within the storage bounds. The Deferred kernel (pack, then the generic
//    unpacker, then lighting) runs with the pack function as generated and
//    with dynamic simplification off: the SIMPLE pixels unpack to the same
//    albedo, F0 and roughness bits as the static layout's, a normal within the
//    top-layer word's bound, every other field neutral, and light as the
//    static layout's pixel does and as the CPU reference lights what they
//    unpack. Pixels with more than one closure left keep the static layout.
//  - The scene's lighting: a small G-buffer of the `street` scene's materials
//    (packed by the CPU mirror of docs/storage.md, some pixels in the SIMPLE
//    layout as dynamic simplification stores them) goes through the emitted
//    tile classification, which must list every tile under the class of its
//    most complex pixel, then through each class's lighting shader over its
//    tiles, which must light each pixel as the CPU reference lights the
//    closures the CPU unpacker reads back, in GLSL and in HLSL.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "batch/batch.h"
#include "emit/generate.h"
#include "emit/scene_emitter.h"
#include "material_fixture.h"
#include "storage/pack.h"
#include "validate/runtime_files.h"

namespace substratec::gputest {
namespace {

namespace fs = std::filesystem;
using namespace kernel;

constexpr int kDiffuseModel = 2;

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

CompileResult compileSceneMaterial(const std::string& stem) {
  const fs::path path = fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / "scenes" / "materials" / (stem + ".json");
  Diagnostics d(path.filename().string());
  auto r = compileText(path.filename().string(), readFile(path), CompileOptions{}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

/// Input values: the defaults with `set` overriding some by name.
reference::InputValues inputsWith(const Material& m, const std::map<std::string, double>& set) {
  reference::InputValues in;
  for (const Input& i : m.inputs) {
    std::array<double, 4> v = i.defaultValue;
    if (auto it = set.find(i.name); it != set.end()) v = {it->second, it->second, it->second, it->second};
    in.values.push_back(v);
  }
  return in;
}

/// The closures of `ref` left at a pixel (weight > 0).
std::vector<int> visible(const std::vector<reference::Closure<double>>& closures) {
  std::vector<int> k;
  for (std::size_t i = 0; i < closures.size(); ++i)
    if (closures[i].weight > 0) k.push_back(static_cast<int>(i));
  return k;
}

double angleDegrees(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  double d = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) /
             std::sqrt((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]));
  return std::acos(std::clamp(d, -1.0, 1.0)) * 180 / M_PI;
}

class SceneOnGpu : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ctx_ = sharedContext(&error);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << error;
  }

  /// The Deferred kernel of `r`, compiled and ready to dispatch.
  struct Kernel {
    std::vector<uint32_t> spirv;
    std::unique_ptr<gpu::ComputePipeline> pipeline;
  };
  Kernel deferredKernel(const CompileResult& r, Target target, bool dynamic) {
    EmitOptions emit;
    emit.dynamicSimplification = dynamic;
    ShaderValidation v = compileKernel(r, target, KernelMode::Deferred, emit);
    EXPECT_TRUE(v.ok) << v.log;
    Kernel k;
    if (!v.ok) return k;
    std::string error;
    k.pipeline = ctx_->createPipeline(v.spirv, &error);
    EXPECT_NE(k.pipeline, nullptr) << error;
    k.spirv = std::move(v.spirv);
    return k;
  }

  /// Runs `k` over `samples` with `inputs`; its results.
  std::vector<float> run(const CompileResult& r, const Kernel& k, const std::vector<Sample>& samples,
                         const reference::InputValues& inputs) {
    if (!k.pipeline) return {};
    const std::size_t floats = static_cast<std::size_t>(resultStride(r)) * samples.size();
    gpu::Resources res =
        kernelResources(r.material, k.pipeline->reflection(), k.spirv, inputs, sampleBuffer(samples), floats);
    std::string error;
    const bool ok = ctx_->dispatch(*k.pipeline, res, static_cast<uint32_t>(samples.size() / kLocalSize), 1, 1, &error);
    EXPECT_TRUE(ok) << error;
    return ok ? floatsOf(res, 0, 7) : std::vector<float>{};
  }

  gpu::Context* ctx_ = nullptr;
};

struct DynamicCase {
  const char* material;
  std::map<std::string, double> inputs;
  const char* what;
};

TEST_F(SceneOnGpu, AMaterialWhoseInputsMakeItSimpleIsStoredSimpleAndLightsTheSame) {
  const DynamicCase cases[] = {
      {"dusty_plastic", {{"dust", 0.0}, {"haze", 0.0}}, "clean: no dust, no haze"},
      {"dusty_plastic", {}, "defaults: dust and haze"},
      {"wet_asphalt", {{"wetness", 0.0}}, "dry: one closure wherever the mask is"},
      {"wet_asphalt", {}, "wet puddles: one closure outside them, two inside"},
  };
  const std::vector<Sample> samples = makeSamples(512, 0x5ce9e);
  std::map<std::string, CompileResult> compiled;
  std::map<std::string, std::array<Kernel, 3>> kernels;  // static layout (GLSL), dynamic (GLSL, HLSL)
  for (const DynamicCase& dc : cases) {
    SCOPED_TRACE(fmt::format("{} ({})", dc.material, dc.what));
    if (!compiled.count(dc.material)) {
      compiled[dc.material] = compileSceneMaterial(dc.material);
      const CompileResult& r = compiled[dc.material];
      kernels[dc.material] = {deferredKernel(r, Target::Glsl, false), deferredKernel(r, Target::Glsl, true),
                              deferredKernel(r, Target::Hlsl, true)};
    }
    const CompileResult& r = compiled[dc.material];
    const StorageLayout& L = r.after;
    ASSERT_NE(L.layoutClass, LayoutClass::Simple);
    ASSERT_FALSE(runtimeSimpleClosures(r.material, L).empty());
    const reference::InputValues inputs = inputsWith(r.material, dc.inputs);
    const int stride = resultStride(r);
    const std::vector<float> off = run(r, kernels[dc.material][0], samples, inputs);
    ASSERT_FALSE(off.empty());
    for (Target target : {Target::Glsl, Target::Hlsl}) {
      SCOPED_TRACE(target == Target::Glsl ? "GLSL" : "HLSL");
      const std::vector<float> on = run(r, kernels[dc.material][target == Target::Glsl ? 1 : 2], samples, inputs);
      ASSERT_FALSE(on.empty());
      const Tolerance tol;
      long simple = 0, failures = 0;
      double worstNormal = 0, worstLight = 0;
      std::string firstFailure;
      auto fail = [&](const std::string& what) {
        if (failures++ == 0) firstFailure = what;
      };
      for (std::size_t i = 0; i < samples.size(); ++i) {
        const float* a = &on[i * stride];
        const float* b = &off[i * stride];
        const auto ref = reference::evaluateMaterial<double>(r, samples[i].geometry, inputs, sampleTexture);
        const std::vector<int> left = visible(ref.closures);
        // Expected: SIMPLE exactly where one closure is left with nothing it stores in use.
        bool plain = left.size() == 1;
        if (plain) {
          const auto& c = ref.closures[left[0]];
          plain = c.weight >= 1 && !(c.secondRoughnessWeight > 0) && !(c.fuzzAmount > 0) && !(c.coverageAbove > 0);
        }
        EXPECT_EQ(b[kResultLayoutClass], static_cast<float>(L.layoutClass)) << "dynamic simplification off";
        if (!plain) {
          if (a[kResultLayoutClass] != static_cast<float>(L.layoutClass) || a[kResultCount] != static_cast<float>(L.closures.size()))
            fail(fmt::format("sample {}: {} closures left, stored as class {}", i, left.size(), a[kResultLayoutClass]));
          continue;
        }
        ++simple;
        if (a[kResultLayoutClass] != 0.0f || a[kResultCount] != 1.0f) {
          fail(fmt::format("sample {}: one plain closure left, stored as class {} with {} closures", i,
                           a[kResultLayoutClass], a[kResultCount]));
          continue;
        }
        const int k = left[0];
        const auto s = closureFromResults(on, stride, static_cast<int>(i), 0);
        const auto full = closureFromResults(off, stride, static_cast<int>(i), k);
        // The same codes for the three fields the SIMPLE layout stores...
        if (s.diffuseAlbedo != full.diffuseAlbedo || s.f0 != full.f0 || s.roughness != full.roughness)
          fail(fmt::format("sample {}: albedo, F0 or roughness differ from the static layout's", i));
        // ... everything else at the value the static layout decodes for it ...
        if (s.weight != 1.0 || full.weight != 1.0 || s.features != 0 || !s.isTop || s.fuzzAmount != full.fuzzAmount ||
            s.secondRoughnessWeight != full.secondRoughnessWeight || s.coverageAbove != 0.0)
          fail(fmt::format("sample {}: a field the SIMPLE layout does not store is not neutral", i));
        // ... and the normal from the top-layer word, within its bound of the static layout's.
        worstNormal = std::max(worstNormal, angleDegrees(s.N, full.N));
        if (angleDegrees(s.N, full.N) > 0.119 + 0.0075 + 1e-3) fail(fmt::format("sample {}: normal off", i));
        // Lighting: the reference's lighting of what was unpacked, and the static layout's lighting.
        const auto ref64 = lightClosures<double>({s}, samples[i], kDiffuseModel);
        const auto ref32 = lightClosures<float>({s}, samples[i], kDiffuseModel);
        for (int c = 0; c < 3; ++c)
          for (auto [at, r64, r32] : {std::tuple{kResultDirect + c, ref64.direct[c], double(ref32.direct[c])},
                                      std::tuple{kResultEnvironment + c, ref64.environment[c], double(ref32.environment[c])}}) {
            const double allowed = tol.k * std::abs(r32 - r64) + tol.abs + tol.rel * std::abs(r64);
            worstLight = std::max(worstLight, std::abs(a[at] - b[at]) / allowed);
            if (!tol.ok(a[at], r64, r32) || std::abs(a[at] - b[at]) > allowed)
              fail(fmt::format("sample {}: lit {} (static layout {}, reference {})", i, a[at], b[at], r64));
          }
      }
      std::printf("[ dynamic  ] %s, %s: %ld of %zu samples stored SIMPLE; normal within %.4f deg of the static "
                  "layout's; lighting difference / allowed %.3f\n",
                  dc.material, dc.what, simple, samples.size(), worstNormal, worstLight);
      EXPECT_EQ(failures, 0) << failures << " failures; first: " << firstFailure;
      if (dc.inputs.empty() && std::string(dc.material) == "dusty_plastic") EXPECT_EQ(simple, 0);
      if (!dc.inputs.empty()) EXPECT_EQ(simple, static_cast<long>(samples.size()));
      if (dc.inputs.empty() && std::string(dc.material) == "wet_asphalt") {
        EXPECT_GT(simple, 0);
        EXPECT_LT(simple, static_cast<long>(samples.size()));
      }
    }
  }
}

// ---------------------------------------------------------------------------
// The scene's tile classification and lighting shaders.

constexpr uint32_t kWidth = 20, kHeight = 12;  // 3 x 2 tiles, the last column and row partial
constexpr uint32_t kTilesX = (kWidth + 7) / 8, kTilesY = (kHeight + 7) / 8, kTiles = kTilesX * kTilesY;

struct Frame {
  std::array<double, 3> forward{0, 0, -1}, right{1, 0, 0}, up{0, 1, 0};
  double tanHalfFov = 0.4;
  std::array<double, 3> light{0.3, 0.5, 0.8124038404635961};  // unit
  std::array<double, 3> radiance{2.0, 1.8, 1.6};
  std::array<double, 3> prefiltered{0.6, 0.5, 0.4};  // a constant environment
  std::array<double, 3> irradiance{1.2, 1.0, 0.8};
};

std::array<double, 3> viewAt(const Frame& f, uint32_t x, uint32_t y) {
  const double nx = (x + 0.5) / kWidth * 2 - 1, ny = (y + 0.5) / kHeight * 2 - 1;
  const double aspect = double(kWidth) / kHeight;
  std::array<double, 3> d;
  for (int c = 0; c < 3; ++c)
    d[c] = f.forward[c] + nx * aspect * f.tanHalfFov * f.right[c] - ny * f.tanHalfFov * f.up[c];
  const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {-d[0] / l, -d[1] / l, -d[2] / l};
}

/// One pixel of the G-buffer: its words, top-layer word, the class it was
/// packed in and the closures the CPU unpacker reads back (in world space).
struct Pixel {
  std::vector<uint32_t> words;
  uint32_t topLayer = 0;
  LayoutClass cls = LayoutClass::Simple;
  std::vector<reference::Closure<double>> closures;
  Sample sample;
};

ClosureValues valuesOf(const reference::Closure<double>& c) {
  ClosureValues v;
  v.diffuseAlbedo = c.diffuseAlbedo;
  v.f0 = c.f0;
  v.f90 = c.f90;
  v.roughness = c.roughness;
  v.anisotropy = c.anisotropy;
  v.sssMfp = c.sssMfp;
  v.sssPhaseAnisotropy = c.sssPhaseAnisotropy;
  v.sssType = c.sssType;
  v.secondRoughness = c.secondRoughness;
  v.secondRoughnessWeight = c.secondRoughnessWeight;
  v.fuzzAmount = c.fuzzAmount;
  v.fuzzColor = c.fuzzColor;
  v.fuzzRoughness = c.fuzzRoughness;
  v.glintValue = c.glintValue;
  v.glintUv = c.glintUv;
  v.glintUvDerivatives = c.glintUvDerivatives;
  v.specularProfile = c.specularProfile;
  v.weight = c.weight;
  v.topTransmittance = c.topTransmittance;
  v.coverageAbove = c.coverageAbove;
  return v;
}

reference::Closure<double> closureOf(const ClosureValues& v, const BasisValues& b) {
  reference::Closure<double> c;
  c.diffuseAlbedo = v.diffuseAlbedo;
  c.f0 = v.f0;
  c.f90 = v.f90;
  c.roughness = v.roughness;
  c.anisotropy = v.anisotropy;
  c.N = b.normal;
  c.T_ = b.tangent;
  c.sssMfp = v.sssMfp;
  c.sssPhaseAnisotropy = v.sssPhaseAnisotropy;
  c.sssType = v.sssType;
  c.secondRoughness = v.secondRoughness;
  c.secondRoughnessWeight = v.secondRoughnessWeight;
  c.fuzzAmount = v.fuzzAmount;
  c.fuzzColor = v.fuzzColor;
  c.fuzzRoughness = v.fuzzRoughness;
  c.glintValue = v.glintValue;
  c.glintUv = v.glintUv;
  c.glintUvDerivatives = v.glintUvDerivatives;
  c.specularProfile = v.specularProfile;
  c.weight = v.weight;
  c.topTransmittance = v.topTransmittance;
  c.coverageAbove = v.coverageAbove;
  c.features = v.features;
  c.isTop = v.isTop;
  return c;
}

/// Packs the closures the reference evaluates for `r` at pixel (x, y) the
/// way the base pass does (the SIMPLE layout when `plain` and one closure is
/// left), and reads them back as the deferred pass does.
Pixel packPixel(const CompileResult& r, const reference::InputValues& inputs, const Frame& f, uint32_t x, uint32_t y,
                double u, bool plain) {
  Pixel p;
  reference::Geometry g;
  g.V = viewAt(f, x, y);
  // A normal toward the eye, tilted by the pixel; a tangent orthogonal to it.
  std::array<double, 3> n{g.V[0] + 0.3 * std::sin(x * 1.7), g.V[1] + 0.3 * std::cos(y * 2.3), g.V[2]};
  const double ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& c : n) c /= ln;
  g.N = n;
  std::array<double, 3> t{n[2], 0, -n[0]};
  const double lt = std::sqrt(t[0] * t[0] + t[2] * t[2]);
  g.T = {t[0] / lt, 0, t[2] / lt};
  g.uv0 = g.uv1 = {u, 0.3 + 0.05 * y};
  g.uvDerivatives = {1e-3, 0, 0, 1e-3};
  g.dither = std::fmod(0.37 + 0.618033988749895 * (x * 31 + y * 17), 1.0);
  p.sample.geometry = g;
  p.sample.light = f.light;
  p.sample.radiance = f.radiance;
  p.sample.prefiltered = f.prefiltered;
  p.sample.irradiance = f.irradiance;
  const auto ref = reference::evaluateMaterial<double>(r, g, inputs, sampleTexture);
  const StorageLayout& L = r.after;
  const std::vector<int> left = visible(ref.closures);
  StorageLayout layout = L;
  std::vector<ClosureValues> values;
  std::vector<BasisValues> bases;
  if (plain) {
    EXPECT_EQ(left.size(), 1u);
    layout = simpleLayoutOf(L, left.at(0));
    values.push_back(valuesOf(ref.closures[left[0]]));
    bases.push_back({ref.closures[left[0]].N, ref.closures[left[0]].T_});
  } else {
    for (const auto& c : ref.closures) values.push_back(valuesOf(c));
    for (int b = 0; b < L.basisCount; ++b) {
      BasisValues bv;
      bool found = false;
      for (std::size_t i = 0; i < L.closures.size(); ++i)
        if (L.closures[i].basis == b && (!found || (L.closures[i].storedFeatures & kFeatAnisotropy))) {
          bv = {ref.closures[i].N, ref.closures[i].T_};
          found = true;
        }
      bases.push_back(bv);
    }
  }
  p.cls = layout.layoutClass;
  p.words = packMaterial(layout, values, bases, g.dither);
  // The top-layer word holds basis 0's normal when it is elided (any normal otherwise).
  const bool elided = layout.closures.size() == 1 || layout.basis0NormalElided;
  p.topLayer = packTopLayer({elided ? bases[0].normal : ref.closures[0].N, values[0].roughness}, g.dither);
  const UnpackedMaterial back = unpackMaterial(p.words.data(), p.words.size(), p.topLayer);
  for (const ClosureValues& c : back.closures) p.closures.push_back(closureOf(c, back.bases.at(c.basis)));
  return p;
}

gpu::BufferResource frameBlock(const Frame& f) {
  std::vector<float> v;
  auto push = [&](const std::array<double, 3>& a, double w) {
    for (double c : a) v.push_back(static_cast<float>(c));
    v.push_back(static_cast<float>(w));
  };
  push(f.forward, f.tanHalfFov);
  push(f.right, 0);
  push(f.up, 0);
  push(f.light, 0);
  push(f.radiance, 0);
  push({1, 0, 0}, 0);  // envParams: one mip
  gpu::BufferResource b;
  b.data.resize(v.size() * 4 + 16);
  std::memcpy(b.data.data(), v.data(), v.size() * 4);
  const uint32_t viewport[4] = {kWidth, kHeight, kTiles, 0};
  std::memcpy(b.data.data() + v.size() * 4, viewport, 16);
  return b;
}

gpu::ImageResource constantCube(const std::array<double, 3>& c) {
  gpu::ImageResource img;
  img.width = img.height = 2;
  img.layers = 6;
  std::vector<float> texels;
  for (int i = 0; i < 2 * 2 * 6; ++i)
    for (double x : {c[0], c[1], c[2], 1.0}) texels.push_back(static_cast<float>(x));
  img.mips = {texels};
  return img;
}

std::vector<std::byte> bytesOf(const std::vector<uint32_t>& w) {
  std::vector<std::byte> b(w.size() * 4);
  std::memcpy(b.data(), w.data(), b.size());
  return b;
}

TEST_F(SceneOnGpu, TilesAreClassifiedAndEachClassLightsItsPixelsAsTheReference) {
  // The street scene's materials, as `substratec scene` builds them.
  const char* names[] = {"plaster", "painted_metal", "wet_asphalt", "dusty_plastic"};
  std::map<std::string, CompileResult> m;
  std::vector<SceneMaterialShape> shapes;
  for (const char* n : names) {
    m[n] = compileSceneMaterial(n);
    shapes.push_back(summarize(m[n]).shape());
  }
  const SceneShape shape = sceneShape("street", shapes, kDiffuseModel);
  ASSERT_EQ(shape.classes.size(), 3u);  // simple, single, complex
  const Frame frame;
  const auto dustyClean = inputsWith(m["dusty_plastic"].material, {{"dust", 0.0}, {"haze", 0.0}});
  const auto dusty = inputsWith(m["dusty_plastic"].material, {});
  const auto wet = inputsWith(m["wet_asphalt"].material, {{"wetness", 0.5}});
  // What each tile holds (tx, ty): its expected class follows its most complex pixel.
  std::vector<Pixel> pixels(kWidth * kHeight);
  std::map<uint32_t, LayoutClass> expected;
  for (uint32_t y = 0; y < kHeight; ++y)
    for (uint32_t x = 0; x < kWidth; ++x) {
      const uint32_t tx = x / 8, ty = y / 8;
      const bool odd = (x + y) % 2;
      Pixel& p = pixels[y * kWidth + x];
      auto plaster = [&] { return packPixel(m["plaster"], inputsWith(m["plaster"].material, {}), frame, x, y, 0.2, false); };
      // Puddle mask (the texture's red channel is u): u > 0.5 in a puddle, two closures left there.
      auto asphalt = [&](bool puddle) { return packPixel(m["wet_asphalt"], wet, frame, x, y, puddle ? 0.8 : 0.2, !puddle); };
      if (ty == 0 && tx == 0) p = plaster();
      else if (ty == 0 && tx == 1) p = odd ? plaster() : packPixel(m["painted_metal"], inputsWith(m["painted_metal"].material, {}), frame, x, y, 0.5, false);
      else if (ty == 0) p = odd ? packPixel(m["dusty_plastic"], dusty, frame, x, y, 0.5, false) : plaster();
      else if (tx == 0) p = odd ? asphalt(true) : packPixel(m["dusty_plastic"], dustyClean, frame, x, y, 0.5, true);
      else if (tx == 1) p = odd ? asphalt(false) : packPixel(m["dusty_plastic"], dustyClean, frame, x, y, 0.5, true);
      else p = odd ? asphalt(false) : packPixel(m["dusty_plastic"], dusty, frame, x, y, 0.5, false);
      const uint32_t tile = ty * kTilesX + tx;
      if (!expected.count(tile) || static_cast<int>(p.cls) > static_cast<int>(expected[tile])) expected[tile] = p.cls;
    }
  EXPECT_EQ(expected[0], LayoutClass::Simple);
  EXPECT_EQ(expected[1], LayoutClass::Simple);
  EXPECT_EQ(expected[2], LayoutClass::Single);
  EXPECT_EQ(expected[3], LayoutClass::Complex);
  EXPECT_EQ(expected[4], LayoutClass::Simple);  // wet_asphalt outside the puddles and clean plastic: stored SIMPLE
  EXPECT_EQ(expected[5], LayoutClass::Single);

  // The G-buffer (words 0-2 and the top-layer word) and the material buffer (words 3..).
  const int slices = materialBufferSlices(shape);
  ASSERT_GT(slices, 0);
  std::vector<uint32_t> gbuffer(kWidth * kHeight * 4, 0u), materialBuffer(kWidth * kHeight * slices, 0u);
  for (uint32_t i = 0; i < kWidth * kHeight; ++i) {
    const Pixel& p = pixels[i];
    for (std::size_t w = 0; w < p.words.size(); ++w) {
      if (w < 3) gbuffer[w * kWidth * kHeight + i] = p.words[w];
      else materialBuffer[(w - 3) * kWidth * kHeight + i] = p.words[w];
    }
    gbuffer[3 * kWidth * kHeight + i] = p.topLayer;
  }
  auto storageImage = [&](const std::vector<uint32_t>& data, uint32_t layers) {
    gpu::StorageImageResource img;
    img.width = kWidth;
    img.height = kHeight;
    img.layers = layers;
    img.format = gpu::StorageFormat::R32Uint;
    img.data = bytesOf(data);
    img.upload = true;
    return img;
  };

  for (Target target : {Target::Glsl, Target::Hlsl}) {
    SCOPED_TRACE(target == Target::Glsl ? "GLSL" : "HLSL");
    const Syntax& syn = syntaxFor(target);
    auto compile = [&](const std::string& name, const std::string& text) {
      ShaderSource src;
      src.name = name;
      src.text = text;
      src.language = target == Target::Glsl ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
      src.stage = ShaderStage::Compute;
      for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
      ShaderValidation v = compileAndValidate(src);
      EXPECT_TRUE(v.ok) << name << "\n" << v.log;
      std::string error;
      auto p = v.ok ? ctx_->createPipeline(v.spirv, &error) : nullptr;
      EXPECT_TRUE(p) << error;
      return p;
    };
    // 1. Classification.
    auto classify = compile(tileClassificationFileName(shape, syn), emitTileClassification(shape, syn));
    ASSERT_TRUE(classify);
    gpu::Resources res;
    res[{0, 0}] = frameBlock(frame);
    res[{0, 6}] = storageImage(gbuffer, 4);
    gpu::BufferResource tiles;
    tiles.data.resize(4 * kTiles * 4);
    tiles.output = true;
    res[{0, 7}] = tiles;
    gpu::BufferResource args;
    std::vector<uint32_t> init;
    for (int c = 0; c < 4; ++c) init.insert(init.end(), {0u, 1u, 1u, 0u});
    args.data = bytesOf(init);
    args.output = args.initialized = true;
    res[{0, 9}] = args;
    std::string error;
    ASSERT_TRUE(ctx_->dispatch(*classify, res, kTilesX, kTilesY, 1, &error)) << error;
    std::vector<uint32_t> argWords(16), listWords(4 * kTiles);
    std::memcpy(argWords.data(), std::get<gpu::BufferResource>(res[{0, 9}]).data.data(), 64);
    std::memcpy(listWords.data(), std::get<gpu::BufferResource>(res[{0, 7}]).data.data(), listWords.size() * 4);
    std::map<int, std::set<uint32_t>> listed;
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(argWords[c * 4 + 1], 1u);
      EXPECT_EQ(argWords[c * 4 + 2], 1u);
      ASSERT_LE(argWords[c * 4], kTiles);
      for (uint32_t t = 0; t < argWords[c * 4]; ++t) {
        const uint32_t word = listWords[c * kTiles + t];
        listed[c].insert((word >> 16) * kTilesX + (word & 0xffffu));
      }
    }
    for (const auto& [tile, cls] : expected)
      EXPECT_TRUE(listed[static_cast<int>(cls)].count(tile)) << "tile " << tile << " not listed as " << layoutClassName(cls);
    EXPECT_EQ(listed[0].size() + listed[1].size() + listed[2].size() + listed[3].size(), kTiles) << "each tile once";

    // 2. Each class's lighting over its tiles.
    std::vector<float> color(kWidth * kHeight * 4, NAN);
    for (const SceneLightingClass& k : shape.classes) {
      const int c = static_cast<int>(k.cls);
      if (argWords[c * 4] == 0) continue;
      auto light = compile(sceneLightingFileName(shape, k.cls, syn), emitSceneLighting(shape, k, syn));
      ASSERT_TRUE(light);
      gpu::Resources lr;
      for (const gpu::DescriptorBinding& b : light->reflection().bindings) {
        const auto key = std::make_pair(b.set, b.binding);
        switch (b.binding) {
          case 0: lr[key] = frameBlock(frame); break;
          case 1: lr[key] = constantCube(frame.prefiltered); break;
          case 2: lr[key] = constantCube(frame.irradiance); break;
          case 3: lr[key] = gpu::SamplerResource{}; break;
          case 4: lr[key] = storageImage(materialBuffer, static_cast<uint32_t>(slices)); break;
          case 5: {
            auto lut = energyLutTables();
            gpu::BufferResource buf;
            buf.data.resize(lut.size_bytes());
            std::memcpy(buf.data.data(), lut.data(), lut.size_bytes());
            lr[key] = buf;
            break;
          }
          case 6: lr[key] = storageImage(gbuffer, 4); break;
          case 7: lr[key] = gpu::BufferResource{bytesOf(listWords), false}; break;
          case 8: {
            gpu::StorageImageResource out;
            out.width = kWidth;
            out.height = kHeight;
            lr[key] = out;
            break;
          }
          default: FAIL() << "unexpected binding " << b.binding;
        }
      }
      ASSERT_TRUE(ctx_->dispatch(*light, lr, argWords[c * 4], 1, 1, &error)) << error;
      const auto& out = std::get<gpu::StorageImageResource>(lr[{0, 8}]).data;
      std::vector<float> lit(kWidth * kHeight * 4);
      std::memcpy(lit.data(), out.data(), lit.size() * 4);
      for (uint32_t tile : listed[c])
        for (uint32_t y = (tile / kTilesX) * 8; y < std::min(kHeight, (tile / kTilesX) * 8 + 8); ++y)
          for (uint32_t x = (tile % kTilesX) * 8; x < std::min(kWidth, (tile % kTilesX) * 8 + 8); ++x)
            for (int ch = 0; ch < 4; ++ch) color[(y * kWidth + x) * 4 + ch] = lit[(y * kWidth + x) * 4 + ch];
    }
    // 3. Every pixel lit once, as the reference lights what the unpacker reads.
    const Tolerance tol;
    long failures = 0;
    double margin = 0;
    std::string first;
    for (uint32_t i = 0; i < kWidth * kHeight; ++i) {
      const Pixel& p = pixels[i];
      const auto r64 = lightClosures<double>(p.closures, p.sample, kDiffuseModel);
      const auto r32 = lightClosures<float>(p.closures, p.sample, kDiffuseModel);
      for (int ch = 0; ch < 3; ++ch) {
        const double want = r64.direct[ch] + r64.environment[ch];
        const double cond = double(r32.direct[ch]) + r32.environment[ch];
        const double allowed = tol.k * std::abs(cond - want) + tol.abs + tol.rel * std::abs(want);
        const float got = color[i * 4 + ch];
        margin = std::max(margin, std::abs(got - want) / allowed);
        if (!tol.ok(got, want, cond) && failures++ == 0)
          first = fmt::format("pixel ({}, {}) class {} channel {}: {} want {}", i % kWidth, i / kWidth,
                              layoutClassName(p.cls), ch, got, want);
      }
      EXPECT_EQ(color[i * 4 + 3], 1.0f);
    }
    std::printf("[ scene    ] %s: %u pixels in %u tiles (%zu simple, %zu single, %zu complex); largest |gpu - ref| / "
                "allowed = %.3f\n",
                target == Target::Glsl ? "GLSL" : "HLSL", kWidth * kHeight, kTiles, listed[0].size(), listed[1].size(),
                listed[2].size(), margin);
    EXPECT_EQ(failures, 0) << first;
  }
}

}  // namespace
}  // namespace substratec::gputest
