// The CPU reference of the shading model: a second, independent implementation
// of what the generated material function (compiler/core/emit/material_emitter.cc,
// docs/codegen.md) and the runtime library (runtime_shaders/) compute, templated
// on the scalar type. It is the oracle of the GPU tests: ref64 (double) is the
// value, and |ref32 - ref64| (float) measures how well conditioned a sample is.
//
// Written from the documented model and the IR, not from the emitter's output;
// where the shaders make a specific choice (a clamp, an epsilon, a guard, a
// fit) the reference mirrors it and cites the shader in a comment.
//
// Precision: the value DAG (inputs, textures, math and helper nodes) is always
// evaluated in double (compiler/core/ir/value_eval.h); for T = float its results are
// rounded to float before the tree walk. Everything after the value DAG (slab
// coverage and transmittance, the tree operators, the walk to the root, the
// tangent frames, the BSDF, the energy tables and the lighting) runs in T.
//
// Files: tree_walk.cc (evaluateMaterial), bsdf.cc (evalClosure and its lobes,
// bsdf.h), energy_lut.cc (the table lookups, energy_lut.h), lighting.cc
// (throughputs, split sum, translucency), integrate.cc (envIntegrated),
// common.h (substrate_common.h's primitives and small vector algebra).
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "pipeline/pipeline.h"
#include "substrate_constants.h"  // runtime_shaders/

