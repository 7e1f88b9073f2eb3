// The lobes of runtime_shaders/substrate_bsdf.h, one function per shader
// function (same names in camelCase), for evalClosure (reference.h), the
// lighting and the tests. Templated on the scalar type (float and double).
#pragma once
#include <cstdint>

#include "reference/reference.h"

namespace substratec::reference {

// Frames.
template <class T> V3<T> closureNormal(const Closure<T>& c);                                 // substrate_closure_normal
template <class T> void closureFrame(const Closure<T>& c, const V3<T>& N, V3<T>& Tn, V3<T>& Bn);  // substrate_closure_frame

/// SubstrateFresnelCurve: the share of the dielectric curve (fresnelShare), per channel the
/// coefficients of w(t) = t + (1 - t) s (a + b s), s = sqrt(t), and the least pull of the
/// dielectric curve's albedo bound (fresnelBCurve; 0 for chi).
template <class T>
struct FresnelCurve {
  T share;
  V3<T> a, b;
  T pull;
};

// Closures under layers (the layers above read as a dielectric of F0 0.04).
/// substrate_closure_fresnel_ends: F0 and F90 (white without the F90 feature),
/// relative to the layers above by coverageAbove, and the curve between them (fresnelCurve).
template <class T> void closureFresnelEnds(const Closure<T>& c, V3<T>& f0, V3<T>& f90, FresnelCurve<T>& curve);
/// substrate_closure_coat_diffuse: lerp(D, P, C) / (D lerp(1, P, C)), P = (T_N G)^2, C = coverageAbove: what the diffuse gets back (1 / D under a full coverage).
template <class T> V3<T> closureCoatDiffuse(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90, int diffuseModel);
/// substrate_closure_coat_specular: what a conductor's lobe under layers keeps, given back what their top
/// sends down (the trapped share R) and the closure reflects again (its hemispherical albedo).
template <class T>
V3<T> closureCoatSpecular(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90, const V2<T>& fd, T share, T NoV,
                          T NoL, T roughness);
/// substrate_closure_above_throughput: what the layers above let through along a direction at cosine mu
/// (their media along the refracted path, their interfaces), blended by coverageAbove; 1 on top.
/// w: the unit direction (its azimuth about a stretched top: coatFloorAlong; coatMeanDirection for none).
template <class T> V3<T> aboveThroughput(const Closure<T>& c, T mu, const V3<T>& w);
/// substrate_closure_layers_crossing: the same where the layers cover the closure, unblended (1 on top).
template <class T> V3<T> layersCrossing(const Closure<T>& c, T mu, const V3<T>& w);
/// substrate_cover_given_view: the coverage the light meets given the view's crossing, C t_V / ((1 - C) + C t_V).
template <class T> V3<T> coverGivenView(T cover, const V3<T>& viewCrossing);
/// substrate_wrap_light_cosine: the cosine a wrap lobe's light crosses the layers above at.
template <class T> T wrapLightCosine(const Closure<T>& c, T NoL);
/// substrate_fuzz_cosine: the cosine a fuzz under layers sees (refracted into them); mu on top.
template <class T> T fuzzCosine(const Closure<T>& c, T mu);
/// substrate_closure_dielectric_part: the Fresnel ends (F0, F90) of the interface the diffuse lies under.
template <class T> V2<T> closureDielectricPart(const Closure<T>& c, const V3<T>& f0, const V3<T>& f90);
/// substrate_closure_compensated_f0: the F0 that Turquin's W reads (a metalness mix's parts' mean).
template <class T> V3<T> closureCompensatedF0(const Closure<T>& c, const V3<T>& f0, const V2<T>& fd);

// GGX.
template <class T> V2<T> ggxAlpha(T roughness, T anisotropy);                               // substrate_ggx_alpha
template <class T> T ggxD(T a, T NoH);                                                      // substrate_ggx_d
template <class T> T ggxDAniso(const V2<T>& alpha, T ToH, T BoH, T NoH);                    // substrate_ggx_d_aniso
template <class T> T ggxVis(T a, T NoV, T NoL);                                             // substrate_ggx_vis
template <class T> T ggxVisAniso(const V2<T>& alpha, T ToV, T BoV, T NoV, T ToL, T BoL, T NoL);
template <class T> T fresnelDelta(T t);                                                    // substrate_fresnel_delta
template <class T> T fresnelWeight(T c);                                                    // substrate_fresnel_weight
template <class T> T coatTransmission(T mu, T coatFloor);                                   // substrate_coat_transmission
template <class T> T coatFloor(T topRoughness);                                             // substrate_coat_floor
template <class T> T coatMeanShare(T coatFloor);                                            // substrate_coat_mean_share
template <class T> V2<T> coatStretch(T roughness, T anisotropy);                            // substrate_coat_stretch
template <class T> T coatFloorProjected(const V2<T>& stretch, T c2);                        // substrate_coat_floor_projected
template <class T> T coatAnisoShare(const V2<T>& stretch);                                  // substrate_coat_aniso_share
template <class T> T coatFloorAlong(const Closure<T>& c, T mu, const V3<T>& w);             // substrate_coat_floor_along
template <class T> V3<T> coatMeanDirection(const Closure<T>& c, T mu);                      // substrate_coat_mean_direction
template <class T> T coatInterface(const V3<T>& topF0);                                     // substrate_coat_interface
template <class T> T fresnelB(const V2<T>& dfg, T e, T pull, T share);                     // substrate_fresnel_b (w)
template <class T>
V3<T> fresnelBCurve(const V2<T>& dfg, T e, T pull, const FresnelCurve<T>& k);                // substrate_fresnel_b (xyz)
template <class T> T fresnelShare(T f0max);                                                // substrate_fresnel_share
template <class T> FresnelCurve<T> fresnelCurve(const V3<T>& f0, T share, T conductor, T lowIor);  // substrate_fresnel_curve
template <class T> V3<T> f90Effective(const V3<T>& f0, const V3<T>& f90);                   // substrate_f90_effective
template <class T> T fresnelPull(T roughness);                                              // substrate_fresnel_pull
template <class T>
V3<T> fresnelAlbedo(const V3<T>& f0, const V3<T>& f90, T e, const V3<T>& b);             // substrate_fresnel_albedo
template <class T>
V3<T> fresnel(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& k, T VoH);          // substrate_fresnel
/// substrate_closure_dielectric_ms: SUBSTRATE_DIELECTRIC_MS, 0 for a top over layers (coversLayers).
template <class T> T closureDielectricMs(const Closure<T>& c);
/// substrate_specular_energy: returns W = (1 + F0w (1 - E) / E)(1 + curve.share msRate r); E_spec in
/// `albedo`, and in `dielectric` the albedo of the closure's dielectric part (ends fd,
/// closureDielectricPart), times 1 + msRate r.
template <class T>
V3<T> specularEnergy(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& curve, const V2<T>& fd,
                     const V3<T>& f0w, T msRate, T NoV,
                     T roughness, V3<T>& albedo, T& dielectric);
/// substrate_specular_energy_aniso: the same with an anisotropic lobe's widened terms.
template <class T>
V3<T> specularEnergyAniso(const V3<T>& f0, const V3<T>& f90, const FresnelCurve<T>& curve, const V2<T>& fd,
                          const V3<T>& f0w, T msRate,
                          T NoV, T roughness, T anisotropy, V3<T>& albedo, T& dielectric);
/// substrate_dielectric_albedo: the compensated albedo of a grey interface of ends d.
template <class T> T dielectricAlbedo(const V2<T>& d, T e, T b);
/// substrate_diffuse_transmission: what the interface lets through to the diffuse along the view,
/// 1 - E_spec, or 1 - E_d of the dielectric part where that is larger, within the energy 1 - E_spec.
template <class T> V3<T> diffuseTransmission(const V3<T>& albedo, const V3<T>& specAlbedo, T dielectric);
/// substrate_interface_albedo_fit: Karis' (A, B), E~ = F0 A + F90 B.
template <class T> V2<T> interfaceAlbedoFit(T mu, T roughness);
/// substrate_interface_albedo_means: (X, Y), the fit's hemispherical means (lower bounds).
template <class T> V2<T> interfaceAlbedoMeans(T roughness);
/// substrate_diffuse_light_coupling: (1 - E~(NoL)) / max(1 - Ē~, 1e-3), haze-blended,
/// one scalar from the channels' mean F0 and F90 (the shader takes those means,
/// substrate_diffuse_interface; the same arithmetic).
template <class T>
T diffuseLightCoupling(const V3<T>& f0, const V3<T>& f90, T NoL, T roughness, T hazeRoughness, T hazeWeight);
/// substrate_diffuse_light_coupling_deviation: an upper bound of the coupling's standard
/// deviation over the cosine-weighted hemisphere of light.
template <class T>
T diffuseLightCouplingDeviation(const V3<T>& f0, const V3<T>& f90, T roughness, T hazeRoughness, T hazeWeight);
/// substrate_fuzz_diffuse_pair_mean: the mean over a uniform hemisphere of light of the
/// diffuse's pair of fuzz crossings, as a share of the view's crossing (the split sum's).
template <class T>
V3<T> fuzzDiffusePairMean(const Closure<T>& c, T amount, const V3<T>& albedo);
/// substrate_fuzz_pair_margin: what the diffuse model adds to the mean of the fuzz pair's
/// light term at the slab's roughness (SUBSTRATE_FUZZ_PAIR_MARGIN_*; 0 for Lambert).
double fuzzPairMargin(int diffuseModel, double roughness);

// Diffuse models (BRDF * NoL).
template <class T> V3<T> diffuseLambert(const V3<T>& albedo, T NoL);
/// substrate_eye_iris_cosine: what multiplies albedo / pi for an eye's iris in
/// place of the diffuse's cosine (the cornea's normal N, toward the light L).
template <class T> T eyeIrisCosine(const Closure<T>& c, const V3<T>& N, const V3<T>& L);
template <class T> V3<T> diffuseChan2018(const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH);
template <class T> V3<T> diffuseChan2024(const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH);
template <class T> T eonAlbedo(T mu, T r);
template <class T> V3<T> diffuseEon(const V3<T>& albedo, T roughness, T NoV, T NoL, T VoL);
/// substrate_diffuse with SUBSTRATE_DIFFUSE_MODEL = model (anything else than 1..3: Lambert).
template <class T> V3<T> diffuse(int model, const V3<T>& albedo, T roughness, T NoV, T NoL, T NoH, T VoH, T VoL);

// SSS wrap.
template <class T> V3<T> sssWrapAmount(const V3<T>& mfp);
template <class T> V3<T> diffuseWrap(const V3<T>& albedo, const V3<T>& wrap, T NoL);

// A slab's medium seen through its interface (substrate_medium_* and substrate_closure_medium).
template <class T> T mixShare(T f0max);  // substrate_mix_share
template <class T> T mediumF0(const Closure<T>& c);
template <class T> V2<T> mediumInterface(T f0, T roughness);
template <class T> T mediumShare(const Closure<T>& c);
template <class T> V3<T> mediumSlope2(const V3<T>& albedo, T share, T f0, T ie2);
template <class T> V3<T> mediumWeight(const V3<T>& s2, T m, T p, T mu);
template <class T> V3<T> closureMedium(const Closure<T>& c, const V3<T>& albedo, T roughness, T& p);

// Fuzz (Charlie sheen).
template <class T> T charlieD(T a, T NoH);
template <class T> T charlieL(T x, T a);
template <class T> T charlieLambda(T mu, T a);
template <class T> T charlieSheen(T fuzzRoughness, T NoV, T NoL, T NoH);

// Glints.
template <class T> T glintLevelSample(const V2<T>& uv, T level, const std::array<int, 2>& slopeBin, T expected);
template <class T> T glintFactor(const Closure<T>& c, T d, T ToH, T BoH, T NoH);

}  // namespace substratec::reference
