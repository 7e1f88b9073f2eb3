// Images of `substratec preview`: linear RGBA32F pixels, the tone curve that
// takes them to display range, the sRGB 8-bit encoding, and PNG output.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "diag/diagnostics.h"

namespace substratec::preview {

/// Linear RGBA32F pixels, row-major, top row first.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgba;

  Image() = default;
  /// A width x height image filled with `fill`.
  Image(int w, int h, std::array<float, 4> fill = {0.0f, 0.0f, 0.0f, 1.0f});
  float* pixel(int x, int y) { return rgba.data() + (static_cast<size_t>(y) * width + x) * 4; }
  const float* pixel(int x, int y) const { return rgba.data() + (static_cast<size_t>(y) * width + x) * 4; }
};

/// Display-referred linear RGB in [0, 1]: each channel times 2^exposure and
/// its gain (white balance), then the shoulder of the Khronos PBR Neutral tone
/// mapper per pixel: below a peak channel of 0.76 nothing changes (so a
/// colour in range comes out as itself); above, the peak goes to
/// 1 − 0.24² / (peak − 0.52) and the pixel toward white by
/// 1 − 1 / (0.15 (peak − new peak) + 1). Negative values count as 0, +inf as
/// a huge value (→ 1); a NaN channel stays NaN (so encodeSrgb8 can count it).
/// Alpha is kept. (docs/textures.md, "Honest previews")
Image tonemap(const Image& hdr, double exposure, const std::array<double, 3>& gains = {1, 1, 1});

/// 8-bit sRGB pixels and how many pixels had a NaN channel.
struct Srgb8 {
  std::vector<uint8_t> rgba;  // width * height * 4, row-major, top row first
  size_t nanCount = 0;        // pixels with at least one NaN channel
};

/// RGB through the exact sRGB OETF (12.92 v for v <= 0.0031308, else
/// 1.055 v^(1/2.4) - 0.055), alpha linear; clamped to [0, 1], then
/// round(255 v). NaN channels become 0 and are counted.
Srgb8 encodeSrgb8(const Image& img);

/// A PNG (8-bit RGBA, sRGB chunk, no time chunk: the same pixels always give
/// the same bytes) of w x h pixels `rgba8`. Returns false, reporting why, for
/// a size mismatch or a libpng failure.
bool encodePng(int w, int h, const std::vector<uint8_t>& rgba8, std::vector<uint8_t>& png, Diagnostics& diags);

/// encodePng written to `path` through a temporary file in the same directory
/// renamed into place: on failure nothing is left behind and an existing file
/// at `path` is untouched. Returns false, reporting why.
bool writePng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba8, Diagnostics& diags);

}  // namespace substratec::preview
