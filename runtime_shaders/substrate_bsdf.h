// substratec runtime shaders: evaluation of one closure for one light.
// Common dialect; include order: prelude -> substrate_closure.h ->
// substrate_common.h -> substrate_energy_lut.h -> this file.
//
//   float3 substrate_eval_closure(SubstrateClosure c, float3 V, float3 L)
//
// returns BSDF * NoL (no weight, no throughput of the layers above): GGX
// specular (+ haze lobe) with F0/F90 Fresnel on the exact curve of IOR 1.5
// and Turquin 2019 energy
// compensation, the diffuse model SUBSTRATE_DIFFUSE_MODEL scaled by
// (1 - E_spec(NoV)) (1 - E~(NoL)) / (1 - Ē~), SSS wrap, Charlie fuzz on
// top, glints and specular profiles.
// Formulas and references: README.md.
#ifndef SUBSTRATE_BSDF_H
#define SUBSTRATE_BSDF_H 1

#include "substrate_hair.h"  // a hair closure's lobes (substrate_eval_closure branches to them)
#include "substrate_eye.h"   // an eye closure's iris (substrate_eval_closure's diffuse)

// The including shader may define this before including the runtime to tint
// the specular with its profile atlas: index = profile index (uint), uv =
// float2(NoV, NoL). Default: no tint.
#ifndef SUBSTRATE_SPECULAR_PROFILE_SAMPLE
#define SUBSTRATE_SPECULAR_PROFILE_SAMPLE(index, uv) SUBSTRATE_SPLAT3(1.0)
#endif

// SUBSTRATE_NOV_BIAS, SUBSTRATE_SSS_WRAP_MFP_SCALE, SUBSTRATE_GLINT_*: substrate_constants.h.

// SUBSTRATE_MIN_ALPHA, the smallest GGX alpha: substrate_closure.h.
// Smallest Charlie sheen alpha (the table generator uses the same).
SUBSTRATE_CONST float SUBSTRATE_FUZZ_MIN_ALPHA = 1e-3;

// ---------------------------------------------------------------------------
// Frames.

// Unit shading normal of a closure (falls back to +Z for a zero normal); c.N
// itself when the includer promises unit normals (SUBSTRATE_UNIT_CLOSURE_NORMALS).
float3 substrate_closure_normal(SubstrateClosure c) {
#if SUBSTRATE_UNIT_CLOSURE_NORMALS
  return c.N;
#else
  return substrate_safe_normalize(c.N, float3(0.0, 0.0, 1.0));
#endif
}

// Tangent frame around the unit normal N: c.T made orthogonal to N (one
// Gram-Schmidt step); the Duff et al. basis when c.T is (nearly) parallel to N.
void substrate_closure_frame(SubstrateClosure c, float3 N, out float3 T, out float3 B) {
  float3 t0;
  float3 b0;
  substrate_orthonormal_basis(N, t0, b0);
  T = substrate_safe_normalize(c.T - N * dot(N, c.T), t0);
  B = cross(N, T);
}

// The share of the curve chi in an interface's Fresnel, from its largest
// channel's F0: 1 up to 0.1 (a dielectric), 0 from 0.2 (a conductor, which
// keeps Schlick's curve t = (1 - c)^5: the ground truth's conductor, by
// Gulbrandsen 2014, is fitted to it, and chi is up to 0.037 from it), linear
// between, as substrate_closure_fresnel_ends reads conductors. The curve is
// then t + share D(t). (The layers above are read as a dielectric: a
// conductor-like top over layers lets through 1 - chi where it reflects up
// to (1 - F0) 0.037 more at grazing; the random stacks of
// Furnace.RandomStacksOfTwoToEightSlabsNeverGainEnergy stay within 1.001.)
float substrate_fresnel_share(float f0max) {
  return 1.0 - saturate((f0max - SUBSTRATE_COAT_DIELECTRIC_F0) * SUBSTRATE_COAT_CONDUCTOR_BLEND);
}

// How much of a closure of largest F0 f0max is read as a metalness mix (0 up
// to SUBSTRATE_MIX_START, 1 from 0.25; substrate_closure_dielectric_part).
float substrate_mix_share(float f0max) {
  return saturate((f0max - SUBSTRATE_MIX_START) * SUBSTRATE_MIX_BLEND);
}

// The Fresnel curve of a closure's interface between its ends: the share of
// the dielectric curve (substrate_fresnel_share), that curve's coefficients
// d = (a, b) of D(t) = (1 - t) s (a + b s), s = sqrt(t), t = (1 - c)^5
// (chi's (A, B), substrate_fresnel_delta, or a low-IOR interface's) and the
// least share of a negative D(t) its albedo bound gives up (pull,
// substrate_fresnel_b; 0 for chi), and per channel the coefficients of
// w(t) = t + (1 - t) s (a + b s) (the conductor's and the dielectric's
// blended by the share). Without SUBSTRATE_USE_CONDUCTOR_CURVE the curve is
// t + share D(t), one weight per light, and a, b are unused; without
// SUBSTRATE_USE_LOW_IOR_CURVE d is chi's and pull 0.
struct SubstrateFresnelCurve {
  float share;
  float2 d;
  float pull;
  float3 a;
  float3 b;
};

// The curve of an interface of F0 f0 (per channel, in [0, 1]) and the
// dielectric curve's share.
// - A dielectric (step 24), where the share is 1: the exact Fresnel of the IOR
//   its largest channel's F0 reads (SUBSTRATE_DIELECTRIC_CURVE_*: chi from F0
//   0.04 on; below it a curve that rises later toward grazing, where chi was
//   0.069 above the exact one at F0 0.01 and 0.186 at 0.002), weighed by
//   `lowIor` (in [0, 1]: chi elsewhere, substrate_closure_fresnel_ends). One
//   curve for the three channels, as chi: a dielectric's F0 is grey.
// - A conductor (issue 19, step 23), where the share is 0: per channel, the
//   ground truth's Gulbrandsen conductor of that channel's F0
//   (SUBSTRATE_CONDUCTOR_CURVE_*: within 0.0063 in reflectance from F0 0.02;
//   Schlick's curve, which conductors followed before, reflected up to 16 %
//   less than it at cosine 0.4 for F0 0.14, so a grey conductor of F0 0.14
//   read -11.6 % albedo at NoV 0.4), weighed by `conductor` (in [0, 1]: how
//   much of it replaces Schlick's, substrate_closure_fresnel_ends).
// The coefficients linear between. With the Fresnel ends, at each evaluation
// of the closure (per light and for the environment).
SubstrateFresnelCurve substrate_fresnel_curve(float3 f0, float share, float conductor, float lowIor) {
  SubstrateFresnelCurve k;
  k.share = share;
  k.d = float2(SUBSTRATE_FRESNEL_CURVE_A, SUBSTRATE_FRESNEL_CURVE_B);
  k.pull = 0.0;
#if SUBSTRATE_USE_LOW_IOR_CURVE
  float y = min(sqrt(max(substrate_max3(f0), SUBSTRATE_DIELECTRIC_CURVE_MIN_F0)), SUBSTRATE_DIELECTRIC_CURVE_X);
  float below = (y - SUBSTRATE_DIELECTRIC_CURVE_X) * lowIor;  // <= 0
  k.d += below * float2(SUBSTRATE_DIELECTRIC_CURVE_P0 + y * (SUBSTRATE_DIELECTRIC_CURVE_P1 + y * SUBSTRATE_DIELECTRIC_CURVE_P2),
                        SUBSTRATE_DIELECTRIC_CURVE_Q0 + y * (SUBSTRATE_DIELECTRIC_CURVE_Q1 + y * SUBSTRATE_DIELECTRIC_CURVE_Q2));
  k.pull = min(SUBSTRATE_DIELECTRIC_CURVE_PULL_MAX, below * -SUBSTRATE_DIELECTRIC_CURVE_PULL_SLOPE);
#endif
#if SUBSTRATE_USE_CONDUCTOR_CURVE
  float3 x = sqrt(max(f0, SUBSTRATE_SPLAT3(SUBSTRATE_CONDUCTOR_CURVE_MIN_F0)));
  float3 a2 = SUBSTRATE_CONDUCTOR_CURVE_A2 + x * SUBSTRATE_CONDUCTOR_CURVE_A3;
  float3 b2 = SUBSTRATE_CONDUCTOR_CURVE_B2 + x * SUBSTRATE_CONDUCTOR_CURVE_B3;
  float3 a = max(SUBSTRATE_CONDUCTOR_CURVE_A0 + x * (SUBSTRATE_CONDUCTOR_CURVE_A1 + x * a2), SUBSTRATE_SPLAT3(0.0));
  float3 b = SUBSTRATE_CONDUCTOR_CURVE_B0 + x * (SUBSTRATE_CONDUCTOR_CURVE_B1 + x * b2);
  k.a = lerp(a * conductor, SUBSTRATE_SPLAT3(k.d.x), share);
  k.b = lerp(b * conductor, SUBSTRATE_SPLAT3(k.d.y), share);
#else
  k.a = SUBSTRATE_SPLAT3(k.d.x);
  k.b = SUBSTRATE_SPLAT3(k.d.y);
#endif
  return k;
}

// F90 as Substrate defines it: "F90 can only change the chromaticity, not the
// intensity" (the course notes: it does not take energy away at grazing
// angles). A conductor's F90 (F0 from 0.2: substrate_fresnel_share 0) gives
// the hue only, F90 / its largest channel (white for a black F90), so its
// Fresnel reaches full intensity at grazing, as every conductor's does. A
// dielectric's (F0 up to 0.1, share 1) keeps its intensity: importers switch
// a dielectric's grazing reflection off with it (Standard Surface's
// `specular` 0). Linear between, by the share. Without it a metal of F90 0
// (Standard Surface with `specular` 0, as `Metal_Brushed`) went black at
// grazing angles: -17.8 / -30.5 % at NoV 0.2 / 0.1 (issue 19, step 11).
float3 substrate_f90_effective(float3 f0, float3 f90) {
  float m = substrate_max3(f90);
  float3 hue = lerp(SUBSTRATE_SPLAT3(1.0), f90 / max(m, 1e-6), step(1e-6, m));
  return lerp(hue, f90, substrate_fresnel_share(substrate_max3(f0)));
}

// The F0 b of a metalness mix's conductor part, per channel, from the mixed
// F0 f and the diffuse A = b (1 - m) beside a dielectric part of F0 d: the
// mixed F0 is f = d + m (b - d), so b is the larger root of
// b^2 - (f + A) b + d A = 0 (issue 19, step 15). Not clamped.
float3 substrate_mix_conductor_f0(float3 f, float3 a, float d) {
  float3 s = f + a;
  return 0.5 * (s + sqrt(max(s * s - (4.0 * d) * a, SUBSTRATE_SPLAT3(0.0))));
}

// The dielectric part of a metalness mix under layers (issue 19, step 25):
// per channel, `weight` times its share 1 - m = A / b of a mix of F0 f0
// (against air) and diffuse A, b its conductor part's F0
// (substrate_mix_conductor_f0 at d = SUBSTRATE_MIX_DIELECTRIC_F0); at most
// `weight`. Under a coat that part is index-matched (F0 and F90 0,
// SUBSTRATE_MIX_DIELECTRIC_F0_UNDER) where the mix kept its 1 - m share of
// F0 0.04 and of F90 1 against air: car_paint (metallic 0.6 under a clear
// coat) read +8.8 / +7.2 % at NoV 1 / 0.4, its parts alone +1.9 and +5.7 %
// head-on.
float3 substrate_closure_mix_under(SubstrateClosure c, float3 f0, float weight) {
  float3 a = saturate(c.diffuseAlbedo);
  float3 b = substrate_mix_conductor_f0(f0, a, SUBSTRATE_MIX_DIELECTRIC_F0);
  return min(a / max(b, SUBSTRATE_SPLAT3(1e-4)), SUBSTRATE_SPLAT3(1.0)) * weight;
}

