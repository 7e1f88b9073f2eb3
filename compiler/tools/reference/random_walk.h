// A Monte Carlo ground truth for layered slabs: the position-free random walk
// through a stack of plane-parallel layers of Guo, Hasan and Zhao 2018
// ("Position-free Monte Carlo simulation for arbitrary layered BSDFs"), with the
// estimator structure of pbrt-v4's LayeredBxDF (f() evaluated stochastically:
// next-event estimation through the interfaces, multiple importance sampling of
// the exit, Russian roulette), generalized from two interfaces to N. It measures
// the analytic layering of the runtime (compiler/tools/reference/lighting.cc,
// substrate_lighting.h): it is not a mirror of any shader.
//
// THE MODEL (per colour channel, channels independent)
//   A stack of layers, top to bottom. Layer k is an interface I_k above a
//   homogeneous slab of medium M_k; M_k lies between I_k and I_{k+1}.
//   * Interface: GGX microfacets, anisotropic by the runtime's mapping (bsdf.cc
//     ggxAlpha: a = sat(roughness)^2, (alpha_x, alpha_y) = (a (1 + A), a (1 - A))
//     clamped to [1e-3, 1], A = anisotropy), x along the layer's tangent
//     (tangentAngle rotates the layer's microsurface about z), height-correlated
//     Smith. Every interface event goes through one place (random_walk.cc,
//     ifcSample / ifcF / ifcPdf). Rough lobes (max alpha > 0.002) scatter by
//     the microsurface walk of Heitz et al. 2016 (microsurface.h): every order
//     of inter-facet scattering (reflection, refraction, total internal
//     reflection), energy conserving — the white furnace of every non-absorbing
//     stack of random_walk_test's grid (rough dielectrics over a white
//     Lambertian, white conductors at every roughness and anisotropy, clear
//     coats over both, roughness 0.1 .. 1) is 0.9992 .. 1.0000. Lobes at the
//     alpha floor, and every lobe under WalkOptions::singleScatteringInterfaces,
//     use the classic single-scattering microfacet BSDF (pbrt-v4's), which
//     loses the inter-facet energy (E_ss of a white conductor 0.893 at
//     roughness 0.45, NoV 0.5; the grid's rough stacks fail the furnace there).
//     - Dielectric: relative IOR (below over above) from the slab's own F0, per
//       channel (a coloured F0 is a coloured IOR; channels walk apart):
//       eta = (1 + sqrt(F0)) / (1 - sqrt(F0)) (F0 clamped to 0.99), so each
//       interface reflects F0 at normal incidence whatever lies above it
//       (WalkOptions::absoluteIor: the other convention). Exact dielectric
//       Fresnel. F90 (of the channel that sets the group's IOR): reflectance
//       remapped F' = F0 + (F90 - F0)(F - F0)/(1 - F0), transmission 1 - F', so
//       F90 = 1 is exact Fresnel and energy is conserved — on single-scattering
//       lobes only (microsurface.h's dielectric has no F90: rough dielectric
//       lobes ignore it). F0 = 0 is eta = 1: an index-matched boundary, a
//       pass-through. The walk carries energy (pbrt's Importance mode), the
//       light chain radiance; f(wo, wi) is the same either way (reciprocity,
//       tested).
//     - Conductor: iff WalkLayer::conductor (explicit). Complex IOR per channel
//       by Gulbrandsen 2014 from r = F0 and the edge tint g = F90 (1 - (1 -
//       F0)^2.75): the factor is the g whose curve is closest to Schlick's with
//       F90 = 1, so the default F90 = 1 reads as the runtime's Schlick (max
//       difference over angles 0.056 / 0.027 / 0.024 / 0.012 / 0.014 / 0.006 at
//       F0 0.02 / 0.04 / 0.3 / 0.56 / 0.9 / 0.97). F90 is the runtime's
//       effective one (bsdf.h f90Effective): a conductor's gives the tint's hue
//       only (its largest channel reads 1), a dielectric's keeps its intensity.
//       Exact conductor Fresnel. A conductor hides everything below it.
//     - Haze: the interface is the mixture of two microsurfaces, roughness and
//       secondRoughness, by secondRoughnessWeight (as the runtime lerps its two
//       lobes): sampling picks a lobe by its weight, f and the pdf mix.
//     - specularTint multiplies the reflection of the interface seen from
//       above (in [0, 1]: it absorbs the rest of F, never creates energy).
//     - Fuzz: a sheen layer on top of the layer's interface — the runtime's
//       model as a layer (bsdf.cc): reflection the Charlie sheen lobe amount *
//       colour * charlieSheen / max(1, E_fuzz(mu_o)) (sampled by cosine with
//       probability amount * min(E_fuzz(mu_o), 1)); everything else crosses it
//       straight with weight 1 - amount * min(E_fuzz(mu), 1) at each crossing
//       (mu of the direction above). An energy-conserving "mean sheen layer"
//       (it reflects at most what it takes from the crossing light), the LTC /
//       table sheen of the runtime as a layer, not a volumetric fibre walk. It
//       is walked as a pass-through of its own (no medium between it and the
//       interface under it), so light bounces between the two as between two
//       layers, and what it catches from below goes back down by the mirror
//       image of its sheen (tinted by its colour); a velvet (fuzz on an F0-0
//       interface) and a fabric under a coat of its own IOR (index-matched)
//       keep their fuzz. Issue 19 step 8: before, the fuzz of a pass-through
//       was skipped and what a fuzz caught from below was absorbed (a white
//       fuzzy coat over a white base returned 0.94). Not reciprocal (the
//       runtime's normalization by E_fuzz(mu_o) is not).
//   * Medium of a layer that is not the bottom: thickness d (the vertical's
//     thickness), extinction sigma_t = 1 / MFP per channel (MFP clamped to
//     >= 1e-30), so optical thickness tau = d / MFP; single-scattering albedo
//     from the diffuse albedo (below); Henyey-Greenstein phase function with
//     g = the slab's SSS phase anisotropy (clamped to [-0.99, 0.99]).
//   * Bottom: the last layer's interface sits over a semi-infinite medium of the
//     same kind (MFP > 0; its thickness is ignored: reflectance of a
//     semi-infinite medium does not depend on the MFP's scale), or — when the
//     slab is opaque (MFP 0, WalkLayer::opaqueBase) — directly over a
//     Lambertian reflector of albedo diffuse_albedo (or is a conductor, above).
//     An opaque slab hides everything below it: the stack ends there.
//   * Single-scattering albedo: diffuse_albedo A is the multiple-scattering
//     albedo the artist sees. For an isotropic semi-infinite index-matched
//     medium, van de Hulst's approximation gives the spherical albedo
//       A(w) = (1 - s)(1 - 0.139 s) / (1 + 1.17 s),   s = sqrt(1 - w);
//     its exact inverse (a quadratic in s; the constants of Kulla & Conty 2017,
//     alpha = 1 - (4.09712 + 4.20863 A - sqrt(9.59217 + 41.6808 A + 17.7126 A^2))^2)
//     gives the reduced albedo w' = 1 - s^2, and for g != 0 the similarity
//     relation w' = w (1 - g) / (1 - w g) gives w = w' / (1 - g + g w').
//     random_walk_test.cc checks it against this walk (semi-infinite medium
//     under an index-matched interface: within 0.005). Under a dielectric
//     interface the slab looks darker than A (the interface reflects light back
//     in): that is the model, not an error of the inversion
//     (WalkOptions::albedoSeenThroughInterface: the other convention).
//
// THE ESTIMATOR (layeredEval)
//   Per sample: one estimate of the top reflection f_0(wo, wi) (exact on a
//   single-scattering lobe; evalMicrosurface, unbiased and stochastic, on a
//   microsurface); a light chain is sampled once from wi down through the
//   stack (transmission only, a direction c_k in every layer, weight L_k =
//   product of f|cos|/pdf and of the full-layer transmittances above); the
//   walk enters from wo (transmission only) and scatters (medium: distance
//   sampling, HG; interfaces: GGX visible normals or the microsurface walk;
//   Lambertian: cosine) with Russian roulette (after 3 events, when the largest
//   channel of the throughput is below 0.25: survival probability mb / 0.25,
//   throughput raised to 0.25) up to maxDepth events. At the top interface from
//   below it continues by reflection only. A restricted strategy (transmission
//   only, reflection only) on a microsurface cannot choose its side: the walk
//   samples every exit and a sample on the unwanted side ends the path; the
//   kept sample's weight stays f/p_all, so the estimator integrates f over the
//   wanted side only — unbiased (single-scattering lobes instead renormalize
//   their Fresnel choice among the allowed lobes). Every path that leaves
//   towards wi is counted at its last vertex v (a medium scattering, a
//   reflection from above at an interface, the Lambertian base), by
//     B: connecting v to the light chain of its layer (the unscattered way up
//        through the interfaces above, sampled from wi; the interface's f by
//        evalMicrosurface where it walks a microsurface), and, when v is in the
//        top layer,
//     A: the direction v sampled for the walk, if it leads up, evaluated
//        through the top interface f_0(-w, wi) with the transmittance to it,
//   weighted by the power heuristic on the pdfs of the two strategies
//   (pdfMicrosurface, a proxy, on microsurfaces: any positive density used
//   the same way by both strategies keeps MIS unbiased; for a vertex below the
//   top layer only B is used: weight 1). Channels whose interfaces (IORs, F90)
//   and optical thicknesses agree share one walk (throughput per channel);
//   others get their own walks, each with `samples` walks. layeredAlbedo walks
//   forward; at the top interface (entering, and from below) it splits the
//   bounce: one microfacet normal gives both the reflection and the
//   transmission with their weights, what leaves is counted and what stays
//   walks on (no Bernoulli choice: 3-8x less variance on the smooth gate).
//   Deterministic: a splitmix64 stream from WalkOptions::seed.
//   maxDepth (default 1024): with energy-conserving interfaces light trapped
//   under a coat (total internal reflection) over a white base bounces many
//   times; at maxDepth 256 a clear coat over a white conductor at roughness
//   0.1 keeps 0.994 at NoV 0.2 (the furnace gate fails), at 1024 0.9992. Walks
//   end early by roulette unless the stack is bright, so the cost is paid by
//   bright stacks only.
//   Cost (one core, -O2, 4096 samples, ms per layeredEval / layeredAlbedo,
//   measured back to back; before = the single-scattering walk of commit
//   9c10eb0 at maxDepth 64):
//     coat over plastic          5.1 / 3.5   ->  15.1 / 9.2
//     SSS base (A 0.8/0.5/0.2)  13.3 / 6.6   ->  77 / 16.9
//     conductor                  0.004 / 0.43 ->  2.1 / 1.4
//     coat over conductor        4.6 / 2.3   ->  16.4 / 6.1
//   (docs/performance.md: the command). Bright semi-infinite media need the
//   long walks: the albedo of an SSS slab (F0 0.04, roughness 0.5) at A = 0.5
//   / 0.8 / 0.95 was short by 0 / 6 / 22 % at maxDepth 64 (single scattering).
//
// NOT MODELLED: glints, emissive, SSS type (wrap /
//   diffusion: only the medium counts), F90 of rough (microsurface) dielectric
//   lobes, thin-surface transmission (the bottom is semi-infinite or opaque),
//   normal maps (ground_truth.cc's frame). Specular profiles enter as their
//   tint only.
#pragma once
#include <cstdint>
#include <vector>

