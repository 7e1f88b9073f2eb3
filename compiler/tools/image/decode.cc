#include "image/decode.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <png.h>
// jpeglib.h needs size_t and FILE declared before it.
#include <jpeglib.h>

namespace substratec::image {

namespace {

bool isPng(const std::uint8_t* b, std::size_t n) {
  static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  return n >= 8 && std::memcmp(b, kSignature, 8) == 0;
}

bool isJpeg(const std::uint8_t* b, std::size_t n) { return n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF; }

}  // namespace

bool sizeAllowed(std::uint64_t w, std::uint64_t h, std::string* why) {
  if (w == 0 || h == 0) {
    *why = "an image of zero texels";
    return false;
  }
  if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxImageTexels) {
    *why = "an image of " + std::to_string(w) + " x " + std::to_string(h) + " texels, larger than the limit (" +
           std::to_string(kMaxImageSide) + " a side, " + std::to_string(kMaxImageTexels) + " texels)";
    return false;
  }
  return true;
}

namespace {

/// PNG through libpng's simplified API: any PNG (palette, grey, 16-bit,
/// interlaced) read as 8-bit RGBA.
bool decodePng(const std::uint8_t* bytes, std::size_t size, Rgba8* out, std::string* why) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes, size)) {
    *why = std::string("a corrupt PNG (") + png.message + ")";
    return false;
  }
  if (!sizeAllowed(png.width, png.height, why)) {
    png_image_free(&png);
    return false;
  }
  png.format = PNG_FORMAT_RGBA;
  out->width = png.width;
  out->height = png.height;
  out->texels.assign(PNG_IMAGE_SIZE(png), 0);
  if (!png_image_finish_read(&png, nullptr, out->texels.data(), 0, nullptr)) {
    *why = std::string("a corrupt PNG (") + png.message + ")";
    png_image_free(&png);
    return false;
  }
  return true;
}

/// libjpeg reports a fatal error through error_exit, which must not return:
/// it jumps back to decodeJpeg with the message.
struct JpegError {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void jpegErrorExit(j_common_ptr cinfo) {
  auto* e = reinterpret_cast<JpegError*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, e->message);
  std::longjmp(e->jump, 1);
}

void jpegSilence(j_common_ptr, int) {}  // warnings (a corrupt but decodable stream) are not fatal

/// The scanlines of a started decompression, RGB expanded to RGBA. Kept apart
/// from the setjmp frame: nothing here owns memory a longjmp would skip.
void readJpegRows(jpeg_decompress_struct& cinfo, std::uint8_t* texels, std::vector<std::uint8_t>& row) {
  while (cinfo.output_scanline < cinfo.output_height) {
    JSAMPROW rows[1] = {row.data()};
    const JDIMENSION y = cinfo.output_scanline;
    if (jpeg_read_scanlines(&cinfo, rows, 1) != 1) break;
    std::uint8_t* dst = texels + static_cast<std::size_t>(y) * cinfo.output_width * 4;
    for (JDIMENSION x = 0; x < cinfo.output_width; ++x) {
      dst[x * 4 + 0] = row[x * 3 + 0];
      dst[x * 4 + 1] = row[x * 3 + 1];
      dst[x * 4 + 2] = row[x * 3 + 2];
      dst[x * 4 + 3] = 255;
    }
  }
}

