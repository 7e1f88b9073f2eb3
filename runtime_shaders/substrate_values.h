// substratec runtime shaders: value nodes at run time. Written in the common
// dialect (include substrate_prelude.glsl or .hlsl first).
//
// The compiler folds a value node whose pins are all constant on the CPU, in
// double precision (compiler/core/ir/value.cc, evalConstOp; compiler/core/ir/helper_math.cc
// for the helper nodes; formulas and guards in docs/value-nodes.md). Every
// other node is computed here at run time, and must be the SAME function: same
// formulas, same clamps, same constants, same results for the undefined cases
// (divide by zero, sqrt of a negative, normalize of zero, 0 to a negative power,
// a zero normal, NoV 0 or < 0, IOR 1, ...). Every function returns a finite
// value for every finite input.
//
// Where float32 forces a different way of computing the same value, the
// function says so ("float:"): an overflow clamped to the largest float, a
// vector scaled by its largest component before it is squared, a logarithm or
// an exponential near 1 by its series, a cosine whose argument is reduced to
// [-pi, pi), exact identities that save work. The formulas are the CPU's.
//
// Public functions (overloaded on float, float2, float3, float4 where marked [n]):
//   math nodes    substrate_safe_div [n], substrate_value_pow [n],
//                 substrate_value_sqrt [n], substrate_value_normalize [n],
//                 substrate_value_exp [n]
//   helper nodes  substrate_metalness_to_diffuse, substrate_metalness_to_f0,
//                 substrate_ior_to_f0, substrate_haziness_second_roughness,
//                 substrate_haziness_weight, substrate_transmittance_to_mfp,
//                 substrate_transmittance_to_mfp_thickness, substrate_thin_film_f0,
//                 substrate_thin_film_f90, substrate_rotation_to_tangent,
//                 substrate_view_dependent_coverage
//   tree walk     substrate_roughness_to_variance, substrate_variance_to_roughness,
//                 substrate_tangent_to_world, substrate_orthogonal_tangent
// The substrate_values_* functions and SUBSTRATE_VALUES_* macros are internal.
#ifndef SUBSTRATE_VALUES_H
#define SUBSTRATE_VALUES_H 1

#define SUBSTRATE_VALUES_FLT_MAX 3.402823466e+38
#define SUBSTRATE_VALUES_FLT_MIN 1.175494351e-38  // smallest normal float
#define SUBSTRATE_VALUES_PI 3.14159265358979323846
#define SUBSTRATE_VALUES_TWO_PI 6.28318530717958647693
#define SUBSTRATE_VALUES_INV_TWO_PI 0.15915494309189533577

// ---------------------------------------------------------------------------
// Math nodes (evalConstOp).

// The float2/3/4 overloads of a two-argument scalar function f, applied per
// component.
#define SUBSTRATE_VALUES_PER_COMPONENT2(f)                                                         \
  float2 f(float2 a, float2 b) { return float2(f(a.x, b.x), f(a.y, b.y)); }                       \
  float3 f(float3 a, float3 b) { return float3(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z)); }          \
  float4 f(float4 a, float4 b) { return float4(f(a.x, b.x), f(a.y, b.y), f(a.z, b.z), f(a.w, b.w)); }

// divide: a / b per component, b == 0 gives 0.
// float: an overflowing quotient (|a / b| > FLT_MAX) is clamped to +-FLT_MAX,
// the float nearest to the CPU's double quotient.
// Without a branch: two selects of trivial operands (OpSelect in GLSL and in
// HLSL), so that inlining a material's thousands of divisions adds no blocks.
// An early return made a block per inlined call, and SPIRV-Tools' redundancy
// elimination copies its value table along the dominator tree: memory
// quadratic in the divisions (1.5 GB for the forward shader of 512 slabs
// mixed in pairs, 96 MB without; docs/performance.md, "The widest material").
float substrate_safe_div(float a, float b) {
  bool zero = b == 0.0;
  float q = clamp(a / (zero ? 1.0 : b), -SUBSTRATE_VALUES_FLT_MAX, SUBSTRATE_VALUES_FLT_MAX);
  return zero ? 0.0 : q;
}
SUBSTRATE_VALUES_PER_COMPONENT2(substrate_safe_div)

