#include "reference/hair_truth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace substratec::reference {

namespace {

using Rgb = std::array<double, 3>;
using Lobes = std::array<Rgb, 4>;  // per lobe p = 0..3, per channel

constexpr double kPi = std::numbers::pi;
constexpr double kMinBeta = 0.01;  // keeps every rule of hairQuadrature under kMaxPanels panels
constexpr int kMinPanels = 4, kMaxPanels = 4096;
// The gamma rule's floor: N_p, wrapped into [-pi, pi], has a kink where the
// wrap folds it (dphi = +-pi), which a wide logistic (beta_n > 0.5) does not
// make negligible; the far field's gamma integrand has it at every phi. With
// 4 panels the white furnace is off by 2e-5 at beta_n = 0.9, with 16 by 2e-6.
constexpr int kMinGammaPanels = 16;

double sq(double x) { return x * x; }
double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }
bool finite(const Rgb& c) { return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]); }

// ---------------------------------------------------------------------------
// Quadrature: composite 8-point Gauss-Legendre.

constexpr std::array<double, 4> kGlX{0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                     0.9602898564975363};
constexpr std::array<double, 4> kGlW{0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                     0.1012285362903763};

struct Node {
  double x, w;
};

/// The nodes and weights of the composite 8-point Gauss-Legendre rule over
/// [a, b] with `panels` equal panels (clamped to [1, kMaxPanels]): exact for
/// polynomials of degree 15 on every panel.
std::vector<Node> compositeRule(double a, double b, int panels) {
  panels = std::clamp(panels, 1, kMaxPanels);
  std::vector<Node> nodes;
  nodes.reserve(8 * static_cast<std::size_t>(panels));
  const double width = (b - a) / panels, r = 0.5 * width;
  for (int i = 0; i < panels; ++i) {
    const double c = a + (i + 0.5) * width;
    for (int k = 0; k < 4; ++k) {
      nodes.push_back({c - r * kGlX[k], r * kGlW[k]});
      nodes.push_back({c + r * kGlX[k], r * kGlW[k]});
    }
  }
  return nodes;
}

/// ceil(length / width) panels, clamped to [least, kMaxPanels].
int panelsFor(double length, double width, int least) {
  const double n = width > 0 ? std::ceil(length / width) : kMaxPanels;
  return static_cast<int>(std::clamp(n, double(least), double(kMaxPanels)));
}

// ---------------------------------------------------------------------------
// The model's constants (pbrt-v4's HairBxDF constructor).

struct Derived {
  std::array<double, 4> v;               // longitudinal variances per lobe
  double s;                              // azimuthal logistic scale
  double trim;                           // 1 / (CDF(pi) - CDF(-pi)) of that logistic
  std::array<double, 3> sin2k, cos2k;    // sin and cos of 2^k alpha, k = 0, 1, 2
};

double logisticCdf(double x, double s) { return 1 / (1 + std::exp(-x / s)); }

/// v_0 = (0.726 b + 0.812 b^2 + 3.7 b^20)^2, v_1 = v_0 / 4, v_2 = v_3 = 4 v_0;
/// s = sqrt(pi / 8) (0.265 b + 1.194 b^2 + 5.372 b^22); the scale tilts by
/// the double-angle recurrences from alpha. Betas clamped to [kMinBeta, 1].
Derived derive(const HairParams& p) {
  Derived d{};
  const double bm = std::clamp(p.betaM, kMinBeta, 1.0), bn = std::clamp(p.betaN, kMinBeta, 1.0);
  d.v[0] = sq(0.726 * bm + 0.812 * bm * bm + 3.7 * std::pow(bm, 20));
  d.v[1] = 0.25 * d.v[0];
  d.v[2] = d.v[3] = 4 * d.v[0];
  d.s = std::sqrt(kPi / 8) * (0.265 * bn + 1.194 * bn * bn + 5.372 * std::pow(bn, 22));
  d.trim = 1 / (logisticCdf(kPi, d.s) - logisticCdf(-kPi, d.s));
  d.sin2k[0] = std::sin(p.alphaDeg * kPi / 180);
  d.cos2k[0] = std::sqrt(std::max(0.0, 1 - sq(d.sin2k[0])));
  for (int k = 1; k < 3; ++k) {
    d.sin2k[k] = 2 * d.cos2k[k - 1] * d.sin2k[k - 1];
    d.cos2k[k] = sq(d.cos2k[k - 1]) - sq(d.sin2k[k - 1]);
  }
  return d;
}

