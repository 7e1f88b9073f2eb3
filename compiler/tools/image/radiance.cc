#include "image/radiance.h"

#include <climits>
#include <cmath>
#include <memory>

#include "image/decode.h"
#include "image/stb_image_hdr.h"

namespace substratec::image {

namespace {

/// Moves `pos` past one header line as stb_image's stbi__hdr_gettoken reads
/// it (up to '\n'; at most 1023 bytes kept, the rest skipped to the '\n'),
/// and says whether stb_image reads it as empty: its first byte is '\n' or
/// '\0', or the data ends after it. (A line of NULs ends the header: the
/// fuzzer's first timeout, fuzz/image_seeds/nul_header.hdr.)
bool stbHeaderLine(const std::uint8_t* b, std::size_t size, std::size_t& pos) {
  auto get8 = [&]() -> std::uint8_t { return pos < size ? b[pos++] : 0; };
  std::uint8_t c = get8();
  const bool empty = c == 0 || c == '\n' || pos >= size;
  std::size_t len = 0;
  while (pos < size && c != '\n') {
    if (++len == 1023) {
      while (pos < size && get8() != '\n') {
      }
      break;
    }
    c = get8();
  }
  return empty;
}

/// stb_image's run-length decoder loops forever on a run of length 0, and a
/// truncated file reads as one (its reader returns 0 past the end): found by
/// RadianceImage.BrokenFilesAreRefusedWithAReason. So the pixel stream is
/// walked here first, as stb_image will read it (flat texels when the width
/// is outside 8…32767 or a scanline does not open with 2, 2; else four
/// channels of runs and literal spans a scanline), and a stream with a run of
/// length 0 or that ends early is refused. What else stb_image finds corrupt
/// (a scanline of another width, a span past the scanline) it refuses itself.
bool checkPixelStream(const std::uint8_t* b, std::size_t size, std::size_t w, std::size_t h, std::string* why) {
  // Where stb_image's pixels start: the signature line, header lines up to
  // the first one it reads as empty, the resolution line (stbi__hdr_load).
  std::size_t pos = 0;
  stbHeaderLine(b, size, pos);
  for (std::size_t line = 0; line < size && !stbHeaderLine(b, size, pos); ++line) {
  }
  stbHeaderLine(b, size, pos);
  auto truncated = [&] {
    *why = "a truncated Radiance image (its pixels end early)";
    return false;
  };
  const bool flatAll = w < 8 || w >= 32768;
  for (std::size_t row = 0; row < h; ++row) {
    if (flatAll || size - pos < 4 || b[pos] != 2 || b[pos + 1] != 2 || (b[pos + 2] & 0x80))
      return size - pos >= w * h * 4 ? true : truncated();  // stb_image reads w * h flat texels from here
    if (((std::size_t{b[pos + 2]} << 8) | b[pos + 3]) != w) return true;  // stb_image refuses the scanline
    pos += 4;
    for (int channel = 0; channel < 4; ++channel)
      for (std::size_t x = 0; x < w;) {  // each step consumes >= 1 texel
        if (pos >= size) return truncated();
        std::size_t count = b[pos++];
        if (count > 128) {
          count -= 128;
          if (pos >= size) return truncated();
          ++pos;
        } else if (count == 0) {
          *why = "a corrupt Radiance image (a run of length 0 in scanline " + std::to_string(row) + ")";
          return false;
        } else {
          if (size - pos < count) return truncated();
          pos += count;
        }
        if (count > w - x) return true;  // stb_image refuses the span
        x += count;
      }
  }
  return true;
}

}  // namespace

bool decodeRadiance(const std::uint8_t* bytes, std::size_t size, RgbF* out, std::string* why) {
  if (size == 0) {
    *why = "an empty file";
    return false;
  }
  if (size > static_cast<std::size_t>(INT_MAX) || size > kMaxImageFileBytes) {
    *why = "a file of " + std::to_string(size) + " bytes, larger than the limit";
    return false;
  }
  const int n = static_cast<int>(size);
  if (!stb::isHdr(bytes, n)) {
    *why = "not a Radiance HDR image (it does not start with \"#?RADIANCE\" or \"#?RGBE\")";
    return false;
  }
  int w = 0, h = 0;
  if (!stb::info(bytes, n, &w, &h)) {
    *why = std::string("a corrupt Radiance header (") + stb::failureReason() + ")";
    return false;
  }
  if (w < 0 || h < 0 || !sizeAllowed(static_cast<std::uint64_t>(w), static_cast<std::uint64_t>(h), why)) {
    if (w < 0 || h < 0) *why = "a corrupt Radiance header (a negative size)";
    return false;
  }
  if (!checkPixelStream(bytes, size, static_cast<std::size_t>(w), static_cast<std::size_t>(h), why)) return false;
  std::unique_ptr<float, void (*)(float*)> pixels(stb::loadRgb(bytes, n, &w, &h), stb::release);
  if (!pixels) {
    *why = std::string("a corrupt Radiance image (") + stb::failureReason() + ")";
    return false;
  }
  out->width = static_cast<std::uint32_t>(w);
  out->height = static_cast<std::uint32_t>(h);
  out->rgb.assign(pixels.get(), pixels.get() + static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < out->rgb.size(); ++i)
    if (!std::isfinite(out->rgb[i]) || out->rgb[i] < 0) {
      *why = "texel " + std::to_string(i / 3 % out->width) + ", " + std::to_string(i / 3 / out->width) +
             " is not a finite radiance >= 0";
      return false;
    }
  return true;
}

bool loadRadiance(const std::string& path, RgbF* out, std::string* why) {
  std::vector<std::uint8_t> bytes;
  return readImageFile(path, &bytes, why) && decodeRadiance(bytes.data(), bytes.size(), out, why);
}

}  // namespace substratec::image
