// The position-free random walk through a layer stack (random_walk.h has the
// model and the estimator; this file follows it section by section):
//   1. random numbers (splitmix64);
//   2. the interfaces: anisotropic GGX (pbrt-v4's TrowbridgeReitzDistribution:
//      D, Smith Lambda, visible-normal sampling), the single-scattering rough
//      dielectric and conductor (pbrt-v4's DielectricBxDF / ConductorBxDF,
//      exact Fresnel), the microsurface walk (microsurface.h) behind one
//      interface API (ifcSample / ifcF / ifcPdf, ifcSplit for the albedo walk),
//      and the pass-through of an index-matched boundary;
//   3. the media: Henyey-Greenstein, the albedo inversion;
//   4. a stack resolved for one group of channels (same IORs and optical
//      thicknesses), the walks (eval: NEE + MIS; albedo: forward).
// The material (the tree expanded into weighted stacks) is ground_truth.cc.
#include "reference/random_walk.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <vector>

#include "reference/bsdf.h"
#include "reference/common.h"
#include "reference/energy_lut.h"
#include "reference/microsurface.h"
#include "util/random.h"

namespace substratec::reference {
using namespace detail;

namespace {

using V = V3<double>;
constexpr double kInvPi = 1.0 / std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kWalkMinAlpha = 1e-3;  // alpha = max(roughness^2, 1e-3) (bsdf.cc: kMinAlpha)
constexpr double kMaxF0 = 0.99;      // eta <= 398
constexpr double kMinMfp = 1e-30;    // as SUBSTRATE_MIN_MFP
constexpr double kMaxG = 0.99;       // |HG g|

// ---------------------------------------------------------------------------
// 1. Random numbers.

/// The splitmix64 stream (util/random.h) of one purpose of one walk seed.
SplitMix64 walkStream(std::uint32_t seed, std::uint64_t stream) {
  std::uint64_t h = (static_cast<std::uint64_t>(seed) << 32) ^ (stream * 0xD1B54A32D192ED03ull);
  return SplitMix64{splitmix64(h)};
}

double sq(double x) { return x * x; }
V neg(const V& v) { return {-v[0], -v[1], -v[2]}; }
bool isZero(const V& v) { return v[0] == 0 && v[1] == 0 && v[2] == 0; }

/// Power heuristic (beta = 2) for the strategy of density a against b; an
/// infinite a (a delta) takes everything.
double powerHeuristic(double a, double b) {
  if (std::isinf(a)) return 1;
  if (!(a > 0)) return 0;
  double a2 = a * a, b2 = b * b;
  return a2 / (a2 + b2);
}

// ---------------------------------------------------------------------------
// 2. Interfaces.
//
// One place for every interface event: ifcSample / ifcF / ifcPdf (below) take
// the interface's frame (its tangent rotation), its lobes (haze: two GGX
// microsurfaces by weight), its tint and its scattering model: the microsurface
// walk of microsurface.h (Heitz et al. 2016, every order) or, for the
// single-scattering mode and near-smooth lobes, the classic single-scattering
// microfacet BSDF (pbrt-v4's rough DielectricBxDF / ConductorBxDF, GGX with
// height-correlated Smith).

/// Anisotropic GGX (Trowbridge-Reitz) with height-correlated Smith masking, in
/// the lobe's own frame (x the tangent, alphaX along it).
struct Ggx {
  double ax = kWalkMinAlpha, ay = kWalkMinAlpha;

