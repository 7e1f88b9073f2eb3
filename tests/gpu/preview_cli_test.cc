// `substratec preview` (issue 5): the material on a sphere, rendered on
// lavapipe by the generated preview kernel, written as an 8-bit sRGB PNG; and
// `--sweep`, the contact sheet of its simplification steps. Driven in-process
// through runCli, like tests/cli_test.cc.
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <iostream>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli.h"
#include "sweep/sweep.h"
#include "../radiance_writer.h"
#include "png_files.h"

namespace {

namespace fs = std::filesystem;
using substratec::runCli;

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

struct CliRun {
  int status;
  std::string out, err;
};

CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  int status = runCli(args, out, err);
  return CliRun{status, out.str(), err.str()};
}

/// A scratch folder for this process's PNGs, removed at exit.
fs::path workDir() {
  static struct Dir {
    fs::path path = fs::temp_directory_path() / ("substratec_preview_test_" + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  } dir;
  return dir.path;
}

std::string example(const char* name) { return (kSource / "examples" / name).string(); }

using substratec::testutil::Png;
using substratec::testutil::readPng;
using substratec::testutil::solidPng;

std::string bytesOf(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Preview, WritesAnSrgbPngOfTheSphere) {
  const fs::path png = workDir() / "car_paint.png";
  CliRun r = cli({"preview", example("car_paint.json"), "-o", png.string(), "--size", "64"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, png.string() + "\n");
  Png img;
  ASSERT_TRUE(readPng(png, &img));
  EXPECT_EQ(img.width, 64);
  EXPECT_EQ(img.height, 64);
  // The sphere (red paint) is in the middle; the corners are the environment.
  auto at = [&](int x, int y) { return &img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4]; };
  const unsigned char* centre = at(32, 32);
  const unsigned char* corner = at(1, 1);
  EXPECT_GT(centre[0], centre[2] + 40) << "the car paint is red";
  EXPECT_NE(std::vector<unsigned char>(centre, centre + 3), std::vector<unsigned char>(corner, corner + 3));
  EXPECT_EQ(centre[3], 255);
}

// A volume has no sphere: its preview marches the cube around the origin
// (kernel_emitter.h, kVolumePreview*). The puff is opaque at its centre and
// absent at the corners, where the environment shows; both languages agree.
TEST(Preview, AVolumeIsMarchedThroughItsCube) {
  const fs::path dir = workDir();
  const fs::path png = dir / "puff.png";
  CliRun r = cli({"preview", example("fog_cloud_puff.json"), "-o", png.string(), "--size", "48"});
  ASSERT_EQ(r.status, 0) << r.err;
  Png img;
  ASSERT_TRUE(readPng(png, &img));
  auto at = [&](int x, int y) { return &img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4]; };
  const unsigned char* centre = at(24, 24);
  const unsigned char* corner = at(1, 1);
  EXPECT_GT(centre[3], 230) << "optical depth 4 through the centre: 98 % covered";
  EXPECT_EQ(corner[3], 0) << "outside the cube: the environment alone";
  EXPECT_NE(std::vector<unsigned char>(centre, centre + 3), std::vector<unsigned char>(corner, corner + 3));
  ASSERT_EQ(cli({"preview", example("fog_cloud_puff.json"), "-o", (dir / "puff_hlsl.png").string(), "--size", "48",
                 "--target", "hlsl"})
                .status,
            0);
  EXPECT_EQ(bytesOf(png), bytesOf(dir / "puff_hlsl.png"));
}

TEST(Preview, TheSameCommandTwiceAndBothLanguagesGiveTheSameBytes) {
  const fs::path dir = workDir();
  ASSERT_EQ(cli({"preview", example("worked_example_72.json"), "-o", (dir / "a.png").string(), "--size", "48"}).status, 0);
  ASSERT_EQ(cli({"preview", example("worked_example_72.json"), "-o", (dir / "b.png").string(), "--size", "48"}).status, 0);
  ASSERT_EQ(cli({"preview", example("worked_example_72.json"), "-o", (dir / "c.png").string(), "--size", "48",
                 "--target", "hlsl"})
                .status,
            0);
  EXPECT_EQ(bytesOf(dir / "a.png"), bytesOf(dir / "b.png"));
  EXPECT_EQ(bytesOf(dir / "a.png"), bytesOf(dir / "c.png"));
}

