// Mirrors runtime_shaders/substrate_bsdf.h: substrate_eval_closure (BSDF * NoL)
// and its lobes — GGX (anisotropic, height-correlated Smith), Schlick/F90
// Fresnel, Turquin 2019 energy compensation from the tables, the four diffuse
// models, SSS wrap, haze, Charlie fuzz, glints — with the shader's guards
// (clamps, epsilons, fallbacks) cited function by function. The runtime's
// SUBSTRATE_USE_* switches are all on here: the generated code turns a feature
// off only when no closure has its bit, and every optional lobe is gated by the
// closure's bits (or, for SSS wrap, by sssType, which the emitter sets only for
// slabs with the SSS feature), so the result is the same.
#include "reference/bsdf.h"

#include <cmath>
#include <cstdint>

#include "reference/common.h"
#include "reference/hair.h"
#include "reference/energy_lut.h"
#include "substrate_constants.h"  // runtime_shaders/

namespace substratec::reference {
using namespace detail;

namespace {
// substrate_bsdf.h constants and default macros (the macros: runtime_shaders/substrate_constants.h).
template <class T> constexpr T kNoVBias = T(SUBSTRATE_NOV_BIAS);
template <class T> constexpr T kWrapMfpScale = T(SUBSTRATE_SSS_WRAP_MFP_SCALE);
template <class T> constexpr T kGlintLog2Min = T(SUBSTRATE_GLINT_LOG2_DENSITY_MIN);
template <class T> constexpr T kGlintLog2Max = T(SUBSTRATE_GLINT_LOG2_DENSITY_MAX);
template <class T> constexpr T kGlintCone = T(SUBSTRATE_GLINT_CONE_ANGLE);
template <class T> constexpr T kMinAlpha = T(1e-3);        // SUBSTRATE_MIN_ALPHA
template <class T> constexpr T kFuzzMinAlpha = T(1e-3);    // SUBSTRATE_FUZZ_MIN_ALPHA
}  // namespace

// ---------------------------------------------------------------------------
// Frames.

// substrate_closure_normal: safe_normalize(c.N, +Z).
template <class T>
V3<T> closureNormal(const Closure<T>& c) {
  return safeNormalize(c.N, V3<T>{T(0), T(0), T(1)});
}

// substrate_closure_frame: c.T made orthogonal to N by one Gram-Schmidt step,
// the Duff basis's tangent when that fails; B = N x T.
template <class T>
void closureFrame(const Closure<T>& c, const V3<T>& N, V3<T>& Tn, V3<T>& Bn) {
  V3<T> t0, b0;
  orthonormalBasis(N, t0, b0);
  Tn = safeNormalize(c.T_ - N * dot(N, c.T_), t0);
  Bn = cross(N, Tn);
}

// ---------------------------------------------------------------------------
// GGX.

// substrate_ggx_alpha: a = sat(r)^2, (a (1 + A), a (1 - A)) clamped to [1e-3, 1].
template <class T>
V2<T> ggxAlpha(T roughness, T anisotropy) {
  T r = saturate(roughness);
  T a = r * r;
  T A = clampT(anisotropy, T(-1), T(1));
  return {clampT(a * (T(1) + A), kMinAlpha<T>, T(1)), clampT(a * (T(1) - A), kMinAlpha<T>, T(1))};
}

// substrate_ggx_d: a2 / (pi max(d^2, 1e-30)), d = (n a2 - n) n + 1, n = sat(NoH).
template <class T>
T ggxD(T a, T NoH) {
  T a2 = a * a;
  T n = saturate(NoH);
  T d = (n * a2 - n) * n + T(1);
  return a2 / (K<T>::pi * std::max(d * d, T(1e-30)));
}

// substrate_ggx_d_aniso: a2 w^2 / pi, w = a2 / max(|(ay ToH, ax BoH, a2 NoH)|^2, 1e-30).
template <class T>
T ggxDAniso(const V2<T>& alpha, T ToH, T BoH, T NoH) {
  T a2 = alpha[0] * alpha[1];
  V3<T> v{alpha[1] * ToH, alpha[0] * BoH, a2 * NoH};
  T w = a2 / std::max(dot(v, v), T(1e-30));
  return a2 * w * w * K<T>::invPi;
}

// substrate_ggx_vis: 0.5 / max(gv + gl, 1e-30).
template <class T>
T ggxVis(T a, T NoV, T NoL) {
  T a2 = a * a;
  T gv = NoL * std::sqrt(NoV * NoV * (T(1) - a2) + a2);
  T gl = NoV * std::sqrt(NoL * NoL * (T(1) - a2) + a2);
  return T(0.5) / std::max(gv + gl, T(1e-30));
}

// substrate_ggx_vis_aniso.
template <class T>
T ggxVisAniso(const V2<T>& alpha, T ToV, T BoV, T NoV, T ToL, T BoL, T NoL) {
  T gv = NoL * length(V3<T>{alpha[0] * ToV, alpha[1] * BoV, NoV});
  T gl = NoV * length(V3<T>{alpha[0] * ToL, alpha[1] * BoL, NoL});
  return T(0.5) / std::max(gv + gl, T(1e-30));
}

// substrate_fresnel_delta: D(t) = (1 - t) s (A + B s), s = sqrt(t).
template <class T>
T fresnelDelta(T t) {
  const T s = std::sqrt(t);
  return (T(1) - t) * s * (T(SUBSTRATE_FRESNEL_CURVE_A) + T(SUBSTRATE_FRESNEL_CURVE_B) * s);
}

// substrate_fresnel_weight: chi(c) = t + D(t), t = pow5(1 - c) (c clamped).
template <class T>
T fresnelWeight(T c) {
  const T t = pow5(T(1) - c);
  return t + fresnelDelta(t);
}

// substrate_fresnel_share: 1 - sat((f0max - 0.1) 10).
template <class T>
T fresnelShare(T f0max) {
  return T(1) - saturate((f0max - T(SUBSTRATE_COAT_DIELECTRIC_F0)) * T(SUBSTRATE_COAT_CONDUCTOR_BLEND));
}

// substrate_fresnel_curve: the dielectric curve's (a, b): chi's (A, B) plus (y - 0.2) lowIor times
// the quadratics in y = min(sqrt(max(max3 F0, DIELECTRIC_CURVE_MIN_F0)), 0.2)
// (SUBSTRATE_DIELECTRIC_CURVE_*), its pull min(PULL_MAX, PULL_SLOPE (0.2 - y) lowIor); per
// channel, the conductor's cubics max(a(x), 0), b(x) at x = sqrt(max(F0, CONDUCTOR_CURVE_MIN_F0))
// (SUBSTRATE_CONDUCTOR_CURVE_*) times `conductor` (toward Schlick's (0, 0)), lerped toward the
// dielectric's by the share.
template <class T>
FresnelCurve<T> fresnelCurve(const V3<T>& f0, T share, T conductor, T lowIor) {
  FresnelCurve<T> k{share, {}, {}, T(0)};
  const T y = std::min(std::sqrt(std::max(max3(f0), T(SUBSTRATE_DIELECTRIC_CURVE_MIN_F0))),
                       T(SUBSTRATE_DIELECTRIC_CURVE_X));
  const T below = (y - T(SUBSTRATE_DIELECTRIC_CURVE_X)) * lowIor;  // <= 0
  const T da = T(SUBSTRATE_FRESNEL_CURVE_A) +
               below * (T(SUBSTRATE_DIELECTRIC_CURVE_P0) +
                        y * (T(SUBSTRATE_DIELECTRIC_CURVE_P1) + y * T(SUBSTRATE_DIELECTRIC_CURVE_P2)));
  const T db = T(SUBSTRATE_FRESNEL_CURVE_B) +
               below * (T(SUBSTRATE_DIELECTRIC_CURVE_Q0) +
                        y * (T(SUBSTRATE_DIELECTRIC_CURVE_Q1) + y * T(SUBSTRATE_DIELECTRIC_CURVE_Q2)));
  k.pull = std::min(T(SUBSTRATE_DIELECTRIC_CURVE_PULL_MAX), below * -T(SUBSTRATE_DIELECTRIC_CURVE_PULL_SLOPE));
  for (int i = 0; i < 3; ++i) {
    const T x = std::sqrt(std::max(f0[i], T(SUBSTRATE_CONDUCTOR_CURVE_MIN_F0)));
    const T a2 = T(SUBSTRATE_CONDUCTOR_CURVE_A2) + x * T(SUBSTRATE_CONDUCTOR_CURVE_A3);
    const T b2 = T(SUBSTRATE_CONDUCTOR_CURVE_B2) + x * T(SUBSTRATE_CONDUCTOR_CURVE_B3);
    const T a = std::max(T(SUBSTRATE_CONDUCTOR_CURVE_A0) + x * (T(SUBSTRATE_CONDUCTOR_CURVE_A1) + x * a2), T(0));
    const T b = T(SUBSTRATE_CONDUCTOR_CURVE_B0) + x * (T(SUBSTRATE_CONDUCTOR_CURVE_B1) + x * b2);
    k.a[i] = lerp(a * conductor, da, share);
    k.b[i] = lerp(b * conductor, db, share);
  }
  return k;
}

// substrate_fresnel: F0 + (F90 - F0) w, w = t + (1 - t) s (a + b s) per channel,
// t = pow5(1 - VoH), s = sqrt(t).
template <class T>
V3<T> fresnel(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& k, T VoH) {
  const T t = pow5(T(1) - VoH);
  const T s = std::sqrt(t);
  V3<T> w;
  for (int i = 0; i < 3; ++i) w[i] = t + (T(1) - t) * s * (k.a[i] + k.b[i] * s);
  return f0 + (f90 - f0) * w;
}

// substrate_fresnel_b, chi's part (w): t = min(B / e, 1), d = D(t): e (t + share (d - pull min(d, 0))).
template <class T>
T fresnelB(const V2<T>& dfg, T e, T pull, T share) {
  const T t = std::min(dfg[1] / e, T(1));
  const T d = fresnelDelta(t);
  return e * (t + share * (d - pull * std::min(d, T(0))));
}

// substrate_fresnel_b, the curve's part (xyz): the same with each channel's
// d = (1 - t) s (a + b s), s = sqrt(t), its pull at least the dielectric curve's times the
// share, and no share.
template <class T>
V3<T> fresnelBCurve(const V2<T>& dfg, T e, T pull, const FresnelCurve<T>& k) {
  const T t = std::min(dfg[1] / e, T(1));
  const T s = std::sqrt(t);
  V3<T> out;
  for (int i = 0; i < 3; ++i) {
    const T d = (T(1) - t) * s * (k.a[i] + k.b[i] * s);
    out[i] = e * (t + (d - std::max(pull, k.pull * k.share) * std::min(d, T(0))));
  }
  return out;
}

// substrate_fresnel_pull: 0.43 below roughness 0.45, else 0.
template <class T>
T fresnelPull(T roughness) {
  return roughness < T(SUBSTRATE_FRESNEL_ROUGH_END) ? T(SUBSTRATE_FRESNEL_ROUGH_K) : T(0);
}

// substrate_fresnel_albedo: F0 e + max(F90 - F0, 0) b (b per channel).
template <class T>
V3<T> fresnelAlbedo(const V3<T>& f0, const V3<T>& f90, T e, const V3<T>& b) {
  return f0 * e + vmax(f90 - f0, splat3(T(0))) * b;
}

// substrate_dielectric_albedo: sat((d.x e + max(d.y - d.x, 0) b) (1 + d.x (1 - e) / e)).
template <class T>
T dielectricAlbedo(const V2<T>& d, T e, T b) {
  return saturate((d[0] * e + std::max(d[1] - d[0], T(0)) * b) * (T(1) + d[0] * ((T(1) - e) / e)));
}

// substrate_closure_dielectric_ms: no dielectric multiple scattering for a top over layers.
template <class T>
T closureDielectricMs(const Closure<T>& c) {
  return c.coversLayers ? T(0) : T(SUBSTRATE_DIELECTRIC_MS);
}

// substrate_specular_energy_aniso: e = clamp(E - B + B, 1e-3, 1) from the dfg
// pair (the shader sums the pair back); an anisotropic lobe, with
// A = min(|anisotropy|, 1): (e, B) -> (E_max, B_max)(NoV, r, A) (energyAniso),
// B -> min(B_max, e), pull 1 (else fresnelPull(r));
// W = (1 + F0w (1 - e) / e)(1 + share msRate r),
// E_spec = sat(fresnelAlbedo(F0, F90, e, fresnelBCurve(dfg, e, pull, curve)) W);
// the dielectric part's (ends fd) sat(dielectricAlbedo(fd, e, fresnelB(dfg, e, pull, 1)) (1 + msRate r)),
// msRate = closureDielectricMs.
template <class T>
V3<T> specularEnergyAniso(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& curve, const V2<T>& fd,
                          const V3<T>& f0w, T msRate,
                          T NoV, T roughness, T anisotropy, V3<T>& albedo, T& dielectric) {
  V2<T> dfg = energyDfg(NoV, roughness);
  T e = clampT(dfg[0] + dfg[1], T(1e-3), T(1));
  T pull = fresnelPull(roughness);
  T A = std::min(std::fabs(anisotropy), T(1));
  if (A > T(0)) {
    const V2<T> eb = energyAniso(NoV, roughness, A, V2<T>{e, dfg[1]});
    e = eb[0];
    dfg[1] = std::min(eb[1], e);
    pull = T(1);
  }
  const T ms = msRate * roughness;
  V3<T> w = (splat3(T(1)) + f0w * ((T(1) - e) / e)) * (T(1) + curve.share * ms);
  albedo = saturate(fresnelAlbedo(f0, f90, e, fresnelBCurve(dfg, e, pull, curve)) * w);
  dielectric = saturate(dielectricAlbedo(fd, e, fresnelB(dfg, e, pull, T(1))) * (T(1) + ms));
  return w;
}

// substrate_specular_energy: the isotropic case.
template <class T>
V3<T> specularEnergy(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& curve, const V2<T>& fd,
                     const V3<T>& f0w, T msRate, T NoV,
                     T roughness, V3<T>& albedo, T& dielectric) {
  return specularEnergyAniso(f0, f90, curve, fd, f0w, msRate, NoV, roughness, T(0), albedo, dielectric);
}

// substrate_diffuse_transmission: min(1 - min(E_spec, E_d), (1 - E_spec) / max(albedo, 1e-3)).
template <class T>
V3<T> diffuseTransmission(const V3<T>& albedo, const V3<T>& specAlbedo, T dielectric) {
  const V3<T> one = splat3(T(1));
  return vmin(one - vmin(specAlbedo, splat3(dielectric)), (one - specAlbedo) / vmax(albedo, splat3(T(1e-3))));
}

// substrate_interface_albedo_fit: c = r (-1, -0.00645, -0.572, 0.022) + (1, 0.03195, 1.04, -0.04),
// a = min(c.x^2, 2^(-7.925 mu)) c.x + c.y, (A, B) = (-1.0091 a + c.z, 1.0091 a + c.w).
template <class T>
V2<T> interfaceAlbedoFit(T mu, T roughness) {
  const T r = saturate(roughness);
  const T c0 = T(1) - r, c1 = T(0.03195) - T(0.00645) * r, c2 = T(1.04) - T(0.572) * r, c3 = T(-0.04) + T(0.022) * r;
  const T a = std::min(c0 * c0, std::exp2(T(-7.925) * mu)) * c0 + c1;
  return {T(-1.0091) * a + c2, T(1.0091) * a + c3};
}

// substrate_interface_albedo_means: x = quartic(r) (the shader's coefficients),
// (x - 4e-4, 1 - 0.55 r - x - 4e-4).
template <class T>
V2<T> interfaceAlbedoMeans(T roughness) {
  const T r = saturate(roughness);
  const T x = T(0.942790291) +
              r * (T(-0.503803993) + r * (T(0.019770635) + r * (T(0.050697408) + r * T(-0.067537130))));
  return {x - T(4e-4), T(1) - T(0.55) * r - x - T(4e-4)};
}

// substrate_diffuse_light_coupling: min(max(1 - f0 A - f90 B, 0) / max(1 - f0 X - f90 Y, 1e-3), cap)
// at max(NoL, 1e-4) with f0, f90 the means of the three channels, (A, B) and
// (X, Y) blended toward the haze lobe's by its weight first; cap 1 when
// f90 < f0, else 1000. One scalar for the three channels.
template <class T>
T diffuseLightCoupling(const V3<T>& f0, const V3<T>& f90, T NoL, T roughness, T hazeRoughness, T hazeWeight) {
  const T mu = std::max(NoL, K<T>::minCos);
  V2<T> ab = interfaceAlbedoFit(mu, roughness);
  V2<T> m = interfaceAlbedoMeans(roughness);
  if (hazeWeight > T(0)) {
    ab = lerp(ab, interfaceAlbedoFit(mu, hazeRoughness), hazeWeight);
    m = lerp(m, interfaceAlbedoMeans(hazeRoughness), hazeWeight);
  }
  const T F0 = mean3(f0), F90 = mean3(f90);
  const T numerator = std::max(T(1) - F0 * ab[0] - F90 * ab[1], T(0));
  const T denominator = std::max(T(1) - F0 * m[0] - F90 * m[1], T(1e-3));
  return std::min(numerator / denominator, F90 < F0 ? T(1) : T(1000));
}

// substrate_diffuse_light_coupling_deviation: 1.0091 max(F90 - F0, 0) max(s, 0) / max(1 - F0 X - F90 Y, 1e-3),
// s = ((0.184984 r - 0.192478) r - 0.101418) r + 0.112939, s and (X, Y) blended
// toward the haze lobe's by its weight; F0, F90 the means of the three channels.
template <class T>
T diffuseLightCouplingDeviation(const V3<T>& f0, const V3<T>& f90, T roughness, T hazeRoughness, T hazeWeight) {
  const auto deviation = [](T r) {
    r = saturate(r);
    return ((T(0.184984) * r - T(0.192478)) * r - T(0.101418)) * r + T(0.112939);
  };
  T s = deviation(roughness);
  V2<T> m = interfaceAlbedoMeans(roughness);
  if (hazeWeight > T(0)) {
    s = lerp(s, deviation(hazeRoughness), hazeWeight);
    m = lerp(m, interfaceAlbedoMeans(hazeRoughness), hazeWeight);
  }
  const T F0 = mean3(f0), F90 = mean3(f90);
  const T denominator = std::max(T(1) - F0 * m[0] - F90 * m[1], T(1e-3));
  return T(1.0091) * std::max(F90 - F0, T(0)) * std::max(s, T(0)) / denominator;
}

double fuzzPairMargin(int diffuseModel, double roughness) {
  const double r = std::clamp(roughness, 0.0, 1.0);
  return diffuseModel == kDiffuseChan2018   ? SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2018_0
         : diffuseModel == kDiffuseChan2024 ? SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2024_1 * r
         : diffuseModel == kDiffuseEon      ? SUBSTRATE_FUZZ_PAIR_MARGIN_EON_1 * r
                                            : 0.0;
}

// ---------------------------------------------------------------------------
// Diffuse models.

template <class T>
V3<T> diffuseLambert(const V3<T>& albedo, T NoL) {
  return albedo * (K<T>::invPi * saturate(NoL));
}

// substrate_eye_iris_cosine: UE's iris lighting, max(I.L, 0) times the caustic
// 0.8 + 0.2 (p + 1) max(C.L, 0)^p (p = lerp(12, 1, max(I.L, 0)), C = the iris
// plane's normal pulled toward -N by mask * distance), over its mean.
template <class T>
T eyeIrisCosine(const Closure<T>& c, const V3<T>& N, const V3<T>& L) {
  const T mask = saturate(c.iris[0]);
  const T depth = mask * saturate(c.iris[1]);
  const V3<T> axis = safeNormalize(lerp(c.irisPlaneN, N * T(-1), depth), c.irisPlaneN);
  const T irisNoL = saturate(dot(c.irisN, L));
  const T p = lerp(T(12), T(1), irisNoL);
  const T caustic = T(0.8) + T(0.2) * (p + T(1)) * std::pow(saturate(dot(axis, L)), p);
  return irisNoL * caustic * (T(1) / T(SUBSTRATE_EYE_CAUSTIC_MEAN));
}

// substrate_diffuse_chan2018: a2 = max(r^4, 1e-7); lobe capped at 1 (as UE),
// divided by 1 + max(0, 0.41 (r - 0.74) - 0.59 sat(NoV)), the bound of the
// model's albedo excess.
template <class T>
V3<T> diffuseChan2018(const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH) {
  T r = saturate(roughness);
  T a2 = std::max(r * r * r * r, T(1e-7));
  T g = saturate((T(1) / T(18)) * std::log2(T(2) / a2 - T(1)));
  T rough = VoH + pow5(T(1) - VoH);
  T smoothTerm = (T(1) - T(0.75) * pow5(T(1) - NoV)) * (T(1) - T(0.75) * pow5(T(1) - NoL));
  T fd = lerp(rough, smoothTerm, saturate(T(2.2) * g - T(0.5)));
  T fb = ((T(34.5) * g - T(59)) * g + T(24.5)) * VoH *
         std::exp2(-std::max(T(73.2) * g - T(21.2), T(8.9)) * std::sqrt(saturate(NoH)));
  T lobe = std::min(T(1), K<T>::invPi * (fd + fb));
  T excess = std::max(T(0), T(0.41) * (r - T(0.74)) - T(0.59) * saturate(NoV));
  return albedo * (lobe * saturate(NoL) / (T(1) + excess));
}

// substrate_chan2024_loss: h(mu, r), with 1 - E(mu, r) = r h for Chan 2024's
// white albedo E; K1 the rational fit SUBSTRATE_CHAN24_K1_*.
template <class T>
T chan2024Loss(T mu, T r, T scale, T bias) {
  T k1 = (T(SUBSTRATE_CHAN24_K1_P0) +
          mu * (T(SUBSTRATE_CHAN24_K1_P1) + mu * (T(SUBSTRATE_CHAN24_K1_P2) + mu * T(SUBSTRATE_CHAN24_K1_P3)))) /
         (mu + T(SUBSTRATE_CHAN24_K1_C));
  return T(1) - T(0.38) * r - scale * (T(0.5) + mu / T(3) + (bias - T(0.025)) * k1);
}

// substrate_diffuse_chan2024 (UE's, Lambertian smooth limit), divided by
// 1 + 0.026 sat(1 - 25 NoV) sat(10 (r - 0.42)), the bound of its albedo excess,
// plus the multiple-scattering lobe r max(h_V, 0) max(h_L, 0) / H (issue 19,
// step 7).
template <class T>
V3<T> diffuseChan2024(const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH) {
  T r = saturate(roughness);
  T a = r * r;
  T scale = std::max(T(0.55) - T(0.2) * r, T(1.25) - T(1.6) * r);
  T bias = saturate(T(4) * a);
  T n = saturate(NoH);
  T fRough = scale * (n + bias) / (n + T(0.025)) * VoH * VoH;
  T f = lerp(T(1), fRough, r) + T(0.38) * a;
  T excess = T(0.026) * saturate(T(1) - T(25) * NoV) * saturate(T(10) * (r - T(0.42)));
  T lossAvg = T(1) - T(0.38) * r - scale * (T(13) / T(18) + (bias - T(0.025)) * T(SUBSTRATE_CHAN24_K1_MEAN));
  T ms = r * std::max(chan2024Loss(saturate(NoV), r, scale, bias), T(0)) *
         std::max(chan2024Loss(saturate(NoL), r, scale, bias), T(0)) / std::max(lossAvg, T(1e-4));
  return albedo * (K<T>::invPi * (f / (T(1) + excess) + ms) * saturate(NoL));
}

// substrate_eon_albedo: Portsmouth et al. 2025's quartic fit of E_FON.
template <class T>
T eonAlbedo(T mu, T r) {
  T m = T(1) - saturate(mu);
  T gOverPi = m * (T(0.0571085289) + m * (T(0.491881867) + m * (T(-0.332181442) + m * T(0.0714429953))));
  return (T(1) + r * gOverPi) / (T(1) + T(0.287793409) * r);
}

// substrate_diffuse_eon: r_EON = 0.4 sat(r); s/t = s / max(max(NoV, NoL), 1e-6)
// for s > 0; the albedo inverted for the model's hemispherical mean; the
// multiple-scattering factors floored at 1e-7.
template <class T>
V3<T> diffuseEon(const V3<T>& albedo, T roughness, T NoV, T NoL, T VoL) {
  T r = T(0.4) * saturate(roughness);
  T mo = saturate(NoV);
  T mi = saturate(NoL);
  T s = VoL - mo * mi;
  T sOverT = s > T(0) ? s / std::max(std::max(mo, mi), T(1e-6)) : s;
  T af = T(1) / (T(1) + T(0.287793409) * r);
  T eAvg = af * (T(1) + T(0.0724882125) * r);
  V3<T> rho = albedo / (splat3(eAvg) + albedo * (T(1) - eAvg));
  V3<T> rhoMs = rho * rho * eAvg / (splat3(T(1)) - rho * (T(1) - eAvg));
  T fss = af * (T(1) + r * sOverT);
  T ms = std::max(T(1e-7), T(1) - eonAlbedo(mo, r)) * std::max(T(1e-7), T(1) - eonAlbedo(mi, r)) /
         std::max(T(1e-7), T(1) - eAvg);
  return (rho * fss + rhoMs * ms) * (K<T>::invPi * mi);
}

template <class T>
V3<T> diffuse(int model, const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH, T VoL) {
  switch (model) {
    case kDiffuseChan2018: return diffuseChan2018(albedo, roughness, NoV, NoL, NoH, VoH);
    case kDiffuseChan2024: return diffuseChan2024(albedo, roughness, NoV, NoL, NoH, VoH);
    case kDiffuseEon: return diffuseEon(albedo, roughness, NoV, NoL, VoL);
    default: return diffuseLambert(albedo, NoL);
  }
}

// ---------------------------------------------------------------------------
// SSS wrap.

// substrate_sss_wrap_amount: m / (m + 0.005), m = max(mfp, 0).
template <class T>
V3<T> sssWrapAmount(const V3<T>& mfp) {
  V3<T> m = vmax(mfp, splat3(T(0)));
  return m / (m + splat3(kWrapMfpScale<T>));
}

// substrate_diffuse_wrap: albedo / pi max(NoL + w, 0) / (1 + w)^2, w saturated.
template <class T>
V3<T> diffuseWrap(const V3<T>& albedo, const V3<T>& wrap, T NoL) {
  V3<T> w = saturate(wrap);
  V3<T> onePlus = splat3(T(1)) + w;
  return albedo * K<T>::invPi * vmax(splat3(NoL) + w, splat3(T(0))) / (onePlus * onePlus);
}

// ---------------------------------------------------------------------------
// A slab's medium seen through its interface (substrate_medium_*, issue 19 step 12).

// substrate_mix_share: sat((f0max - SUBSTRATE_MIX_START) SUBSTRATE_MIX_BLEND).
template <class T>
T mixShare(T f0max) {
  return saturate((f0max - T(SUBSTRATE_MIX_START)) * T(SUBSTRATE_MIX_BLEND));
}

// substrate_medium_f0: the mean of the closure's own saturated F0 (against air, under layers too).
template <class T>
T mediumF0(const Closure<T>& c) {
  return mean3(saturate(c.f0));
}

// substrate_medium_share: 1 with a medium (else 0), times 1 - mixShare(max3(F0)) for a
// metalness mix (its medium's albedo is the base colour, which the closure does not hold).
template <class T>
T mediumShare(const Closure<T>& c) {
  if (c.sssType == kSssNone) return T(0);
  if (!c.metalnessMix) return T(1);
  return T(1) - mixShare(max3(saturate(c.f0)));
}

// substrate_medium_interface: (1 / eta^2, p), eta = (1 + sqrt(F0)) / (1 - sqrt(F0)) of
// f0 (substrate_medium_f0, mediumF0), p = sqrt(1 - 1 / eta^2) (1 - SPREAD sat(r)).
template <class T>
V2<T> mediumInterface(T f0, T roughness) {
  const T sq = std::sqrt(f0);
  const T ie = (T(1) - sq) / (T(1) + sq);
  const T ie2 = ie * ie;
  return {ie2, std::sqrt(T(1) - ie2) * (T(1) - T(SUBSTRATE_MEDIUM_SPREAD) * saturate(roughness))};
}

// substrate_medium_slope2: 2 s = share 2 t (1 - A) / (t + (1 - t + SUBSTRATE_MEDIUM_INVERSE) A),
// t = max(1 - R21, 1e-4) = max((1 - F0) (20 / 21) / eta^2, 1e-4) (R12 = F0 + (1 - F0) / 21: the
// rational inverse of van de Hulst's albedo at A' = A / (t + (1 - t) A), the albedo seen from
// inside); share = mediumShare.
template <class T>
V3<T> mediumSlope2(const V3<T>& albedo, T share, T f0, T ie2) {
  const T t = std::max((T(1) - f0) * (T(20) / T(21)) * ie2, T(1e-4));
  V3<T> s2{};
  for (int i = 0; i < 3; ++i)
    s2[i] = T(2) * t * share * (T(1) - albedo[i]) / (t + (T(1) + T(SUBSTRATE_MEDIUM_INVERSE) - t) * albedo[i]);
  return s2;
}

// The medium's weight (1 + 2 s m) / (1 + 2 s mu') per channel, mu' = p + (1 - p) mu the
// cosine inside for mu outside (substrate_eval_closure multiplies the view's, at m =
// MEAN_COS, and the light's, at m = p + (1 - p) MEAN_COS; the split sum takes the view's).
template <class T>
V3<T> mediumWeight(const V3<T>& s2, T m, T p, T mu) {
  V3<T> w{};
  for (int i = 0; i < 3; ++i) w[i] = (T(1) + s2[i] * m) / (T(1) + s2[i] * (p + (T(1) - p) * mu));
  return w;
}

// substrate_closure_medium: 2 s per channel of the closure's medium, and p.
template <class T>
V3<T> closureMedium(const Closure<T>& c, const V3<T>& albedo, T roughness, T& p) {
  const T f0 = mediumF0(c);
  const V2<T> mi = mediumInterface(f0, roughness);
  p = mi[1];
  return mediumSlope2(albedo, mediumShare(c), f0, mi[0]);
}

// ---------------------------------------------------------------------------
// Fuzz.

// substrate_charlie_d: (2 + 1/a) substrate_pow(max(1 - NoH^2, 0), 0.5/a) / (2 pi).
template <class T>
T charlieD(T a, T NoH) {
  T inv = T(1) / a;
  T sin2 = std::max(T(1) - NoH * NoH, T(0));
  return (T(2) + inv) * substratePow(sin2, T(0.5) * inv) * (T(0.5) * K<T>::invPi);
}

// substrate_charlie_l: the paper's two rows lerped by (1 - a)^2.
template <class T>
T charlieL(T x, T a) {
  T t = (T(1) - a) * (T(1) - a);
  T pa = lerp(T(21.5473), T(25.3245), t);
  T pb = lerp(T(3.82987), T(3.32435), t);
  T pc = lerp(T(0.19823), T(0.16801), t);
  T pd = lerp(T(-1.97760), T(-1.27393), t);
  T pe = lerp(T(-4.32054), T(-4.85967), t);
  return pa / (T(1) + pb * substratePow(x, pc)) + pd * x + pe;
}

// substrate_charlie_lambda: exp(min(l, 80)).
template <class T>
T charlieLambda(T mu, T a) {
  T m = saturate(mu);
  T l = m < T(0.5) ? charlieL(m, a) : T(2) * charlieL(T(0.5), a) - charlieL(T(1) - m, a);
  return std::exp(std::min(l, T(80)));
}

// substrate_charlie_sheen: D G / (4 max(NoV, 1e-4)), a = max(sat(r)^2, 1e-3).
template <class T>
T charlieSheen(T fuzzRoughness, T NoV, T NoL, T NoH) {
  T r = saturate(fuzzRoughness);
  T a = std::max(r * r, kFuzzMinAlpha<T>);
  T g = T(1) / (T(1) + charlieLambda(NoV, a) + charlieLambda(NoL, a));
  return charlieD(a, NoH) * g / (T(4) * std::max(NoV, K<T>::minCos));
}

// ---------------------------------------------------------------------------
// Glints.

namespace {
// GLSL float -> int conversion truncates toward zero; uint(int) wraps modulo 2^32.
template <class T>
std::uint32_t uintOfInt(T x) {
  return static_cast<std::uint32_t>(static_cast<std::int32_t>(x));
}
}  // namespace

// substrate_glint_level_sample.
template <class T>
T glintLevelSample(const V2<T>& uv, T level, const std::array<int, 2>& slopeBin, T expected) {
  T size = std::exp2(level);
  V2<T> cell{clampT(std::floor(uv[0] / size), T(-8388608.0), T(8388607.0)),
             clampT(std::floor(uv[1] / size), T(-8388608.0), T(8388607.0))};
  std::array<std::uint32_t, 3> key{
      uintOfInt(cell[0]), uintOfInt(cell[1]),
      (static_cast<std::uint32_t>(slopeBin[0]) & 0xffffu) | (static_cast<std::uint32_t>(slopeBin[1]) << 16u)};
  key[2] ^= static_cast<std::uint32_t>(static_cast<std::int32_t>(level) + 128) * 0x9E3779B9u;
  std::array<std::uint32_t, 3> h = pcg3d(key);
  T q = std::min(expected, T(1));
  T v = q * (T(1) + T(1) / expected) - T(1);
  T sigma2 = std::log(T(1) + std::max(v, T(0)));
  T z = std::sqrt(T(-2) * std::log(hashToUnit<T>(h[0]))) * std::cos(K<T>::twoPi * hashToUnit<T>(h[1]));
  T y = std::exp(std::sqrt(sigma2) * z - T(0.5) * sigma2);
  return hashToUnit<T>(h[2]) <= q ? y / q : T(0);
}

// substrate_glint_factor: footprint area >= (longer axis)^2 / 64 with the axis
// clamped to [1e-6, 1e6]; expected count clamped to [1e-4, 1e30]; slope over
// max(NoH, 0.05); level clamped to [-40, 20]; two levels blended.
template <class T>
T glintFactor(const Closure<T>& c, T d, T ToH, T BoH, T NoH) {
  T density = saturate(c.glintValue);
  if (density >= T(1)) return T(1);
  const V4<T>& g = c.glintUvDerivatives;
  T lx = std::sqrt(g[0] * g[0] + g[1] * g[1]);
  T ly = std::sqrt(g[2] * g[2] + g[3] * g[3]);
  T wide = clampT(std::max(lx, ly), T(1e-6), T(1e6));
  T area = std::max(std::fabs(g[0] * g[3] - g[1] * g[2]), wide * wide * (T(1) / T(64)));
  T rho = std::exp2(lerp(kGlintLog2Min<T>, kGlintLog2Max<T>, density));
  T gamma = kGlintCone<T>;
  T p = std::min(T(1), d * saturate(NoH) * (K<T>::pi * gamma * gamma));
  T expected = clampT(rho * area * p, T(1e-4), T(1e30));
  T den = std::max(NoH, T(0.05));
  std::array<int, 2> bin{static_cast<int>(std::floor(ToH / den / (T(2) * gamma))),
                         static_cast<int>(std::floor(BoH / den / (T(2) * gamma)))};
  T level = clampT(T(0.5) * std::log2(area), T(-40), T(20));
  T l0 = std::floor(level);
  T t = level - l0;
  T m0 = glintLevelSample(c.glintUv, l0, bin, expected);
  T m1 = glintLevelSample(c.glintUv, l0 + T(1), bin, expected);
  return lerp(m0, m1, t);
}

// ---------------------------------------------------------------------------
// --- closures under layers (substrate_closure_fresnel_ends, substrate_closure_coat_diffuse)

// substrate_coat_floor: SCALE x / (x + HALF), x = max(r - START, 0).
template <class T>
T coatFloor(T topRoughness) {
  const T x = std::max(topRoughness - T(SUBSTRATE_COAT_ROUGH_START), T(0));
  return T(SUBSTRATE_COAT_ROUGH_SCALE) * x / (x + T(SUBSTRATE_COAT_ROUGH_HALF));
}

// substrate_coat_top_alpha: r^2, r = START + HALF f / (SCALE - f) (f clamped to
// [0, 0.99 SCALE]), the inverse of coatFloor; 0 for f = 0.
template <class T>
T coatTopAlpha(T floor) {
  const T f = clampT(floor, T(0), T(0.99) * T(SUBSTRATE_COAT_ROUGH_SCALE));
  const T r = T(SUBSTRATE_COAT_ROUGH_START) + T(SUBSTRATE_COAT_ROUGH_HALF) * f / (T(SUBSTRATE_COAT_ROUGH_SCALE) - f);
  return f > T(0) ? r * r : T(0);
}

// substrate_coat_mean_share: sat(f (A + f (B + C f))).
template <class T>
T coatMeanShare(T coatFloor) {
  return saturate(coatFloor *
                  (T(SUBSTRATE_COAT_MEAN_A) + coatFloor * (T(SUBSTRATE_COAT_MEAN_B) + T(SUBSTRATE_COAT_MEAN_C) * coatFloor)));
}

// substrate_coat_stretch: (ay^2, ax^2 - ay^2) of ggxAlpha(r, A).
template <class T>
V2<T> coatStretch(T roughness, T anisotropy) {
  const V2<T> a = ggxAlpha(roughness, anisotropy);
  return {a[1] * a[1], a[0] * a[0] - a[1] * a[1]};
}

// substrate_coat_floor_projected: coatFloor((s.x + s.y c2)^(1/4)).
template <class T>
T coatFloorProjected(const V2<T>& stretch, T c2) {
  return coatFloor(std::sqrt(std::sqrt(stretch[0] + stretch[1] * c2)));
}

// substrate_coat_aniso_share: the mean of coatMeanShare(coatFloorProjected) at
// c2 = AZIMUTH_C2_0 and AZIMUTH_C2_1.
template <class T>
T coatAnisoShare(const V2<T>& stretch) {
  return (coatMeanShare(coatFloorProjected(stretch, T(SUBSTRATE_COAT_AZIMUTH_C2_0))) +
          coatMeanShare(coatFloorProjected(stretch, T(SUBSTRATE_COAT_AZIMUTH_C2_1)))) *
         T(0.5);
}

// substrate_closure_coat_top_alpha: max(coatTopAlpha(coatFloor), (sqrt(s.x) + sqrt(s.x + s.y)) / 2),
// s = coatStretch (one of the two is 0).
template <class T>
T closureCoatTopAlpha(const Closure<T>& c) {
  return std::max(coatTopAlpha(c.coatFloor),
                  (std::sqrt(c.coatStretch[0]) + std::sqrt(c.coatStretch[0] + c.coatStretch[1])) / T(2));
}

// substrate_unpack_material / the emitter's emitCoversLayers: on top, when some closure is not.
template <class T>
void setCoversLayers(std::vector<Closure<T>>& closures) {
  const bool under = std::any_of(closures.begin(), closures.end(), [](const Closure<T>& c) { return !c.isTop; });
  for (Closure<T>& c : closures) c.coversLayers = c.isTop && under;
}

template <class T>
void setCoatFloor(std::vector<Closure<T>>& closures, T topR) {
  int tops = 0;
  const Closure<T>* top = nullptr;
  for (const Closure<T>& c : closures)
    if (c.isTop) {
      ++tops;
      top = &c;
    }
  const bool one = tops == 1;
  const bool haze = one && (top->features & kFeatureHaze);
  const bool stretched = one && !haze && (top->features & kFeatureAnisotropy);
  const T f = one && !haze && !stretched ? coatFloor(topR) : T(0);
  const V2<T> stretch = stretched ? coatStretch(top->roughness, top->anisotropy) : V2<T>{T(0), T(0)};
  const V3<T> tangent = stretched ? top->T_ : V3<T>{T(1), T(0), T(0)};
  const T share = stretched ? coatAnisoShare(stretch) : coatMeanShare(f);
  for (Closure<T>& c : closures) {
    const bool under = !c.isTop && c.extraInterfaces == 0;
    c.coatFloor = under ? f : T(0);
    c.coatStretch = under ? stretch : V2<T>{T(0), T(0)};
    c.coatTangent = under ? tangent : V3<T>{T(1), T(0), T(0)};
    c.coatShare = under ? share : T(0);
  }
}

// substrate_coat_floor_along: max(coatFloor, coatFloorProjected(coatStretch, c2)),
// c2 = sat((T.w)^2 / max(1 - mu^2, 1e-8)), T = coatTangent, w a unit direction.
template <class T>
T coatFloorAlong(const Closure<T>& c, T mu, const V3<T>& w) {
  const T tw = dot(c.coatTangent, w);
  const T c2 = saturate(tw * tw / std::max(T(1) - mu * mu, T(1e-8)));
  return std::max(c.coatFloor, coatFloorProjected(c.coatStretch, c2));
}

// substrate_coat_mean_direction: T sqrt((1 - mu^2) / 2), T = coatTangent.
template <class T>
V3<T> coatMeanDirection(const Closure<T>& c, T mu) {
  return c.coatTangent * std::sqrt(T(0.5) * (T(1) - mu * mu));
}

// substrate_coat_interface: 1 - clamp(mean F0, 0, SUBSTRATE_COAT_TOP_F0_MAX).
template <class T>
T coatInterface(const V3<T>& topF0) {
  return T(1) - clampT(dot(topF0, splat3(T(1) / T(3))), T(0), T(SUBSTRATE_COAT_TOP_F0_MAX));
}

template <class T>
void setCoatInterface(std::vector<Closure<T>>& closures) {
  int tops = 0;
  T ifc = T(SUBSTRATE_COAT_T_0);
  for (const Closure<T>& c : closures)
    if (c.isTop) {
      ++tops;
      ifc = coatInterface(c.f0);
    }
  for (Closure<T>& c : closures) c.coatInterface = !c.isTop && tops == 1 ? ifc : T(SUBSTRATE_COAT_T_0);
}

// substrate_coat_transmission: max(1 - chi(mu), 1 - (1 - f) (1 - sat(mu))^2).
template <class T>
T coatTransmission(T mu, T coatFloor) {
  const T m = T(1) - saturate(mu);
  return std::max(T(1) - fresnelWeight(mu), T(1) - (T(1) - coatFloor) * (m * m));
}

// substrate_interfaces_transmission: the interface term to the power 1 + extra
// by multiplies (g, g2 = g g, then g2 | g2 g | g2 g2 for extra 1 | 2 | >= 3).
template <class T>
T interfacesTransmission(T mu, std::uint32_t extra, T coatFloor) {
  T g = coatTransmission(mu, coatFloor);
  const T g2 = g * g;
  if (extra == 1u) g = g2;
  else if (extra == 2u) g = g2 * g;
  else if (extra >= 3u) g = g2 * g2;
  return g;
}

// substrate_coat_path_length: 1.5 rsqrt(1.25 + sat(mu)^2) = 1 / mu_t, the
// path per unit thickness along the cosine refracted into the layers above.
template <class T>
T coatPathLength(T mu) {
  const T m = saturate(mu);
  return T(1.5) / std::sqrt(T(1.25) + m * m);
}

// substrate_closure_layers_crossing: T_N^coatPathLength(mu) *
// coatTransmission(mu, coatFloor)^(1 + extraInterfaces) where the layers above
// cover the closure, and exactly 1 (no transcendental) when nothing covers it.
template <class T>
V3<T> layersCrossing(const Closure<T>& c, T mu, const V3<T>& w) {
  if (!(saturate(c.coverageAbove) > T(0))) return splat3(T(1));
  const T path = coatPathLength(mu);
  V3<T> t;
  for (int k = 0; k < 3; ++k)
    t[k] = std::exp(std::log(clampT(c.topTransmittance[k], K<T>::minTransmittance, T(1))) * path);
  const T i = interfacesTransmission(mu, c.extraInterfaces, coatFloorAlong(c, mu, w));
  return V3<T>{t[0] * i, t[1] * i, t[2] * i};
}

// substrate_closure_above_throughput: lerp(1, layersCrossing(c, mu, w), sat(coverageAbove)).
template <class T>
V3<T> aboveThroughput(const Closure<T>& c, T mu, const V3<T>& w) {
  const T cover = saturate(c.coverageAbove);
  if (cover > T(0)) return lerp(splat3(T(1)), layersCrossing(c, mu, w), cover);
  return splat3(T(1));
}

// substrate_cover_given_view: C t_V / max((1 - C) + C t_V, 1e-30) per channel,
// the coverage the light meets given the view's crossing (issue 19, step 22).
template <class T>
V3<T> coverGivenView(T cover, const V3<T>& viewCrossing) {
  V3<T> r;
  for (int k = 0; k < 3; ++k) {
    const T seen = cover * viewCrossing[k];
    r[k] = seen / std::max(T(1) - cover + seen, T(1e-30));
  }
  return r;
}

// substrate_wrap_light_cosine: the cosine the layers above are crossed at by
// the light of a wrap lobe, (NoL + w) / (1 + w), w the smallest channel's wrap
// amount; NoL for every other closure.
template <class T>
T wrapLightCosine(const Closure<T>& c, T NoL) {
  if (c.sssType != kSssWrap) return NoL;
  const V3<T> w3 = sssWrapAmount(c.sssMfp);
  const T w = saturate(std::min(w3[0], std::min(w3[1], w3[2])));
  return (NoL + w) / (T(1) + w);
}

// substrate_wrap_light_ratio: for a wrap closure, what the layers above let
// through at NoL over what they let through at the wrap's cosine, at most 1
// (the lighting applies the latter to the whole closure); 1 otherwise.
template <class T>
V3<T> wrapLightRatio(const Closure<T>& c, bool isWrap, T NoLc, T NoL, const V3<T>& L) {
  if (!isWrap) return splat3(T(1));
  const V3<T> at = aboveThroughput(c, NoLc, L);
  const V3<T> wrapped = aboveThroughput(c, wrapLightCosine(c, NoL), L);
  V3<T> r;
  for (int k = 0; k < 3; ++k) r[k] = std::min(at[k] / std::max(wrapped[k], T(1e-4)), T(1));
  return r;
}

// substrate_fuzz_cosine: under layers (coverageAbove > 0), the cosine mu
// refracted into an interface of IOR eta = 1 + 0.5 coverageAbove, sqrt(max(1 -
// (1 - mu^2) / eta^2, 0)), never below mu; mu on top.
template <class T>
T fuzzRefractedCosine(T mu, T inv2) {  // substrate_fuzz_refracted_cosine, inv2 = 1 / eta^2
  return std::max(std::sqrt(std::max(T(1) - (T(1) - mu * mu) * inv2, T(0))), mu);  // never below mu
}

template <class T>
T fuzzCosine(const Closure<T>& c, T mu) {
  const T cover = saturate(c.coverageAbove);
  if (!(cover > T(0))) return mu;
  const T inv = T(1) / (T(1) + T(0.5) * cover);
  return fuzzRefractedCosine(mu, inv * inv);
}

// substrate_fuzz_under_layers: the cosines a fuzz under layers sees, the view
// and the light refracted (fuzzCosine; V' = (V - N NoV) / eta + N fv), the
// half vector's N.H' = (fv + fl) / sqrt(2 + 2 V'.L'), V'.L' = (VoL - NoV NoL) /
// eta^2 + fv fl, and `spread` = NoL / (eta^2 fl), which turns the lobe inside
// times fl into the lobe seen from above (1 / eta^2 of it: cos dw = eta^2
// cos' dw') times NoL; unchanged on top.
template <class T>
void fuzzUnderLayers(const Closure<T>& c, T NoV, T NoL, T VoL, T& fv, T& fl, T& fh, T& spread) {
  const T cover = saturate(c.coverageAbove);
  if (!(cover > T(0))) return;
  const T inv = T(1) / (T(1) + T(0.5) * cover);
  spread = inv * inv;
  fv = fuzzRefractedCosine(NoV, spread);
  fl = fuzzRefractedCosine(std::max(NoL, T(0)), spread);
  const T vl = (VoL - NoV * NoL) * spread + fv * fl;
  fh = saturate((fv + fl) / std::sqrt(std::max(T(2) + T(2) * vl, T(1e-8))));
  spread = spread * std::max(NoL, T(0)) / std::max(fl, T(1e-6));  // the lobe times NoL, not NoL' (fl >= NoL)
}

template <class T> constexpr T kCoatSqrtF0 = T(SUBSTRATE_COAT_SQRT_F0);
template <class T> constexpr T kCoatTrap = T(SUBSTRATE_COAT_TRAP);

// substrate_f90_effective: lerp(F90 / max3 F90 (white when max3 F90 < 1e-6),
// F90, fresnelShare(max3 F0)): a conductor's F90 is a hue, a dielectric's keeps its intensity.
template <class T>
V3<T> f90Effective(const V3<T>& f0, const V3<T>& f90) {
  const T m = max3(f90);
  const V3<T> hue = m >= T(1e-6) ? f90 * (T(1) / m) : splat3(T(1));
  const T share = fresnelShare(max3(f0));
  return hue + (f90 - hue) * share;
}

// substrate_mix_conductor_f0, one channel: the larger root of b^2 - (f + A) b + d A = 0,
// (s + sqrt(max(s^2 - 4 d A, 0))) / 2, s = f + A. Not clamped.
template <class T>
T mixConductorF0(T f, T a, T d) {
  const T s = f + a;
  return T(0.5) * (s + std::sqrt(std::max(s * s - (T(4) * d) * a, T(0))));
}

// substrate_closure_mix_under: per channel, weight times the dielectric part's share of a
// metalness mix of F0 f0 (against air) and diffuse A: A / b, b = mixConductorF0(f0, A,
// SUBSTRATE_MIX_DIELECTRIC_F0); at most weight.
template <class T>
V3<T> closureMixUnder(const Closure<T>& c, const V3<T>& f0, T weight) {
  const V3<T> a = saturate(c.diffuseAlbedo);
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    const T b = mixConductorF0(f0[i], a[i], T(SUBSTRATE_MIX_DIELECTRIC_F0));
    r[i] = std::min(a[i] / std::max(b, T(1e-4)), T(1)) * weight;
  }
  return r;
}