  double D(const V& m) const {
    if (m[2] <= 0) return 0;
    double d = sq(m[0] / ax) + sq(m[1] / ay) + m[2] * m[2];
    return 1 / (std::numbers::pi * ax * ay * d * d);
  }
  double lambda(const V& w) const {
    double c2 = w[2] * w[2];
    if (c2 == 0) return kInf;
    double x = (sq(ax * w[0]) + sq(ay * w[1])) / c2;
    return 0.5 * x / (std::sqrt(1 + x) + 1);  // (sqrt(1 + x) - 1) / 2 without cancellation
  }
  double G1(const V& w) const { return 1 / (1 + lambda(w)); }
  double G(const V& wo, const V& wi) const { return 1 / (1 + lambda(wo) + lambda(wi)); }
  /// Density of visible normals m seen from w (pbrt's D(w, wm)).
  double Dv(const V& w, const V& m) const {
    if (w[2] == 0) return 0;
    return G1(w) / std::fabs(w[2]) * D(m) * std::fabs(dot(w, m));
  }
  /// Samples a visible normal from w (w flipped to the upper hemisphere first).
  V sample(const V& w, double u1, double u2) const {
    V wh = normalize(V{ax * w[0], ay * w[1], w[2]});
    if (wh[2] < 0) wh = neg(wh);
    V t1 = wh[2] < 0.99999 ? normalize(cross(V{0, 0, 1}, wh)) : V{1, 0, 0};
    V t2 = cross(wh, t1);
    double r = std::sqrt(u1), phi = 2 * std::numbers::pi * u2;
    double px = r * std::cos(phi), py = r * std::sin(phi);
    double h = std::sqrt(std::max(0.0, 1 - px * px));
    double s = 0.5 * (1 + wh[2]);
    py = (1 - s) * h + s * py;
    double pz = std::sqrt(std::max(0.0, 1 - px * px - py * py));
    V nh = t1 * px + t2 * py + wh * pz;
    return normalize(V{ax * nh[0], ay * nh[1], std::max(1e-6, nh[2])});
  }
};

enum class Mode { Radiance, Importance };
enum Flags : int { kReflection = 1, kTransmission = 2, kAll = 3 };

/// One microsurface of an interface: its GGX slopes, and (multiple) whether
/// the walk of microsurface.h scatters on it (else single scattering).
struct Lobe {
  Ggx ggx;
  Microsurface ms;
  bool multiple = false;
};

struct Interface {
  enum class Kind { Pass, Dielectric, Conductor } kind = Kind::Pass;
  double eta = 1;                  // dielectric: IOR below / IOR above
  std::array<Lobe, 2> lobe{};      // [1]: the haze lobe
  double haze = 0;                 // the weight of lobe[1]
  double cosT = 1, sinT = 0;       // the tangent's rotation about z
  V n{1, 1, 1}, k{0, 0, 0};        // conductor: complex IOR per channel
  double dielF0 = 0, dielF90 = 1;  // dielectric: F90 remap of exact Fresnel (F90 1: none)
  V tint{1, 1, 1};                 // reflection seen from above
  double fuzzAmount = 0, fuzzRough = 0.5;  // the sheen layer on top (fuzz)
  V fuzzColor{0, 0, 0};
};

struct BsdfSample {
  V weight{0, 0, 0};  // f |cos wi| / p of the sampling that produced wi
  V wi{0, 0, 1};
  double pdf = 0;  // the (proxy) density of wi, for MIS
  bool reflect = false;
};

V sampleCosine(double u1, double u2);

V reflectAbout(const V& wo, const V& n) { return n * (2 * dot(wo, n)) - wo; }

/// pbrt's Refract: wi on either side of n; etap the relative IOR it used.
bool refract(const V& wi, V n, double eta, double& etap, V& wt) {
  double c = dot(n, wi);
  if (c < 0) {
    eta = 1 / eta;
    c = -c;
    n = neg(n);
  }
  double s2t = std::max(0.0, 1 - c * c) / (eta * eta);
  if (s2t >= 1) return false;
  double ct = std::sqrt(1 - s2t);
  wt = wi * (-1 / eta) + n * (c / eta - ct);
  etap = eta;
  return true;
}

/// Exact conductor Fresnel per channel.
V conductorFresnel(const Interface& I, double c) {
  V F;
  for (int ch = 0; ch < 3; ++ch) F[ch] = fresnelConductor(std::clamp(c, 0.0, 1.0), I.n[ch], I.k[ch]);
  return F;
}

/// Exact dielectric Fresnel, remapped by F90 (F' = F0 + (F90 - F0)(F - F0)/(1 - F0)).
double dielectricFresnel(const Interface& I, double c) {
  double F = fresnelDielectric(c, I.eta);
  if (I.dielF90 == 1 || !(I.dielF0 < 1)) return F;
  return std::clamp(I.dielF0 + (I.dielF90 - I.dielF0) * (F - I.dielF0) / (1 - I.dielF0), 0.0, 1.0);
}

/// The generalized half vector of (wo, wi) for the dielectric, facing +z; false
/// for degenerate or back-facing configurations (pbrt's discards).
bool dielectricHalf(const Interface& I, const V& wo, const V& wi, V& wm, double& etap, bool& reflect) {
  double co = wo[2], ci = wi[2];
  if (co == 0 || ci == 0) return false;
  reflect = co * ci > 0;
  etap = reflect ? 1 : (co > 0 ? I.eta : 1 / I.eta);
  wm = wi * etap + wo;
  double l2 = dot(wm, wm);
  if (!(l2 > 0)) return false;
  wm = wm / std::sqrt(l2);
  if (wm[2] < 0) wm = neg(wm);
  return !(dot(wm, wi) * ci < 0 || dot(wm, wo) * co < 0);
}

/// Single-scattering BSDF value of one lobe (no cosine), in the lobe's frame.
V ssF(const Interface& I, const Ggx& g, const V& wo, const V& wi, Mode mode) {
  if (I.kind == Interface::Kind::Conductor) {
    if (wo[2] <= 0 || wi[2] <= 0) return {0, 0, 0};
    V h = wo + wi;
    double l2 = dot(h, h);
    if (!(l2 > 0)) return {0, 0, 0};
    h = h / std::sqrt(l2);
    return conductorFresnel(I, std::fabs(dot(wo, h))) * (g.D(h) * g.G(wo, wi) / (4 * wo[2] * wi[2]));
  }
  V wm;
  double etap;
  bool reflect;
  if (!dielectricHalf(I, wo, wi, wm, etap, reflect)) return {0, 0, 0};
  double F = dielectricFresnel(I, dot(wo, wm));
  if (reflect) return splat3(g.D(wm) * g.G(wo, wi) * F / std::fabs(4 * wi[2] * wo[2]));
  double denom = sq(dot(wi, wm) + dot(wo, wm) / etap) * wi[2] * wo[2];
  double ft = g.D(wm) * (1 - F) * g.G(wo, wi) * std::fabs(dot(wi, wm) * dot(wo, wm) / denom);
  if (mode == Mode::Radiance) ft /= etap * etap;
  return splat3(ft);
}

/// Solid-angle density with which ssSample(wo, flags) returns wi.
double ssPdf(const Interface& I, const Ggx& g, const V& wo, const V& wi, int flags) {
  if (I.kind == Interface::Kind::Conductor) {
    if (!(flags & kReflection) || wo[2] <= 0 || wi[2] <= 0) return 0;
    V h = wo + wi;
    double l2 = dot(h, h);
    if (!(l2 > 0)) return 0;
    h = h / std::sqrt(l2);
    return g.Dv(wo, h) / (4 * std::fabs(dot(wo, h)));
  }
  V wm;
  double etap;
  bool reflect;
  if (!dielectricHalf(I, wo, wi, wm, etap, reflect)) return 0;
  double R = dielectricFresnel(I, dot(wo, wm));
  double pr = (flags & kReflection) ? R : 0, pt = (flags & kTransmission) ? 1 - R : 0;
  if (pr == 0 && pt == 0) return 0;
  if (reflect) return g.Dv(wo, wm) / (4 * std::fabs(dot(wo, wm))) * pr / (pr + pt);
  double denom = sq(dot(wi, wm) + dot(wo, wm) / etap);
  return g.Dv(wo, wm) * std::fabs(dot(wi, wm)) / denom * pt / (pr + pt);
}

/// Samples wi from wo on one lobe, single scattering (visible normals, then
/// reflection or transmission by Fresnel among the allowed ones).
bool ssSample(const Interface& I, const Ggx& g, const V& wo, SplitMix64& rng, Mode mode, int flags, BsdfSample& s) {
  const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  if (wo[2] == 0) return false;
  const bool conductor = I.kind == Interface::Kind::Conductor;
  if (conductor && (!(flags & kReflection) || wo[2] <= 0)) return false;
  V wm = g.sample(wo, u1, u2);
  double R = conductor ? 1 : dielectricFresnel(I, dot(wo, wm));
  double pr = (flags & kReflection) ? R : 0, pt = (flags & kTransmission) ? 1 - R : 0;
  if (pr == 0 && pt == 0) return false;
  if (uc < pr / (pr + pt)) {
    V wi = reflectAbout(wo, wm);
    if (wo[2] * wi[2] <= 0) return false;
    s.wi = wi;
    s.pdf = g.Dv(wo, wm) / (4 * std::fabs(dot(wo, wm))) * pr / (pr + pt);
    s.reflect = true;
  } else {
    V wi;
    double etap;
    if (!refract(wo, wm, I.eta, etap, wi)) return false;
    if (wo[2] * wi[2] >= 0 || wi[2] == 0) return false;
    double denom = sq(dot(wi, wm) + dot(wo, wm) / etap);
    s.wi = wi;
    s.pdf = g.Dv(wo, wm) * std::fabs(dot(wi, wm)) / denom * pt / (pr + pt);
    s.reflect = false;
  }
  if (!(s.pdf > 0)) return false;
  s.weight = ssF(I, g, wo, s.wi, mode) * (std::fabs(s.wi[2]) / s.pdf);
  return true;
}

Transport transport(Mode m) { return m == Mode::Radiance ? Transport::Radiance : Transport::Importance; }
V toLocal(const Interface& I, const V& v) { return {I.cosT * v[0] + I.sinT * v[1], -I.sinT * v[0] + I.cosT * v[1], v[2]}; }
V toStack(const Interface& I, const V& v) { return {I.cosT * v[0] - I.sinT * v[1], I.sinT * v[0] + I.cosT * v[1], v[2]}; }
double lobeWeight(const Interface& I, int l) { return l == 0 ? 1 - I.haze : I.haze; }
/// The tint of a reflection seen from above (specularTint), else 1.
V tintOf(const Interface& I, const V& wo, const V& wi) { return wo[2] > 0 && wi[2] > 0 ? I.tint : V{1, 1, 1}; }

/// f(wo, wi) of the interface (no cosine): the lobes' mixture; a stochastic
/// (unbiased) estimate where a lobe walks its microsurface.
V coreF(const Interface& I, const V& wo, const V& wi, Mode mode, SplitMix64& rng) {
  if (I.kind == Interface::Kind::Pass || wi[2] == 0) return {0, 0, 0};
  const V lo = toLocal(I, wo), li = toLocal(I, wi);
  V f{0, 0, 0};
  for (int l = 0; l < 2; ++l) {
    const double w = lobeWeight(I, l);
    if (!(w > 0)) continue;
    const Lobe& L = I.lobe[l];
    V fl = L.multiple ? evalMicrosurface(L.ms, lo, li, transport(mode), rng) / std::fabs(li[2]) : ssF(I, L.ggx, lo, li, mode);
    f = f + fl * w;
  }
  return f * tintOf(I, wo, wi);
}

/// The density (a proxy where a lobe walks its microsurface, pdfMicrosurface)
/// with which ifcSample(wo, flags) returns wi.
double corePdf(const Interface& I, const V& wo, const V& wi, int flags) {
  if (I.kind == Interface::Kind::Pass) return 0;
  const V lo = toLocal(I, wo), li = toLocal(I, wi);
  const int side = lo[2] * li[2] > 0 ? kReflection : kTransmission;
  double p = 0;
  for (int l = 0; l < 2; ++l) {
    const double w = lobeWeight(I, l);
    if (!(w > 0)) continue;
    const Lobe& L = I.lobe[l];
    if (L.multiple)
      p += (flags & side) ? w * pdfMicrosurface(L.ms, lo, li) : 0;
    else
      p += w * ssPdf(I, L.ggx, lo, li, flags);
  }
  return p;
}

/// Samples the interface from wo, restricted to `flags`. A lobe is picked by
/// its weight (one-sample model of the mixture: the pick's probability cancels
/// the mixture's weight). On a microsurface walk the exit side cannot be
/// chosen: an exit on an unwanted side ends the path (returns false), and the
/// weight of a kept exit stays f / p_all — the restricted estimator is then
/// the integral of f over the wanted side only, unbiased (the single-scattering
/// lobes instead renormalize their Fresnel choice among the allowed lobes).
bool ifcSample(const Interface& I, const V& wo, SplitMix64& rng, Mode mode, int flags, BsdfSample& s) {
  if (I.kind == Interface::Kind::Pass) return false;
  const int l = (I.haze > 0 && (I.haze >= 1 || rng.uniform() < I.haze)) ? 1 : 0;
  const Lobe& L = I.lobe[l];
  const V lo = toLocal(I, wo);
  if (L.multiple) {
    if (I.kind == Interface::Kind::Conductor && !(lo[2] > 0)) return false;
    MicrosurfaceSample ms;
    if (!sampleMicrosurface(L.ms, lo, transport(mode), rng, ms)) return false;
    if (!(flags & (ms.reflected ? kReflection : kTransmission))) return false;
    s.wi = ms.wi;
    s.weight = ms.weight;
    s.reflect = ms.reflected;
  } else if (!ssSample(I, L.ggx, lo, rng, mode, flags, s)) {
    return false;
  }
  s.wi = toStack(I, s.wi);
  if (!(s.wi[2] != 0) || !std::isfinite(s.weight[0] + s.weight[1] + s.weight[2])) return false;
  s.weight = s.weight * tintOf(I, wo, s.wi);
  s.pdf = corePdf(I, wo, s.wi, flags);
  return s.pdf > 0;
}

/// Both lobes of one bounce off I from wo (the albedo walk's variance
/// reduction at the top interface): on a single-scattering lobe one sampled
/// microfacet normal gives the reflection r and the transmission t, each with
/// its weight f |cos| / p (p the density of that lobe's direction alone, so
/// E[r.weight] + E[t.weight] is the interface's whole albedo, with no Bernoulli
/// choice between them); on a microsurface walk the exit fills one of them.
/// A zero weight: that side is absent.
void ifcSplit(const Interface& I, const V& wo, SplitMix64& rng, BsdfSample& r, BsdfSample& t) {
  r = BsdfSample{};
  t = BsdfSample{};
  const int l = (I.haze > 0 && (I.haze >= 1 || rng.uniform() < I.haze)) ? 1 : 0;
  const Lobe& L = I.lobe[l];
  const V lo = toLocal(I, wo);
  if (L.multiple) {
    if (I.kind == Interface::Kind::Conductor && !(lo[2] > 0)) return;
    MicrosurfaceSample ms;
    if (!sampleMicrosurface(L.ms, lo, Transport::Importance, rng, ms)) return;
    BsdfSample& s = ms.reflected ? r : t;
    s.wi = ms.wi;
    s.weight = ms.weight;
  } else {
    rng.uniform();  // ssSample's draw pattern: the choice it no longer needs
    const V wm = L.ggx.sample(lo, rng.uniform(), rng.uniform());
    const V wr = reflectAbout(lo, wm);
    const double pr = ssPdf(I, L.ggx, lo, wr, kReflection);
    if (lo[2] * wr[2] > 0 && pr > 0) {
      r.wi = wr;
      r.weight = ssF(I, L.ggx, lo, wr, Mode::Importance) * (std::fabs(wr[2]) / pr);
    }
    V wt;
    double etap;
    if (I.kind == Interface::Kind::Dielectric && refract(lo, wm, I.eta, etap, wt) && lo[2] * wt[2] < 0) {
      const double pt = ssPdf(I, L.ggx, lo, wt, kTransmission);
      if (pt > 0) {
        t.wi = wt;
        t.weight = ssF(I, L.ggx, lo, wt, Mode::Importance) * (std::fabs(wt[2]) / pt);
      }
    }
  }
  for (BsdfSample* s : {&r, &t}) {
    s->wi = toStack(I, s->wi);
    if (!std::isfinite(s->weight[0] + s->weight[1] + s->weight[2]) || s->wi[2] == 0) s->weight = V{0, 0, 0};
    s->weight = s->weight * tintOf(I, wo, s->wi);
    s->reflect = s == &r;
  }
}

// The fuzz of a layer: a sheen layer on top of its interface, the runtime's
// model as a layer (bsdf.cc, substrate_eval_closure): reflection the Charlie
// sheen lobe amount * colour * charlieSheen / max(1, E_fuzz(mu_o)); everything
// else crosses it straight, with weight 1 - amount * min(E_fuzz(mu), 1) at
// each crossing (mu that of the direction above). An energy-conserving "mean
// sheen layer" (what the sheen reflects at most, amount * min(E, 1), is what
// it takes from the crossing light) — the LTC / table sheen of the runtime as
// a layer, not a volumetric fibre walk. resolve() puts it on a pass-through of
// its own over its interface (pushInterface), so only pass-throughs carry
// fuzz: a real interface is its core (ifcF, ifcPdf, ifcSample, ifcSplit), a
// pass-through's f and density are its sheen's, and the walks take its delta
// crossing apart (passThrough, sheenFromAbove, sheenFromBelow).

double fuzzCatch(const Interface& I, double mu) {
  return I.fuzzAmount > 0 ? I.fuzzAmount * std::min(fuzzAlbedo(std::clamp(mu, 0.0, 1.0), I.fuzzRough), 1.0) : 0.0;
}
/// The sheen's f |cos wi| (wo, wi above).
V sheenFcos(const Interface& I, const V& wo, const V& wi) {
  const V h = unitOr(wo + wi, V{0, 0, 1});
  const double e = fuzzAlbedo(std::clamp(wo[2], 0.0, 1.0), I.fuzzRough);
  return I.fuzzColor * (I.fuzzAmount * charlieSheen(I.fuzzRough, wo[2], wi[2], h[2]) / std::max(1.0, e));
}

/// f(wo, wi) of I (no cosine): a real interface's lobes, or the sheen of a
/// pass-through's fuzz (wo, wi above).
V ifcF(const Interface& I, const V& wo, const V& wi, Mode mode, SplitMix64& rng) {
  if (I.kind != Interface::Kind::Pass) return coreF(I, wo, wi, mode, rng);
  if (!(I.fuzzAmount > 0) || !(wo[2] > 0) || !(wi[2] > 0)) return V{0, 0, 0};
  return sheenFcos(I, wo, wi) / wi[2];
}

/// The density of ifcF's lobes: a pass-through's sheen is cosine-sampled with
/// probability fuzzCatch (sheenFromAbove).
double ifcPdf(const Interface& I, const V& wo, const V& wi, int flags) {
  if (I.kind != Interface::Kind::Pass) return corePdf(I, wo, wi, flags);
  if (!(wo[2] > 0) || !(flags & kReflection) || !(wi[2] > 0)) return 0;
  return fuzzCatch(I, wo[2]) * wi[2] * kInvPi;
}

/// The sheen picked with probability q (wo above): a cosine-sampled reflection.
bool sheenSample(const Interface& I, const V& wo, double q, SplitMix64& rng, BsdfSample& s) {
  s.wi = sampleCosine(rng.uniform(), rng.uniform());
  if (!(s.wi[2] > 0)) return false;
  s.weight = sheenFcos(I, wo, s.wi) / (q * s.wi[2] * kInvPi);
  s.reflect = true;
  return true;
}

/// What the fuzz of a pass-through (index-matched) interface lets through a
/// crossing in direction w (either way): 1 - fuzzCatch at the cosine of the
/// direction above, |w_z|. The pass-through itself is a delta.
double passThrough(const Interface& I, const V& w) { return 1 - fuzzCatch(I, std::fabs(w[2])); }

/// Light travelling down (w) meets the fuzz of a pass-through from above: its
/// sheen reflects it back up with probability q (what it catches; bs the
/// sample, its density ifcPdf's), the rest crosses with weight (1 - q) / (1 -
/// q). `reflected` says which; false: the sheen's sample failed, the walk ends.
bool sheenFromAbove(const Interface& I, V& w, V& beta, SplitMix64& rng, BsdfSample& bs, bool& reflected) {
  const double q = fuzzCatch(I, std::fabs(w[2]));
  reflected = q > 0 && rng.uniform() < q;
  if (!reflected) return true;
  if (!sheenSample(I, neg(w), q, rng, bs)) return false;
  bs.pdf = ifcPdf(I, neg(w), bs.wi, kAll);
  beta = beta * bs.weight;
  w = bs.wi;
  return true;
}

/// Light travelling up (w) meets the fuzz of a pass-through from below: its
/// sheen reflects it back down with probability q (the mirror image of the
/// reflection from above), the rest crosses with weight (1 - q) / (1 - q).
/// True when reflected (w, beta updated).
bool sheenFromBelow(const Interface& I, V& w, V& beta, SplitMix64& rng) {
  const double q = fuzzCatch(I, std::fabs(w[2]));
  if (!(q > 0 && rng.uniform() < q)) return false;
  BsdfSample bs;
  if (!sheenSample(I, V{-w[0], -w[1], w[2]}, q, rng, bs)) {
    beta = V{0, 0, 0};  // a sample below the horizon: the path carries nothing
    return true;
  }
  beta = beta * bs.weight;
  w = V{bs.wi[0], bs.wi[1], -bs.wi[2]};
  return true;
}

// ---------------------------------------------------------------------------
// 3. Media.

/// Henyey-Greenstein phase function of the angle between travel directions.
double hg(double mu, double g) {
  double d = 1 + g * g - 2 * g * mu;
  return (1 - g * g) / (4 * std::numbers::pi * d * std::sqrt(d));
}

V sampleHg(const V& w, double g, double u1, double u2) {
  double mu;
  if (std::fabs(g) < 1e-3) {
    mu = 1 - 2 * u1;
  } else {
    double s = (1 - g * g) / (1 - g + 2 * g * u1);
    mu = (1 + g * g - s * s) / (2 * g);
  }
  mu = std::clamp(mu, -1.0, 1.0);
  double st = std::sqrt(std::max(0.0, 1 - mu * mu)), phi = 2 * std::numbers::pi * u2;
  V t1, t2;
  orthonormalBasis(w, t1, t2);
  return t1 * (st * std::cos(phi)) + t2 * (st * std::sin(phi)) + w * mu;
}

V sampleCosine(double u1, double u2) {
  double r = std::sqrt(u1), phi = 2 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u1))};
}

