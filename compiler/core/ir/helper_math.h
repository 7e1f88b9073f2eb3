// Helper value nodes of the Substrate material format, in double precision.
//
// These are the physical conversions an author reaches for instead of typing
// raw slab parameters (docs/value-nodes.md, "Helpers"): metalness to
// diffuse/F0, IOR to F0, haziness to a second specular lobe, transmittance to
// mean free path, thin-film iridescence, rotation to tangent and
// view-dependent coverage. The compiler folds them with these functions when
// their pins are constant, and the CPU reference evaluates them per sample;
// the shader library implements the same formulas.
//
// Contract shared by every function:
// - pure, no state, no dependency beyond the C++ standard library;
// - every finite input gives a finite output (NoV 0, negative or > 1, IOR 1,
//   thickness 0 or huge, colours 0 or 1, ...): each input is clamped where the
//   formula stops making sense, and the clamp is stated on the function;
// - NaN inputs are treated as the lower bound of their clamp unless said
//   otherwise (they never escape as NaN).
#pragma once
#include <array>

namespace substratec::helpers {

using Vec3 = std::array<double, 3>;

struct DiffuseF0 {
  Vec3 diffuse_albedo;
  Vec3 f0;
};

/// Metalness workflow to Substrate's diffuse albedo / F0 (UE4 "Default Lit"):
///   diffuse_albedo = base_color * (1 - metallic)
///   f0             = lerp(0.08 * specular, base_color, metallic)
///                  = 0.08 * specular * (1 - metallic) + base_color * metallic
/// `specular` 0.5 gives the dielectric F0 0.04 (IOR 1.5).
/// Guards: base_color (per channel), metallic and specular are clamped to [0, 1].
DiffuseF0 metalnessToDiffuseF0(const Vec3& base_color, double metallic, double specular);

/// Reflectance at normal incidence of a dielectric interface of relative IOR n:
///   f0 = ((n - 1) / (n + 1))^2
/// n and 1/n give the same f0 (an IOR below 1 is the same interface seen from
/// the dense side). 1.5 -> 0.04, 1 -> 0.
/// Guards: n is clamped to [0, DBL_MAX]; n <= 0 (non-physical) gives 1, the
/// limit of n -> 0+; a huge n tends to 1. The result is in [0, 1].
double iorToF0(double ior);

struct SecondRoughness {
  double second_roughness;
  double second_roughness_weight;
};

/// Haziness to a second (haze) GGX lobe, an isotropic, F0-free reading of
/// Barla, Pacanowski & Vangorp, "A Composite BRDF Model for Hazy Gloss"
/// (EGSR / Computer Graphics Forum 2018). With r = roughness, h = haziness,
/// both clamped to [0, 1], and GGX alpha = roughness^2:
///   alpha_c = r^2                               core (sharp) lobe
///   alpha_h = min(1, (1 + L) * alpha_c), L = 3  haze lobe, Barla's relative
///                                               "extent" fixed at 3
///   second_roughness = sqrt(alpha_h) = min(1, 2 r)
///   p = (alpha_c / alpha_h)^2                   ratio of the haze lobe's peak
///                                               to the core's (GGX D(0) ~ 1/alpha^2);
///                                               p = 1/16 when alpha_c = 0 (the limit)
///   second_roughness_weight = h / (h + p (1 - h))
/// so that h is the share of the highlight's peak (mirror direction) brought by
/// the haze lobe: w p / ((1 - w) + w p) = h. This is Barla et al.'s haze
/// parameter in their positivity-limited regime (F0 <= p, every dielectric),
/// with the total reflectance kept at the slab's own F0 instead of being
/// raised (energy is conserved; the slab's lerp of two lobes mixes energy).
/// h = 0 -> weight 0 (no haze), h = 1 -> weight 1 (only the haze lobe).
SecondRoughness hazinessToSecondRoughness(double roughness, double haziness);

struct Mfp {
  Vec3 mfp;
  double thickness;
};

/// Transmittance at normal incidence through `thickness` metres of a
/// non-scattering medium to its mean free path (Beer-Lambert):
///   T = exp(-thickness / mfp)  ->  mfp = -thickness / ln(T)   (per channel)
/// T = 1 (clear) gives the "transparent" sentinel 1e9 m, T = 0 (opaque) gives 0.
/// `thickness` is passed through (after the guard) so that the slab and its
/// vertical layer use the thickness the MFP was computed for.
/// Guards: T is clamped to [0, 1]; thickness <= 0 (or NaN) becomes 0.0001 m,
/// the format's default surface thickness; mfp is capped at the 1e9 m sentinel
/// (so mfp is continuous and monotone as T -> 1), which keeps the round trip
/// exp(-thickness / mfp) = T exact whenever thickness / -ln(T) < 1e9.
Mfp transmittanceToMfp(const Vec3& transmittance, double thickness);

struct F0F90 {
  Vec3 f0;
  Vec3 f90;
};

/// Thin-film iridescence: the view-dependent F0 of a slab whose interface is
/// coated by a dielectric film, a real-time simplification of Belcour & Barla,
/// "A Practical Extension to Microfacet Theory for the Modeling of Varying
/// Iridescence" (SIGGRAPH 2017). Stack: air (IOR 1) / film (IOR `ior`,
/// thickness d = `film_thickness_m`, in METRES) / base (per-channel IOR
/// eta3 = (1 + sqrt(f0)) / (1 - sqrt(f0)), a dielectric reading of the base).
///   cos(theta2) = sqrt(1 - (1 - NoV^2) / ior^2)          Snell, air -> film
///   R12 = Fresnel(ior, NoV), T121 = 1 - R12              exact dielectric Fresnel
///   R23 = Fresnel(eta3 / ior, cos(theta2)) + (f90 - 1)(1 - cos(theta2))^5
///   phi = pi + (eta3 < ior ? pi : 0)                      phase shifts (0 or pi)
///   OPD = 2 ior d cos(theta2)
///   R123 = min(R12 R23, 0.9999), Rs = T121^2 R23 / (1 - R123)
///   I(d) = R12 + Rs + sum_{m=1,2} 2 (Rs - T121) R123^(m/2) S_m
///   S_m  = spectral sensitivity at path difference m OPD and shift m phi:
///          Belcour & Barla's Gaussian fit of the CIE 1931 XYZ functions,
///          converted to linear Rec.709 and white-balanced so that S = cos(m phi)
///          at OPD = 0 (a film of zero optical thickness is colourless)
///   f0'  = clamp(f0 + I(d) - I(0), 0, 1)                   per channel
///   f90' = f90                                             unchanged
/// I(d) - I(0) is the change the film brings at this NoV: the slab keeps its
/// own Fresnel for the angular falloff, so its reflectance at this angle
/// becomes Schlick(f0, f90, NoV) + (1 - (1 - NoV)^5) (I(d) - I(0)): the Airy
/// change exactly at normal incidence, fading out at grazing where F90 takes
/// over. Subtracting I(0) also cancels the approximation's bias (truncated
/// series, dielectric base) and makes the result continuous at d = 0.
/// Guards: thickness <= 0 (or NaN) returns f0 and f90 unchanged, bit for bit;
/// NoV clamped to [0, 1]; film IOR clamped to [1, 5]; thickness clamped to
/// 1 mm (interference has faded out beyond ~10 um); f0 and f90 clamped to
/// [0, 1] (f0 to 0.9999 where it becomes an IOR).
F0F90 thinFilm(double NoV, const Vec3& f0, const Vec3& f90, double film_thickness_m, double ior);

/// Tangent rotated by `angle` radians around `normal`, counter-clockwise seen
/// from the tip of the normal (right-hand rule), starting from the canonical
/// tangent b1 of the branchless orthonormal basis of Duff et al., "Building an
/// Orthonormal Basis, Revisited" (JCGT 2017, fixing Frisvad 2012):
///   s = copysign(1, n.z), a = -1 / (s + n.z), b = n.x n.y a
///   b1 = (1 + s n.x^2 a, s b, -s n.x),  b2 = (b, s + n.y^2 a, -n.y)  (= n x b1)
///   tangent = cos(angle) b1 + sin(angle) b2
/// For n = +Z: b1 = +X, b2 = +Y. The result is unit length and orthogonal to
/// the normalized normal for every normal, poles included.
/// Guards: the normal is normalized (scaled first, so tiny normals work); a zero
/// or non-finite normal is replaced by (0, 0, 1); a non-finite angle is 0.
Vec3 rotationToTangent(double angle, const Vec3& normal);

/// Coverage of a layer seen at an angle: a layer of coverage c (fraction of
/// the surface covered, seen along the normal) covers more of the view at
/// grazing angles, as the path through it lengthens by 1 / NoV:
///   coverage' = 1 - (1 - c)^(1 / max(NoV, 1e-4))
/// computed as -expm1(log1p(-c) / NoV) for precision near c = 0.
/// Guards: c clamped to [0, 1]; NoV clamped to [1e-4, 1] (NoV >= 1 returns c
/// exactly). The result is in [c, 1].
double viewDependentCoverage(double coverage, double NoV);

}  // namespace substratec::helpers