// ---------------------------------------------------------------------------
// The longitudinal lobes.

/// log I0(x), x >= 0. Below 500, the log of std::cyl_bessel_i (accurate to
/// double; pbrt's 10-term series is not, e.g. 2 % low at x = 12); above it (I0
/// overflows a double near 713) the asymptotic expansion
/// I0(x) = e^x / sqrt(2 pi x) (1 + 1/(8x) + 9/(128x^2) + 225/(3072x^3) + ...),
/// whose first omitted term is below 2e-12 there (pbrt keeps only 1/(8x), past x = 12).
double logI0(double x) {
  if (x < 500) return std::log(std::cyl_bessel_i(0.0, x));
  const double y = 1 / x;
  return x - 0.5 * std::log(2 * kPi * x) + std::log1p(y * (1.0 / 8 + y * (9.0 / 128 + y * (225.0 / 3072))));
}

/// log sinh(x), x > 0, without overflow: x - ln 2 + log(1 - e^{-2x}).
double logSinh(double x) { return x - std::numbers::ln2 + std::log(-std::expm1(-2 * x)); }

/// M_p: the azimuthal integral of the von Mises-Fisher lobe of concentration
/// 1/v about the direction (cosO, -sinO), e^{-b} I0(a) / (2 v sinh(1/v)) with
/// a = cosI cosO / v, b = sinI sinO / v, in logs at every v (pbrt's small-v
/// branch is this with log(1 - e^{-2/v}) dropped and ln 2 ~ 0.6931).
double longitudinalLobe(double cosI, double cosO, double sinI, double sinO, double v) {
  const double a = cosI * cosO / v, b = sinI * sinO / v;
  return std::exp(logI0(a) - b - std::log(2 * v) - logSinh(1 / v));
}

/// sin and |cos| of lobe p's outgoing angle tilted by the cuticle scales:
/// theta_o - 2 alpha (R), theta_o + alpha (TT), theta_o + 4 alpha (TRT).
std::pair<double, double> tiltedOut(int p, double sinO, double cosO, const Derived& d) {
  if (p == 0) return {sinO * d.cos2k[1] - cosO * d.sin2k[1], std::abs(cosO * d.cos2k[1] + sinO * d.sin2k[1])};
  if (p == 1) return {sinO * d.cos2k[0] + cosO * d.sin2k[0], std::abs(cosO * d.cos2k[0] - sinO * d.sin2k[0])};
  return {sinO * d.cos2k[2] + cosO * d.sin2k[2], std::abs(cosO * d.cos2k[2] - sinO * d.sin2k[2])};
}

double cosFromSin(double s) { return std::sqrt(std::max(0.0, 1 - s * s)); }

std::array<double, 4> longitudinal(const Derived& d, double sinO, double sinI) {
  sinO = std::clamp(sinO, -1.0, 1.0);
  sinI = std::clamp(sinI, -1.0, 1.0);
  const double cosO = cosFromSin(sinO), cosI = cosFromSin(sinI);
  std::array<double, 4> m{};
  for (int p = 0; p < 3; ++p) {
    const auto [sinP, cosP] = tiltedOut(p, sinO, cosO, d);
    m[p] = longitudinalLobe(cosI, cosP, sinI, sinP, d.v[p]);
  }
  m[3] = longitudinalLobe(cosI, cosO, sinI, sinO, d.v[3]);
  return m;
}

// ---------------------------------------------------------------------------
// The attenuations and the azimuthal lobes at one offset h.

/// Unpolarised Fresnel reflectance of a dielectric of relative index eta > 1
/// seen from outside at cos(theta) = cosI.
double fresnelDielectric(double cosI, double eta) {
  cosI = std::clamp(cosI, 0.0, 1.0);
  const double sin2T = (1 - cosI * cosI) / (eta * eta);
  if (sin2T >= 1) return 1;
  const double cosT = std::sqrt(1 - sin2T);
  const double rPar = (eta * cosI - cosT) / (eta * cosI + cosT), rPerp = (cosI - eta * cosT) / (cosI + eta * cosT);
  return 0.5 * (rPar * rPar + rPerp * rPerp);
}

/// The path through the fibre at offset h for the view at sinO: gamma_o,
/// gamma_t (refracted with the modified index eta' = sqrt(eta^2 - sin^2
/// theta_o) / cos theta_o, Bravais), and the attenuations A_p.
struct Chord {
  double gammaO, gammaT;
  Lobes a;
};

