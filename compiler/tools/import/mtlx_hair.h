// Chiang et al. 2016's hair parameters as MaterialX's hair nodes compute them,
// and back: the formulas of MaterialX 1.39's genglsl implementation
// (libraries/pbrlib/genglsl/mx_chiang_hair_bsdf.glsl) and its PBR
// specification (documents/Specification/MaterialX.PBRSpec.md,
// "chiang_hair_bsdf" and the three helper nodes), for the import of
// chiang_hair_bsdf onto the format's `hair` node (mtlx_import.cc) and the
// folding of the helpers (mtlx_graph.cc). Double precision, no state.
//
//  - chiang_hair_roughness(longitudinal l, azimuthal a, scale_TT, scale_TRT):
//      l, a clamped to [0.001, 1]; v = (0.726 l + 0.812 l^2 + 3.7 l^20)^2 (the
//      longitudinal variance), s = 0.265 a + 1.194 a^2 + 5.372 a^22 (the
//      azimuthal logistic scale, before Chiang's sqrt(pi/8), which the BSDF
//      applies); roughness_R = (v, s), roughness_TT = (v scale_TT^2, s),
//      roughness_TRT = (v scale_TRT^2, s). These are pbrt's HairBSDF formulas
//      (pbrt-v3 src/materials/hair.cpp), whose TT and TRT variances are v / 4
//      and 4 v: MaterialX's default scales 0.5 and 2. chiang_hair_bsdf's
//      roughness inputs are these (v, s), clamped to [0.001, 1] by the BSDF —
//      not the artist's [0, 1] roughness the `hair` node takes, which is
//      recovered by inverting the polynomials (both increase on [0, 1]).
//  - chiang_hair_absorption_from_color(color, azimuthal_roughness bn):
//      sigma = (ln(clamp(color, 0.001, 1)) / P(bn))^2, P(b) = 5.969 − 0.215 b
//      + 2.532 b^2 − 10.73 b^3 + 5.574 b^4 + 0.245 b^5 (Chiang 2016, eq. 9).
//      The `hair` node takes the colour c with sigma = (ln c / P(bn))^2 of its
//      own azimuthal roughness, whose exact inverse is c = exp(−sqrt(sigma) P(bn)).
//  - deon_hair_absorption_from_melanin(concentration, redness, eumelanin_color,
//      pheomelanin_color): melanin = −ln(max(1 − concentration, 0.0001)),
//      eumelanin = melanin (1 − redness), pheomelanin = melanin redness,
//      sigma = max(eumelanin (−ln eumelanin_color) + pheomelanin (−ln
//      pheomelanin_color), 0); the default colours (0.657704, 0.498077,
//      0.254107) and (0.829444, 0.67032, 0.349938) are exp(−(0.419, 0.697,
//      1.37)) and exp(−(0.187, 0.4, 1.05)), pbrt's eumelanin and pheomelanin
//      absorption (d'Eon et al. 2011).
//  - The unit of the absorption: the specification calls absorption_coefficient
//      "normalized to the hair fiber diameter", but the implementation
//      attenuates one pass by exp(−sigma · 2 cos(gamma_t) / cos(theta_t)),
//      pbrt's formula for a fibre of radius 1 (the chord 2 cos(gamma_t) is in
//      radii), and feeds it pbrt's melanin constants and Chiang's eq. 9 as pbrt
//      does: the coefficient is per unit radius, as the `hair` node's sigma_a
//      (runtime_shaders/substrate_hair.h). No conversion.
//  - cuticle_angle in [0, 1]: the BSDF's alpha = cuticle_angle · pi − pi / 2
//      radians ("remap [0, 1] to [-PI/2, PI/2]"; 0.5 no tilt; the
//      specification: "values above 0.5 tilt the scales towards the root"),
//      applied as pbrt-v3's HairBSDF::f does: the light's angle theta_i turned
//      by +2 alpha for R, −alpha for TT, −4 alpha for TRT, so that R peaks at
//      theta_i + theta_o = −2 alpha. The `hair` node follows pbrt-v4's HairBxDF
//      (compiler/tools/reference/hair_truth.cc): the view's angle turned by
//      −2 alpha for R (+alpha TT, +4 alpha TRT), R peaking at theta_i + theta_o
//      = +2 alpha. The same highlights therefore take the opposite angle:
//      (0.5 − cuticle_angle) · 180 degrees (0 at MaterialX's default).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