// F0 and F90 scaled by the ratio of the largest channel's F0 relative to a dielectric of
// F0 0.04 above, ((s - 0.2) / (1 - 0.2 s))^2, to itself: never above 1, only
// in the dielectric range (back to 1 over F0 0.1 .. 0.2), lerped toward 1 by
// coverageAbove; a metalness mix's dielectric part then relative too (closureMixUnder: its share
// of F0 0.04 lowered to MIX_DIELECTRIC_F0_UNDER, of F90 scaled by UNDER / 0.04). The curve: the conductor's own where the closure has no diffuse nor medium, or is a
// metalness mix (mixShare), not under layers (times 1 - coverageAbove); the low-F0 dielectric's own
// not under layers either, nor on top of them (coversLayers).
template <class T>
void closureFresnelEnds(const Closure<T>& c, V3<T>& f0, V3<T>& f90, FresnelCurve<T>& curve) {
  f0 = saturate(c.f0);
  f90 = splat3(T(1));
  if (c.features & kFeatureF90) f90 = f90Effective(f0, saturate(c.f90));
  // No branch, as in the shader: at coverageAbove 0 the scale is exactly 1.
  const T cover = saturate(c.coverageAbove);
  const T f = max3(saturate(c.f0));
  const T s = std::sqrt(f);
  const T r = (s - kCoatSqrtF0<T>) / (T(1) - kCoatSqrtF0<T> * s);
  T rel = std::min(f, r * r);
  rel = lerp(rel, f, saturate((f - T(SUBSTRATE_COAT_DIELECTRIC_F0)) * T(SUBSTRATE_COAT_CONDUCTOR_BLEND)));
  const T scale = lerp(T(1), rel / std::max(f, T(1e-4)), cover);
  f0 = f0 * scale;
  f90 = f90 * scale;
  if (c.metalnessMix) {
    const V3<T> part = closureMixUnder(c, f0, mixShare(f) * cover);
    f0 = vmax(f0 - part * T(SUBSTRATE_MIX_DIELECTRIC_F0 - SUBSTRATE_MIX_DIELECTRIC_F0_UNDER), splat3(T(0)));
    f90 = f90 * (splat3(T(1)) - part * T(1 - SUBSTRATE_MIX_DIELECTRIC_F0_UNDER / SUBSTRATE_MIX_DIELECTRIC_F0));
  }
  T conductor = !c.conductorCurve || std::max(max3(saturate(c.diffuseAlbedo)), max3(c.sssMfp)) > T(0) ? T(0) : T(1);
  if (c.metalnessMix) conductor = std::max(conductor, mixShare(f));
  const T lowIor = c.lowIorCurve && !c.coversLayers ? T(1) - cover : T(0);
  curve = fresnelCurve(f0, fresnelShare(f * scale), conductor * (T(1) - cover), lowIor);
}

