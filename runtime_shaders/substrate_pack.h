// substratec runtime shaders: per-pixel storage — the encodings of
// docs/storage.md (quantizers substrate_q_*, decoders substrate_dq_*) and a bit
// reader/writer over the material buffer's words. The generic unpacker of the
// deferred lighting pass is substrate_unpack.h. Common dialect: include
// substrate_prelude.glsl or .hlsl, then this file (it includes
// substrate_common.h, which needs nothing else, for the tangent frame).
//
// The CPU mirror is compiler/core/storage/pack.{h,cc} (tests/unit/pack_test.cc);
// the two must agree bit for bit on every layout.
//
// Conventions (docs/storage.md):
//  - stream bit i is bit (i mod 32) of word i / 32; a field's bits go from
//    least to most significant; sub-fields in the order of the field table,
//    each from its least significant bit;
//  - a quantized field is floor(x * (2^n - 1) + dither), clamped; `dither` is
//    the per-pixel u in [0, 1) (SubstrateGeometry.dither), the same for every
//    field of the pixel. snorm n bits: floor(s * x + s + dither) in [0, 2s],
//    s = 2^(n-1) - 1;
//  - material header bit 15 is 1 for the multi-closure header, 0 for the
//    single-closure header (used by one closure, whatever the class);
//  - the tangent angle is measured in the frame (substrate_orthonormal_basis) of the
//    normal *as stored*: pass substrate_normal_as_stored(N, dither), or, for a
//    basis whose normal is elided, substrate_top_layer_normal_as_stored(N, dither).
#ifndef SUBSTRATE_PACK_H
#define SUBSTRATE_PACK_H 1

#include "substrate_common.h"  // substrate_orthonormal_basis

// Words of the material buffer the unpacker reads (a layout must fit).
#ifndef SUBSTRATE_MAX_WORDS
#define SUBSTRATE_MAX_WORDS 32
#endif
// Basis ids are 3 bits.
#define SUBSTRATE_MAX_BASES 8

#define SUBSTRATE_HEADER_MULTI 0x8000u
// Bit 14 of a single-closure header: the pixel holds no closure (an unlit
// material: it emits, the base pass added that, and nothing is lit).
#define SUBSTRATE_HEADER_NO_CLOSURE 0x4000u
// Bit 12 of a single-closure header: the closure is a hair (SUBSTRATE_FEATURE_HAIR):
// its F0 field is the hair field, and its basis stores the fibre's tangent angle.
#define SUBSTRATE_HEADER_HAIR 0x1000u
// Bit 13 of a single-closure header: the closure is an eye (SUBSTRATE_FEATURE_EYE):
// its F0 field is the iris normal and iris fields (its F0 is 0.04).
#define SUBSTRATE_HEADER_EYE 0x2000u

// Field widths in bits (docs/storage.md, "Field table").
#define SUBSTRATE_BITS_HEADER 16u
#define SUBSTRATE_BITS_CLOSURE_HEADER 16u
#define SUBSTRATE_BITS_COLOR 20u
#define SUBSTRATE_BITS_ROUGHNESS 8u
#define SUBSTRATE_BITS_WEIGHT 8u
#define SUBSTRATE_BITS_COVERAGE_ABOVE 8u
#define SUBSTRATE_BITS_SSS 28u
#define SUBSTRATE_BITS_HAZE 16u
#define SUBSTRATE_BITS_FUZZ 32u
#define SUBSTRATE_BITS_ANISOTROPY 8u
#define SUBSTRATE_BITS_SPECULAR_PROFILE 8u
#define SUBSTRATE_BITS_HAIR 32u
#define SUBSTRATE_BITS_IRIS_NORMAL 32u
#define SUBSTRATE_BITS_IRIS 32u
#define SUBSTRATE_BITS_GLINT 136u
#define SUBSTRATE_BITS_NORMAL 32u
#define SUBSTRATE_BITS_TANGENT_ANGLE 14u

