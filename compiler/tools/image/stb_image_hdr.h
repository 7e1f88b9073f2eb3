// The few stb_image calls radiance.cc makes, behind functions so that
// stb_image's implementation and macros stay in stb_image_hdr.cc.
#pragma once

namespace substratec::image::stb {

/// True when `bytes` start with a Radiance signature.
bool isHdr(const unsigned char* bytes, int size);
/// The size from the header alone; false for a header stb_image cannot read.
bool info(const unsigned char* bytes, int size, int* width, int* height);
/// The pixels as linear RGB floats (release them), or null.
float* loadRgb(const unsigned char* bytes, int size, int* width, int* height);
void release(float* pixels);
/// Why the last call failed (stb_image's short reason).
const char* failureReason();

}  // namespace substratec::image::stb
