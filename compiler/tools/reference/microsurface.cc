// The microsurface random walk (microsurface.h has the contract). It follows
// the supplemental code of Heitz, Hanika, d'Eon and Dachsbacher 2016
// ("Multiple-scattering microfacet BSDFs with the Smith model"), in double
// precision, section by section:
//   1. the uniform height distribution on [-1, 1] (P1, C1, invC1);
//   2. the GGX slope distribution, anisotropic by stretch (alphaX along x):
//      D, Smith Lambda, the projected area, the visible-normal density D_wi
//      and its sampling (Heitz 2018, "Sampling the GGX distribution of visible
//      normals", valid for directions below the horizon too: the sampled disk
//      is then the half-disk minus the half-ellipse);
//   3. G_1(w, h) = C1(h)^Lambda(w) and the height of the next intersection;
//   4. Fresnel: exact dielectric, exact conductor (complex IOR), Gulbrandsen
//      2014's artist mapping;
//   5. the walk: one state (side, local direction, local height, weight) that
//      the sampler advances and the evaluator advances with next-event
//      estimation at each vertex.
// Sides: the walk is always started from above (a dielectric seen from below
// is the same problem with every direction negated and eta inverted). Below
// the microsurface the walk runs in the flipped frame (h -> -h, w -> -w), as
// Heitz's MicrosurfaceDielectric does, so one set of formulas serves both
// sides; `eta` of the current side is n(other side) / n(this side).
#include "reference/microsurface.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

