// The Monte Carlo reference for rough diffuse reflection (diffuse_reference.h):
// Heitz et al. 2016's random walk on a GGX Smith microsurface with Lambertian
// facets, and the error table of the runtime's diffuse models against it.
#include "reference/diffuse_reference.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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
constexpr int kMaxHits = 4096;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A splitmix64 stream (util/random.h) per call, seeded from `seed`.
SplitMix64 diffuseStream(std::uint32_t seed) {
  return SplitMix64{0x243F6A8885A308D3ull ^ (static_cast<std::uint64_t>(seed) << 17u)};
}

/// Smith's Lambda of isotropic GGX for a direction of cosine z (any sign):
/// (-1 + sqrt(1 + a^2 tan^2))/2 above the horizon (written without
/// cancellation), Lambda(-w) = -1 - Lambda(w) below; +-inf at z = 0.
double lambda(double alpha, double z) {
  double az = std::fabs(z);
  if (az >= 1.0) return z > 0 ? 0.0 : -1.0;
  double x = alpha * alpha * (1.0 - az * az) / (az * az);  // a^2 tan^2 (inf at z = 0)
  double up = std::isinf(x) ? x : x / (2.0 * (1.0 + std::sqrt(1.0 + x)));
  return z > 0 ? up : -1.0 - up;
}

/// G1(w, h) = C1(h)^Lambda(w) with t = ln C1(h) <= 0: the probability that a
/// ray leaving height h in direction w escapes the microsurface.
double g1(double alpha, const D3& w, double t) {
  if (!(w[2] > 0)) return 0.0;
  double l = lambda(alpha, w[2]);
  if (l == 0.0) return 1.0;
  return std::exp(l * t);
}

/// A normal drawn from the visible normals of GGX(alpha) seen from direction
/// `v` (unit, any hemisphere): density <v, m>+ D(m) / (projected area), m.z > 0.
/// Dupuy & Benyoub 2023: in the stretched (alpha = 1) configuration the visible
/// normals are normalize(c + v) with c uniform on the spherical cap z > -v.z.
D3 sampleVisibleNormal(double alpha, const D3& v, double u1, double u2) {
  D3 s = normalize(D3{alpha * v[0], alpha * v[1], v[2]});
  double phi = 2.0 * std::numbers::pi * u1;
  double z = (1.0 - u2) * (1.0 + s[2]) - s[2];
  double sinT = std::sqrt(std::max(0.0, 1.0 - z * z));
  D3 h{sinT * std::cos(phi) + s[0], sinT * std::sin(phi) + s[1], z + s[2]};
  D3 m{alpha * h[0], alpha * h[1], std::max(h[2], 0.0)};
  double len = length(m);
  if (!(len > 1e-300)) return D3{0.0, 0.0, 1.0};
  return m / len;
}

/// A cosine-distributed direction about the unit normal m.
D3 sampleCosine(const D3& m, double u1, double u2) {
  D3 t, b;
  orthonormalBasis(m, t, b);
  double r = std::sqrt(u1);
  double phi = 2.0 * std::numbers::pi * u2;
  double z = std::sqrt(std::max(0.0, 1.0 - u1));
  return t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + m * z;
}

/// One free flight from log-height t in direction w: the next facet hit's
/// log-height, or +inf when the ray leaves the microsurface (Heitz et al.'s
/// sampleHeight with C1 replaced by exp(t)).
double flight(double alpha, const D3& w, double t, double u) {
  double l = lambda(alpha, w[2]);
  if (std::isinf(l)) return t;  // horizontal: hits at once
  double e = std::log1p(-u);    // ln(1 - u) <= 0
  if (w[2] > 0) {
    if (l <= 0.0) return kInf;  // vertical (or alpha = 0): nothing above
    double tn = t - e / l;
    return tn >= 0.0 ? kInf : tn;
  }
  return t + e / -l;  // downward: Lambda <= -1
}

struct Walk {
  double alpha, rho;
};

/// One walk entering from wo: the next-event estimate of f(wo, wi) cos(wi)
/// (wi non-null) and/or the escaped throughput (the albedo estimate).
void walk(const Walk& w, const D3& wo, const D3* wi, SplitMix64& rng, double& nee, double& escaped) {
  double t = 0.0;  // ln C1 at the top of the microsurface
  D3 dir = -wo;    // travel direction
  double thr = 1.0;
  for (int hit = 0; hit < kMaxHits; ++hit) {
    t = flight(w.alpha, dir, t, rng.uniform());
    if (std::isinf(t)) {
      escaped += thr;
      return;
    }
    double u1 = rng.uniform(), u2 = rng.uniform();
    D3 m = sampleVisibleNormal(w.alpha, -dir, u1, u2);
    if (wi) nee += thr * w.rho / std::numbers::pi * std::max(0.0, dot(*wi, m)) * g1(w.alpha, *wi, t);
    double u3 = rng.uniform(), u4 = rng.uniform();
    dir = sampleCosine(m, u3, u4);
    thr *= w.rho;
    if (thr == 0.0) return;
  }
}