// log2 of the mean free path is stored over [-24, 8] (meters).
#define SUBSTRATE_MFP_LOG2_MIN (-24.0)
#define SUBSTRATE_MFP_LOG2_RANGE 32.0
#define SUBSTRATE_HALF_MAX 65504.0
#define SUBSTRATE_PACK_TWO_PI 6.28318530717959

// ---- Scalars ------------------------------------------------------------------

// unorm of `width` bits (1..24) of saturate(x); NaN encodes as 0.
uint substrate_q_unorm(float x, uint width, float dither) {
  float n = float((1u << width) - 1u);
  float v = x > 0.0 ? min(x, 1.0) : 0.0;
  return uint(clamp(floor(v * n + dither), 0.0, n));
}

float substrate_dq_unorm(uint code, uint width) {
  uint m = (1u << width) - 1u;
  return float(code & m) / float(m);
}

// snorm of `width` bits (2..24) over [-1, 1]: codes 0 .. 2s, s = 2^(width-1) - 1
// (0 and +-1 exact); NaN encodes as 0.
uint substrate_q_snorm(float x, uint width, float dither) {
  float s = float((1u << (width - 1u)) - 1u);
  float v = x >= -1.0 ? min(x, 1.0) : (x < -1.0 ? -1.0 : 0.0);
  return uint(clamp(floor(v * s + s + dither), 0.0, 2.0 * s));
}

float substrate_dq_snorm(uint code, uint width) {
  float s = float((1u << (width - 1u)) - 1u);
  return clamp(float(code & ((1u << width) - 1u)) / s - 1.0, -1.0, 1.0);
}

// Colour (20 bits): sqrt(saturate(c)) as unorm 7/7/6; r bits 0-6, g 7-13, b 14-19.
uint substrate_q_color20(float3 c, float dither) {
  uint r = substrate_q_unorm(sqrt(saturate(c.x)), 7u, dither);
  uint g = substrate_q_unorm(sqrt(saturate(c.y)), 7u, dither);
  uint b = substrate_q_unorm(sqrt(saturate(c.z)), 6u, dither);
  return r | (g << 7u) | (b << 14u);
}

float3 substrate_dq_color20(uint code) {
  float r = substrate_dq_unorm(code, 7u);
  float g = substrate_dq_unorm(code >> 7u, 7u);
  float b = substrate_dq_unorm(code >> 14u, 6u);
  return float3(r * r, g * g, b * b);
}

// One mean free path channel (8 bits): 0 = no medium (mfp <= 0 or NaN), else
// clamp(floor(255 (log2(mfp) + 24) / 32 + dither), 1, 255): 2^-24 m .. 2^8 m,
// saturating at both ends.
uint substrate_q_mfp(float mfp, float dither) {
  if (!(mfp > 0.0)) {
    return 0u;
  }
  float t = clamp((log2(mfp) - SUBSTRATE_MFP_LOG2_MIN) / SUBSTRATE_MFP_LOG2_RANGE, 0.0, 1.0);
  return uint(clamp(floor(t * 255.0 + dither), 1.0, 255.0));
}

float substrate_dq_mfp(uint code) {
  uint c = code & 0xffu;
  if (c == 0u) {
    return 0.0;
  }
  return exp2(float(c) * (SUBSTRATE_MFP_LOG2_RANGE / 255.0) + SUBSTRATE_MFP_LOG2_MIN);
}

// SSS (28 bits): MFP r, g, b (8 bits each, bits 0-23; pass the MFP after
// sss_mfp_scale, in meters), phase anisotropy snorm4 (bits 24-27).
uint substrate_q_sss(float3 mfp, float phaseAnisotropy, float dither) {
  return substrate_q_mfp(mfp.x, dither) | (substrate_q_mfp(mfp.y, dither) << 8u) |
         (substrate_q_mfp(mfp.z, dither) << 16u) | (substrate_q_snorm(phaseAnisotropy, 4u, dither) << 24u);
}