// The Fresnel ends of a closure: its reflectance at normal incidence, and at
// grazing incidence (white unless it has the F90 feature; then
// substrate_f90_effective), and the curve between them
// (substrate_fresnel_curve: the share of the dielectric curve from the
// largest channel of the relative F0, each channel's conductor curve from its own).
// The conductor's own curve (issue 19, step 23) where the truth walks a
// conductor: a closure of no diffuse and no medium (an opaque slab of diffuse
// 0 and F0 above 0.1 is Gulbrandsen's conductor there), or a metalness mix's
// (substrate_mix_share: the mix's conductor part, read at the mixed F0).
// Elsewhere Schlick's, as before: a slab of F0 above 0.1 over a diffuse or a
// medium is a dielectric of high IOR in the truth, nearer Schlick's in albedo
// (glTF IORTestGrid's transmitting IOR 2.42 sphere read +3.6 / +10.7 % at NoV
// 0.6 / 0.4 with the conductor's curve, -4.6 / -0.8 % with Schlick's). And not under
// layers (by 1 - coverageAbove): the lobe reads the Fresnel at the outside
// angles where the truth's light reaches it refracted by the layers (at
// cosines from 0.745 for IOR 1.5, where every curve is near F0), and the
// layers' terms for it (substrate_closure_coat_specular) were built on
// Schlick's; with its own curve the control conductor_under_clear_coat rose
// from +3.3 to +5.1 % at NoV 0.4.
// A dielectric of F0 below 0.04 follows the curve of its own IOR (issue 19,
// step 24) by `lowIor`: not under layers (1 - coverageAbove), whose relative F0
// is read on chi (step 2), nor on top of them (coversLayers): the layers'
// interface term lets 1 - chi through to what lies under the top (step 17: a
// clear coat of IOR 1 on its own curve returned 0.44 of a white furnace).
//
// Under layers (coverageAbove > 0) the interface is relative to the layers
// above, read as a dielectric of F0 0.04 (SUBSTRATE_COAT_SQRT_F0): a slab's F0
// says its IOR against air, n = (1 + sqrt F0) / (1 - sqrt F0), and under a
// medium of IOR 1.5 it reflects ((s - 0.2) / (1 - 0.2 s))^2 at normal
// incidence (s = sqrt F0), never more than in air. Only the dielectric range
// (F0 <= 0.1) is made relative: above 0.2 a slab is read as a conductor and
// keeps its F0 (as the ground truth walks conductors), with a linear blend
// between. The ratio, taken on the largest channel's F0 (one square root: a
// dielectric's F0 is grey; a coloured metal, or a metalness mix whose metal
// part reaches 0.2 in a channel, is read as a conductor) and blended by
// coverageAbove, scales F0 and F90 alike (an index-matched boundary, F0 0.04
// under 0.04, reflects nothing at any angle).
// Without it a base under a clear coat kept its own 4 % specular and its
// diffuse coupling to air: once the coat's trapped light is returned
// (substrate_closure_coat_diffuse) the clear coat control read +4.5 .. +7.3 %
// over the truth and a white Lambertian under a clear coat of the same IOR
// returned up to 1.003 of the light head-on.
void substrate_closure_fresnel_ends(SubstrateClosure c, out mfloat3 f0, out mfloat3 f90,
                                    out SubstrateFresnelCurve curve) {
  float3 f0f = saturate(c.f0);
  float3 f90f = SUBSTRATE_SPLAT3(1.0);
#if SUBSTRATE_USE_F90
  if ((c.features & SUBSTRATE_FEATURE_F90) != 0u) {
    f90f = substrate_f90_effective(f0f, saturate(c.f90));
  }
#endif
  float f = substrate_max3(f0f);
  float conductor = max(substrate_max3(saturate(c.diffuseAlbedo)), substrate_max3(c.sssMfp)) > 0.0 ? 0.0 : 1.0;
#if SUBSTRATE_USE_METALNESS_MIX
  conductor = max(conductor, substrate_mix_share(f));
#endif
  float lowIor = 1.0;
#if SUBSTRATE_USE_LAYERS
  conductor *= 1.0 - saturate(c.coverageAbove);
  lowIor = c.coversLayers ? 0.0 : 1.0 - saturate(c.coverageAbove);
  // No branch: at coverageAbove 0 the scale is exactly 1. In float: one
  // conversion per end in half precision.
  float s = sqrt(f);
  float r = (s - SUBSTRATE_COAT_SQRT_F0) / (1.0 - SUBSTRATE_COAT_SQRT_F0 * s);
  float rel = min(f, r * r);
  rel = lerp(rel, f, saturate((f - SUBSTRATE_COAT_DIELECTRIC_F0) * SUBSTRATE_COAT_CONDUCTOR_BLEND));
  float scale = lerp(1.0, rel / max(f, 1e-4), saturate(c.coverageAbove));
  f0f *= scale;
  f90f *= scale;
#if SUBSTRATE_USE_METALNESS_MIX
  // A metalness mix's dielectric part is relative to the layers too
  // (substrate_closure_mix_under), where its conductor part keeps its F0.
  float3 part = substrate_closure_mix_under(c, f0f, substrate_mix_share(f) * saturate(c.coverageAbove));
  f0f = max(f0f - part * (SUBSTRATE_MIX_DIELECTRIC_F0 - SUBSTRATE_MIX_DIELECTRIC_F0_UNDER), SUBSTRATE_SPLAT3(0.0));
  f90f *= SUBSTRATE_SPLAT3(1.0) - part * (1.0 - SUBSTRATE_MIX_DIELECTRIC_F0_UNDER / SUBSTRATE_MIX_DIELECTRIC_F0);
#endif
  f *= scale;
#endif
  curve = substrate_fresnel_curve(f0f, substrate_fresnel_share(f), conductor, lowIor);
  f0 = SUBSTRATE_M3(f0f);
  f90 = SUBSTRATE_M3(f90f);
}

// The diffuse model's lobe factor of G_k (SUBSTRATE_COAT_LOBE_*): Chan 2024's
// or EON's, 1 for the others.
float substrate_coat_lobe(float chan2024, float eon) {
#if SUBSTRATE_DIFFUSE_MODEL == 2
  return chan2024;
#elif SUBSTRATE_DIFFUSE_MODEL == 3
  return eon;
#else
  return 1.0;
#endif
}

// What the diffuse model adds to the mean of the fuzz pair's light term at
// roughness r (SUBSTRATE_FUZZ_PAIR_MARGIN_*): 0 for Lambert.
float substrate_fuzz_pair_margin(float roughness) {
#if SUBSTRATE_DIFFUSE_MODEL == 1
  return SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2018_0;
#elif SUBSTRATE_DIFFUSE_MODEL == 2
  return SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2024_1 * roughness;
#elif SUBSTRATE_DIFFUSE_MODEL == 3
  return SUBSTRATE_FUZZ_PAIR_MARGIN_EON_1 * roughness;
#else
  return 0.0;
#endif
}

// substrate_coat_mean_share, h(f): substrate_closure.h (set per pixel in SubstrateClosure.coatShare).

// What the diffuse of a closure under layers gets back from them, per
// channel: 1 / D under a full coverage, lerp(D, P, C) / (D lerp(1, P, C))
// under a coverage C = coverageAbove, P = (T_N G)^2 (below), with
//   D = G_k T_i (1 - 0.12 (1 - T_i)) + TRAP A (1 - T_m^4).
// The adding formula for a Lambertian under a smooth interface of IOR n over
// a medium of transmittance T_m (along the normal), with the slab's albedo A
// read as seen through an interface of its own (the convention of the
// format): light the base reflects up is sent back down by the interface's
// underside (hemispherical reflectance R_i, 0.596 at n = 1.5, most of it
// total internal reflection) and returns, so the diffuse is multiplied by
//   1 / (n^2 (1 - R_i) + n^2 A (R_i - R_i(T_m))),
// R_i(T_m) the share of the trapped light the medium lets make its round trip,
// 0.596 exp(-3.53 x^0.9) (x = -ln T_m, fitted to the integral within 0.01)
// replaced here by 0.596 T_m^4 (within 0.012: two multiplies). At T_m = 1 it is
// 1 / (1 - F_avg): what the light-side throughput takes on average, given
// back, so a white base under a clear coat returns all it receives.
// n^2 (1 - R_i) is replaced by the cosine-weighted mean of the lighting's own
// light-side interface term, G_k T_i^1.13 (G_k = 2 int mu g(mu)^(1 + k) dmu:
// 0.95238 / 0.91991 / 0.89524 / 0.87535 for k = extraInterfaces 0..3, T_i the
// interfaces' share of topTransmittance, I 0.96^k unless the layers let more
// through, I = c.coatInterface the top's own 1 - F0 (substrate_coat_interface;
// 0.96 before issue 19 step 18, when a clear coat of F0 0.06 read as media of
// transmittance 0.98 and lost 12 % of a white furnace), the k interfaces under
// it read as IOR 1.5's), bounded above by Bernoulli's inequality so that the
// normalized light side never averages above 1. T_m = topTransmittance / (I 0.96^k).
// A is the closure's diffuse albedo. The closure's own interface (f0, f90:
// substrate_closure_fresnel_ends) couples the diffuse to the light too, and
// both couplings fall toward grazing light, so the mean of their product
// exceeds the product of their means by up to their covariance:
// Var((1 - mu)^5) = 0.0129 under the cosine, times F90 - F0, over 1 - E_avg
// >= 0.9, so the first term is raised by 1 + 0.0145 (mean F90 - mean F0)
// (0 for the usual index-matched base, whose interface is gone). Without it a
// base of F0 0.805 under an F0-0 layer returned 1.0013 and a closure under a
// half coverage 1.0025 (furnace_test.cc); with it the largest is 1.0008.
// Under a rough top the term is larger at grazing angles, and G_k becomes
// G_k + (1 - G_k) h(f) (substrate_coat_mean_share, a bound from above).
// G_k is for a cosine-distributed lobe: a rough one that favours light near the
// normal takes more of the light-side term, so it is raised by the diffuse
// model's bound of that (substrate_coat_lobe: Chan 2024 1.0062 at k = 0, EON
// 1.0037; issue 19 step 7).
// `ends`: the means of the closure's F0 and F90 (substrate_diffuse_interface).
float3 substrate_closure_coat_diffuse(SubstrateClosure c, float2 ends) {
#if !SUBSTRATE_USE_LAYERS
  return SUBSTRATE_SPLAT3(1.0);
#else
  // No branch: at coverageAbove 0 the factor is exactly 1.
  float cover = saturate(c.coverageAbove);
  float gk = SUBSTRATE_COAT_G_0;
  float lobe = substrate_coat_lobe(SUBSTRATE_COAT_LOBE_CHAN2024_0, SUBSTRATE_COAT_LOBE_EON_0);
  float ifc = c.coatInterface;  // the top's; each interface under it 0.96
#if SUBSTRATE_USE_EXTRA_INTERFACES
  if (c.extraInterfaces == 1u) {
    gk = SUBSTRATE_COAT_G_1;
    lobe = substrate_coat_lobe(SUBSTRATE_COAT_LOBE_CHAN2024_1, SUBSTRATE_COAT_LOBE_EON_1);
    ifc *= SUBSTRATE_COAT_T_0;
  } else if (c.extraInterfaces == 2u) {
    gk = SUBSTRATE_COAT_G_2;
    lobe = substrate_coat_lobe(SUBSTRATE_COAT_LOBE_CHAN2024_2, SUBSTRATE_COAT_LOBE_EON_2);
    ifc *= SUBSTRATE_COAT_T_1;
  } else if (c.extraInterfaces >= 3u) {
    gk = SUBSTRATE_COAT_G_3;
    lobe = substrate_coat_lobe(SUBSTRATE_COAT_LOBE_CHAN2024_3, SUBSTRATE_COAT_LOBE_EON_3);
    ifc *= SUBSTRATE_COAT_T_2;
  }
#endif
#if SUBSTRATE_USE_COAT_FLOOR || SUBSTRATE_USE_COAT_ANISO
  float share = c.coatShare;  // 0 under a smooth top
#else
  float share = 0.0;  // the floor is 0
#endif
  float g = (gk + (1.0 - gk) * share) * lobe;
  float3 tn = saturate(c.topTransmittance);
  float3 ti = max(tn, SUBSTRATE_SPLAT3(ifc));
  float3 tm = saturate(tn / ifc);  // ifc >= 0.82 * 0.96^3
  float3 tm2 = tm * tm;
  g *= 1.0 + SUBSTRATE_COAT_COVARIANCE * saturate(ends.y - ends.x);  // the closure's own interface
  float3 d = g * ti * (1.0 - SUBSTRATE_COAT_BEND * (1.0 - ti)) +
             SUBSTRATE_COAT_TRAP * saturate(c.diffuseAlbedo) * (1.0 - tm2 * tm2);
  // Under a partial coverage only the covered part gives back or absorbs what
  // its top traps (issue 19, step 22): the lighting lets lerp(1, P, C)
  // through (P = t_V t_L, substrate_light_closure) where (1 - C) + C P / D is
  // due, so the factor is lerp(D, P, C) / (D lerp(1, P, C)), P read as the
  // mean round trip (T_N G)^2, G the light-side interface term's mean above
  // (floored so that an opaque layer keeps the quotient); 1 / D under a full
  // coverage, 1 at coverage 0.
  float3 p = max(tn * g * (tn * g), SUBSTRATE_SPLAT3(1e-30));
  return lerp(d, p, cover) / (d * lerp(SUBSTRATE_SPLAT3(1.0), p, cover));
#endif
}

// ---------------------------------------------------------------------------
// GGX.

// substrate_ggx_alpha, (ax, ay) from roughness and anisotropy: substrate_closure.h.

// Isotropic GGX NDF: a^2 / (pi ((a^2 - 1) NoH^2 + 1)^2). With NoH in [0, 1]
// the bracket is >= a^2, so D <= 1 / (pi a^2).
float substrate_ggx_d(float a, float NoH) {
  float a2 = a * a;
  float n = saturate(NoH);
  float d = (n * a2 - n) * n + 1.0;
  return a2 / (SUBSTRATE_PI * max(d * d, 1e-30));
}

// Anisotropic GGX NDF (Burley 2012), written as a2 w^2 / pi with
// w = a2 / |(ay ToH, ax BoH, a2 NoH)|^2 and a2 = ax ay (finite for ax, ay in
// [1e-3, 1] and unit H).
float substrate_ggx_d_aniso(float2 alpha, float ToH, float BoH, float NoH) {
  float a2 = alpha.x * alpha.y;
  float3 v = float3(alpha.y * ToH, alpha.x * BoH, a2 * NoH);
  float w = a2 / max(dot(v, v), 1e-30);
  return a2 * w * w * SUBSTRATE_INV_PI;
}

// Height-correlated Smith visibility G2 / (4 NoV NoL) (Heitz 2014):
// 0.5 / (NoL sqrt(NoV^2 (1 - a^2) + a^2) + NoV sqrt(NoL^2 (1 - a^2) + a^2)).
float substrate_ggx_vis(float a, float NoV, float NoL) {
  float a2 = a * a;
  float gv = NoL * sqrt(NoV * NoV * (1.0 - a2) + a2);
  float gl = NoV * sqrt(NoL * NoL * (1.0 - a2) + a2);
  return 0.5 / max(gv + gl, 1e-30);
}

// Anisotropic height-correlated visibility:
// 0.5 / (NoL |(ax ToV, ay BoV, NoV)| + NoV |(ax ToL, ay BoL, NoL)|).
float substrate_ggx_vis_aniso(float2 alpha, float ToV, float BoV, float NoV, float ToL, float BoL, float NoL) {
  float gv = NoL * length(float3(alpha.x * ToV, alpha.y * BoV, NoV));
  float gl = NoV * length(float3(alpha.x * ToL, alpha.y * BoL, NoL));
  return 0.5 / max(gv + gl, 1e-30);
}

// GGX distribution D and visibility V of one lobe of roughness alpha: the
// anisotropic forms (frame dot products ToH, BoH, ToV, BoV, ToL, BoL) when
// `aniso`, else the isotropic ones with alpha.x.
void substrate_ggx_d_vis(float2 alpha, bool aniso, float ToH, float BoH, float NoH, float ToV, float BoV, float NoV,
                         float ToL, float BoL, float NoL, out float d, out float vis) {
  if (aniso) {
    d = substrate_ggx_d_aniso(alpha, ToH, BoH, NoH);
    vis = substrate_ggx_vis_aniso(alpha, ToV, BoV, NoV, ToL, BoL, NoL);
  } else {
    d = substrate_ggx_d(alpha.x, NoH);
    vis = substrate_ggx_vis(alpha.x, NoV, NoL);
  }
}

