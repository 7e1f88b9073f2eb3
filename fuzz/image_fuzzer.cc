// libFuzzer target: the texture image decoders (issue 20). Arbitrary bytes
// through image::decode (PNG by libpng, JPEG by libjpeg-turbo, told apart by
// signature): every input ends in an image within the limits whose texel
// count matches its size, then a mip chain whose levels halve down to 1 x 1,
// or in a refusal that says why; never a crash, a leak or an exception.
// The same bytes through image::decodeRadiance (Radiance HDR by stb_image,
// behind the pixel-stream check that keeps it from looping forever): an image
// within the limits of finite radiance >= 0, or a refusal that says why.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <cmath>

#include "image/decode.h"
#include "image/radiance.h"

using namespace substratec;

namespace {

void radiance(const std::uint8_t* data, std::size_t size) {
  image::RgbF img;
  std::string why;
  if (!image::decodeRadiance(data, size, &img, &why)) {
    if (why.empty()) std::abort();
    return;
  }
  if (img.width == 0 || img.height == 0 || std::uint64_t{img.width} * img.height > image::kMaxImageTexels) std::abort();
  if (img.rgb.size() != std::size_t{img.width} * img.height * 3) std::abort();
  for (float v : img.rgb)
    if (!std::isfinite(v) || v < 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  radiance(data, size);
  image::Rgba8 img;
  std::string why;
  if (!image::decode(data, size, &img, &why)) {
    if (why.empty()) std::abort();  // refused without saying why
    return 0;
  }
  if (img.width == 0 || img.height == 0 || img.width > image::kMaxImageSide || img.height > image::kMaxImageSide)
    std::abort();
  if (std::uint64_t{img.width} * img.height > image::kMaxImageTexels) std::abort();
  if (img.texels.size() != std::size_t{img.width} * img.height * 4) std::abort();
  if (std::uint64_t{img.width} * img.height > (1u << 16)) return 0;  // big ones: decoding was the test
  const image::MipChain chain = image::mipChain(img, (size & 1) != 0);
  if (chain.levels.empty() || chain.widths.back() != 1 || chain.heights.back() != 1) std::abort();
  for (std::size_t l = 0; l < chain.levels.size(); ++l)
    if (chain.levels[l].size() != std::size_t{chain.widths[l]} * chain.heights[l] * 4) std::abort();
  return 0;
}
