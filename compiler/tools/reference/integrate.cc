// The reference for environment lighting (no shader counterpart: it measures
// the error of substrate_env_split_sum, runtime_shaders/substrate_lighting.h):
//   integral over the sphere of radiance(L) lightThroughput(c, t_V, t_L) evalClosure(c, V, L) dL
// by multiple importance sampling with the balance heuristic. Strategies, each
// with `samples` points of a Hammersley set under its own Cranley-Patterson
// rotation (drawn from the seed): GGX visible normals (Heitz 2018, "Sampling
// the GGX Distribution of Visible Normals") of the primary lobe and, when it has
// weight, of the haze lobe, at the lobes' clamped alphas (substrate_ggx_alpha);
// the cosine-weighted hemisphere (diffuse, fuzz); the Charlie sheen distribution
// (fuzz: its lobe lies along the horizon for smooth fuzz, where the cosine
// strategy puts few points); the uniform sphere for SSS
// wrap (lit from below the horizon). Every strategy contributes
// f(x) / sum_k p_k(x) per point, averaged over its points: unbiased wherever one
// strategy's density is positive, which covers every direction the closure
// reflects (NoL > 0, and NoL > -w for wrap).
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "reference/bsdf.h"
#include "reference/common.h"
#include "reference/reference.h"
#include "util/random.h"

namespace substratec::reference {
using namespace detail;

namespace {

using D3 = V3<double>;

double radicalInverse(std::uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xAAAAAAAAu) >> 1u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xCCCCCCCCu) >> 2u);
  i = ((i & 0x0F0F0F0Fu) << 4u) | ((i & 0xF0F0F0F0u) >> 4u);
  i = ((i & 0x00FF00FFu) << 8u) | ((i & 0xFF00FF00u) >> 8u);
  return static_cast<double>(i) * (1.0 / 4294967296.0);
}


double fract(double x) { return x - std::floor(x); }

/// The local frame (T, B, N) of the closure and the view in it, lifted to
/// z >= 1e-4 for the visible-normal sampling (a view at or below the horizon
/// has no visible normals; the lifted view defines a valid density all the same).
struct Frame {
  D3 t, b, n;
  D3 toLocal(const D3& v) const { return {dot(v, t), dot(v, b), dot(v, n)}; }
  D3 toWorld(const D3& v) const { return t * v[0] + b * v[1] + n * v[2]; }
};

/// GGX of alphas (ax, ay) sampled by visible normals for the local view Ve (z > 0).
struct VisibleGgx {
  double ax, ay;
  D3 Ve;

  double D(const D3& h) const {
    if (h[2] <= 0) return 0;
    double x = h[0] / ax, y = h[1] / ay, z = h[2];
    double k = x * x + y * y + z * z;
    return 1.0 / (std::numbers::pi * ax * ay * k * k);
  }
  double G1() const {
    double s = (ax * ax * Ve[0] * Ve[0] + ay * ay * Ve[1] * Ve[1]) / (Ve[2] * Ve[2]);
    return 2.0 / (1.0 + std::sqrt(1.0 + s));
  }
  /// Density of the local light direction l: D_V(h) / (4 V.h) = G1(V) D(h) / (4 V.z).
  double pdf(const D3& l) const {
    D3 hv = Ve + l;
    double len = length(hv);
    if (!(len > 1e-12)) return 0;
    D3 h = hv / len;
    if (dot(Ve, h) <= 0) return 0;
    return G1() * D(h) / (4.0 * Ve[2]);
  }
  D3 sample(double u1, double u2) const {
    D3 vh = normalize(D3{ax * Ve[0], ay * Ve[1], Ve[2]});
    double lensq = vh[0] * vh[0] + vh[1] * vh[1];
    D3 t1 = lensq > 0 ? D3{-vh[1], vh[0], 0} / std::sqrt(lensq) : D3{1, 0, 0};
    D3 t2 = cross(vh, t1);
    double r = std::sqrt(u1), phi = 2.0 * std::numbers::pi * u2;
    double p1 = r * std::cos(phi), p2 = r * std::sin(phi);
    double s = 0.5 * (1.0 + vh[2]);
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    D3 nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2));
    D3 h = normalize(D3{ax * nh[0], ay * nh[1], std::max(0.0, nh[2])});
    return h * (2.0 * dot(Ve, h)) - Ve;  // reflect(-Ve, h)
  }
};

/// The Charlie sheen distribution of alpha a (substrate_charlie_d), sampled
/// exactly: D(h) NoH is a density over the hemisphere of h whose sin(theta_h)
/// has the CDF s^(2 + 1/a). The light is the view reflected about h; an h that
/// faces away from the view yields no sample (the density below is then that
/// of the directions it does yield, a sub-density, which the balance heuristic
/// accepts).
struct Sheen {
  double a;
  D3 Ve;