// substrate_closure_dielectric_part: lerp((max F0, max F90), (MIX_DIELECTRIC_F0, 1) relative
// to the layers above by coverageAbove, sat((max F0 - MIX_START) MIX_BLEND)).
template <class T>
V2<T> closureDielectricPart(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90) {
  // Without SUBSTRATE_USE_METALNESS_MIX: (1, 1), so E_d = 1 and the transmission is 1 - E_spec.
  if (!c.metalnessMix) return {T(1), T(1)};
  const T cover = saturate(c.coverageAbove);
  const T f = max3(f0);
  const V2<T> mixed{lerp(T(SUBSTRATE_MIX_DIELECTRIC_F0), T(SUBSTRATE_MIX_DIELECTRIC_F0_UNDER), cover),
                    lerp(T(1), T(SUBSTRATE_MIX_DIELECTRIC_F0_UNDER / SUBSTRATE_MIX_DIELECTRIC_F0), cover)};
  const T t = mixShare(f);
  return {lerp(f, mixed[0], t), lerp(max3(f90), mixed[1], t)};
}

// substrate_closure_compensated_f0: F + t (F - d)^+ (b - F)^+ / max(F, 1e-4) per channel, d = fd.x,
// b = min(mixConductorF0(F, A, d), 1), A the saturated diffuse albedo,
// t = mixShare(max F0); F without a metalness mix.
template <class T>
V3<T> closureCompensatedF0(const Closure<T>& c, const V3<T>& f0, const V2<T>& fd) {
  if (!c.metalnessMix) return f0;
  const T t = mixShare(max3(f0));
  const V3<T> a = saturate(c.diffuseAlbedo);
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    const T b = std::min(mixConductorF0(f0[i], a[i], fd[0]), T(1));
    const T var = std::max(f0[i] - fd[0], T(0)) * std::max(b - f0[i], T(0));
    r[i] = f0[i] + t * var / std::max(f0[i], T(1e-4));
  }
  return r;
}

