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
//  - The scene's lighting: a small G-buffer of the `street` scene's materials and an unlit sign
//    (packed by the CPU mirror of docs/storage.md, some pixels in the SIMPLE
//    layout as dynamic simplification stores them) goes through the emitted
//    tile classification, which must list every tile under the class of its
//    most complex pixel, then through each class's lighting shader over its
//    tiles, which must light each pixel as the CPU reference lights the
//    closures the CPU unpacker reads back, in GLSL and in HLSL. The same for
//    a SPECIAL tile of eyes and white fibres beside a SIMPLE one, every pixel
//    lit (a check of black against black would test nothing).
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
#include "pipeline/generate.h"
#include "emit/scene_emitter.h"
#include "gpu/gbuffer.h"
#include "material_fixture.h"
#include "storage/pack.h"
#include "validate/runtime_files.h"

namespace substratec::gputest {
namespace scene_gpu_test {

namespace fs = std::filesystem;
using namespace kernel;

constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// examples/scenes/materials/<stem>.json, or with `dir` "" examples/<stem>.json, compiled.
CompileResult compileSceneMaterial(const std::string& stem, const std::string& dir = "scenes/materials") {
  const fs::path path = fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / dir / (stem + ".json");
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
    Diagnostics diags("test");
    ctx_ = sharedContext(diags);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
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
    Diagnostics diags("test");
    k.pipeline = ctx_->createPipeline(v.spirv, diags);
    EXPECT_NE(k.pipeline, nullptr) << diags.errorMessages();
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
    Diagnostics diags("test");
    const bool ok = ctx_->dispatch(*k.pipeline, res, static_cast<uint32_t>(samples.size() / kLocalSize), 1, 1, diags);
    EXPECT_TRUE(ok) << diags.errorMessages();
    return ok ? floatsOf(res, 0, 7) : std::vector<float>{};
  }


  /// The emitted tile classification over `gbuffer` must list every tile once,
  /// under `expected`, its most complex pixel's class; each class's emitted
  /// lighting over its tiles must light every pixel as the CPU reference
  /// lights the closures of `pixels` (what the CPU unpacker reads back), in
  /// GLSL and in HLSL. Prints each language's largest error over its allowance
  /// and how many pixels the reference lights (some channel above 1e-6);
  /// `litByReference`, when given, gets per pixel whether the reference lit it.
  void classifyAndLight(const SceneShape& shape, const gpu::SceneFrame& frame, const gpu::Gbuffer& gbuffer,
                        const std::vector<gpu::GbufferPixel>& pixels, const std::vector<gpu::Sample>& samples,
                        const std::map<uint32_t, LayoutClass>& expected, std::vector<bool>* lit = nullptr) {
    const uint32_t W = frame.width, H = frame.height;
    std::vector<bool> litByReference(W * H, false);
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
        Diagnostics diags("test");
        auto p = v.ok ? ctx_->createPipeline(v.spirv, diags) : nullptr;
        EXPECT_TRUE(p) << diags.errorMessages();
        return p;
      };
      // 1. Classification: every tile listed once, under the class of its most complex pixel.
      auto classify = compile(tileClassificationFileName(shape, syn), emitTileClassification(shape, syn));
      ASSERT_TRUE(classify);
      gpu::TileLists lists;
      Diagnostics diags("test");
      ASSERT_TRUE(gpu::classifyTiles(*ctx_, *classify, frame, gbuffer, &lists, diags)) << diags.errorMessages();
      std::size_t listed = 0;
      for (const auto& [tile, cls] : expected) {
        const auto& l = lists.tiles[static_cast<int>(cls)];
        EXPECT_EQ(std::count(l.begin(), l.end(), tile), 1) << "tile " << tile << " as " << layoutClassName(cls);
      }
      for (const auto& l : lists.tiles) listed += l.size();
      EXPECT_EQ(listed, frame.tiles()) << "each tile once";