// pow: max(x, 0)^y per component; x^0 = 1 (0^0 included), 0^y = 0 for y != 0
// (0 to a negative power is 0, not infinity).
// float: y == 0 is tested first (the CPU's result is 1 for every x): a GPU's
// pow is exp2(y * log2(x)), and a denormal x flushed to 0 would give 0 * inf.
// An overflowing power is clamped to FLT_MAX.
float substrate_value_pow(float x, float y) {
  if (y == 0.0) return 1.0;
  float b = max(x, 0.0);
  if (b == 0.0) return 0.0;
  return min(pow(b, y), SUBSTRATE_VALUES_FLT_MAX);
}
SUBSTRATE_VALUES_PER_COMPONENT2(substrate_value_pow)

// sqrt: sqrt(max(x, 0)) per component.
float substrate_value_sqrt(float x) { return sqrt(max(x, 0.0)); }
float2 substrate_value_sqrt(float2 x) { return sqrt(max(x, SUBSTRATE_SPLAT2(0.0))); }
float3 substrate_value_sqrt(float3 x) { return sqrt(max(x, SUBSTRATE_SPLAT3(0.0))); }
float4 substrate_value_sqrt(float4 x) { return sqrt(max(x, SUBSTRATE_SPLAT4(0.0))); }

// exp: e^x per component (the simplifier's transmittance exp(-d / mfp)).
// float: an overflowing power (x above ~88.72) is clamped to FLT_MAX, the
// float nearest to the CPU's double value (which is capped there too).
float substrate_value_exp(float x) { return min(exp(x), SUBSTRATE_VALUES_FLT_MAX); }
float2 substrate_value_exp(float2 x) { return min(exp(x), SUBSTRATE_SPLAT2(SUBSTRATE_VALUES_FLT_MAX)); }
float3 substrate_value_exp(float3 x) { return min(exp(x), SUBSTRATE_SPLAT3(SUBSTRATE_VALUES_FLT_MAX)); }
float4 substrate_value_exp(float4 x) { return min(exp(x), SUBSTRATE_SPLAT4(SUBSTRATE_VALUES_FLT_MAX)); }

// normalize: x / length(x); the zero vector gives the zero vector. On a float:
// x / |x|, i.e. -1, 0 or 1.
// float: the vector is divided by its largest |component| before it is squared
// (as helper_math.cc's normalizeOr), so that tiny (1e-30) and huge (1e30)
// vectors normalize like the CPU's double instead of under/overflowing to 0.
// A vector whose components are all denormal (< 1.2e-38, which GPUs may flush
// to zero) reads as the zero vector.
float substrate_value_normalize(float x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }
float2 substrate_value_normalize(float2 x) {
  float m = max(abs(x.x), abs(x.y));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return SUBSTRATE_SPLAT2(0.0);
  return normalize(x / m);
}
float3 substrate_value_normalize(float3 x) {
  float m = max(max(abs(x.x), abs(x.y)), abs(x.z));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return SUBSTRATE_SPLAT3(0.0);
  return normalize(x / m);
}
float4 substrate_value_normalize(float4 x) {
  float m = max(max(abs(x.x), abs(x.y)), max(abs(x.z), abs(x.w)));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return SUBSTRATE_SPLAT4(0.0);
  return normalize(x / m);
}

// ---------------------------------------------------------------------------
// Internal helpers.

// helper_math.cc's normalizeOr: v normalized; a zero or non-finite vector gives
// `fallback`. Scaled by the largest |component| first (see above).
float3 substrate_values_normalize_or(float3 v, float3 fallback) {
  if (any(isnan(v)) || any(isinf(v))) return fallback;
  float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return fallback;
  return normalize(v / m);
}