TEST(Preview, HalfPrecisionMovesNoValueByMoreThanOneLevel) {
  // float16 colours, weights and throughputs (docs/stability.md, "Half
  // precision"): the 8-bit image differs from float32's by at most 1 in any
  // channel, and in few values (measured at 256 px: 0.2-1.1 % per example).
  const fs::path dir = workDir();
  ASSERT_EQ(cli({"preview", example("worked_example_72.json"), "-o", (dir / "f.png").string(), "--size", "64"}).status, 0);
  CliRun r = cli({"preview", example("worked_example_72.json"), "-o", (dir / "h.png").string(), "--size", "64",
                  "--precision", "half"});
  ASSERT_EQ(r.status, 0) << r.err;
  Png f, h;
  ASSERT_TRUE(readPng(dir / "f.png", &f));
  ASSERT_TRUE(readPng(dir / "h.png", &h));
  ASSERT_EQ(f.rgba.size(), h.rgba.size());
  int differ = 0, largest = 0;
  for (std::size_t i = 0; i < f.rgba.size(); ++i) {
    const int d = std::abs(int(f.rgba[i]) - int(h.rgba[i]));
    differ += d != 0;
    largest = std::max(largest, d);
  }
  EXPECT_LE(largest, 1);
  EXPECT_LT(differ, static_cast<int>(f.rgba.size() / 50)) << "under 2 % of the values";
  EXPECT_EQ(cli({"preview", example("row12_simple.json"), "-o", (dir / "x.png").string(), "--precision", "double"})
                .status,
            2)
      << "a usage error";
}

TEST(Preview, SweepIsAContactSheetOfTheSimplificationSteps) {
  const fs::path one = workDir() / "one.png", sheet = workDir() / "sheet.png";
  ASSERT_EQ(cli({"preview", example("worked_example_72.json"), "-o", one.string(), "--size", "48"}).status, 0);
  CliRun r = cli({"preview", example("worked_example_72.json"), "-o", sheet.string(), "--size", "48", "--sweep"});
  ASSERT_EQ(r.status, 0) << r.err;
  Png a, b;
  ASSERT_TRUE(readPng(one, &a));
  ASSERT_TRUE(readPng(sheet, &b));
  // worked_example_72 (72 B, 3 closures) has at least the authored and the fully simplified tiles.
  EXPECT_GE(b.width, 2 * a.width);
  EXPECT_GT(b.height, a.height) << "room for the labels";
}