#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace substratec::reference {

/// One layer of a stack (top to bottom). Colours per channel (RGB).
struct WalkLayer {
  V3<double> f0{0.04, 0.04, 0.04}, f90{1, 1, 1}, diffuseAlbedo{0, 0, 0}, mfp{0, 0, 0};
  double roughness = 0.5, phaseAnisotropy = 0, thickness = 0;
  bool opaqueBase = false;  // MFP 0: a Lambertian of diffuseAlbedo (or a conductor) right under the interface
  // --- issue 18: every feature of the shipping model (ground_truth.cc fills these)
  bool conductor = false;       // a conductor interface (complex IOR from f0 and f90) hiding everything below
  double anisotropy = 0;        // -1..1, mapped to (alpha_x, alpha_y) as the runtime maps it
  double tangentAngle = 0;      // this layer's tangent, rotated about the stack's normal from the stack's x (radians)
  double secondRoughness = 0.5, secondRoughnessWeight = 0;  // haze: a second GGX lobe of the interface, by weight
  double fuzzAmount = 0, fuzzRoughness = 0.5;               // fuzz: a sheen layer on top of the interface
  V3<double> fuzzColor{0, 0, 0};
  V3<double> specularTint{1, 1, 1};  // the specular profile's tint of the interface's reflection (1: none)
};

