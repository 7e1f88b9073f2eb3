// Tone mapping, sRGB encoding and PNG output of preview images (image.h).
#include "preview/image.h"

#include <png.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace substratec::preview {

Image::Image(int w, int h, std::array<float, 4> fill) : width(w), height(h) {
  rgba.resize(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < rgba.size(); ++i) rgba[i] = fill[i % 4];
}

namespace {

/// The shoulder of the Khronos PBR Neutral tone mapper (Khronos 3D Commerce,
/// 2024) on one exposed pixel, in place: identity up to a peak channel of
/// 0.76, then a hue-preserving shoulder that desaturates toward white. (PBR
/// Neutral also subtracts up to 0.04 from every channel, the dielectric
/// Fresnel a base colour gains under a white furnace; a preview keeps it, so
/// that a Lambertian lands on its albedo and a dielectric shows its sheen.)
/// NaN channels stay NaN; negatives count as 0 and +inf as 1e30.
void neutralShoulder(float* rgb) {
  constexpr double kStartCompression = 0.8 - 0.04, kDesaturation = 0.15;
  double c[3];
  for (int i = 0; i < 3; ++i) c[i] = std::isnan(rgb[i]) ? 0.0 : std::clamp(static_cast<double>(rgb[i]), 0.0, 1e30);
  const double peak = std::max({c[0], c[1], c[2]});
  if (peak >= kStartCompression) {
    const double d = 1.0 - kStartCompression;
    const double newPeak = 1.0 - d * d / (peak + d - kStartCompression);
    const double g = 1.0 - 1.0 / (kDesaturation * (peak - newPeak) + 1.0);
    for (double& v : c) v = (v * newPeak / peak) * (1.0 - g) + newPeak * g;
  }
  for (int i = 0; i < 3; ++i)
    if (!std::isnan(rgb[i])) rgb[i] = static_cast<float>(std::clamp(c[i], 0.0, 1.0));
}

/// round(255 clamp(v)); `srgb` applies the OETF first.
uint8_t quantize(float value, bool srgb) {
  double v = value;
  v = v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
  if (srgb) v = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::floor(v * 255.0 + 0.5));
}

bool fail(Diagnostics& diags, std::string message) {
  diags.fail(std::move(message));
  return false;
}

}  // namespace

Image tonemap(const Image& hdr, double exposure, const std::array<double, 3>& gains) {
  Image out = hdr;
  const double scale = std::exp2(exposure);
  for (size_t p = 0; p + 3 < out.rgba.size(); p += 4) {
    for (int c = 0; c < 3; ++c) out.rgba[p + c] = static_cast<float>(out.rgba[p + c] * (scale * gains[c]));
    neutralShoulder(&out.rgba[p]);
  }
  return out;
}

Srgb8 encodeSrgb8(const Image& img) {
  Srgb8 out;
  out.rgba.resize(img.rgba.size());
  for (size_t p = 0; p + 3 < img.rgba.size(); p += 4) {
    bool nan = false;
    for (size_t c = 0; c < 4; ++c) {
      float v = img.rgba[p + c];
      if (std::isnan(v)) {
        nan = true;
        v = 0.0f;
      }
      out.rgba[p + c] = quantize(v, c != 3);
    }
    if (nan) ++out.nanCount;
  }
  return out;
}

bool encodePng(int w, int h, const std::vector<uint8_t>& rgba8, std::vector<uint8_t>& png, Diagnostics& diags) {
  if (w < 1 || h < 1 || rgba8.size() != static_cast<size_t>(w) * h * 4)
    return fail(diags, "PNG of " + std::to_string(w) + "x" + std::to_string(h) + " pixels needs " +
                           std::to_string(static_cast<size_t>(w > 0 ? w : 0) * (h > 0 ? h : 0) * 4) + " bytes, got " +
                           std::to_string(rgba8.size()));
  // libpng's simplified API: 8-bit sRGB output writes an sRGB chunk and never
  // a tIME chunk; the first call sizes the buffer.
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(w);
  image.height = static_cast<png_uint_32>(h);
  image.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&image, nullptr, &size, 0, rgba8.data(), 0, nullptr))
    return fail(diags, std::string("libpng: ") + image.message);
  png.resize(size);
  if (!png_image_write_to_memory(&image, png.data(), &size, 0, rgba8.data(), 0, nullptr))
    return fail(diags, std::string("libpng: ") + image.message);
  png.resize(size);
  return true;
}

bool writePng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba8, Diagnostics& diags) {
  std::vector<uint8_t> png;
  Diagnostics encoding(path);
  if (!encodePng(w, h, rgba8, png, encoding))
    return fail(diags, "cannot encode '" + path + "': " + encoding.errorMessages());
  namespace fs = std::filesystem;
  fs::path target(path);
  fs::path dir = target.parent_path();
  std::string tmpl = ((dir.empty() ? fs::path(".") : dir) / ("." + target.filename().string() + ".tmpXXXXXX")).string();
  int fd = ::mkstemp(tmpl.data());
  if (fd < 0) return fail(diags, "cannot write '" + path + "': " + std::strerror(errno));
  // mkstemp creates 0600; a PNG is an ordinary readable file.
  ::fchmod(fd, 0644);
  size_t done = 0;
  while (done < png.size()) {
    ssize_t n = ::write(fd, png.data() + done, png.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::string message = std::strerror(n < 0 ? errno : EIO);
      ::close(fd);
      ::unlink(tmpl.c_str());
      return fail(diags, "cannot write '" + path + "': " + message);
    }
    done += static_cast<size_t>(n);
  }
  if (::close(fd) != 0) {
    std::string message = std::strerror(errno);
    ::unlink(tmpl.c_str());
    return fail(diags, "cannot write '" + path + "': " + message);
  }
  if (::rename(tmpl.c_str(), path.c_str()) != 0) {
    std::string message = std::strerror(errno);
    ::unlink(tmpl.c_str());
    return fail(diags, "cannot rename into '" + path + "': " + message);
  }
  return true;
}

}  // namespace substratec::preview