void substrate_dq_sss(uint code, out float3 mfp, out float phaseAnisotropy) {
  mfp = float3(substrate_dq_mfp(code), substrate_dq_mfp(code >> 8u), substrate_dq_mfp(code >> 16u));
  phaseAnisotropy = substrate_dq_snorm(code >> 24u, 4u);
}

// Haze (16 bits): second roughness unorm8 (bits 0-7), weight unorm8 (8-15).
uint substrate_q_haze(float secondRoughness, float secondRoughnessWeight, float dither) {
  return substrate_q_unorm(secondRoughness, 8u, dither) | (substrate_q_unorm(secondRoughnessWeight, 8u, dither) << 8u);
}

void substrate_dq_haze(uint code, out float secondRoughness, out float secondRoughnessWeight) {
  secondRoughness = substrate_dq_unorm(code, 8u);
  secondRoughnessWeight = substrate_dq_unorm(code >> 8u, 8u);
}

// Fuzz (32 bits): amount unorm6 (bits 0-5), colour 20 (6-25), roughness unorm6 (26-31).
uint substrate_q_fuzz(float amount, float3 color, float roughness, float dither) {
  return substrate_q_unorm(amount, 6u, dither) | (substrate_q_color20(color, dither) << 6u) |
         (substrate_q_unorm(roughness, 6u, dither) << 26u);
}

void substrate_dq_fuzz(uint code, out float amount, out float3 color, out float roughness) {
  amount = substrate_dq_unorm(code, 6u);
  color = substrate_dq_color20((code >> 6u) & 0xfffffu);
  roughness = substrate_dq_unorm(code >> 26u, 6u);
}

// Hair (32 bits, SubstrateClosure.hair): azimuthal roughness unorm8 (bits
// 0-7), (ior - 1) / 2 unorm8 (8-15), cuticle angle / 20 degrees snorm8
// (16-23), scatter unorm8 (24-31).
uint substrate_q_hair(float4 hair, float dither) {
  return substrate_q_unorm(hair.x, 8u, dither) | (substrate_q_unorm((hair.y - 1.0) * 0.5, 8u, dither) << 8u) |
         (substrate_q_snorm(hair.z / 20.0, 8u, dither) << 16u) | (substrate_q_unorm(hair.w, 8u, dither) << 24u);
}

float4 substrate_dq_hair(uint code) {
  return float4(substrate_dq_unorm(code, 8u), 1.0 + 2.0 * substrate_dq_unorm(code >> 8u, 8u),
                20.0 * substrate_dq_snorm(code >> 16u, 8u), substrate_dq_unorm(code >> 24u, 8u));
}

// Anisotropy (8 bits): snorm8, code = round(127 a) + 127 on average.
uint substrate_q_anisotropy(float anisotropy, float dither) {
  return substrate_q_snorm(anisotropy, 8u, dither);
}

float substrate_dq_anisotropy(uint code) {
  return substrate_dq_snorm(code, 8u);
}

// Specular profile (8 bits): the atlas index, i.e. SubstrateClosure.specularProfile - 1.
uint substrate_q_specular_profile(uint specularProfile) {
  return specularProfile == 0u ? 0u : min(specularProfile - 1u, 255u);
}

uint substrate_dq_specular_profile(uint code) {
  return (code & 0xffu) + 1u;
}

// IEEE half bits (low 16), clamped to +-65504 (never infinite).
uint substrate_q_half(float x) {
  return substrate_f32tof16(clamp(x, -SUBSTRATE_HALF_MAX, SUBSTRATE_HALF_MAX));
}

float substrate_dq_half(uint code) {
  // The argument is a plain `x`: the GLSL prelude's substrate_f16tof32(x)
  // expands to (unpackHalf2x16(uint(x)).x), whose `.x` is the macro parameter.
  uint x = code & 0xffffu;
  return substrate_f16tof32(x);
}

