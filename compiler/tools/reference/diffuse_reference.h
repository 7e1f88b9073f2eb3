// A Monte Carlo reference for rough diffuse reflection, and the error of the
// runtime's four diffuse models (SUBSTRATE_DIFFUSE_MODEL 0..3,
// runtime_shaders/substrate_bsdf.h) against it. No shader counterpart: like
// envIntegrated (integrate.cc) it is a measuring instrument for the tests.
//
// The surface. A Smith microsurface (Heitz et al. 2016, "Multiple-Scattering
// Microfacet BSDFs with the Smith Model") with the isotropic GGX distribution
// of normals, whose facets are Lambertian with reflectance `albedo`, and light
// bouncing between the facets any number of times. The walk is Heitz et al.'s:
// the ray alternates free flights through the microsurface's height field
// (explicit heights, so the masking of the entry direction and the shadowing of
// the exit direction are height-correlated, as in their paper; the
// single-scattering term is exactly the height-correlated Smith G2) and
// scattering by a facet drawn from the visible normals of the ray's direction
// (any direction, also from below the macro-surface) with a cosine lobe about
// it. Heights enter only through C1(h), the height CDF, so the walk tracks
// ln C1(h) (0 at the top): free flights are exponential in it with rate
// |Lambda(w)| (Smith's Lambda of GGX), exactly Heitz et al.'s sampleHeight for
// any height distribution, without the underflow of C1 itself after many
// downward flights. Direction sampling of visible normals: Dupuy & Benyoub
// 2023 (a spherical cap of the stretched configuration), valid below the
// horizon too. The value is the unidirectional next-event estimator of Heitz
// et al.: the walk enters from the view and, at every facet hit, adds
// throughput x rho/pi max(0, wi.m) x G1(wi, h) (the facet's Lambertian lobe
// toward the light and the probability that the light direction leaves the
// microsurface from that height). Its expectation is f(wo, wi) cos(wi), the
// microsurface's BRDF (all bounce orders) times the light's cosine: the same
// quantity as evalClosure. Paths longer than 4096 facet hits are dropped (a
// negligible tail: a walk makes 2.0 hits on average at alpha = 1).
// Single scattering alone is checked against the analytic height-correlated
// Smith lobe in tests/unit/diffuse_reference_test.cc.
//
// Roughness. `roughness` is the closure's perceptual roughness r, and the
// microsurface's GGX alpha = r^2 (saturated r; alpha = 0 is the flat Lambertian
// plane, reproduced exactly). This is the alpha every runtime model's own
// mapping implies: the specular and Chan 2018 use alpha = r^2 (Chan's
// a^2 = r^4), Chan 2024 its a = r^2, and EON's r_EON = 0.4 r is UE's fit of the
// Oren-Nayar-style roughness to GGX-distributed Lambertian facets at alpha = r^2
// — so every model is compared with the reference at alpha = r^2 of the same r,
// which is what a material with that roughness renders. Lambert has no
// roughness (it is the alpha = 0 limit) and is compared at the same alpha.
//
// Determinism: every function is a pure function of its arguments (seed
// included): splitmix64 streams, no global state, no threads.
#pragma once
#include <cstdint>
#include <vector>

#include "reference/reference.h"

namespace substratec::reference {

/// f(wo, wi) cos(wi) of the GGX-faceted Lambertian microsurface above, at
/// alpha = saturate(roughness)^2, for facet reflectance `albedo` (in [0, 1]).
/// wo (view) and wi (light) are unit vectors in the surface frame (normal +z);
/// 0 when either is at or below the horizon. Mean of `samples` random walks
/// from the stream `seed`. Cost: ~0.15 us per facet hit; mean hits per walk
/// 1.0 (r <= 0.25), 1.1 (r = 0.5), 1.4 (r = 0.75), 2.0 (r = 1), whatever the
/// albedo: 0.13-0.4 us per walk, 0.5-1.5 ms for 4096 walks (RelWithDebInfo).
double microfacetDiffuse(double albedo, double roughness, const V3<double>& wo, const V3<double>& wi, int samples,
                         std::uint32_t seed);

/// The directional albedo integral f(wo, wi) cos(wi) dwi of the same surface:
/// the throughput (albedo^bounces) of `samples` walks entering from wo that
/// leave the microsurface. Exactly 1 for albedo 1 (no absorption, every walk
/// leaves), below `albedo` for albedo < 1 and alpha > 0 (interreflection loss).
double microfacetDiffuseAlbedo(double albedo, double roughness, const V3<double>& wo, int samples,
                               std::uint32_t seed);

/// The error of one diffuse model (SUBSTRATE_DIFFUSE_MODEL) against the reference.
struct DiffuseModelError {
  int model;           // 0 Lambert, 1 Chan 2018, 2 Chan 2024, 3 EON
  double relMse;       // mean over the grid of (x - y)^2 / (y^2 + 0.01), x model, y reference, both BRDF * NoL
  double maxAbs;       // max over the grid of |x - y|
  double albedoError;  // max over roughnesses and views of |A_model(wo) - A_ref(wo)| (directional albedo)
};

/// evalClosure (bsdf.cc) of a pure diffuse closure — diffuseAlbedo = `albedo`,
/// f0 = 0 and (the F90 feature bit set) f90 = 0, so the specular lobe is 0 and
/// E_spec = 0, and the diffuse is not scaled — for every model 0..3, against the
/// reference at facet reflectance `albedo` (the closure's diffuseAlbedo is
/// taken as the facet reflectance; with albedo 1, the default, every convention
/// agrees — EON's runtime inverts its albedo so that its hemispherical mean
/// equals diffuseAlbedo, which for albedo < 1 is brighter than facets of that
/// reflectance). Grid: each roughness r; `viewCount` views at cos(theta_o) =
/// (i + 0.5) / viewCount, phi = 0; `lightCount` lights on a spherical Fibonacci
/// set of the upper hemisphere (cos(theta_i) = 1 - (j + 0.5) / lightCount,
/// golden-angle phi). Reference values from microfacetDiffuse with `samples`
/// walks (a fixed seed per grid point); reference albedo from
/// microfacetDiffuseAlbedo with 4 x `samples` walks; model albedo by a 64 x 64
/// midpoint rule in (cos(theta_i), phi), mirrored about the plane of incidence.
/// Returns the four models in order 0..3. MC noise of the reference adds about
/// Var(y) / (y^2 + 0.01) to relMse (a floor, see the tests).
std::vector<DiffuseModelError> diffuseModelErrors(const std::vector<double>& roughnesses, int viewCount,
                                                  int lightCount, int samples, double albedo = 1.0);

}  // namespace substratec::reference
