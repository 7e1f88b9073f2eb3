// Radiance HDR files written for tests (docs/render.md, `--env FILE.hdr`):
// RGBE texels, flat or with the "new" per-channel run-length scanlines,
// under the header every writer puts first. Values that are powers of two
// times an 8-bit mantissa (1, 0.5, 2, 0.25…) survive RGBE exactly.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace substratec::testutil {

inline void rgbe(const float* rgb, std::uint8_t* out) {
  const float v = std::max(rgb[0], std::max(rgb[1], rgb[2]));
  if (v < 1e-32f) {
    out[0] = out[1] = out[2] = out[3] = 0;
    return;
  }
  int e = 0;
  const float scale = std::frexp(v, &e) * 256.0f / v;
  for (int c = 0; c < 3; ++c) out[c] = static_cast<std::uint8_t>(rgb[c] * scale);
  out[3] = static_cast<std::uint8_t>(e + 128);
}

/// `rgb` (width * height * 3 floats, top row first) as a Radiance file:
/// flat texels, or run-length scanlines (literal runs only, which every
/// reader accepts) when `rle` and 8 <= width < 32768.
inline std::string radianceFile(int width, int height, const std::vector<float>& rgb, bool rle = false) {
  std::string out = "#?RADIANCE\n# substratec test\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(height) +
                    " +X " + std::to_string(width) + "\n";
  for (int y = 0; y < height; ++y) {
    std::vector<std::uint8_t> row(static_cast<std::size_t>(width) * 4);
    for (int x = 0; x < width; ++x) rgbe(&rgb[(static_cast<std::size_t>(y) * width + x) * 3], &row[x * 4]);
    if (!rle || width < 8 || width >= 32768) {
      out.append(row.begin(), row.end());
      continue;
    }
    out += {char(2), char(2), char(width >> 8), char(width & 255)};
    for (int c = 0; c < 4; ++c)
      for (int x = 0; x < width; x += 128) {
        const int n = std::min(128, width - x);
        out += static_cast<char>(n);
        for (int i = 0; i < n; ++i) out += static_cast<char>(row[(x + i) * 4 + c]);
      }
  }
  return out;
}

/// A width x height image of one radiance.
inline std::string constantRadianceFile(int width, int height, float r, float g, float b, bool rle = false) {
  std::vector<float> rgb;
  for (int i = 0; i < width * height; ++i) rgb.insert(rgb.end(), {r, g, b});
  return radianceFile(width, height, rgb, rle);
}

}  // namespace substratec::testutil