Lobes attenuations(double f, const Rgb& t) {
  Lobes a{};
  for (int c = 0; c < 3; ++c) {
    a[0][c] = f;
    a[1][c] = sq(1 - f) * t[c];
    a[2][c] = a[1][c] * t[c] * f;
    const double rest = 1 - f * t[c];
    a[3][c] = rest > 0 ? a[2][c] * f * t[c] / rest : 0;
  }
  return a;
}

Chord chord(const HairParams& p, double h, double sinO) {
  h = std::clamp(h, -1.0, 1.0);
  sinO = std::clamp(sinO, -1.0, 1.0);
  const double cosO = cosFromSin(sinO), cosT = cosFromSin(sinO / p.eta);
  const double etap = std::sqrt(std::max(0.0, p.eta * p.eta - sinO * sinO)) / cosO;  // +inf at cosO = 0
  const double sinGammaT = h / etap, cosGammaT = cosFromSin(sinGammaT);
  Rgb t;
  for (int c = 0; c < 3; ++c) t[c] = std::exp(-p.sigmaA[c] * (2 * cosGammaT / cosT));
  return {std::asin(h), std::asin(sinGammaT), attenuations(fresnelDielectric(cosO * cosFromSin(h), p.eta), t)};
}

/// The trimmed logistic N_p(phi): scale s about Phi(p) = 2 p gamma_t - 2
/// gamma_o + p pi, the difference wrapped into [-pi, pi] (std::remainder).
double azimuthalLobe(double phi, int p, const Derived& d, const Chord& ch) {
  const double dphi = std::remainder(phi - (2 * p * ch.gammaT - 2 * ch.gammaO + p * kPi), 2 * kPi);
  const double e = std::exp(-std::abs(dphi) / d.s);
  return d.trim * e / (d.s * sq(1 + e));
}

/// Adds w times the lobes' azimuthal terms at one chord — A_p N_p(phi) for
/// p < 3, A_3 / (2 pi) — to out[j] for every phis[j].
void addAzimuthalTerms(const Derived& d, const Chord& ch, const std::vector<double>& phis, double w,
                       std::vector<Lobes>& out) {
  for (std::size_t j = 0; j < phis.size(); ++j) {
    for (int p = 0; p < 3; ++p) {
      const double n = w * azimuthalLobe(phis[j], p, d, ch);
      for (int c = 0; c < 3; ++c) out[j][p][c] += ch.a[p][c] * n;
    }
    for (int c = 0; c < 3; ++c) out[j][3][c] += w * ch.a[3][c] / (2 * kPi);
  }
}

/// chiangAzimuthal at every phi of `phis`: the chord (the costly part) once
/// per node of the gamma rule, the logistics per phi; weight 1/2 cos(gamma).
std::vector<Lobes> azimuthalTable(const HairParams& p, const Derived& d, double sinO, const std::vector<double>& phis,
                                  int gammaPanels) {
  std::vector<Lobes> out(phis.size(), Lobes{});
  for (const Node& g : compositeRule(-0.5 * kPi, 0.5 * kPi, gammaPanels))
    addAzimuthalTerms(d, chord(p, std::sin(g.x), sinO), phis, 0.5 * g.w * std::cos(g.x), out);
  return out;
}

Rgb combine(const std::array<double, 4>& m, const Lobes& az) {
  Rgb r{0, 0, 0};
  for (int p = 0; p < 4; ++p)
    for (int c = 0; c < 3; ++c) r[c] += m[p] * az[p][c];
  return r;
}

double colourPolynomial(double bn) {
  return 5.969 - 0.215 * bn + 2.532 * bn * bn - 10.73 * std::pow(bn, 3) + 5.574 * std::pow(bn, 4) +
         0.245 * std::pow(bn, 5);
}

/// The albedo rules' nodes: theta_i over [-pi/2, pi/2] with the weight
/// cos(theta_i) folded in (d sin theta_i = cos theta_i d theta_i), phi over
/// [0, pi] with the weight doubled (the far field is even in phi).
std::pair<std::vector<Node>, std::vector<Node>> albedoRule(const HairQuadrature& q) {
  std::vector<Node> theta = compositeRule(-0.5 * kPi, 0.5 * kPi, q.thetaPanels);
  for (Node& n : theta) n.w *= std::cos(n.x);
  std::vector<Node> phi = compositeRule(0, kPi, q.phiPanels);
  for (Node& n : phi) n.w *= 2;
  return {theta, phi};
}

}  // namespace