// NoV of the view-dependent helpers, as value_eval.cc computes it:
// dot(normal, view) / length(normal), 0 for a zero normal (the view is used as
// given). float: the normal is scaled by its largest |component| first.
float substrate_values_nov(float3 normal, float3 view) {
  float m = max(max(abs(normal.x), abs(normal.y)), abs(normal.z));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return 0.0;
  float3 n = normal / m;
  return dot(n, view) / length(n);
}

// -ln(1 - u) = log1p(-u) negated, for u in [0, 1/16], by its series (relative
// error < 5e-10). float: a GPU's log is only accurate to ~2^-21 absolute near 1,
// which is a large relative error for a small result; the CPU uses log1p.
float substrate_values_neglog1m_series(float u) {
  return u * (1.0 + u * (1.0 / 2.0 + u * (1.0 / 3.0 + u * (1.0 / 4.0 + u * (1.0 / 5.0 + u * (1.0 / 6.0 + u / 7.0))))));
}

// 1 - exp(-x) = -expm1(-x), for x in [0, 1/16], by its series (relative error
// < 2e-9). float: as above, for the CPU's expm1.
float substrate_values_oneminusexp_series(float x) {
  return x * (1.0 - x / 2.0 * (1.0 - x / 3.0 * (1.0 - x / 4.0 * (1.0 - x / 5.0))));
}

// ---------------------------------------------------------------------------
// Helper nodes (helper_math.cc), formula for formula.

// metalness_to_diffuse_f0: base_color, metallic and specular clamped to [0, 1];
//   diffuse_albedo = base_color * (1 - metallic)
//   f0             = 0.08 * specular * (1 - metallic) + base_color * metallic
float3 substrate_metalness_to_diffuse(float3 base, float metallic, float specular) {
  float m = saturate(metallic);
  float3 b = saturate(base);
  return b * (1.0 - m);
}
float3 substrate_metalness_to_f0(float3 base, float metallic, float specular) {
  float m = saturate(metallic);
  float dielectricF0 = 0.08 * saturate(specular);
  float3 b = saturate(base);
  return SUBSTRATE_SPLAT3(dielectricF0 * (1.0 - m)) + b * m;
}

// ior_to_f0: ((n - 1) / (n + 1))^2, n clamped to [0, inf) (n <= 0 gives 1).
// float: the CPU clamps n to DBL_MAX; here to 1e30, so that 1 / (n + 1) stays
// a normal float for GPUs that divide by multiplying with a reciprocal (which
// flushes 1 / FLT_MAX to 0). For n >= 1e30 the float result is 1.0 either way.
float substrate_ior_to_f0(float ior) {
  float n = clamp(ior, 0.0, 1e30);
  float r = (n - 1.0) / (n + 1.0);  // in [-1, 1]
  return r * r;
}

// haziness_to_second_roughness (Barla et al. 2018, extent L = 3): with r, h
// clamped to [0, 1], alpha_c = r^2, alpha_h = min(1, (1 + L) alpha_c):
//   second_roughness        = sqrt(alpha_h)
//   second_roughness_weight = h / (h + p (1 - h)),  p = (alpha_c / alpha_h)^2,
//                             ratio 1 / (1 + L) when alpha_h = 0
#define SUBSTRATE_VALUES_HAZE_EXTENT 3.0
float substrate_haziness_second_roughness(float roughness, float haziness) {
  float r = saturate(roughness);
  float alphaC = r * r;
  float alphaH = min(1.0, (1.0 + SUBSTRATE_VALUES_HAZE_EXTENT) * alphaC);
  return sqrt(alphaH);
}
// float: the CPU tests alpha_h > 0; here alpha_h >= FLT_MIN, so that a denormal
// alpha_h never reaches a division. The value is the same: for 0 < alpha_h < 1,
// alpha_h = 4 alpha_c exactly and alpha_c / alpha_h = 0.25 = 1 / (1 + L).
float substrate_haziness_weight(float roughness, float haziness) {
  float r = saturate(roughness);
  float h = saturate(haziness);
  float alphaC = r * r;
  float alphaH = min(1.0, (1.0 + SUBSTRATE_VALUES_HAZE_EXTENT) * alphaC);
  float ratio = alphaH >= SUBSTRATE_VALUES_FLT_MIN ? alphaC / alphaH : 1.0 / (1.0 + SUBSTRATE_VALUES_HAZE_EXTENT);
  float p = ratio * ratio;          // in [1/16, 1]
  return h / (h + p * (1.0 - h));  // denominator = p + h (1 - p) >= p > 0
}

