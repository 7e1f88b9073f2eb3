// Mirrors runtime_shaders/substrate_lighting.h: the throughput of the layers
// above along the view and the light, one closure lit by one light
// (substrate_light_closure), the split-sum environment (substrate_env_roughness,
// substrate_reflection_dir, substrate_env_mip, substrate_env_split_sum) and
// translucency (substrate_translucency). As in bsdf.cc every SUBSTRATE_USE_*
// switch is on: the closure's feature bits gate each optional part.
#include <cmath>

#include "reference/bsdf.h"
#include "reference/common.h"
#include "reference/hair.h"
#include "reference/energy_lut.h"
#include "substrate_constants.h"  // runtime_shaders/
#include "reference/reference.h"

namespace substratec::reference {
using namespace detail;

namespace {

// runtime_shaders/substrate_constants.h
template <class T> constexpr T kDiffuseMeanCos = T(SUBSTRATE_DIFFUSE_MEAN_COS);
template <class T> constexpr T kNoVBias = T(SUBSTRATE_NOV_BIAS);


// substrate_env_roughness: r lerped toward the haze roughness by its weight.
template <class T>
T envRoughness(const Closure<T>& c) {
  T r = saturate(c.roughness);
  if (c.features & kFeatureHaze) r = lerp(r, saturate(c.secondRoughness), saturate(c.secondRoughnessWeight));
  return r;
}

// E_spec at NoV (haze lerped in when its weight is > 0), as the split sum and
// translucency compute it (both test c.secondRoughnessWeight > 0, unsaturated),
// and the dielectric part's in `dielectric` (substrate_closure_specular_albedo_of).
template <class T>
V3<T> specularAlbedo(const Closure<T>& c, T NoV, T& dielectric) {
  V3<T> f0, f90;
  FresnelCurve<T> curve;
  closureFresnelEnds(c, f0, f90, curve);
  const V2<T> fd = closureDielectricPart(c, f0, f90);
  const V3<T> f0w = closureCompensatedF0(c, f0, fd);
  V3<T> specAlbedo;
  const T msRate = closureDielectricMs(c);
  specularEnergy(f0, f90, curve, fd, f0w, msRate, NoV, saturate(c.roughness), specAlbedo, dielectric);
  if ((c.features & kFeatureHaze) && c.secondRoughnessWeight > T(0)) {
    V3<T> specAlbedo2;
    T dielectric2;
    specularEnergy(f0, f90, curve, fd, f0w, msRate, NoV, saturate(c.secondRoughness), specAlbedo2, dielectric2);
    specAlbedo = lerp(specAlbedo, specAlbedo2, saturate(c.secondRoughnessWeight));
    dielectric = lerp(dielectric, dielectric2, saturate(c.secondRoughnessWeight));
  }
  return specAlbedo;
}

}  // namespace

template <class T>
V3<T> viewThroughput(const Closure<T>& c, T NoV, const V3<T>& V) {
  return aboveThroughput(c, NoV, V) * std::max(c.weight, T(0));  // max(weight, 0) * above
}

// substrate_closure_light_throughput: lerp(1, lightCrossing, coverGivenView(C,
// viewCrossing)), the layers met only where the view met them; the weight
// counts once, on the view side; 1 on top.
template <class T>
V3<T> lightThroughput(const Closure<T>& c, const V3<T>& viewCrossing, const V3<T>& lightCrossing) {
  const T cover = saturate(c.coverageAbove);
  if (!(cover > T(0))) return splat3(T(1));
  return splat3(T(1)) + (lightCrossing - splat3(T(1))) * coverGivenView(cover, viewCrossing);
}

// substrate_light_closure: max(weight, 0) lerp(1, t_V t_L, C) f radiance (a
// path meets the layers above on both sides or on neither).
template <class T>
V3<T> lightClosure(const Closure<T>& c, const V3<T>& V, const V3<T>& L, const V3<T>& radiance, int diffuseModel) {
  V3<T> N = closureNormal(c);
  V3<T> f = evalClosure(c, V, L, diffuseModel);
  V3<T> throughput = splat3(std::max(c.weight, T(0)));
  const T cover = saturate(c.coverageAbove);
  if (cover > T(0)) {
    const V3<T> pair = layersCrossing(c, dot(N, V), V) * layersCrossing(c, wrapLightCosine(c, dot(N, L)), L);
    throughput = throughput * lerp(splat3(T(1)), pair, cover);
  }
  return throughput * f * radiance;
}

// substrate_reflection_dir: the dominant direction lerp(N, R, (1 - a)(sqrt(1 - a) + a)),
// a = r^2 of the env roughness; anisotropic closures first bend N toward V in the
// plane orthogonal to B (A > 0) or T (A < 0) by |A| sat(5 r).
template <class T>
V3<T> reflectionDir(const Closure<T>& c, const V3<T>& V) {
  V3<T> N = closureNormal(c);
  T r = envRoughness(c);
  if ((c.features & kFeatureAnisotropy) && c.anisotropy != T(0)) {
    V3<T> Tn, Bn;
    closureFrame(c, N, Tn, Bn);
    T A = clampT(c.anisotropy, T(-1), T(1));
    V3<T> axis = A < T(0) ? Tn : Bn;
    V3<T> side = cross(axis, V);
    V3<T> bentN = safeNormalize(cross(side, axis), N);
    N = safeNormalize(lerp(N, bentN, std::fabs(A) * saturate(T(5) * r)), N);
  }
  T NoV = dot(N, V);
  V3<T> R = (T(2) * NoV) * N - V;
  T a = r * r;
  T k = (T(1) - a) * (std::sqrt(T(1) - a) + a);
  return safeNormalize(lerp(N, R, k), N);
}

template <class T>
T envMip(T roughness, T mipCount) {
  return saturate(roughness) * std::max(mipCount - T(1), T(0));
}

// substrate_env_split_sum: specular E_spec * prefiltered through the layers above
// at NoV; diffuse albedo T irradiance / pi (T: diffuseTransmission) and fuzz through them at
// SUBSTRATE_DIFFUSE_MEAN_COS (every diffuse model, wrap included, uses albedo as
// its hemispherical albedo); under a fuzz on top the diffuse also by the mean of
// the direct light's pair of crossings (fuzzDiffusePairMean). The view-side
// throughput is the caller's.
template <class T>
V3<T> envSplitSum(const Closure<T>& c, const V3<T>& V, const V3<T>& prefilteredRadiance, const V3<T>& irradiance,
                  int diffuseModel /* the diffuse is albedo for every model; its coat factor is the model's */) {
  if (c.features & kFeatureHair) return hairEnv(c, V, irradiance);  // a fibre's albedo times the mean radiance
  V3<T> N = closureNormal(c);
  T NoVraw = dot(N, V);
  if (!(NoVraw > -kNoVBias<T>)) return splat3(T(0));
  T NoV = clampT(NoVraw, K<T>::minCos, T(1));
  V3<T> f0, f90;
  FresnelCurve<T> curve;
  closureFresnelEnds(c, f0, f90, curve);
  T dielectric;
  V3<T> specAlbedo = specularAlbedo(c, NoV, dielectric);
  const V2<T> fd = closureDielectricPart(c, f0, f90);
  // Under layers: what their top sends back down instead of out (substrate_closure_coat_specular;
  // the light comes from the mirror direction, at NoV).
  V3<T> spec = specAlbedo * closureCoatSpecular(c, f0, f90, fd, curve.share, NoV, NoV, envRoughness(c)) *
               vmax(prefilteredRadiance, splat3(T(0)));
  // Specular profile: the default tint is 1.
  V3<T> irr = vmax(irradiance, splat3(T(0))) * K<T>::invPi;
  const V3<T> albedo = saturate(c.diffuseAlbedo);
  const V3<T> f0d = vmin(f0, splat3(fd[0]));
  const V3<T> f90d = vmin(f90, splat3(fd[1]));
  V3<T> diff = albedo * diffuseTransmission(albedo, specAlbedo, dielectric) *
               closureCoatDiffuse(c, f0d, f90d, diffuseModel) * irr;
  // A slab's medium: its view dependence (substrate_env_split_sum).
  if (c.sssType != kSssNone) {
    T p;
    const V3<T> s2 = closureMedium(c, albedo, saturate(c.roughness), p);
    diff = diff * mediumWeight(s2, T(SUBSTRATE_MEDIUM_MEAN_COS), p, NoV);
  }
  // The light meets the layers only where the view met them; the mirror
  // direction's azimuth is the view's; the diffuse's light has no one
  // direction: the azimuths' mean (coatMeanDirection).
  const V3<T> viewCrossing = layersCrossing(c, NoV, V);
  V3<T> specLight = lightThroughput(c, viewCrossing, viewCrossing);
  V3<T> diffuseLight =
      lightThroughput(c, viewCrossing, layersCrossing(c, kDiffuseMeanCos<T>, coatMeanDirection(c, kDiffuseMeanCos<T>)));
  V3<T> result = spec * specLight + diff * diffuseLight;
  if (c.features & kFeatureFuzz) {
    T amount = saturate(c.fuzzAmount);
    T eFuzz = std::min(fuzzAlbedo(fuzzCosine(c, NoV), c.fuzzRoughness), T(1));
    // The diffuse on top: the pair's mean (not under layers, nor for the wrap lobe).
    const V3<T> pairMean = lerp(fuzzDiffusePairMean(c, amount, albedo), splat3(T(1)),
                                c.sssType == kSssWrap ? T(1) : saturate(c.coverageAbove));
    result = (spec * specLight + diff * diffuseLight * pairMean) * (T(1) - amount * eFuzz) +
             saturate(c.fuzzColor) * (amount * eFuzz) * irr * diffuseLight;
  }
  return result;
}

// substrate_translucency: coverage sat(weight); transmittance = the layers above
// at mu = clamp(NoV, 1e-4, 1), times (1 - E_spec(mu)), times (1 - fuzz min(E_fuzz, 1)).
template <class T>
void translucency(const Closure<T>& c, T NoV, const V3<T>& V, T& coverage, V3<T>& transmittanceOut) {
  coverage = saturate(c.weight);
  if (c.features & kFeatureHair) {  // a fibre covers what it covers
    transmittanceOut = splat3(T(0));
    return;
  }
  T mu = clampT(NoV, K<T>::minCos, T(1));
  T dielectric;
  V3<T> specAlbedo = specularAlbedo(c, mu, dielectric);
  transmittanceOut = aboveThroughput(c, mu, V) * (splat3(T(1)) - specAlbedo);
  if (c.features & kFeatureFuzz)
    transmittanceOut = transmittanceOut * (T(1) - saturate(c.fuzzAmount) * std::min(fuzzAlbedo(fuzzCosine(c, mu), c.fuzzRoughness), T(1)));
}

namespace {
template <class T>
V3<T> clampPositive3(const V3<T>& x, T hi) {  // substrate_water_clamp3
  V3<T> r;
  for (int i = 0; i < 3; ++i) r[i] = x[i] > T(0) ? std::min(x[i], hi) : T(0);
  return r;
}
template <class T>
T hgPhaseT(T cosTheta, T g) {  // substrate_fog_hg_phase
  const T k = g > T(-0.99) ? std::min(g, T(0.99)) : (g <= T(-0.99) ? T(-0.99) : T(0));
  const T c = cosTheta > T(-1) ? std::min(cosTheta, T(1)) : (cosTheta <= T(-1) ? T(-1) : T(1));
  const T d = std::max(T(1) + k * k - T(2) * k * c, T(1e-6));
  return (T(1) - k * k) / (T(4) * K<T>::pi * d * std::sqrt(d));
}
}  // namespace

// substrate_water_body.
template <class T>
V3<T> waterBody(const Water<T>& w, const V3<T>& background, T distance, T cosPhase, const V3<T>& light) {
  const T d = distance > T(0) ? std::min(distance, K<T>::fltMax) : T(0);
  const V3<T> sigma = clampPositive3(w.extinction, K<T>::fltMax);
  V3<T> t;
  for (int i = 0; i < 3; ++i) t[i] = std::exp(-std::min(sigma[i] * d, T(88)));
  const V3<T> behind = clampPositive3(background, K<T>::fltMax) * clampPositive3(w.scaleBehind, T(65504));
  const T phase = hgPhaseT(cosPhase, w.phaseG);
  return clampPositive3(behind * t + saturate(w.albedo) * (splat3(T(1)) - t) * clampPositive3(light, K<T>::fltMax) * phase,
                        K<T>::fltMax);
}

// substrate_water_seen: the uncovered share times the interface's 1 - E along the
// view, of the body lit through it (1 - E along the light).
template <class T>
V3<T> waterSeen(const Closure<T>& c, const Water<T>& w, const V4<T>& behind, T surfaceDistance, const V3<T>& V,
                const V3<T>& L, const V3<T>& lightRadiance) {
  const V3<T> N = closureNormal(c);
  const T NoVraw = dot(N, V);
  if (!(NoVraw > -kNoVBias<T>)) return splat3(T(0));  // seen from below the surface: not this model's
  Closure<T> s = c;  // the bare water interface
  s.f0 = splat3(saturate(w.f0));
  s.f90 = splat3(T(1));
  s.features = 0;
  const T NoV = clampT(NoVraw, K<T>::minCos, T(1));
  const T NoL = dot(N, L);
  T dielectric;
  const V3<T> through = splat3(T(1)) - specularAlbedo(s, NoV, dielectric);
  const V3<T> lightIn = NoL > T(0) ? lightRadiance * (splat3(T(1)) - specularAlbedo(s, NoL, dielectric)) : splat3(T(0));
  const V3<T> body = waterBody(w, V3<T>{behind[0], behind[1], behind[2]}, behind[3] - surfaceDistance,
                               dot(L * T(-1), V), lightIn);
  return through * body * (T(1) - saturate(w.opacity));
}

#define SUBSTRATEC_INSTANTIATE(T)                                                                         \
  template V3<T> viewThroughput<T>(const Closure<T>&, T, const V3<T>&);                                                 \
  template V3<T> lightThroughput<T>(const Closure<T>&, const V3<T>&, const V3<T>&);                       \
  template V3<T> lightClosure<T>(const Closure<T>&, const V3<T>&, const V3<T>&, const V3<T>&, int);       \
  template V3<T> reflectionDir<T>(const Closure<T>&, const V3<T>&);                                       \
  template T envMip<T>(T, T);                                                                             \
  template V3<T> envSplitSum<T>(const Closure<T>&, const V3<T>&, const V3<T>&, const V3<T>&, int);        \
  template void translucency<T>(const Closure<T>&, T, const V3<T>&, T&, V3<T>&);                         \
  template V3<T> waterBody<T>(const Water<T>&, const V3<T>&, T, T, const V3<T>&);                         \
  template V3<T> waterSeen<T>(const Closure<T>&, const Water<T>&, const V4<T>&, T, const V3<T>&, const V3<T>&, \
                              const V3<T>&);
SUBSTRATEC_INSTANTIATE(float)
SUBSTRATEC_INSTANTIATE(double)
#undef SUBSTRATEC_INSTANTIATE

}  // namespace substratec::reference