TEST(Preview, ABrokenMaterialWritesNothing) {
  const fs::path dir = workDir();
  const fs::path broken = dir / "broken.json", png = dir / "broken.png";
  std::ofstream(broken) << R"({"format": "substrate-material/1", "name": "m", "nodes": {}, "output": "nope"})";
  CliRun r = cli({"preview", broken.string(), "-o", png.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("broken.json"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(png));
}

// The PNG is committed like every output (cli/command_outputs.h): an earlier
// file replaced whole, no temporary left beside it.
TEST(Preview, APreviewReplacesItsPngWholeAndLeavesNoTemporary) {
  const fs::path dir = workDir() / "replace";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "x.png") << "an earlier preview";
  CliRun r = cli({"preview", example("row12_simple.json"), "-o", (dir / "x.png").string(), "--size", "16"});
  ASSERT_EQ(r.status, 0) << r.err;
  Png png;
  ASSERT_TRUE(readPng(dir / "x.png", &png));
  EXPECT_EQ(png.width, 16);
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += !e.path().empty();
  EXPECT_EQ(entries, 1u) << "a temporary was left behind";
}

TEST(Preview, AnUnknownEnvironmentIsAUsageError) {
  CliRun r = cli({"preview", example("row12_simple.json"), "-o", (workDir() / "x.png").string(), "--env", "moon"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("moon"), std::string::npos) << r.err;
}

// ---------------------------------------------------------------- real textures (issue 20)


/// A glTF whose one material's base colour is the texture `image`.
void texturedGltf(const fs::path& path, const std::string& image) {
  std::ofstream(path) << R"({"asset": {"version": "2.0"}, "images": [{"uri": ")" << image
                      << R"("}], "textures": [{"source": 0}], "materials": [{"name": "Painted",
     "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0, "roughnessFactor": 0.8}}]})";
}

/// The centre pixel of a preview.
std::array<int, 3> centreOf(const fs::path& png) {
  Png img;
  EXPECT_TRUE(readPng(png, &img));
  const unsigned char* p = &img.rgba[(static_cast<std::size_t>(img.height / 2) * img.width + img.width / 2) * 4];
  return {p[0], p[1], p[2]};
}

/// A .gltf beside a solid green PNG previews green (it previewed a lavender
/// checker), in both languages alike; --texture binds another image instead.
TEST(PreviewTextures, AGltfBesideASolidGreenPngPreviewsGreenAndTextureBindsAnother) {
  const fs::path dir = workDir() / "gltf_green";
  fs::create_directories(dir);
  solidPng(dir / "green.png", 0, 200, 0);
  solidPng(dir / "red.png", 220, 0, 0);
  texturedGltf(dir / "painted.gltf", "green.png");
  CliRun r = cli({"preview", (dir / "painted.gltf").string(), "-o", (dir / "g.png").string(), "--size", "32"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::array<int, 3> green = centreOf(dir / "g.png");
  EXPECT_GT(green[1], green[0] + 60) << green[0] << " " << green[1] << " " << green[2];
  EXPECT_GT(green[1], green[2] + 60) << green[0] << " " << green[1] << " " << green[2];
  ASSERT_EQ(cli({"preview", (dir / "painted.gltf").string(), "-o", (dir / "h.png").string(), "--size", "32", "--target",
                 "hlsl"})
                .status,
            0);
  EXPECT_EQ(bytesOf(dir / "g.png"), bytesOf(dir / "h.png")) << "GLSL and HLSL bind the same image";
  r = cli({"preview", (dir / "painted.gltf").string(), "-o", (dir / "r.png").string(), "--size", "32", "--texture",
           "baseColorTexture=" + (dir / "red.png").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::array<int, 3> red = centreOf(dir / "r.png");
  EXPECT_GT(red[0], red[1] + 60) << red[0] << " " << red[1] << " " << red[2];
}

/// A .glb whose base colour image (a solid blue PNG) is in its binary chunk
/// previews blue: embedded images are decoded from the container's bytes.
TEST(PreviewTextures, AGlbsEmbeddedImageIsDecodedFromItsBinaryChunk) {
  const fs::path dir = workDir() / "glb_embedded";
  fs::create_directories(dir);
  std::vector<unsigned char> texels;
  for (int i = 0; i < 16; ++i) texels.insert(texels.end(), {0, 0, 230});
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = image.height = 4;
  image.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  ASSERT_TRUE(png_image_write_to_memory(&image, nullptr, &size, 0, texels.data(), 0, nullptr));
  std::string bin(size, '\0');
  ASSERT_TRUE(png_image_write_to_memory(&image, bin.data(), &size, 0, texels.data(), 0, nullptr));
  std::string json = R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": )" + std::to_string(bin.size()) +
                     R"(}], "bufferViews": [{"buffer": 0, "byteLength": )" + std::to_string(bin.size()) +
                     R"(}], "images": [{"bufferView": 0, "mimeType": "image/png"}], "textures": [{"source": 0}],
      "materials": [{"name": "Blue", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}]})";
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  auto le32 = [](std::size_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[i] = static_cast<char>(v >> (8 * i));
    return b;
  };
  std::ofstream(dir / "blue.glb", std::ios::binary)
      << le32(0x46546C67) + le32(2) + le32(12 + 8 + json.size() + 8 + bin.size()) + le32(json.size()) +
             le32(0x4E4F534A) + json + le32(bin.size()) + le32(0x004E4942) + bin;
  CliRun r = cli({"preview", (dir / "blue.glb").string(), "-o", (dir / "b.png").string(), "--size", "32"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::array<int, 3> blue = centreOf(dir / "b.png");
  EXPECT_GT(blue[2], blue[0] + 60) << blue[0] << " " << blue[1] << " " << blue[2];
  EXPECT_GT(blue[2], blue[1] + 60) << blue[0] << " " << blue[1] << " " << blue[2];
}

/// An input's `wrap` is how its image is addressed: repeat, clamp and mirror
/// of a red-to-green image over three times its uv range give three pictures,
/// in both languages alike (HLSL binds the input's own sampler).
TEST(PreviewTextures, AnInputsWrapDecidesHowItsImageRepeats) {
  const fs::path dir = workDir() / "wrap";
  fs::create_directories(dir);
  std::vector<unsigned char> texels;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) texels.insert(texels.end(), {static_cast<unsigned char>(255 - 60 * x), static_cast<unsigned char>(60 * x), 0});
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = image.height = 4;
  image.format = PNG_FORMAT_RGB;
  ASSERT_TRUE(png_image_write_to_file(&image, (dir / "ramp.png").c_str(), 0, texels.data(), 0, nullptr));
  std::vector<std::string> pictures;
  for (const char* wrap : {"repeat", "clamp", "mirror"})
    for (const char* target : {"glsl", "hlsl"}) {
      const fs::path material = dir / (std::string(wrap) + ".json");
      std::ofstream(material) << R"({"format": "substrate-material/1", "name": "wrapped",
        "inputs": {"ramp": {"type": "texture2d", "file": "ramp.png", "wrap": ")" << wrap << R"("}},
        "nodes": {"a": {"kind": "texture", "texture": "$ramp",
                        "uv": {"kind": "multiply", "a": {"kind": "geometry", "attribute": "uv0"}, "b": 3}},
                  "root": {"kind": "slab", "diffuse_albedo": "a", "f0": 0, "roughness": 1}},
        "output": "root"})";
      const fs::path png = dir / (std::string(wrap) + "." + target + ".png");
      CliRun r = cli({"preview", material.string(), "-o", png.string(), "--size", "32", "--target", target});
      ASSERT_EQ(r.status, 0) << r.err;
      pictures.push_back(bytesOf(png));
    }
  for (int w = 0; w < 3; ++w) EXPECT_EQ(pictures[2 * w], pictures[2 * w + 1]) << "GLSL and HLSL, wrap " << w;
  EXPECT_NE(pictures[0], pictures[2]) << "repeat and clamp";
  EXPECT_NE(pictures[0], pictures[4]) << "repeat and mirror";
  EXPECT_NE(pictures[2], pictures[4]) << "clamp and mirror";
}

/// A black and a white image give different pictures (the checker made them byte-identical).
TEST(PreviewTextures, BlackAndWhiteImagesGiveDifferentPictures) {
  const fs::path dir = workDir() / "black_white";
  fs::create_directories(dir);
  solidPng(dir / "black.png", 0, 0, 0);
  solidPng(dir / "white.png", 255, 255, 255);
  texturedGltf(dir / "piece.gltf", "black.png");
  ASSERT_EQ(cli({"preview", (dir / "piece.gltf").string(), "-o", (dir / "b.png").string(), "--size", "32"}).status, 0);
  ASSERT_EQ(cli({"preview", (dir / "piece.gltf").string(), "-o", (dir / "w.png").string(), "--size", "32", "--texture",
                 "baseColorTexture=" + (dir / "white.png").string()})
                .status,
            0);
  const std::array<int, 3> black = centreOf(dir / "b.png"), white = centreOf(dir / "w.png");
  EXPECT_GT(white[0], black[0] + 100) << black[0] << " " << white[0];
}

/// A material whose image is missing is an error naming the file and where it
/// is asked for; nothing is written.
TEST(PreviewTextures, AMissingImageIsALocatedErrorAndNothingIsWritten) {
  const fs::path dir = workDir() / "missing_image";
  fs::create_directories(dir);
  texturedGltf(dir / "lost.gltf", "lost.png");
  const fs::path material = dir / "native.json";
  std::ofstream(material) << R"({"format": "substrate-material/1", "name": "native",
  "inputs": {"albedo": {"type": "texture2d", "colorspace": "srgb", "file": "textures/albedo.png"}},
  "nodes": {"a": {"kind": "texture", "texture": "$albedo"}, "root": {"kind": "slab", "diffuse_albedo": "a"}},
  "output": "root"})";
  CliRun r = cli({"preview", material.string(), "-o", (dir / "n.png").string(), "--size", "16"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("native.json:2:76: error: texture input \"albedo\": cannot use the image \"textures/albedo.png\""),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "n.png"));
  // A glTF's missing image is the importer's error, at the glTF pointer.
  r = cli({"preview", (dir / "lost.gltf").string(), "-o", (dir / "l.png").string(), "--size", "16"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("lost.png"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "l.png"));
}

// ---------------------------------------------------------------- honest previews (issue 20)

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

/// A Lambertian of albedo (0.2, 0.4, 0.6) lands on sRGB(albedo) = (124, 170, 203)
/// at the sphere's centre under every environment: the preview is calibrated
/// (exposure and white balance) to the irradiance facing the camera, and the
/// tone curve leaves colours in range alone. (It rendered (217, 226, 226).)
TEST(PreviewCalibration, ALambertianLandsOnItsAlbedoAtTheCentreUnderEveryEnvironment) {
  const fs::path dir = workDir() / "calibration";
  fs::create_directories(dir);
  std::ofstream(dir / "lambert.json") << R"({"format": "substrate-material/1", "name": "lambert",
    "nodes": {"root": {"kind": "slab", "diffuse_albedo": [0.2, 0.4, 0.6], "f0": 0, "roughness": 1}}, "output": "root"})";
  int measured = 0;
  for (const char* env : {"studio", "sky", "white"}) {
    const fs::path png = dir / (std::string(env) + ".png");
    CliRun r = cli({"preview", (dir / "lambert.json").string(), "-o", png.string(), "--size", "64", "--env", env});
    ASSERT_EQ(r.status, 0) << r.err;
    const std::array<int, 3> centre = centreOf(png), want{124, 170, 203};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], want[c], 3) << env << " channel " << c;
    ++measured;
  }
  EXPECT_EQ(measured, 3);
}