namespace substratec::reference {
namespace microsurface_detail {

using V = V3<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kMinAlpha = 1e-3;

double dot(const V& a, const V& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V scale(const V& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
V add(const V& a, const V& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V neg(const V& a) { return {-a[0], -a[1], -a[2]}; }
V normalize(const V& a) {
  double l = std::sqrt(dot(a, a));
  return l > 0 ? scale(a, 1 / l) : V{0, 0, 1};
}
bool finite(const V& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }
V mul(const V& a, const V& b) { return {a[0] * b[0], a[1] * b[1], a[2] * b[2]}; }

// --- 1. Uniform heights on [-1, 1].
double C1(double h) { return std::clamp(0.5 * (h + 1), 0.0, 1.0); }
double invC1(double u) { return std::clamp(2 * u - 1, -1.0, 1.0); }
// Above the microsurface: where every walk starts (Heitz: 1 + invC1(0.999)).
const double kStartHeight = 1 + invC1(0.999);

// --- 2. GGX slopes (Trowbridge-Reitz), stretched by (ax, ay).
struct Slopes {
  double ax, ay;
  /// alpha_i^2 tan^2(theta) * cos^2(theta): the stretched tangential length^2.
  double q(const V& w) const { return ax * ax * w[0] * w[0] + ay * ay * w[1] * w[1]; }
  /// D(m) for a unit normal m (0 below the horizon).
  double D(const V& m) const {
    if (m[2] <= 0) return 0;
    double s = m[2] * m[2] + m[0] * m[0] / (ax * ax) + m[1] * m[1] / (ay * ay);
    return 1 / (kPi * ax * ay * s * s);
  }
  /// Smith Lambda(w) for a direction on either side (Lambda(-w) = -1 - Lambda(w)).
  double Lambda(const V& w) const {
    double z2 = w[2] * w[2];
    if (z2 == 0) return std::numeric_limits<double>::infinity();
    double t = q(w) / z2;                              // alpha_i^2 tan^2(theta)
    double up = t / (2 * (std::sqrt(1 + t) + 1));      // (sqrt(1+t) - 1) / 2, stable at t -> 0
    return w[2] > 0 ? up : -1 - up;
  }
  /// The microsurface's area projected along w, per unit area of the mean
  /// plane: 0.5 (z + sqrt(z^2 + q)) = z (1 + Lambda(w)), for either side.
  double projectedArea(const V& w) const {
    double z = w[2], qq = q(w), r = std::sqrt(z * z + qq);
    return z >= 0 ? 0.5 * (z + r) : 0.5 * qq / (r - z);
  }
  /// The density of the normals visible from w: <w, m>+ D(m) / projectedArea(w).
  double Dwi(const V& w, const V& m) const {
    double a = projectedArea(w), c = dot(w, m);
    return (a > 0 && c > 0) ? c * D(m) / a : 0;
  }
  /// Samples a normal with density Dwi(w, .) (Heitz 2018).
  V sampleDwi(const V& w, double u1, double u2) const {
    V vh = normalize({ax * w[0], ay * w[1], w[2]});
    double lensq = vh[0] * vh[0] + vh[1] * vh[1];
    V t1 = lensq > 0 ? scale(V{-vh[1], vh[0], 0}, 1 / std::sqrt(lensq)) : V{1, 0, 0};
    V t2{vh[1] * t1[2] - vh[2] * t1[1], vh[2] * t1[0] - vh[0] * t1[2], vh[0] * t1[1] - vh[1] * t1[0]};
    double r = std::sqrt(u1), phi = 2 * kPi * u2;
    double p1 = r * std::cos(phi), p2 = r * std::sin(phi);
    double s = 0.5 * (1 + vh[2]);
    p2 = (1 - s) * std::sqrt(std::max(0.0, 1 - p1 * p1)) + s * p2;
    double p3 = std::sqrt(std::max(0.0, 1 - p1 * p1 - p2 * p2));
    V nh = add(add(scale(t1, p1), scale(t2, p2)), scale(vh, p3));
    return normalize({ax * nh[0], ay * nh[1], std::max(1e-12, nh[2])});
  }
};

// --- 3. Shadowing and the next intersection.

/// The probability that a ray leaving height h along w escapes the microsurface.
double G1(const Slopes& sl, const V& w, double h) {
  if (w[2] <= 0) return 0;
  double lambda = sl.Lambda(w);
  return lambda <= 0 ? 1.0 : std::pow(C1(h), lambda);
}

/// The height of the next intersection of the ray (h, w); false if it escapes.
/// A downward ray always hits (G_1 = 0).
bool nextHeight(const Slopes& sl, const V& w, double h, double u, double& hit) {
  double lambda = sl.Lambda(w);
  if (w[2] > 0 && (lambda <= 0 || u > 1 - G1(sl, w, h))) return false;
  if (!std::isfinite(lambda)) {  // horizontal: the next hit is where it is
    hit = h;
    return true;
  }
  hit = invC1(C1(h) / std::pow(1 - u, 1 / lambda));
  return std::isfinite(hit);
}

}  // namespace microsurface_detail

// --- 4. Fresnel.

double fresnelConductor(double cosThetaI, double n, double k) {
  using C = std::complex<double>;
  double ci = std::clamp(cosThetaI, 0.0, 1.0);
  C eta(n, k);
  C sin2t = C(1 - ci * ci) / (eta * eta);
  C ct = std::sqrt(C(1) - sin2t);
  C dParl = eta * ci + ct, dPerp = ci + eta * ct;
  if (std::norm(dParl) == 0 || std::norm(dPerp) == 0) return 1;
  double rParl = std::norm((eta * ci - ct) / dParl), rPerp = std::norm((ci - eta * ct) / dPerp);
  return std::clamp(0.5 * (rParl + rPerp), 0.0, 1.0);
}

void conductorIor(double r, double g, double& n, double& k) {
  r = std::clamp(r, 0.0, 0.9999);
  g = std::clamp(g, 0.0, 0.9999);
  double sr = std::sqrt(r);
  n = g * (1 - r) / (1 + r) + (1 - g) * (1 + sr) / (1 - sr);
  k = std::sqrt(std::max(0.0, (r * (n + 1) * (n + 1) - (n - 1) * (n - 1)) / (1 - r)));
}

namespace microsurface_detail {

/// Exact unpolarized dielectric Fresnel at cos(theta_i) = ci >= 0 into a medium
/// of relative index eta = n_t / n_i (1 on total internal reflection).
double fresnelDielectric(double ci, double eta) {
  ci = std::clamp(ci, 0.0, 1.0);
  double s2t = (1 - ci * ci) / (eta * eta);
  if (s2t >= 1) return 1;
  double ct = std::sqrt(1 - s2t);
  double ds = ci + eta * ct, dp = eta * ci + ct;
  if (ds <= 0 || dp <= 0) return 1;
  double rs = (ci - eta * ct) / ds, rp = (eta * ci - ct) / dp;
  return 0.5 * (rs * rs + rp * rp);
}

/// v refracted through the facet m (v . m > 0, no TIR) into relative index eta.
V refract(const V& v, const V& m, double eta) {
  double ci = dot(v, m);
  double ct = std::sqrt(std::max(0.0, 1 - (1 - ci * ci) / (eta * eta)));
  return normalize(add(scale(v, -1 / eta), scale(m, ci / eta - ct)));
}
V reflect(const V& v, const V& m) { return add(neg(v), scale(m, 2 * dot(v, m))); }

// --- 5. The walk.

/// The state of one walk: the ray (local direction w and height h, in the
/// frame of the side it is on), the side (+1 the side it arrived from, -1 the
/// other), its weight per channel and the number of vertices so far.
struct Walk {
  const Microsurface& m;
  Slopes sl;
  double eta0;  // n(other side) / n(arrival side), dielectric
  Transport mode;
  V w;
  double h = kStartHeight;
  int side = 1, order = 0;
  V weight{1, 1, 1};

  int maxOrder() const { return m.maxOrder > 0 ? std::min(m.maxOrder, kMaxMicrosurfaceOrder) : kMaxMicrosurfaceOrder; }
  double eta() const { return side > 0 ? eta0 : 1 / eta0; }
  /// The weight's factor of one refraction into relative index e.
  double refractionFactor(double e) const { return mode == Transport::Radiance ? 1 / (e * e) : 1.0; }

  /// The conductor's Fresnel per channel (computed once for grey n, k).
  V conductorFresnel(double c) const {
    double f0 = fresnelConductor(c, m.n[0], m.k[0]);
    if (m.n[1] == m.n[0] && m.n[2] == m.n[0] && m.k[1] == m.k[0] && m.k[2] == m.k[0]) return {f0, f0, f0};
    return {f0, fresnelConductor(c, m.n[1], m.k[1]), fresnelConductor(c, m.n[2], m.k[2])};
  }

  /// Samples the phase function at the current vertex (the ray arrived along w).
  bool scatter(SplitMix64& rng) {
    V v = neg(w);
    double u1 = rng.uniform(), u2 = rng.uniform();
    V mn = sl.sampleDwi(v, u1, u2);
    double c = std::max(0.0, dot(v, mn));
    if (m.kind == Microsurface::Kind::Conductor) {
      weight = mul(weight, conductorFresnel(c));
      w = reflect(v, mn);
      return finite(w);
    }
    double e = eta();
    if (rng.uniform() < fresnelDielectric(c, e)) {
      w = reflect(v, mn);
    } else {
      weight = scale(weight, refractionFactor(e));
      w = neg(refract(v, mn, e));  // in the other side's (flipped) frame
      h = -h;
      side = -side;
    }
    return finite(w);
  }

  /// phase(v, wl) where wl (local frame) is on the current side (reflection).
  V reflectionPhase(const V& v, const V& wl) const {
    V wh = add(v, wl);
    if (dot(wh, wh) == 0) return {0, 0, 0};
    wh = normalize(wh);
    if (wh[2] <= 0) return {0, 0, 0};
    double c = dot(v, wh);
    if (c <= 0) return {0, 0, 0};
    double p = 0.25 * sl.Dwi(v, wh) / c;
    if (m.kind == Microsurface::Kind::Dielectric) return scale(V{1, 1, 1}, p * fresnelDielectric(c, eta()));
    return scale(conductorFresnel(c), p);
  }

  /// phase(v, wl) where wl (local frame, wl.z < 0) is on the other side
  /// (refraction, Walter et al. 2007's half-vector Jacobian), times the
  /// crossing's transport factor.
  double transmissionPhase(const V& v, const V& wl) const {
    double e = eta();
    V wh = neg(add(v, scale(wl, e)));
    if (dot(wh, wh) == 0) return 0;
    wh = normalize(wh);
    if (wh[2] < 0) wh = neg(wh);
    double ci = dot(v, wh), co = dot(wl, wh);
    if (ci <= 0 || co >= 0) return 0;
    double den = ci + e * co;
    if (den == 0) return 0;
    double p = e * e * (1 - fresnelDielectric(ci, e)) * sl.Dwi(v, wh) * (-co) / (den * den);
    return p * refractionFactor(e);
  }

  /// Next-event estimate towards the global exit wi (in the arrival frame):
  /// phase(-w, wi) G_1(wi, h), shadowing towards the side wi is on. At the
  /// first vertex G_1 is replaced by its expectation over the first hit's
  /// height (C1(h) = U^(1 / (1 + Lambda_o)) from above the surface): the
  /// height-correlated G2 / G1 of Heitz 2014 — same mean, less variance.
  V nextEvent(const V& wi) const {
    V wl = side > 0 ? wi : neg(wi);
    V v = neg(w);
    double lo = order == 1 ? sl.Lambda(v) : 0;
    if (wl[2] > 0) {
      double g = order == 1 ? firstShadowingSame(lo, sl.Lambda(wl)) : G1(sl, wl, h);
      return scale(mul(weight, reflectionPhase(v, wl)), g);
    }
    if (m.kind == Microsurface::Kind::Conductor) return {0, 0, 0};
    double g = order == 1 ? firstShadowingOther(lo, sl.Lambda(neg(wl))) : G1(sl, neg(wl), -h);
    return scale(weight, transmissionPhase(v, wl) * g);
  }
  /// E[C1(h)^li] over the first hit: (1 + lo) / (1 + lo + li).
  static double firstShadowingSame(double lo, double li) {
    if (!std::isfinite(li)) return 0;
    return (1 + lo) / (1 + lo + li);
  }
  /// E[(1 - C1(h))^li] over the first hit: a B(a, li + 1), a = 1 + lo.
  static double firstShadowingOther(double lo, double li) {
    if (!std::isfinite(li) || !std::isfinite(lo)) return 0;
    double a = 1 + lo;
    return a * std::exp(std::lgamma(a) + std::lgamma(li + 1) - std::lgamma(a + li + 1));
  }
};

/// The walk's frame: a dielectric arriving from below is the problem from
/// above with directions negated and eta inverted (`flip` = -1).
Walk startWalk(const Microsurface& m, const V& wo, Transport mode, double& flip) {
  flip = wo[2] < 0 ? -1.0 : 1.0;
  double eta = std::max(m.eta, 1e-6);
  Slopes sl{std::clamp(m.alphaX, kMinAlpha, 1e3), std::clamp(m.alphaY, kMinAlpha, 1e3)};
  Walk walk{m, sl, flip > 0 ? eta : 1 / eta, mode, neg(scale(wo, flip))};
  return walk;
}

/// True for the directions the microsurface walks (unit-ish, finite, off the
/// horizon; a conductor from above only).
bool walkable(const Microsurface& m, const V& wo) {
  if (!finite(wo) || wo[2] == 0) return false;
  return m.kind == Microsurface::Kind::Dielectric || wo[2] > 0;
}

bool sampleImpl(const Microsurface& m, const V& wo, Transport mode, SplitMix64& rng, MicrosurfaceSample& s) {
  if (!walkable(m, wo)) return false;
  V won = normalize(wo);
  if (m.kind == Microsurface::Kind::Dielectric && m.eta == 1) {  // index-matched: a pass-through
    s.wi = neg(won);
    s.weight = V{1, 1, 1};
    s.reflected = false;
    return true;
  }
  double flip;
  Walk walk = startWalk(m, won, mode, flip);
  while (true) {
    double hit;
    if (!nextHeight(walk.sl, walk.w, walk.h, rng.uniform(), hit)) break;
    if (++walk.order > walk.maxOrder()) return false;
    walk.h = hit;
    if (!walk.scatter(rng)) return false;
  }
  if (walk.order == 0 || !finite(walk.weight)) return false;
  V wl = walk.side > 0 ? walk.w : neg(walk.w);
  s.wi = scale(wl, flip);
  s.weight = walk.weight;
  s.reflected = walk.side > 0;
  return true;
}

V evalImpl(const Microsurface& m, const V& wo, const V& wi, Transport mode, SplitMix64& rng) {
  V sum{0, 0, 0};
  if (!walkable(m, wo) || !finite(wi) || wi[2] == 0) return sum;
  if (m.kind == Microsurface::Kind::Conductor && wi[2] < 0) return sum;
  if (m.kind == Microsurface::Kind::Dielectric && m.eta == 1) return sum;  // a pass-through: a delta, no density
  double flip;
  Walk walk = startWalk(m, normalize(wo), mode, flip);
  V wiA = scale(normalize(wi), flip);
  while (walk.order < walk.maxOrder()) {
    double hit;
    if (!nextHeight(walk.sl, walk.w, walk.h, rng.uniform(), hit)) break;
    ++walk.order;
    walk.h = hit;
    V c = walk.nextEvent(wiA);
    if (finite(c)) sum = add(sum, c);
    if (walk.order == walk.maxOrder() || !walk.scatter(rng)) break;
  }
  return sum;
}

double pdfImpl(const Microsurface& m, const V& wo, const V& wi) {
  // The single-scattering density of the walk's first vertex (the visible
  // normal's reflection or refraction, chosen by Fresnel for a dielectric),
  // unshadowed, plus a floor (a cosine lobe on both sides and a uniform part)
  // standing for the multiple orders. A proxy for MIS weights only.
  if (!walkable(m, wo) || !finite(wi)) return 0;
  double flip;
  Microsurface single = m;
  if (m.kind == Microsurface::Kind::Conductor) {  // n = 0, k = 1: F = 1 at every angle (no Fresnel weighting)
    single.n = V{0, 0, 0};
    single.k = V{1, 1, 1};
  }
  Walk walk = startWalk(single, normalize(wo), Transport::Importance, flip);
  V wl = scale(normalize(wi), flip);
  V v = neg(walk.w);
  double p = wl[2] > 0 ? walk.reflectionPhase(v, wl)[0]
                       : (m.kind == Microsurface::Kind::Dielectric ? walk.transmissionPhase(v, wl) : 0.0);
  if (!std::isfinite(p)) p = 0;
  double floorWeight = m.maxOrder == 1 ? 0.01 : 0.1;
  return p + floorWeight * (std::abs(wl[2]) / kPi + 0.01 / (4 * kPi));
}

}  // namespace microsurface_detail

bool sampleMicrosurface(const Microsurface& m, const V3<double>& wo, Transport mode, SplitMix64& rng,
                        MicrosurfaceSample& s) {
  return microsurface_detail::sampleImpl(m, wo, mode, rng, s);
}

V3<double> evalMicrosurface(const Microsurface& m, const V3<double>& wo, const V3<double>& wi, Transport mode,
                            SplitMix64& rng) {
  return microsurface_detail::evalImpl(m, wo, wi, mode, rng);
}

double pdfMicrosurface(const Microsurface& m, const V3<double>& wo, const V3<double>& wi) {
  return microsurface_detail::pdfImpl(m, wo, wi);
}

}  // namespace substratec::reference