/// A Monte Carlo estimate: the mean per channel, its standard error, and the
/// number of independent walks behind it.
struct Estimate {
  V3<double> value{0, 0, 0}, standardError{0, 0, 0};
  long samples = 0;
};

struct WalkOptions {
  int samples = 4096;           // walks per channel group
  int maxDepth = 1024;            // events per walk (interfaces, media, base); see the cost note above
  std::uint32_t seed = 1;
  /// The albedo convention. false (the default, the model above): diffuse_albedo is
  /// the albedo of the medium alone (index-matched), the Lambertian's albedo.
  /// true: it is the albedo seen through the slab's own interface in air — the
  /// analytic model's meaning (albedo (1 - E_spec) leaves, no darkening by the
  /// interface's internal reflection): each layer's A is first replaced by
  /// A' = A / (1 - R21 + R21 A), R21 the cosine-weighted internal reflectance of
  /// the slab's own interface in air (internalReflectance(eta of its F0) when
  /// smooth; a rough one's is estimated once on its microsurface), the closed
  /// form of a Lambertian under that interface, then inverted as above.
  bool albedoSeenThroughInterface = false;
  /// The IOR convention. false (the default, the model above): each slab's F0
  /// gives the relative IOR of its own interface, so layers' IORs multiply (a
  /// base of F0 0.04 under a coat of F0 0.04 sits at 2.25 and keeps its 4 %
  /// specular). true: each slab's F0 gives its absolute IOR (against air) and
  /// an interface's relative IOR is n_k / n_{k-1} (that base under that coat is
  /// index-matched: no specular of its own, no extra trapping; eta < 1 allowed).
  bool absoluteIor = false;
  /// Rough interfaces scatter once on the microsurface (the classic microfacet
  /// BSDF, which loses the inter-facet bounces) instead of walking it
  /// (microsurface.h): for the single-scattering gates and comparisons.
  bool singleScatteringInterfaces = false;
};

