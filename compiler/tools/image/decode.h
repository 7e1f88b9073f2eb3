// Texture images read from disk: PNG (libpng) and JPEG (libjpeg-turbo)
// decoded to RGBA, colour-decoded to linear floats by their colour space, and
// their mip chain. Used where a material's textures are bound for rendering
// (preview/textures.h); nothing here knows about materials.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace substratec::image {

/// The largest image decoded: either side at most kMaxImageSide texels and at
/// most kMaxImageTexels in all (RGBA32F: 256 MiB before mips). Larger images
/// are refused before their pixels are decoded.
inline constexpr std::uint32_t kMaxImageSide = 16384;
inline constexpr std::uint64_t kMaxImageTexels = std::uint64_t{1} << 24;
/// The largest image file read (bytes).
inline constexpr std::size_t kMaxImageFileBytes = std::size_t{256} << 20;

/// True for a size the decoders accept (1 to kMaxImageSide a side, at most
/// kMaxImageTexels); false, with `*why` saying so, otherwise.
bool sizeAllowed(std::uint64_t width, std::uint64_t height, std::string* why);

/// 8-bit RGBA texels as stored in the file (sRGB-encoded or not, as the file
/// is), row-major, top row first. Grey, grey + alpha, palette and RGB images
/// are expanded to RGBA (alpha 255 where the file has none); 16-bit PNG
/// channels are reduced to 8 bits.
struct Rgba8 {
  std::uint32_t width = 0, height = 0;
  std::vector<std::uint8_t> texels;  // width * height * 4
};

/// Decodes PNG or JPEG `bytes` (told apart by their signature). False, with
/// `*why` saying what is wrong (not an image, a format other than PNG or JPEG,
/// a truncated or corrupt stream, too large), on failure.
bool decode(const std::uint8_t* bytes, std::size_t size, Rgba8* out, std::string* why);

/// Reads the file at `path` whole (at most kMaxImageFileBytes). False, with
/// `*why` (no such file, not a regular file, too large, the system's reason),
/// on failure.
bool readImageFile(const std::string& path, std::vector<std::uint8_t>* bytes, std::string* why);

/// Reads and decodes the image file at `path`. False, with `*why` (the
/// system's reason or decode's), on failure.
bool load(const std::string& path, Rgba8* out, std::string* why);

/// Linear RGBA32F levels, level 0 first, each level half the one above
/// (rounded down, at least 1), down to 1 x 1.
struct MipChain {
  std::vector<std::uint32_t> widths, heights;
  std::vector<std::vector<float>> levels;  // 4 floats a texel, row-major
};

/// The mip chain of `img`: level 0 is each texel / 255, RGB through the sRGB
/// EOTF when `srgb` (alpha is always linear); texel (x, y) of each further
/// level is the box average of texels 2x…2x+1, 2y…2y+1 of the level above
/// (clamped to its edge), in linear values: for power-of-two sizes every
/// level's mean is level 0's.
MipChain mipChain(const Rgba8& img, bool srgb);

/// The sRGB EOTF of an 8-bit code: (c / 255) decoded to linear.
double srgbToLinear(double encoded);

}  // namespace substratec::image