// ---------------------------------------------------------------------------
// 4. The stack for one group of channels, and the walks.

struct Medium {
  double tau = 0;          // optical thickness (infinite: the semi-infinite bottom)
  V omega{0, 0, 0};        // single-scattering albedo per channel
  double g = 0;
  bool scatters = false;   // some channel of the group scatters: distance sampling
};

enum class Bottom { Semi, Lambert, Conductor };

struct Resolved {
  std::vector<Interface> ifc;  // I_k
  std::vector<Medium> med;     // M_k, under I_k (unused under a conductor)
  Bottom bottom = Bottom::Semi;
  V lambert{0, 0, 0};
  int lastLayer() const { return bottom == Bottom::Conductor ? static_cast<int>(ifc.size()) - 2 : static_cast<int>(ifc.size()) - 1; }
};


/// Microsurface walks on lobes rougher than this (alpha): below it the
/// inter-facet bounces carry < 0.1 % of the energy (E_ss of GGX at alpha 0.02
/// is 0.9996 at grazing... measured in random_walk_test) and the single
/// scattering lobe is exact, cheaper and noiseless to evaluate.
constexpr double kMultipleMinAlpha = 0.002;

/// Gulbrandsen's edge tint from the slab's F0 and F90: g = F90 (1 - (1 - F0)^2.75).
/// The factor is the g whose curve is closest to Schlick's with F90 = 1 (fitted
/// over F0 in [0.02, 1]; random_walk.h has the differences), so the default
/// F90 = 1 reads as the runtime's Schlick, and a tinted F90 tints the edge
/// (finishInterface passes the runtime's effective F90).
double edgeTint(double f0, double f90) {
  return std::clamp(f90, 0.0, 1.0) * (1 - std::pow(1 - std::clamp(f0, 0.0, 1.0), 2.75));
}

