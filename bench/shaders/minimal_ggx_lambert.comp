// The floor of bench/shader_cost.cc: a hand-written minimal GGX + Lambert
// compute kernel doing the job of the generated Throughput kernel
// (compiler/core/emit/kernel_emitter.cc, throughputKernel) for a simple one-slab
// material (examples/row12_simple.json), with nothing a generic runtime adds.
//
//   * Shading point: the Throughput kernel's prologue, copied exactly (pcg3d
//     hash of the invocation index -> normal, tangent, view, light, uv, dither;
//     the helpers below are copies of substrate_pcg3d, substrate_hash_to_unit,
//     substrate_values_normalize_or and substrate_orthogonal_tangent).
//   * Lighting: one light of radiance 1 with GGX specular (isotropic NDF,
//     height-correlated Smith visibility, Schlick Fresnel with F90 = 1, alpha =
//     max(r^2, 1e-3)) + Lambert diffuse, times NoL; plus a constant split-sum
//     environment: prefiltered (0.5) * (F0 A + B) + irradiance (1.5) / pi * albedo,
//     (A, B) from Karis' analytic fit ("Physically Based Shading on Mobile", 2014)
//     or, with MINIMAL_ENV_LUT 1, from the runtime's own split-sum tables (the same
//     uniform buffer at set 0, binding 5, and the same bilinear lookup, eight
//     fetches, as runtime_shaders/substrate_energy_lut.h: A = E - B, B). No energy
//     compensation, no layer throughputs, no closure struct.
//   * Parameters: row12_simple's inputs (albedo, F0, roughness). With
//     MINIMAL_PARAMS_UNIFORM (the default) they are read from the same uniform
//     block as the generated material reads (set 1, binding 0, std140, the same
//     member names, so the bench fills it the same way); with
//     MINIMAL_PARAMS_UNIFORM 0 they are compile-time constants, the defaults of
//     the example, which the driver may fold.
//   * Output: one float4 per invocation (colour, coverage 1) into binding 7.
//   * MINIMAL_SHADING 0: no material and no lighting at all, the shading point
//     written out as is (N + V + L): what the prologue and the write cost alone.
//   * MINIMAL_RUNTIME_MODEL 1 (needs MINIMAL_ENV_LUT 1): the runtime's shading
//     model written out by hand, to split the generated kernel's cost into the
//     model and the rest: Turquin 2019 energy compensation (W = 1 + F0 (1 - E) / E
//     on the specular lobe, E_spec = sat((F0 (E - B) + B) W) for the environment,
//     the diffuse scaled by 1 - E_spec) and Chan 2024 diffuse instead of Lambert
//     (substrate_bsdf.h's formulas, without its guards, closure struct or layers).
//
// bench/shader_cost.cc compiles it at run time with the project's glslang path
// (compileAndValidate), as the generated kernels are.
#version 450

#ifndef MINIMAL_PARAMS_UNIFORM
#define MINIMAL_PARAMS_UNIFORM 1
#endif
#ifndef MINIMAL_ENV_LUT
#define MINIMAL_ENV_LUT 0
#endif
#ifndef MINIMAL_SHADING
#define MINIMAL_SHADING 1
#endif
#ifndef MINIMAL_RUNTIME_MODEL
#define MINIMAL_RUNTIME_MODEL 0
#endif
#if MINIMAL_RUNTIME_MODEL && !MINIMAL_ENV_LUT
#error MINIMAL_RUNTIME_MODEL needs MINIMAL_ENV_LUT
#endif

layout(local_size_x = 64) in;
layout(set = 0, binding = 7, std430) writeonly buffer Results { vec4 results[]; };

#if MINIMAL_PARAMS_UNIFORM
layout(set = 1, binding = 0, std140) uniform row12_simple_Inputs {
  vec3 i_albedo;
  vec3 i_specular;
  float i_roughness;
} params;
#define ALBEDO params.i_albedo
#define F0 params.i_specular
#define ROUGHNESS params.i_roughness
#else
#define ALBEDO vec3(0.55, 0.35, 0.25)
#define F0 vec3(0.04)
#define ROUGHNESS 0.45
#endif

const float PI = 3.14159265358979;
const float FLT_MIN = 1.175494351e-38;

