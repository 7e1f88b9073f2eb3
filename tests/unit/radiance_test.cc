// Radiance HDR environments (`--env FILE.hdr`, docs/render.md): the decoder
// (stb_image's, image/radiance.h) and the lat-long environment built on it
// (preview/environment.h).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../radiance_writer.h"
#include "image/radiance.h"
#include "preview/environment.h"

namespace substratec {
namespace {

std::string readSeed(const char* name) {
  std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/fuzz/image_seeds/" + name, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  EXPECT_FALSE(s.str().empty()) << name;
  return s.str();
}

image::RgbF decoded(const std::string& file, std::string* why) {
  image::RgbF img;
  const bool ok =
      image::decodeRadiance(reinterpret_cast<const std::uint8_t*>(file.data()), file.size(), &img, why);
  return ok ? img : image::RgbF{};
}

TEST(RadianceImage, FlatAndRunLengthFilesDecodeToTheirRadiance) {
  std::vector<float> rgb;
  for (int i = 0; i < 16 * 4; ++i) rgb.insert(rgb.end(), {0.5f * (i % 4), 0.25f, 2.0f * (i % 2)});
  for (bool rle : {false, true}) {
    SCOPED_TRACE(rle ? "run-length" : "flat");
    std::string why;
    const image::RgbF img = decoded(testutil::radianceFile(16, 4, rgb, rle), &why);
    ASSERT_EQ(img.width, 16u) << why;
    ASSERT_EQ(img.height, 4u);
    EXPECT_EQ(img.rgb, rgb);  // these values survive RGBE exactly
  }
}

TEST(RadianceImage, BrokenFilesAreRefusedWithAReason) {
  const std::string good = testutil::constantRadianceFile(16, 4, 1, 1, 1, true);
  // A span of length 0 where the first scanline's first span starts: stb_image
  // looped forever on it (and on every truncated run-length file).
  std::string zeroRun = good;
  zeroRun[good.find("+X 16\n") + 6 + 4] = 0;
  const struct {
    const char* what;
    std::string bytes;
    const char* reason;
  } cases[] = {
      {"empty", "", "empty"},
      {"a PNG", "\x89PNG\r\n\x1a\n rest", "not a Radiance"},
      {"truncated pixels", good.substr(0, good.size() - 20), "truncated"},
      {"truncated flat pixels", testutil::constantRadianceFile(4, 4, 1, 1, 1).substr(0, 70), "truncated"},
      {"a run of length 0", zeroRun, "a run of length 0 in scanline 0"},
      // image_fuzzer's first timeout: a header line of NULs is an empty line
      // to stb_image, so its pixels start two lines later than a search for
      // "\n\n" said, and their zero-length span looped.
      {"a header line of NULs", readSeed("nul_header.hdr"), "a run of length 0 in scanline 0"},
      {"no size line", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n", "corrupt"},
      {"a size beyond the limit", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000 +X 100000\n", "limit"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    std::string why;
    image::RgbF img;
    EXPECT_FALSE(image::decodeRadiance(reinterpret_cast<const std::uint8_t*>(c.bytes.data()), c.bytes.size(), &img,
                                       &why));
    EXPECT_NE(why.find(c.reason), std::string::npos) << why;
  }
}

TEST(LatLongEnvironment, TheTopRowIsUpAndTheMiddleColumnIsAwayFromTheCamera) {
  // 64 x 32: the top half radiance (1, 0, 0), the bottom half (0, 0, 1), and
  // the middle column (u = 0.5) of the top half (0, 1, 0).
  const int w = 64, h = 32;
  std::vector<float> rgb;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (y >= h / 2) rgb.insert(rgb.end(), {0, 0, 1});
      else if (x == w / 2 - 1 || x == w / 2) rgb.insert(rgb.end(), {0, 1, 0});
      else rgb.insert(rgb.end(), {1, 0, 0});
    }
  std::string why;
  const preview::Environment env = preview::latLongEnvironment("test.hdr", decoded(testutil::radianceFile(w, h, rgb), &why));
  const auto up = env.radiance({0, 1, 0}), down = env.radiance({0, -1, 0});
  EXPECT_NEAR(up[0], 1, 1e-6);
  EXPECT_NEAR(down[2], 1, 1e-6);
  const double s = std::sqrt(0.5);
  const auto away = env.radiance({0, s, -s}), toward = env.radiance({0, s, s}), right = env.radiance({s, s, 0});
  EXPECT_NEAR(away[1], 1, 1e-6) << "u = 0.5 is -Z";
  EXPECT_NEAR(toward[0], 1, 1e-6);
  EXPECT_NEAR(right[0], 1, 1e-6);
  const auto uv = preview::latLongCoordinates({s, 0, -s});
  EXPECT_NEAR(uv[0], 0.625, 1e-12) << "u grows toward +X";
  EXPECT_NEAR(uv[1], 0.5, 1e-12);
}

TEST(LatLongEnvironment, ALargeImageIsAveragedDownKeepingItsMeanAndItsSun) {
  // 2048 x 1024, black but for one texel of radiance 1e6: averaged down to
  // 512 x 256, the sun becomes a 4 x 4 block's mean, 1e6 / 16, in one texel.
  const int w = 2048, h = 1024;
  image::RgbF img;
  img.width = w;
  img.height = h;
  img.rgb.assign(std::size_t{w} * h * 3, 0.0f);
  const int sx = 1029, sy = 301;
  for (int c = 0; c < 3; ++c) img.rgb[(std::size_t{sy} * w + sx) * 3 + c] = 1e6f;
  const preview::Environment env = preview::latLongEnvironment("big.hdr", img);
  // The direction of the reduced texel's centre (sx / 4, sy / 4).
  const double u = (sx / 4 + 0.5) / 512, v = (sy / 4 + 0.5) / 256;
  const double phi = (u - 0.5) * 2 * M_PI, theta = v * M_PI;
  const std::array<double, 3> d{std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
  EXPECT_NEAR(env.radiance(d)[0], 1e6 / 16, 1.0);
}

TEST(EnvironmentFile, OnlyHdrPathsAreFilesAndAMissingOneThrowsWithItsPath) {
  EXPECT_TRUE(preview::isEnvironmentFile("a/b/Goegap.HDR"));
  EXPECT_FALSE(preview::isEnvironmentFile("studio"));
  EXPECT_FALSE(preview::isEnvironmentFile(".hdr"));
  try {
    preview::makeEnvironment("/nonexistent/sky.hdr");
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/sky.hdr: no such file");
  }
}

}  // namespace
}  // namespace substratec