// The Fresnel curve of every interface between its ends (issue 19, step 4;
// docs/accuracy.md, "4. The Fresnel curve"): chi(c) = t + D(t), t = (1 - c)^5
// Schlick's weight (the curve before) and
//   D(t) = (1 - t) s (0.18317 - 0.39315 s),  s = sqrt(t),
// a fit (least squares on 4,001 cosines, scripts/fit_fresnel_albedo.py) of
// (F(c) - 0.04) / 0.96, F the exact Fresnel of IOR 1.5: within 9.7e-4 of it
// at every cosine, where Schlick's is 22.8 % below it at c = 0.6 and 6.2 % above
// it at 0.1 (F0 0.04). chi(1) = 0 and chi(0) = 1. One curve for every
// interface, so that the layers above (read as IOR 1.5) let through exactly
// what a top of any F0 does not reflect (substrate_coat_transmission).
// Other F0 keep this IOR's curve: at c = 0.6 an F0 of 0.02 reads 0.045 where
// its own IOR reflects 0.039 (Schlick's 0.030), an F0 of 0.1 0.123 against
// 0.137 (0.109); a conductor's normalized curve lies near Schlick's (the
// ground truth's Gulbrandsen mapping is fitted to it): this one is within
// 0.037 of it.
float substrate_fresnel_delta(float t) {
  float s = sqrt(t);
  return (1.0 - t) * s * (SUBSTRATE_FRESNEL_CURVE_A + SUBSTRATE_FRESNEL_CURVE_B * s);
}

// D(t) of the form above with the coefficients d = (a, b) of a curve
// (SubstrateFresnelCurve.d).
float substrate_fresnel_delta_of(float t, float2 d) {
  float s = sqrt(t);
  return (1.0 - t) * s * (d.x + d.y * s);
}

// chi(c) (above), for c clamped to [0, 1]: in [0, 1] with no clamp of its
// own (t + D(t) >= t - 0.21 (1 - t) s > 0 for t in (0, 1], and D(t) <= 1 - t).
float substrate_fresnel_weight(float c) {
  float t = substrate_pow5(1.0 - c);
  return t + substrate_fresnel_delta(t);
}

// The angular part of what the layers' interface lets through along a
// direction at cosine mu, normalized to 1 at normal incidence (where T_N
// already holds its 1 - F0). The layers above are read as one interface of
// IOR 1.5: at least 1 - chi(mu), chi the Fresnel curve every interface
// follows (Schlick's (1 - mu)^5 before issue 19 step 4), so that (1 - F0)
// times the term is at least 1 - F(mu), what a smooth top of that F0 (and F90
// 1) does not reflect. Without it a coat reflected F(mu) at a grazing view and
// still let 1 - F0 reach the base: a white base under a clear coat returned
// 1.21 of the light at NoV 0.1 (docs/stability.md). The smooth transmission
// falls to 0 at grazing angles; a rough top reflects far less there, and what
// it does not reflect reaches the layers under it (issue 19, step 9). What an interface of F0 0 and F90 1
// and roughness r lets through, 1 - b (b the chi-weighted part of the tables'
// albedo, substrate_fresnel_b at share 1), is the least any top of F0 0 ..
// 0.04 lets through per unit of T_N (which holds its 1 - F0): 1 - b + F0 (1 -
// e) / (1 - F0) >= 1 - b. Without a lookup: max(1 - chi(mu), 1 - (1 - f)
// (1 - mu)^2), f = c.coatFloor (substrate_coat_floor of the top layer's
// roughness): the largest f of that form that keeps the term within max(1 -
// chi(mu), 1 - b) at every mu (scripts/fit_coat_transmission.py; it takes 46 %
// of the light that 1 - b adds at r 0.2, 85 % at r 1). At r 0.6 the term is
// 0.85 at mu 0.1 (a smooth top: 0.45); up to r 0.1 it is the smooth one.
// Without it a white Lambertian under a clear coat of roughness 1 returned
// 0.46 of the light at NoV 0.1, a white conductor 0.46.
float substrate_coat_transmission(float mu, float coatFloor) {
#if SUBSTRATE_USE_COAT_FLOOR || SUBSTRATE_USE_COAT_ANISO
  float m = 1.0 - saturate(mu);
  return max(1.0 - substrate_fresnel_weight(mu), 1.0 - (1.0 - coatFloor) * (m * m));
#else
  return 1.0 - substrate_fresnel_weight(mu);  // the floor is 0: the smooth term, exactly
#endif
}

// The floor of the layers' top along the unit direction w at cosine mu
// (issue 19, step 19): c.coatFloor, but under one stretched top
// (c.coatStretch) substrate_coat_floor_projected at w's azimuth about the
// top's tangent, cos^2 phi = sat((T.w)^2 / (1 - mu^2)). No branch: one of the
// two is 0 (a stretched top has no coatFloor; any other leaves coatStretch 0).
// Compiled only with SUBSTRATE_USE_COAT_ANISO.
float substrate_coat_floor_along(SubstrateClosure c, float mu, float3 w) {
#if SUBSTRATE_USE_COAT_ANISO
  float tw = dot(c.coatTangent, w);
  float c2 = saturate(tw * tw / max(1.0 - mu * mu, 1e-8));
  return max(c.coatFloor, substrate_coat_floor_projected(c.coatStretch, c2));
#else
  return c.coatFloor;
#endif
}

// For light with no one direction (the split sum's diffuse, at cosine mu): a
// direction at the azimuths' mean about the layers' stretched top, cos^2 phi
// = 0.5. substrate_coat_floor_along reads only T.w of it, so T sqrt((1 -
// mu^2) / 2) stands for it (a constant factor at a constant mu).
float3 substrate_coat_mean_direction(SubstrateClosure c, float mu) {
  return c.coatTangent * sqrt(0.5 * (1.0 - mu * mu));
}

// The angular part of the 1 + `extra` interfaces above a closure (extra =
// SubstrateClosure.extraInterfaces, 0..3): the interface term to the power
// 1 + extra, by multiplies. A stack of clear coats lets through no more than
// each of its interfaces in turn: with one term for the whole stack every
// further interface reflected its F(mu) and still passed everything on (issue
// 16: six white transparent slabs returned 1.38 of the light at NoV 0.1).
// Interfaces beyond 1 + 3 are folded into topTransmittance by the material
// (substrate_extra_interfaces, substrate_tree.h). Compiled only when some
// closure of the material (or scene) has extra interfaces.
float substrate_interfaces_transmission(float mu, uint extra, float coatFloor) {
  float g = substrate_coat_transmission(mu, coatFloor);
#if SUBSTRATE_USE_EXTRA_INTERFACES
  float g2 = g * g;
  if (extra == 1u) {
    g = g2;
  } else if (extra == 2u) {
    g = g2 * g;
  } else if (extra >= 3u) {
    g = g2 * g2;
  }
#endif
  return g;
}

// The path length, per unit thickness, of a direction at cosine mu above the
// layers once refracted into them (read as a dielectric of IOR 1.5,
// substrate_constants.h): 1 / mu_t, mu_t = sqrt(1 - (1 - mu^2) / 1.5^2) =
// sqrt(1.25 + mu^2) / 1.5, so 1.5 rsqrt(1.25 + mu^2), in [1, 1.342]. Light
// crosses the media above along it: with mu itself a grazing ray crossed them
// 13x farther than it does (1 / 0.1 against 1 / 0.75), and the interfaces'
// (1 - F0), which topTransmittance holds, was raised to the power 1 / mu too.
float substrate_coat_path_length(float mu) {
  float m = saturate(mu);
  return 1.5 * rsqrt(1.25 + m * m);
}

// T_N^(1/mu_t) * g(mu)^(1 + extraInterfaces), g the layers' interface term
// under their top (substrate_coat_transmission): what the layers above let
// through along a direction at cosine mu where they cover the closure (their
// media along the refracted path 1 / mu_t = substrate_coat_path_length(mu),
// T_N clamped to [1e-30, 1] as substrate_transmittance_at_cosine does, and
// their interfaces). Float: the remap (exp, log) and the interface term
// (1 - chi(mu) cancels at grazing). Callers take it only under layers
// (coverageAbove > 0): a closure on top pays no transcendental.
float3 substrate_closure_layers_crossing(SubstrateClosure c, float mu, float3 w) {
  float3 t = clamp(c.topTransmittance, SUBSTRATE_SPLAT3(SUBSTRATE_MIN_TRANSMITTANCE), SUBSTRATE_SPLAT3(1.0));
  return exp(log(t) * substrate_coat_path_length(mu)) *
         substrate_interfaces_transmission(mu, c.extraInterfaces, substrate_coat_floor_along(c, mu, w));
}

// lerp(1, substrate_closure_layers_crossing(c, mu, w), coverageAbove): the
// throughput of the layers above along one direction, blended by their
// coverage (in [0, 1], mfloat); 1 with no transcendental on top.
mfloat3 substrate_closure_above_throughput(SubstrateClosure c, float mu, float3 w) {
#if SUBSTRATE_USE_LAYERS
  float cover = saturate(c.coverageAbove);
  if (cover > 0.0) {
    return mlerp(SUBSTRATE_MSPLAT3(1.0), SUBSTRATE_M3(substrate_closure_layers_crossing(c, mu, w)), SUBSTRATE_M(cover));
  }
#endif
  return SUBSTRATE_MSPLAT3(1.0);
}

// Issue 19, step 22: the view and the light cross the same covering. Where
// layers cover a closure in part (coverageAbove C < 1: a coat under a weight),
// a path either meets them on both sides or on neither: its throughput is
// (1 - C) + C t_V t_L, not the product of the two blends, which is lower by
// C (1 - C)(1 - t_V)(1 - t_L) (with it, and the diffuse darkened alike by what
// only the covered part traps, substrate_closure_coat_diffuse, a tinted coat
// over half the surface lost 20 %).
// So the light meets the layers with the coverage that the view's crossing
// t_V leaves: C t_V / ((1 - C) + C t_V), per channel, in [0, 1]; C itself
// where C is 0 or 1 (t_V / t_V is exactly 1 in float) and where t_V is 1.
float3 substrate_cover_given_view(float cover, float3 viewCrossing) {
  float3 seen = cover * viewCrossing;
  return seen / max(SUBSTRATE_SPLAT3(1.0 - cover) + seen, SUBSTRATE_SPLAT3(1e-30));
}

// The Fresnel of an interface with an F90: F0 + (F90 - F0) w(VoH), w the
// curve (substrate_fresnel_curve: chi for a dielectric, each channel's own for
// a conductor; the weight from the half vector in float, the blend of the
// colours in mfloat).
mfloat3 substrate_fresnel(mfloat3 f0, mfloat3 f90, SubstrateFresnelCurve k, float VoH) {
  float t = substrate_pow5(1.0 - VoH);
#if SUBSTRATE_USE_CONDUCTOR_CURVE
  float s = sqrt(t);
  float3 w = t + ((1.0 - t) * s) * (k.a + k.b * s);
  return f0 + (f90 - f0) * SUBSTRATE_M3(w);
#else
  float w = t + k.share * substrate_fresnel_delta_of(t, k.d);
  return f0 + (f90 - f0) * SUBSTRATE_M(w);
#endif
}

// An upper bound of the part of a lobe's albedo weighted by the Fresnel curve
// chi, E mean(chi(VoH)), from the tables' (E - B, B) (B weighted by
// Schlick's t = (1 - VoH)^5) and e, their sum clamped (an upper bound of E):
// with the lobe's mean t = B / e, e (t + D(t)) for a smooth lobe, exactly;
// a rough one's mean of D(t) is below D(mean t) where D < 0 (Jensen's
// inequality), so that part is taken times 1 - pull:
// e (t + D(t) - pull min(D(t), 0)). With pull = k(r) (substrate_fresnel_pull,
// fitted on the integral at every roughness and view,
// scripts/fit_fresnel_albedo.py) it is at most 0.016 above the lobe's in the
// albedo of an F0 0.04 interface (Schlick's missed by up to 0.036 either
// way); a stretched lobe, whose B_max and E_max (substrate_energy_aniso) the
// fit does not cover, takes pull = 1: e (t + max(D(t), 0)). `share` is the
// curve's (substrate_fresnel_share): e (t + share (D - pull min(D, 0))).
// A low-IOR curve (substrate_fresnel_curve) takes the same bound with its own
// D and a pull of at least its own (k.pull: such a curve is more convex in t
// than chi); a conductor's with its own D per channel. Returns it per channel
// for the curve k (xyz) and for chi (w: a closure's dielectric part,
// substrate_dielectric_albedo).
float4 substrate_fresnel_b(float2 dfg, float e, float pull, SubstrateFresnelCurve k) {
  float t = min(dfg.y / e, 1.0);  // dfg.y >= 0, e > 0
  float d = substrate_fresnel_delta(t);
  float x = d - pull * min(d, 0.0);
#if SUBSTRATE_USE_LOW_IOR_CURVE
  float pullk = max(pull, k.pull * k.share);
#else
  float pullk = pull;
#endif
#if SUBSTRATE_USE_CONDUCTOR_CURVE
  float s = sqrt(t);
  float3 dk = ((1.0 - t) * s) * (k.a + k.b * s);
  float3 xk = dk - pullk * min(dk, SUBSTRATE_SPLAT3(0.0));
  return e * float4(t + xk, t + x);
#elif SUBSTRATE_USE_LOW_IOR_CURVE
  float dd = substrate_fresnel_delta_of(t, k.d);
  return e * float4(SUBSTRATE_SPLAT3(t + k.share * (dd - pullk * min(dd, 0.0))), t + x);
#else
  return e * float4(SUBSTRATE_SPLAT3(t + k.share * x), t + x);
#endif
}

// k(r) of substrate_fresnel_b: 0.43 below roughness 0.45, 0 from there (the
// share the fit needs is at most 0.425, at r 0.225, and 0 from r 0.45 on).
float substrate_fresnel_pull(float roughness) {
  return roughness < SUBSTRATE_FRESNEL_ROUGH_END ? SUBSTRATE_FRESNEL_ROUGH_K : 0.0;
}

// The directional albedo of a lobe whose albedo with F = 1 is below e and
// whose chi-weighted part is below b (substrate_fresnel_b), an upper bound:
// F0 e + max(F90 - F0, 0) b per channel. An inverted edge (F90 < F0) reflects
// at most F0 at any angle: F0 e (the tables give no lower bound of the
// chi-weighted part; with Schlick's curve the pair's E - B bounded it).
// In float (one conversion back): in half precision the clamp of the colour
// difference cost lavapipe 25 % more executed instructions on row12_simple.
mfloat3 substrate_fresnel_albedo(mfloat3 f0, mfloat3 f90, float e, float3 b) {
  float3 f0f = SUBSTRATE_F3(f0);
  return SUBSTRATE_M3(f0f * e + max(SUBSTRATE_F3(f90) - f0f, SUBSTRATE_SPLAT3(0.0)) * b);
}

