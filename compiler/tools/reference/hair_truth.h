// The ground truth for hair: pbrt-v4's HairBxDF, the model of Chiang, Sun and
// Ashikhmin 2016 ("A Practical and Controllable Hair and Fur Model for
// Production Path Tracing"), written again in double precision from the
// published model, with its far field (the average over the fibre offset h),
// its directional albedo, and a harness that measures another hair model
// against it. No shader counterpart: like the other references it is a
// measuring instrument for the tests and the accuracy tools.
//
// The fibre frame. The fibre's tangent is the x axis; a direction w has
// sin(theta) = w.x (theta: its angle to the plane normal to the fibre) and the
// azimuth phi = atan2(w.z, w.y) about the fibre. "O" is the direction to the
// eye, "I" the direction to the light, and phi = phi_i - phi_o.
//
// The model, per fibre offset h in [-1, 1] (gamma_o = asin(h)), as pbrt-v4
// evaluates it: four lobes p = 0 (R), 1 (TT), 2 (TRT), 3 (the rest, TRRT+),
//   S_h = sum_{p<3} M_p(theta_i | theta_o'_p) A_p(h) N_p(phi, h)
//       + M_3(theta_i | theta_o) A_3(h) / (2 pi),
// where M_p is the longitudinal lobe (d'Eon et al. 2011's normalised von
// Mises-Fisher marginal, variance v_p from beta_m, about the outgoing angle
// tilted by the cuticle scales: theta_o - 2 alpha, + alpha, + 4 alpha, none),
// A_p the attenuation (exact dielectric Fresnel at cos(theta_o) cos(gamma_o),
// absorption T = exp(-sigma_a 2 cos(gamma_t) / cos(theta_t)) along a chord of
// the fibre, sigma_a per unit fibre RADIUS as in pbrt), and N_p a logistic in
// phi (scale s from beta_n, trimmed to [-pi, pi]) about the exit azimuth
// Phi(p, h) = 2 p gamma_t - 2 gamma_o + p pi. S_h is pbrt's f times
// |cos theta_i| (pbrt divides by it, its integrator multiplies it back): the
// reflected radiance is L_o = integral over the SPHERE of S L_i d omega_i.
//
// Double precision, and the model rather than its float shortcuts: I0 is the
// accurate modified Bessel function (std::cyl_bessel_i; pbrt's truncated
// 10-term series is off by 2 % at x = 12), log I0 an accurate asymptotic
// expansion past where I0 overflows (pbrt's two-term expansion past x = 12),
// ln 2 exact where pbrt writes 0.6931, and the small-v form of M_p keeps the
// log1p(-e^{-2/v}) term pbrt drops. With those, every M_p integrates to
// exactly 1 over sin(theta_i) and sum_p A_p = 1 without absorption, so the
// far field of a white fibre conserves energy to the quadrature's accuracy
// (the white furnace test in tests/unit/hair_truth_test.cc).
//
// Determinism: every function is a pure function of its arguments (fixed
// quadrature rules; compareWithTruth's grid of truth values is computed once
// and shared, under a function-local static).
#pragma once
#include <array>
#include <functional>
#include <string>