// ---------------------------------------------------------------- --env FILE.hdr (issue 20)

/// A Radiance image of radiance 1 everywhere lights exactly as the white
/// furnace does (same cube maps, no lights): the same bytes.
TEST(PreviewEnvironment, AConstantRadianceImageIsTheWhiteFurnace) {
  const fs::path dir = workDir() / "env_constant";
  fs::create_directories(dir);
  std::ofstream(dir / "one.hdr", std::ios::binary) << substratec::testutil::constantRadianceFile(64, 32, 1, 1, 1, true);
  CliRun a = cli({"preview", example("car_paint.json"), "-o", (dir / "a.png").string(), "--size", "48", "--env",
                  (dir / "one.hdr").string()});
  ASSERT_EQ(a.status, 0) << a.err;
  CliRun b = cli({"preview", example("car_paint.json"), "-o", (dir / "b.png").string(), "--size", "48", "--env", "white"});
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_EQ(bytesOf(dir / "a.png"), bytesOf(dir / "b.png"));
}

/// Under an image environment (a bright blue sky over a dark warm ground,
/// the image the whole lighting) a Lambertian still lands on its albedo at
/// the centre: the calibration divides by the irradiance the image gives.
TEST(PreviewEnvironment, ALambertianLandsOnItsAlbedoUnderAnImage) {
  const fs::path dir = workDir() / "env_sky";
  fs::create_directories(dir);
  std::vector<float> rgb;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 64; ++x) rgb.insert(rgb.end(), y < 16 ? std::initializer_list<float>{0.5f, 1, 2} : std::initializer_list<float>{0.25f, 0.125f, 0.0625f});
  std::ofstream(dir / "sky.hdr", std::ios::binary) << substratec::testutil::radianceFile(64, 32, rgb);
  std::ofstream(dir / "lambert.json") << R"({"format": "substrate-material/1", "name": "lambert",
    "nodes": {"root": {"kind": "slab", "diffuse_albedo": [0.2, 0.4, 0.6], "f0": 0, "roughness": 1}}, "output": "root"})";
  const fs::path png = dir / "lambert.png";
  CliRun r = cli({"preview", (dir / "lambert.json").string(), "-o", png.string(), "--size", "64", "--env",
                  (dir / "sky.hdr").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::array<int, 3> centre = centreOf(png), want{124, 170, 203};
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], want[c], 3) << "channel " << c;
}