// 1 / lerp(1, D, cover), D = G_k(f) T_i (1 - 0.12 (1 - T_i)) + TRAP A (1 - T_m^4),
// G_k(f) = G_k + (1 - G_k) coatShare (setCoatFloor: coatMeanShare(coatFloor), or coatAnisoShare),
// T_i = max(T_N, I), T_m = sat(T_N / I), I = coatInterface 0.96^k.
// The first term raised by 1 + 0.0145 sat(mean F90 - mean F0) of the closure's
// own (relative) interface: the covariance of its coupling with the layers' (the
// shader takes the two means, substrate_diffuse_interface).
template <class T>
V3<T> closureCoatDiffuse(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90, int diffuseModel) {
  // No branch, as in the shader: at coverageAbove 0 the factor is exactly 1.
  const T cover = saturate(c.coverageAbove);
  // substrate_coat_lobe: the diffuse model's bound of its lobe's share of G_k.
  auto lobe = [diffuseModel](double chan2024, double eon) {
    return T(diffuseModel == kDiffuseChan2024 ? chan2024 : diffuseModel == kDiffuseEon ? eon : 1.0);
  };
  T gk = T(SUBSTRATE_COAT_G_0), lb = lobe(SUBSTRATE_COAT_LOBE_CHAN2024_0, SUBSTRATE_COAT_LOBE_EON_0);
  T ifc = c.coatInterface;  // the top's; each interface under it 0.96
  if (c.extraInterfaces == 1u) {
    gk = T(SUBSTRATE_COAT_G_1);
    lb = lobe(SUBSTRATE_COAT_LOBE_CHAN2024_1, SUBSTRATE_COAT_LOBE_EON_1);
    ifc = ifc * T(SUBSTRATE_COAT_T_0);
  } else if (c.extraInterfaces == 2u) {
    gk = T(SUBSTRATE_COAT_G_2);
    lb = lobe(SUBSTRATE_COAT_LOBE_CHAN2024_2, SUBSTRATE_COAT_LOBE_EON_2);
    ifc = ifc * T(SUBSTRATE_COAT_T_1);
  } else if (c.extraInterfaces >= 3u) {
    gk = T(SUBSTRATE_COAT_G_3);
    lb = lobe(SUBSTRATE_COAT_LOBE_CHAN2024_3, SUBSTRATE_COAT_LOBE_EON_3);
    ifc = ifc * T(SUBSTRATE_COAT_T_2);
  }
  T g = (gk + (T(1) - gk) * c.coatShare) * lb;
  const T own = saturate(dot(f90 - f0, splat3(T(1) / T(3))));
  g = g * (T(1) + T(SUBSTRATE_COAT_COVARIANCE) * own);
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    const T tn = saturate(c.topTransmittance[i]);
    const T ti = std::max(tn, ifc);
    const T tm = saturate(tn / ifc);
    const T tm2 = tm * tm;
    const T d = g * ti * (T(1) - T(SUBSTRATE_COAT_BEND) * (T(1) - ti)) + kCoatTrap<T> * saturate(c.diffuseAlbedo[i]) * (T(1) - tm2 * tm2);
    // The covered part alone gives back what the top traps (issue 19, step 22).
    const T p = std::max(tn * g * (tn * g), T(1e-30));
    r[i] = lerp(d, p, cover) / (d * lerp(T(1), p, cover));
  }
  return r;
}