/// One lobe of a layer's interface at a roughness: GGX alpha by the runtime's
/// mapping (bsdf.cc ggxAlpha: a = sat(r)^2, (a (1 + A), a (1 - A)) in [1e-3, 1]).
Lobe makeLobe(const Interface& I, double roughness, double anisotropy, bool single) {
  Lobe L;
  const double r = saturate(roughness), a = r * r, A = std::clamp(anisotropy, -1.0, 1.0);
  L.ggx.ax = std::clamp(a * (1 + A), kWalkMinAlpha, 1.0);
  L.ggx.ay = std::clamp(a * (1 - A), kWalkMinAlpha, 1.0);
  L.multiple = !single && std::max(L.ggx.ax, L.ggx.ay) > kMultipleMinAlpha;
  L.ms.alphaX = L.ggx.ax;
  L.ms.alphaY = L.ggx.ay;
  L.ms.kind = I.kind == Interface::Kind::Conductor ? Microsurface::Kind::Conductor : Microsurface::Kind::Dielectric;
  L.ms.eta = I.eta;
  L.ms.n = I.n;
  L.ms.k = I.k;
  return L;
}

/// The interface of layer L (kind and eta set by the caller): frame, lobes, tint.
/// F90 is the runtime's (f90Effective: a conductor's is a hue, a dielectric's
/// keeps its intensity).
void finishInterface(Interface& I, const WalkLayer& L, int rc, bool single) {
  const V f90 = f90Effective(vclamp(L.f0, 0.0, 1.0), vclamp(L.f90, 0.0, 1.0));
  if (I.kind == Interface::Kind::Conductor)
    for (int c = 0; c < 3; ++c) conductorIor(saturate(L.f0[c]), edgeTint(L.f0[c], f90[c]), I.n[c], I.k[c]);
  if (I.kind == Interface::Kind::Dielectric) {
    I.dielF0 = sq((I.eta - 1) / (I.eta + 1));
    I.dielF90 = f90[rc];
  }
  I.cosT = std::cos(L.tangentAngle);
  I.sinT = std::sin(L.tangentAngle);
  I.haze = saturate(L.secondRoughnessWeight);
  I.lobe[0] = makeLobe(I, L.roughness, L.anisotropy, single);
  I.lobe[1] = makeLobe(I, L.secondRoughness, L.anisotropy, single);
  I.tint = vclamp(L.specularTint, 0.0, 1.0);
  I.fuzzAmount = saturate(L.fuzzAmount);
  I.fuzzRough = saturate(L.fuzzRoughness);
  I.fuzzColor = vclamp(L.fuzzColor, 0.0, 1.0);
}