namespace substratec::reference {

struct HairParams {
  std::array<double, 3> sigmaA{0, 0, 0};  // absorption per unit fibre radius, per channel (>= 0)
  double betaM = 0.3;                     // longitudinal roughness, (0, 1] (clamped to [0.01, 1])
  double betaN = 0.3;                     // azimuthal roughness, (0, 1] (clamped to [0.01, 1])
  double eta = 1.55;                      // the fibre's index of refraction, > 1
  double alphaDeg = 2.0;                  // the cuticle scales' tilt, in degrees
};

/// Chiang et al.'s colour mapping: the sigma_a whose far field, at azimuthal
/// roughness beta_n, has (roughly) the multiple-scattered colour c, per
/// channel, c in (0, 1] (clamped to [1e-6, 1]):
/// sigma_a = (ln c / (5.969 - 0.215 b + 2.532 b^2 - 10.73 b^3 + 5.574 b^4 + 0.245 b^5))^2.
std::array<double, 3> hairSigmaAFromColor(const std::array<double, 3>& c, double betaN);

/// The exact inverse of hairSigmaAFromColor: c = exp(-sqrt(sigma_a) poly(beta_n)).
std::array<double, 3> hairColorFromSigmaA(const std::array<double, 3>& sigmaA, double betaN);

/// d'Eon's melanin mapping (pbrt-v4's SigmaAFromConcentration): linear in the
/// concentrations, eumelanin (0.419, 0.697, 1.37), pheomelanin (0.187, 0.4, 1.05).
std::array<double, 3> hairSigmaAFromMelanin(double eumelanin, double pheomelanin);

/// The attenuations A_0..A_3 at fibre offset h (clamped to [-1, 1]) for the
/// view at sinThetaO, per channel: A_0 = F, A_1 = (1 - F)^2 T, A_2 = A_1 T F,
/// A_3 = A_2 F T / (1 - F T) (0 where F T = 1), F the exact dielectric Fresnel
/// at cos(theta_o) cos(gamma_o). Their sum is 1 when sigma_a = 0.
std::array<std::array<double, 3>, 4> chiangAttenuation(const HairParams& p, double h, double sinThetaO);

/// The longitudinal lobes M_0..M_3 for the view at sinThetaO and the light at
/// sinThetaI (M_0..M_2 about the tilted outgoing angles, M_3 untilted). Each
/// integrates to 1 over sinThetaI in [-1, 1].
std::array<double, 4> chiangLongitudinal(const HairParams& p, double sinThetaO, double sinThetaI);

/// One fibre offset h: the lobe sum S_h above for the view at sinThetaO, the
/// light at sinThetaI and the azimuth difference phi = phi_i - phi_o.
std::array<double, 3> chiangLobeSum(const HairParams& p, double h, double sinThetaO, double sinThetaI, double phi);

/// The panels of the composite 8-point Gauss-Legendre rules (the defaults of
/// hairQuadrature; each clamped to [4, 4096], gamma to [16, 4096]):
///  gamma (the far field's h integral, in gamma = asin(h) over [-pi/2, pi/2]):
///    ceil(pi / (2 s)) — panels 2 s wide. N_p is a logistic of scale s in
///    Phi(p, h), which moves at most 2x as fast as gamma, so a panel spans at
///    most 4 s of the logistic, whose poles lie pi s off the real axis: 8-point
///    Gauss-Legendre then converges like 3.4^-16 ~ 1e-9 per panel. At least
///    16 panels: the wrap of N_p into [-pi, pi] leaves a kink at dphi = +-pi,
///    which only matters (1e-6..1e-5) for wide logistics, where 2 s panels are few.
///  theta (the albedo's sin(theta_i) integral, in theta_i over [-pi/2, pi/2],
///    weight cos(theta_i)): ceil(pi / (2 sqrt(v_1))) — panels two standard
///    deviations of the narrowest lobe (TT's, v_1 = v_0 / 4) wide.
///  phi (the albedo's phi integral, over [0, pi] and doubled: the far field is
///    even in phi): ceil(pi / (2 s)) — panels 2 s wide.
/// Convergence under doubling is measured in tests/unit/hair_truth_test.cc.
struct HairQuadrature {
  int gammaPanels = 0, thetaPanels = 0, phiPanels = 0;
};
HairQuadrature hairQuadrature(const HairParams& p);

/// The azimuthal factors of the far field at phi for the view at sinThetaO:
/// 1/2 integral_{-1}^{1} A_p N_p dh for p < 3 and 1/2 integral A_3 dh / (2 pi)
/// (by the gamma rule with `gammaPanels`, 0: hairQuadrature's). The far field
/// is sum_p chiangLongitudinal[p] * chiangAzimuthal[p], since M_p does not
/// depend on h.
std::array<std::array<double, 3>, 4> chiangAzimuthal(const HairParams& p, double sinThetaO, double phi,
                                                      int gammaPanels = 0);

/// The far field: S = 1/2 integral_{-1}^{1} S_h dh (a fibre seen whole, every
/// offset h equally likely), integrated in gamma = asin(h), dh = cos(gamma)
/// d gamma, by the gamma rule of hairQuadrature. Even in phi.
std::array<double, 3> chiangFarField(const HairParams& p, double sinThetaO, double sinThetaI, double phi);
/// The same with `gammaPanels` panels (for convergence checks; 0: hairQuadrature's).
std::array<double, 3> chiangFarField(const HairParams& p, double sinThetaO, double sinThetaI, double phi,
                                     int gammaPanels);

/// The far field from unit directions V (to the eye), L (to the light) and
/// the fibre tangent T (normalised here): sin(theta_o) = V.T, sin(theta_i) =
/// L.T, |phi| the angle between V's and L's projections on the plane normal
/// to T (0 when either lies along T). No normal is needed: the far field
/// depends on phi only through |phi|.
std::array<double, 3> chiangFarField(const HairParams& p, const std::array<double, 3>& V,
                                     const std::array<double, 3>& L, const std::array<double, 3>& T);

/// The directional albedo for the view at sinThetaO: the integral of the far
/// field over the sphere of omega_i (d omega = d sin(theta_i) d phi), by the
/// product of the theta and phi rules of `q` (default: hairQuadrature(p)).
/// 1 to the quadrature's accuracy when sigma_a = 0.
std::array<double, 3> chiangAlbedo(const HairParams& p, double sinThetaO);
std::array<double, 3> chiangAlbedo(const HairParams& p, double sinThetaO, const HairQuadrature& q);

/// A hair model to judge: its far field (the same quantity as chiangFarField)
/// for the parameters, the view's and the light's sin(theta), and cos(phi).
using HairModelFn =
    std::function<std::array<double, 3>(const HairParams&, double sinThetaO, double sinThetaI, double cosPhi)>;

/// The directional albedo of `model` at parameters `p` by exactly
/// chiangAlbedo's rule (the same nodes and weights).
std::array<double, 3> hairModelAlbedo(const HairModelFn& model, const HairParams& p, double sinThetaO);

/// A model against the truth. All figures on the luminance (0.2126, 0.7152,
/// 0.0722) of the RGB values. The relative error of a point is
/// |model - truth| / max(truth, floor), the floor 5 % of the mean truth over
/// the direction grid for that parameter set (so that the far tails of narrow
/// lobes, near zero, do not dominate).
struct HairComparison {
  int cases = 0;          // (direction, parameter set) points compared
  int albedoCases = 0;    // (view, parameter set) albedos compared
  double medianRel = 0, p95Rel = 0, maxRel = 0, meanRel = 0;  // p95: nearest rank, ceil(0.95 n)
  double maxAlbedoRel = 0;                            // max |A_model - A_truth| / A_truth
  double worstAlbedoModel = 0, worstAlbedoTruth = 0;  // the albedos at that max
  double albedoRatioMin = 0, albedoRatioMax = 0;      // min and max of A_model / A_truth
  std::string worstCase, worstAlbedoCase;             // where maxRel and maxAlbedoRel are
};

/// `model` against the truth over a fixed grid:
///  parameter sets: beta_m x beta_n in {0.2, 0.3, 0.5, 0.8}^2 x colour in
///    {0.05, 0.3, 0.8 (grey, sigma_a = hairSigmaAFromColor(c, beta_n)),
///    white (sigma_a = 0)}, eta 1.55, alpha 2 degrees: 64 sets;
///  directions: sinThetaO in {-0.75, -0.35, 0, 0.35, 0.75} x sinThetaI in
///    {-0.9, -0.75, -0.35, 0, 0.2, 0.35, 0.75} x phi in {0, pi/6, ..., pi}
///    (7): 245 per set, 15680 cases;
///  albedos: at every sinThetaO of the grid (5 per set, 320), the model's by
///    hairModelAlbedo, the truth's by chiangAlbedo.
/// The model is called ~2.46 million times (nearly all for the albedos); the
/// truth on the grid is computed once per process.
/// Throws std::runtime_error when it compared no case or a model or truth
/// value is not finite.
HairComparison compareWithTruth(const HairModelFn& model);

}  // namespace substratec::reference