// The compensated albedo of a closure's dielectric part (substrate_closure_dielectric_part),
// a grey interface of F0 d.x and F90 d.y on the whole curve (b: substrate_fresnel_b
// at share 1): (d.x e + max(d.y - d.x, 0) b) (1 + d.x (1 - e) / e). Scalar.
float substrate_dielectric_albedo(float2 d, float e, float b) {
  return saturate((d.x * e + max(d.y - d.x, 0.0) * b) * (1.0 + d.x * ((1.0 - e) / e)));
}

// The Fresnel ends (F0, F90) of the interface a closure's diffuse lies under:
// its dielectric part (SUBSTRATE_MIX_START). A closure whose largest F0 is a
// dielectric's (up to 0.18) is all dielectric: its largest channels (E_d >=
// E_spec up to F0 0.1, where both follow the curve chi; from there E_d keeps
// chi where E_spec blends toward Schlick's: +0.9 % albedo at NoV 0.1 for F0
// 0.17 over a diffuse of 0.8, toward the truth). From F0 0.25 it is read as a metalness
// mix whose dielectric part is SUBSTRATE_MIX_DIELECTRIC_F0 with F90 1, both
// relative to the layers above by coverageAbove as substrate_closure_fresnel_ends
// makes a dielectric (index-matched under them at 0.04); linear between.
// Without SUBSTRATE_USE_METALNESS_MIX: (1, 1), the whole interface.
float2 substrate_closure_dielectric_part(SubstrateClosure c, mfloat3 f0, mfloat3 f90) {
#if SUBSTRATE_USE_METALNESS_MIX
  float cover = 0.0;
#if SUBSTRATE_USE_LAYERS
  cover = saturate(c.coverageAbove);
#endif
  float f = substrate_max3(SUBSTRATE_F3(f0));
  float2 mixed = float2(lerp(SUBSTRATE_MIX_DIELECTRIC_F0, SUBSTRATE_MIX_DIELECTRIC_F0_UNDER, cover),
                        lerp(1.0, SUBSTRATE_MIX_DIELECTRIC_F0_UNDER / SUBSTRATE_MIX_DIELECTRIC_F0, cover));
  return lerp(float2(f, substrate_max3(SUBSTRATE_F3(f90))), mixed,
              substrate_mix_share(f));
#else
  return SUBSTRATE_SPLAT2(1.0);
#endif
}

// The F0 that Turquin's W reads (substrate_specular_energy), per channel. A
// metalness mix (issue 19, step 15; docs/accuracy.md, "15. A metalness mix
// scatters in each part") is a conductor of F0 b beside a dielectric part of
// F0 d = fd.x (substrate_closure_dielectric_part), of metallic m, each
// compensated for its own multiple scattering: the F0-weighted mean of their
// W = 1 + F_i k is 1 + k E[F_i^2] / E[F_i], so W reads F + Var / F, with
// Var = m (1 - m)(b - d)^2 = (F - d)(b - F): the mixed F0 is F = d + m (b - d)
// and the diffuse albedo A = b (1 - m), so b is the larger root of
// b^2 - (F + A) b + d A = 0, at most 1; times t = substrate_mix_share (0 for
// a dielectric). At most 1 (Var / F <= b - F). One lobe of the mixed F0 with
// W = 1 + F k returned 0.90 of a white furnace (metallic 0.5, roughness 0.8).
// The closure's own F0 without SUBSTRATE_USE_METALNESS_MIX.
mfloat3 substrate_closure_compensated_f0(SubstrateClosure c, mfloat3 f0, float2 fd) {
#if SUBSTRATE_USE_METALNESS_MIX
  float3 f = SUBSTRATE_F3(f0);
  float3 a = saturate(c.diffuseAlbedo);
  float3 b = min(substrate_mix_conductor_f0(f, a, fd.x), SUBSTRATE_SPLAT3(1.0));
  float3 var = max(f - SUBSTRATE_SPLAT3(fd.x), SUBSTRATE_SPLAT3(0.0)) * max(b - f, SUBSTRATE_SPLAT3(0.0));
  return SUBSTRATE_M3(f + substrate_mix_share(substrate_max3(f)) * var / max(f, SUBSTRATE_SPLAT3(1e-4)));
#else
  return f0;
#endif
}

// The channel means of F0 and F90 of the interface the diffuse lies under, for
// its light-side coupling and the layers' covariance term: F0 and F90 at most
// the dielectric part's (substrate_closure_dielectric_part) per channel. (F90
// too since issue 19 step 6: a mix's dielectric part under a coat is
// index-matched, F0 = F90 = 0, where F90 1 gave its diffuse a coupling and a
// covariance term of an interface that is not there.) Float.
float2 substrate_diffuse_interface(mfloat3 f0, mfloat3 f90, float2 fd) {
  float3 f = SUBSTRATE_F3(f0);
  float3 g = SUBSTRATE_F3(f90);
#if SUBSTRATE_USE_METALNESS_MIX
  f = min(f, SUBSTRATE_SPLAT3(fd.x));
  g = min(g, SUBSTRATE_SPLAT3(fd.y));
#endif
  return float2(dot(f, SUBSTRATE_SPLAT3(1.0 / 3.0)), dot(g, SUBSTRATE_SPLAT3(1.0 / 3.0)));
}

// What a closure's dielectric lobe scatters between and through its facets,
// per unit of perceptual roughness (SUBSTRATE_DIELECTRIC_MS; issue 19, step
// 20): the lobe and its albedo take 1 + share rate r. None for a top over
// layers (coversLayers): the layers' interface term under it (1 - chi, or
// under a rough top its floor) is what a single-scattering top does not
// reflect, so a top that reflected more would still let that through (a white
// base under a stretched clear coat returned 1.008 of a white furnace).
float substrate_closure_dielectric_ms(SubstrateClosure c) {
  return c.coversLayers ? 0.0 : SUBSTRATE_DIELECTRIC_MS;
}

// Turquin 2019 multiple-scattering compensation W = 1 + F0w (1 - E) / E (F0w
// the closure's F0, or a metalness mix's substrate_closure_compensated_f0),
// times 1 + share msRate r (substrate_closure_dielectric_ms: a dielectric's
// multiple scattering), and the
// compensated lobe's directional albedo E_spec = (F0 E + (F90 - F0) B_chi) W,
// from the tables at (NoV, r) (upper bounds of E - B and B; E = their sum
// clamped to [1e-3, 1]; B_chi bounded from them, substrate_fresnel_b and
// substrate_fresnel_albedo). Returns W; E_spec in `albedo`. Both are safe for
// energy: W E <= 1 and E_spec is never below the compensated lobe's true
// albedo. The table lookup and E are float; W (<= 1000) and E_spec are colours
// (mfloat).
mfloat3 substrate_specular_energy(mfloat3 f0, mfloat3 f90, SubstrateFresnelCurve curve, float2 fd, mfloat3 f0w,
                                  float msRate, float NoV, float roughness, out mfloat3 albedo, out float dielectric) {
  float2 dfg = substrate_energy_dfg(NoV, roughness);
  float e = clamp(dfg.x + dfg.y, 1e-3, 1.0);
  float ms = msRate * roughness;
  mfloat3 w = (SUBSTRATE_MSPLAT3(1.0) + f0w * SUBSTRATE_M((1.0 - e) / e)) * SUBSTRATE_M(1.0 + curve.share * ms);
  float4 b = substrate_fresnel_b(dfg, e, substrate_fresnel_pull(roughness), curve);
  albedo = msaturate(substrate_fresnel_albedo(f0, f90, e, b.xyz) * w);
  dielectric = saturate(substrate_dielectric_albedo(fd, e, b.w) * (1.0 + ms));
  return w;
}

// The same for a lobe of anisotropy A. A stretched lobe's albedo leaves the
// isotropic family (seen along its rough axis at NoV 0.1, r 0.5, A 0.5:
// E = 0.918, above the isotropic E at every alpha in [ay, ax]; head-on at r 1,
// |A| 1: 0.533, below every isotropic lobe's) and depends on the view's azimuth
// (r 1, |A| 1, NoV 0.1: 0.53 along the smooth axis, 0.86 along the rough one).
// E and B are E_max and B_max(NoV, r, |A|), the largest over the azimuths
// (substrate_energy_aniso): W = 1 / E_max gains energy at no azimuth and is
// exact at normal incidence, and the diffuse below gets no more than 1 - E_spec
// of the true lobe (issue 19; docs/accuracy.md, "Anisotropy"). F0 multiplies
// E_max itself (substrate_fresnel_albedo): no table bounds E - B at every
// azimuth, E_max does.
// Compiled only with SUBSTRATE_USE_ANISOTROPY (the optimizer does not remove
// the branch for a constant A = 0). docs/stability.md, "Energy: the white furnace".
mfloat3 substrate_specular_energy_aniso(mfloat3 f0, mfloat3 f90, SubstrateFresnelCurve curve, float2 fd, mfloat3 f0w,
                                        float msRate, float NoV, float roughness, float anisotropy, out mfloat3 albedo,
                                        out float dielectric) {
  float2 dfg = substrate_energy_dfg(NoV, roughness);
  float e = clamp(dfg.x + dfg.y, 1e-3, 1.0);
  float pull = substrate_fresnel_pull(roughness);
#if SUBSTRATE_USE_ANISOTROPY
  float A = min(abs(anisotropy), 1.0);
  if (A > 0.0) {
    float2 eb = substrate_energy_aniso(NoV, roughness, A, float2(e, dfg.y));
    e = eb.x;
    dfg.y = min(eb.y, e);
    pull = 1.0;
  }
#endif
  float ms = msRate * roughness;
  mfloat3 w = (SUBSTRATE_MSPLAT3(1.0) + f0w * SUBSTRATE_M((1.0 - e) / e)) * SUBSTRATE_M(1.0 + curve.share * ms);
  float4 b = substrate_fresnel_b(dfg, e, pull, curve);
  albedo = msaturate(substrate_fresnel_albedo(f0, f90, e, b.xyz) * w);
  dielectric = saturate(substrate_dielectric_albedo(fd, e, b.w) * (1.0 + ms));
  return w;
}

// What the interface lets through to the diffuse along the view, per
// channel: 1 - E_spec, unless the closure is a metalness mix (issue 19,
// item 5; SUBSTRATE_MIX_DIELECTRIC_F0): its diffuse lies under the
// dielectric part, which reflects E_d (substrate_dielectric_albedo), not
// the mixed F0's E_spec, so it gets 1 - min(E_spec, E_d); never more than
// the energy the interface leaves, (1 - E_spec) / albedo, so that the
// closure's albedo, albedo (...) + E_spec, stays at most 1 (a slab of
// diffuse 1 and F0 0.5 is not a mix: it keeps 1 - E_spec). A metalness mix
// of base colour b, metallic m and dielectric F0 fd has diffuse b (1 - m)
// and 1 - E_spec = (1 - m)(1 - E_d) + m (1 - E_b), so the bound holds it
// where b is 1. Float (albedo may be 0).
float3 substrate_diffuse_transmission_of(float3 albedo, float3 specAlbedo, float dielectric) {
#if SUBSTRATE_USE_METALNESS_MIX
  return min(SUBSTRATE_SPLAT3(1.0) - min(specAlbedo, SUBSTRATE_SPLAT3(dielectric)),
             (SUBSTRATE_SPLAT3(1.0) - specAlbedo) / max(albedo, SUBSTRATE_SPLAT3(1e-3)));
#else
  return SUBSTRATE_SPLAT3(1.0) - specAlbedo;
#endif
}

// The same for the lighting's colours (one conversion back in half precision).
mfloat3 substrate_diffuse_transmission(mfloat3 albedo, mfloat3 specAlbedo, float dielectric) {
#if SUBSTRATE_USE_METALNESS_MIX
  return SUBSTRATE_M3(substrate_diffuse_transmission_of(SUBSTRATE_F3(albedo), SUBSTRATE_F3(specAlbedo), dielectric));
#else
  return SUBSTRATE_MSPLAT3(1.0) - specAlbedo;
#endif
}