// transmittance_to_mfp (Beer-Lambert): thickness <= 0 becomes 1e-4 m; T clamped
// to [0, 1] per channel; mfp = -thickness / ln(T), T = 0 gives 0, T = 1 the
// "transparent" sentinel 1e9 m, and mfp is capped at the sentinel.
// float: -ln(T) for T > 15/16 by the series of -ln(1 - u), u = 1 - T (exact):
// a GPU's log is only accurate to ~2^-21 absolute near 1, which would make the
// MFP of a nearly clear medium wrong by up to several per cent.
#define SUBSTRATE_VALUES_MFP_TRANSPARENT 1e9
#define SUBSTRATE_VALUES_DEFAULT_SURFACE_THICKNESS 1e-4
float substrate_values_mfp_thickness(float thickness) {
  return thickness > 0.0 ? thickness : SUBSTRATE_VALUES_DEFAULT_SURFACE_THICKNESS;
}
float substrate_values_mfp_channel(float transmittance, float t) {
  float T = saturate(transmittance);
  if (T <= 0.0) return 0.0;  // opaque
  if (T >= 1.0) return SUBSTRATE_VALUES_MFP_TRANSPARENT;
  float negLogT = T > 0.9375 ? substrate_values_neglog1m_series(1.0 - T) : -log(T);  // > 0
  return min(t / negLogT, SUBSTRATE_VALUES_MFP_TRANSPARENT);  // an overflow (inf) is capped too
}
float3 substrate_transmittance_to_mfp(float3 transmittance, float thickness) {
  float t = substrate_values_mfp_thickness(thickness);
  return float3(substrate_values_mfp_channel(transmittance.x, t), substrate_values_mfp_channel(transmittance.y, t),
                substrate_values_mfp_channel(transmittance.z, t));
}
float substrate_transmittance_to_mfp_thickness(float3 transmittance, float thickness) {
  return substrate_values_mfp_thickness(thickness);
}

// Thin film (Belcour & Barla 2017), see helper_math.h for the whole derivation.
#define SUBSTRATE_VALUES_FILM_IOR_MAX 5.0
#define SUBSTRATE_VALUES_FILM_THICKNESS_MAX 1e-3  // metres
#define SUBSTRATE_VALUES_BASE_F0_MAX 0.9999       // keeps the base IOR finite
#define SUBSTRATE_VALUES_R123_MAX 0.9999          // keeps 1 / (1 - R12 R23) finite

// fresnelDielectric(eta, c): unpolarized Fresnel reflectance of a smooth
// dielectric interface of relative IOR eta, cosine of incidence c in [0, 1]
// (Walter et al. 2007 form); total internal reflection gives 1:
//   g2 = eta^2 - 1 + c^2, g = sqrt(g2), a = (g - c) / (g + c),
//   b = (c (g + c) - 1) / (c (g - c) + 1), F = 0.5 a^2 (1 + b^2)
// float: the caller passes e2m1 = eta^2 - 1, g2 and s2 = 1 - c^2 computed
// without cancellation (each sum of this form loses every digit near an edge:
// eta near 1, c near 1, and the critical angle of the film-to-base interface,
// which a base of F0 ~ 0 reaches at grazing), and the same values are then
// formed as g - c = e2m1 / (g + c), c (g + c) - 1 = c g - s2 and
// c (g - c) + 1 = c g + s2.
float substrate_values_fresnel_dielectric(float eta, float c, float e2m1, float g2, float s2) {
  if (eta == 1.0) return 0.0;  // no interface (also avoids 0/0 at c = 0)
  if (g2 <= 0.0) return 1.0;   // total internal reflection (or its edge)
  float g = sqrt(g2);
  float a = e2m1 / ((g + c) * (g + c));  // (g - c) / (g + c); g + c > 0 here
  float b = (c * g - s2) / (c * g + s2);  // c g + 1 - c^2 > 0 here
  return saturate(0.5 * a * a * (1.0 + b * b));
}

