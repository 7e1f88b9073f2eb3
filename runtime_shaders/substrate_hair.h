// substratec runtime shaders: the hair BSDF — a fibre's far-field scattering,
// lit per light (substrate_hair_eval) and by an environment
// (substrate_hair_env). Common dialect; substrate_bsdf.h includes it (include
// order: prelude -> substrate_closure.h -> substrate_common.h -> this).
//
// The model (docs/format.md, "The hair BSDF"; README.md, "Hair"): the lobes R
// (reflection), TT (transmission) and TRT (one internal reflection) of
// Marschner et al. 2003, with
//  - Chiang et al. 2016's parameters and longitudinal lobes: variance
//    v = (0.726 bm + 0.812 bm^2 + 3.7 bm^20)^2 from the roughness bm (TT v/4,
//    TRT 4 v), d'Eon et al. 2011's Bessel lobe M_p, each lobe's outgoing angle
//    tilted by the cuticle (R by -2a, TT by +a, TRT by +4a), the absorption
//    sigma_a = (ln c / P(bn))^2 from the base colour c (Chiang's eq. 9), exact
//    dielectric Fresnel, and the rest of the paths (p >= 3) as pbrt-v4's
//    isotropic remainder;
//  - closed-form azimuthal lobes in place of the integral over the fibre's
//    width (after Karis 2016, "Physically Based Hair Shading in Unreal"): R is
//    Marschner's far field, cos(phi/2) / 4 times the Fresnel at the offset
//    that reflects toward phi; TT, TRT and the rest take their attenuations
//    averaged over the width (a 4-point rule), and TT and TRT Karis's von
//    Mises shapes (kappa 3.65 around phi = pi, 17 around 0) widened by the
//    variance of Chiang's logistic of scale s(bn) and normalized to integrate
//    to 1 (Karis's integrate to 0.94 and 0.76), so a white fibre keeps its
//    energy (its albedo is 1 to the rule's error);
//  - dense hair (UE's Scatter pin): a single fibre is bright (its absorption
//    is small: Chiang's c is the colour of DENSE hair, which multiple
//    scattering between fibres makes), so the scatter blends the fibre's
//    lobes toward c times Karis 2016's Kajiya-Kay-like lobe
//    lerp((N'.L + 1) / 4, 1 - |T.L|, 0.33) / (1.33 pi) (that lobe normalized;
//    N' the view projected across the fibre). UE adds that lobe with sqrt(c);
//    a blend toward c keeps the energy and the colour the artist named.
//    Not a single fibre's: 0 by default.
// The value returned is what multiplies a light's radiance (the BSDF times the
// cosine, as substrate_eval_closure returns): S(V, L) with the integral over
// the sphere of S equal to the fibre's albedo. The closure's fields: base colour
// in diffuseAlbedo, longitudinal roughness in roughness, the fibre in T, and
// hair = (azimuthal roughness, ior, cuticle angle in degrees, scatter).
// Truth: pbrt-v4's HairBxDF integrated over the fibre's width, in double
// (compiler/tools/reference/hair_truth.h); the CPU mirror is
// compiler/tools/reference/hair.cc.
#ifndef SUBSTRATE_HAIR_H
#define SUBSTRATE_HAIR_H 1

// SUBSTRATE_USE_HAIR (substrate_closure.h): 0 compiles this file out, with
// the closure's hair field and the branches to it.
#if SUBSTRATE_USE_HAIR

// The smallest longitudinal variance (a lobe about 0.9 degrees wide): a
// roughness of 0 stays finite.
SUBSTRATE_CONST float SUBSTRATE_HAIR_MIN_VARIANCE = 2.5e-4;
// The darkest base colour the absorption is taken from (c = 0 would be an
// infinite sigma_a): sigma_a <= 5.4 per unit radius.
SUBSTRATE_CONST float SUBSTRATE_HAIR_MIN_COLOR = 1e-6;
// Karis 2016's azimuthal concentrations (TT around phi = pi, TRT around 0).
SUBSTRATE_CONST float SUBSTRATE_HAIR_KAPPA_TT = 3.65;
SUBSTRATE_CONST float SUBSTRATE_HAIR_KAPPA_TRT = 17.0;