std::array<double, 3> hairSigmaAFromColor(const std::array<double, 3>& c, double betaN) {
  const double poly = colourPolynomial(betaN);
  Rgb s;
  for (int i = 0; i < 3; ++i) s[i] = sq(std::log(std::clamp(c[i], 1e-6, 1.0)) / poly);
  return s;
}

std::array<double, 3> hairColorFromSigmaA(const std::array<double, 3>& sigmaA, double betaN) {
  const double poly = colourPolynomial(betaN);
  Rgb c;
  for (int i = 0; i < 3; ++i) c[i] = std::exp(-std::sqrt(std::max(0.0, sigmaA[i])) * poly);
  return c;
}

std::array<double, 3> hairSigmaAFromMelanin(double eumelanin, double pheomelanin) {
  const Rgb eu{0.419, 0.697, 1.37}, pheo{0.187, 0.4, 1.05};
  Rgb s;
  for (int i = 0; i < 3; ++i) s[i] = eumelanin * eu[i] + pheomelanin * pheo[i];
  return s;
}

std::array<std::array<double, 3>, 4> chiangAttenuation(const HairParams& p, double h, double sinThetaO) {
  return chord(p, h, sinThetaO).a;
}

std::array<double, 4> chiangLongitudinal(const HairParams& p, double sinThetaO, double sinThetaI) {
  return longitudinal(derive(p), sinThetaO, sinThetaI);
}

std::array<double, 3> chiangLobeSum(const HairParams& p, double h, double sinThetaO, double sinThetaI, double phi) {
  const Derived d = derive(p);
  std::vector<Lobes> az(1, Lobes{});
  addAzimuthalTerms(d, chord(p, h, sinThetaO), {phi}, 1.0, az);
  return combine(longitudinal(d, sinThetaO, sinThetaI), az[0]);
}

HairQuadrature hairQuadrature(const HairParams& p) {
  const Derived d = derive(p);
  return {panelsFor(kPi, 2 * d.s, kMinGammaPanels), panelsFor(kPi, 2 * std::sqrt(d.v[1]), kMinPanels),
          panelsFor(kPi, 2 * d.s, kMinPanels)};
}

std::array<std::array<double, 3>, 4> chiangAzimuthal(const HairParams& p, double sinThetaO, double phi,
                                                      int gammaPanels) {
  const int panels = gammaPanels > 0 ? gammaPanels : hairQuadrature(p).gammaPanels;
  return azimuthalTable(p, derive(p), sinThetaO, {phi}, panels)[0];
}

std::array<double, 3> chiangFarField(const HairParams& p, double sinThetaO, double sinThetaI, double phi,
                                     int gammaPanels) {
  return combine(chiangLongitudinal(p, sinThetaO, sinThetaI), chiangAzimuthal(p, sinThetaO, phi, gammaPanels));
}

std::array<double, 3> chiangFarField(const HairParams& p, double sinThetaO, double sinThetaI, double phi) {
  return chiangFarField(p, sinThetaO, sinThetaI, phi, 0);
}