/// A missing or broken environment file is an error at its path (exit 1),
/// and an output over it is refused: nothing is written.
TEST(PreviewEnvironment, AMissingOrBrokenImageIsAnErrorAtItsPathAndNothingIsWritten) {
  const fs::path dir = workDir() / "env_bad";
  fs::create_directories(dir);
  const fs::path png = dir / "x.png", broken = dir / "broken.hdr";
  std::ofstream(broken, std::ios::binary) << substratec::testutil::constantRadianceFile(16, 4, 1, 1, 1, true).substr(0, 60);
  for (const fs::path& env : {dir / "missing.hdr", broken}) {
    CliRun r = cli({"preview", example("row12_simple.json"), "-o", png.string(), "--env", env.string()});
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err.rfind(env.string() + ": error: cannot use the environment: ", 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(png));
  }
  const std::string before = bytesOf(broken);
  CliRun r = cli({"preview", example("row12_simple.json"), "-o", broken.string(), "--env", broken.string()});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(bytesOf(broken), before);
}

/// The ColorChecker example (its 24 published sRGB values as a matte chart)
/// under the white furnace: each patch's mean colour over the middle of the
/// patch, wherever it falls on the sphere, within ΔE2000 3 of its albedo.
TEST(PreviewCalibration, TheColorCheckerUnderTheWhiteFurnaceIsWithinDeltaE3OfItsAlbedos) {
  static const int kPatches[24][3] = {
      {115, 82, 68},   {194, 150, 130}, {98, 122, 157},  {87, 108, 67},   {133, 128, 177}, {103, 189, 170},
      {214, 126, 44},  {80, 91, 166},   {193, 90, 99},   {94, 60, 108},   {157, 188, 64},  {224, 163, 46},
      {56, 61, 150},   {70, 148, 73},   {175, 54, 60},   {231, 199, 31},  {187, 86, 149},  {8, 133, 161},
      {243, 243, 242}, {200, 200, 200}, {160, 160, 160}, {122, 122, 121}, {85, 85, 85},    {52, 52, 52}};
  const int size = 256;
  const fs::path png = workDir() / "color_checker.png";
  CliRun r = cli({"preview", example("color_checker.json"), "-o", png.string(), "--size", std::to_string(size), "--env",
                  "white"});
  ASSERT_EQ(r.status, 0) << r.err;
  Png img;
  ASSERT_TRUE(readPng(png, &img));
  // Each pixel's hit on the sphere, as the preview kernel finds it (camera on
  // +Z at 4.2, 30 degrees of field), its uv0 and the chart's uv (the example's
  // (uv0 - (1, 0.5)) * 2 + 0.5).
  std::array<std::array<double, 3>, 24> sum{};
  std::array<int, 24> count{};
  const double t = std::tan(15.0 * M_PI / 180.0);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const double nx = (x + 0.5) / size * 2 - 1, ny = (y + 0.5) / size * 2 - 1;
      double d[3] = {nx * t, -ny * t, -1};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double& c : d) c /= len;
      const double o[3] = {0, 0, 4.2};
      const double b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2], disc = b * b - (4.2 * 4.2 - 1);
      if (disc < 0) continue;
      const double hit = -b - std::sqrt(disc);
      const double n[3] = {o[0] + hit * d[0], o[1] + hit * d[1], o[2] + hit * d[2]};
      const double u0 = 2 * (0.5 + std::atan2(n[0], n[2]) / (2 * M_PI)), v0 = std::acos(std::clamp(n[1], -1.0, 1.0)) / M_PI;
      const double u = (u0 - 1) * 2 + 0.5, v = (v0 - 0.5) * 2 + 0.5;
      if (u < 0 || u >= 1 || v < 0 || v >= 1) continue;
      const double pu = u * 6 - std::floor(u * 6), pv = v * 4 - std::floor(v * 4);
      if (pu < 0.25 || pu > 0.75 || pv < 0.25 || pv > 0.75) continue;  // the middle of a patch
      const int patch = static_cast<int>(v * 4) * 6 + static_cast<int>(u * 6);
      const unsigned char* p = &img.rgba[(static_cast<std::size_t>(y) * size + x) * 4];
      for (int c = 0; c < 3; ++c) sum[patch][c] += srgbToLinear(p[c] / 255.0);
      ++count[patch];
    }
  double worst = 0;
  int measured = 0;
  for (int k = 0; k < 24; ++k) {
    ASSERT_GE(count[k], 20) << "patch " << k + 1 << " has too few pixels to measure";
    std::array<double, 3> got, want;
    for (int c = 0; c < 3; ++c) {
      got[c] = sum[k][c] / count[k];
      want[c] = srgbToLinear(kPatches[k][c] / 255.0);
    }
    const double de = substratec::sweep::deltaE2000(got, want);
    EXPECT_LE(de, 3.0) << "patch " << k + 1;
    worst = std::max(worst, de);
    ++measured;
  }
  EXPECT_EQ(measured, 24);
  std::cout << "color checker under the white furnace: " << measured << " patches, worst ΔE2000 " << worst << "\n";
}