// What the lobe of a conductor under layers keeps, per channel (issue 19,
// step 6; docs/accuracy.md, "6. A conductor under a coat"). Light crosses the
// layers (read as a dielectric of IOR 1.5) at mu_i = sqrt(1 - (1 - mu^2) /
// 1.5^2), never below the critical cosine 0.74536; a smooth lobe sends it back
// there, but a rough one spreads it, and the share R it sends below the
// critical cosine is reflected back down by the layers' top (total internal
// reflection) and meets the closure again:
//   R = P1 a^2 / (a^2 + P2 dV dL) + P3 a^2,
// a the GGX alpha of the (haze-lerped) roughness, d = mu_i - 0.74536 along the
// view and along the light (their product keeps it reciprocal;
// SUBSTRATE_COAT_TIR_*, a fit to the integral, scripts/fit_coat_tir.py). Each
// pass leaves the interface by (1 - R) g, g the layers' interface term at the
// larger of NoV and NoL (substrate_coat_transmission, as the throughputs take
// it) times the interface's own transmission head-on, T_i = max(T_N, I)
// (I = c.coatInterface, 1 - F0 of the layers' top: T_N holds it; the coat
// diffuse splits T_N so too), and the closure reflects e of the rest, times the
// media's round trip, T_m = sat(T_N / I): e is its hemispherical albedo (the mean
// Fresnel F0 + (F90 - F0) / 21 and the diffuse below it,
// substrate_diffuse_transmission_of: one value for every direction, so the
// factor stays reciprocal). The round trip is T_m^2 for what the interface
// reflects near the normal, T_m^4 for the trapped share: it crosses the media
// below the critical cosine, at twice the path or more (issue 19, step 14:
// with T_m^2 a white conductor of roughness 0.7 under a smooth coat of
// transmittance 0.7 returned +19.8 % head-on, +6.3 % with T_m^4). With R' = t R
// and g' = lerp(1, T_i g, t), t = 1 - share (under a full coverage; below):
//   k = (1 - R') / (1 - e T_m^2 (R' T_m^2 + (1 - R') (1 - g'))).
// A white closure under clear layers gets 1 / g'. The light-side throughput
// is at most T_m g' (in every channel), and T_m h / (1 - T_m^2 (1 - h)) <= 1
// for h = (1 - R') g' in [0, 1] (T_m^4 R' <= T_m^2 R' only lowers k), so the
// lobe returns no more than the view's
// throughput lets in, as without the factor; the media's scattering is the
// layers' own albedo and is not given back. All of this is the part the layers
// cover; under a coverage C < 1 the factor is lerp(1, P k, C) / lerp(1, P, C),
// P = (T_N g)^2 (issue 19, step 22: the lighting lets (1 - C) + C t_V t_L
// through, and only the covered part gets its light back; with t blended by C
// instead, the part the layers leave bare was given light back too).
// Under one rough top (coatFloor f > 0; issue 19, step 14) two more terms:
// R is read at a - TOP_SPREAD coverageAbove a_t (a_t the top's alpha,
// substrate_coat_top_alpha), because the closure's roughness holds the top's
// spread (Belcour's widening) and that spread is mostly undone on the way out;
// and the lobe crosses the media along an extra Q f^3 (p(NoV) (1 - NoV)^2 +
// p(NoL) (1 - NoL)^2) t (SUBSTRATE_COAT_ROUGH_PATH), k times T_m to that
// power: grazing light refracted by tilted facets runs flatter than 1 / mu_t.
// A white conductor of roughness 0.4 under a top of roughness 0.4 and
// transmittance 0.7 read -5.2 / +1.0 / +9.8 / +15.0 / +17.5 / +19.7 % at
// NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1, -5.3 / -2.1 / +1.4 / +1.5 / +2.5 /
// +5.2 % with them (scripts/scan_tinted_coat.py). (Issue 19 step 13: with g' =
// lerp(1, g, t) the 4 % the interface reflects head-on on the way out never
// came back: a white conductor of roughness 0.4 under a clear coat returned
// 0.90 .. 0.94 of a white furnace, 0.93 .. 0.97 with T_i.) Without the
// factor a rough conductor under a clear coat returned all its lobe reflects:
// +21 / +33 / +19 / +11 % at NoV
// 1 / 0.6 / 0.2 / 0.1 over the truth
// (bench/materials/conductor_under_clear_coat.json), +1.5 / +1.3 / +3.2 /
// +3.2 % with it. Only for conductors: at share 1 (F0 up to 0.1) the factor
// is exactly 1 (a dielectric's trapped light returns through its diffuse,
// substrate_closure_coat_diffuse), and the compiler clears
// SUBSTRATE_USE_COAT_CONDUCTOR when every closure under a layer has such a
// constant F0. Float.
// How far a cosine mu in [0, 1], once refracted into the layers above (IOR
// 1.5), lies above their critical cosine: sqrt(1 - (1 - mu^2) / 1.5^2) -
// 0.74536, in [0, 0.2546] (substrate_closure_coat_specular's d).
float substrate_coat_critical_margin(float mu) {
  return max(sqrt(1.0 - (1.0 - mu * mu) * SUBSTRATE_COAT_INV_ETA2) - SUBSTRATE_COAT_CRITICAL_COS, 0.0);
}

// The GGX alpha of the layers' one rough top, whose spread the closure's
// roughness holds (substrate_closure_coat_specular): substrate_coat_top_alpha
// of the floor under an isotropic top; under a stretched one (issue 19, step
// 19) its alphas' mean, (a_x + a_y) / 2 = r^2, back from coatStretch (a
// conductor of roughness 0.4 under a clear coat of roughness 0.6 and
// anisotropy 0.8 read -6.1 / -7.3 / -6.0 % at NoV 1 / 0.6 / 0.2 with none,
// -3.0 / -4.8 / -4.9 % with it). 0 under no one rough top.
float substrate_closure_coat_top_alpha(SubstrateClosure c) {
  float a = 0.0;
#if SUBSTRATE_USE_COAT_FLOOR
  a = substrate_coat_top_alpha(c.coatFloor);
#endif
#if SUBSTRATE_USE_COAT_ANISO
  a = max(a, 0.5 * (sqrt(c.coatStretch.x) + sqrt(c.coatStretch.x + c.coatStretch.y)));  // one of the two is 0
#endif
  return a;
}

float3 substrate_closure_coat_specular(SubstrateClosure c, mfloat3 f0, mfloat3 f90, float2 fd, float share, float NoV,
                                       float NoL, float roughness) {
#if !SUBSTRATE_USE_LAYERS || !SUBSTRATE_USE_COAT_CONDUCTOR
  return SUBSTRATE_SPLAT3(1.0);
#else
  // No branch: at coverageAbove 0 (or share 1) the factor is exactly 1.
  float cover = saturate(c.coverageAbove);
  float t = 1.0 - share;  // where the layers cover the closure
  float r = saturate(roughness);
  float a = r * r;
#if SUBSTRATE_USE_COAT_FLOOR || SUBSTRATE_USE_COAT_ANISO
  a -= SUBSTRATE_COAT_TOP_SPREAD * cover * substrate_closure_coat_top_alpha(c);
#endif
  a = max(a, SUBSTRATE_MIN_ALPHA);
  float a2 = a * a;
  float v = saturate(NoV);
  float l = saturate(NoL);
  float dv = substrate_coat_critical_margin(v);
  float dl = substrate_coat_critical_margin(l);
  float trapped =
      t * (SUBSTRATE_COAT_TIR_P1 * a2 / (a2 + SUBSTRATE_COAT_TIR_P2 * dv * dl) + SUBSTRATE_COAT_TIR_P3 * a2);
  // The closure's hemispherical albedo: its interface's mean Fresnel and what
  // that lets through to its diffuse (the dielectric part's, for a mix).
  float3 f0f = SUBSTRATE_F3(f0);
  float3 fAvg = f0f + (SUBSTRATE_F3(f90) - f0f) * (1.0 / 21.0);
  float dAvg = fd.x + (fd.y - fd.x) * (1.0 / 21.0);
  float3 albedo = saturate(c.diffuseAlbedo);
  float3 e = saturate(fAvg + albedo * substrate_diffuse_transmission_of(albedo, fAvg, dAvg));
  float3 tn = saturate(c.topTransmittance);
  float3 tm = saturate(tn / c.coatInterface);  // coatInterface >= 0.82
  float3 tm2 = tm * tm;
  float3 ti = max(tn, SUBSTRATE_SPLAT3(c.coatInterface));
  float g = substrate_coat_transmission(max(v, l), c.coatFloor);
  float3 gl = lerp(SUBSTRATE_SPLAT3(1.0), ti * g, t);
  float3 back = tm2 * (trapped * tm2 + (1.0 - trapped) * (SUBSTRATE_SPLAT3(1.0) - gl));
  float3 k = (1.0 - trapped) / (SUBSTRATE_SPLAT3(1.0) - e * back);
#if SUBSTRATE_USE_COAT_FLOOR
  float f = saturate(c.coatFloor);
  float mv = 1.0 - v;
  float ml = 1.0 - l;
  float extra = SUBSTRATE_COAT_ROUGH_PATH * (f * f * f) * t *
                (substrate_coat_path_length(v) * (mv * mv) + substrate_coat_path_length(l) * (ml * ml));
  k *= exp(log(max(tm, SUBSTRATE_SPLAT3(SUBSTRATE_MIN_TRANSMITTANCE))) * extra);
#endif
  // The covered part alone gets k (issue 19, step 22): lerp(1, P k, C) / lerp(1, P, C),
  // P = (T_N g)^2 the round trip the lighting lets through where the layers cover.
  float3 p = max(tn * g * (tn * g), SUBSTRATE_SPLAT3(1e-30));
  return lerp(SUBSTRATE_SPLAT3(1.0), p * k, cover) / lerp(SUBSTRATE_SPLAT3(1.0), p, cover);
#endif
}

// Karis' analytic fit ("Physically Based Shading on Mobile", 2014; UE's
// EnvBRDFApprox) of an interface's directional albedo, E~(mu, r) = F0 A + F90 B,
// with B refitted for the Fresnel curve chi (issue 19, step 4; it was
// Schlick's (1 - VoH)^5 part: 2^(-9.28 mu), (A, B) = (-1.04, 1.04) a + c.zw,
// c.y = 0.0425 - 0.0275 r): the cosine-weighted squared error against the
// integral of chi over the lobe, at 41 roughnesses and 30 cosines from 0.005
// to 1 (scripts/fit_fresnel_albedo.py), falls from 7.2e-5 to 3.9e-5. (Fitted to
// the view side's bound, substrate_fresnel_b, instead, the rough dielectric
// of Accuracy.ADiffuseUnderAnInterfaceIsReciprocal read 1.055, not 1.052.)
// c = r (-1, -0.00645, -0.572, 0.022) + (1, 0.03195, 1.04, -0.04),
// a = min(c.x^2, 2^(-7.925 mu)) c.x + c.y, (A, B) = (-1.0091, 1.0091) a + c.zw.
// A dozen instructions where the tables' E_spec costs eight fetches.
float2 substrate_interface_albedo_fit(float mu, float roughness) {
  float r = saturate(roughness);
  float4 c = r * float4(-1.0, -0.00645, -0.572, 0.022) + float4(1.0, 0.03195, 1.04, -0.04);
  float a = min(c.x * c.x, exp2(-7.925 * mu)) * c.x + c.y;
  return float2(-1.0091, 1.0091) * a + c.zw;
}

// (X, Y): the cosine-weighted means over the hemisphere, 2 int A mu dmu and
// 2 int B mu dmu, of the fit above at roughness r, as lower bounds: X is a
// quartic in r (least squares on 257 roughnesses, within 3.5e-4 of the
// midpoint rule with 4,096 points) and Y = 1 - 0.55 r - X (A + B = 1 - 0.55 r
// exactly), each lowered by 4e-4 (tests/unit/reference_test.cc,
// ReferenceEnergy.TheDiffuseLightCouplingKeepsTheViewsAlbedo).
float2 substrate_interface_albedo_means(float roughness) {
  float r = saturate(roughness);
  float x = 0.942790291 + r * (-0.503803993 + r * (0.019770635 + r * (0.050697408 + r * -0.067537130)));
  return float2(x - 4e-4, 1.0 - 0.55 * r - x - 4e-4);
}

// The diffuse lobe's light-side coupling, (1 - E~(NoL)) / (1 - Ē~)
// (Kelemen & Szirmay-Kalos 2001; Kulla & Conty 2017's coupling of a lobe
// under an interface): light entering at a grazing NoL is mostly reflected by
// the interface and feeds the diffuse less (x 0.25 at NoL 0.05 under a smooth
// F0 0.04, x 1.05 at normal incidence). E~ is Karis' fit (above), Ē~ = F0 X + F90 Y
// its cosine-weighted mean over the hemisphere (substrate_interface_albedo_means,
// lower bounds), so the coupling's mean is at most 1 (within 5e-4 of it for
// F0 <= 0.1): the diffuse's directional albedo along the view,
// albedo (1 - E_spec(NoV)), is kept, and the lobe is reciprocal in its Fresnel
// terms to the fit's accuracy. Haze: the fit and the means of both lobes
// blended by the haze weight before the division (the mean stays 1). The
// isotropic fit serves an anisotropic lobe too. The denominator is at least
// 1e-3 (F0 -> 1: the coupling underestimates, never adds). An inverted edge
// (F90 < F0) reflects least at grazing, so its coupling would grow toward the
// horizon, where the rough diffuse models weigh light more than Lambert's
// cosine does (a white furnace of 1.026 at F0 1, F90 0, r 0.5, NoV 0.1 with
// Chan 2024): there the coupling is at most 1. One scalar for the three
// channels, from the means of F0 and F90 (any scalar interface keeps the mean
// of 1; one division instead of three). Float; converted once (<= 1000). No
// table: the fit and the means' polynomial cost about as much as one fetch.
mfloat substrate_diffuse_light_coupling(float2 ends, float NoL, float roughness, float hazeRoughness,
                                        float hazeWeight) {
  float mu = max(NoL, SUBSTRATE_MIN_COS);
  float2 ab = substrate_interface_albedo_fit(mu, roughness);
  float2 m = substrate_interface_albedo_means(roughness);
  if (hazeWeight > 0.0) {
    ab = lerp(ab, substrate_interface_albedo_fit(mu, hazeRoughness), hazeWeight);
    m = lerp(m, substrate_interface_albedo_means(hazeRoughness), hazeWeight);
  }
  float F0 = ends.x;  // the means of F0 and F90 (substrate_diffuse_interface)
  float F90 = ends.y;
  float numerator = max(1.0 - F0 * ab.x - F90 * ab.y, 0.0);
  float denominator = max(1.0 - F0 * m.x - F90 * m.y, 1e-3);
  float cap = F90 < F0 ? 1.0 : 1000.0;
  return SUBSTRATE_M(min(numerator / denominator, cap));
}

// An upper bound of the coupling's standard deviation over the cosine-weighted
// hemisphere of light (issue 19, step 16: the normalization of the diffuse's
// pair of fuzz terms in substrate_eval_closure uses it). Karis' fit is affine
// in one function a(mu, r): the coupling is 1.0091 (F90 - F0) a / D plus a
// constant (D its denominator), clamped, which never widens a spread. So its
// deviation is at most 1.0091 (F90 - F0) sigma_a(r) / D, sigma_a a cubic in r
// at or above a's deviation at every roughness (0.113 at r = 0, 0.035 at 0.5,
// 0 at 1; fitted to the midpoint rule with 4,000 points at 1,001 roughnesses,
// at most 0.004 above it; ReferenceEnergy.TheCouplingDeviationBoundsTheFits),
// blended toward the haze lobe's by its weight (the deviation of a blend is at
// most the blend of the deviations). Only F90 > F0 counts: a and
// min(E_fuzz, 1) both fall as the light rises, so under an inverted edge the
// coupling rises toward the horizon and the two never correlate positively.
float substrate_diffuse_light_coupling_deviation(float2 ends, float roughness, float hazeRoughness,
                                                 float hazeWeight) {
  float2 r = saturate(float2(roughness, hazeRoughness));
  float2 s = ((0.184984 * r - 0.192478) * r - 0.101418) * r + 0.112939;
  float2 m = substrate_interface_albedo_means(roughness);
  if (hazeWeight > 0.0) {
    s.x = lerp(s.x, s.y, hazeWeight);
    m = lerp(m, substrate_interface_albedo_means(hazeRoughness), hazeWeight);
  }
  float denominator = max(1.0 - ends.x * m.x - ends.y * m.y, 1e-3);
  return 1.0091 * max(ends.y - ends.x, 0.0) * max(s.x, 0.0) / denominator;
}

// ---------------------------------------------------------------------------
// Diffuse models (each returns BRDF * NoL for albedo `albedo`).

mfloat3 substrate_diffuse_lambert(mfloat3 albedo, float NoL) {
  return albedo * SUBSTRATE_M(SUBSTRATE_INV_PI * saturate(NoL));
}