// Two halves in one word: v.x in bits 0-15, v.y in 16-31.
uint substrate_q_half2(float2 v) {
  return substrate_q_half(v.x) | (substrate_q_half(v.y) << 16u);
}

float2 substrate_dq_half2(uint code) {
  return float2(substrate_dq_half(code), substrate_dq_half(code >> 16u));
}

// Glint (136 bits): returns the density unorm8 (the first 8 bits); `rest` gets
// the 4 words that follow: asuint(uv.x), asuint(uv.y), then d(uv)/dx and
// d(uv)/dy as two halves each (substrate_q_half2).
uint substrate_q_glint(float glintValue, float2 uv, float4 uvDerivatives, float dither, out uint4 rest) {
  rest = uint4(asuint(uv.x), asuint(uv.y), substrate_q_half2(uvDerivatives.xy), substrate_q_half2(uvDerivatives.zw));
  return substrate_q_unorm(glintValue, 8u, dither);
}

void substrate_dq_glint(uint densityCode, uint4 rest, out float glintValue, out float2 uv, out float4 uvDerivatives) {
  glintValue = substrate_dq_unorm(densityCode, 8u);
  uv = float2(asfloat(rest.x), asfloat(rest.y));
  float2 dx = substrate_dq_half2(rest.z);
  float2 dy = substrate_dq_half2(rest.w);
  uvDerivatives = float4(dx.x, dx.y, dy.x, dy.y);
}

// ---- Directions -----------------------------------------------------------------

float substrate_pack_sign_not_zero(float x) {
  return x >= 0.0 ? 1.0 : -1.0;
}

// Octahedral projection of a direction (any length; zero gives +Z) to [-1, 1]^2.
float2 substrate_oct_project(float3 n) {
  float l1 = abs(n.x) + abs(n.y) + abs(n.z);
  if (!(l1 > 0.0)) {
    return float2(0.0, 0.0);
  }
  float px = n.x / l1;
  float py = n.y / l1;
  if (n.z < 0.0) {
    float ox = (1.0 - abs(py)) * substrate_pack_sign_not_zero(px);
    float oy = (1.0 - abs(px)) * substrate_pack_sign_not_zero(py);
    px = ox;
    py = oy;
  }
  return float2(px, py);
}

float3 substrate_oct_unproject(float2 p) {
  float3 n = float3(p.x, p.y, 1.0 - abs(p.x) - abs(p.y));
  if (n.z < 0.0) {
    float ox = (1.0 - abs(n.y)) * substrate_pack_sign_not_zero(n.x);
    float oy = (1.0 - abs(n.x)) * substrate_pack_sign_not_zero(n.y);
    n.x = ox;
    n.y = oy;
  }
  return normalize(n);
}

// Octahedral codes, snorm of `width` bits per coordinate (basis normals).
uint2 substrate_oct_encode(float3 n, uint width, float dither) {
  float2 p = substrate_oct_project(n);
  return uint2(substrate_q_snorm(p.x, width, dither), substrate_q_snorm(p.y, width, dither));
}

float3 substrate_oct_decode(uint2 code, uint width) {
  return substrate_oct_unproject(float2(substrate_dq_snorm(code.x, width), substrate_dq_snorm(code.y, width)));
}

// Octahedral codes, unorm of (p + 1) / 2 (the top-layer word).
uint2 substrate_oct_encode_unorm(float3 n, uint width, float dither) {
  float2 p = substrate_oct_project(n);
  return uint2(substrate_q_unorm(p.x * 0.5 + 0.5, width, dither), substrate_q_unorm(p.y * 0.5 + 0.5, width, dither));
}

float3 substrate_oct_decode_unorm(uint2 code, uint width) {
  return substrate_oct_unproject(
      float2(substrate_dq_unorm(code.x, width) * 2.0 - 1.0, substrate_dq_unorm(code.y, width) * 2.0 - 1.0));
}