namespace substratec::reference {

template <class T> using V2 = std::array<T, 2>;
template <class T> using V3 = std::array<T, 3>;
template <class T> using V4 = std::array<T, 4>;

// Closure feature bits: SUBSTRATE_FEATURE_* (runtime_shaders/substrate_constants.h).
inline constexpr std::uint32_t kFeatureF90 = SUBSTRATE_FEATURE_F90, kFeatureAnisotropy = SUBSTRATE_FEATURE_ANISOTROPY,
                               kFeatureHaze = SUBSTRATE_FEATURE_HAZE, kFeatureFuzz = SUBSTRATE_FEATURE_FUZZ,
                               kFeatureGlint = SUBSTRATE_FEATURE_GLINT,
                               kFeatureSpecularProfile = SUBSTRATE_FEATURE_SPECULAR_PROFILE,
                               kFeatureWeight = SUBSTRATE_FEATURE_WEIGHT,
                               kFeatureCoverageAbove = SUBSTRATE_FEATURE_COVERAGE_ABOVE,
                               kFeatureHair = SUBSTRATE_FEATURE_HAIR, kFeatureEye = SUBSTRATE_FEATURE_EYE;
// sssType values (SUBSTRATE_SSS_*).
inline constexpr std::uint32_t kSssNone = 0, kSssWrap = 1, kSssDiffusion = 2, kSssSimpleVolume = 3;
// Diffuse models (SUBSTRATE_DIFFUSE_MODEL).
inline constexpr int kDiffuseLambert = diffuseModelNumber(DiffuseModel::Lambert),
                     kDiffuseChan2018 = diffuseModelNumber(DiffuseModel::Chan2018),
                     kDiffuseChan2024 = diffuseModelNumber(DiffuseModel::Chan2024),
                     kDiffuseEon = diffuseModelNumber(DiffuseModel::Eon);

/// SubstrateClosure (substrate_closure.h): the same fields, names and neutral
/// values (substrate_closure_init); the tangent is `T_`.
template <class T>
struct Closure {
  V3<T> diffuseAlbedo{T(0.18), T(0.18), T(0.18)};
  V3<T> f0{T(0.04), T(0.04), T(0.04)};
  V3<T> f90{T(1), T(1), T(1)};
  T roughness = T(0.5);
  T anisotropy = T(0);
  V3<T> N{T(0), T(0), T(1)};
  V3<T> T_{T(1), T(0), T(0)};
  V3<T> sssMfp{T(0), T(0), T(0)};
  T sssPhaseAnisotropy = T(0);
  std::uint32_t sssType = kSssNone;
  T secondRoughness = T(0.5);
  T secondRoughnessWeight = T(0);
  T fuzzAmount = T(0);
  V3<T> fuzzColor{T(0), T(0), T(0)};
  T fuzzRoughness = T(0.5);
  T glintValue = T(1);
  V2<T> glintUv{T(0), T(0)};
  V4<T> glintUvDerivatives{T(0), T(0), T(0), T(0)};
  std::uint32_t specularProfile = 0;
  V4<T> hair{T(0.5), T(1.55), T(2), T(0)};  // a hair's azimuthal roughness, ior, cuticle angle (deg), scatter
  V3<T> irisN{T(0), T(0), T(1)};            // an eye's iris normal,
  V3<T> irisPlaneN{T(0), T(0), T(1)};       // its iris plane's normal,
  V2<T> iris{T(0), T(0)};                   // and its iris mask and iris distance
  V3<T> emissive{T(0), T(0), T(0)};
  T weight = T(1);
  V3<T> topTransmittance{T(1), T(1), T(1)};
  T coverageAbove = T(0);
  std::uint32_t extraInterfaces = 0;  // interfaces above beyond the first, 0..3
  T coatFloor = T(0);  // what the layers' top lets through at grazing angles: coatFloor(topRoughness)
  T coatInterface = T(SUBSTRATE_COAT_T_0);  // the layers' top's 1 - F0 head-on: setCoatInterface
  V2<T> coatStretch{T(0), T(0)};        // the one stretched top's (ay^2, ax^2 - ay^2) (0: none): setCoatFloor
  V3<T> coatTangent{T(1), T(0), T(0)};  // its tangent
  T coatShare = T(0);  // coatMeanShare of the floor (coatAnisoShare under a stretched top): setCoatFloor
  std::uint32_t features = 0;
  bool isTop = true;
  bool coversLayers = false;  // on top of a pixel where some closure lies under layers: setCoversLayers
  /// SUBSTRATE_USE_METALNESS_MIX of the shader that lights it (Material::metalnessMix;
  /// the deferred scene lighting always has it): false reads the diffuse under the whole
  /// interface (closureDielectricPart (1, 1)).
  bool metalnessMix = true;
  /// SUBSTRATE_USE_CONDUCTOR_CURVE of the shader that lights it (usesConductorCurve; the
  /// runtime's default, and the deferred scene lighting's, is 1): false keeps every
  /// channel on chi or Schlick's curve (closureFresnelEnds).
  bool conductorCurve = true;
  /// SUBSTRATE_USE_LOW_IOR_CURVE of the shader that lights it (usesLowIorCurve; the runtime's
  /// default is 1): false keeps every dielectric on chi (closureFresnelEnds).
  bool lowIorCurve = true;
};

/// One shading point, as SubstrateGeometry (world space; converted to T inside).
struct Geometry {
  std::array<double, 3> N{0, 0, 1}, T{1, 0, 0}, V{0, 0, 1}, position{0, 0, 0};
  std::array<double, 2> uv0{0.5, 0.5}, uv1{0.5, 0.5};
  std::array<double, 4> vertexColor{1, 1, 1, 1}, uvDerivatives{0, 0, 0, 0};
  double dither = 0.5;
};

/// The texture input `inputIndex` (index into Material::inputs) sampled at (u, v):
/// the generated shader's SUBSTRATE_SAMPLE at the texture node's uv. Wrap, filter
/// and colour-space policy are the caller's.
using TextureFn = std::function<std::array<double, 4>(int inputIndex, double u, double v)>;

/// One value per Material::inputs entry (texture inputs ignored); empty: every default.
struct InputValues {
  std::vector<std::array<double, 4>> values;
};

/// The pixel's top-layer roughness as the top-layer word stores it (the
/// emitter's topRoughnessExpr): the top closures' roughness weighted by their
/// weights (one top closure: its roughness), saturated; every closure under
/// layers reads coatFloor of it.
template <class T>
T topRoughness(const std::vector<Closure<T>>& closures) {
  T r = T(0), w = T(0);
  int tops = 0;
  for (const Closure<T>& c : closures)
    if (c.isTop) {
      r = r + c.weight * c.roughness;
      w = w + c.weight;
      ++tops;
    }
  if (tops == 1)
    for (const Closure<T>& c : closures)
      if (c.isTop) return std::clamp(c.roughness, T(0), T(1));
  return std::clamp(r / std::max(w, T(1e-6)), T(0), T(1));
}

/// SubstrateClosure.coatFloor, coatStretch, coatTangent and coatShare of every
/// closure, as the material function and the unpacker set them, for the
/// closures under one interface when one closure is on top (else 0): its lobe
/// one isotropic GGX lobe (no anisotropy or haze feature), coatFloor(topR), topR
/// the pixel's top-layer roughness, and coatShare = coatMeanShare of it; one
/// stretched lobe (anisotropy, no haze), coatStretch = coatStretch(r, A), coatTangent
/// its tangent and coatShare = coatAnisoShare(coatStretch) (coatFloor 0).
template <class T>
void setCoatFloor(std::vector<Closure<T>>& closures, T topR);

/// SubstrateClosure.coversLayers of every closure, as the material function and
/// the unpacker set it: true on top when some closure of the pixel is not (its
/// lobe takes no dielectric multiple scattering: closureDielectricMs).
template <class T>
void setCoversLayers(std::vector<Closure<T>>& closures);

/// SubstrateClosure.coatInterface of every closure, as the material function
/// and the unpacker set it (substrate_coat_interface): 1 - the mean F0 of the
/// one closure on top, clamped to [0, SUBSTRATE_COAT_TOP_F0_MAX], for the
/// closures under it; SUBSTRATE_COAT_T_0 (0.96) for the others and under a mix
/// of tops.
template <class T>
void setCoatInterface(std::vector<Closure<T>>& closures);

/// SubstrateWater (substrate_water.h): a single-layer water's body, the same
/// fields and neutral values (substrate_water_init).
template <class T>
struct Water {
  V3<T> albedo{T(0), T(0), T(0)};
  V3<T> extinction{T(0), T(0), T(0)};  // 1/m
  T phaseG = T(0);
  V3<T> scaleBehind{T(1), T(1), T(1)};
  T opacity = T(0);  // the top material's
  T f0 = T(0.04);    // the water surface's
};

template <class T>
struct MaterialResult {
  std::vector<Closure<T>> closures;  // in closure order (r.after.closures)
  T coverage;                        // the root's C
  V3<T> transmittance;               // the root's T
  V3<T> emission{T(0), T(0), T(0)};  // what the unlit nodes emit, weighted (the emitter's `emission`)
  std::optional<Water<T>> water;     // a single-layer water's body (the emitter's `water`)
};

/// substrate_water_body: `background` through `distance` metres of water plus
/// `light` scattered once at the phase angle of cosine `cosPhase`.
template <class T>
V3<T> waterBody(const Water<T>& w, const V3<T>& background, T distance, T cosPhase, const V3<T>& light);
/// substrate_water_seen: what a pixel of water shows of its body (`behind`:
/// rgb what lies behind, [3] its distance from the eye).
template <class T>
V3<T> waterSeen(const Closure<T>& c, const Water<T>& w, const V4<T>& behind, T surfaceDistance, const V3<T>& V,
                const V3<T>& L, const V3<T>& lightRadiance);

/// <name>_evaluate: the value DAG, the tree walk (C and T per node, operators
/// bottom-up) and each closure's walk to the root. An unset `tex` samples every
/// texture as value_eval's constant sample.
template <class T>
MaterialResult<T> evaluateMaterial(const CompileResult& r, const Geometry& g, const InputValues& in,
                                   const TextureFn& tex);

/// substrate_eval_closure: BSDF * NoL (no weight, no throughput of the layers
/// above). diffuseModel is SUBSTRATE_DIFFUSE_MODEL (0..3); the specular profile
/// tint is the runtime's default (SUBSTRATE_SPECULAR_PROFILE_SAMPLE = 1).
template <class T>
V3<T> evalClosure(const Closure<T>& c, const V3<T>& V, const V3<T>& L, int diffuseModel);

/// substrate_closure_view_throughput / substrate_closure_light_throughput.
template <class T>
V3<T> viewThroughput(const Closure<T>& c, T NoV, const V3<T>& V);
/// The light's given what the layers above let through along the view and the light
/// (layersCrossing(c, N.V, V) and layersCrossing(c, N.L, L), L unit; coatMeanDirection: no one).
template <class T>
V3<T> lightThroughput(const Closure<T>& c, const V3<T>& viewCrossing, const V3<T>& lightCrossing);

/// substrate_light_closure: max(weight, 0) lerp(1, t_V t_L, coverageAbove) * evalClosure * radiance,
/// which is viewThroughput times lightThroughput.
template <class T>
V3<T> lightClosure(const Closure<T>& c, const V3<T>& V, const V3<T>& L, const V3<T>& radiance, int diffuseModel);

/// substrate_reflection_dir and substrate_env_mip.
template <class T>
V3<T> reflectionDir(const Closure<T>& c, const V3<T>& V);
template <class T>
T envMip(T roughness, T mipCount);

/// substrate_env_split_sum (light-side throughput included, view-side not).
/// `irradiance` is E = integral of L cos over the hemisphere (pi for a constant
/// unit environment); `prefilteredRadiance` is the prefiltered radiance (1 for it).
template <class T>
V3<T> envSplitSum(const Closure<T>& c, const V3<T>& V, const V3<T>& prefilteredRadiance, const V3<T>& irradiance,
                  int diffuseModel);

/// substrate_translucency.
template <class T>
void translucency(const Closure<T>& c, T NoV, const V3<T>& V, T& coverage, V3<T>& transmittance);

/// The reference for environment lighting: the integral over the sphere of
/// radiance(L) * lightThroughput(c, t_V, t_L) * evalClosure(c, V, L) dL (the
/// light-side throughput is what envSplitSum includes: 1 for a top closure), by
/// importance sampling with the balance heuristic: `samples` points per strategy
/// (GGX visible normals of the primary lobe and of the haze lobe when it has
/// weight, cosine-weighted hemisphere, and the uniform sphere for SSS wrap, which
/// is lit from below the horizon), a Hammersley set with a Cranley-Patterson
/// rotation per strategy drawn from `seed`. Deterministic. Not split sum: it
/// measures split sum's error.
V3<double> envIntegrated(const Closure<double>& c, const V3<double>& V,
                         const std::function<V3<double>(const V3<double>&)>& radiance, int diffuseModel, int samples,
                         std::uint32_t seed);

}  // namespace substratec::reference