/// Cosine-weighted hemispherical reflectance of interface I seen from below
/// (light arriving from inside, the lobes' microsurface walks included): the
/// mean over 2^20 directions stratified in mu^2 of ifcSplit's reflected weight.
/// A microsurface walk leaves by one side (a Bernoulli of sd 0.49), so the
/// standard error is about 5e-4 (three seeds at 2^18 spread by 1.4e-3): 0.1 %
/// of a grey 0.18 seen through the interface; about 0.25 s. The same stream
/// for every interface, so the figure is deterministic; memoized per
/// interface (the walks ask for it at every evaluation). Tint and fuzz act on
/// light above the interface only: not part of it.
double roughInternalReflectance(const Interface& I) {
  const std::array<double, 8> key{I.eta,           I.dielF90,         I.haze,
                                  I.lobe[0].ggx.ax, I.lobe[0].ggx.ay, I.lobe[1].ggx.ax,
                                  I.lobe[1].ggx.ay, I.lobe[0].multiple ? 1.0 : 0.0};
  static std::mutex mutex;
  static std::map<std::array<double, 8>, double> cache;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = cache.find(key); it != cache.end()) return it->second;
  constexpr int kStrata = 1 << 20;
  SplitMix64 rng = walkStream(0x52323121u, 0);
  double sum = 0;
  for (int i = 0; i < kStrata; ++i) {
    V w = sampleCosine((i + rng.uniform()) / kStrata, rng.uniform());
    w[2] = -w[2];  // wo inside, pointing down: the light travels up to the interface
    BsdfSample r, t;
    ifcSplit(I, w, rng, r, t);
    sum += r.weight[0];
  }
  const double R21 = std::clamp(sum / kStrata, 0.0, 1.0);
  cache.emplace(key, R21);
  return R21;
}

/// The albedo under a slab's own interface in air (WalkOptions::albedoSeenThroughInterface),
/// channel c: the A' whose light, re-reflected inside by that interface
/// (cosine-weighted internal reflectance R21), leaves as A:
/// A'(1 - R21) / (1 - R21 A') = A, so A' = A / (1 - R21 + R21 A). Exact for
/// any interface over a Lambertian (it sends cosine-distributed light up
/// whatever came down). A smooth interface (every lobe's alpha at most
/// kMultipleMinAlpha) takes the closed form internalReflectance; a rough one
/// its own (roughInternalReflectance): a rough interface lets more of the
/// light under its critical angle out (R21 0.575 at F0 0.04, roughness 0.7,
/// against 0.596 smooth), and with the smooth R21 the truth returned 3.5 % more
/// than A of a grey 0.18 (MaterialX's Greysphere).
double underInterface(const WalkLayer& L, int c, const WalkOptions& o) {
  const double A = std::clamp(L.diffuseAlbedo[c], 0.0, 1.0);
  if (A <= 0 || A >= 1 || L.conductor) return A;
  Interface I;
  I.eta = iorFromF0(std::clamp(L.f0[c], 0.0, kMaxF0));
  if (!(I.eta > 1)) return A;
  I.kind = Interface::Kind::Dielectric;
  finishInterface(I, L, c, o.singleScatteringInterfaces);
  const bool smooth = std::max(I.lobe[0].ggx.ax, I.lobe[0].ggx.ay) <= kMultipleMinAlpha &&
                      (I.haze <= 0 || std::max(I.lobe[1].ggx.ax, I.lobe[1].ggx.ay) <= kMultipleMinAlpha);
  const double r21 = smooth ? internalReflectance(I.eta) : roughInternalReflectance(I);
  return std::clamp(A / (1 - r21 + r21 * A), 0.0, 1.0);
}

/// Pushes interface I: a real interface with fuzz goes in as two, a
/// pass-through carrying the fuzz over the bare interface with no medium
/// between them, so that what the fuzz catches from below goes back down by
/// the pass-through's rules (sheenFromBelow) instead of being absorbed, and
/// light bounces between the fuzz and the interface as between two layers.
void pushInterface(Resolved& r, Interface I) {
  if (I.kind != Interface::Kind::Pass && I.fuzzAmount > 0) {
    Interface fuzz;
    fuzz.fuzzAmount = I.fuzzAmount;
    fuzz.fuzzRough = I.fuzzRough;
    fuzz.fuzzColor = I.fuzzColor;
    r.ifc.push_back(fuzz);
    r.med.push_back(Medium{});  // tau 0: the interface lies right under its fuzz
    I.fuzzAmount = 0;
  }
  r.ifc.push_back(I);
}

/// The stack with the IORs and optical thicknesses of channel `rc`; per-channel
/// weights (albedos, conductor Fresnel) for all channels.
Resolved resolve(const std::vector<WalkLayer>& stack, const std::vector<V>& albedos, int rc, const WalkOptions& o) {
  Resolved r;
  double nAbove = 1;  // absoluteIor: the IOR of the layer above (air at the top)
  for (std::size_t i = 0; i < stack.size(); ++i) {
    const WalkLayer& L = stack[i];
    const bool bottom = i + 1 == stack.size() || L.opaqueBase;
    Interface I;
    if (L.conductor) {
      I.kind = Interface::Kind::Conductor;
      finishInterface(I, L, rc, o.singleScatteringInterfaces);
      pushInterface(r, I);
      r.med.push_back(Medium{});
      r.bottom = Bottom::Conductor;
      break;
    }
    const double n = iorFromF0(std::clamp(L.f0[rc], 0.0, kMaxF0));
    I.eta = o.absoluteIor ? n / nAbove : n;
    nAbove = n;
    I.kind = I.eta == 1 ? Interface::Kind::Pass : Interface::Kind::Dielectric;
    finishInterface(I, L, rc, o.singleScatteringInterfaces);
    Medium M;
    M.g = std::clamp(L.phaseAnisotropy, -kMaxG, kMaxG);
    pushInterface(r, I);
    const V& albedo = albedos[i];
    if (L.opaqueBase) {
      r.lambert = albedo;
      r.bottom = Bottom::Lambert;
      r.med.push_back(M);  // tau 0: the Lambertian is right under the interface
      break;
    }
    for (int c = 0; c < 3; ++c) M.omega[c] = singleScatteringAlbedo(albedo[c], M.g);
    if (bottom) {
      M.tau = kInf;
      r.bottom = Bottom::Semi;
    } else {
      double d = L.thickness > 0 ? L.thickness : 0;
      M.tau = d / std::max(L.mfp[rc], kMinMfp);
    }
    r.med.push_back(M);
  }
  return r;
}

/// What makes two channels walk differently: the kinds, IORs and optical thicknesses.
std::vector<double> geometryKey(const Resolved& r) {
  std::vector<double> k;
  for (std::size_t i = 0; i < r.ifc.size(); ++i) {
    k.push_back(static_cast<double>(r.ifc[i].kind));
    k.push_back(r.ifc[i].eta);
    k.push_back(r.ifc[i].dielF90);
    k.push_back(r.med[i].tau);
  }
  k.push_back(static_cast<double>(r.bottom));
  return k;
}

struct Group {
  Resolved stack;
  std::array<bool, 3> mask{false, false, false};
};