// Chiang 2016's longitudinal variance of the R lobe from the roughness bm.
float substrate_hair_variance(float bm) {
  float b = saturate(bm);
  float b2 = b * b;
  float b4 = b2 * b2;
  float b20 = b4 * b4 * b4 * b4 * b4;
  float x = 0.726 * b + 0.812 * b2 + 3.7 * b20;
  return max(x * x, SUBSTRATE_HAIR_MIN_VARIANCE);
}

// Chiang 2016's logistic scale from the azimuthal roughness bn.
float substrate_hair_logistic_scale(float bn) {
  float b = saturate(bn);
  float b2 = b * b;
  float b11 = b2 * b2 * b2 * b2 * b2 * b;
  return 0.626657 * (0.265 * b + 1.194 * b2 + 5.372 * b11 * b11);  // sqrt(pi / 8)
}

// Chiang 2016's absorption per unit radius from the colour of dense hair
// (eq. 9), per channel.
float3 substrate_hair_sigma_a(float3 color, float bn) {
  float b = saturate(bn);
  float p = 5.969 - 0.215 * b + 2.532 * b * b - 10.73 * b * b * b + 5.574 * b * b * b * b + 0.245 * b * b * b * b * b;
  float3 l = log(clamp(color, SUBSTRATE_SPLAT3(SUBSTRATE_HAIR_MIN_COLOR), SUBSTRATE_SPLAT3(1.0))) / p;
  return l * l;
}

// log(I0(x)) - x for x >= 0 (Abramowitz & Stegun 9.8.1, 9.8.2: relative error
// of I0 below 2e-7), without overflow for any x.
float substrate_hair_log_i0_scaled(float x) {
  if (x <= 3.75) {
    float t = x / 3.75;
    float t2 = t * t;
    float i0 = 1.0 + t2 * (3.5156229 + t2 * (3.0899424 + t2 * (1.2067492 + t2 * (0.2659732 + t2 * (0.0360768 + t2 * 0.0045813)))));
    return log(i0) - x;
  }
  float u = 3.75 / x;
  float p = 0.39894228 + u * (0.01328592 + u * (0.00225319 + u * (-0.00157565 + u * (0.00916281 +
            u * (-0.02057706 + u * (0.02635537 + u * (-0.01647633 + u * 0.00392377)))))));
  return log(p) - 0.5 * log(x);
}

// d'Eon 2011's longitudinal lobe of variance v: exp(-b) I0(a) / (2 v sinh(1/v)),
// a = cos_i cos_o / v, b = sin_i sin_o / v, in the log domain (cos(theta_i +
// theta_o) - 1 over v, then log I0(a) - a, then 2 v sinh(1/v) = v e^(1/v) (1 - e^(-2/v))).
float substrate_hair_mp(float cosI, float cosO, float sinI, float sinO, float v) {
  float a = cosI * cosO / v;
  float e = (cosI * cosO - sinI * sinO - 1.0) / v + substrate_hair_log_i0_scaled(a) - log(v * (1.0 - exp(-2.0 / v)));
  return exp(min(e, 80.0));
}

// Exact unpolarized Fresnel reflectance of a dielectric of index eta >= 1 at
// cosine c, from outside.
float substrate_hair_fresnel(float c, float eta) {
  float ci = saturate(c);
  if (!(ci > 1e-7)) {
    return 1.0;
  }
  float ct = sqrt(max(1.0 - (1.0 - ci * ci) / (eta * eta), 0.0));
  float rs = (ci - eta * ct) / (ci + eta * ct);
  float rp = (eta * ci - ct) / (eta * ci + ct);
  return saturate(0.5 * (rs * rs + rp * rp));
}

// A von Mises lobe of concentration kappa around 0 at cos(x), normalized over
// the circle: exp(kappa (cos x - 1)) / (2 pi e^-kappa I0(kappa)).
float substrate_hair_von_mises(float cosX, float kappa) {
  return exp(kappa * (cosX - 1.0) - substrate_hair_log_i0_scaled(kappa)) / SUBSTRATE_TWO_PI;
}

// Karis's concentration kappa0 widened by the variance pi^2 s^2 / 3 of
// Chiang's logistic of scale s.
float substrate_hair_kappa(float kappa0, float s) {
  return 1.0 / (1.0 / kappa0 + 3.28986813 * s * s);  // pi^2 / 3
}