// rgbSensitivity(opd, 0, c) for the three channels: Belcour & Barla's Gaussian
// fit of the CIE 1931 XYZ functions (the same four lobes as the CPU), to linear
// Rec.709, white-balanced by its value at opd = 0 (so S(0) = 1).
// float: cos(pos * 2 pi opd) is computed as cos(2 pi f) with f the fraction of a
// turn in [-0.5, 0.5), so that the argument stays in [-pi, pi), where GPU
// cosines are specified; a lobe whose Gaussian underflows is 0 (as the CPU's).
float3 substrate_values_film_sensitivity(float opd) {
  // Lobes x, y, z, then the second (blue) lobe of x: val, pos (m^-1), var.
  float4 val = float4(5.4856e-13, 4.4201e-13, 5.2481e-13, 9.7470e-14);
  float4 pos = float4(1.6810e+06, 1.7953e+06, 2.2084e+06, 2.2399e+06);
  float4 var = float4(4.3278e+09, 9.3046e+09, 6.6121e+09, 4.5282e+09);
  float norm = 1.0685e-7;
  float4 amp = val * sqrt(SUBSTRATE_VALUES_TWO_PI * var);
  float phase = SUBSTRATE_VALUES_TWO_PI * opd;
  float4 g = exp(-(phase * phase) * var);
  float4 turns = frac(pos * opd + SUBSTRATE_SPLAT4(0.5)) - SUBSTRATE_SPLAT4(0.5);
  float4 lobe = amp * cos(SUBSTRATE_VALUES_TWO_PI * turns) * g;
  float3 xyz = float3(lobe.x + lobe.w, lobe.y, lobe.z) / norm;
  float3 xyzWhite = float3(amp.x + amp.w, amp.y, amp.z) / norm;  // opd = 0: cos = 1, g = 1
  // CIE XYZ to linear Rec.709 (D65), one row per RGB channel.
  float3 toR = float3(3.2404542, -1.5371385, -0.4985314);
  float3 toG = float3(-0.9692660, 1.8760108, 0.0415560);
  float3 toB = float3(0.0556434, -0.2040259, 1.0572252);
  float3 rgb = float3(dot(toR, xyz), dot(toG, xyz), dot(toB, xyz));
  float3 white = float3(dot(toR, xyzWhite), dot(toG, xyzWhite), dot(toB, xyzWhite));
  return rgb / white;
}

