// Radiance HDR images (.hdr, RGBE, flat or run-length encoded), decoded by
// Debian's stb_image (libstb-dev) to linear floats: the environments that
// `preview` and `render` light with (`--env FILE.hdr`, docs/render.md).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace substratec::image {

/// Linear RGB radiance, 3 floats a texel, row-major, top row first.
struct RgbF {
  std::uint32_t width = 0, height = 0;
  std::vector<float> rgb;  // width * height * 3
};

/// Decodes Radiance HDR `bytes`. The size is read from the header first and
/// refused beyond the decoders' limits (sizeAllowed) before any pixel is
/// decoded; a texel that decodes to a non-finite or negative value is an
/// error. False, with `*why`, for anything else than a well-formed Radiance
/// file (its signature is "#?RADIANCE" or "#?RGBE").
bool decodeRadiance(const std::uint8_t* bytes, std::size_t size, RgbF* out, std::string* why);

/// Reads (readImageFile) and decodes the Radiance file at `path`.
bool loadRadiance(const std::string& path, RgbF* out, std::string* why);

}  // namespace substratec::image