// What one pass through the fibre at offset h lets through, per channel:
// exp(-sigma_a 2 cos(gamma_t) / cos(theta_t)), and the Fresnel reflectance at
// the entry point (cos theta_o cos gamma_o). etap: Bravais's eta' of the view.
float3 substrate_hair_pass(float h, float cosO, float etap, float cosT, float eta, float3 sigmaA, out float f) {
  float hh = clamp(h, -1.0, 1.0);
  f = substrate_hair_fresnel(cosO * sqrt(max(1.0 - hh * hh, 0.0)), eta);
  float sinGt = hh / etap;
  float cosGt = sqrt(max(1.0 - sinGt * sinGt, 0.0));
  return exp(-sigmaA * (2.0 * cosGt / max(cosT, 1e-4)));
}

// The fibre's attenuations of TT, TRT and the rest (A_1 = (1 - f)^2 T,
// A_2 = A_1 f T, A_3 = A_2 f T / (1 - f T)), each averaged over the fibre's
// width: the 4-point Gauss-Legendre rule in gamma = asin(h) over [0, pi/2]
// (offsets h_k, weights cos(gamma_k) w_k pi / 4, which sum to 1 - 2e-8). Also
// that mean of the R attenuation f (the environment's). At every offset the
// four sum to 1 without absorption, so the means do too, to the rule's 1e-5:
// a white fibre keeps its energy whatever the view (the R lobe's own integral
// over phi is exact: substrate_hair_eval).
void substrate_hair_attenuations(SubstrateClosure c, float sinO, float cosO, out float aR, out float3 aTT,
                                 out float3 aTRT, out float3 a3) {
  float eta = max(c.hair.y, 1.0);
  float3 sigmaA = substrate_hair_sigma_a(c.diffuseAlbedo, c.hair.x);
  float sinT = sinO / eta;
  float cosT = sqrt(max(1.0 - sinT * sinT, 0.0));
  float etap = sqrt(max(eta * eta - sinO * sinO, 0.0)) / max(cosO, 1e-4);
  aR = 0.0;
  aTT = SUBSTRATE_SPLAT3(0.0);
  aTRT = SUBSTRATE_SPLAT3(0.0);
  a3 = SUBSTRATE_SPLAT3(0.0);
  for (int k = 0; k < 4; ++k) {
    float h = k == 0 ? 0.108847200 : (k == 1 ? 0.495471601 : (k == 2 ? 0.868624138 : 0.994058493));
    float w = k == 0 ? 0.271581310 : (k == 1 ? 0.444903730 : (k == 2 ? 0.253777386 : 0.029737551));
    float f;
    float3 t = substrate_hair_pass(h, cosO, etap, cosT, eta, sigmaA, f);
    float3 tt = (1.0 - f) * (1.0 - f) * t;
    float3 trt = tt * f * t;
    aR += w * f;
    aTT += w * tt;
    aTRT += w * trt;
    a3 += w * trt * f * t / max(SUBSTRATE_SPLAT3(1.0) - f * t, SUBSTRATE_SPLAT3(1e-4));
  }
}

// The longitudinal lobes of R, TT, TRT (x, y, z) and the remainder (w) at the
// light's sin/cos and the view's, each view angle tilted by the cuticle.
float4 substrate_hair_longitudinal(SubstrateClosure c, float sinI, float cosI, float sinO, float cosO) {
  float v = substrate_hair_variance(c.roughness);
  float alpha = clamp(c.hair.z, -20.0, 20.0) * (SUBSTRATE_PI / 180.0);
  float s1 = sin(alpha);
  float c1 = cos(alpha);
  float s2 = 2.0 * c1 * s1;
  float c2 = c1 * c1 - s1 * s1;
  float s4 = 2.0 * c2 * s2;
  float c4 = c2 * c2 - s2 * s2;
  float mR = substrate_hair_mp(cosI, abs(cosO * c2 + sinO * s2), sinI, sinO * c2 - cosO * s2, v);
  float mTT = substrate_hair_mp(cosI, abs(cosO * c1 - sinO * s1), sinI, sinO * c1 + cosO * s1, 0.25 * v);
  float mTRT = substrate_hair_mp(cosI, abs(cosO * c4 - sinO * s4), sinI, sinO * c4 + cosO * s4, 4.0 * v);
  float m3 = substrate_hair_mp(cosI, cosO, sinI, sinO, 4.0 * v);
  return float4(mR, mTT, mTRT, m3);
}