// thin_film.f0: clamp(f0 + I(d) - I(0), 0, 1) per channel; thickness <= 0 (or
// NaN) returns f0 unchanged, bit for bit.
// float: the three channels are computed at once. The CPU evaluates
// S(m opd, m phi) with the phase shift inside the cosine; phi is pi or 2 pi, so
// cos(x + m phi) = cos(phi)^m cos(x) exactly, and S(m opd, m phi) =
// cos(phi)^m S(m opd, 0): the spectral sums are computed once for the three
// channels (and S(0, m phi) = cos(phi)^m, the CPU's white balance).
float3 substrate_thin_film_f0(float3 normal, float3 f0, float3 f90, float thickness, float ior, float3 view) {
  if (!(thickness > 0.0)) return f0;  // no film: identity, bit for bit
  float d = min(thickness, SUBSTRATE_VALUES_FILM_THICKNESS_MAX);
  float cosTheta1 = saturate(substrate_values_nov(normal, view));
  // Air / film interface, shared by the three channels.
  float eta2 = clamp(ior, 1.0, SUBSTRATE_VALUES_FILM_IOR_MAX);
  float invEta2Sq = 1.0 / (eta2 * eta2);
  float sin2Theta1 = (1.0 - cosTheta1) * (1.0 + cosTheta1);
  float eta2Sqm1 = (eta2 - 1.0) * (eta2 + 1.0);
  float g2Film = eta2Sqm1 + cosTheta1 * cosTheta1;        // eta2^2 - 1 + cos^2(theta1) >= 0
  float sin2Theta2 = sin2Theta1 * invEta2Sq;               // Snell; eta2 >= 1: no TIR
  float cosTheta2 = sqrt(max(0.0, g2Film * invEta2Sq));  // = sqrt(1 - sin2Theta2)
  float R12 = substrate_values_fresnel_dielectric(eta2, cosTheta1, eta2Sqm1, g2Film, sin2Theta1);
  float T121 = 1.0 - R12;
  float opd = 2.0 * eta2 * d * cosTheta2;  // optical path difference of one round trip
  float3 baseF0 = saturate(f0);
  float3 baseF90 = saturate(f90);
  // airyReflectance, per channel. Base IOR from its F0 (dielectric reading).
  float3 sF0 = sqrt(min(baseF0, SUBSTRATE_SPLAT3(SUBSTRATE_VALUES_BASE_F0_MAX)));
  float3 oneMinusSF0 = SUBSTRATE_SPLAT3(1.0) - sF0;
  float3 eta3 = (SUBSTRATE_SPLAT3(1.0) + sF0) / oneMinusSF0;
  // Film -> base: exact dielectric Fresnel of relative IOR eta3 / eta2 at
  // cos(theta2), with eta3^2 - 1 = 4 sF0 / (1 - sF0)^2 (no cancellation):
  //   eta^2 - 1 = (eta3 - eta2) (eta3 + eta2) / eta2^2
  //   g2 = eta^2 - 1 + cos^2(theta2) = (eta3^2 - 1 + cos^2(theta1)) / eta2^2
  // then its grazing value moved from 1 to F90.
  float3 e2m1Base = (eta3 - SUBSTRATE_SPLAT3(eta2)) * (eta3 + SUBSTRATE_SPLAT3(eta2)) * invEta2Sq;
  float3 g2Base = (4.0 * sF0 / (oneMinusSF0 * oneMinusSF0) + SUBSTRATE_SPLAT3(cosTheta1 * cosTheta1)) * invEta2Sq;
  float3 R23 = float3(
      substrate_values_fresnel_dielectric(eta3.x / eta2, cosTheta2, e2m1Base.x, g2Base.x, sin2Theta2),
      substrate_values_fresnel_dielectric(eta3.y / eta2, cosTheta2, e2m1Base.y, g2Base.y, sin2Theta2),
      substrate_values_fresnel_dielectric(eta3.z / eta2, cosTheta2, e2m1Base.z, g2Base.z, sin2Theta2));
  float x = sin2Theta2 / (1.0 + cosTheta2);  // 1 - cos(theta2)
  float x5 = x * x * x * x * x;
  R23 = saturate(R23 + (baseF90 - SUBSTRATE_SPLAT3(1.0)) * x5);
  // Phase: phi = pi + (eta3 < eta2 ? pi : 0), so cos(phi) = eta3 < eta2 ? 1 : -1.
  float3 cosPhi = SUBSTRATE_SPLAT3(1.0) - 2.0 * step(SUBSTRATE_SPLAT3(eta2), eta3);
  // Compound terms.
  float3 R123 = clamp(R12 * R23, SUBSTRATE_SPLAT3(0.0), SUBSTRATE_SPLAT3(SUBSTRATE_VALUES_R123_MAX));
  float3 r123 = sqrt(R123);
  float3 Rs = T121 * T121 * R23 / (SUBSTRATE_SPLAT3(1.0) - R123);
  float3 C1 = (Rs - SUBSTRATE_SPLAT3(T121)) * r123;  // m = 1
  float3 C2 = C1 * r123;                             // m = 2
  float3 I0 = SUBSTRATE_SPLAT3(R12) + Rs;            // m = 0
  float3 withFilm = I0 + 2.0 * C1 * cosPhi * substrate_values_film_sensitivity(opd) +
                    2.0 * C2 * substrate_values_film_sensitivity(2.0 * opd);
  float3 zeroFilm = I0 + 2.0 * C1 * cosPhi + 2.0 * C2;
  // Out-of-gamut terms can go negative: each Airy reflectance is clamped at 0.
  withFilm = max(withFilm, SUBSTRATE_SPLAT3(0.0));
  zeroFilm = max(zeroFilm, SUBSTRATE_SPLAT3(0.0));
  return saturate(baseF0 + (withFilm - zeroFilm));
}

