// PNG files the GPU tests write and read back (libpng's simplified API).
#pragma once
#include <png.h>

#include <filesystem>
#include <vector>

#include <gtest/gtest.h>

namespace substratec::testutil {

struct Png {
  int width = 0, height = 0;
  std::vector<unsigned char> rgba;
};

/// Reads a PNG back as 8-bit RGBA (false when it is not one).
inline bool readPng(const std::filesystem::path& path, Png* out) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return false;
  image.format = PNG_FORMAT_RGBA;
  out->width = static_cast<int>(image.width);
  out->height = static_cast<int>(image.height);
  out->rgba.resize(PNG_IMAGE_SIZE(image));
  return png_image_finish_read(&image, nullptr, out->rgba.data(), 0, nullptr) != 0;
}

/// Writes a size x size RGB PNG of one colour.
inline void solidPng(const std::filesystem::path& path, unsigned char r, unsigned char g, unsigned char b,
                     int size = 4) {
  std::vector<unsigned char> texels;
  for (int i = 0; i < size * size; ++i) texels.insert(texels.end(), {r, g, b});
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = image.height = static_cast<png_uint_32>(size);
  image.format = PNG_FORMAT_RGB;
  ASSERT_TRUE(png_image_write_to_file(&image, path.c_str(), 0, texels.data(), 0, nullptr));
}

}  // namespace substratec::testutil