// UE's dense-hair scattering (see the header), normalized to integrate to 1
// over the sphere: lerp((N'.L + 1) / 4, 1 - |T.L|, 0.33) integrates to
// pi 0.67 + 2 pi 0.33 = 1.33 pi.
float substrate_hair_dense(float3 V, float3 L, float3 T, float sinI) {
  float3 n = substrate_safe_normalize(V - dot(V, T) * T, V);
  float wrapped = saturate((dot(n, L) + 1.0) * 0.25);
  return lerp(wrapped, 1.0 - abs(sinI), 0.33) / (1.33 * SUBSTRATE_PI);
}

// S(V, L) of a hair closure: what multiplies the radiance of a light from L
// (unit), seen from V (unit). Every direction is valid: the fibre scatters
// all around (no hemisphere).
float3 substrate_hair_eval(SubstrateClosure c, float3 V, float3 L) {
  float3 T = substrate_safe_normalize(c.T, float3(1.0, 0.0, 0.0));
  float sinO = clamp(dot(V, T), -1.0, 1.0);
  float sinI = clamp(dot(L, T), -1.0, 1.0);
  float cosO = sqrt(max(1.0 - sinO * sinO, 0.0));
  float cosI = sqrt(max(1.0 - sinI * sinI, 0.0));
  // The azimuth between the light and the view around the fibre.
  float3 lp = L - sinI * T;
  float3 vp = V - sinO * T;
  float cosPhi = clamp(dot(lp, vp) * rsqrt(max(dot(lp, lp) * dot(vp, vp), 1e-12)), -1.0, 1.0);
  float cosHalfPhi = sqrt(saturate(0.5 + 0.5 * cosPhi));
  float eta = max(c.hair.y, 1.0);
  // R: the offset that reflects toward phi is h = sin(phi / 2) (gamma_o = -phi / 2),
  // so A_R = F(cos theta_o cos(phi / 2)), N_R = cos(phi / 2) / 4 (Marschner's far field).
  float aR = substrate_hair_fresnel(cosO * cosHalfPhi, eta);
  float aMeanR;
  float3 aTT;
  float3 aTRT;
  float3 a3;
  substrate_hair_attenuations(c, sinO, cosO, aMeanR, aTT, aTRT, a3);
  float4 m = substrate_hair_longitudinal(c, sinI, cosI, sinO, cosO);
  float s = substrate_hair_logistic_scale(c.hair.x);
  float nTT = substrate_hair_von_mises(-cosPhi, substrate_hair_kappa(SUBSTRATE_HAIR_KAPPA_TT, s));
  float nTRT = substrate_hair_von_mises(cosPhi, substrate_hair_kappa(SUBSTRATE_HAIR_KAPPA_TRT, s));
  float3 lobes = SUBSTRATE_SPLAT3(m.x * aR * 0.25 * cosHalfPhi) + m.y * nTT * aTT + m.z * nTRT * aTRT +
                 (m.w / SUBSTRATE_TWO_PI) * a3;
  // Dense hair: the fibre's lobes blended toward the dense lobe of albedo c by the scatter.
  float w = saturate(c.hair.w);
  float3 dense = saturate(c.diffuseAlbedo) * substrate_hair_dense(V, L, T, sinI);
  return max(lerp(lobes, dense, w), SUBSTRATE_SPLAT3(0.0));
}

// Environment lighting of a hair closure from the irradiance E (the
// hemisphere's, as for slabs): under a uniform environment of radiance E / pi
// a fibre returns its albedo, the sum of its attenuations averaged over its
// width (substrate_hair_attenuations; each lobe's M_p N_p integrates to 1
// over the sphere), blended toward the dense lobe's c by the scatter.
// The caller multiplies by the view throughput (the weight), as for slabs.
float3 substrate_hair_env(SubstrateClosure c, float3 V, float3 irradiance) {
  float3 T = substrate_safe_normalize(c.T, float3(1.0, 0.0, 0.0));
  float sinO = clamp(dot(V, T), -1.0, 1.0);
  float cosO = sqrt(max(1.0 - sinO * sinO, 0.0));
  float aR;
  float3 aTT;
  float3 aTRT;
  float3 a3;
  substrate_hair_attenuations(c, sinO, cosO, aR, aTT, aTRT, a3);
  float3 albedo = lerp(SUBSTRATE_SPLAT3(aR) + aTT + aTRT + a3, saturate(c.diffuseAlbedo), saturate(c.hair.w));
  return albedo * max(irradiance, SUBSTRATE_SPLAT3(0.0)) * SUBSTRATE_INV_PI;
}

#endif  // SUBSTRATE_USE_HAIR

#endif
