// The position-free random walk through a layer stack (random_walk.h has the
// model and the estimator; this file follows it section by section):
//   1. random numbers (splitmix64);
//   2. the interfaces: GGX (pbrt-v4's TrowbridgeReitzDistribution: D, Smith
//      Lambda, visible-normal sampling), the rough dielectric (pbrt-v4's
//      DielectricBxDF, rough branch), the Schlick conductor, and the
//      pass-through of an index-matched boundary;
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
#include <numbers>
#include <vector>

#include "reference/common.h"
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

/// Isotropic GGX (Trowbridge-Reitz) with height-correlated Smith masking.
struct Ggx {
  double a = kWalkMinAlpha;

  double D(const V& m) const {
    if (m[2] <= 0) return 0;
    double a2 = a * a;
    double d = a2 * m[2] * m[2] + (m[0] * m[0] + m[1] * m[1]);
    return a2 / (std::numbers::pi * d * d);
  }
  double lambda(const V& w) const {
    double c2 = w[2] * w[2];
    if (c2 == 0) return kInf;
    double x = a * a * (w[0] * w[0] + w[1] * w[1]) / c2;
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
    V wh = normalize(V{a * w[0], a * w[1], w[2]});
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
    return normalize(V{a * nh[0], a * nh[1], std::max(1e-6, nh[2])});
  }
};

enum class Mode { Radiance, Importance };
enum Flags : int { kReflection = 1, kTransmission = 2, kAll = 3 };

struct Interface {
  enum class Kind { Pass, Dielectric, Conductor } kind = Kind::Pass;
  double eta = 1;  // dielectric: IOR below / IOR above
  Ggx ggx;
  V f0{0, 0, 0}, f90{1, 1, 1};  // conductor: Schlick per channel
};

struct BsdfSample {
  V f{0, 0, 0};
  V wi{0, 0, 1};
  double pdf = 0;
  bool reflect = false;
};

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