std::array<double, 3> chiangFarField(const HairParams& p, const std::array<double, 3>& V,
                                     const std::array<double, 3>& L, const std::array<double, 3>& T) {
  auto dot = [](const Rgb& a, const Rgb& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const double tl = std::sqrt(dot(T, T));
  const Rgb t{T[0] / tl, T[1] / tl, T[2] / tl};
  const double sinO = std::clamp(dot(V, t), -1.0, 1.0), sinI = std::clamp(dot(L, t), -1.0, 1.0);
  const Rgb vp{V[0] - sinO * t[0], V[1] - sinO * t[1], V[2] - sinO * t[2]};
  const Rgb lp{L[0] - sinI * t[0], L[1] - sinI * t[1], L[2] - sinI * t[2]};
  const double n = std::sqrt(dot(vp, vp) * dot(lp, lp));
  const double cosPhi = n > 0 ? std::clamp(dot(vp, lp) / n, -1.0, 1.0) : 1.0;
  return chiangFarField(p, sinO, sinI, std::acos(cosPhi));
}

/// The product rule over (theta_i, phi) applied to the far field, summed as
/// sum_p (sum_k w_k M_p(theta_k)) (sum_j w_j Az_p(phi_j)): the same sum as
/// evaluating chiangFarField at every node (M_p does not depend on phi nor
/// Az_p on theta_i), at the cost of one gamma integral per phi node.
std::array<double, 3> chiangAlbedo(const HairParams& p, double sinThetaO, const HairQuadrature& q) {
  const Derived d = derive(p);
  const auto [theta, phi] = albedoRule(q);
  std::array<double, 4> mSum{};
  for (const Node& n : theta) {
    const std::array<double, 4> m = longitudinal(d, sinThetaO, std::sin(n.x));
    for (int l = 0; l < 4; ++l) mSum[l] += n.w * m[l];
  }
  std::vector<double> phis;
  for (const Node& n : phi) phis.push_back(n.x);
  const std::vector<Lobes> az = azimuthalTable(p, d, sinThetaO, phis, q.gammaPanels);
  Lobes azSum{};
  for (std::size_t j = 0; j < phi.size(); ++j)
    for (int l = 0; l < 4; ++l)
      for (int c = 0; c < 3; ++c) azSum[l][c] += phi[j].w * az[j][l][c];
  return combine(mSum, azSum);
}

std::array<double, 3> chiangAlbedo(const HairParams& p, double sinThetaO) {
  return chiangAlbedo(p, sinThetaO, hairQuadrature(p));
}

std::array<double, 3> hairModelAlbedo(const HairModelFn& model, const HairParams& p, double sinThetaO) {
  const auto [theta, phi] = albedoRule(hairQuadrature(p));
  Rgb sum{0, 0, 0};
  for (const Node& t : theta)
    for (const Node& f : phi) {
      const Rgb v = model(p, sinThetaO, std::sin(t.x), std::cos(f.x));
      for (int c = 0; c < 3; ++c) sum[c] += t.w * f.w * v[c];
    }
  return sum;
}

// ---------------------------------------------------------------------------
// The comparison.

namespace {

constexpr std::array<double, 4> kGridBetas{0.2, 0.3, 0.5, 0.8};
constexpr std::array<double, 4> kGridColours{0.05, 0.3, 0.8, 1.0};  // 1.0: white, sigma_a = 0
constexpr std::array<double, 5> kGridSinO{-0.75, -0.35, 0.0, 0.35, 0.75};
constexpr std::array<double, 7> kGridSinI{-0.9, -0.75, -0.35, 0.0, 0.2, 0.35, 0.75};
constexpr int kGridPhis = 7;  // phi = j pi / 6

double gridPhi(int j) { return j * kPi / (kGridPhis - 1); }

struct GridSet {
  HairParams params;
  double colour;
};

/// The truth on the grid, luminance only: values[set][o][i][phi], the floor
/// of each set, albedos[set][o].
struct TruthGrid {
  std::vector<GridSet> sets;
  std::vector<double> values, floors, albedos;
};

constexpr std::size_t kPerSet = kGridSinO.size() * kGridSinI.size() * kGridPhis;

std::vector<GridSet> gridSets() {
  std::vector<GridSet> sets;
  for (double bm : kGridBetas)
    for (double bn : kGridBetas)
      for (double c : kGridColours) {
        HairParams p;
        p.betaM = bm;
        p.betaN = bn;
        p.sigmaA = c < 1 ? hairSigmaAFromColor({c, c, c}, bn) : Rgb{0, 0, 0};
        sets.push_back({p, c});
      }
  return sets;
}

/// "betaM=.. betaN=.. colour=.. sinThetaO=.." and, for a direction (sinI within [-1, 1]), " sinThetaI=.. phi=..".
std::string describe(const GridSet& s, double sinO, double sinI = 2, double phi = 0) {
  char colour[32] = "white", buf[160];
  if (s.colour < 1) std::snprintf(colour, sizeof colour, "%g", s.colour);
  int n = std::snprintf(buf, sizeof buf, "betaM=%g betaN=%g colour=%s sinThetaO=%g", s.params.betaM, s.params.betaN,
                        colour, sinO);
  if (sinI <= 1) std::snprintf(buf + n, sizeof buf - n, " sinThetaI=%g phi=%g", sinI, phi);
  return buf;
}

void requireFinite(const Rgb& v, const char* what, const std::string& where) {
  if (!finite(v)) throw std::runtime_error(std::string("compareWithTruth: ") + what + " not finite at " + where);
}

/// One set's truth: the grid values (by the factors: one gamma integral per
/// (view, phi)), its floor, its albedos.
void addTruthSet(const GridSet& s, TruthGrid& g) {
  const Derived d = derive(s.params);
  std::vector<double> phis;
  for (int j = 0; j < kGridPhis; ++j) phis.push_back(gridPhi(j));
  double sum = 0;
  for (double sinO : kGridSinO) {
    const std::vector<Lobes> az = azimuthalTable(s.params, d, sinO, phis, hairQuadrature(s.params).gammaPanels);
    for (double sinI : kGridSinI)
      for (int j = 0; j < kGridPhis; ++j) {
        const Rgb v = combine(longitudinal(d, sinO, sinI), az[j]);
        requireFinite(v, "truth", describe(s, sinO, sinI, phis[j]));
        g.values.push_back(luminance(v));
        sum += g.values.back();
      }
    const Rgb a = chiangAlbedo(s.params, sinO);
    requireFinite(a, "truth albedo", describe(s, sinO));
    g.albedos.push_back(luminance(a));
  }
  g.floors.push_back(0.05 * sum / kPerSet);
}

const TruthGrid& truthGrid() {
  static const TruthGrid grid = [] {
    TruthGrid g;
    g.sets = gridSets();
    for (const GridSet& s : g.sets) addTruthSet(s, g);
    return g;
  }();
  return grid;
}

/// The model at every direction of the grid: relative errors into `rel`, the worst into `out`.
void compareDirections(const HairModelFn& model, const TruthGrid& g, std::vector<double>& rel, HairComparison& out) {
  std::size_t k = 0;
  for (std::size_t si = 0; si < g.sets.size(); ++si)
    for (double sinO : kGridSinO)
      for (double sinI : kGridSinI)
        for (int j = 0; j < kGridPhis; ++j, ++k) {
          const Rgb v = model(g.sets[si].params, sinO, sinI, std::cos(gridPhi(j)));
          requireFinite(v, "model", describe(g.sets[si], sinO, sinI, gridPhi(j)));
          rel.push_back(std::abs(luminance(v) - g.values[k]) / std::max(g.values[k], g.floors[si]));
          if (rel.back() > out.maxRel) {
            out.maxRel = rel.back();
            out.worstCase = describe(g.sets[si], sinO, sinI, gridPhi(j));
          }
        }
}

/// The model's albedos against the truth's at every view of every set.
void compareAlbedos(const HairModelFn& model, const TruthGrid& g, HairComparison& out) {
  out.albedoRatioMin = std::numeric_limits<double>::infinity();
  out.albedoRatioMax = -std::numeric_limits<double>::infinity();
  for (std::size_t si = 0; si < g.sets.size(); ++si)
    for (std::size_t o = 0; o < kGridSinO.size(); ++o) {
      const Rgb a = hairModelAlbedo(model, g.sets[si].params, kGridSinO[o]);
      requireFinite(a, "model albedo", describe(g.sets[si], kGridSinO[o]));
      const double m = luminance(a), t = g.albedos[si * kGridSinO.size() + o];
      const double relErr = std::abs(m - t) / t;
      out.albedoRatioMin = std::min(out.albedoRatioMin, m / t);
      out.albedoRatioMax = std::max(out.albedoRatioMax, m / t);
      ++out.albedoCases;
      if (relErr >= out.maxAlbedoRel) {
        out.maxAlbedoRel = relErr;
        out.worstAlbedoModel = m;
        out.worstAlbedoTruth = t;
        out.worstAlbedoCase = describe(g.sets[si], kGridSinO[o]);
      }
    }
}

/// Median (the mean of the middle two of an even count), 95th percentile
/// (nearest rank, ceil(0.95 n)) and mean of `rel`.
void summarize(std::vector<double>& rel, HairComparison& out) {
  std::sort(rel.begin(), rel.end());
  const std::size_t n = rel.size();
  out.cases = static_cast<int>(n);
  out.medianRel = n % 2 ? rel[n / 2] : 0.5 * (rel[n / 2 - 1] + rel[n / 2]);
  out.p95Rel = rel[static_cast<std::size_t>(std::ceil(0.95 * n)) - 1];
  double sum = 0;
  for (double r : rel) sum += r;
  out.meanRel = sum / n;
}

}  // namespace

HairComparison compareWithTruth(const HairModelFn& model) {
  const TruthGrid& g = truthGrid();
  HairComparison out;
  std::vector<double> rel;
  rel.reserve(g.values.size());
  compareDirections(model, g, rel, out);
  if (rel.empty()) throw std::runtime_error("compareWithTruth: no case compared");
  compareAlbedos(model, g, out);
  summarize(rel, out);
  return out;
}

}  // namespace substratec::reference