/// f(wo, wi) * |cos(wi)| of the stack (directions in the local frame, z up; wo
/// the view, wi the light), per channel. Zero unless both are above the surface.
V3<double> layeredEval(const std::vector<WalkLayer>& stack, const V3<double>& wo, const V3<double>& wi,
                       const WalkOptions& options);

/// layeredEval and layeredAlbedo with their standard errors (same walks, same bits).
Estimate layeredEvalEstimate(const std::vector<WalkLayer>& stack, const V3<double>& wo, const V3<double>& wi,
                             const WalkOptions& options);
Estimate layeredAlbedoEstimate(const std::vector<WalkLayer>& stack, const V3<double>& wo, const WalkOptions& options);

/// Directional albedo of the stack for view wo: the integral of layeredEval over
/// wi, estimated with `samples` forward walks (per channel group) that sample wi.
V3<double> layeredAlbedo(const std::vector<WalkLayer>& stack, const V3<double>& wo, const WalkOptions& options);

/// van de Hulst's spherical albedo of a semi-infinite medium of single-scattering
/// albedo `omega` and HG anisotropy g (through the similarity relation).
double multipleScatteringAlbedo(double omega, double g = 0);
/// Its inverse: the single-scattering albedo for the albedo A the artist sees.
double singleScatteringAlbedo(double albedo, double g = 0);
/// The relative IOR of an interface of normal reflectance f0 (1 for f0 <= 0).
double iorFromF0(double f0);
/// Cosine-weighted hemispherical reflectance of a smooth interface of relative
/// IOR eta > 1 seen from the dense side (total internal reflection included),
/// from the outside one by 1 - R21 = (1 - R12) / eta^2.
double internalReflectance(double eta);
/// Unpolarized dielectric Fresnel reflectance for cos(theta_i) (negative: from
/// the other side) and relative IOR eta (transmitted side over incident side
/// for cos > 0); 1 under total internal reflection.
double fresnelDielectric(double cosThetaI, double eta);

}  // namespace substratec::reference
