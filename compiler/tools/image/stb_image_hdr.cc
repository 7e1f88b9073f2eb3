// stb_image's implementation, compiled here from Debian's header
// (libstb-dev) with the Radiance HDR decoder only: built with the project's
// sanitizer and fuzzer instrumentation like the rest of the image floor
// (image_fuzzer feeds it), and no other format's code linked in. Excluded
// from unity builds (its macros stay in this file); warnings off (not our code).
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#define STBI_MAX_DIMENSIONS 16384
#include <stb_image.h>

#include "image/stb_image_hdr.h"

namespace substratec::image::stb {

bool isHdr(const unsigned char* bytes, int size) { return stbi_is_hdr_from_memory(bytes, size) != 0; }

bool info(const unsigned char* bytes, int size, int* width, int* height) {
  int channels = 0;
  return stbi_info_from_memory(bytes, size, width, height, &channels) != 0;
}

float* loadRgb(const unsigned char* bytes, int size, int* width, int* height) {
  int channels = 0;
  return stbi_loadf_from_memory(bytes, size, width, height, &channels, 3);
}

void release(float* pixels) { stbi_image_free(pixels); }

const char* failureReason() { return stbi_failure_reason(); }

}  // namespace substratec::image::stb
