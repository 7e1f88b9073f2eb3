// substratec runtime shaders: the volumetric fog cloud BSDF (UE Substrate's
// Volumetric Fog Cloud: pins albedo, extinction in 1/m, emissive, ambient
// occlusion), a volume-domain material a ray-marcher evaluates per sample
// point. Common dialect: include substrate_prelude.glsl or .hlsl, then this
// file (it includes substrate_common.h, which needs nothing else).
//
//  - SubstrateFogCloudSample: one sample point's coefficients.
//  - substrate_fog_cloud_make: a sample from the material's outputs,
//    sanitized: albedo and ambient occlusion saturated, extinction and
//    emissive clamped to [0, SUBSTRATE_FOG_MAX_EXTINCTION] (65408, the largest
//    value RGB9E5 holds); NaN becomes 0 in every field, +Inf the maximum.
//  - substrate_rgb9e5_encode / _decode: GL_EXT_texture_shared_exponent's
//    RGB9E5 (DXGI_FORMAT_R9G9B9E5_SHAREDEXP): 9-bit mantissas r bits 0-8,
//    g 9-17, b 18-26, shared exponent bits 27-31, bias 15; the spec's
//    encoding with round-to-nearest (ties up) and the exponent bump when the
//    largest mantissa rounds to 512. Exact integer logic on every target: the
//    exponent is read from the float's bits, the scale is a power of two built
//    from bits, and rounding is floor plus a comparison of the (exact)
//    fraction, never floor(x + 0.5) (which rounds 0.5 - 2^-25 up in float).
//    Absolute error per channel <= half a step, 2^(e - 25): at most
//    max(largest channel / 511.5, 2^-25).
//  - substrate_fog_cloud_pack / _unpack: the froxel payload, 3 words = 12 bytes:
//      word 0: albedo unorm8 r bits 0-7, g 8-15, b 16-23, ambient occlusion
//              unorm8 bits 24-31 (round to nearest, no dither);
//      word 1: extinction, RGB9E5;
//      word 2: emissive, RGB9E5.
//  - substrate_fog_cloud_step: one step of a ray-march, Hillaire 2015
//    ("Physically based and unified volumetric rendering in Frostbite"): the
//    coefficients constant over the step, the source
//      S = albedo sigma_t (inScattered + ambient ao) + emissive
//    (emissive: radiance emitted per metre; inScattered: the lights' radiance
//    x phase x visibility per unit scattering coefficient) integrated exactly:
//      radiance   += throughput S (1 - exp(-sigma_t ds)) / sigma_t
//      throughput *= exp(-sigma_t ds)
//    per channel; below sigma_t ds = 1e-2 the factor is ds (1 - tau / 2 + tau^2 / 6), tau = sigma_t ds
//    (sigma_t = 0 gives S ds, no division by 0). The scattered part is
//    computed as albedo L (sigma_t factor), sigma_t factor in [0, 1], so a
//    large sigma_t never overflows.
//  - substrate_fog_hg_phase: Henyey-Greenstein, normalized over the sphere
//    (1 / (4 pi) at g = 0), g clamped to [-0.99, 0.99].
//
// Guards: no input gives NaN or Inf. NaN, Inf, negative, huge or zero
// extinction, ds 0, negative, NaN or huge (clamped to
// SUBSTRATE_FOG_MAX_STEP), non-finite lights: every output is finite (the
// step re-sanitizes the sample's extinction, so a sample not made by
// substrate_fog_cloud_make is safe too; radiance and throughput come out in
// [0, SUBSTRATE_FLT_MAX]).
//
// The CPU mirror, in double, is compiler/tools/reference/fog_cloud.{h,cc}
// (tests/unit/fog_cloud_test.cc).
#ifndef SUBSTRATE_FOG_CLOUD_H
#define SUBSTRATE_FOG_CLOUD_H 1

#include "substrate_common.h"  // SUBSTRATE_PI, SUBSTRATE_FLT_MAX