namespace substratec::import::hair {

/// The bounds chiang_hair_bsdf clamps its roughness inputs (v and s) to, and
/// chiang_hair_roughness its longitudinal and azimuthal roughness.
inline constexpr double kMinRoughness = 0.001, kMaxRoughness = 1.0;
/// The smallest colour chiang_hair_absorption_from_color reads.
inline constexpr double kMinColor = 0.001;
/// The `hair` node's cuticle angle range, degrees.
inline constexpr double kMaxCuticleDegrees = 20.0;

/// 0.726 b + 0.812 b^2 + 3.7 b^20: the square root of the R lobe's variance.
inline double longitudinalDeviation(double b) { return 0.726 * b + 0.812 * b * b + 3.7 * std::pow(b, 20); }
/// The R lobe's longitudinal variance of roughness b.
inline double longitudinalVariance(double b) {
  const double d = longitudinalDeviation(b);
  return d * d;
}
/// 0.265 b + 1.194 b^2 + 5.372 b^22: the azimuthal logistic scale of roughness b
/// (before sqrt(pi / 8)).
inline double azimuthalScale(double b) { return 0.265 * b + 1.194 * b * b + 5.372 * std::pow(b, 22); }
/// Chiang 2016's P(bn) of eq. 9.
inline double absorptionDenominator(double b) {
  return 5.969 + b * (-0.215 + b * (2.532 + b * (-10.73 + b * (5.574 + 0.245 * b))));
}

/// The b in [0, 1] where the increasing `f` reaches `y` (0 below f(0), 1 above f(1)).
template <class F>
double inverseOnUnit(F f, double y) {
  if (!(y > f(0.0))) return 0.0;
  if (y >= f(1.0)) return 1.0;
  double lo = 0, hi = 1;
  for (int i = 0; i < 64; ++i) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < y ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}
/// The roughness whose R lobe has longitudinal variance v.
inline double roughnessOfVariance(double v) {
  return inverseOnUnit(longitudinalDeviation, std::sqrt(std::max(v, 0.0)));
}
/// The azimuthal roughness of logistic scale s.
inline double azimuthalRoughnessOfScale(double s) { return inverseOnUnit(azimuthalScale, s); }

using Vec2 = std::array<double, 2>;
using Vec3 = std::array<double, 3>;

/// chiang_hair_roughness's outputs.
struct LobeRoughness {
  Vec2 r, tt, trt;
};
inline LobeRoughness chiangHairRoughness(double longitudinal, double azimuthal, double scaleTT, double scaleTRT) {
  const double v = longitudinalVariance(std::clamp(longitudinal, kMinRoughness, kMaxRoughness));
  const double s = azimuthalScale(std::clamp(azimuthal, kMinRoughness, kMaxRoughness));
  return {{v, s}, {v * scaleTT * scaleTT, s}, {v * scaleTRT * scaleTRT, s}};
}

/// chiang_hair_absorption_from_color.
inline Vec3 absorptionFromColor(const Vec3& color, double azimuthalRoughness) {
  const double p = absorptionDenominator(azimuthalRoughness);
  Vec3 sigma;
  for (int i = 0; i < 3; ++i) {
    const double l = std::log(std::clamp(color[i], kMinColor, 1.0)) / p;
    sigma[i] = l * l;
  }
  return sigma;
}

/// d'Eon's melanin amount of a concentration: −ln(max(1 − concentration, 0.0001)).
inline double melaninAmount(double concentration) { return -std::log(std::max(1.0 - concentration, 0.0001)); }
/// amount · (−ln pigment) per channel: a pigment's absorption (a colour at or
/// below 0 read as 1e-30, where MaterialX's −ln is infinite).
inline Vec3 pigmentAbsorption(double amount, const Vec3& pigment) {
  Vec3 sigma;
  for (int i = 0; i < 3; ++i) sigma[i] = amount * -std::log(std::max(pigment[i], 1e-30));
  return sigma;
}
/// deon_hair_absorption_from_melanin.
inline Vec3 absorptionFromMelanin(double concentration, double redness, const Vec3& eumelanin, const Vec3& pheomelanin) {
  const double melanin = melaninAmount(concentration);
  const Vec3 eu = pigmentAbsorption(melanin * (1.0 - redness), eumelanin);
  const Vec3 pheo = pigmentAbsorption(melanin * redness, pheomelanin);
  return {std::max(eu[0] + pheo[0], 0.0), std::max(eu[1] + pheo[1], 0.0), std::max(eu[2] + pheo[2], 0.0)};
}

/// The `hair` node's base colour for absorption sigma at azimuthal roughness
/// bn: exp(−sqrt(sigma) P(bn)), the exact inverse of its sigma = (ln c / P(bn))^2.
inline Vec3 colorOfAbsorption(const Vec3& sigma, double azimuthalRoughness) {
  const double p = absorptionDenominator(azimuthalRoughness);
  Vec3 c;
  for (int i = 0; i < 3; ++i) c[i] = std::exp(-std::sqrt(std::max(sigma[i], 0.0)) * p);
  return c;
}

/// MaterialX's cuticle_angle (0.5: no tilt) as the `hair` node's angle, in
/// degrees: the one whose lobes peak where MaterialX's do (see above).
inline double cuticleDegrees(double cuticleAngle) { return (0.5 - cuticleAngle) * 180.0; }

}  // namespace substratec::import::hair