Walk makeWalk(double albedo, double roughness) {
  double r = saturate(roughness);
  return Walk{r * r, saturate(albedo)};
}

}  // namespace

double microfacetDiffuse(double albedo, double roughness, const D3& wo, const D3& wi, int samples,
                         std::uint32_t seed) {
  if (!(wo[2] > 0) || !(wi[2] > 0) || samples <= 0) return 0.0;
  Walk w = makeWalk(albedo, roughness);
  SplitMix64 rng = diffuseStream(seed);
  double nee = 0.0, escaped = 0.0;
  for (int i = 0; i < samples; ++i) walk(w, wo, &wi, rng, nee, escaped);
  return nee / samples;
}

double microfacetDiffuseAlbedo(double albedo, double roughness, const D3& wo, int samples, std::uint32_t seed) {
  if (!(wo[2] > 0) || samples <= 0) return 0.0;
  Walk w = makeWalk(albedo, roughness);
  SplitMix64 rng = diffuseStream(seed);
  double nee = 0.0, escaped = 0.0;
  for (int i = 0; i < samples; ++i) walk(w, wo, nullptr, rng, nee, escaped);
  return escaped / samples;
}

namespace {

constexpr int kModels = 4;

Closure<double> pureDiffuse(double albedo, double roughness) {
  Closure<double> c;
  c.diffuseAlbedo = splat3(albedo);
  c.f0 = splat3(0.0);
  c.f90 = splat3(0.0);
  c.features = kFeatureF90;  // f90 = 0 instead of the default 1: no specular, E_spec = 0
  c.roughness = roughness;
  return c;
}

/// Directional albedo of evalClosure: midpoint rule, 64 cos(theta_i) x 64 phi
/// over [0, pi], doubled (wo lies in the xz plane, the models are isotropic).
double modelAlbedo(const Closure<double>& c, const D3& wo, int model) {
  constexpr int n = 64;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    double mu = (i + 0.5) / n;
    double s = std::sqrt(1.0 - mu * mu);
    for (int j = 0; j < n; ++j) {
      double phi = std::numbers::pi * (j + 0.5) / n;
      sum += evalClosure(c, wo, D3{s * std::cos(phi), s * std::sin(phi), mu}, model)[0];
    }
  }
  return sum * (1.0 / n) * (std::numbers::pi / n) * 2.0;  // d(mu) d(phi), both halves
}

}  // namespace

std::vector<DiffuseModelError> diffuseModelErrors(const std::vector<double>& roughnesses, int viewCount,
                                                  int lightCount, int samples, double albedo) {
  std::vector<DiffuseModelError> out;
  for (int m = 0; m < kModels; ++m) out.push_back(DiffuseModelError{m, 0.0, 0.0, 0.0});
  std::vector<double> sq(kModels, 0.0);
  long count = 0;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::uint32_t seed = 1;
  for (double r : roughnesses) {
    Closure<double> c = pureDiffuse(albedo, r);
    for (int i = 0; i < viewCount; ++i) {
      double muO = (i + 0.5) / viewCount;
      D3 wo{std::sqrt(1.0 - muO * muO), 0.0, muO};
      double refAlbedo = microfacetDiffuseAlbedo(albedo, r, wo, 4 * samples, seed++);
      for (int m = 0; m < kModels; ++m)
        out[m].albedoError = std::max(out[m].albedoError, std::fabs(modelAlbedo(c, wo, m) - refAlbedo));
      for (int j = 0; j < lightCount; ++j) {
        double muI = 1.0 - (j + 0.5) / lightCount;
        double s = std::sqrt(1.0 - muI * muI);
        double phi = golden * j;
        D3 wi{s * std::cos(phi), s * std::sin(phi), muI};
        double y = microfacetDiffuse(albedo, r, wo, wi, samples, seed++);
        for (int m = 0; m < kModels; ++m) {
          double x = evalClosure(c, wo, wi, m)[0];
          double d = x - y;
          sq[m] += d * d / (y * y + 0.01);
          out[m].maxAbs = std::max(out[m].maxAbs, std::fabs(d));
        }
        ++count;
      }
    }
  }
  for (int m = 0; m < kModels; ++m) out[m].relMse = count > 0 ? sq[m] / static_cast<double>(count) : 0.0;
  return out;
}

}  // namespace substratec::reference