// The largest value RGB9E5 holds: (511 / 512) 2^16.
#define SUBSTRATE_FOG_MAX_EXTINCTION 65408.0
// The longest step integrated (metres): emissive x step stays far from the
// float range whatever the step count.
#define SUBSTRATE_FOG_MAX_STEP 1.0e9
// Below this optical depth of a step, its factor is the series ds (1 - tau / 2 + tau^2 / 6)
// (truncation 4e-8 relative at the threshold; 1 - exp(-tau) in float loses 1e-3 relative at tau 1e-4).
#define SUBSTRATE_FOG_THIN_STEP 1.0e-2

struct SubstrateFogCloudSample {
  float3 albedo;
  float3 extinction;  // 1/m
  float3 emissive;    // radiance emitted per metre
  float ambientOcclusion;
};

// x clamped to [0, hi]; NaN gives 0 (the comparison is false), +Inf gives hi.
float substrate_fog_clamp(float x, float hi) {
  return x > 0.0 ? min(x, hi) : 0.0;
}

float3 substrate_fog_clamp3(float3 v, float hi) {
  return float3(substrate_fog_clamp(v.x, hi), substrate_fog_clamp(v.y, hi), substrate_fog_clamp(v.z, hi));
}

SubstrateFogCloudSample substrate_fog_cloud_make(float3 albedo, float3 extinction, float3 emissive, float ambientOcclusion) {
  SubstrateFogCloudSample s;
  s.albedo = substrate_fog_clamp3(albedo, 1.0);
  s.extinction = substrate_fog_clamp3(extinction, SUBSTRATE_FOG_MAX_EXTINCTION);
  s.emissive = substrate_fog_clamp3(emissive, SUBSTRATE_FOG_MAX_EXTINCTION);
  s.ambientOcclusion = substrate_fog_clamp(ambientOcclusion, 1.0);
  return s;
}

// ---- Payload ----------------------------------------------------------------

// Round to nearest, ties up, for x >= 0: floor, then the exact fraction
// compared with 1/2.
float substrate_fog_round(float x) {
  float r = floor(x);
  return x - r >= 0.5 ? r + 1.0 : r;
}

// 2^k as a float from its bits (k in [-126, 127]): exact on every target,
// unlike exp2.
float substrate_fog_exp2i(int k) {
  return asfloat(uint(k + 127) << 23u);
}

uint substrate_rgb9e5_encode(float3 color) {
  float3 c = substrate_fog_clamp3(color, SUBSTRATE_FOG_MAX_EXTINCTION);
  float m = substrate_max3(c);
  // floor(log2(m)) from the exponent bits (exact; 0 and denormals read -127),
  // then exp_shared' = max(-B - 1, floor(log2(m))) + 1 + B, in [0, 31].
  int e = max(int((asuint(m) >> 23u) & 0xffu) - 127, -16) + 16;
  // The step is 2^(e - B - N) = 2^(e - 24); the largest mantissa rounds to
  // at most 512, and to 512 only below the format's maximum: bump e.
  if (substrate_fog_round(m * substrate_fog_exp2i(24 - e)) >= 512.0) {
    e = e + 1;
  }
  float inv = substrate_fog_exp2i(24 - e);
  uint r = uint(substrate_fog_round(c.x * inv));
  uint g = uint(substrate_fog_round(c.y * inv));
  uint b = uint(substrate_fog_round(c.z * inv));
  return r | (g << 9u) | (b << 18u) | (uint(e) << 27u);
}

float3 substrate_rgb9e5_decode(uint w) {
  float unit = substrate_fog_exp2i(int(w >> 27u) - 24);
  return float3(float(w & 0x1ffu), float((w >> 9u) & 0x1ffu), float((w >> 18u) & 0x1ffu)) * unit;
}

// unorm8 of saturate(x), round to nearest (NaN gives 0).
uint substrate_fog_unorm8(float x) {
  return uint(substrate_fog_round(substrate_fog_clamp(x, 1.0) * 255.0));
}