// Basis normal (32 bits): octahedral x snorm16 (bits 0-15), y (16-31).
uint substrate_q_normal(float3 n, float dither) {
  uint2 c = substrate_oct_encode(n, 16u, dither);
  return c.x | (c.y << 16u);
}

float3 substrate_dq_normal(uint code) {
  return substrate_oct_decode(uint2(code & 0xffffu, code >> 16u), 16u);
}

// The normal a basis field decodes to (for the tangent angle's frame).
float3 substrate_normal_as_stored(float3 n, float dither) {
  return substrate_dq_normal(substrate_q_normal(n, dither));
}

// Top-layer word: octahedral normal 2 x unorm12 (x bits 0-11, y 12-23),
// roughness unorm8 (24-31).
uint substrate_q_top_layer(float3 n, float roughness, float dither) {
  uint2 c = substrate_oct_encode_unorm(n, 12u, dither);
  return c.x | (c.y << 12u) | (substrate_q_unorm(roughness, 8u, dither) << 24u);
}

void substrate_dq_top_layer(uint word, out float3 n, out float roughness) {
  n = substrate_oct_decode_unorm(uint2(word & 0xfffu, (word >> 12u) & 0xfffu), 12u);
  roughness = substrate_dq_unorm(word >> 24u, 8u);
}

// The normal the top-layer word decodes to (the tangent frame of an elided basis 0).
float3 substrate_top_layer_normal_as_stored(float3 n, float dither) {
  float3 d;
  float r;
  substrate_dq_top_layer(substrate_q_top_layer(n, 0.0, dither), d, r);
  return d;
}

// Iris (32 bits, SubstrateClosure.irisPlaneN and .iris): the iris plane's
// normal octahedral 2 x unorm8 (x bits 0-7, y 8-15), iris mask unorm8
// (16-23), iris distance unorm8 (24-31). The iris normal is a field of its
// own, encoded as a basis normal (substrate_q_normal).
uint substrate_q_iris(float3 planeN, float2 iris, float dither) {
  uint2 o = substrate_oct_encode_unorm(planeN, 8u, dither);
  return o.x | (o.y << 8u) | (substrate_q_unorm(iris.x, 8u, dither) << 16u) |
         (substrate_q_unorm(iris.y, 8u, dither) << 24u);
}

void substrate_dq_iris(uint code, out float3 planeN, out float2 iris) {
  planeN = substrate_oct_decode_unorm(uint2(code & 0xffu, (code >> 8u) & 0xffu), 8u);
  iris = float2(substrate_dq_unorm((code >> 16u) & 0xffu, 8u), substrate_dq_unorm(code >> 24u, 8u));
}

// The canonical frame around a unit N (Duff et al. 2017) is
// substrate_orthonormal_basis (substrate_common.h), as in the compiler's
// rotationToTangent.

// Tangent angle (14 bits): unorm14 of atan2(T.B0, T.T0) / 2pi in [0, 1), in the
// frame of N, the normal as the unpacker decodes it (see the header comment).
uint substrate_tangent_angle_encode(float3 T, float3 N, float dither) {
  float3 t0;
  float3 b0;
  substrate_orthonormal_basis(N, t0, b0);
  float y = dot(T, b0);
  float x = dot(T, t0);
  float angle = (x != 0.0 || y != 0.0) ? atan2(y, x) : 0.0;
  if (angle < 0.0) {
    angle += SUBSTRATE_PACK_TWO_PI;
  }
  return substrate_q_unorm(angle / SUBSTRATE_PACK_TWO_PI, SUBSTRATE_BITS_TANGENT_ANGLE, dither);
}

float3 substrate_tangent_angle_decode(uint code, float3 N) {
  float3 t0;
  float3 b0;
  substrate_orthonormal_basis(N, t0, b0);
  float angle = substrate_dq_unorm(code, SUBSTRATE_BITS_TANGENT_ANGLE) * SUBSTRATE_PACK_TWO_PI;
  return normalize(cos(angle) * t0 + sin(angle) * b0);
}

