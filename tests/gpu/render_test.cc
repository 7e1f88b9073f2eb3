// `substratec render` (issue 20): glTF meshes drawn on lavapipe with the
// emitted fragment shaders in raster passes — the deferred path (depth
// pre-pass, base passes into the G-buffer, the scene's tile classification
// and lighting) and the forward path — and the command around it.
//
// The scene is generated here: a UV sphere over a ground quad, written as a
// .gltf with its buffer in a data: URI (no tangents: the loader generates
// them), each primitive with its own material.
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "batch/batch.h"
#include "cli/cli.h"
#include "../examples.h"
#include "import/gltf_resources.h"
#include "material_fixture.h"
#include "mesh/gltf_mesh.h"
#include "pipeline/pipeline.h"
#include "render/camera.h"
#include "render/render.h"
#include "png_files.h"
#include "render_scene.h"

namespace substratec::gputest {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

std::string readBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A scratch folder for this process's files, removed at exit.
fs::path workDir() {
  static struct Dir {
    fs::path path = fs::temp_directory_path() / ("substratec_render_test_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

/// The test scene written once as a file.
const fs::path& scenePath() {
  static const fs::path path = [] {
    const fs::path p = workDir() / "sphere_scene.gltf";
    std::ofstream(p) << sceneGltf();
    return p;
  }();
  return path;
}

const mesh::Scene& testScene() {
  static const mesh::Scene scene = [] {
    Diagnostics diags("test");
    auto s = mesh::loadGltfScene(scenePath().string(), mesh::MeshLimits{}, diags);
    EXPECT_TRUE(s.has_value()) << diags.formatAll();
    return s ? *s : mesh::Scene{};
  }();
  return scene;
}

CompileResult compileExample(const std::string& stem) {
  const fs::path path = kSource / "examples" / (stem + ".json");
  Diagnostics d(path.filename().string());
  auto r = compileText(path.filename().string(), readBytes(path), CompileOptions{}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

class RenderOnGpu : public ::testing::Test {
 protected:
  void SetUp() override {
    Diagnostics diags("test");
    ctx_ = sharedContext(diags);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
    ASSERT_FALSE(testScene().primitives.empty());
  }

  /// Every primitive of the test scene with `r`.
  render::RenderResult draw(const CompileResult& r, render::RenderOptions o) {
    const mesh::Scene& scene = testScene();
    std::vector<render::SceneMaterial> materials = {{&r, nullptr}};
    const std::vector<int> which(scene.primitives.size(), 0);
    render::RenderResult out;
    Diagnostics diags("test");
    EXPECT_TRUE(render::renderScene(*ctx_, scene, materials, which, scene.cameras.at(0), o, &out, diags))
        << diags.formatAll();
    return out;
  }

  gpu::Context* ctx_ = nullptr;
};

render::RenderOptions small(Target target = Target::Glsl, bool forward = false) {
  render::RenderOptions o;
  o.width = 64;
  o.height = 48;
  o.target = target;
  o.forward = forward;
  return o;
}

/// Relative differences of two renders over the pixels both cover, sorted.
std::vector<double> relativeDifferences(const render::RenderResult& a, const render::RenderResult& b) {
  std::vector<double> d;
  for (std::size_t i = 0; i < a.depth.size(); ++i) {
    if (!(a.depth[i] < 1.0f) || !(b.depth[i] < 1.0f)) continue;
    double num = 0, den = 0;
    for (int c = 0; c < 3; ++c) {
      num = std::max(num, std::abs(double(a.hdr.rgba[i * 4 + c]) - b.hdr.rgba[i * 4 + c]));
      den = std::max(den, std::abs(double(b.hdr.rgba[i * 4 + c])));
    }
    d.push_back(num / std::max(den, 0.05));
  }
  std::sort(d.begin(), d.end());
  return d;
}

std::vector<std::string> everyExampleStem() {
  std::vector<std::string> stems;
  for (const fs::path& e : test::exampleFiles(test::Examples::Surfaces)) stems.push_back(e.stem().string());
  return stems;
}

// Deferred against forward, every example on the test scene: the deferred
// path lights what the G-buffer stores (quantized as docs/storage.md says,
// the quantization dithered per pixel), the forward pass what the material
// evaluates. Both cover the same pixels (the depth pre-pass and the base pass
// agree to the bit); the lit colours differ per pixel by the quantization
// (p99 and max of |deferred - forward| / max(forward, 0.05), the channel of
// largest difference) and on average by less than 2.5 %. A glint's sparkle is
// a hash of its uv, which the G-buffer stores in 12 bits a coordinate: the
// sparkles move, and only the image's mean is compared (within 15 %). A
// translucent material and a single-layer water are drawn forward on both
// paths: the same image.
/// The per-example suite, apart: the sanitizer stage of scripts/test.sh leaves it out.
class RenderEveryExample : public RenderOnGpu {};

TEST_F(RenderEveryExample, DeferredMatchesForward) {
  std::size_t compared = 0;
  for (const std::string& stem : everyExampleStem()) {
    SCOPED_TRACE(stem);
    const CompileResult r = compileExample(stem);
    const render::RenderResult deferred = draw(r, small()), forward = draw(r, small(Target::Glsl, true));
    ASSERT_EQ(deferred.depth, forward.depth) << "the same geometry, the same depth";
    ++compared;
    if (deferred.stats.coveredPixels == 0) {  // translucent or water: nothing in the G-buffer
      EXPECT_EQ(deferred.hdr.rgba, forward.hdr.rgba);
      continue;
    }
    const std::vector<double> d = relativeDifferences(deferred, forward);
    ASSERT_GT(d.size(), 1000u) << "the sphere and the floor cover most of the image";
    double sum[3] = {0, 0, 0}, ref[3] = {0, 0, 0};
    for (std::size_t i = 0; i < deferred.depth.size(); ++i)
      if (deferred.depth[i] < 1.0f)
        for (int c = 0; c < 3; ++c) sum[c] += deferred.hdr.rgba[i * 4 + c], ref[c] += forward.hdr.rgba[i * 4 + c];
    double meanOff = 0;
    for (int c = 0; c < 3; ++c) meanOff = std::max(meanOff, std::abs(sum[c] / ref[c] - 1));
    const double p99 = d[d.size() * 99 / 100], max = d.back();
    const bool glint = (summarize(r).storedFeatures & kFeatGlint) != 0;
    std::printf("[ render   ] %-28s deferred vs forward over %zu pixels: p99 %.4f, max %.4f, mean off by %.4f%s\n",
                stem.c_str(), d.size(), p99, max, meanOff, glint ? " (glint: mean only)" : "");
    EXPECT_LE(meanOff, glint ? 0.15 : 0.025);
    if (glint) continue;
    EXPECT_LE(p99, 0.10);
    EXPECT_LE(max, 0.20);
  }
  EXPECT_EQ(compared, everyExampleStem().size());
  EXPECT_GE(compared, 19u);
}

TEST_F(RenderOnGpu, GlslAndHlslDrawTheSameImageAndARenderRepeatsBitForBit) {
  for (const char* stem : {"car_paint", "translucent_absorbing"}) {
    SCOPED_TRACE(stem);
    const CompileResult r = compileExample(stem);
    for (bool forward : {false, true}) {
      const render::RenderResult glsl = draw(r, small(Target::Glsl, forward));
      const render::RenderResult hlsl = draw(r, small(Target::Hlsl, forward));
      const render::RenderResult again = draw(r, small(Target::Glsl, forward));
      EXPECT_EQ(glsl.hdr.rgba, hlsl.hdr.rgba) << (forward ? "forward" : "deferred");
      EXPECT_EQ(glsl.hdr.rgba, again.hdr.rgba) << (forward ? "forward" : "deferred");
      if (std::string(stem) != "translucent_absorbing") EXPECT_GT(glsl.stats.coveredPixels, 1000u);  // translucency covers nothing opaque
    }
  }
}

CompileResult compileJson(const std::string& json) {
  Diagnostics d("water.json");
  auto r = compileText("water.json", json, CompileOptions{}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

/// A water sphere that scatters nothing (albedo 0, no top material) of grey
/// extinction `sigma` (1/m), seeing `scale` of what lies behind it.
CompileResult clearWater(double sigma, double scale) {
  return compileJson(fmt::format(R"({{"format": "substrate-material/1", "name": "clear_water", "output": "w", "nodes": {{
      "w": {{"kind": "single_layer_water", "base_color": 0, "specular": 0.5, "roughness": 0.2,
             "top_material_opacity": 0, "water_albedo": 0, "water_extinction": {}, "water_phase_g": 0,
             "color_scale_behind_water": {}}}}}}})",
                                 sigma, scale));
}

// A single-layer water is drawn over what lies behind it, as an engine draws
// it: `render` hands its forward entry the frame drawn so far (binding 6: the
// colour, and the distance from the eye). Where the water sphere stands in
// front of the floor, what the water adds when it sees the floor (colour
// scale 1, against 0) is the floor's colour of the render without the
// sphere, times a grey factor (the interface's transmission, no extinction)
// and, with extinction sigma, times exp(-sigma d): d the distance from the
// sphere's surface to the floor behind it, both from the depth buffers.
// Where the sky is behind, that water hides it. Deferred and forward, GLSL and HLSL.
TEST_F(RenderOnGpu, ASingleLayerWaterShowsWhatLiesBehindItAtItsDepth) {
  const CompileResult floorMaterial = compileExample("row12_simple");
  const double sigma = 0.8;
  const CompileResult seen = clearWater(0, 1), deep = clearWater(sigma, 1), blind = clearWater(0, 0);
  const mesh::Scene& scene = testScene();
  ASSERT_EQ(scene.primitives.size(), 2u);  // the sphere, then the floor
  mesh::Scene floorOnly = scene;            // the same bounds, so the same view
  floorOnly.primitives.erase(floorOnly.primitives.begin());
  for (Target target : {Target::Glsl, Target::Hlsl})
    for (bool forward : {false, true}) {
      SCOPED_TRACE(fmt::format("{} {}", target == Target::Glsl ? "glsl" : "hlsl", forward ? "forward" : "deferred"));
      const render::RenderOptions o = small(target, forward);
      auto drawWith = [&](const mesh::Scene& sc, const CompileResult& water, std::vector<int> which) {
        std::vector<render::SceneMaterial> materials = {{&water, nullptr}, {&floorMaterial, nullptr}};
        render::RenderResult out;
        Diagnostics diags("test");
        EXPECT_TRUE(render::renderScene(*ctx_, sc, materials, which, sc.cameras.at(0), o, &out, diags))
            << diags.formatAll();
        return out;
      };
      const render::RenderResult behind = drawWith(floorOnly, blind, {1});
      const render::RenderResult a = drawWith(scene, seen, {0, 1}), b = drawWith(scene, deep, {0, 1}),
                                 c = drawWith(scene, blind, {0, 1});
      const render::ViewSetup view = render::viewSetup(scene.cameras.at(0), o.width, o.height, scene.boundsMin,
                                                       scene.boundsMax);
      // The distance along the pixel's ray of a depth (camera.h's projection, inverted here).
      auto distance = [&](int x, int y, float depth) {
        const double A = view.zfar / (view.zfar - view.znear), B = -view.zfar * view.znear / (view.zfar - view.znear);
        const auto r = view.ray(x, y, o.width, o.height);
        return B / (depth - A) / (r[0] * view.forward[0] + r[1] * view.forward[1] + r[2] * view.forward[2]);
      };
      int overFloor = 0, overSky = 0;
      double worstGrey = 0, worstDepth = 0, worstSky = 0;
      for (int y = 0; y < o.height; ++y)
        for (int x = 0; x < o.width; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * o.width + x;
          if (!(a.depth[i] < behind.depth[i])) continue;  // not the sphere's
          double k[3], along[3];
          for (int ch = 0; ch < 3; ++ch) {
            const double shown = a.hdr.rgba[i * 4 + ch] - c.hdr.rgba[i * 4 + ch];
            k[ch] = shown / behind.hdr.rgba[i * 4 + ch];
            along[ch] = (b.hdr.rgba[i * 4 + ch] - c.hdr.rgba[i * 4 + ch]) / std::max(shown, 1e-30);
          }
          if (!(behind.depth[i] < 1.0f)) {  // the sky: deep water hides it
            ++overSky;
            for (int ch = 0; ch < 3; ++ch)
              worstSky = std::max(worstSky, std::abs(double(b.hdr.rgba[i * 4 + ch]) - c.hdr.rgba[i * 4 + ch]));
            continue;
          }
          if (k[1] < 0.05) continue;  // grazing: the interface lets little through
          ++overFloor;
          const double d = distance(x, y, behind.depth[i]) - distance(x, y, a.depth[i]);
          ASSERT_GT(d, 0.0);
          for (int ch = 0; ch < 3; ++ch) {
            EXPECT_LE(k[ch], 1.0 + 1e-4);
            worstGrey = std::max(worstGrey, std::abs(k[ch] / k[1] - 1));
            worstDepth = std::max(worstDepth, std::abs(along[ch] / std::exp(-sigma * d) - 1));
          }
        }
      std::printf("[ render   ] water over %d floor and %d sky pixels: grey factor off by %.2e, exp(-sigma d) off "
                  "by %.2e, sky through deep water %.2e\n",
                  overFloor, overSky, worstGrey, worstDepth, worstSky);
      EXPECT_GE(overFloor, 100);
      EXPECT_LE(worstGrey, 1e-5);
      EXPECT_LE(worstDepth, 1e-3);
      EXPECT_LE(worstSky, 1e-6);
    }
}

// ----- the command --------------------------------------------------------------

struct CliRun {
  int status;
  std::string out, err;
};
CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  const int status = runCli(args, out, err);
  return {status, out.str(), err.str()};
}

TEST(RenderCli, DrawsTheDocumentsMaterialsIntoAPng) {
  const fs::path png = workDir() / "scene.png";
  const CliRun r = cli({"render", scenePath().string(), "-o", png.string(), "--size", "64x48", "--timings"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(png));
  EXPECT_NE(r.out.find("GPU ms"), std::string::npos) << r.out;
  const std::string bytes = readBytes(png);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  // For a platform: its budget and features (a coat over SSS on mobile: one closure, no SSS).
  const fs::path mobile = workDir() / "mobile.png";
  const CliRun m = cli({"render", scenePath().string(), "--material", (kSource / "examples/skin_coated.json").string(),
                        "--platform", "mobile", "-o", mobile.string(), "--size", "32x32"});
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_EQ(readBytes(mobile).substr(1, 3), "PNG");
}

TEST(RenderCli, BadInputIsALocatedErrorAndNothingIsWritten) {
  const fs::path png = workDir() / "bad.png";
  // A primitive of lines.
  nlohmann::json doc = nlohmann::json::parse(sceneGltf());
  const fs::path bad = workDir() / "lines.gltf";
  doc["meshes"][0]["primitives"][0]["mode"] = 1;  // lines
  std::ofstream(bad) << doc.dump();
  CliRun r = cli({"render", bad.string(), "-o", png.string()});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("/meshes/0/primitives/0"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
  // A missing buffer file.
  doc = nlohmann::json::parse(sceneGltf());
  doc["buffers"][0]["uri"] = "missing.bin";
  const fs::path missing = workDir() / "missing_buffer.gltf";
  std::ofstream(missing) << doc.dump();
  r = cli({"render", missing.string(), "-o", png.string()});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("missing.bin"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
  // A platform nobody defined.
  r = cli({"render", scenePath().string(), "-o", png.string(), "--platform", "moon"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("unknown platform \"moon\" (known: mobile, console, pc-high)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
  // A camera the document does not have.
  r = cli({"render", scenePath().string(), "-o", png.string(), "--camera", "3"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_FALSE(fs::exists(png));
  // The output over the input.
  r = cli({"render", scenePath().string(), "-o", scenePath().string()});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(readBytes(scenePath()), sceneGltf());
  // The output over an external buffer the document reads: an input too.
  doc = nlohmann::json::parse(sceneGltf());
  std::string why;
  const std::string bin = import::decodeDataUri(doc["buffers"][0]["uri"].get<std::string>(), &why).value();
  const fs::path buffer = workDir() / "external.bin";
  std::ofstream(buffer, std::ios::binary) << bin;
  doc["buffers"][0]["uri"] = "external.bin";
  doc["buffers"][0]["byteLength"] = bin.size();
  const fs::path external = workDir() / "external_buffer.gltf";
  std::ofstream(external) << doc.dump();
  r = cli({"render", external.string(), "-o", buffer.string()});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(readBytes(buffer), bin);
}

// ----- glTF texture coordinates in the raster pipeline --------------------------


/// Three quads in a row, facing the camera, each its own material over one
/// 2 x 1 image (left texel red, right texel green; nearest, clamped): the
/// first reads uv0 as it is, the second through KHR_texture_transform
/// (scale (0.5, 1), offset (0.5, 0): u from 0.5 to 1, all green), the third
/// reads TEXCOORD_1, which is (0.25, 0.5) at every vertex (all red).
std::string texCoordGltf() {
  using J = nlohmann::json;
  const float positions[] = {-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0};
  const float normals[] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  const float uv0[] = {0, 1, 1, 1, 1, 0, 0, 0};
  const float uv1[] = {0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f, 0.25f, 0.5f};
  const uint32_t indices[] = {0, 1, 2, 0, 2, 3};
  std::string buffer;
  J views = J::array(), accessors = J::array();
  auto add = [&](const void* data, std::size_t bytes, std::size_t count, int type, const char* kind) {
    views.push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", bytes}});
    buffer.append(static_cast<const char*>(data), bytes);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", type}, {"count", count}, {"type", kind}});
  };
  add(positions, sizeof positions, 4, 5126, "VEC3");
  accessors.back()["min"] = {-0.5, -0.5, 0};
  accessors.back()["max"] = {0.5, 0.5, 0};
  add(normals, sizeof normals, 4, 5126, "VEC3");
  add(uv0, sizeof uv0, 4, 5126, "VEC2");
  add(uv1, sizeof uv1, 4, 5126, "VEC2");
  add(indices, sizeof indices, 6, 5125, "SCALAR");
  J meshes = J::array(), nodes = J::array();
  for (int m = 0; m < 3; ++m) {
    meshes.push_back({{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}, {"TEXCOORD_1", 3}}},
                                       {"indices", 4}, {"material", m}}}}});
    nodes.push_back({{"mesh", m}, {"translation", {1.1 * (m - 1), 0.0, 0.0}}});
  }
  nodes.push_back({{"camera", 0}, {"translation", {0.0, 0.0, 3.0}}});
  auto textured = [](const char* name, J info) {
    return J{{"name", name},
             {"pbrMetallicRoughness", {{"baseColorTexture", info}, {"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}}};
  };
  J doc = {{"asset", {{"version", "2.0"}}},
           {"extensionsUsed", {"KHR_texture_transform"}},
           {"scene", 0},
           {"scenes", {{{"nodes", {0, 1, 2, 3}}}}},
           {"nodes", nodes},
           {"cameras", {{{"type", "perspective"}, {"perspective", {{"yfov", 0.8}, {"aspectRatio", 3.0}, {"znear", 0.05}}}}}},
           {"meshes", meshes},
           {"materials",
            {textured("plain", {{"index", 0}}),
             textured("transformed",
                      {{"index", 0},
                       {"extensions", {{"KHR_texture_transform", {{"offset", {0.5, 0.0}}, {"scale", {0.5, 1.0}}}}}}}),
             textured("second_set", {{"index", 0}, {"texCoord", 1}})}},
           {"textures", {{{"source", 0}, {"sampler", 0}}}},
           {"samplers", {{{"magFilter", 9728}, {"minFilter", 9728}, {"wrapS", 33071}, {"wrapT", 33071}}}},
           {"images", {{{"uri", "halves.png"}}}},
           {"accessors", accessors},
           {"bufferViews", views},
           {"buffers", {{{"byteLength", buffer.size()},
                         {"uri", "data:application/octet-stream;base64," + base64(buffer)}}}}};
  return doc.dump();
}

// What the importer makes of a glTF texture's coordinates (KHR_texture_transform,
// texCoord) reaches the raster pipeline: the vertex stage passes uv0 and uv1,
// the base pass and the forward pass read them through the material's uv math.
TEST(RenderCli, TextureTransformsAndTheSecondUvSetReachTheRasterPipeline) {
  const fs::path dir = workDir() / "texcoords";
  fs::create_directories(dir);
  const unsigned char halves[] = {255, 0, 0, 0, 255, 0};
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = 2;
  image.height = 1;
  image.format = PNG_FORMAT_RGB;
  ASSERT_TRUE(png_image_write_to_file(&image, (dir / "halves.png").c_str(), 0, halves, 0, nullptr));
  std::ofstream(dir / "quads.gltf") << texCoordGltf();
  std::size_t checked = 0;
  for (const char* path : {"deferred", "forward"}) {
    SCOPED_TRACE(path);
    const fs::path png = dir / (std::string(path) + ".png");
    std::vector<std::string> args = {"render", (dir / "quads.gltf").string(), "-o", png.string(), "--size", "192x64",
                                     "--env", "white"};
    if (std::string(path) == "forward") args.push_back("--forward");
    const CliRun r = cli(args);
    ASSERT_EQ(r.status, 0) << r.err;
    testutil::Png picture;
    ASSERT_TRUE(testutil::readPng(png, &picture));
    const int w = picture.width, h = picture.height;
    const std::vector<unsigned char>& rgba = picture.rgba;
    // Pixel column of world x on the row through the quads' centres.
    const double halfWidth = 3.0 * std::tan(0.4) * 3.0;
    auto at = [&](double x) {
      const int px = static_cast<int>((x / halfWidth * 0.5 + 0.5) * w);
      return &rgba[(static_cast<std::size_t>(h / 2) * w + px) * 4];
    };
    auto red = [](const unsigned char* p) { return p[0] > p[1] + 100 && p[0] > p[2] + 100; };
    auto green = [](const unsigned char* p) { return p[1] > p[0] + 100 && p[1] > p[2] + 100; };
    const struct {
      double x;
      bool wantRed;
      const char* what;
    } probes[] = {{-1.35, true, "uv0, left half: red"},    {-0.85, false, "uv0, right half: green"},
                  {-0.25, false, "transformed, left: green"}, {0.25, false, "transformed, right: green"},
                  {0.85, true, "TEXCOORD_1: red"},         {1.35, true, "TEXCOORD_1: red"}};
    for (const auto& probe : probes) {
      const unsigned char* p = at(probe.x);
      EXPECT_TRUE(probe.wantRed ? red(p) : green(p))
          << probe.what << ": (" << int(p[0]) << ", " << int(p[1]) << ", " << int(p[2]) << ")";
      ++checked;
    }
  }
  EXPECT_EQ(checked, 12u);
}

}  // namespace
}  // namespace substratec::gputest