/// NaN parameters read as 0 (an infinite MFP or thickness is meaningful: kept).
double orZero(double x) { return std::isnan(x) ? 0.0 : x; }
V orZero(const V& v) { return {orZero(v[0]), orZero(v[1]), orZero(v[2])}; }
WalkLayer sanitized(const WalkLayer& L) {
  WalkLayer s = L;
  s.f0 = orZero(L.f0);
  s.f90 = orZero(L.f90);
  s.diffuseAlbedo = orZero(L.diffuseAlbedo);
  s.mfp = orZero(L.mfp);
  s.roughness = orZero(L.roughness);
  s.phaseAnisotropy = orZero(L.phaseAnisotropy);
  s.thickness = orZero(L.thickness);
  s.anisotropy = orZero(L.anisotropy);
  s.tangentAngle = orZero(L.tangentAngle);
  s.secondRoughness = orZero(L.secondRoughness);
  s.secondRoughnessWeight = orZero(L.secondRoughnessWeight);
  s.fuzzAmount = orZero(L.fuzzAmount);
  s.fuzzRoughness = orZero(L.fuzzRoughness);
  s.fuzzColor = orZero(L.fuzzColor);
  s.specularTint = orZero(L.specularTint);
  return s;
}

/// Channels grouped by geometryKey, each group's stack ready to walk.
std::vector<Group> groups(const std::vector<WalkLayer>& rawStack, const WalkOptions& o) {
  std::vector<WalkLayer> stack;
  for (const WalkLayer& L : rawStack) stack.push_back(sanitized(L));
  std::vector<V> albedos;
  for (const WalkLayer& L : stack) {
    V a = vclamp(L.diffuseAlbedo, 0.0, 1.0);
    if (o.albedoSeenThroughInterface)
      for (int c = 0; c < 3; ++c) a[c] = underInterface(L, c, o);
    albedos.push_back(a);
  }
  std::vector<Group> out;
  std::vector<std::vector<double>> keys;
  for (int c = 0; c < 3; ++c) {
    Resolved r = resolve(stack, albedos, c, o);
    std::vector<double> key = geometryKey(r);
    std::size_t gi = 0;
    while (gi < keys.size() && keys[gi] != key) ++gi;
    if (gi == keys.size()) {
      keys.push_back(key);
      out.push_back(Group{std::move(r), {false, false, false}});
    }
    out[gi].mask[c] = true;
  }
  for (Group& g : out)
    for (Medium& m : g.stack.med)
      for (int c = 0; c < 3; ++c)
        if (g.mask[c] && m.omega[c] > 0 && m.tau > 0) m.scatters = true;
  return out;
}

double maxMasked(const V& v, const std::array<bool, 3>& mask) {
  double m = 0;
  for (int c = 0; c < 3; ++c)
    if (mask[c]) m = std::max(m, v[c]);
  return m;
}

/// Russian roulette after 3 events, when the largest channel of the
/// throughput is below 0.25: the walk survives with probability mb / 0.25 and
/// its throughput is raised to 0.25 (pbrt's LayeredBxDF raises it to 1 with
/// probability mb: far noisier for dark stacks); false when the walk ends.
bool roulette(V& beta, int depth, const std::array<bool, 3>& mask, SplitMix64& rng) {
  constexpr double kFloor = 0.25;
  double mb = maxMasked(beta, mask);
  if (!(mb > 0)) return false;
  if (depth > 3 && mb < kFloor) {
    const double survive = mb / kFloor;
    if (rng.uniform() >= survive) return false;
    beta = beta / survive;
  }
  return true;
}

/// Moves the walk through the medium of its layer: either to a scattering
/// vertex (returns true, t = its depth) or to the boundary it heads to
/// (returns false, t = 0 or tau; beta attenuated when the medium does not
/// scatter). `alive` false: absorbed.
bool propagate(const Medium& M, const V& w, double& t, V& beta, SplitMix64& rng, bool& alive) {
  alive = true;
  if (M.scatters) {
    double dist = -std::log(1 - rng.uniform());
    double tp = t - dist * w[2];  // optical depth grows downwards
    if (tp > 0 && tp < M.tau) {
      t = tp;
      return true;
    }
  } else {
    double span = w[2] < 0 ? M.tau - t : t;
    if (std::isinf(span)) {
      alive = false;
      return false;
    }
    if (span > 0) beta = beta * std::exp(-span / std::fabs(w[2]));
  }
  t = w[2] < 0 ? M.tau : 0;
  return false;
}

/// An importance-sampled bounce off I from `from` (flags: which lobes):
/// beta *= f |cos| / pdf and w = the sampled direction; false: no sample.
bool bounce(const Interface& I, const V& from, int flags, SplitMix64& rng, V& beta, V& w, BsdfSample& bs) {
  if (!ifcSample(I, from, rng, Mode::Importance, flags, bs)) return false;
  beta = beta * bs.weight;
  w = bs.wi;
  return true;
}

/// The light chain of one evalGroup sample: from wi down through every
/// interface (transmission only). dir[k] the direction below I_k, weight[k]
/// the chain's throughput to there; returns the chain's length, and pB0 the
/// light-side density of dir[0] (infinite: a delta through a pass-through).
int traceLightChain(const Resolved& s, int last, const V& wi, SplitMix64& rng, std::vector<V>& dir, std::vector<V>& weight,
                    double& pB0) {
  int chainLen = 0;
  pB0 = kInf;
  V from = wi;
  V wgt{1, 1, 1};
  for (int k = 0; k <= last; ++k) {
    const Interface& I = s.ifc[k];
    V c;
    if (I.kind == Interface::Kind::Pass) {
      // A delta transmission: f / pdf = 1 / |cos|, and f |cos| / pdf = 1 (k >= 1).
      c = neg(from);
      wgt = wgt * passThrough(I, c);
      if (k == 0) wgt = wgt / std::fabs(c[2]);
    } else {
      BsdfSample bs;
      if (!ifcSample(I, from, rng, Mode::Radiance, kTransmission, bs)) break;
      c = bs.wi;
      // The cosine of the segment above I_k (towards the exit) for k >= 1;
      // at I_0 that segment is wi's, which the caller's |cos wi| carries.
      wgt = wgt * bs.weight * ((k == 0 ? 1.0 : std::fabs(from[2])) / std::fabs(c[2]));
      if (k == 0) pB0 = bs.pdf;
    }
    if (!(c[2] < 0)) break;
    dir[k] = c;
    weight[k] = wgt;
    chainLen = k + 1;
    if (k < last) {
      wgt = wgt * std::exp(-s.med[k].tau / std::fabs(c[2]));
      from = neg(c);
    }
  }
  return chainLen;
}

/// One walk of evalGroup from wo into the stack: its state (layer k, optical
/// depth t, direction w, weight beta) and the two strategies by which its
/// vertices add to `sum` (exitA: leaving through I_0 towards wi; connectB:
/// joining the light chain).
struct EvalWalk {
  const Resolved& s;
  const V& wi;
  bool exitDelta;
  const std::vector<V>& chainDir;
  const std::vector<V>& chainW;
  int chainLen;
  double pB0;
  SplitMix64& rng;
  V& sum;
  V beta{1, 1, 1}, w{0, 0, 0};
  int k = 0;
  double t = 0;

