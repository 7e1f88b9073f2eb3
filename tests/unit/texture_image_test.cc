// Texture images (issue 20): PNG and JPEG decoded to RGBA as stored, their
// colour decoded by the input's colour space, a mip chain that keeps the mean;
// broken, truncated and oversized files refused with a reason; and the binding
// of a material's texture inputs — the image named on the command line, the
// input's own file (beside the material, then along the search path), or the
// neutral texel with a note — with located errors.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <png.h>
#include <unistd.h>
#include <zlib.h>

#include "image/decode.h"
#include "preview/image.h"
#include "preview/textures.h"
#include "test_util.h"

namespace substratec {
namespace {

namespace fs = std::filesystem;

std::vector<std::uint8_t> pngOf(std::uint32_t w, std::uint32_t h, std::uint32_t format,
                                const std::vector<std::uint8_t>& pixels) {
  png_image img{};
  img.version = PNG_IMAGE_VERSION;
  img.width = w;
  img.height = h;
  img.format = format;
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&img, nullptr, &size, 0, pixels.data(), 0, nullptr));
  std::vector<std::uint8_t> out(size);
  EXPECT_TRUE(png_image_write_to_memory(&img, out.data(), &size, 0, pixels.data(), 0, nullptr));
  out.resize(size);
  return out;
}

std::vector<std::uint8_t> jpegOf(int w, int h, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  jpeg_compress_struct c;
  jpeg_error_mgr err;
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  unsigned char* mem = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &mem, &size);
  c.image_width = w;
  c.image_height = h;
  c.input_components = 3;
  c.in_color_space = JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 98, TRUE);
  jpeg_start_compress(&c, TRUE);
  std::vector<std::uint8_t> row(static_cast<std::size_t>(w) * 3);
  for (int x = 0; x < w; ++x) row[x * 3] = r, row[x * 3 + 1] = g, row[x * 3 + 2] = b;
  while (c.next_scanline < c.image_height) {
    JSAMPROW rows[1] = {row.data()};
    jpeg_write_scanlines(&c, rows, 1);
  }
  jpeg_finish_compress(&c);
  std::vector<std::uint8_t> out(mem, mem + size);
  jpeg_destroy_compress(&c);
  std::free(mem);
  return out;
}

bool decodes(const std::vector<std::uint8_t>& bytes, image::Rgba8* out, std::string* why) {
  return image::decode(bytes.data(), bytes.size(), out, why);
}

TEST(TextureImage, APngDecodesToItsTexelsWhateverItsChannels) {
  const std::vector<std::uint8_t> rgba = {255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110, 120};
  image::Rgba8 img;
  std::string why;
  ASSERT_TRUE(decodes(pngOf(3, 2, PNG_FORMAT_RGBA, rgba), &img, &why)) << why;
  EXPECT_EQ(img.width, 3u);
  EXPECT_EQ(img.height, 2u);
  EXPECT_EQ(img.texels, rgba);
  // Grey becomes RGB with alpha 255.
  ASSERT_TRUE(decodes(pngOf(2, 1, PNG_FORMAT_GRAY, {7, 200}), &img, &why)) << why;
  EXPECT_EQ(img.texels, (std::vector<std::uint8_t>{7, 7, 7, 255, 200, 200, 200, 255}));
  // And RGB gets alpha 255.
  ASSERT_TRUE(decodes(pngOf(1, 1, PNG_FORMAT_RGB, {1, 2, 3}), &img, &why)) << why;
  EXPECT_EQ(img.texels, (std::vector<std::uint8_t>{1, 2, 3, 255}));
}

TEST(TextureImage, AJpegDecodesToItsColourWithinItsQuantization) {
  image::Rgba8 img;
  std::string why;
  ASSERT_TRUE(decodes(jpegOf(16, 8, 200, 100, 50), &img, &why)) << why;
  ASSERT_EQ(img.width, 16u);
  ASSERT_EQ(img.height, 8u);
  for (std::size_t i = 0; i < img.texels.size(); i += 4) {
    EXPECT_NEAR(img.texels[i], 200, 3);
    EXPECT_NEAR(img.texels[i + 1], 100, 3);
    EXPECT_NEAR(img.texels[i + 2], 50, 3);
    EXPECT_EQ(img.texels[i + 3], 255);
  }
}