// substrate_closure_coat_specular: (1 - R') / (1 - e T_m^2 (R' T_m^2 + (1 - R') (1 - g'))) per channel,
// with t = 1 - share, R' = t (P1 a^2 / (a^2 + P2 dV dL) + P3 a^2) (a = max(r^2 -
// TOP_SPREAD sat(coverageAbove) closureCoatTopAlpha(c), 1e-3), d = max(mu_i - mu_c, 0) along the view
// and along the light), g' = lerp(1, T_i coatTransmission(max(NoV, NoL), coatFloor), t), T_i =
// max(T_N, I) the interface's own (I = coatInterface), T_m = sat(T_N / I) and e the closure's hemispherical albedo,
// F_avg + A diffuseTransmission(A, F_avg, d_avg) (F_avg = F0 + (F90 - F0) / 21 per channel, d_avg the
// same of the dielectric part fd); times max(T_m, 1e-30)^x, x = ROUGH_PATH f^3 t (coatPathLength(NoV)
// (1 - NoV)^2 + coatPathLength(NoL) (1 - NoL)^2), f = sat(coatFloor): k, the covered part's; under a coverage
// C = sat(coverageAbove), lerp(1, P k, C) / lerp(1, P, C), P = max((T_N g)^2, 1e-30) (issue 19, step 22).
template <class T>
V3<T> closureCoatSpecular(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90, const V2<T>& fd, T share, T NoV,
                          T NoL, T roughness) {
  // No branch, as in the shader: at coverageAbove 0 (or share 1) the factor is exactly 1.
  const T cover = saturate(c.coverageAbove);
  const T t = T(1) - share;  // where the layers cover the closure
  const T r = saturate(roughness);
  const T a = std::max(r * r - T(SUBSTRATE_COAT_TOP_SPREAD) * cover * closureCoatTopAlpha(c), kMinAlpha<T>);
  const T a2 = a * a;
  auto inner = [](T mu) {
    const T inside = std::sqrt(T(1) - (T(1) - mu * mu) * T(SUBSTRATE_COAT_INV_ETA2));
    return std::max(inside - T(SUBSTRATE_COAT_CRITICAL_COS), T(0));
  };
  const T v = saturate(NoV);
  const T l = saturate(NoL);
  const T trapped = t * (T(SUBSTRATE_COAT_TIR_P1) * a2 / (a2 + T(SUBSTRATE_COAT_TIR_P2) * inner(v) * inner(l)) +
                         T(SUBSTRATE_COAT_TIR_P3) * a2);
  const T g = coatTransmission(std::max(v, l), c.coatFloor);
  const V3<T> albedo = saturate(c.diffuseAlbedo);
  const V3<T> fAvg = f0 + (f90 - f0) * T(1.0 / 21.0);
  const T dAvg = fd[0] + (fd[1] - fd[0]) * T(1.0 / 21.0);
  const V3<T> e = saturate(fAvg + albedo * diffuseTransmission(albedo, fAvg, dAvg));
  const T f = saturate(c.coatFloor);
  const T mv = T(1) - v, ml = T(1) - l;
  const T extra = T(SUBSTRATE_COAT_ROUGH_PATH) * (f * f * f) * t *
                  (coatPathLength(v) * (mv * mv) + coatPathLength(l) * (ml * ml));
  V3<T> k;
  for (int i = 0; i < 3; ++i) {
    const T tn = saturate(c.topTransmittance[i]);
    const T tm = saturate(tn / c.coatInterface);
    const T ti = std::max(tn, c.coatInterface);
    const T tm2 = tm * tm;
    const T back = tm2 * (trapped * tm2 + (T(1) - trapped) * (T(1) - lerp(T(1), ti * g, t)));
    k[i] = (T(1) - trapped) / (T(1) - e[i] * back);
    k[i] *= std::exp(std::log(std::max(tm, K<T>::minTransmittance)) * extra);
    // The covered part alone gets it (issue 19, step 22; closureCoatDiffuse).
    const T p = std::max(tn * g * (tn * g), T(1e-30));
    k[i] = lerp(T(1), p * k[i], cover) / lerp(T(1), p, cover);
  }
  return k;
}

