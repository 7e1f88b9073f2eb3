// Issue 20, part 5: the MaterialX corpus (tests/import/corpus/materialx, the
// documents MaterialX ships) drawn by `render` on a ball, deferred and
// forward, as its users preview them on MaterialX's shader ball.
//
// The ball is MaterialX's shader ball (../shared/corpus/assets/materialx/
// Geometry/shaderball.glb) when the shared corpus sits next to the
// repository, else the generated sphere-over-ground scene of render_scene.h
// (a clean clone has no ../shared): the test says which it drew on. The
// texture images of the corpus (brick, wood: several MB of JPEG) are only in
// ../shared, so the test that needs them says so and skips without them; the
// rest runs everywhere. SUBSTRATEC_TEST_STAND_IN=1 draws on the stand-in
// even where the shader ball is (to see what a clean clone's CI sees).
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../import/corpus.h"
#include "cli/cli.h"
#include "image/decode.h"
#include "import/import.h"
#include "material_fixture.h"
#include "mesh/gltf_mesh.h"
#include "pipeline/pipeline.h"
#include "preview/textures.h"
#include "render/render.h"
#include "png_files.h"
#include "render_scene.h"

namespace substratec::gputest {
namespace {

namespace fs = std::filesystem;

const fs::path kMaterialXAssets = fs::path(SUBSTRATEC_SOURCE_DIR) / "../shared/corpus/assets/materialx";
const fs::path kMaterialXCorpus = fs::path(SUBSTRATEC_SOURCE_DIR) / "tests/import/corpus/materialx";

/// A scratch folder for this process's files, removed at exit.
const fs::path& corpusWorkDir() {
  static struct Dir {
    fs::path path = fs::temp_directory_path() / ("substratec_render_corpus_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

/// What the corpus is drawn on, loaded once.
struct Ball {
  fs::path path;
  std::string what;
  mesh::Scene scene;
  mesh::Camera camera;
};

const Ball& ball() {
  static const Ball b = [] {
    Ball out;
    const fs::path real = kMaterialXAssets / "Geometry/shaderball.glb";
    if (fs::exists(real) && !std::getenv("SUBSTRATEC_TEST_STAND_IN")) {
      out.path = real;
      out.what = "MaterialX's shader ball";
    } else {
      out.path = corpusWorkDir() / "stand_in_ball.gltf";
      std::ofstream(out.path) << sceneGltf();
      out.what = "the generated sphere-over-ground stand-in (no ../shared/corpus)";
    }
    Diagnostics diags("ball");
    auto s = mesh::loadGltfScene(out.path.string(), mesh::MeshLimits{}, diags);
    EXPECT_TRUE(s.has_value()) << diags.formatAll();
    if (s) out.scene = std::move(*s);
    out.camera = mesh::framingCamera(out.scene, 1.0);
    return out;
  }();
  return b;
}

/// A MaterialX corpus material the importer accepts, with where its images are relative to.
struct CorpusMaterial {
  std::string label;  // "materialx/…/file.mtlx [name]"
  std::string text;
  std::string baseDir;
};

std::vector<CorpusMaterial> materialXCorpus() {
  std::vector<CorpusMaterial> out;
  for (const auto& f : importtest::corpusFiles()) {
    if (f.display.rfind("materialx/", 0) != 0 || importtest::corpusExceptions().count(f.display)) continue;
    const importtest::CorpusImport r = importtest::importCorpusFile(f);
    EXPECT_TRUE(r.ok) << f.display << "\n" << r.diagnostics;
    for (const auto& m : r.materials)
      out.push_back({f.display + " [" + m.name + "]", m.text, f.path.parent_path().string()});
  }
  return out;
}

render::RenderOptions ballOptions(bool forward, const std::string& environment = "studio", int size = 64) {
  render::RenderOptions o;
  o.width = o.height = size;
  o.forward = forward;
  o.environment = environment;
  return o;
}

/// Draws every primitive of the ball with `r` and its `textures` (null: every texture at its neutral texel).
render::RenderResult drawOnBall(gpu::Context& ctx, const CompileResult& r, const preview::BoundTextures* textures,
                                const render::RenderOptions& o) {
  const Ball& b = ball();
  const std::vector<render::SceneMaterial> materials = {{&r, textures}};
  const std::vector<int> which(b.scene.primitives.size(), 0);
  render::RenderResult out;
  Diagnostics diags("ball");
  EXPECT_TRUE(render::renderScene(ctx, b.scene, materials, which, b.camera, o, &out, diags)) << diags.formatAll();
  return out;
}

class RenderCorpus : public ::testing::Test {
 protected:
  void SetUp() override {
    Diagnostics diags("test");
    ctx_ = sharedContext(diags);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
    ASSERT_FALSE(ball().scene.primitives.empty());
  }
  gpu::Context* ctx_ = nullptr;
};

/// How far a deferred render is from the forward one over the pixels both cover.
struct Agreement {
  std::size_t pixels = 0, nonFinite = 0, blackButLit = 0;
  double p99 = 0, max = 0, meanOff = 0;
};

Agreement compare(const render::RenderResult& deferred, const render::RenderResult& forward) {
  Agreement a;
  std::vector<double> d;
  double sum[3] = {0, 0, 0}, ref[3] = {0, 0, 0};
  for (std::size_t i = 0; i < deferred.depth.size(); ++i) {
    const float* p = &deferred.hdr.rgba[i * 4];
    const float* q = &forward.hdr.rgba[i * 4];
    for (int c = 0; c < 4; ++c) a.nonFinite += !std::isfinite(p[c]) + !std::isfinite(q[c]);
    if (!(deferred.depth[i] < 1.0f)) continue;
    double num = 0, den = 0;
    for (int c = 0; c < 3; ++c) {
      num = std::max(num, std::abs(double(p[c]) - q[c]));
      den = std::max(den, std::abs(double(q[c])));
      sum[c] += p[c];
      ref[c] += q[c];
    }
    // "Left black": nothing at all where the material, evaluated directly, reflects something.
    a.blackButLit += (p[0] == 0 && p[1] == 0 && p[2] == 0 && den > 1e-3);
    d.push_back(num / std::max(den, 0.05));
  }
  a.pixels = d.size();
  if (d.empty()) return a;
  std::sort(d.begin(), d.end());
  a.p99 = d[d.size() * 99 / 100];
  a.max = d.back();
  for (int c = 0; c < 3; ++c)
    if (ref[c] > 1e-6 * a.pixels) a.meanOff = std::max(a.meanOff, std::abs(sum[c] / ref[c] - 1));
  return a;
}

/// The corpus materials whose deferred render is further from the forward
/// one than the bounds below, with the bound they break and what was
/// measured (2026-12-06, on MaterialX's shader ball; docs/render.md).
const std::map<std::string, std::string>& agreementExceptions() {
  static const std::map<std::string, std::string> list = {
      // Anisotropic: max 0.70 at a few pixels (p99 0.14); not investigated.
      {"materialx/OpenPbr/open_pbr_aluminum_brushed.mtlx [Aluminum_Brushed]", "max"},
      // A coat over a coloured base: 4.3 % darker deferred. Minimal coats show
      // the same sign (a clear coat over grey diffuse: -1.3 % under the key
      // light, -0.25 % under the white furnace); not understood.
      {"materialx/OpenPbr/open_pbr_carpaint.mtlx [Car_Paint]", "mean"},
  };
  return list;
}

// Every material of the MaterialX corpus, small on the ball, deferred and
// forward: no NaN or Inf anywhere, no covered pixel left black where the
// forward pass (the material evaluated directly) is not, and the two paths
// within the storage layout's quantization: per pixel, the relative
// difference of the channel that differs most, |deferred - forward| /
// max(forward, 0.05), has a p99 within 0.15 and a max within 0.25 (colours
// are stored as 7/7/6 bits of their square root, dithered: a dark channel of
// 0.04 is off by up to 8 % a step, 16 % in the 6-bit blue), and the image
// means agree within 2.5 %. (The examples on the test scene stay within 0.10
// and 0.20, RenderEveryExample; the shader ball shows more grazing angles.)
// The documented exceptions break exactly their bound, so a fix shows as a
// stale entry. Textures at their neutral texels (the images are in ../shared
// only; the next test binds them).
TEST_F(RenderCorpus, EveryMaterialXMaterialOnTheBallDeferredMatchesForward) {
  std::printf("[ corpus   ] drawn on %s\n", ball().what.c_str());
  std::size_t rendered = 0, compared = 0, within10 = 0;
  double worstP99 = 0, worstMean = 0;
  for (const CorpusMaterial& m : materialXCorpus()) {
    SCOPED_TRACE(m.label);
    Diagnostics diags(m.label);
    auto r = compileText(m.label, m.text, CompileOptions{}, diags);
    ASSERT_TRUE(r.has_value()) << diags.formatAll();
    const render::RenderResult deferred = drawOnBall(*ctx_, *r, nullptr, ballOptions(false));
    const render::RenderResult forward = drawOnBall(*ctx_, *r, nullptr, ballOptions(true));
    ASSERT_EQ(deferred.depth, forward.depth) << "the same geometry, the same depth";
    const Agreement a = compare(deferred, forward);
    std::printf("[ corpus   ] %-62s %4zu px: p99 %.4f, max %.4f, mean off by %.4f\n", m.label.c_str(), a.pixels,
                a.p99, a.max, a.meanOff);
    EXPECT_EQ(a.nonFinite, 0u);
    EXPECT_EQ(a.blackButLit, 0u);
    ++rendered;
    if (deferred.stats.coveredPixels == 0) {  // translucent: drawn forward on both paths
      EXPECT_EQ(deferred.hdr.rgba, forward.hdr.rgba);
      continue;
    }
    ASSERT_GT(a.pixels, 400u) << "the ball covers a good part of the image";
    ++compared;
    within10 += a.p99 <= 0.10 && a.max <= 0.20;
    const auto exception = agreementExceptions().find(m.label);
    const std::string broken = exception == agreementExceptions().end() ? "" : exception->second;
    if (broken != "max") worstP99 = std::max(worstP99, a.p99);
    if (broken != "mean") worstMean = std::max(worstMean, a.meanOff);
    EXPECT_EQ(a.p99 > 0.15, broken == "p99") << "p99 " << a.p99;
    EXPECT_EQ(a.max > 0.25, broken == "max") << "max " << a.max;
    EXPECT_EQ(a.meanOff > 0.025, broken == "mean") << "mean off by " << a.meanOff;
  }
  std::printf("[ corpus   ] %zu rendered, %zu compared (the rest translucent: the same image), %zu within the "
              "examples' bounds (p99 0.10, max 0.20); worst p99 %.4f, worst mean %.4f outside the exceptions\n",
              rendered, compared, within10, worstP99, worstMean);
  EXPECT_GE(rendered, 60u) << "the corpus's MaterialX materials, less the documented exceptions";
}

// ---- real textures -------------------------------------------------------------


/// The mean linear colour of the covered pixels.
std::array<double, 3> meanColour(const render::RenderResult& r) {
  std::array<double, 3> mean{};
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.depth.size(); ++i) {
    if (!(r.depth[i] < 1.0f)) continue;
    for (int c = 0; c < 3; ++c) mean[c] += r.hdr.rgba[i * 4 + c];
    ++n;
  }
  for (double& m : mean) m /= std::max<std::size_t>(n, 1);
  return mean;
}

/// How far two renders of the same geometry are apart pixel by pixel: the
/// mean over covered pixels of the summed |difference| of the channels, over
/// the summed mean of `b`.
double patternDifference(const render::RenderResult& a, const render::RenderResult& b) {
  double diff = 0, ref = 0;
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    if (!(a.depth[i] < 1.0f)) continue;
    for (int c = 0; c < 3; ++c) {
      diff += std::abs(double(a.hdr.rgba[i * 4 + c]) - b.hdr.rgba[i * 4 + c]);
      ref += b.hdr.rgba[i * 4 + c];
    }
  }
  return diff / std::max(ref, 1e-9);
}

// The textured corpus materials show their own images. Each is drawn twice
// under the white furnace: with its images (found along the search path, as
// MaterialX's tools find them), and with each image replaced by a solid image
// of that image's mean colour, decoded on the CPU (image::load, colour-decoded
// by the input's colour space, averaged in linear values). Small (64 px: the
// mip chain averages the images before the material's nonlinear steps, brick's
// masks) the shading is nearly linear in the texels, so the two pictures' mean
// colours agree (within 8 % a channel), while the images' own pattern sets the
// two pictures apart pixel by pixel (by 3 % of the mean at least; measured 5.8 and 6.4 %). Neutral
// texels in place of the images (what a texture without an image gets) do not
// pass for them.
TEST_F(RenderCorpus, TheTexturedMaterialsShowTheirImagesAgainstTheirDecodedMeanColour) {
  if (!fs::exists(kMaterialXAssets / "Images/wood_color.jpg"))
    GTEST_SKIP() << "the corpus images are in ../shared/corpus/assets/materialx only";
  if (ball().path.extension() != ".glb")  // the bounds below were measured on the shader ball's 914 pixels
    GTEST_SKIP() << "drawn on the stand-in (SUBSTRATEC_TEST_STAND_IN), where the images are minified to 0.7 % of pattern";
  std::size_t checked = 0;
  for (const char* doc : {"StandardSurface/standard_surface_wood_tiled.mtlx",
                          "StandardSurface/standard_surface_brick_procedural.mtlx"}) {
    SCOPED_TRACE(doc);
    const fs::path path = kMaterialXCorpus / doc;
    Diagnostics diags(doc);
    auto sources = import::loadMaterialSources(path.string(), "", false, ReadLimits{}, diags);
    ASSERT_TRUE(sources.has_value()) << diags.formatAll();
    const import::MaterialSource& src = sources->front();
    auto r = compileText(src.displayName, src.text, CompileOptions{}, diags);
    ASSERT_TRUE(r.has_value()) << diags.formatAll();
    preview::TextureSources real;
    real.baseDir = src.baseDir;
    real.searchPaths = {kMaterialXAssets.string()};
    real.imported = true;
    preview::BoundTextures images, means, neutral;
    ASSERT_TRUE(preview::bindTextures(r->material, real, &images, diags)) << diags.formatAll();
    preview::TextureSources solid = real;
    std::size_t textures = 0;
    for (const Input& in : r->material.inputs) {
      if (in.type != VType::Texture || in.file.empty()) continue;
      image::Rgba8 img;
      std::string why;
      ASSERT_TRUE(image::load(preview::resolveImagePath(in.file, real), &img, &why)) << why;
      const image::MipChain chain = image::mipChain(img, in.srgb);
      std::array<double, 3> mean{};
      const std::vector<float>& top = chain.levels.front();
      for (std::size_t i = 0; i < top.size(); i += 4)
        for (int c = 0; c < 3; ++c) mean[c] += top[i + c] / (top.size() / 4);
      std::array<int, 3> code{};
      for (int c = 0; c < 3; ++c) {  // the 8-bit code that decodes nearest to the mean
        int best = 0;
        for (int k = 0; k < 256; ++k) {
          const double v = in.srgb ? image::srgbToLinear(k / 255.0) : k / 255.0;
          const double b = in.srgb ? image::srgbToLinear(best / 255.0) : best / 255.0;
          if (std::abs(v - mean[c]) < std::abs(b - mean[c])) best = k;
        }
        code[c] = best;
      }
      const fs::path png = corpusWorkDir() / (in.name + "_mean.png");
      testutil::solidPng(png, static_cast<unsigned char>(code[0]), static_cast<unsigned char>(code[1]),
                         static_cast<unsigned char>(code[2]));
      solid.overrides[in.name] = png.string();
      ++textures;
    }
    ASSERT_GE(textures, 2u) << "its images are bound from files";
    ASSERT_TRUE(preview::bindTextures(r->material, solid, &means, diags)) << diags.formatAll();
    Material imageless = r->material;  // what a texture without an image gets
    for (Input& in : imageless.inputs) in.file.clear();
    ASSERT_TRUE(preview::bindTextures(imageless, preview::TextureSources{}, &neutral, diags)) << diags.formatAll();
    const render::RenderResult withImages = drawOnBall(*ctx_, *r, &images, ballOptions(false, "white"));
    const render::RenderResult withMeans = drawOnBall(*ctx_, *r, &means, ballOptions(false, "white"));
    const std::array<double, 3> withReal = meanColour(withImages), flat = meanColour(withMeans),
                                none = meanColour(drawOnBall(*ctx_, *r, &neutral, ballOptions(false, "white")));
    const double pattern = patternDifference(withImages, withMeans);
    std::printf("[ textures ] %s: mean (%.3f, %.3f, %.3f) with its images, (%.3f, %.3f, %.3f) with their mean "
                "colours, (%.3f, %.3f, %.3f) with neutral texels; pixels %.1f %% apart from the mean colours' picture\n",
                doc, withReal[0], withReal[1], withReal[2], flat[0], flat[1], flat[2], none[0], none[1], none[2], 100 * pattern);
    double off = 0, neutralOff = 0;
    for (int c = 0; c < 3; ++c) {
      off = std::max(off, std::abs(withReal[c] / flat[c] - 1));
      neutralOff = std::max(neutralOff, std::abs(none[c] / flat[c] - 1));
    }
    EXPECT_LE(off, 0.08);
    EXPECT_GT(neutralOff, 0.08) << "the neutral texels would pass for the images";
    EXPECT_GE(pattern, 0.03) << "the images' own pattern shows";
    ++checked;
  }
  EXPECT_EQ(checked, 2u);
}

// A corpus document whose image is not found is an error that names the
// file and the MaterialX element, and `render` writes nothing (no
// ../shared needed: the document is in the repository, its images are not
// next to it).
TEST(RenderCorpusCli, AMissingImageIsALocatedErrorAndNothingIsWritten) {
  const fs::path png = corpusWorkDir() / "wood.png";
  std::ostringstream out, err;
  const int status = runCli({"render", ball().path.string(), "--material",
                             (kMaterialXCorpus / "StandardSurface/standard_surface_wood_tiled.mtlx").string(), "--size",
                             "32x32", "-o", png.string()},
                            out, err);
  EXPECT_EQ(status, 1) << err.str();
  EXPECT_NE(err.str().find("tiledimage 'image_color' in nodegraph 'NG_wood1'"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("cannot use the image \"../../../Images/wood_color.jpg\""), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("[/inputs/"), std::string::npos) << err.str();
  EXPECT_FALSE(fs::exists(png));
}

}  // namespace
}  // namespace substratec::gputest