bool decodeJpeg(const std::uint8_t* bytes, std::size_t size, Rgba8* out, std::string* why) {
  jpeg_decompress_struct cinfo;
  JpegError error;
  std::vector<std::uint8_t> row;  // declared before setjmp: its destructor runs either way
  cinfo.err = jpeg_std_error(&error.manager);
  error.manager.error_exit = jpegErrorExit;
  error.manager.emit_message = jpegSilence;
  if (setjmp(error.jump)) {
    *why = std::string("a corrupt JPEG (") + error.message + ")";
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_create_decompress(&cinfo);
  jpeg_mem_src(&cinfo, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(&cinfo, TRUE);
  if (!sizeAllowed(cinfo.image_width, cinfo.image_height, why)) {
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  cinfo.out_color_space = JCS_RGB;  // grey and YCbCr both come out RGB; CMYK fails with libjpeg's reason
  jpeg_start_decompress(&cinfo);
  out->width = cinfo.output_width;
  out->height = cinfo.output_height;
  out->texels.assign(static_cast<std::size_t>(out->width) * out->height * 4, 0);
  row.resize(static_cast<std::size_t>(cinfo.output_width) * 3);
  readJpegRows(cinfo, out->texels.data(), row);
  if (cinfo.output_scanline < cinfo.output_height) {
    *why = "a truncated JPEG";
    jpeg_destroy_decompress(&cinfo);
    return false;
  }
  jpeg_finish_decompress(&cinfo);
  jpeg_destroy_decompress(&cinfo);
  return true;
}

}  // namespace

bool decode(const std::uint8_t* bytes, std::size_t size, Rgba8* out, std::string* why) {
  if (isPng(bytes, size)) return decodePng(bytes, size, out, why);
  if (isJpeg(bytes, size)) return decodeJpeg(bytes, size, out, why);
  *why = size == 0 ? "an empty file" : "not a PNG or JPEG image (its first bytes are neither signature)";
  return false;
}

bool readImageFile(const std::string& path, std::vector<std::uint8_t>* bytes, std::string* why) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    *why = std::filesystem::exists(path, ec) ? "not a regular file" : "no such file";
    return false;
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) {
    *why = ec.message();
    return false;
  }
  if (size > kMaxImageFileBytes) {
    *why = "a file of " + std::to_string(size) + " bytes, larger than the limit (" +
           std::to_string(kMaxImageFileBytes) + ")";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  bytes->assign(static_cast<std::size_t>(size), 0);
  if (!in || !in.read(reinterpret_cast<char*>(bytes->data()), static_cast<std::streamsize>(bytes->size()))) {
    *why = std::string("cannot read it (") + std::strerror(errno) + ")";
    return false;
  }
  return true;
}

bool load(const std::string& path, Rgba8* out, std::string* why) {
  std::vector<std::uint8_t> bytes;
  return readImageFile(path, &bytes, why) && decode(bytes.data(), bytes.size(), out, why);
}

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

MipChain mipChain(const Rgba8& img, bool srgb) {
  MipChain m;
  float table[256];
  for (int c = 0; c < 256; ++c) table[c] = static_cast<float>(srgb ? srgbToLinear(c / 255.0) : c / 255.0);
  std::vector<float> level(static_cast<std::size_t>(img.width) * img.height * 4);
  for (std::size_t i = 0; i < level.size(); ++i)
    level[i] = (i % 4 == 3) ? img.texels[i] / 255.0f : table[img.texels[i]];
  std::uint32_t w = img.width, h = img.height;
  m.widths.push_back(w);
  m.heights.push_back(h);
  m.levels.push_back(std::move(level));
  while (w > 1 || h > 1) {  // at most 2 log2(kMaxImageSide) levels
    const std::uint32_t nw = std::max<std::uint32_t>(1, w / 2), nh = std::max<std::uint32_t>(1, h / 2);
    const std::vector<float>& above = m.levels.back();
    std::vector<float> next(static_cast<std::size_t>(nw) * nh * 4);
    for (std::uint32_t y = 0; y < nh; ++y)
      for (std::uint32_t x = 0; x < nw; ++x)
        for (int c = 0; c < 4; ++c) {
          const std::uint32_t x0 = 2 * x, y0 = 2 * y;
          const std::uint32_t x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
          auto at = [&](std::uint32_t xx, std::uint32_t yy) {
            return above[(static_cast<std::size_t>(yy) * w + xx) * 4 + c];
          };
          next[(static_cast<std::size_t>(y) * nw + x) * 4 + c] =
              0.25f * (at(x0, y0) + at(x1, y0) + at(x0, y1) + at(x1, y1));
        }
    w = nw;
    h = nh;
    m.widths.push_back(w);
    m.heights.push_back(h);
    m.levels.push_back(std::move(next));
  }
  return m;
}

}  // namespace substratec::image