// substrate_eval_closure.

// substrate_fuzz_diffuse_pair: (1 - q(NoV)) (1 - q(NoL)) / N, q = amount min(E_fuzz, 1),
// N = (1 - amount (albedo colour fuzzMeanAlbedo - deviation fuzzAlbedoDeviation))
// (1 + amount fuzzPairMargin(model, roughness)).
template <class T>
V3<T> fuzzDiffusePair(const Closure<T>& c, T amount, T eView, T eLight, const V3<T>& albedo, T deviation,
                      int diffuseModel) {
  const T crossings = (T(1) - amount * std::min(eView, T(1))) * (T(1) - amount * std::min(eLight, T(1)));
  const V3<T> bounce = albedo * saturate(c.fuzzColor) * fuzzMeanAlbedo(c.fuzzRoughness);
  const T covariance = deviation * fuzzAlbedoDeviation(c.fuzzRoughness);
  const T margin = T(1) + amount * T(fuzzPairMargin(diffuseModel, double(saturate(c.roughness))));
  V3<T> pair;
  for (int i = 0; i < 3; ++i) pair[i] = crossings / ((T(1) - amount * (bounce[i] - covariance)) * margin);
  return pair;
}

// substrate_fuzz_diffuse_pair_mean: (1 - amount fuzzMeanAlbedo) / (1 - amount albedo colour fuzzMeanAlbedo).
template <class T>
V3<T> fuzzDiffusePairMean(const Closure<T>& c, T amount, const V3<T>& albedo) {
  const T caught = amount * fuzzMeanAlbedo(c.fuzzRoughness);
  const V3<T> colour = saturate(c.fuzzColor);
  V3<T> mean;
  for (int i = 0; i < 3; ++i) mean[i] = (T(1) - caught) / (T(1) - albedo[i] * colour[i] * caught);
  return mean;
}