TEST(TextureImage, BrokenFilesAreRefusedWithAReason) {
  image::Rgba8 img;
  std::string why;
  EXPECT_FALSE(decodes({}, &img, &why));
  EXPECT_EQ(why, "an empty file");
  EXPECT_FALSE(decodes({'G', 'I', 'F', '8', '9', 'a', 0, 0}, &img, &why));
  EXPECT_NE(why.find("not a PNG or JPEG"), std::string::npos) << why;
  std::vector<std::uint8_t> png = pngOf(8, 8, PNG_FORMAT_RGBA, std::vector<std::uint8_t>(8 * 8 * 4, 90));
  png.resize(png.size() - 30);  // into the image data
  EXPECT_FALSE(decodes(png, &img, &why));
  EXPECT_NE(why.find("a corrupt PNG"), std::string::npos) << why;
  std::vector<std::uint8_t> jpeg = jpegOf(64, 64, 1, 2, 3);
  jpeg.resize(200);
  EXPECT_FALSE(decodes(jpeg, &img, &why));
  EXPECT_NE(why.find("JPEG"), std::string::npos) << why;
  std::vector<std::uint8_t> header = jpegOf(8, 8, 1, 2, 3);
  header.resize(4);  // the signature and nothing else
  EXPECT_FALSE(decodes(header, &img, &why));
  EXPECT_NE(why.find("a corrupt JPEG"), std::string::npos) << why;
}

TEST(TextureImage, AnOversizedImageIsRefusedFromItsHeader) {
  // A 1 x 1 PNG whose IHDR is rewritten to 100000 x 100000 (CRC recomputed):
  // refused before a texel is decoded.
  std::vector<std::uint8_t> png = pngOf(1, 1, PNG_FORMAT_RGBA, {1, 2, 3, 4});
  auto put32 = [&](std::size_t at, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) png[at + i] = static_cast<std::uint8_t>(v >> (24 - 8 * i));
  };
  put32(16, 100000);  // width, after the signature, the length and "IHDR"
  put32(20, 100000);
  put32(29, static_cast<std::uint32_t>(crc32(0, png.data() + 12, 17)));
  image::Rgba8 img;
  std::string why;
  EXPECT_FALSE(decodes(png, &img, &why));
  EXPECT_NE(why.find("larger than the limit"), std::string::npos) << why;
  EXPECT_TRUE(img.texels.empty());
}

TEST(TextureImage, SrgbTexelsAreDecodedToLinearAndAlphaStaysLinear) {
  image::Rgba8 img{1, 1, {188, 188, 255, 188}};
  const image::MipChain srgb = image::mipChain(img, true), linear = image::mipChain(img, false);
  EXPECT_NEAR(srgb.levels[0][0], 0.5029, 1e-4);  // sRGB 188 is linear 0.503
  EXPECT_NEAR(srgb.levels[0][2], 1.0, 1e-6);
  EXPECT_NEAR(srgb.levels[0][3], 188 / 255.0, 1e-6);
  EXPECT_NEAR(linear.levels[0][0], 188 / 255.0, 1e-6);
}

TEST(TextureImage, TheMipChainHalvesDownToOneTexelAndKeepsTheMean) {
  image::Rgba8 img{4, 4, {}};
  for (int i = 0; i < 16; ++i) img.texels.insert(img.texels.end(), {static_cast<std::uint8_t>(i * 16), 0, 255, 255});
  const image::MipChain m = image::mipChain(img, false);
  ASSERT_EQ(m.levels.size(), 3u);
  EXPECT_EQ(m.widths, (std::vector<std::uint32_t>{4, 2, 1}));
  double mean0 = 0;
  for (int i = 0; i < 16; ++i) mean0 += m.levels[0][i * 4] / 16.0;
  EXPECT_NEAR(m.levels[2][0], mean0, 1e-6);
  // Odd sizes: 5 x 3 -> 2 x 1 -> 1 x 1, each level's texel count right.
  image::Rgba8 odd{5, 3, std::vector<std::uint8_t>(5 * 3 * 4, 100)};
  const image::MipChain o = image::mipChain(odd, true);
  EXPECT_EQ(o.widths, (std::vector<std::uint32_t>{5, 2, 1}));
  EXPECT_EQ(o.heights, (std::vector<std::uint32_t>{3, 1, 1}));
  for (std::size_t l = 0; l < o.levels.size(); ++l) EXPECT_EQ(o.levels[l].size(), o.widths[l] * o.heights[l] * 4u);
  EXPECT_NEAR(o.levels[2][0], image::srgbToLinear(100 / 255.0), 1e-6);
}