// --- The Throughput kernel's helpers, copied (runtime_shaders/substrate_common.h, substrate_values.h).
uvec3 pcg3d(uvec3 v) {
  v = v * 1664525u + uvec3(1013904223u, 1013904223u, 1013904223u);
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

float hash_to_unit(uint h) {
  return (float(h >> 8u) + 1.0) * (1.0 / 16777216.0);
}

vec3 normalize_or(vec3 v, vec3 fallback) {
  if (any(isnan(v)) || any(isinf(v))) return fallback;
  float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
  if (!(m >= FLT_MIN)) return fallback;
  return normalize(v / m);
}

vec3 orthogonal_tangent(vec3 N, vec3 T) {
  vec3 n = normalize_or(N, vec3(0.0, 0.0, 1.0));
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float b = n.x * n.y * a;
  vec3 t0 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  if (any(isnan(T)) || any(isinf(T))) return t0;
  float m = max(max(abs(T.x), abs(T.y)), abs(T.z));
  if (!(m >= FLT_MIN)) return t0;
  vec3 ts = T / m;
  vec3 t = ts - n * dot(n, ts);
  if (!(dot(t, t) > 1e-6 * dot(ts, ts))) return t0;
  t = t - n * dot(n, t);
  return normalize(t);
}

// --- The minimal BRDF.
#if MINIMAL_ENV_LUT
// The runtime's tables: E (table 0) and B (table 1), 32 x 32 each, NoV across, roughness down.
layout(set = 0, binding = 5, std140) uniform SubstrateLutBuffer {
  vec4 lut[768];
};
float lut_fetch(int k) {
  return lut[k >> 2][k & 3];
}
// (A, B) = (E - B, B) at (NoV, roughness): the same cells and bilinear weights as
// substrate_energy_dfg (substrate_energy_lut.h), with plain clamps.
vec2 env_brdf(float NoV, float roughness) {
  vec2 p = vec2(clamp(NoV, 0.0, 1.0), clamp(roughness, 0.0, 1.0)) * 32.0 - vec2(0.5);
  vec2 p0 = clamp(floor(p), vec2(0.0), vec2(30.0));
  vec2 f = p - p0;
  int i = int(p0.y) * 32 + int(p0.x);
  float e = mix(mix(lut_fetch(i), lut_fetch(i + 1), f.x), mix(lut_fetch(i + 32), lut_fetch(i + 33), f.x), f.y);
  float b = mix(mix(lut_fetch(1024 + i), lut_fetch(1025 + i), f.x), mix(lut_fetch(1056 + i), lut_fetch(1057 + i), f.x),
                f.y);
  e = clamp(e, 1e-3, 1.0);
  b = clamp(b, 0.0, e);
  return vec2(e - b, b);
}
#else
// Karis 2014: the split-sum pair (A, B) of GGX, analytic fit; the lobe's albedo is F0 A + B.
vec2 env_brdf(float NoV, float roughness) {
  const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
  const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
  vec4 r = roughness * c0 + c1;
  float a004 = min(r.x * r.x, exp2(-9.28 * NoV)) * r.x + r.y;
  return vec2(-1.04, 1.04) * a004 + r.zw;
}
#endif

void main() {
  uint i = gl_GlobalInvocationID.x;
  // The shading point, exactly as the Throughput kernel makes it.
  uvec3 h = pcg3d(uvec3(i, i * 7919u + 17u, 0x5eedu));
  uvec3 k = pcg3d(h);
  float z = hash_to_unit(h.x) * 2.0 - 1.0;
  float phi = 6.28318530718 * hash_to_unit(h.y);
  float rxy = sqrt(max(0.0, 1.0 - z * z));
  vec3 N = vec3(rxy * cos(phi), rxy * sin(phi), z);
  vec3 T = orthogonal_tangent(N, vec3(1.0, 0.0, 0.0));
  vec3 B = cross(N, T);
  float cv = 0.05 + 0.95 * hash_to_unit(h.z);
  float av = 6.28318530718 * hash_to_unit(k.x);
  vec3 V = cv * N + sqrt(1.0 - cv * cv) * (cos(av) * T + sin(av) * B);
  float cl = hash_to_unit(k.y);
  float al = 6.28318530718 * hash_to_unit(k.z);
  vec3 L = cl * N + sqrt(1.0 - cl * cl) * (cos(al) * T + sin(al) * B);

#if !MINIMAL_SHADING
  results[i] = vec4(N + V + L, 1.0);
#else
  vec3 albedo = ALBEDO;
  vec3 f0 = F0;
  float roughness = clamp(ROUGHNESS, 0.0, 1.0);
  float NoV = clamp(dot(N, V), 1e-4, 1.0);
  float NoL = dot(N, L);
  vec2 AB = env_brdf(NoV, roughness);  // the lobe's albedo is F0 A + B
#if MINIMAL_RUNTIME_MODEL
  float E = AB.x + AB.y;
  vec3 W = vec3(1.0) + f0 * ((1.0 - E) / E);
  vec3 specAlbedo = clamp((f0 * AB.x + AB.y) * W, 0.0, 1.0);
  vec3 diffuseAlbedo = albedo * (vec3(1.0) - specAlbedo);
#else
  vec3 W = vec3(1.0);
  vec3 specAlbedo = f0 * AB.x + AB.y;
  vec3 diffuseAlbedo = albedo;
#endif
  vec3 color = vec3(0.0);
  // One light, radiance 1.
  if (NoL > 0.0) {
    vec3 H = normalize(V + L);
    float NoH = clamp(dot(N, H), 0.0, 1.0);
    float VoH = clamp(dot(V, H), 0.0, 1.0);
    float a = max(roughness * roughness, 1e-3);
    float a2 = a * a;
    float d = (NoH * a2 - NoH) * NoH + 1.0;
    float D = a2 / (PI * d * d);
    float vis = 0.5 / (NoL * sqrt(NoV * NoV * (1.0 - a2) + a2) + NoV * sqrt(NoL * NoL * (1.0 - a2) + a2));
    float fw = 1.0 - VoH;
    float fw2 = fw * fw;
    vec3 F = f0 + (vec3(1.0) - f0) * (fw2 * fw2 * fw);
#if MINIMAL_RUNTIME_MODEL
    // Chan 2024 (substrate_diffuse_chan2024).
    float r = roughness;
    float ra = r * r;
    float scale = max(0.55 - 0.2 * r, 1.25 - 1.6 * r);
    float bias = clamp(4.0 * ra, 0.0, 1.0);
    float fRough = scale * (NoH + bias) / (NoH + 0.025) * VoH * VoH;
    float fd = (mix(1.0, fRough, r) + 0.38 * ra) * (1.0 / PI);
#else
    float fd = 1.0 / PI;  // Lambert
#endif
    color = (F * W * (D * vis) + diffuseAlbedo * fd) * NoL;
  }
  // Constant split-sum environment: prefiltered 0.5, irradiance 1.5.
  color += vec3(0.5) * specAlbedo + vec3(1.5 / PI) * diffuseAlbedo;
  results[i] = vec4(color, 1.0);
#endif
}