// long: it mirrors substrate_eval_closure statement for statement, so the two
// are compared side by side (the float instantiation must round as the shader).
template <class T>
V3<T> evalClosure(const Closure<T>& c, const V3<T>& V, const V3<T>& L, int diffuseModel) {
  if (c.features & kFeatureHair) return hairEval(c, V, L);  // a fibre: lit from every direction
  const V3<T> zero = splat3(T(0));
  V3<T> N = closureNormal(c);
  T NoVraw = dot(N, V);
  // Back-facing beyond SUBSTRATE_NOV_BIAS (or NaN): nothing; else NoV >= 1e-4.
  if (!(NoVraw > -kNoVBias<T>)) return zero;
  T NoV = clampT(NoVraw, K<T>::minCos, T(1));
  T NoL = clampT(dot(N, L), T(-1), T(1));

  bool isWrap = false;
  V3<T> wrap = zero;
  if (c.sssType == kSssWrap) {
    isWrap = true;
    wrap = sssWrapAmount(c.sssMfp);
  }
  bool lightFacing = NoL > T(0);
  // Wrap lighting reaches below the horizon, down to NoL = -max(w).
  if (!lightFacing && !(isWrap && NoL > -max3(wrap))) return zero;
  T NoLc = std::max(NoL, T(0));
  V3<T> H = safeNormalize(V + L, N);  // V = -L: H = N
  T NoH = saturate(dot(N, H));
  T VoH = saturate(dot(V, H));
  T VoL = clampT(dot(V, L), T(-1), T(1));

  V3<T> f0, f90;
  FresnelCurve<T> curve;
  closureFresnelEnds(c, f0, f90, curve);
  T roughness = saturate(c.roughness);

  T anisotropy = T(0);
  if (c.features & kFeatureAnisotropy) anisotropy = clampT(c.anisotropy, T(-1), T(1));

  // Energy terms (needed by the diffuse even when NoL <= 0; anisotropic lobes
  // widen them, substrate_specular_energy_aniso).
  const V2<T> fd = closureDielectricPart(c, f0, f90);
  const V3<T> f0w = closureCompensatedF0(c, f0, fd);
  V3<T> specAlbedo;
  T dielectric;
  const T msRate = closureDielectricMs(c);
  V3<T> w1 = specularEnergyAniso(f0, f90, curve, fd, f0w, msRate, NoV, roughness, anisotropy, specAlbedo, dielectric);
  T hazeWeight = T(0);
  T hazeRoughness = roughness;
  if (c.features & kFeatureHaze) {
    hazeWeight = saturate(c.secondRoughnessWeight);
    hazeRoughness = saturate(c.secondRoughness);
  }
  V3<T> w2 = w1;
  if (hazeWeight > T(0)) {
    V3<T> specAlbedo2;
    T dielectric2;
    w2 = specularEnergyAniso(f0, f90, curve, fd, f0w, msRate, NoV, hazeRoughness, anisotropy, specAlbedo2,
                             dielectric2);
    specAlbedo = lerp(specAlbedo, specAlbedo2, hazeWeight);
    dielectric = lerp(dielectric, dielectric2, hazeWeight);
  }

  V3<T> spec = zero;
  if (lightFacing) {
    bool needFrame = anisotropy != T(0);
    needFrame = needFrame || ((c.features & kFeatureGlint) != 0u && c.glintValue < T(1));
    T ToV = T(0), BoV = T(0), ToL = T(0), BoL = T(0), ToH = T(0), BoH = T(0);
    if (needFrame) {
      V3<T> Tn, Bn;
      closureFrame(c, N, Tn, Bn);
      ToV = dot(Tn, V);
      BoV = dot(Bn, V);
      ToL = dot(Tn, L);
      BoL = dot(Bn, L);
      ToH = dot(Tn, H);
      BoH = dot(Bn, H);
    }
    // GGX D and visibility at a roughness (anisotropic along the frame when anisotropy is not 0).
    auto ggxTerms = [&](T rough, T& d, T& vis) {
      const V2<T> alpha = ggxAlpha(rough, anisotropy);
      if (anisotropy != T(0)) {
        d = ggxDAniso(alpha, ToH, BoH, NoH);
        vis = ggxVisAniso(alpha, ToV, BoV, NoV, ToL, BoL, NoLc);
      } else {
        d = ggxD(alpha[0], NoH);
        vis = ggxVis(alpha[0], NoV, NoLc);
      }
    };
    T d1, vis1;
    ggxTerms(roughness, d1, vis1);
    V3<T> lobe = w1 * (d1 * vis1 * NoLc);
    if (hazeWeight > T(0)) {
      T d2, vis2;
      ggxTerms(hazeRoughness, d2, vis2);
      lobe = lerp(lobe, w2 * (d2 * vis2 * NoLc), hazeWeight);
    }
    // Under layers: what the layers' top sends back down instead of out (a conductor's lobe).
    spec = fresnel(f0, f90, curve, VoH) * lobe *
           closureCoatSpecular(c, f0, f90, fd, curve.share, NoV, NoLc, lerp(roughness, hazeRoughness, hazeWeight));
    if (c.features & kFeatureGlint) spec = spec * glintFactor(c, d1, ToH, BoH, NoH);
    // Specular profile: SUBSTRATE_SPECULAR_PROFILE_SAMPLE's default tint is 1.
  }
  // A wrap lobe's light crosses the layers above at its own cosine
  // (wrapLightCosine); the lobes on its interface at NoL.
  const V3<T> lightRatio = wrapLightRatio(c, isWrap, NoLc, NoL, L);
  spec = spec * lightRatio;

  // Diffuse, below the specular interface.
  V3<T> albedo = saturate(c.diffuseAlbedo);
  // The diffuse's interface: the dielectric part's (F0 and F90 at most fd's).
  const V3<T> f0d = vmin(f0, splat3(fd[0]));
  const V3<T> f90d = vmin(f90, splat3(fd[1]));
  // The light-side coupling for every lobe but the wrap (substrate_eval_closure).
  V3<T> diff = isWrap ? diffuseWrap(albedo, wrap, NoL) : diffuse(diffuseModel, albedo, roughness, NoV, NoLc, NoH, VoH, VoL);
  if (!isWrap && (c.features & kFeatureEye))  // the iris where the mask is: its own cosine (substrate_eye.h)
    diff = lerp(diff, albedo * (K<T>::invPi * eyeIrisCosine(c, N, L)), saturate(c.iris[0]));
  if (!isWrap) diff = diff * diffuseLightCoupling(f0d, f90d, NoLc, roughness, hazeRoughness, hazeWeight);
  // A slab's medium: its view and light dependence ("A slab's medium" in substrate_bsdf.h).
  if (c.sssType != kSssNone) {
    T p;
    const V3<T> s2 = closureMedium(c, albedo, roughness, p);
    const T m = T(SUBSTRATE_MEDIUM_MEAN_COS);
    diff = diff * mediumWeight(s2, m, p, NoV) * mediumWeight(s2, p + (T(1) - p) * m, p, NoLc);
  }
  // Under layers: what their underside sends back down.
  const V3<T> under = diff * diffuseTransmission(albedo, specAlbedo, dielectric) *
                      closureCoatDiffuse(c, f0d, f90d, diffuseModel);
  V3<T> result = spec + under;

  if (c.features & kFeatureFuzz) {
    T amount = saturate(c.fuzzAmount);
    // Under layers the fuzz sees the view and the light refracted into them (fuzzUnderLayers).
    T fv = NoV, fl = NoLc, fh = NoH, spread = T(1);
    fuzzUnderLayers(c, NoV, NoL, VoL, fv, fl, fh, spread);
    T eFuzz = fuzzAlbedo(fv, c.fuzzRoughness);
    // The lobe is normalized where the model's albedo exceeds 1; what it
    // reflects no longer reaches the layers below.
    // ... along the view and along the light alike (substrate_eval_closure):
    // the layers below are scaled by 1 - amount min(max(E_fuzz(NoV), E_fuzz(NoL)), 1).
    V3<T> fuzz = zero;
    T eCaught = eFuzz;
    // The diffuse: the pair of crossings (fuzzDiffusePair), lerped toward the
    // larger of the two by coverageAbove, and the larger of the two for the wrap lobe.
    V3<T> diffuseKept = V3<T>{1, 1, 1} * (T(1) - amount * std::min(eFuzz, T(1)));
    if (lightFacing) {
      fuzz = saturate(c.fuzzColor) *
             (amount * spread * charlieSheen(c.fuzzRoughness, fv, fl, fh) / std::max(T(1), eFuzz)) * lightRatio;
      const T eLight = fuzzAlbedo(fl, c.fuzzRoughness);
      eCaught = std::max(eFuzz, eLight);
      const T deviation =
          isWrap ? T(0) : diffuseLightCouplingDeviation(f0d, f90d, roughness, hazeRoughness, hazeWeight);
      diffuseKept = lerp(fuzzDiffusePair(c, amount, eFuzz, eLight, albedo, deviation, diffuseModel),
                         V3<T>{1, 1, 1} * (T(1) - amount * std::min(eCaught, T(1))),
                         isWrap ? T(1) : saturate(c.coverageAbove));
    }
    result = spec * (T(1) - amount * std::min(eCaught, T(1))) + under * diffuseKept + fuzz;
  }
  return result;
}