/// A specular profile takes effect in a preview: bound to its image, or with
/// none to the default (pearlescent) profile, which differs from a white one
/// (no profile). Here the base's index differs from its coat's, so it has a
/// specular interface for the profile to tint.
TEST(PreviewCalibration, ASpecularProfileTintsTheSpecularItIsBoundTo) {
  const fs::path dir = workDir() / "profile";
  fs::create_directories(dir);
  solidPng(dir / "white.png", 255, 255, 255);
  solidPng(dir / "black.png", 0, 0, 0);
  std::ofstream(dir / "profiled.json") << R"({"format": "substrate-material/1", "name": "profiled",
    "inputs": {"lut": {"type": "texture2d"}},
    "nodes": {"base": {"kind": "slab", "diffuse_albedo": 0.2, "f0": 0.3, "roughness": 0.35, "specular_profile": "$lut"},
              "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.1, "sss_mfp": 10},
              "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0.0001}},
    "output": "root"})";
  const std::string material = (dir / "profiled.json").string();
  CliRun byDefault = cli({"preview", material, "-o", (dir / "d.png").string(), "--size", "48"});
  ASSERT_EQ(byDefault.status, 0) << byDefault.err;
  EXPECT_NE(byDefault.err.find("note: texture input \"lut\" has no image: bound to the default specular profile"),
            std::string::npos)
      << byDefault.err;
  ASSERT_EQ(cli({"preview", material, "-o", (dir / "w.png").string(), "--size", "48", "--texture",
                 "lut=" + (dir / "white.png").string()})
                .status,
            0);
  ASSERT_EQ(cli({"preview", material, "-o", (dir / "b.png").string(), "--size", "48", "--texture",
                 "lut=" + (dir / "black.png").string()})
                .status,
            0);
  EXPECT_NE(bytesOf(dir / "d.png"), bytesOf(dir / "w.png")) << "the default profile is not white";
  EXPECT_NE(bytesOf(dir / "b.png"), bytesOf(dir / "w.png")) << "a black profile removes the base's specular";
}

}  // namespace