// thin_film.f90: f90, unchanged (not clamped), whatever the film.
float3 substrate_thin_film_f90(float3 normal, float3 f0, float3 f90, float thickness, float ior, float3 view) {
  return f90;
}

// rotation_to_tangent (Duff et al. 2017): the canonical tangent b1 of the
// normalized normal (zero or non-finite normal -> (0, 0, 1)) rotated by angle
// around it (right-hand rule), then one Gram-Schmidt step and a normalization
// (falling back to b1). A non-finite angle reads as 0.
// float: copysign(1, n.z) is read from the sign bit (-0 gives -1, as on the
// CPU). An angle outside [-pi, pi] is reduced to [-pi, pi] first (GPU sin and cos
// are only specified there; a huge angle stays finite).
float3 substrate_rotation_to_tangent(float angle, float3 normal) {
  float3 n = substrate_values_normalize_or(normal, float3(0.0, 0.0, 1.0));
  float s = (asuint(n.z) & 0x80000000u) != 0u ? -1.0 : 1.0;
  float a = -1.0 / (s + n.z);
  float b = n.x * n.y * a;
  float3 b1 = float3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  float3 b2 = float3(b, s + n.y * n.y * a, -n.y);
  float theta = (isnan(angle) || isinf(angle)) ? 0.0 : angle;
  if (abs(theta) > SUBSTRATE_VALUES_PI) {
    // theta - 2 pi turns, 2 pi split in 6.28125 (exact products for |turns| < 2^16)
    // and the rest (Cody & Waite); clamped for a huge angle, where float has no
    // digit left below 2 pi anyway.
    float turns = floor(theta * SUBSTRATE_VALUES_INV_TWO_PI + 0.5);
    theta = (theta - turns * 6.28125) - turns * 1.9353071795864769e-3;
    theta = clamp(theta, -SUBSTRATE_VALUES_PI, SUBSTRATE_VALUES_PI);
  }
  float3 t = cos(theta) * b1 + sin(theta) * b2;
  float k = dot(t, n);
  t = t - k * n;
  return substrate_values_normalize_or(t, b1);
}

// view_dependent_coverage: 1 - (1 - c)^(1 / NoV), c clamped to [0, 1], NoV to
// [1e-4, 1]; NoV >= 1, c = 0 and c = 1 return c exactly; the result is
// clamped to [c, 1]. The CPU computes -expm1(log1p(-c) / NoV).
// float: log1p and expm1 near 0 by their series, log and exp elsewhere (not
// 1 - pow(1 - c, 1 / NoV), which loses most digits for a small coverage).
float substrate_view_dependent_coverage(float coverage, float3 normal, float3 view) {
  float c = saturate(coverage);
  float mu = clamp(substrate_values_nov(normal, view), 1e-4, 1.0);
  if (mu >= 1.0 || c <= 0.0 || c >= 1.0) return c;
  float L = c < 0.0625 ? substrate_values_neglog1m_series(c) : -log(1.0 - c);  // -log1p(-c) > 0
  float x = L / mu;
  float covered = x < 0.0625 ? substrate_values_oneminusexp_series(x) : 1.0 - exp(-x);
  return clamp(covered, c, 1.0);
}