// ---- Headers --------------------------------------------------------------------

// Single-closure header: class (bits 0-1), SUBSTRATE_FEATURE_* bits F90 ..
// WEIGHT (2-8; bit 9, coverage above, is reserved), SSS type (10-11); a hair
// closure ORs SUBSTRATE_HEADER_HAIR (bit 12), an eye SUBSTRATE_HEADER_EYE (bit 13).
uint substrate_material_header_single(uint layoutClass, uint features, uint sssType) {
  return (layoutClass & 3u) | ((features & 0x7fu) << 2u) | ((sssType & 3u) << 10u);
}

// The header of a pixel with no closure (an unlit material): SIMPLE, bit 14 set.
uint substrate_material_header_unlit() {
  return SUBSTRATE_HEADER_NO_CLOSURE;
}

// Multi-closure header: class (0-1), closure count - 1 (2-4), basis count
// (5-8), bit 15 set.
uint substrate_material_header_multi(uint layoutClass, uint closureCount, uint basisCount) {
  return (layoutClass & 3u) | (((closureCount - 1u) & 7u) << 2u) | ((basisCount & 15u) << 5u) | SUBSTRATE_HEADER_MULTI;
}

// Closure header: basis id (0-2), is top (3), SUBSTRATE_FEATURE_* (4-11), SSS type (12-13),
// extra interfaces above (14-15, SubstrateClosure.extraInterfaces).
uint substrate_closure_header(uint basis, bool isTop, uint features, uint sssType, uint extraInterfaces) {
  return (basis & 7u) | (isTop ? 8u : 0u) | ((features & 0xffu) << 4u) | ((sssType & 3u) << 12u) |
         ((extraInterfaces & 3u) << 14u);
}

// The layout class of a pixel (SUBSTRATE_LAYOUT_*), from word 0.
uint substrate_layout_class(uint word0) {
  return word0 & 3u;
}

// ---- Bit stream -----------------------------------------------------------------

// The `width` (0..32) bits at bit `shift` (0..31) of the 64-bit pair lo | hi << 32.
uint substrate_bits_from_pair(uint lo, uint hi, uint shift, uint width) {
  uint v = (lo >> shift) | (shift != 0u ? (hi << (32u - shift)) : 0u);
  return v & (width >= 32u ? 0xffffffffu : ((1u << width) - 1u));
}

// The `width` (0..32) bits at stream bit `pos` of the word array W (a
// variable: the macro indexes it in place, where a function call would copy
// the whole array); the field may straddle two words.
#define SUBSTRATE_READ_BITS(W, pos, width)                                                         \
  substrate_bits_from_pair((W)[min((pos) >> 5u, uint(SUBSTRATE_MAX_WORDS - 1))],                   \
                           (W)[min(((pos) >> 5u) + 1u, uint(SUBSTRATE_MAX_WORDS - 1))], (pos) & 31u, \
                           (width))

// The same as a function (the array is passed by value).
uint substrate_read_bits(uint words[SUBSTRATE_MAX_WORDS], uint pos, uint width) {
  return SUBSTRATE_READ_BITS(words, pos, width);
}

// ORs `value` (masked to `width` bits, 0..32) into the stream at bit `pos`
// (the words start at 0).
void substrate_write_bits(inout uint words[SUBSTRATE_MAX_WORDS], uint pos, uint width, uint value) {
  uint m = width >= 32u ? 0xffffffffu : ((1u << width) - 1u);
  uint v = value & m;
  uint w = pos >> 5u;
  uint s = pos & 31u;
  if (w < uint(SUBSTRATE_MAX_WORDS)) {
    words[w] |= v << s;
  }
  if (s != 0u && s + width > 32u && w + 1u < uint(SUBSTRATE_MAX_WORDS)) {
    words[w + 1u] |= v >> (32u - s);
  }
}

#endif