V schlick(const Interface& I, double c) {
  double m = std::clamp(1 - c, 0.0, 1.0);
  double m5 = m * m * m * m * m;
  return I.f0 + (I.f90 - I.f0) * m5;
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

/// BSDF value (no cosine). wo: towards where the walk came from; wi: onward.
V bsdfF(const Interface& I, const V& wo, const V& wi, Mode mode) {
  switch (I.kind) {
    case Interface::Kind::Pass: return {0, 0, 0};
    case Interface::Kind::Conductor: {
      if (wo[2] <= 0 || wi[2] <= 0) return {0, 0, 0};
      V h = wo + wi;
      double l2 = dot(h, h);
      if (!(l2 > 0)) return {0, 0, 0};
      h = h / std::sqrt(l2);
      double s = I.ggx.D(h) * I.ggx.G(wo, wi) / (4 * wo[2] * wi[2]);
      return schlick(I, std::fabs(dot(wo, h))) * s;
    }
    case Interface::Kind::Dielectric: {
      V wm;
      double etap;
      bool reflect;
      if (!dielectricHalf(I, wo, wi, wm, etap, reflect)) return {0, 0, 0};
      double F = fresnelDielectric(dot(wo, wm), I.eta);
      if (reflect) return splat3(I.ggx.D(wm) * I.ggx.G(wo, wi) * F / std::fabs(4 * wi[2] * wo[2]));
      double denom = sq(dot(wi, wm) + dot(wo, wm) / etap) * wi[2] * wo[2];
      double ft = I.ggx.D(wm) * (1 - F) * I.ggx.G(wo, wi) * std::fabs(dot(wi, wm) * dot(wo, wm) / denom);
      if (mode == Mode::Radiance) ft /= etap * etap;
      return splat3(ft);
    }
  }
  return {0, 0, 0};
}

/// Solid-angle density with which bsdfSample(wo, flags) returns wi.
double bsdfPdf(const Interface& I, const V& wo, const V& wi, int flags) {
  switch (I.kind) {
    case Interface::Kind::Pass: return 0;
    case Interface::Kind::Conductor: {
      if (!(flags & kReflection) || wo[2] <= 0 || wi[2] <= 0) return 0;
      V h = wo + wi;
      double l2 = dot(h, h);
      if (!(l2 > 0)) return 0;
      h = h / std::sqrt(l2);
      return I.ggx.Dv(wo, h) / (4 * std::fabs(dot(wo, h)));
    }
    case Interface::Kind::Dielectric: {
      V wm;
      double etap;
      bool reflect;
      if (!dielectricHalf(I, wo, wi, wm, etap, reflect)) return 0;
      double R = fresnelDielectric(dot(wo, wm), I.eta);
      double pr = (flags & kReflection) ? R : 0, pt = (flags & kTransmission) ? 1 - R : 0;
      if (pr == 0 && pt == 0) return 0;
      if (reflect) return I.ggx.Dv(wo, wm) / (4 * std::fabs(dot(wo, wm))) * pr / (pr + pt);
      double denom = sq(dot(wi, wm) + dot(wo, wm) / etap);
      return I.ggx.Dv(wo, wm) * std::fabs(dot(wi, wm)) / denom * pt / (pr + pt);
    }
  }
  return 0;
}

/// Samples wi from wo (visible normals, then reflection or transmission by
/// Fresnel among the allowed ones). Not for pass-through interfaces.
bool bsdfSample(const Interface& I, const V& wo, SplitMix64& rng, Mode mode, int flags, BsdfSample& s) {
  const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
  if (wo[2] == 0) return false;
  if (I.kind == Interface::Kind::Conductor) {
    if (!(flags & kReflection) || wo[2] <= 0) return false;
    V wm = I.ggx.sample(wo, u1, u2);
    V wi = reflectAbout(wo, wm);
    if (wi[2] <= 0) return false;
    double c = std::fabs(dot(wo, wm));
    s.wi = wi;
    s.pdf = I.ggx.Dv(wo, wm) / (4 * c);
    s.f = schlick(I, c) * (I.ggx.D(wm) * I.ggx.G(wo, wi) / (4 * wo[2] * wi[2]));
    s.reflect = true;
    return s.pdf > 0;
  }
  if (I.kind != Interface::Kind::Dielectric) return false;
  V wm = I.ggx.sample(wo, u1, u2);
  double R = fresnelDielectric(dot(wo, wm), I.eta);
  double pr = (flags & kReflection) ? R : 0, pt = (flags & kTransmission) ? 1 - R : 0;
  if (pr == 0 && pt == 0) return false;
  if (uc < pr / (pr + pt)) {
    V wi = reflectAbout(wo, wm);
    if (wo[2] * wi[2] <= 0) return false;
    s.wi = wi;
    s.pdf = I.ggx.Dv(wo, wm) / (4 * std::fabs(dot(wo, wm))) * pr / (pr + pt);
    s.f = splat3(I.ggx.D(wm) * I.ggx.G(wo, wi) * R / std::fabs(4 * wi[2] * wo[2]));
    s.reflect = true;
    return s.pdf > 0;
  }
  V wi;
  double etap;
  if (!refract(wo, wm, I.eta, etap, wi)) return false;
  if (wo[2] * wi[2] >= 0 || wi[2] == 0) return false;
  double denom = sq(dot(wi, wm) + dot(wo, wm) / etap);
  s.wi = wi;
  s.pdf = I.ggx.Dv(wo, wm) * std::fabs(dot(wi, wm)) / denom * pt / (pr + pt);
  double ft = (1 - R) * I.ggx.D(wm) * I.ggx.G(wo, wi) * std::fabs(dot(wi, wm) * dot(wo, wm) / (wi[2] * wo[2] * denom));
  if (mode == Mode::Radiance) ft /= etap * etap;
  s.f = splat3(ft);
  s.reflect = false;
  return s.pdf > 0;
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

double saturate1(double x) { return std::clamp(x, 0.0, 1.0); }

/// The albedo under a slab's own interface (WalkOptions::albedoSeenThroughInterface):
/// the A' whose light, re-reflected inside by the interface (cosine-weighted
/// internal reflectance R21), leaves as A: A'(1 - R21) / (1 - R21 A') = A.
double underInterface(double A, double f0) {
  double r21 = internalReflectance(iorFromF0(std::clamp(f0, 0.0, kMaxF0)));
  return std::clamp(A / (1 - r21 + r21 * A), 0.0, 1.0);
}

/// The stack with the IORs and optical thicknesses of channel `rc`; per-channel
/// weights (albedos, conductor Fresnel) for all channels.
Resolved resolve(const std::vector<WalkLayer>& stack, const std::vector<V>& albedos, int rc, bool absoluteIor) {
  Resolved r;
  double nAbove = 1;  // absoluteIor: the IOR of the layer above (air at the top)
  for (std::size_t i = 0; i < stack.size(); ++i) {
    const WalkLayer& L = stack[i];
    const bool bottom = i + 1 == stack.size() || L.opaqueBase;
    Interface I;
    double rough = saturate1(L.roughness);
    I.ggx.a = std::max(rough * rough, kWalkMinAlpha);
    const bool conductor = L.opaqueBase && L.diffuseAlbedo[0] <= 0 && L.diffuseAlbedo[1] <= 0 && L.diffuseAlbedo[2] <= 0;
    if (conductor) {
      I.kind = Interface::Kind::Conductor;
      I.f0 = vclamp(L.f0, 0.0, 1.0);
      I.f90 = vclamp(L.f90, 0.0, 1.0);
      r.ifc.push_back(I);
      r.med.push_back(Medium{});
      r.bottom = Bottom::Conductor;
      break;
    }
    const double n = iorFromF0(std::clamp(L.f0[rc], 0.0, kMaxF0));
    I.eta = absoluteIor ? n / nAbove : n;
    nAbove = n;
    I.kind = I.eta == 1 ? Interface::Kind::Pass : Interface::Kind::Dielectric;
    Medium M;
    M.g = std::clamp(L.phaseAnisotropy, -kMaxG, kMaxG);
    r.ifc.push_back(I);
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
  return s;
}

/// Channels grouped by geometryKey, each group's stack ready to walk.
std::vector<Group> groups(const std::vector<WalkLayer>& rawStack, bool throughInterface, bool absoluteIor) {
  std::vector<WalkLayer> stack;
  for (const WalkLayer& L : rawStack) stack.push_back(sanitized(L));
  std::vector<V> albedos;
  for (const WalkLayer& L : stack) {
    V a = vclamp(L.diffuseAlbedo, 0.0, 1.0);
    if (throughInterface)
      for (int c = 0; c < 3; ++c) a[c] = underInterface(a[c], L.f0[c]);
    albedos.push_back(a);
  }
  std::vector<Group> out;
  std::vector<std::vector<double>> keys;
  for (int c = 0; c < 3; ++c) {
    Resolved r = resolve(stack, albedos, c, absoluteIor);
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

/// Russian roulette (pbrt's LayeredBxDF): false when the walk ends.
bool roulette(V& beta, int depth, const std::array<bool, 3>& mask, SplitMix64& rng) {
  double mb = maxMasked(beta, mask);
  if (!(mb > 0)) return false;
  if (depth > 3 && mb < 0.25) {
    double q = std::max(0.0, 1 - mb);
    if (rng.uniform() < q) return false;
    beta = beta / (1 - q);
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
  if (!bsdfSample(I, from, rng, Mode::Importance, flags, bs)) return false;
  beta = beta * bs.f * (std::fabs(bs.wi[2]) / bs.pdf);
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
      if (k == 0) wgt = wgt / std::fabs(c[2]);
    } else {
      BsdfSample bs;
      if (!bsdfSample(I, from, rng, Mode::Radiance, kTransmission, bs)) break;
      c = bs.wi;
      // The cosine of the segment above I_k (towards the exit) for k >= 1;
      // at I_0 that segment is wi's, which the caller's |cos wi| carries.
      wgt = wgt * bs.f * ((k == 0 ? 1.0 : std::fabs(from[2])) / bs.pdf);
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
    V fe = bsdfF(s.ifc[0], neg(w1), wi, Mode::Importance);
    if (isZero(fe)) return;
    double pB = bsdfPdf(s.ifc[0], wi, neg(w1), kTransmission);
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
    if (exitDelta) {
      w = neg(wo);
    } else {
      BsdfSample bs;
      if (!bsdfSample(s.ifc[0], wo, rng, Mode::Importance, kTransmission, bs)) return false;
      w = bs.wi;
      beta = bs.f * (std::fabs(w[2]) / bs.pdf);
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
      // Leaving is counted at the last vertex: only reflection continues.
      if (exitDelta) return false;
      BsdfSample bs;
      return bounce(I, neg(w), kReflection, rng, beta, w, bs);
    }
    if (I.kind == Interface::Kind::Pass) {
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
    if (I.kind == Interface::Kind::Pass) {
      ++k;
      t = 0;
      return true;
    }
    if (k < chainLen) {
      V lw = neg(chainDir[k]);
      V fv = bsdfF(I, neg(w), lw, Mode::Importance);
      if (!isZero(fv)) connectB(fv * std::fabs(lw[2]), bsdfPdf(I, neg(w), lw, kAll), std::exp(-trUp / std::fabs(lw[2])));
    }
    BsdfSample bs;
    if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) return false;
    if (bs.reflect) {
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

/// layeredEval for one group: sum over the walks of f(wo, wi) (no cosine), divided by the count.
Estimate evalGroup(const Group& grp, const V& wo, const V& wi, const WalkOptions& o, SplitMix64& rng) {
  const Resolved& s = grp.stack;
  const Interface& top = s.ifc[0];
  const V topReflection = bsdfF(top, wo, wi, Mode::Importance);
  const int last = s.lastLayer();
  if (last < 0 || o.samples <= 0) return Tally{}.estimate(topReflection);  // a conductor alone
  const bool exitDelta = top.kind == Interface::Kind::Pass;

  std::vector<V> chainDir(static_cast<std::size_t>(last) + 1), chainW(static_cast<std::size_t>(last) + 1);
  Tally tally;
  for (int sample = 0; sample < o.samples; ++sample) {
    V sum{0, 0, 0};
    double pB0 = kInf;
    const int chainLen = traceLightChain(s, last, wi, rng, chainDir, chainW, pB0);
    EvalWalk walk{s, wi, exitDelta, chainDir, chainW, chainLen, pB0, rng, sum};
    if (walk.enter(wo)) walk.run(o.maxDepth, grp.mask);
    tally.add(sum);
  }
  return tally.estimate(topReflection);
}

/// layeredAlbedo for one group: the mean weight with which forward walks leave the top.
Estimate albedoGroup(const Group& grp, const V& wo, const WalkOptions& o, SplitMix64& rng) {
  const Resolved& s = grp.stack;
  const int n = static_cast<int>(s.ifc.size());
  Tally tally;
  for (int sample = 0; sample < o.samples; ++sample) {
    V sum{0, 0, 0};
    V beta{1, 1, 1}, w = neg(wo);
    int k = 0;
    double t = 0;
    bool atTopFromAbove = true;  // the first event: I_0 from outside
    for (int depth = 0; depth < o.maxDepth; ++depth) {
      if (!roulette(beta, depth, grp.mask, rng)) break;
      if (atTopFromAbove) {
        atTopFromAbove = false;
        const Interface& I = s.ifc[0];
        if (I.kind != Interface::Kind::Pass) {
          BsdfSample bs;
          if (!bounce(I, wo, kAll, rng, beta, w, bs)) break;
          if (w[2] > 0) {
            sum = sum + beta;
            break;
          }
        }
        continue;
      }
      const Medium& M = s.med[k];
      bool alive;
      if (propagate(M, w, t, beta, rng, alive)) {
        w = sampleHg(w, M.g, rng.uniform(), rng.uniform());
        beta = beta * M.omega;
        continue;
      }
      if (!alive) break;
      if (w[2] > 0) {
        const Interface& I = s.ifc[k];
        bool up = true;
        if (I.kind != Interface::Kind::Pass) {
          BsdfSample bs;
          if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) break;
          up = !bs.reflect;
        }
        if (up) {
          if (k == 0) {
            sum = sum + beta;
            break;
          }
          --k;
          t = s.med[k].tau;
        }
        continue;
      }
      if (k == n - 1) {  // the Lambertian base
        if (s.bottom != Bottom::Lambert) break;
        w = sampleCosine(rng.uniform(), rng.uniform());
        beta = beta * s.lambert;
        continue;
      }
      const Interface& I = s.ifc[k + 1];
      bool down = true;
      if (I.kind != Interface::Kind::Pass) {
        BsdfSample bs;
        if (!bounce(I, neg(w), kAll, rng, beta, w, bs)) break;
        down = !bs.reflect;
      }
      if (down) {
        ++k;
        t = 0;
      }
    }
    tally.add(sum);
  }
  return tally.estimate();
}

V unitOr(const V& v, const V& fallback) {
  double l2 = dot(v, v);
  if (!(l2 > 0) || !std::isfinite(l2)) return fallback;
  return v / std::sqrt(l2);
}

/// Runs `walk` per channel group and gathers each group's channels.
template <class F>
Estimate perGroup(const std::vector<WalkLayer>& stack, const WalkOptions& o, std::uint64_t purpose, F&& walk) {
  Estimate out;
  if (stack.empty()) return out;
  std::vector<Group> gs = groups(stack, o.albedoSeenThroughInterface, o.absoluteIor);
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