  /// The exit through the top interface after a vertex of layer 0 sampled w1
  /// (strategy A): beta already includes that sample; pA its density; tr the
  /// transmittance to I_0.
  void exitA(const V& w1, double pA, double tr) {
    if (exitDelta || !(w1[2] > 0)) return;
    V fe = ifcF(s.ifc[0], neg(w1), wi, Mode::Importance, rng);
    if (isZero(fe)) return;
    double pB = ifcPdf(s.ifc[0], wi, neg(w1), kTransmission);
    sum = sum + beta * fe * (tr * powerHeuristic(pA, pB));
  }
  /// The connection of a vertex of layer k to the light chain (strategy B):
  /// fv the vertex's f (times |cos| for a surface) towards -c_k, pA the density
  /// of the walk's own sampling of -c_k, tr the transmittance to I_k.
  void connectB(const V& fv, double pA, double tr) {
    double wB = (k == 0 && !exitDelta) ? powerHeuristic(pB0, pA) : 1.0;
    sum = sum + beta * fv * chainW[k] * (tr * wB);
  }
  /// Enters through the top interface (its reflection is counted apart); false: no entry.
  bool enter(const V& wo) {
    if (exitDelta) {  // the top's sheen reflection is counted apart (ifcF)
      w = neg(wo);
      beta = beta * passThrough(s.ifc[0], w);
    } else {
      BsdfSample bs;
      if (!ifcSample(s.ifc[0], wo, rng, Mode::Importance, kTransmission, bs)) return false;
      w = bs.wi;
      beta = bs.weight;
    }
    return w[2] < 0;
  }
  /// Walks up to maxDepth events.
  void run(int maxDepth, const std::array<bool, 3>& mask) {
    for (int depth = 0; depth < maxDepth; ++depth) {
      if (!roulette(beta, depth, mask, rng)) break;
      const Medium& M = s.med[k];
      bool alive;
      if (propagate(M, w, t, beta, rng, alive)) {
        scatter(M);
        continue;
      }
      if (!alive) break;
      if (!(w[2] > 0 ? up() : down(M))) break;
    }
  }
  /// A scattering vertex at depth t of layer k.
  void scatter(const Medium& M) {
    if (k < chainLen) {
      V lw = neg(chainDir[k]);
      double p = hg(dot(w, lw), M.g);
      connectB(M.omega * p, p, std::exp(-t / std::fabs(lw[2])));
    }
    V w1 = sampleHg(w, M.g, rng.uniform(), rng.uniform());
    double p1 = hg(dot(w, w1), M.g);
    beta = beta * M.omega;
    if (k == 0) exitA(w1, p1, std::exp(-t / std::fabs(w1[2])));
    w = w1;
  }
  /// At I_k from below; false: the walk ends.
  bool up() {
    const Interface& I = s.ifc[k];
    if (k == 0) {
      // Leaving is counted at the last vertex: only reflection continues
      // (on a pass-through, its fuzz's).
      if (exitDelta) return sheenFromBelow(I, w, beta, rng) && !isZero(beta);
      BsdfSample bs;
      return bounce(I, neg(w), kReflection, rng, beta, w, bs);
    }
    if (I.kind == Interface::Kind::Pass) {
      if (sheenFromBelow(I, w, beta, rng)) return !isZero(beta);
      --k;
      t = s.med[k].tau;
      return true;
    }
    BsdfSample bs;
    if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) return false;
    if (!bs.reflect) {
      --k;
      t = s.med[k].tau;
    }
    return true;
  }
  /// At the bottom of layer k (medium M), going down: a surface vertex (or a
  /// pass-through); false: the walk ends.
  bool down(const Medium& M) {
    const double trUp = M.tau;  // optical depth from the vertex to I_k
    if (k == static_cast<int>(s.ifc.size()) - 1) {
      // The Lambertian base (Bottom::Lambert; tau 0).
      if (s.bottom != Bottom::Lambert) return false;
      if (k < chainLen) {
        V lw = neg(chainDir[k]);
        connectB(s.lambert * (kInvPi * lw[2]), lw[2] * kInvPi, std::exp(-trUp / lw[2]));
      }
      V w1 = sampleCosine(rng.uniform(), rng.uniform());
      if (!(w1[2] > 0)) return false;
      beta = beta * s.lambert;
      if (k == 0) exitA(w1, w1[2] * kInvPi, std::exp(-trUp / w1[2]));
      w = w1;
      return true;
    }
    const Interface& I = s.ifc[k + 1];
    if (I.kind == Interface::Kind::Pass && !(I.fuzzAmount > 0)) {
      ++k;
      t = 0;
      return true;
    }
    if (k < chainLen) {
      V lw = neg(chainDir[k]);
      V fv = ifcF(I, neg(w), lw, Mode::Importance, rng);
      if (!isZero(fv)) connectB(fv * std::fabs(lw[2]), ifcPdf(I, neg(w), lw, kAll), std::exp(-trUp / std::fabs(lw[2])));
    }
    BsdfSample bs;
    bool reflected = false;
    if (I.kind == Interface::Kind::Pass) {  // its fuzz (NEE above: ifcF is the sheen's)
      if (!sheenFromAbove(I, w, beta, rng, bs, reflected)) return false;
    } else if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) {
      return false;
    } else {
      reflected = bs.reflect;
    }
    if (reflected) {
      if (k == 0) exitA(w, bs.pdf, std::exp(-trUp / std::fabs(w[2])));
    } else {
      ++k;
      t = 0;
    }
    return true;
  }
};

/// The running mean and standard error of one group's per-walk contributions.
struct Tally {
  V sum{0, 0, 0}, sum2{0, 0, 0};
  long n = 0;
  void add(const V& x) {
    sum = sum + x;
    sum2 = sum2 + x * x;
    ++n;
  }
  Estimate estimate(const V& offset = V{0, 0, 0}) const {
    Estimate e;
    e.samples = n;
    if (n <= 0) {
      e.value = offset;
      return e;
    }
    const double dn = static_cast<double>(n);
    const V mean = sum / dn;
    e.value = offset + mean;
    for (int c = 0; c < 3; ++c) {
      const double var = n > 1 ? std::max(0.0, (sum2[c] / dn - mean[c] * mean[c]) * dn / (dn - 1)) : 0.0;
      e.standardError[c] = std::sqrt(var / dn);
    }
    return e;
  }
};

/// layeredEval for one group: sum over the walks of f(wo, wi) (no cosine),
/// divided by the count. Each walk adds one estimate of the top reflection
/// f_0(wo, wi) (exact on single-scattering lobes, a microsurface walk else).
Estimate evalGroup(const Group& grp, const V& wo, const V& wi, const WalkOptions& o, SplitMix64& rng) {
  const Resolved& s = grp.stack;
  const Interface& top = s.ifc[0];
  const int last = s.lastLayer();
  const bool exitDelta = top.kind == Interface::Kind::Pass;
  Tally tally;
  std::vector<V> chainDir(static_cast<std::size_t>(std::max(last, 0)) + 1), chainW(chainDir.size());
  for (int sample = 0; sample < o.samples; ++sample) {
    V sum = ifcF(top, wo, wi, Mode::Importance, rng);
    if (last >= 0) {  // else a conductor alone
      double pB0 = kInf;
      const int chainLen = traceLightChain(s, last, wi, rng, chainDir, chainW, pB0);
      EvalWalk walk{s, wi, exitDelta, chainDir, chainW, chainLen, pB0, rng, sum};
      if (walk.enter(wo)) walk.run(o.maxDepth, grp.mask);
    }
    tally.add(sum);
  }
  return tally.estimate();
}

/// One forward walk of albedoGroup: state (layer k, optical depth t, direction
/// w, weight beta) and what has left through the top (sum). At the top
/// interface, both ways in and out, the bounce is split (ifcSplit): what leaves
/// is counted, what stays walks on.
struct AlbedoWalk {
  const Resolved& s;
  SplitMix64& rng;
  V sum{0, 0, 0}, beta{1, 1, 1}, w{0, 0, 0};
  int k = 0;
  double t = 0;