// Chan 2018, "Material Advances in Call of Duty: WWII": GGX-rough diffuse with
// g = sat(log2(2 / a^2 - 1) / 18) (a = r^2), a rough term VoH + (1 - VoH)^5,
// a smooth term (1 - 0.75 (1 - NoV)^5)(1 - 0.75 (1 - NoL)^5) blended by
// sat(2.2 g - 0.5), and a retro-reflection term
// ((34.5 g - 59) g + 24.5) VoH 2^(-max(73.2 g - 21.2, 8.9) sqrt(NoH)).
// As in UE, the lobe (f * pi) / pi is capped at 1. The model's directional
// albedo exceeds its albedo when rough and grazing (1.10 at r = 1, NoV -> 0;
// 1.035 at NoV 0.1): the lobe is divided by a bound of that excess, linear in r
// and NoV, 1 + max(0, 0.41 (r - 0.74) - 0.59 NoV) (fitted above the measured
// albedo; docs/stability.md), so it never returns more than `albedo`.
mfloat3 substrate_diffuse_chan2018(mfloat3 albedo, float roughness, float NoV, float NoL, float NoH, float VoH) {
  float r = saturate(roughness);
  float a2 = max(r * r * r * r, 1e-7);
  float g = saturate((1.0 / 18.0) * log2(2.0 / a2 - 1.0));
  float rough = VoH + substrate_pow5(1.0 - VoH);
  float smoothTerm = (1.0 - 0.75 * substrate_pow5(1.0 - NoV)) * (1.0 - 0.75 * substrate_pow5(1.0 - NoL));
  float fd = lerp(rough, smoothTerm, saturate(2.2 * g - 0.5));
  float fb = ((34.5 * g - 59.0) * g + 24.5) * VoH * exp2(-max(73.2 * g - 21.2, 8.9) * sqrt(saturate(NoH)));
  float lobe = min(1.0, SUBSTRATE_INV_PI * (fd + fb));
  float excess = max(0.0, 0.41 * (r - 0.74) - 0.59 * saturate(NoV));
  return albedo * SUBSTRATE_M(lobe * saturate(NoL) / (1.0 + excess));
}

// What Chan 2024's lobe loses of a white albedo at cosine mu, over r:
// 1 - E(mu, r) = r h, h = 1 - 0.38 r - Scale (1/2 + mu/3 + (Bias - 0.025) K1(mu)),
// because (NoH + Bias) / (NoH + 0.025) = 1 + (Bias - 0.025) / (NoH + 0.025) and
// int VoH^2 cos / pi = 1/2 + mu/3 exactly; K1 = int VoH^2 / (NoH + 0.025) cos / pi
// is a rational fit (SUBSTRATE_CHAN24_K1_*, scripts/fit_chan2024_energy.py).
float substrate_chan2024_loss(float mu, float r, float scale, float bias) {
  float k1 = (SUBSTRATE_CHAN24_K1_P0 +
              mu * (SUBSTRATE_CHAN24_K1_P1 + mu * (SUBSTRATE_CHAN24_K1_P2 + mu * SUBSTRATE_CHAN24_K1_P3))) /
             (mu + SUBSTRATE_CHAN24_K1_C);
  return 1.0 - 0.38 * r - scale * (0.5 + mu * (1.0 / 3.0) + (bias - 0.025) * k1);
}

// Chan 2024, "Multiscattering Diffuse and Specular BRDFs" (as UE ships it, with
// a Lambertian smooth limit): Scale = max(0.55 - 0.2 r, 1.25 - 1.6 r),
// Bias = sat(4 a), FRough = Scale (NoH + Bias) / (NoH + 0.025) VoH^2,
// f = albedo / pi (lerp(1, FRough, r) + 0.38 a). Its directional albedo
// exceeds `albedo` by up to 2.4 % at grazing views (NoV < 0.04) for r > 0.43:
// the lobe is divided by 1 + 0.026 sat(1 - NoV / 0.04) sat(10 (r - 0.42)), a
// bound of that excess (docs/stability.md). Elsewhere it returns only 0.94-1
// of `albedo` (issue 19, step 7): what it loses comes back as a reciprocal
// multiple-scattering lobe (Kulla & Conty 2017's form, as EON's),
// albedo / pi r max(h_V, 0) max(h_L, 0) / H, H = int h 2 mu dmu =
// 1 - 0.38 r - Scale (13/18 + (Bias - 0.025) M), whose directional albedo is
// r h_V = 1 - E: with it the white albedo is 0.9993-1.0000 for NoV >= 0.05.
// Under layers, substrate_closure_coat_diffuse bounds the lobe's shape
// (SUBSTRATE_COAT_LOBE_CHAN2024_*).
mfloat3 substrate_diffuse_chan2024(mfloat3 albedo, float roughness, float NoV, float NoL, float NoH, float VoH) {
  float r = saturate(roughness);
  float a = r * r;
  float scale = max(0.55 - 0.2 * r, 1.25 - 1.6 * r);
  float bias = saturate(4.0 * a);
  float n = saturate(NoH);
  float fRough = scale * (n + bias) / (n + 0.025) * VoH * VoH;
  float f = lerp(1.0, fRough, r) + 0.38 * a;
  float excess = 0.026 * saturate(1.0 - 25.0 * NoV) * saturate(10.0 * (r - 0.42));
  float lossAvg = 1.0 - 0.38 * r - scale * (13.0 / 18.0 + (bias - 0.025) * SUBSTRATE_CHAN24_K1_MEAN);
  float ms = r * max(substrate_chan2024_loss(saturate(NoV), r, scale, bias), 0.0) *
             max(substrate_chan2024_loss(saturate(NoL), r, scale, bias), 0.0) / max(lossAvg, 1e-4);
  return albedo * SUBSTRATE_M(SUBSTRATE_INV_PI * (f / (1.0 + excess) + ms) * saturate(NoL));
}

// E_FON(mu, r): the directional albedo of the Fujii Oren-Nayar lobe, the
// quartic fit of Portsmouth et al. 2025 (max error 5e-4).
float substrate_eon_albedo(float mu, float r) {
  float m = 1.0 - saturate(mu);
  float gOverPi = m * (0.0571085289 + m * (0.491881867 + m * (-0.332181442 + m * 0.0714429953)));
  return (1.0 + r * gOverPi) / (1.0 + 0.287793409 * r);
}

// EON, Portsmouth, Kutz & Hill 2025, "EON: A Practical Energy-Preserving Rough
// Diffuse BRDF": f = rho/pi AF (1 + r s/t) + rho_ms/pi (1 - E(mu_o))(1 - E(mu_i)) /
// (1 - E_avg), AF = 1 / (1 + c1 r), c1 = 1/2 - 2/(3 pi), E_avg = AF (1 + c2 r),
// c2 = 2/3 - 28/(15 pi), rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)).
// The EON roughness is 0.4 r (UE's match to GGX-distributed Lambertian facets).
// The albedo is inverted exactly for the model's hemispherical mean: with
// A = rho E_avg / (1 - rho (1 - E_avg)), rho = A / (E_avg + A (1 - E_avg)), so the
// mean albedo equals the closure's diffuseAlbedo (post multiple scattering).
// The angular terms are float, the albedo inversion per channel mfloat: with
// NoV >= 1e-4 (substrate_eval_closure's clamp) f_ss <= 1 + 0.4e4, within half.
mfloat3 substrate_diffuse_eon(mfloat3 albedo, float roughness, float NoV, float NoL, float VoL) {
  float r = 0.4 * saturate(roughness);
  float mo = saturate(NoV);
  float mi = saturate(NoL);
  float s = VoL - mo * mi;
  float sOverT = s > 0.0 ? s / max(max(mo, mi), 1e-6) : s;
  float af = 1.0 / (1.0 + 0.287793409 * r);
  float eAvg = af * (1.0 + 0.0724882125 * r);
  mfloat3 rho = albedo / (SUBSTRATE_MSPLAT3(eAvg) + albedo * SUBSTRATE_M(1.0 - eAvg));
  mfloat3 rhoMs = rho * rho * SUBSTRATE_M(eAvg) / (SUBSTRATE_MSPLAT3(1.0) - rho * SUBSTRATE_M(1.0 - eAvg));
  float fss = af * (1.0 + r * sOverT);
  float ms = max(1e-7, 1.0 - substrate_eon_albedo(mo, r)) * max(1e-7, 1.0 - substrate_eon_albedo(mi, r)) /
             max(1e-7, 1.0 - eAvg);
  return (rho * SUBSTRATE_M(fss) + rhoMs * SUBSTRATE_M(ms)) * SUBSTRATE_M(SUBSTRATE_INV_PI * mi);
}

// The diffuse model selected by SUBSTRATE_DIFFUSE_MODEL.
mfloat3 substrate_diffuse(mfloat3 albedo, float roughness, float NoV, float NoL, float NoH, float VoH, float VoL) {
#if SUBSTRATE_DIFFUSE_MODEL == 1
  return substrate_diffuse_chan2018(albedo, roughness, NoV, NoL, NoH, VoH);
#elif SUBSTRATE_DIFFUSE_MODEL == 2
  return substrate_diffuse_chan2024(albedo, roughness, NoV, NoL, NoH, VoH);
#elif SUBSTRATE_DIFFUSE_MODEL == 3
  return substrate_diffuse_eon(albedo, roughness, NoV, NoL, VoL);
#else
  return substrate_diffuse_lambert(albedo, NoL);
#endif
}

// ---------------------------------------------------------------------------
// SSS wrap.

// Per-channel wrap amount from the mean free path (meters):
// w = mfp / (mfp + SUBSTRATE_SSS_WRAP_MFP_SCALE), in [0, 1): 0 for no medium,
// 0.5 at mfp = 5 mm, -> 1 for very long paths.
float3 substrate_sss_wrap_amount(float3 mfp) {
  float3 m = max(mfp, SUBSTRATE_SPLAT3(0.0));
  return m / (m + SUBSTRATE_SPLAT3(SUBSTRATE_SSS_WRAP_MFP_SCALE));
}

// Energy-conserving wrap lighting: albedo / pi * max(NoL + w, 0) / (1 + w)^2
// (its integral over the sphere equals Lambert's over the hemisphere). The
// wrap factor (NoL + w cancels near the terminator) is float.
mfloat3 substrate_diffuse_wrap(mfloat3 albedo, float3 wrap, float NoL) {
  float3 w = saturate(wrap);
  float3 onePlus = SUBSTRATE_SPLAT3(1.0) + w;
  return albedo * SUBSTRATE_M3(SUBSTRATE_INV_PI * max(SUBSTRATE_SPLAT3(NoL) + w, SUBSTRATE_SPLAT3(0.0)) / (onePlus * onePlus));
}

// The cosine at which the light of a closure's lobes crosses the layers above
// (substrate_light_closure; issue 19, step 13): NoL, but for a wrap lobe
// (NoL + w) / (1 + w), w the smallest of the channels' wrap amounts. The wrap
// lobe is a Lambertian in that cosine (albedo / pi mu' / (1 + w) over the
// sphere, d(NoL) = (1 + w) d(mu')), so the layers' mean transmission, by which
// substrate_closure_coat_diffuse gives back what their underside reflects, is
// the one it meets. At NoL its light from below the horizon met a
// transmission of 0 under a smooth top and the light near it little: the
// wrap lobe under row40's clear coat (without its fuzz) returned 0.87 of a
// white furnace (-12.7 % against the truth head-on), 0.95 .. 0.97 with this
// cosine. The smallest channel's, as no channel then meets more than at its
// own cosine: the channels' mean gave 0.98 .. 0.99 there, but 1.044 for
// channels of MFP 0, 5 mm and 1 m (Furnace.NoClosureReturnsMoreEnergyThanItReceives).
float substrate_wrap_light_cosine(SubstrateClosure c, float NoL) {
#if SUBSTRATE_USE_SSS && SUBSTRATE_USE_LAYERS && SUBSTRATE_USE_WRAP_UNDER_LAYERS
  if (c.sssType == SUBSTRATE_SSS_WRAP) {
    float3 w3 = substrate_sss_wrap_amount(c.sssMfp);
    float w = saturate(min(w3.x, min(w3.y, w3.z)));
    return (NoL + w) / (1.0 + w);
  }
#endif
  return NoL;
}

// What the layers above let through at NoL over what they let through at the
// wrap lobe's cosine (at most 1, per channel; 1 for any other closure): the
// lighting applies the latter to the whole closure, and the lobes on its
// interface (specular, fuzz) meet the layers at NoL. Float.
float3 substrate_wrap_light_ratio(SubstrateClosure c, bool isWrap, float NoLc, float NoL, float3 L) {
#if SUBSTRATE_USE_SSS && SUBSTRATE_USE_LAYERS && SUBSTRATE_USE_WRAP_UNDER_LAYERS
  if (isWrap) {
    float3 at = SUBSTRATE_F3(substrate_closure_above_throughput(c, NoLc, L));
    float3 wrapped = SUBSTRATE_F3(substrate_closure_above_throughput(c, substrate_wrap_light_cosine(c, NoL), L));
    return min(at / max(wrapped, SUBSTRATE_SPLAT3(1e-4)), SUBSTRATE_SPLAT3(1.0));
  }
#endif
  return SUBSTRATE_SPLAT3(1.0);
}

// The cosines a fuzz under layers sees (issue 19, step 13). The layers are
// read as an interface of IOR eta = 1 + 0.5 coverageAbove (1.5 under full
// cover, 1 on top); the view and the light are refracted into them,
// V' = (V - N NoV) / eta + N mu'(NoV), mu'(mu) = sqrt(1 - (1 - mu^2) / eta^2)
// (at least the critical cosine 0.745 under full cover), and the fuzz is
// evaluated at N.V', N.L' and their half vector's N.H'; seen from above its
// lobe is the lobe inside over eta^2 (cos dw = eta^2 cos' dw'), so it returns
// what it reflects of the light from inside the refracted cone.
// The split sum and the translucency take the fuzz's albedo at the refracted
// view too.
// The sheen is strongest at grazing angles, which a fuzz under a clear coat
// never sees: evaluated at NoV, row40's fuzz read +8.6 % against the truth at
// NoV 0.4 and 0.2 (its slab alone: +2.2 / +1.9 %). On top the cosines are
// NoV, NoLc and NoH untouched (no instruction but the test).
// The cosine mu refracted into an interface of 1 / eta^2 = inv2, never below
// mu (rounding included).
float substrate_fuzz_refracted_cosine(float mu, float inv2) {
  return max(sqrt(max(1.0 - (1.0 - mu * mu) * inv2, 0.0)), mu);
}