  double D(double NoH) const {
    const double inv = 1.0 / a;
    return (2.0 + inv) * std::pow(std::max(1.0 - NoH * NoH, 0.0), 0.5 * inv) * (0.5 / std::numbers::pi);
  }
  double pdf(const D3& l) const {
    D3 hv = Ve + l;
    double len = length(hv);
    if (!(len > 1e-12)) return 0;
    D3 h = hv / len;
    const double VoH = dot(Ve, h);
    if (VoH <= 0 || h[2] <= 0) return 0;
    return D(h[2]) * h[2] / (4.0 * VoH);
  }
  D3 sample(double u1, double u2) const {
    const double sinT = std::pow(u1, 1.0 / (2.0 + 1.0 / a));
    const double cosT = std::sqrt(std::max(0.0, 1.0 - sinT * sinT));
    const double phi = 2.0 * std::numbers::pi * u2;
    const D3 h{sinT * std::cos(phi), sinT * std::sin(phi), cosT};
    const double VoH = dot(Ve, h);
    if (!(VoH > 0)) return {0, 0, 0};
    return h * (2.0 * VoH) - Ve;
  }
};

enum class Kind { Ggx, Cosine, Sphere, Sheen };
struct Strategy {
  Kind kind;
  VisibleGgx ggx;  // Kind::Ggx
  Sheen sheen{1, {0, 0, 1}};  // Kind::Sheen
};

double pdfOf(const Strategy& s, const D3& l) {
  switch (s.kind) {
    case Kind::Ggx: return s.ggx.pdf(l);
    case Kind::Cosine: return l[2] > 0 ? l[2] / std::numbers::pi : 0.0;
    case Kind::Sphere: return 1.0 / (4.0 * std::numbers::pi);
    case Kind::Sheen: return s.sheen.pdf(l);
  }
  return 0;
}

D3 sampleOf(const Strategy& s, double u1, double u2) {
  switch (s.kind) {
    case Kind::Ggx: return s.ggx.sample(u1, u2);
    case Kind::Cosine: {
      double r = std::sqrt(u1), phi = 2.0 * std::numbers::pi * u2;
      return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1))};
    }
    case Kind::Sphere: {
      double z = 1.0 - 2.0 * u1, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * std::numbers::pi * u2;
      return {r * std::cos(phi), r * std::sin(phi), z};
    }
    case Kind::Sheen: return s.sheen.sample(u1, u2);
  }
  return {0, 0, 1};
}

}  // namespace

V3<double> envIntegrated(const Closure<double>& c, const V3<double>& V,
                         const std::function<V3<double>(const V3<double>&)>& radiance, int diffuseModel, int samples,
                         std::uint32_t seed) {
  D3 sum{0, 0, 0};
  if (samples <= 0) return sum;
  Frame fr;
  fr.n = closureNormal(c);
  closureFrame(c, fr.n, fr.t, fr.b);
  D3 Ve = fr.toLocal(V);
  Ve[2] = std::max(Ve[2], 1e-4);
  Ve = normalize(Ve);

  const double anisotropy = (c.features & kFeatureAnisotropy) ? clampT(c.anisotropy, -1.0, 1.0) : 0.0;
  std::vector<Strategy> strategies;
  auto addGgx = [&](double roughness) {
    V2<double> a = ggxAlpha(saturate(roughness), anisotropy);
    strategies.push_back({Kind::Ggx, VisibleGgx{a[0], a[1], Ve}});
  };
  addGgx(c.roughness);
  if ((c.features & kFeatureHaze) && saturate(c.secondRoughnessWeight) > 0) addGgx(c.secondRoughness);
  strategies.push_back({Kind::Cosine, {}});
  if ((c.features & kFeatureFuzz) && saturate(c.fuzzAmount) > 0) {
    // The sheen lobe of smooth fuzz lies along the horizon, where the cosine
    // strategy puts few points: sampled by its own distribution (a = max(r^2,
    // 1e-3), substrate_charlie_sheen).
    const double r = saturate(c.fuzzRoughness);
    strategies.push_back({Kind::Sheen, {}, Sheen{std::max(r * r, 1e-3), Ve}});
  }
  if (c.sssType == kSssWrap) strategies.push_back({Kind::Sphere, {}});

  // The light meets the layers above only where the view met them (lightThroughput).
  const D3 viewCrossing = layersCrossing(c, dot(fr.n, V), V);
  std::uint64_t state = seed;
  for (const Strategy& s : strategies) {
    // the rotations from the seed (splitmix64, util/random.h)
    const double r1 = unitInterval(splitmix64(state)), r2 = unitInterval(splitmix64(state));
    D3 acc{0, 0, 0};
    for (int j = 0; j < samples; ++j) {
      const double u1 = fract((j + 0.5) / samples + r1);
      const double u2 = fract(radicalInverse(static_cast<std::uint32_t>(j)) + r2);
      D3 l = sampleOf(s, u1, u2);
      const double len = length(l);
      if (!(len > 0)) continue;
      l = l / len;
      double pdfSum = 0;
      for (const Strategy& k : strategies) pdfSum += pdfOf(k, l);
      if (!(pdfSum > 0)) continue;
      const D3 L = fr.toWorld(l);
      const D3 f = evalClosure(c, V, L, diffuseModel);
      if (f[0] == 0 && f[1] == 0 && f[2] == 0) continue;
      const D3 lightCrossing = layersCrossing(c, wrapLightCosine(c, dot(fr.n, L)), L);
      acc = acc + radiance(L) * lightThroughput(c, viewCrossing, lightCrossing) * f / pdfSum;
    }
    sum = sum + acc / static_cast<double>(samples);
  }
  return sum;
}

}  // namespace substratec::reference