// ---------------------------------------------------------------------------
// Tree-walk helpers.

// Roughness to the variance the tree walk adds up through layers:
// r^1.1 / (1 - r), r clamped to [0, 0.999] (so the variance is in [0, ~999]).
float substrate_roughness_to_variance(float r) {
  float rc = clamp(r, 0.0, 0.999);
  return substrate_value_pow(rc, 1.1) / (1.0 - rc);
}

// Its inverse: the r in [0, 0.999] with r^1.1 / (1 - r) = v (v <= 0 gives 0,
// v above the variance of 0.999 gives 0.999). Two Newton steps in
// x = logit(r) = ln(r / (1 - r)) on h(x) = 1.1 ln r - ln(1 - r) - ln v, whose
// slope dh/dx = 1.1 - 0.1 r is in [1, 1.1]: h is nearly linear in x, and the
// start x0 = ln v (r near 1) or ln v / 1.1 (r near 0) is within 0.07 of the
// root in x (0.017 in r); one step brings r within 2e-5, two within 1e-11 in
// double (float rounding here). Checked by tests/unit/values_shader_test.cc.
// v below 1e-30 reads as 1e-30 (r ~ 4e-28), which keeps exp(-x) finite.
float substrate_variance_to_roughness(float v) {
  if (!(v > 0.0)) return 0.0;
  float L = log(clamp(v, 1e-30, substrate_roughness_to_variance(0.999)));
  float x = L >= 0.0 ? L : L / 1.1;
  for (int i = 0; i < 2; ++i) {
    float r = 1.0 / (1.0 + exp(-x));
    float h = 1.1 * log(r) - log(1.0 - r) - L;
    x = x - h / (1.1 - 0.1 * r);
  }
  return clamp(1.0 / (1.0 + exp(-x)), 0.0, 0.999);
}

// normalize(T v.x + (N x T) v.y + N v.z): a tangent-space vector to the frame
// (N, T); a zero (or overflowing) result gives N.
// float: v is divided by its largest |component| first (the normalization does
// not see the scale), so that a huge v does not overflow; a v whose components
// are all denormal reads as zero.
float3 substrate_tangent_to_world(float3 v, float3 N, float3 T) {
  float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN) || isinf(m)) return N;
  float3 vs = v / m;
  float3 B = cross(N, T);
  return substrate_values_normalize_or(T * vs.x + B * vs.y + N * vs.z, N);
}

// T made orthogonal to N (Gram-Schmidt, applied twice for orthogonality to
// rounding) and normalized. N is normalized first (a zero N reads as (0, 0, 1)).
// When T is zero or (nearly) parallel to N — the part of T orthogonal to N is
// below 1e-3 of |T| — the tangent b1 of Duff et al. 2017's orthonormal basis
// of N: s = N.z >= 0 ? 1 : -1, a = -1 / (s + N.z), b = N.x N.y a,
// b1 = (1 + s N.x^2 a, s b, -s N.x).
float3 substrate_orthogonal_tangent(float3 N, float3 T) {
  float3 n = substrate_values_normalize_or(N, float3(0.0, 0.0, 1.0));
  float s = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (s + n.z);
  float b = n.x * n.y * a;
  float3 t0 = float3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
  if (any(isnan(T)) || any(isinf(T))) return t0;
  float m = max(max(abs(T.x), abs(T.y)), abs(T.z));
  if (!(m >= SUBSTRATE_VALUES_FLT_MIN)) return t0;
  float3 ts = T / m;  // largest |component| 1: no overflow below
  float3 t = ts - n * dot(n, ts);
  if (!(dot(t, t) > 1e-6 * dot(ts, ts))) return t0;
  t = t - n * dot(n, t);
  return normalize(t);
}

#endif