float substrate_fuzz_cosine(SubstrateClosure c, float mu) {
#if SUBSTRATE_USE_LAYERS && SUBSTRATE_USE_FUZZ_UNDER_LAYERS
  float cover = saturate(c.coverageAbove);
  if (cover > 0.0) {
    float inv = 1.0 / (1.0 + 0.5 * cover);
    return substrate_fuzz_refracted_cosine(mu, inv * inv);
  }
#endif
  return mu;
}

// substrate_fuzz_cosine along the view and the light, the half vector's N.H'
// of the refracted pair and `spread` = NoL / (eta^2 NoL'), which turns the
// lobe inside times NoL' (substrate_charlie_sheen's f cos) into the lobe seen
// from above times NoL (fv, fl, fh, spread keep NoV, NoLc, NoH, 1 on top).
// The refracted directions are unit vectors, V' = (V - N NoV) / eta + N fv
// and L' likewise, so V'.L' = (VoL - NoV NoL) / eta^2 + fv fl and
// N.H' = (fv + fl) / sqrt(2 + 2 V'.L') (1 where V' = -L').
void substrate_fuzz_under_layers(SubstrateClosure c, float NoV, float NoL, float VoL, inout float fv, inout float fl,
                                 inout float fh, inout float spread) {
#if SUBSTRATE_USE_LAYERS && SUBSTRATE_USE_FUZZ_UNDER_LAYERS
  float cover = saturate(c.coverageAbove);
  if (cover > 0.0) {
    float inv = 1.0 / (1.0 + 0.5 * cover);
    spread = inv * inv;
    fv = substrate_fuzz_refracted_cosine(NoV, spread);
    fl = substrate_fuzz_refracted_cosine(max(NoL, 0.0), spread);
    float vl = (VoL - NoV * NoL) * spread + fv * fl;
    fh = saturate((fv + fl) * rsqrt(max(2.0 + 2.0 * vl, 1e-8)));
    spread *= max(NoL, 0.0) / max(fl, 1e-6);  // the lobe times NoL, not NoL' (fl >= NoL: at most 1)
  }
#endif
}

// ---------------------------------------------------------------------------
// A slab's medium seen through its interface (issue 19, step 12).
//
// A semi-infinite scattering medium is not Lambertian: light that enters
// along the normal goes deep and less of it comes back than the medium's
// albedo A (its spherical albedo, van de Hulst), light that enters at a
// grazing angle stays shallow and more comes back. With s = sqrt(1 - w') the
// medium's slope (w' its reduced single-scattering albedo), the directional
// albedo is R(mu) = A (1 + 2 s m) / (1 + 2 s mu) (Chandrasekhar's H-function
// in its first approximation, H(mu) ~ (1 + 2 mu) / (1 + 2 s mu)), mu the
// cosine inside the medium and m its mean. The diffuse of a slab with a mean
// free path is weighted by that ratio along the view and along the light,
// which keeps it reciprocal (substrate_eval_closure; the split sum takes the
// view's part):
//   (1 + 2 s m)(1 + 2 s m') / ((1 + 2 s mu_v')(1 + 2 s mu_l')).
// mu' = p + (1 - p) mu is the cosine inside for mu outside, on the line from
// the critical cosine p = sqrt(1 - 1/eta^2) (1 - SPREAD r) at grazing (a
// rough interface refracts a grazing view over a spread of directions, some
// of them grazing inside) to 1 head-on; m' = p + (1 - p) m is the light
// side's mean of mu', so the view's directional albedo is
// A (1 + 2 s m) / (1 + 2 s mu_v') whatever the light. s comes from the
// medium's albedo seen from inside, A' = A / (1 - R21 + R21 A): the
// interface's underside reflects R21 of what leaves back in (R21 = 1 - (1 -
// R12) / eta^2, R12 Schlick's hemispherical mean F0 + (1 - F0) / 21, eta
// from the closure's mean F0 against air, substrate_medium_f0), and a rational inverse of van de
// Hulst's albedo gives s. A closure without a medium (an opaque Lambertian:
// no mean free path) has s = 0, weight 1, as has A = 1 (the white furnace
// does not move). substrate_constants.h, SUBSTRATE_MEDIUM_*. Float; about thirty
// operations and two square roots, for materials with an SSS medium only.

// The F0 of the interface over the medium, against air: the mean of the
// closure's own F0, under layers too (not the F0 relative to them,
// substrate_closure_fresnel_ends): light reaches the medium refracted by every
// interface above it, as by one of the medium's own IOR.
float substrate_medium_f0(SubstrateClosure c) {
  return dot(saturate(c.f0), SUBSTRATE_SPLAT3(1.0 / 3.0));
}

// How much of the closure's diffuse is a medium's: 1 with a medium (sssType
// not none), else 0. A metalness mix's medium lies under its dielectric part
// with the base colour as its albedo, which the closure no longer holds (its
// diffuse is the base colour times 1 - metallic, far darker): the weight fades
// out by the mix's share, as substrate_closure_dielectric_part blends it in,
// and the mix keeps the Lambertian's response.
float substrate_medium_share(SubstrateClosure c) {
  float share = c.sssType != SUBSTRATE_SSS_NONE ? 1.0 : 0.0;
#if SUBSTRATE_USE_METALNESS_MIX
  share *= 1.0 - substrate_mix_share(substrate_max3(saturate(c.f0)));
#endif
  return share;
}

// (1 / eta^2, p) of the interface of F0 f0 (substrate_medium_f0).
float2 substrate_medium_interface(float f0, float roughness) {
  float sq = sqrt(f0);
  float ie = (1.0 - sq) / (1.0 + sq);
  float ie2 = ie * ie;
  return float2(ie2, sqrt(1.0 - ie2) * (1.0 - SUBSTRATE_MEDIUM_SPREAD * saturate(roughness)));
}

// 2 s per channel, times share (substrate_medium_share): s = (1 - A') / (1 + c A'),
// c = SUBSTRATE_MEDIUM_INVERSE, with A' = A / (t + (1 - t) A), t = 1 - R21:
// s = t (1 - A) / (t + (1 - t + c) A), one division. R12 is the hemispherical
// mean of a dielectric's Schlick curve to F90 = 1, F0 + (1 - F0) / 21, so
// t = (1 - F0) (20 / 21) / eta^2 (at least 1e-4). albedo in [0, 1].
float3 substrate_medium_slope2(float3 albedo, float share, float f0, float ie2) {
  float t = max((1.0 - f0) * (20.0 / 21.0) * ie2, 1e-4);
  float3 s2 = (2.0 * t * share) * (SUBSTRATE_SPLAT3(1.0) - albedo) /
              (SUBSTRATE_SPLAT3(t) + (1.0 + SUBSTRATE_MEDIUM_INVERSE - t) * albedo);
  return s2;
}

// What the weight needs of a closure: 2 s per channel (substrate_medium_slope2)
// and, in p, the cosine inside at grazing (substrate_medium_interface).
float3 substrate_closure_medium(SubstrateClosure c, float3 albedo, float roughness, out float p) {
  float f0 = substrate_medium_f0(c);
  float2 mi = substrate_medium_interface(f0, roughness);
  p = mi.y;
  return substrate_medium_slope2(albedo, substrate_medium_share(c), f0, mi.x);
}

// ---------------------------------------------------------------------------
// Fuzz: Charlie sheen (Estevez & Kulla 2017).

// D = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi), a = max(r^2, 1e-3).
float substrate_charlie_d(float a, float NoH) {
  float inv = 1.0 / a;
  float sin2 = max(1.0 - NoH * NoH, 0.0);
  return (2.0 + inv) * substrate_pow(sin2, 0.5 * inv) * (0.5 * SUBSTRATE_INV_PI);
}

// The fitted exponent L(x) of Estevez & Kulla's shadowing, parameters
// interpolated between a = 1 and a = 0 by (1 - a)^2.
float substrate_charlie_l(float x, float a) {
  float t = (1.0 - a) * (1.0 - a);
  float pa = lerp(21.5473, 25.3245, t);
  float pb = lerp(3.82987, 3.32435, t);
  float pc = lerp(0.19823, 0.16801, t);
  float pd = lerp(-1.97760, -1.27393, t);
  float pe = lerp(-4.32054, -4.85967, t);
  return pa / (1.0 + pb * substrate_pow(x, pc)) + pd * x + pe;
}

// Lambda(mu) = exp(L(mu)) for mu < 0.5, exp(2 L(0.5) - L(1 - mu)) otherwise.
float substrate_charlie_lambda(float mu, float a) {
  float m = saturate(mu);
  float l = m < 0.5 ? substrate_charlie_l(m, a) : 2.0 * substrate_charlie_l(0.5, a) - substrate_charlie_l(1.0 - m, a);
  return exp(min(l, 80.0));
}

// Charlie sheen f * NoL = D G / (4 NoV), G = 1 / (1 + Lambda(NoV) + Lambda(NoL)).
float substrate_charlie_sheen(float fuzzRoughness, float NoV, float NoL, float NoH) {
  float r = saturate(fuzzRoughness);
  float a = max(r * r, SUBSTRATE_FUZZ_MIN_ALPHA);
  float g = 1.0 / (1.0 + substrate_charlie_lambda(NoV, a) + substrate_charlie_lambda(NoL, a));
  return substrate_charlie_d(a, NoH) * g / (4.0 * max(NoV, SUBSTRATE_MIN_COS));
}

// ---------------------------------------------------------------------------
// Glints: a cheap stand-in for Chermain et al. 2021 ("Procedural Physically
// based BRDF for Real-Time Rendering of Glints"). The pixel footprint in uv
// (area A = |det(duv/dx, duv/dy)|) holds N = rho A microfacets
// (rho = 2^lerp(8, 40, glintValue) per uv unit^2); a fraction
// p = min(1, D(H) NoH Omega) of them (Omega = pi gamma^2, gamma the reflection
// cone) reflect toward H: an expected count lambda = N p. The lobe is
// multiplied by M, a random variable of mean 1 and variance ~1/lambda (the
// relative variance of a Poisson count), drawn from a hash of (the uv cell at
// the footprint's scale, H's slope bin at the cone's scale):
//   q = min(lambda, 1): the probability that the cell holds a reflecting facet;
//   M = (u < q) ? Y / q : 0, with Y log-normal of mean 1 and variance
//   v = q (1 + 1/lambda) - 1 (so Var M = 1/lambda): exp(sigma z - sigma^2/2),
//   sigma^2 = ln(1 + v), z a Gaussian (Box-Muller).
// Sparse (lambda << 1): dark cells with rare bright sparkles; dense: M -> 1,
// the smooth lobe. Two grid levels around the footprint size are blended (no
// popping). E[M] = 1 exactly (energy-neutral on average). glintValue >= 1:
// no glint.
float substrate_glint_level_sample(float2 uv, float level, int2 slopeBin, float expected) {
  float size = exp2(level);
  float2 cell = clamp(floor(uv / size), SUBSTRATE_SPLAT2(-8388608.0), SUBSTRATE_SPLAT2(8388607.0));
  uint3 key = uint3(uint(int(cell.x)), uint(int(cell.y)),
                    (uint(slopeBin.x) & 0xffffu) | (uint(slopeBin.y) << 16u));
  key.z ^= uint(int(level) + 128) * 0x9E3779B9u;
  uint3 h = substrate_pcg3d(key);
  float q = min(expected, 1.0);
  float v = q * (1.0 + 1.0 / expected) - 1.0;
  float sigma2 = log(1.0 + max(v, 0.0));
  float z = sqrt(-2.0 * log(substrate_hash_to_unit(h.x))) * cos(SUBSTRATE_TWO_PI * substrate_hash_to_unit(h.y));
  float y = exp(sqrt(sigma2) * z - 0.5 * sigma2);
  return substrate_hash_to_unit(h.z) <= q ? y / q : 0.0;
}

// The glint multiplier of the specular lobe. d = D(H) of the primary lobe;
// ToH, BoH, NoH: H in the closure's tangent frame.
float substrate_glint_factor(SubstrateClosure c, float d, float ToH, float BoH, float NoH) {
  float density = saturate(c.glintValue);
  if (density >= 1.0) {
    return 1.0;
  }
  float2 dx = c.glintUvDerivatives.xy;
  float2 dy = c.glintUvDerivatives.zw;
  // Footprint: area (anisotropy capped at 64:1), at least 1e-6 uv units wide.
  float lx = length(dx);
  float ly = length(dy);
  float wide = clamp(max(lx, ly), 1e-6, 1e6);
  float area = max(abs(dx.x * dy.y - dx.y * dy.x), wide * wide * (1.0 / 64.0));
  float rho = exp2(lerp(SUBSTRATE_GLINT_LOG2_DENSITY_MIN, SUBSTRATE_GLINT_LOG2_DENSITY_MAX, density));
  float gamma = SUBSTRATE_GLINT_CONE_ANGLE;
  float p = min(1.0, d * saturate(NoH) * (SUBSTRATE_PI * gamma * gamma));
  float expected = clamp(rho * area * p, 1e-4, 1e30);
  // H's slope, binned at the cone's scale (a new light direction meets new facets).
  float2 slope = float2(ToH, BoH) / max(NoH, 0.05);
  int2 bin = int2(floor(slope / (2.0 * gamma)));
  float level = clamp(0.5 * log2(area), -40.0, 20.0);
  float l0 = floor(level);
  float t = level - l0;
  float m0 = substrate_glint_level_sample(c.glintUv, l0, bin, expected);
  float m1 = substrate_glint_level_sample(c.glintUv, l0 + 1.0, bin, expected);
  return lerp(m0, m1, t);
}

// ---------------------------------------------------------------------------
// The closure.