// ---------------------------------------------------------------- binding a material's textures

/// A scratch directory with a 2 x 2 PNG of `rgb` at `name`.
struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("substratec_texture_test_" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() { fs::remove_all(dir); }
  std::string png(const std::string& name, std::uint8_t r, std::uint8_t g, std::uint8_t b) const {
    const fs::path p = dir / name;
    fs::create_directories(p.parent_path());
    const std::vector<std::uint8_t> bytes = pngOf(2, 2, PNG_FORMAT_RGB, {r, g, b, r, g, b, r, g, b, r, g, b});
    std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    return p.string();
  }
};

/// A material whose albedo samples `albedo` (an input object) and whose normal samples the input `bumps`.
Material textured(const std::string& albedo) {
  return test::buildMaterial(test::material(
      R"("a": {"kind": "texture", "texture": "$albedo"},
         "n": {"kind": "texture", "texture": "$bumps"},
         "root": {"kind": "slab", "diffuse_albedo": "a", "normal": "n"})",
      R"({"albedo": )" + albedo + R"(, "bumps": {"type": "texture2d"}})"));
}

TEST(TextureBinding, AnInputsFileIsFoundBesideTheMaterialAndDecodedByItsColourSpace) {
  Scratch s;
  s.png("maps/green.png", 0, 188, 0);
  const Material m = textured(R"({"type": "texture2d", "colorspace": "srgb", "file": "maps/green.png"})");
  EXPECT_EQ(m.inputs[0].file, "maps/green.png");
  EXPECT_TRUE(m.inputs[0].srgb);
  preview::TextureSources sources;
  sources.baseDir = s.dir.string();
  preview::BoundTextures bound;
  Diagnostics d("m.json");
  ASSERT_TRUE(preview::bindTextures(m, sources, &bound, d)) << d.formatAll();
  const gpu::ImageResource& albedo = bound.images.at("albedo");
  EXPECT_EQ(albedo.width, 2u);
  EXPECT_EQ(albedo.mips.size(), 2u);
  EXPECT_NEAR(albedo.mips[0][1], 0.5029, 1e-4);
  EXPECT_EQ(albedo.mips[0][0], 0.0f);
  // The normal map has no image: its flat texel, and a note that says so.
  const gpu::ImageResource& bumps = bound.images.at("bumps");
  EXPECT_EQ(bumps.mips[0], (std::vector<float>{0.5f, 0.5f, 1.0f, 1.0f}));
  EXPECT_EQ(bound.sources.at("bumps"), "neutral");
  EXPECT_NE(d.formatAll().find("note: texture input \"bumps\" has no image: bound to its neutral texel (0.5, 0.5, 1, 1)"),
            std::string::npos)
      << d.formatAll();
  EXPECT_FALSE(d.hasErrors());
}

TEST(TextureBinding, TheCommandLinesImageWinsAndASearchPathFindsAPrefixedFile) {
  Scratch s;
  const std::string red = s.png("red.png", 255, 0, 0);
  s.png("library/Images/wood.png", 10, 20, 30);
  const Material m = textured(R"({"type": "texture2d", "file": "../../../Images/wood.png"})");
  preview::TextureSources sources;
  sources.baseDir = (s.dir / "documents").string();
  sources.searchPaths = {(s.dir / "nowhere").string(), (s.dir / "library").string()};
  preview::BoundTextures bound;
  Diagnostics d("m.json");
  ASSERT_TRUE(preview::bindTextures(m, sources, &bound, d)) << d.formatAll();
  EXPECT_EQ(bound.sources.at("albedo"), (s.dir / "library/Images/wood.png").string());
  EXPECT_NEAR(bound.images.at("albedo").mips[0][0], 10 / 255.0, 1e-6);  // linear: as stored
  sources.overrides = {{"albedo", red}};
  preview::BoundTextures overridden;
  ASSERT_TRUE(preview::bindTextures(m, sources, &overridden, d)) << d.formatAll();
  EXPECT_EQ(overridden.sources.at("albedo"), red);
  EXPECT_EQ(overridden.images.at("albedo").mips[0][0], 1.0f);
}