#define SUBSTRATEC_INSTANTIATE(T)                                                                      \
  template V3<T> closureNormal<T>(const Closure<T>&);                                                  \
  template V3<T> fuzzDiffusePairMean<T>(const Closure<T>&, T, const V3<T>&);                          \
  template void closureFresnelEnds<T>(const Closure<T>&, V3<T>&, V3<T>&, FresnelCurve<T>&);                         \
  template V3<T> f90Effective<T>(const V3<T>&, const V3<T>&);                                          \
  template V3<T> closureCoatDiffuse<T>(const Closure<T>&, const V3<T>&, const V3<T>&, int);            \
  template V3<T> closureCoatSpecular<T>(const Closure<T>&, const V3<T>&, const V3<T>&, const V2<T>&, T, T, T, T); \
  template V3<T> aboveThroughput<T>(const Closure<T>&, T, const V3<T>&);                               \
  template V3<T> layersCrossing<T>(const Closure<T>&, T, const V3<T>&);                                \
  template V3<T> coverGivenView<T>(T, const V3<T>&);                                                   \
  template T wrapLightCosine<T>(const Closure<T>&, T);                                                 \
  template T fuzzCosine<T>(const Closure<T>&, T);                                                      \
  template void closureFrame<T>(const Closure<T>&, const V3<T>&, V3<T>&, V3<T>&);                      \
  template V2<T> ggxAlpha<T>(T, T);                                                                    \
  template T ggxD<T>(T, T);                                                                            \
  template T ggxDAniso<T>(const V2<T>&, T, T, T);                                                      \
  template T ggxVis<T>(T, T, T);                                                                       \
  template T ggxVisAniso<T>(const V2<T>&, T, T, T, T, T, T);                                           \
  template T fresnelDelta<T>(T);                                                                       \
  template T fresnelWeight<T>(T);                                                                      \
  template T coatTransmission<T>(T, T);                                                                \
  template T coatFloor<T>(T);                                                                          \
  template T coatMeanShare<T>(T);                                                                      \
  template V2<T> coatStretch<T>(T, T);                                                                 \
  template T coatFloorProjected<T>(const V2<T>&, T);                                                   \
  template T coatAnisoShare<T>(const V2<T>&);                                                          \
  template T coatFloorAlong<T>(const Closure<T>&, T, const V3<T>&);                                    \
  template V3<T> coatMeanDirection<T>(const Closure<T>&, T);                                           \
  template T coatInterface<T>(const V3<T>&);                                                           \
  template void setCoatFloor<T>(std::vector<Closure<T>>&, T);                                         \
  template void setCoversLayers<T>(std::vector<Closure<T>>&);                                         \
  template void setCoatInterface<T>(std::vector<Closure<T>>&);                                        \
  template T fresnelB<T>(const V2<T>&, T, T, T);                                                       \
  template V3<T> fresnelBCurve<T>(const V2<T>&, T, T, const FresnelCurve<T>&);                          \
  template T fresnelShare<T>(T);                                                                       \
  template FresnelCurve<T> fresnelCurve<T>(const V3<T>&, T, T, T);                                         \
  template T fresnelPull<T>(T);                                                                        \
  template V3<T> fresnelAlbedo<T>(const V3<T>&, const V3<T>&, T, const V3<T>&);                       \
  template V3<T> fresnel<T>(const V3<T>&, const V3<T>&, const FresnelCurve<T>&, T);                    \
  template T closureDielectricMs<T>(const Closure<T>&);                                                 \
  template V3<T> specularEnergy<T>(const V3<T>&, const V3<T>&, const FresnelCurve<T>&, const V2<T>&,         \
                                   const V3<T>&, T, T, T, V3<T>&, T&);                                        \
  template V3<T> specularEnergyAniso<T>(const V3<T>&, const V3<T>&, const FresnelCurve<T>&, const V2<T>&,    \
                                        const V3<T>&, T, T, T, T, V3<T>&,                                     \
                                        T&);                                                            \
  template V3<T> diffuseTransmission<T>(const V3<T>&, const V3<T>&, T);                              \
  template T dielectricAlbedo<T>(const V2<T>&, T, T);                                                \
  template V2<T> closureDielectricPart<T>(const Closure<T>&, const V3<T>&, const V3<T>&);                \
  template V3<T> closureCompensatedF0<T>(const Closure<T>&, const V3<T>&, const V2<T>&);              \
  template V2<T> interfaceAlbedoFit<T>(T, T);                                                         \
  template V2<T> interfaceAlbedoMeans<T>(T);                                                          \
  template T diffuseLightCoupling<T>(const V3<T>&, const V3<T>&, T, T, T, T);                         \
  template T diffuseLightCouplingDeviation<T>(const V3<T>&, const V3<T>&, T, T, T);                   \
  template V3<T> diffuseLambert<T>(const V3<T>&, T);                                                   \
  template T eyeIrisCosine<T>(const Closure<T>&, const V3<T>&, const V3<T>&);                           \
  template V3<T> diffuseChan2018<T>(const V3<T>&, T, T, T, T, T);                                      \
  template V3<T> diffuseChan2024<T>(const V3<T>&, T, T, T, T, T);                                      \
  template T eonAlbedo<T>(T, T);                                                                       \
  template V3<T> diffuseEon<T>(const V3<T>&, T, T, T, T);                                              \
  template V3<T> diffuse<T>(int, const V3<T>&, T, T, T, T, T, T);                                      \
  template V3<T> sssWrapAmount<T>(const V3<T>&);                                                       \
  template V3<T> diffuseWrap<T>(const V3<T>&, const V3<T>&, T);                                        \
  template T mixShare<T>(T);                                                                           \
  template T mediumF0<T>(const Closure<T>&);                                                            \
  template V2<T> mediumInterface<T>(T, T);                                                             \
  template T mediumShare<T>(const Closure<T>&);                                                         \
  template V3<T> mediumSlope2<T>(const V3<T>&, T, T, T);                                               \
  template V3<T> mediumWeight<T>(const V3<T>&, T, T, T);                                               \
  template V3<T> closureMedium<T>(const Closure<T>&, const V3<T>&, T, T&);                             \
  template T charlieD<T>(T, T);                                                                        \
  template T charlieL<T>(T, T);                                                                        \
  template T charlieLambda<T>(T, T);                                                                   \
  template T charlieSheen<T>(T, T, T, T);                                                              \
  template T glintLevelSample<T>(const V2<T>&, T, const std::array<int, 2>&, T);                       \
  template T glintFactor<T>(const Closure<T>&, T, T, T, T);                                            \
  template V3<T> evalClosure<T>(const Closure<T>&, const V3<T>&, const V3<T>&, int);
SUBSTRATEC_INSTANTIATE(float)
SUBSTRATEC_INSTANTIATE(double)
#undef SUBSTRATEC_INSTANTIATE

}  // namespace substratec::reference