      // 2. Each class's lighting over its tiles.
      std::vector<float> color(W * H * 4, NAN);
      for (const SceneLightingClass& k : shape.classes) {
        const auto& tiles = lists.tiles[static_cast<int>(k.cls)];
        if (tiles.empty()) continue;
        auto light = compile(sceneLightingFileName(shape, k.cls, syn), emitSceneLighting(shape, k, syn));
        ASSERT_TRUE(light);
        gpu::Resources res = gpu::lightingResources(*light, frame, gbuffer, lists);
        ASSERT_TRUE(ctx_->dispatch(*light, res, static_cast<uint32_t>(tiles.size()), 1, 1, diags))
            << diags.errorMessages();
        const auto& out = std::get<gpu::StorageImageResource>(res[{0, 8}]).data;
        std::vector<float> lit(W * H * 4);
        std::memcpy(lit.data(), out.data(), lit.size() * 4);
        for (uint32_t tile : tiles)
          for (uint32_t y = (tile / frame.tilesX()) * 8; y < std::min(H, (tile / frame.tilesX()) * 8 + 8); ++y)
            for (uint32_t x = (tile % frame.tilesX()) * 8; x < std::min(W, (tile % frame.tilesX()) * 8 + 8); ++x)
              for (int ch = 0; ch < 4; ++ch) color[(y * W + x) * 4 + ch] = lit[(y * W + x) * 4 + ch];
      }
      // 3. Every pixel lit once, as the reference lights what the unpacker reads.
      const Tolerance tol;
      long failures = 0;
      double margin = 0;
      std::string first;
      for (uint32_t i = 0; i < W * H; ++i) {
        const auto r64 = lightClosures<double>(pixels[i].closures, samples[i], kDiffuseModel);
        const auto r32 = lightClosures<float>(pixels[i].closures, samples[i], kDiffuseModel);
        for (int ch = 0; ch < 3; ++ch) {
          const double want = r64.direct[ch] + r64.environment[ch];
          if (want > 1e-6) litByReference[i] = true;
          const double cond = double(r32.direct[ch]) + r32.environment[ch];
          const double allowed = tol.k * std::abs(cond - want) + tol.abs + tol.rel * std::abs(want);
          const float got = color[i * 4 + ch];
          margin = std::max(margin, std::abs(got - want) / allowed);
          if (!tol.ok(got, want, cond) && failures++ == 0)
            first = fmt::format("pixel ({}, {}) class {} channel {}: {} want {}", i % W, i / W,
                                layoutClassName(pixels[i].cls), ch, got, want);
        }
        EXPECT_EQ(color[i * 4 + 3], 1.0f);
      }
      std::printf("[ scene    ] %s: %u pixels (%ld lit by the reference) in %u tiles (%zu simple, %zu single, "
                  "%zu complex, %zu special); largest |gpu - ref| / allowed = %.3f\n",
                  target == Target::Glsl ? "GLSL" : "HLSL", W * H,
                  static_cast<long>(std::count(litByReference.begin(), litByReference.end(), true)), frame.tiles(),
                  lists.tiles[0].size(), lists.tiles[1].size(), lists.tiles[2].size(), lists.tiles[3].size(), margin);
      EXPECT_EQ(failures, 0) << first;
    }
    if (lit) *lit = litByReference;
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
  // The static layout and the dynamic one, in GLSL (the scene test below runs both languages).
  std::map<std::string, std::array<Kernel, 2>> kernels;
  for (const DynamicCase& dc : cases) {
    SCOPED_TRACE(fmt::format("{} ({})", dc.material, dc.what));
    if (!compiled.count(dc.material)) {
      compiled[dc.material] = compileSceneMaterial(dc.material);
      const CompileResult& r = compiled[dc.material];
      kernels[dc.material] = {deferredKernel(r, Target::Glsl, false), deferredKernel(r, Target::Glsl, true)};
    }
    const CompileResult& r = compiled[dc.material];
    const StorageLayout& L = r.after;
    ASSERT_NE(L.layoutClass, LayoutClass::Simple);
    ASSERT_FALSE(runtimeSimpleClosures(r.material, L).empty());
    const reference::InputValues inputs = inputsWith(r.material, dc.inputs);
    const int stride = resultStride(r);
    const std::vector<float> off = run(r, kernels[dc.material][0], samples, inputs);
    ASSERT_FALSE(off.empty());
    {
      const std::vector<float> on = run(r, kernels[dc.material][1], samples, inputs);
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
        std::vector<ClosureValues> values;  // the CPU mirror of the pack function decides the same
        for (const auto& c : ref.closures) values.push_back(gpu::closureValues(c));
        if (runtimeSimpleClosure(r.material, L, values).has_value() != plain)
          fail(fmt::format("sample {}: the CPU mirror decides otherwise", i));
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
        const auto s = closureFromResults(on, stride, static_cast<int>(i), 0, r);
        const auto full = closureFromResults(off, stride, static_cast<int>(i), k, r);
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

TEST_F(SceneOnGpu, TilesAreClassifiedAndEachClassLightsItsPixelsAsTheReference) {
  // The street scene's materials, as `substratec scene` builds them, and an
  // unlit sign (examples/scenes/materials/neon_sign.json: no closure).
  const char* names[] = {"plaster", "painted_metal", "wet_asphalt", "dusty_plastic", "neon_sign"};
  std::map<std::string, CompileResult> m;
  std::vector<SceneMaterialShape> shapes;
  for (const char* n : names) {
    m[n] = compileSceneMaterial(n);
    shapes.push_back(summarize(m[n]).shape());
  }
  const SceneShape shape = sceneShape("street_and_sign", shapes, kDefaultDiffuseModel);
  ASSERT_EQ(shape.classes.size(), 3u);  // simple, single, complex
  gpu::SceneFrame frame;
  frame.width = 20;  // 3 x 2 tiles, the last column and row partial
  frame.height = 12;
  const uint32_t W = frame.width, H = frame.height;
  const auto dustyClean = inputsWith(m["dusty_plastic"].material, {{"dust", 0.0}, {"haze", 0.0}});
  const auto dusty = inputsWith(m["dusty_plastic"].material, {});
  const auto wet = inputsWith(m["wet_asphalt"].material, {{"wetness", 0.5}});
  // What each tile holds: its class is that of its most complex pixel. The
  // puddle mask is the texture's red channel, u: a puddle (two closures) at u 0.8.
  std::vector<gpu::GbufferPixel> pixels(W * H);
  std::vector<gpu::Sample> samples(W * H);
  std::map<uint32_t, LayoutClass> expected;
  gpu::Gbuffer gbuffer(W, H, materialBufferSlices(shape));
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      const uint32_t tx = x / 8, ty = y / 8;
      const bool odd = (x + y) % 2;
      auto at = [&](const char* material, const reference::InputValues& in, double u) {
        return gpu::packPixel(m[material], gpu::pixelGeometry(frame, x, y, {u, 0.3 + 0.05 * y}), in);
      };
      const auto plaster = inputsWith(m["plaster"].material, {});
      // Unlit pixels (no closure: lit 0) in a SIMPLE, a SINGLE and a COMPLEX
      // tile, so each unpacker meets the no-closure header.
      const bool neon = x % 4 == 1;
      const auto sign = inputsWith(m["neon_sign"].material, {});
      gpu::GbufferPixel& p = pixels[y * W + x];
      if (ty == 0 && tx == 0) p = neon ? at("neon_sign", sign, 0.5) : at("plaster", plaster, 0.2);
      else if (ty == 0 && tx == 1) p = odd ? at("plaster", plaster, 0.2) : at("painted_metal", inputsWith(m["painted_metal"].material, {}), 0.5);
      else if (ty == 0) p = odd ? at("dusty_plastic", dusty, 0.5) : neon ? at("neon_sign", sign, 0.5) : at("plaster", plaster, 0.2);
      else if (tx == 0) p = odd ? (neon ? at("neon_sign", sign, 0.5) : at("wet_asphalt", wet, 0.8)) : at("dusty_plastic", dustyClean, 0.5);
      else if (tx == 1) p = odd ? at("wet_asphalt", wet, 0.2) : at("dusty_plastic", dustyClean, 0.5);
      else p = odd ? at("wet_asphalt", wet, 0.2) : at("dusty_plastic", dusty, 0.5);
      gbuffer.set(x, y, p);
      gpu::Sample& s = samples[y * W + x];
      s.geometry = gpu::pixelGeometry(frame, x, y, {0, 0});
      s.light = frame.light;
      s.radiance = frame.radiance;
      s.prefiltered = frame.prefiltered;
      s.irradiance = frame.irradiance;
      const uint32_t tile = ty * frame.tilesX() + tx;
      if (!expected.count(tile) || static_cast<int>(p.cls) > static_cast<int>(expected[tile])) expected[tile] = p.cls;
    }
  EXPECT_EQ(expected[0], LayoutClass::Simple);
  EXPECT_EQ(expected[1], LayoutClass::Simple);
  EXPECT_EQ(expected[2], LayoutClass::Single);
  EXPECT_EQ(expected[3], LayoutClass::Complex);
  EXPECT_EQ(expected[4], LayoutClass::Simple);  // dry asphalt and clean plastic: stored SIMPLE dynamically
  EXPECT_EQ(expected[5], LayoutClass::Single);

  classifyAndLight(shape, frame, gbuffer, pixels, samples, expected);
}

TEST_F(SceneOnGpu, ASpecialTileLightsEyesAndHairAsTheReference) {
  // The SPECIAL class's lighting (SUBSTRATE_USE_EYE and SUBSTRATE_USE_HAIR 1)
  // over eye pixels (all iris, and the hazel eye's sclera, iris and pupil
  // wherever the frame's positions put them), white fibres and plaster; a
  // SIMPLE tile of plaster beside it.
  const std::map<std::string, CompileResult> m = {
      {"plaster", compileSceneMaterial("plaster")},
      {"eye_hazel", compileSceneMaterial("eye_hazel", "")},
      {"eye_iris_closeup", compileSceneMaterial("eye_iris_closeup", "")},
      {"hair_white_fibre", compileSceneMaterial("hair_white_fibre", "")},
  };
  std::vector<SceneMaterialShape> shapes;
  for (const auto& [name, r] : m) shapes.push_back(summarize(r).shape());
  const SceneShape shape = sceneShape("eyes_and_hair", shapes, kDefaultDiffuseModel);
  ASSERT_EQ(shape.classes.size(), 2u);  // simple, special
  gpu::SceneFrame frame;
  frame.width = 16;  // 2 x 1 tiles
  frame.height = 8;
  std::vector<gpu::GbufferPixel> pixels(frame.width * frame.height);
  std::vector<gpu::Sample> samples(pixels.size());
  std::map<uint32_t, LayoutClass> expected;
  gpu::Gbuffer gbuffer(frame.width, frame.height, materialBufferSlices(shape));
  const char* special[] = {"eye_hazel", "eye_iris_closeup", "hair_white_fibre", "plaster"};
  int counts[4] = {0, 0, 0, 0};
  for (uint32_t y = 0; y < frame.height; ++y)
    for (uint32_t x = 0; x < frame.width; ++x) {
      const int pick = x < 8 ? 3 : static_cast<int>((x + 3 * y) % 4);
      const CompileResult& r = m.at(special[pick]);
      ++counts[pick];
      gpu::GbufferPixel& p = pixels[y * frame.width + x];
      p = gpu::packPixel(r, gpu::pixelGeometry(frame, x, y, {0.5, 0.5}), inputsWith(r.material, {}));
      gbuffer.set(x, y, p);
      gpu::Sample& s = samples[y * frame.width + x];
      s.geometry = gpu::pixelGeometry(frame, x, y, {0, 0});
      s.light = frame.light;
      s.radiance = frame.radiance;
      s.prefiltered = frame.prefiltered;
      s.irradiance = frame.irradiance;
      const uint32_t tile = x / 8;
      if (!expected.count(tile) || static_cast<int>(p.cls) > static_cast<int>(expected[tile])) expected[tile] = p.cls;
    }
  EXPECT_EQ(expected[0], LayoutClass::Simple);
  EXPECT_EQ(expected[1], LayoutClass::Special);
  EXPECT_EQ(counts[0] + counts[1], 32) << "eye pixels";
  EXPECT_EQ(counts[2], 16) << "hair pixels";
  std::vector<bool> lit;
  classifyAndLight(shape, frame, gbuffer, pixels, samples, expected, &lit);
  ASSERT_EQ(lit.size(), pixels.size());
  // The special tile's pixels are lit (a check of black against black tests nothing).
  long litSpecial = 0;
  for (uint32_t y = 0; y < frame.height; ++y)
    for (uint32_t x = 8; x < frame.width; ++x) litSpecial += lit[y * frame.width + x] ? 1 : 0;
  EXPECT_EQ(litSpecial, 64);
}

}  // namespace scene_gpu_test
}  // namespace substratec::gputest