TEST(TextureBinding, AMissingOrBrokenImageIsAnErrorAtTheInputsFile) {
  Scratch s;
  std::ofstream(s.dir / "broken.png", std::ios::binary) << "\x89PNG\r\n\x1a\nnot really";
  const std::string json = test::material(R"("a": {"kind": "texture", "texture": "$albedo"},
      "root": {"kind": "slab", "diffuse_albedo": "a"})",
                                          R"({"albedo": {"type": "texture2d", "file": "missing.png"}})");
  const Material missing = test::buildMaterial(json);
  preview::TextureSources sources;
  sources.baseDir = s.dir.string();
  preview::BoundTextures bound;
  Diagnostics d("m.json");
  EXPECT_FALSE(preview::bindTextures(missing, sources, &bound, d));
  EXPECT_NE(d.formatAll().find("error: texture input \"albedo\": cannot use the image \"missing.png\""), std::string::npos)
      << d.formatAll();
  EXPECT_NE(d.formatAll().find("no such file"), std::string::npos) << d.formatAll();
  EXPECT_NE(d.formatAll().find("[/inputs/albedo/file]"), std::string::npos) << d.formatAll();
  Material broken = missing;
  broken.inputs[0].file = "broken.png";
  Diagnostics d2("m.json");
  EXPECT_FALSE(preview::bindTextures(broken, sources, &bound, d2));
  EXPECT_NE(d2.formatAll().find("a corrupt PNG"), std::string::npos) << d2.formatAll();
  // An image named for an input the material does not have.
  sources.overrides = {{"albedoo", "x.png"}};
  Diagnostics d3("m.json");
  EXPECT_FALSE(preview::bindTextures(test::buildMaterial(json), sources, &bound, d3));
  EXPECT_NE(d3.formatAll().find("--texture albedoo=x.png: the material has no texture input \"albedoo\" (its texture "
                                "inputs: albedo)"),
            std::string::npos)
      << d3.formatAll();
}

TEST(TextureBinding, AnInputsWrapAndFilterAreHowItsImageIsBound) {
  Scratch s;
  s.png("a.png", 1, 2, 3);
  const Material m = textured(R"({"type": "texture2d", "file": "a.png", "wrap": ["clamp", "mirror"], "filter": "nearest"})");
  EXPECT_EQ(m.inputs[0].wrapU, Wrap::Clamp);
  EXPECT_EQ(m.inputs[0].wrapV, Wrap::Mirror);
  EXPECT_TRUE(m.inputs[0].nearest);
  preview::TextureSources sources;
  sources.baseDir = s.dir.string();
  preview::BoundTextures bound;
  Diagnostics d("m.json");
  ASSERT_TRUE(preview::bindTextures(m, sources, &bound, d)) << d.formatAll();
  const gpu::ImageResource& img = bound.images.at("albedo");
  EXPECT_EQ(img.address, gpu::Address::ClampToEdge);
  EXPECT_EQ(img.addressV, gpu::Address::MirroredRepeat);
  EXPECT_EQ(img.filter, gpu::Filter::Nearest);
  // One mode for both axes; a bad mode is an error at its pointer.
  const Material one = textured(R"({"type": "texture2d", "wrap": "mirror"})");
  EXPECT_EQ(one.inputs[0].wrapU, Wrap::Mirror);
  EXPECT_EQ(one.inputs[0].wrapV, Wrap::Mirror);
  EXPECT_NE(test::diagnosticsOf(test::material(R"("a": {"kind": "texture", "texture": "$t"},
      "root": {"kind": "slab", "diffuse_albedo": "a"})",
                                               R"({"t": {"type": "texture2d", "wrap": "border"}})"))
                .find("expected \"repeat\", \"clamp\" or \"mirror\", or an array of two (u, v), got \"border\" "
                      "[/inputs/t/wrap]"),
            std::string::npos);
}

TEST(TextureBinding, FileIsAStringOnATextureInputOnly) {
  EXPECT_NE(test::diagnosticsOf(test::material(R"("root": {"kind": "slab", "roughness": "$r"})",
                                               R"({"r": {"type": "float", "default": 0.5, "file": "r.png"}})"))
                .find("\"file\" applies to texture2d inputs only"),
            std::string::npos);
  EXPECT_NE(test::diagnosticsOf(test::material(R"("a": {"kind": "texture", "texture": "$t"},
      "root": {"kind": "slab", "diffuse_albedo": "a"})",
                                               R"({"t": {"type": "texture2d", "file": ""}})"))
                .find("expected an image path (a non-empty string), got \"\""),
            std::string::npos);
}

}  // namespace
}  // namespace substratec
