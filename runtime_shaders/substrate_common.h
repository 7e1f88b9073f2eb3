// substratec runtime shaders: constants and guarded primitives used by every
// other runtime file. Common dialect: include substrate_prelude.{glsl,hlsl}
// (and substrate_closure.h) first. See README.md for the formulas.
//
// Guards live here, not at call sites: every function below is finite for any
// finite input (and for the zero / grazing cases the BSDF feeds it).
#ifndef SUBSTRATE_COMMON_H
#define SUBSTRATE_COMMON_H 1

SUBSTRATE_CONST float SUBSTRATE_PI = 3.14159265358979;
SUBSTRATE_CONST float SUBSTRATE_TWO_PI = 6.28318530717959;
SUBSTRATE_CONST float SUBSTRATE_INV_PI = 0.318309886183791;
// Smallest cosine used for view / light remapping (T^(1/cos)) and the bias of
// NoV for shading normals that face slightly away from the eye.
SUBSTRATE_CONST float SUBSTRATE_MIN_COS = 1e-4;
// Smallest transmittance / mean free path considered (keeps log() finite).
SUBSTRATE_CONST float SUBSTRATE_MIN_TRANSMITTANCE = 1e-30;
SUBSTRATE_CONST float SUBSTRATE_MIN_MFP = 1e-30;
// Largest finite value the helpers return instead of +inf.
SUBSTRATE_CONST float SUBSTRATE_FLT_MAX = 3.0e38;

// pow with the compiler's constant-folding semantics (compiler/core/ir/value.cc,
// Op::Pow): the base is clamped at 0; 0^y = 0 for y != 0 and 0^0 = 1. The pow()
// intrinsic is never called with a zero base (undefined for y <= 0 on GPUs).
// A result beyond the float range (e.g. (1e-30)^-2) is clamped to 3e38.
float substrate_pow(float x, float y) {
  float b = max(x, 0.0);
  float r = pow(b > 0.0 ? b : 1.0, y);
  if (b > 0.0) {
    return min(r, SUBSTRATE_FLT_MAX);
  }
  return y == 0.0 ? 1.0 : 0.0;
}

float3 substrate_pow(float3 x, float y) {
  return float3(substrate_pow(x.x, y), substrate_pow(x.y, y), substrate_pow(x.z, y));
}

float3 substrate_pow(float3 x, float3 y) {
  return float3(substrate_pow(x.x, y.x), substrate_pow(x.y, y.y), substrate_pow(x.z, y.z));
}

// x^5 for x clamped to [0, 1] (Schlick's weight is substrate_pow5(1 - cos)).
float substrate_pow5(float x) {
  float t = saturate(x);
  float t2 = t * t;
  return t2 * t2 * t;
}

// (Division by a value that may be 0 follows the compiler's folding rule: substrate_safe_div, substrate_values.h.)

float substrate_safe_sqrt(float x) {
  return sqrt(max(x, 0.0));
}

float substrate_max3(float3 v) {
  return max(v.x, max(v.y, v.z));
}

// Rec. 709 / linear sRGB luminance.
float substrate_luminance(float3 c) {
  return dot(c, float3(0.2126, 0.7152, 0.0722));
}

// v / |v|, or `fallback` when v is (near) zero, not finite, or too large to
// square: v is first divided by its largest |component| so dot(v, v) never
// under- or overflows.
float3 substrate_safe_normalize(float3 v, float3 fallback) {
  float m = substrate_max3(abs(v));
  if (m > 1e-30 && m <= SUBSTRATE_FLT_MAX) {
    float3 u = v / m;
    return u * rsqrt(dot(u, u));
  }
  return fallback;
}

// Branchless orthonormal basis around a unit N (Duff et al. 2017, "Building an
// Orthonormal Basis, Revisited"), the frame the storage's tangent angle is
// measured in (compiler/core/ir/helper_math.cc, rotationToTangent):
//   s = sign(N.z) (copysign: -0 counts as negative, like the compiler),
//   a = -1 / (s + N.z), b = N.x N.y a,
//   T = (1 + s N.x^2 a, s b, -s N.x),  B = (b, s + N.y^2 a, -N.y).
// s + N.z has |.| >= 1, so the basis is finite for any unit N.
void substrate_orthonormal_basis(float3 N, out float3 T, out float3 B) {
  float s = (asuint(N.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
  float a = -1.0 / (s + N.z);
  float b = N.x * N.y * a;
  T = float3(1.0 + s * N.x * N.x * a, s * b, -s * N.x);
  B = float3(b, s + N.y * N.y * a, -N.y);
}

// Beer-Lambert transmittance over a distance d (meters) through a medium with
// per-channel mean free path mfp (meters): exp(-d / max(mfp, 1e-30)).
// d = 0 gives 1 (even for mfp = 0); mfp = 0 with d > 0 gives 0 (opaque);
// negative d is treated as 0.
float3 substrate_transmittance(float3 mfp, float d) {
  float dd = max(d, 0.0);
  float3 m = max(mfp, SUBSTRATE_SPLAT3(SUBSTRATE_MIN_MFP));
  return exp(-min(SUBSTRATE_SPLAT3(dd) / m, SUBSTRATE_SPLAT3(1e30)));
}

// A transmittance given along the normal, remapped to a direction at cosine
// mu from the normal: T^(1 / max(mu, 1e-4)), computed as
// exp(log(clamp(T, 1e-30, 1)) / max(mu, 1e-4)) (never pow(T, 1/0)).
float3 substrate_transmittance_at_cosine(float3 normalTransmittance, float mu) {
  float3 t = clamp(normalTransmittance, SUBSTRATE_SPLAT3(SUBSTRATE_MIN_TRANSMITTANCE), SUBSTRATE_SPLAT3(1.0));
  return exp(log(t) / max(mu, SUBSTRATE_MIN_COS));
}

// 3D -> 3D integer hash (Jarzynski & Olano 2020, "Hash Functions for GPU
// Rendering": pcg3d). Used by the glint approximation.
uint3 substrate_pcg3d(uint3 v) {
  v = v * 1664525u + uint3(1013904223u, 1013904223u, 1013904223u);
  v.x += v.y * v.z;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.x ^= v.x >> 16u;
  v.y ^= v.y >> 16u;
  v.z ^= v.z >> 16u;
  v.x += v.y * v.z;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  return v;
}

// Uniform in (0, 1] from the top 24 bits of a hash (never 0: safe for log()).
float substrate_hash_to_unit(uint h) {
  return (float(h >> 8u) + 1.0) * (1.0 / 16777216.0);
}

#endif