// What a diffuse under a fuzz on top keeps of a light (issue 19, step 16):
// the light crosses the fuzz on the way in and on the way out, each crossing
// keeping 1 - q (q = amount min(E_fuzz, 1) at its cosine, what the fuzz
// catches), and what the fuzz catches of the base's light from below it sends
// back down in its colour, so the base's light bounces between the two:
//   (1 - q(NoV)) (1 - q(NoL)) / N,
//   N = (1 - amount (albedo colour mean E' - deviation sigma'(r_f))) (1 + amount margin(r)),
// E' = min(E_fuzz, 1), the base's share of what comes back up read as its
// diffuse albedo. Reciprocal. The larger of the two crossings, 1 - max(q(NoV),
// q(NoL)), lost for a white base the light arriving where the fuzz catches
// more than along the view (a white velvet, F0 0.04 of roughness 1 over a
// white Lambertian under a white fuzz of roughness 1, read 0.859 of a white
// furnace head-on, now 0.992), and for a dark one kept what the truth's fuzz sends back into it
// (FuzzParameterSweep's black base under a white fuzz, +8.8 ... +30.5 %).
// For a white base under a white fuzz, N bounds the mean over the light of the
// light crossing times the diffuse's light coupling, which both favour light
// near the normal: their means (substrate_fuzz_mean_albedo, a lower bound of
// E''s), the most their covariance can be (Cauchy-Schwarz: the product of
// their deviations, substrate_diffuse_light_coupling_deviation and
// substrate_fuzz_albedo_deviation; `deviation` is the coupling's, 0 for a lobe
// without one) and the diffuse model's own margin (substrate_fuzz_pair_margin).
// With the means alone a white Lambertian under a smooth interface and a fuzz
// of roughness 1 returned 1.009. At amount 0 it is exactly 1, as without a fuzz.
float3 substrate_fuzz_diffuse_pair(SubstrateClosure c, float amount, float eView, float eLight, float3 albedo,
                                   float deviation) {
  float crossings = (1.0 - amount * min(eView, 1.0)) * (1.0 - amount * min(eLight, 1.0));
  float3 bounce = albedo * saturate(c.fuzzColor) * substrate_fuzz_mean_albedo(c.fuzzRoughness);
  float covariance = deviation * substrate_fuzz_albedo_deviation(c.fuzzRoughness);
  return SUBSTRATE_SPLAT3(crossings) /
         ((SUBSTRATE_SPLAT3(1.0) - amount * (bounce - SUBSTRATE_SPLAT3(covariance))) *
          (1.0 + amount * substrate_fuzz_pair_margin(saturate(c.roughness))));
}

// The pair's mean over light from the whole hemisphere, as a share of the view's
// crossing (the split sum's diffuse under a fuzz, substrate_env_split_sum):
// (1 - amount mean E') / (1 - amount albedo colour mean E'). 1 for a white base
// under a white fuzz (the split sum's white furnace unchanged); lower as the
// base darkens, which absorbs what the fuzz sends back down.
float3 substrate_fuzz_diffuse_pair_mean(SubstrateClosure c, float amount, float3 albedo) {
  float caught = amount * substrate_fuzz_mean_albedo(c.fuzzRoughness);
  return SUBSTRATE_SPLAT3(1.0 - caught) / (SUBSTRATE_SPLAT3(1.0) - albedo * saturate(c.fuzzColor) * caught);
}

float3 substrate_eval_closure(SubstrateClosure c, float3 V, float3 L) {
#if SUBSTRATE_USE_HAIR
  if ((c.features & SUBSTRATE_FEATURE_HAIR) != 0u) {
    return substrate_hair_eval(c, V, L);  // a fibre: lit from every direction
  }
#endif
  float3 N = substrate_closure_normal(c);
  float NoVraw = dot(N, V);
  // Back-facing beyond the bias (or NaN): nothing. Otherwise NoV >= 1e-4.
  if (!(NoVraw > -SUBSTRATE_NOV_BIAS)) {
    return SUBSTRATE_SPLAT3(0.0);
  }
  float NoV = clamp(NoVraw, SUBSTRATE_MIN_COS, 1.0);
  float NoL = clamp(dot(N, L), -1.0, 1.0);

  bool isWrap = false;
  float3 wrap = SUBSTRATE_SPLAT3(0.0);
#if SUBSTRATE_USE_SSS
  if (c.sssType == SUBSTRATE_SSS_WRAP) {
    isWrap = true;
    wrap = substrate_sss_wrap_amount(c.sssMfp);
  }
#endif
  bool lightFacing = NoL > 0.0;
  // Wrap lighting reaches below the horizon, down to NoL = -w.
  if (!lightFacing && !(isWrap && NoL > -substrate_max3(wrap))) {
    return SUBSTRATE_SPLAT3(0.0);
  }
  float NoLc = max(NoL, 0.0);
  float3 H = substrate_safe_normalize(V + L, N);
  float NoH = saturate(dot(N, H));
  float VoH = saturate(dot(V, H));
  float VoL = clamp(dot(V, L), -1.0, 1.0);

  mfloat3 f0;
  mfloat3 f90;
  SubstrateFresnelCurve curve;
  substrate_closure_fresnel_ends(c, f0, f90, curve);
  float roughness = saturate(c.roughness);

  float anisotropy = 0.0;
#if SUBSTRATE_USE_ANISOTROPY
  if ((c.features & SUBSTRATE_FEATURE_ANISOTROPY) != 0u) {
    anisotropy = clamp(c.anisotropy, -1.0, 1.0);
  }
#endif

  // Specular: energy terms (needed by the diffuse even when NoL <= 0).
  float2 fd = substrate_closure_dielectric_part(c, f0, f90);
  mfloat3 f0w = substrate_closure_compensated_f0(c, f0, fd);
  float msRate = substrate_closure_dielectric_ms(c);
  mfloat3 specAlbedo;
  float dielectric;
  mfloat3 w1 =
      substrate_specular_energy_aniso(f0, f90, curve, fd, f0w, msRate, NoV, roughness, anisotropy, specAlbedo,
                                      dielectric);
  float hazeWeight = 0.0;
  float hazeRoughness = roughness;
#if SUBSTRATE_USE_HAZE
  if ((c.features & SUBSTRATE_FEATURE_HAZE) != 0u) {
    hazeWeight = saturate(c.secondRoughnessWeight);
    hazeRoughness = saturate(c.secondRoughness);
  }
#endif
  mfloat3 w2 = w1;
  if (hazeWeight > 0.0) {
    mfloat3 specAlbedo2;
    float dielectric2;
    w2 = substrate_specular_energy_aniso(f0, f90, curve, fd, f0w, msRate, NoV, hazeRoughness, anisotropy, specAlbedo2,
                                         dielectric2);
    specAlbedo = mlerp(specAlbedo, specAlbedo2, SUBSTRATE_M(hazeWeight));
    dielectric = lerp(dielectric, dielectric2, hazeWeight);
  }

  float3 spec = SUBSTRATE_SPLAT3(0.0);
  if (lightFacing) {
    bool needFrame = anisotropy != 0.0;
#if SUBSTRATE_USE_GLINT
    needFrame = needFrame || ((c.features & SUBSTRATE_FEATURE_GLINT) != 0u && c.glintValue < 1.0);
#endif
    float ToV = 0.0;
    float BoV = 0.0;
    float ToL = 0.0;
    float BoL = 0.0;
    float ToH = 0.0;
    float BoH = 0.0;
    if (needFrame) {
      float3 T;
      float3 B;
      substrate_closure_frame(c, N, T, B);
      ToV = dot(T, V);
      BoV = dot(B, V);
      ToL = dot(T, L);
      BoL = dot(B, L);
      ToH = dot(T, H);
      BoH = dot(B, H);
    }
    float2 alpha1 = substrate_ggx_alpha(roughness, anisotropy);
    float d1;
    float vis1;
    substrate_ggx_d_vis(alpha1, anisotropy != 0.0, ToH, BoH, NoH, ToV, BoV, NoV, ToL, BoL, NoLc, d1, vis1);
    // The lobe in float: D reaches 1 / (pi 1e-6) = 3.2e5 at the smallest alpha.
    float3 lobe = SUBSTRATE_F3(w1) * (d1 * vis1 * NoLc);
    if (hazeWeight > 0.0) {
      float2 alpha2 = substrate_ggx_alpha(hazeRoughness, anisotropy);
      float d2;
      float vis2;
      substrate_ggx_d_vis(alpha2, anisotropy != 0.0, ToH, BoH, NoH, ToV, BoV, NoV, ToL, BoL, NoLc, d2, vis2);
      lobe = lerp(lobe, SUBSTRATE_F3(w2) * (d2 * vis2 * NoLc), hazeWeight);
    }
    // Under layers: what their top sends back down instead of out.
    spec = SUBSTRATE_F3(substrate_fresnel(f0, f90, curve, VoH)) * lobe *
           substrate_closure_coat_specular(c, f0, f90, fd, curve.share, NoV, NoLc,
                                           lerp(roughness, hazeRoughness, hazeWeight));
#if SUBSTRATE_USE_GLINT
    if ((c.features & SUBSTRATE_FEATURE_GLINT) != 0u) {
      spec *= substrate_glint_factor(c, d1, ToH, BoH, NoH);
    }
#endif
#if SUBSTRATE_USE_SPECULAR_PROFILE
    if ((c.features & SUBSTRATE_FEATURE_SPECULAR_PROFILE) != 0u && c.specularProfile > 0u) {
      spec *= SUBSTRATE_SPECULAR_PROFILE_SAMPLE(c.specularProfile - 1u, float2(NoV, NoLc));
    }
#endif
  }
  // A wrap lobe's light crosses the layers above at its own cosine
  // (substrate_wrap_light_cosine); the lobes on its interface at NoL.
  float3 lightRatio = substrate_wrap_light_ratio(c, isWrap, NoLc, NoL, L);
  spec *= lightRatio;

  // Diffuse, below the specular interface: what the interface lets in along
  // the view, 1 - E_spec(NoV) (substrate_diffuse_transmission: the dielectric
  // part's of a metalness mix), and along the light, the coupling, of the
  // dielectric part too (F0 at most fd; not for the wrap lobe, which reaches
  // below the horizon: it keeps the view's term).
  mfloat3 albedo = SUBSTRATE_M3(saturate(c.diffuseAlbedo));
  float2 ends = substrate_diffuse_interface(f0, f90, fd);
  mfloat3 diffuse;
  if (isWrap) {
    diffuse = substrate_diffuse_wrap(albedo, wrap, NoL);
  } else {
#if SUBSTRATE_USE_EYE
    // An eye's iris where its mask is: its own cosine (substrate_eye.h).
    diffuse = substrate_eye_diffuse(c, substrate_diffuse(albedo, roughness, NoV, NoLc, NoH, VoH, VoL), albedo, N, L) *
              substrate_diffuse_light_coupling(ends, NoLc, roughness, hazeRoughness, hazeWeight);
#else
    diffuse = substrate_diffuse(albedo, roughness, NoV, NoLc, NoH, VoH, VoL) *
              substrate_diffuse_light_coupling(ends, NoLc, roughness, hazeRoughness, hazeWeight);
#endif
  }
#if SUBSTRATE_USE_SSS
  // A slab's medium: its view and light dependence ("A slab's medium", above;
  // no branch: a closure without a mean free path has slope 0, weight 1).
  {
    float p;
    float3 s2 = substrate_closure_medium(c, SUBSTRATE_F3(albedo), roughness, p);
    float3 u = SUBSTRATE_SPLAT3(1.0) + s2 * p;  // 1 + 2 s mu' = u + w mu
    float3 w = s2 * (1.0 - p);
    diffuse *= SUBSTRATE_M3((SUBSTRATE_SPLAT3(1.0) + s2 * SUBSTRATE_MEDIUM_MEAN_COS) * (u + w * SUBSTRATE_MEDIUM_MEAN_COS) /
                            ((u + w * NoV) * (u + w * NoLc)));
  }
#endif
  // Under layers: what their underside sends back down (float: a factor up to 1.1).
  float3 under = SUBSTRATE_F3(diffuse * substrate_diffuse_transmission(albedo, specAlbedo, dielectric)) *
                 substrate_closure_coat_diffuse(c, ends);
  float3 result = spec + under;

#if SUBSTRATE_USE_FUZZ
  if ((c.features & SUBSTRATE_FEATURE_FUZZ) != 0u) {
    float amount = saturate(c.fuzzAmount);
    // Under layers the fuzz sees the view and the light refracted into them.
    float fv = NoV;
    float fl = NoLc;
    float fh = NoH;
    float spread = 1.0;
    substrate_fuzz_under_layers(c, NoV, NoL, VoL, fv, fl, fh, spread);
    float eFuzz = substrate_fuzz_albedo(fv, c.fuzzRoughness);
    // The lobe is normalized where the model's albedo exceeds 1 (grazing,
    // smooth fuzz); what it reflects no longer reaches the layers below, along
    // the view and along the light alike: the layers below are scaled by
    // 1 - amount min(max(E_fuzz(NoV), E_fuzz(NoL)), 1) (KHR_materials_sheen's
    // min of the two albedo scalings). With the view's alone, light arriving at
    // grazing was reflected by the fuzz and still fed the base whole: a white
    // diffuse under fuzz returned up to 1.48 of a light at NoL 0.1. The
    // specular keeps that; the diffuse takes the pair of crossings instead
    // (substrate_fuzz_diffuse_pair; issue 19, step 16), on top only: under
    // layers the light meets the fuzz within their refraction cone, where the
    // pair's hemispherical means do not hold (lerped by coverageAbove toward
    // the larger of the two). Not for the wrap lobe either, whose light
    // reaches below the horizon and weighs grazing light more than the cosine
    // the means assume (it keeps the larger of the two, as it keeps no light
    // coupling: the pair lost 2 points of row28_anisotropy's furnace).
    float3 fuzz = SUBSTRATE_SPLAT3(0.0);
    float eCaught = eFuzz;
    float3 diffuseKept = SUBSTRATE_SPLAT3(1.0 - amount * min(eFuzz, 1.0));
    if (lightFacing) {
      fuzz = saturate(c.fuzzColor) *
             (amount * spread * substrate_charlie_sheen(c.fuzzRoughness, fv, fl, fh) / max(1.0, eFuzz)) * lightRatio;
      float eLight = substrate_fuzz_albedo(fl, c.fuzzRoughness);
      eCaught = max(eFuzz, eLight);
      float deviation =
          isWrap ? 0.0 : substrate_diffuse_light_coupling_deviation(ends, roughness, hazeRoughness, hazeWeight);
      float cover = isWrap ? 1.0 : 0.0;
#if SUBSTRATE_USE_LAYERS
      cover = max(cover, saturate(c.coverageAbove));
#endif
      diffuseKept = lerp(substrate_fuzz_diffuse_pair(c, amount, eFuzz, eLight, SUBSTRATE_F3(albedo), deviation),
                         SUBSTRATE_SPLAT3(1.0 - amount * min(eCaught, 1.0)), cover);
    }
    result = spec * (1.0 - amount * min(eCaught, 1.0)) + under * diffuseKept + fuzz;
  }
#endif
  return result;
}

#endif