  /// The first event: I_0 from outside; false: nothing enters.
  bool enter(const V& wo) {
    w = neg(wo);
    const Interface& I = s.ifc[0];
    if (I.kind == Interface::Kind::Pass) {
      // The fuzz on top reflects by its sheen with probability q (what it
      // catches) and lets the rest through (weight 1 - q over 1 - q).
      const double q = fuzzCatch(I, wo[2]);
      if (q > 0 && rng.uniform() < q) {
        BsdfSample r;
        if (sheenSample(I, wo, q, rng, r)) sum = sum + r.weight;
        return false;
      }
      return true;
    }
    BsdfSample r, tr;
    ifcSplit(I, wo, rng, r, tr);
    sum = sum + r.weight;
    if (isZero(tr.weight)) return false;
    beta = tr.weight;
    w = tr.wi;
    return true;
  }
  /// At I_k from below; false: the walk ends.
  bool up() {
    const Interface& I = s.ifc[k];
    bool crossed = true;
    if (k == 0 && I.kind != Interface::Kind::Pass) {
      BsdfSample r, tr;
      ifcSplit(I, neg(w), rng, r, tr);
      sum = sum + beta * tr.weight;
      if (isZero(r.weight)) return false;
      beta = beta * r.weight;
      w = r.wi;
      return true;
    }
    if (I.kind != Interface::Kind::Pass) {
      BsdfSample bs;
      if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) return false;
      crossed = !bs.reflect;
    }
    if (crossed && I.kind == Interface::Kind::Pass && sheenFromBelow(I, w, beta, rng)) return !isZero(beta);
    if (crossed) {
      if (k == 0) {
        sum = sum + beta;
        return false;
      }
      --k;
      t = s.med[k].tau;
    }
    return true;
  }
  /// At the bottom of layer k, going down; false: the walk ends.
  bool down() {
    if (k == static_cast<int>(s.ifc.size()) - 1) {  // the Lambertian base
      if (s.bottom != Bottom::Lambert) return false;
      w = sampleCosine(rng.uniform(), rng.uniform());
      beta = beta * s.lambert;
      return true;
    }
    const Interface& I = s.ifc[k + 1];
    bool crossed = true;
    if (I.kind != Interface::Kind::Pass) {
      BsdfSample bs;
      if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) return false;
      crossed = !bs.reflect;
    } else {
      BsdfSample bs;
      bool reflected = false;
      if (!sheenFromAbove(I, w, beta, rng, bs, reflected)) return false;
      crossed = !reflected;
    }
    if (crossed) {
      ++k;
      t = 0;
    }
    return true;
  }
  void run(int maxDepth, const std::array<bool, 3>& mask) {
    for (int depth = 0; depth < maxDepth; ++depth) {
      if (!roulette(beta, depth, mask, rng)) break;
      const Medium& M = s.med[k];
      bool alive;
      if (propagate(M, w, t, beta, rng, alive)) {
        w = sampleHg(w, M.g, rng.uniform(), rng.uniform());
        beta = beta * M.omega;
        continue;
      }
      if (!alive || !(w[2] > 0 ? up() : down())) break;
    }
  }
};

/// layeredAlbedo for one group: the mean weight with which forward walks leave the top.
Estimate albedoGroup(const Group& grp, const V& wo, const WalkOptions& o, SplitMix64& rng) {
  Tally tally;
  for (int sample = 0; sample < o.samples; ++sample) {
    AlbedoWalk walk{grp.stack, rng};
    if (walk.enter(wo)) walk.run(o.maxDepth - 1, grp.mask);
    tally.add(walk.sum);
  }
  return tally.estimate();
}


/// Runs `walk` per channel group and gathers each group's channels.
template <class F>
Estimate perGroup(const std::vector<WalkLayer>& stack, const WalkOptions& o, std::uint64_t purpose, F&& walk) {
  Estimate out;
  if (stack.empty()) return out;
  std::vector<Group> gs = groups(stack, o);
  for (std::size_t gi = 0; gi < gs.size(); ++gi) {
    SplitMix64 rng = walkStream(o.seed, purpose * 8 + gi);
    Estimate v = walk(gs[gi], rng);
    out.samples += v.samples;
    for (int c = 0; c < 3; ++c)
      if (gs[gi].mask[c]) {
        out.value[c] = v.value[c];
        out.standardError[c] = v.standardError[c];
      }
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------
// Public helpers.

double multipleScatteringAlbedo(double omega, double g) {
  omega = std::clamp(omega, 0.0, 1.0);
  g = std::clamp(g, -kMaxG, kMaxG);
  double reduced = omega * (1 - g) / (1 - omega * g);
  double s = std::sqrt(std::max(0.0, 1 - reduced));
  return (1 - s) * (1 - 0.139 * s) / (1 + 1.17 * s);
}

double singleScatteringAlbedo(double albedo, double g) {
  double A = std::clamp(albedo, 0.0, 1.0);
  g = std::clamp(g, -kMaxG, kMaxG);
  // A (1 + 1.17 s) = (1 - s)(1 - 0.139 s): 0.139 s^2 - (1.139 + 1.17 A) s + (1 - A) = 0,
  // the root in [0, 1]; 1.139 / 0.278 = 4.09712, 1.17 / 0.278 = 4.20863 (Kulla & Conty).
  double b = 1.139 + 1.17 * A;
  double disc = std::max(0.0, b * b - 4 * 0.139 * (1 - A));
  double s = std::clamp(2 * (1 - A) / (b + std::sqrt(disc)), 0.0, 1.0);  // = (b - sqrt(disc)) / 0.278, stable
  double reduced = 1 - s * s;
  return std::clamp(reduced / (1 - g + g * reduced), 0.0, 1.0);
}

double internalReflectance(double eta) {
  if (!(eta > 1)) return 0;
  // 1 - R21 = (1 - R12) / eta^2, R12 = integral of F(mu) 2 mu dmu from outside
  // (smooth in mu: Simpson's rule, 256 intervals).
  const int n = 256;
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    double mu = static_cast<double>(i) / n;
    double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += w * fresnelDielectric(mu, eta) * 2 * mu;
  }
  double r12 = sum / (3.0 * n);
  return 1 - (1 - r12) / (eta * eta);
}

double iorFromF0(double f0) {
  if (!(f0 > 0)) return 1;
  double r = std::sqrt(std::min(f0, kMaxF0));
  return (1 + r) / (1 - r);
}

double fresnelDielectric(double cosThetaI, double eta) {
  double c = std::clamp(cosThetaI, -1.0, 1.0);
  if (c < 0) {
    eta = 1 / eta;
    c = -c;
  }
  double s2t = (1 - c * c) / (eta * eta);
  if (s2t >= 1) return 1;
  double ct = std::sqrt(std::max(0.0, 1 - s2t));
  double rParl = (eta * c - ct) / (eta * c + ct);
  double rPerp = (c - eta * ct) / (c + eta * ct);
  return 0.5 * (rParl * rParl + rPerp * rPerp);
}

Estimate layeredEvalEstimate(const std::vector<WalkLayer>& stack, const V3<double>& wo, const V3<double>& wi,
                             const WalkOptions& options) {
  if (!(wo[2] > 0) || !(wi[2] > 0)) return Estimate{};
  const V o = unitOr(wo, V{0, 0, 1}), i = unitOr(wi, V{0, 0, 1});
  Estimate f =
      perGroup(stack, options, 1, [&](const Group& g, SplitMix64& rng) { return evalGroup(g, o, i, options, rng); });
  f.value = f.value * i[2];
  f.standardError = f.standardError * i[2];
  return f;
}

Estimate layeredAlbedoEstimate(const std::vector<WalkLayer>& stack, const V3<double>& wo, const WalkOptions& options) {
  if (!(wo[2] > 0)) return Estimate{};
  const V o = unitOr(wo, V{0, 0, 1});
  return perGroup(stack, options, 2, [&](const Group& g, SplitMix64& rng) { return albedoGroup(g, o, options, rng); });
}

V3<double> layeredEval(const std::vector<WalkLayer>& stack, const V3<double>& wo, const V3<double>& wi,
                       const WalkOptions& options) {
  return layeredEvalEstimate(stack, wo, wi, options).value;
}

V3<double> layeredAlbedo(const std::vector<WalkLayer>& stack, const V3<double>& wo, const WalkOptions& options) {
  return layeredAlbedoEstimate(stack, wo, options).value;
}

}  // namespace substratec::reference