// `report --html --previews --sweep` (issue 24): every simplification step of
// the page has its preview (a PNG data URI) and its row of sweep's cells, and
// the error-against-cost plot is in the page. tests/html/culled_and_simplified
// has two steps: the authored tree (28 B) and the budget's (16 B).
TEST(ReportHtmlOnGpu, PreviewsAndSweepGiveEveryStepAnImageAndItsCostAndError) {
  const fs::path page = workDir() / "report.html";
  CliRun r = cli({"report", (kSource / "tests/html/culled_and_simplified.json").string(), "--html", page.string(),
                  "--previews", "--sweep"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string html = bytesOf(page);
  std::size_t images = 0, rows = 0;
  for (std::size_t i = html.find("src=\"data:image/png;base64,"); i != std::string::npos;
       i = html.find("src=\"data:image/png;base64,", i + 1)) {
    EXPECT_EQ(html.compare(i + 27, 11, "iVBORw0KGgo"), 0) << "a PNG's signature";
    ++images;
  }
  const std::size_t table = html.find("<h3>Simplification steps, measured</h3>");
  ASSERT_NE(table, std::string::npos);
  const std::size_t tableEnd = html.find("</table>", table);
  for (std::size_t i = html.find("<tr><td>", table); i < tableEnd; i = html.find("<tr><td>", i + 1)) ++rows;
  EXPECT_EQ(images, 2u);
  EXPECT_EQ(rows, 2u);
  for (const std::string& column : substratec::sweep::cellColumns())
    EXPECT_NE(html.find("<th>" + column + "</th>", table), std::string::npos) << column;
  EXPECT_NE(html.find("<tr><td>authored</td><td class=\"num\">28</td>"), std::string::npos);
  EXPECT_NE(html.find("error against cost"), std::string::npos) << "the plot";
}