void substrate_fog_cloud_pack(SubstrateFogCloudSample s, out uint words[3]) {
  words[0] = substrate_fog_unorm8(s.albedo.x) | (substrate_fog_unorm8(s.albedo.y) << 8u) |
             (substrate_fog_unorm8(s.albedo.z) << 16u) | (substrate_fog_unorm8(s.ambientOcclusion) << 24u);
  words[1] = substrate_rgb9e5_encode(s.extinction);
  words[2] = substrate_rgb9e5_encode(s.emissive);
}

SubstrateFogCloudSample substrate_fog_cloud_unpack(uint w0, uint w1, uint w2) {
  SubstrateFogCloudSample s;
  s.albedo = float3(float(w0 & 0xffu), float((w0 >> 8u) & 0xffu), float((w0 >> 16u) & 0xffu)) * (1.0 / 255.0);
  s.ambientOcclusion = float(w0 >> 24u) * (1.0 / 255.0);
  s.extinction = substrate_rgb9e5_decode(w1);
  s.emissive = substrate_rgb9e5_decode(w2);
  return s;
}

// ---- Integration --------------------------------------------------------------

// One channel's (1 - exp(-sigma ds)) / sigma (the series below the thin
// threshold), returned as the pair: factor = that, absorbed = sigma factor
// (in [0, 1]); transmittance exp(-sigma ds).
void substrate_fog_step_channel(float sigma, float ds, out float factor, out float absorbed, out float transmittance) {
  float tau = sigma * ds;
  transmittance = exp(-tau);
  if (tau < SUBSTRATE_FOG_THIN_STEP) {
    float series = 1.0 - tau * (0.5 - tau * (1.0 / 6.0));  // (1 - e^-tau) / tau to third order
    factor = ds * series;
    absorbed = tau * series;
  } else {
    absorbed = 1.0 - transmittance;
    factor = absorbed / sigma;
  }
}

void substrate_fog_cloud_step(SubstrateFogCloudSample s, float ds, float3 inScattered, float3 ambient,
                              inout float3 radiance, inout float3 throughput) {
  float d = substrate_fog_clamp(ds, SUBSTRATE_FOG_MAX_STEP);
  float3 sigma = substrate_fog_clamp3(s.extinction, SUBSTRATE_FOG_MAX_EXTINCTION);
  float3 albedo = substrate_fog_clamp3(s.albedo, 1.0);
  float3 emissive = substrate_fog_clamp3(s.emissive, SUBSTRATE_FOG_MAX_EXTINCTION);
  float ao = substrate_fog_clamp(s.ambientOcclusion, 1.0);
  float3 light = substrate_fog_clamp3(inScattered + ambient * ao, SUBSTRATE_FLT_MAX);
  float3 factor;
  float3 absorbed;
  float3 transmittance;
  substrate_fog_step_channel(sigma.x, d, factor.x, absorbed.x, transmittance.x);
  substrate_fog_step_channel(sigma.y, d, factor.y, absorbed.y, transmittance.y);
  substrate_fog_step_channel(sigma.z, d, factor.z, absorbed.z, transmittance.z);
  float3 added = albedo * light * absorbed + emissive * factor;
  float3 t = substrate_fog_clamp3(throughput, SUBSTRATE_FLT_MAX);
  radiance = substrate_fog_clamp3(substrate_fog_clamp3(radiance, SUBSTRATE_FLT_MAX) + t * added, SUBSTRATE_FLT_MAX);
  throughput = t * transmittance;
}

// Henyey-Greenstein: (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)). g clamped
// to [-0.99, 0.99] (NaN: 0), cos to [-1, 1] (NaN: 1); the denominator's base
// is at least (1 - |g|)^2 = 1e-4, kept >= 1e-6 against rounding.
float substrate_fog_hg_phase(float cosTheta, float g) {
  float k = g > -0.99 ? min(g, 0.99) : (g <= -0.99 ? -0.99 : 0.0);
  float c = cosTheta > -1.0 ? min(cosTheta, 1.0) : (cosTheta <= -1.0 ? -1.0 : 1.0);
  float d = max(1.0 + k * k - 2.0 * k * c, 1e-6);
  return (1.0 - k * k) / (4.0 * SUBSTRATE_PI * d * sqrt(d));
}

#endif
