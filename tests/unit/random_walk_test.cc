// The Monte Carlo ground truth for layered slabs (compiler/tools/reference/random_walk.h).
// These tests read like its spec: each expectation is computed here from
// textbook formulas (Fresnel, GGX, the layering closed form, van de Hulst's
// albedo) or is a physical law (energy, reciprocity), never read back from the
// code under test. Sample counts are modest (the suite takes a few seconds); the
// figures in the comments were measured with the counts written next to them.
#include <gtest/gtest.h>
#include <numbers>

#include <algorithm>
#include <chrono>
#include <array>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"
#include "reference/energy_lut.h"
#include "reference/random_walk.h"
#include "test_util.h"

namespace substratec {
namespace {

using namespace reference;
using D3 = V3<double>;

D3 dir(double mu, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  return {s * std::cos(phi), s * std::sin(phi), mu};
}
D3 grey(double x) { return {x, x, x}; }

// --- textbook formulas, written out independently of the code under test

/// Unpolarized Fresnel reflectance of a smooth boundary, light arriving at
/// cos(theta_i) = c > 0 from the medium of index n1 into n2.
double fresnel(double c, double n1, double n2) {
  double s2t = (n1 / n2) * (n1 / n2) * (1 - c * c);
  if (s2t >= 1) return 1;
  double ct = std::sqrt(1 - s2t);
  double rs = (n1 * c - n2 * ct) / (n1 * c + n2 * ct);
  double rp = (n1 * ct - n2 * c) / (n1 * ct + n2 * c);
  return 0.5 * (rs * rs + rp * rp);
}

/// Cosine-weighted hemispherical average of fresnel(., n1, n2): the integral of
/// F(mu) 2 mu dmu, midpoint rule with a million points.
double hemisphericalFresnel(double n1, double n2) {
  const int n = 1000000;
  double s = 0;
  for (int i = 0; i < n; ++i) {
    double mu = (i + 0.5) / n;
    s += fresnel(mu, n1, n2) * 2 * mu;
  }
  return s / n;
}

/// Isotropic GGX, height-correlated Smith (Heitz 2014), alpha = roughness^2.
double ggxD(double a, double cosH) {
  double a2 = a * a, d = cosH * cosH * (a2 - 1) + 1;
  return a2 / (std::numbers::pi * d * d);
}
double smithLambda(double a, double mu) {
  double t2 = (1 - mu * mu) / (mu * mu);
  return 0.5 * (-1 + std::sqrt(1 + a * a * t2));
}

/// Gulbrandsen 2014: (n, k) of normal reflectivity r and edge tint g.
std::pair<double, double> rwGulbrandsen(double r, double g) {
  r = std::min(r, 0.9999);
  g = std::min(g, 0.9999);
  const double n = g * (1 - r) / (1 + r) + (1 - g) * (1 + std::sqrt(r)) / (1 - std::sqrt(r));
  const double k2 = (r * (n + 1) * (n + 1) - (n - 1) * (n - 1)) / (1 - r);
  return {n, std::sqrt(std::max(0.0, k2))};
}
/// Fresnel reflectance of a conductor n + ik from air, with complex arithmetic (Born & Wolf).
double rwConductorFresnel(double c, double n, double k) {
  const std::complex<double> eta(n, k);
  const double s2 = 1 - c * c;
  const std::complex<double> ct = std::sqrt(1.0 - s2 / (eta * eta));
  const std::complex<double> rs = (c - eta * ct) / (c + eta * ct), rp = (eta * c - ct) / (eta * c + ct);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}

// --- stacks used by several tests

/// A rough dielectric over an SSS medium: the typical bottom slab.
WalkLayer sssBase() {
  WalkLayer L;
  L.f0 = grey(0.04);
  L.roughness = 0.5;
  L.diffuseAlbedo = {0.8, 0.5, 0.2};
  L.mfp = grey(0.01);
  return L;
}
/// A rough, scattering, absorbing coat of colored MFP (every channel walks alone).
WalkLayer dustyCoat() {
  WalkLayer L;
  L.f0 = grey(0.04);
  L.roughness = 0.3;
  L.diffuseAlbedo = grey(0.5);
  L.mfp = {0.002, 0.004, 0.01};
  L.thickness = 0.002;
  L.phaseAnisotropy = 0.3;
  return L;
}
/// A nearly smooth clear coat (alpha = 2.5e-3), as the examples' clear coats.
WalkLayer clearCoat() {
  WalkLayer L;
  L.f0 = grey(0.04);
  L.roughness = 0.05;
  L.diffuseAlbedo = grey(0);
  L.mfp = grey(0.01);
  L.thickness = 0.001;
  return L;
}
/// An opaque dielectric slab: a Lambertian under the interface.
WalkLayer plastic() {
  WalkLayer L;
  L.f0 = grey(0.04);
  L.roughness = 0.5;
  L.diffuseAlbedo = {0.7, 0.4, 0.1};
  L.opaqueBase = true;
  return L;
}
/// A conductor (WalkLayer::conductor: complex IOR from F0 and F90).
WalkLayer gold() {
  WalkLayer L;
  L.f0 = {0.9, 0.6, 0.3};
  L.roughness = 0.4;
  L.diffuseAlbedo = grey(0);
  L.opaqueBase = true;
  L.conductor = true;
  return L;
}

WalkOptions opts(int samples, std::uint32_t seed = 1, int maxDepth = 64) {
  WalkOptions o;
  o.samples = samples;
  o.seed = seed;
  o.maxDepth = maxDepth;
  return o;
}

#define EXPECT_REL(a, b, tol) EXPECT_NEAR((a) / (b), 1.0, tol) << (a) << " vs " << (b)

// ---------------------------------------------------------------------------
// The single-scattering albedo inversion.

TEST(RandomWalkInversion, RoundTripsVanDeHulst) {
  // van de Hulst's spherical albedo A(w) = (1 - s)(1 - 0.139 s) / (1 + 1.17 s),
  // s = sqrt(1 - w'), w' = w (1 - g) / (1 - w g); written out here.
  auto vdh = [](double w, double g) {
    double wr = w * (1 - g) / (1 - w * g);
    double s = std::sqrt(1 - wr);
    return (1 - s) * (1 - 0.139 * s) / (1 + 1.17 * s);
  };
  for (double g : {0.0, 0.5, -0.3, 0.9})
    for (int i = 0; i <= 40; ++i) {
      double A = i / 40.0;
      double w = singleScatteringAlbedo(A, g);
      EXPECT_GE(w, 0);
      EXPECT_LE(w, 1);
      EXPECT_NEAR(vdh(w, g), A, 1e-12) << "A " << A << " g " << g;
      EXPECT_NEAR(multipleScatteringAlbedo(w, g), A, 1e-12);
      if (i > 0) {
        EXPECT_GT(w, singleScatteringAlbedo((i - 1) / 40.0, g));
      }
    }
  // Kulla & Conty 2017's form with their rounded constants, at g = 0.
  for (double A : {0.1, 0.5, 0.8, 0.95}) {
    double s = 4.09712 + 4.20863 * A - std::sqrt(9.59217 + 41.6808 * A + 17.7126 * A * A);
    EXPECT_NEAR(singleScatteringAlbedo(A), 1 - s * s, 2e-5) << A;
  }
  EXPECT_NEAR(singleScatteringAlbedo(0.5), 0.9117066, 1e-6);
  EXPECT_EQ(singleScatteringAlbedo(0), 0);
  EXPECT_EQ(singleScatteringAlbedo(1), 1);
}

TEST(RandomWalkInversion, TheWalkOfTheInvertedMediumHasTheArtistsAlbedo) {
  // An index-matched (F0 = 0) semi-infinite medium of w = inverse(A): its
  // spherical albedo (directional albedo averaged with weight 2 mu dmu, 8
  // midpoints in mu^2, 4000 walks each, maxDepth 1e5) is A. Measured here:
  // |walk - A| <= 0.0048 (noise ~0.003); with 16 x 20000 walks <= 0.0015 over
  // A in {0.1 .. 0.97}, g in {0, 0.5}. Tolerance 0.012.
  for (double g : {0.0, 0.5})
    for (double A : {0.1, 0.5, 0.9}) {
      WalkLayer L;
      L.f0 = grey(0);
      L.diffuseAlbedo = grey(A);
      L.mfp = grey(1e-3);
      L.phaseAnisotropy = g;
      double h = 0;
      for (int i = 0; i < 8; ++i)
        h += layeredAlbedo({L}, dir(std::sqrt((i + 0.5) / 8), 0.3), opts(4000, 10 + i, 100000))[0] / 8;
      EXPECT_NEAR(h, A, 0.012) << "g " << g;
    }
}

// ---------------------------------------------------------------------------
// Layering against closed forms.

TEST(RandomWalkIndexMatched, AClearCoatOfIorOneIsTheBaseAlone) {
  // F0 = 0 is an index-matched boundary; with thickness 0 (or an MFP 1e9 times
  // the thickness) the coat is no matter at all: coat + base equals the base
  // within 4 combined standard errors (the Estimates'), eval (4096 walks) and
  // albedo (8192 walks). A velvet base (fuzz on its own F0-0 interface) keeps
  // its sheen under the coat (issue 19 step 8: the walk skipped it there).
  WalkLayer none;
  none.f0 = grey(0);
  none.roughness = 0.2;
  none.mfp = grey(1);
  none.thickness = 0;
  WalkLayer thin = none;
  thin.thickness = 1e-3;
  thin.mfp = grey(1e6);
  thin.diffuseAlbedo = grey(0.5);
  WalkLayer velvet = plastic();  // its fuzz on a pass-through: under the coat, walked as on top
  velvet.f0 = grey(0);
  velvet.fuzzAmount = 0.7;
  velvet.fuzzRoughness = 0.5;
  velvet.fuzzColor = {1, 0.7, 0.4};
  int cases = 0;
  for (const WalkLayer& coat : {none, thin})
    for (const WalkLayer& base : {sssBase(), plastic(), velvet}) {
      for (auto [wo, wi] : {std::pair{dir(0.8, 0.1), dir(0.3, 2.0)}, std::pair{dir(0.5, 0), dir(0.6, 3.0)}}) {
        const Estimate a = layeredEvalEstimate({coat, base}, wo, wi, opts(4096, 3));
        const Estimate b = layeredEvalEstimate({base}, wo, wi, opts(4096, 4));
        for (int c = 0; c < 3; ++c, ++cases)
          EXPECT_NEAR(a.value[c], b.value[c], 4 * std::hypot(a.standardError[c], b.standardError[c]));
      }
      const Estimate a = layeredAlbedoEstimate({coat, base}, dir(0.7, 0), opts(8192, 5));
      const Estimate b = layeredAlbedoEstimate({base}, dir(0.7, 0), opts(8192, 6));
      for (int c = 0; c < 3; ++c, ++cases)
        EXPECT_NEAR(a.value[c], b.value[c], 4 * std::hypot(a.standardError[c], b.standardError[c]));
    }
  EXPECT_EQ(cases, 54);
}

TEST(RandomWalkIndexMatched, AVelvetsFuzzIsWalkedOnItsIndexMatchedInterface) {
  // A velvet: fuzz on a slab of F0 0 (a pass-through) over its own Lambertian.
  // The sheen layer on top reflects amount * colour * E_fuzz(mu_o) (up to the
  // table's own error) and lets the rest through, both ways, with weight
  // 1 - amount * min(E_fuzz(mu), 1); what it catches from below it sends back
  // down, tinted by its colour (random_walk.h). The Lambertian's light is
  // cosine-distributed, so each round trip keeps A colour amount Ebar:
  //   albedo(mu_o) = amount colour E(mu_o)
  //                + (1 - amount E(mu_o)) A (1 - amount Ebar) / (1 - A colour amount Ebar),
  // Ebar = int min(E, 1) 2 mu dmu. Issue 19 step 8: before, the walk skipped the
  // fuzz of a pass-through (a standard_surface velvet read +1356 % at NoV 0.1).
  // 16384 walks; tolerance 4 standard errors + 1 % (the sheen's table against
  // its integral): measured within -4.1 ... +0.0 %, all inside.
  WalkLayer velvet = plastic();
  velvet.f0 = grey(0);
  velvet.diffuseAlbedo = {0.6, 0.3, 0.1};
  velvet.fuzzAmount = 0.8;
  velvet.fuzzColor = {0.9, 0.5, 1.0};
  int cases = 0;
  for (double fuzzRoughness : {0.3, 0.7}) {
    velvet.fuzzRoughness = fuzzRoughness;
    const int n = 2000;
    double ebar = 0;
    for (int i = 0; i < n; ++i) {
      const double mu = (i + 0.5) / n;
      ebar += std::min(fuzzAlbedo(mu, fuzzRoughness), 1.0) * 2 * mu / n;
    }
    for (double mu : {1.0, 0.5, 0.15}) {
      const double e = std::min(fuzzAlbedo(mu, fuzzRoughness), 1.0);
      const Estimate got = layeredAlbedoEstimate({velvet}, dir(mu, 0.3), opts(16384, 40 + cases));
      for (int c = 0; c < 3; ++c, ++cases) {
        const double a = velvet.diffuseAlbedo[c], col = velvet.fuzzColor[c];
        const double want = 0.8 * col * e + (1 - 0.8 * e) * a * (1 - 0.8 * ebar) / (1 - a * col * 0.8 * ebar);
        EXPECT_NEAR(got.value[c], want, 4 * got.standardError[c] + 0.01 * want)
            << "fuzz roughness " << fuzzRoughness << ", NoV " << mu << ", channel " << c;
      }
    }
  }
  EXPECT_EQ(cases, 18);
}

TEST(RandomWalkSmooth, ACoatOverALambertianMatchesTheAddingFormula) {
  // The gate of issue 18: a smooth dielectric (F0 0.04: n = 1.5; roughness 0:
  // alpha 1e-3, single scattering) over a Lambertian of albedo a:
  //   R = F + (1 - F) a (1 - Fi) / (1 - a Fi),
  // F = F(mu) from air, Fi the cosine-weighted internal reflectance (n 1.5 ->
  // 1, total internal reflection included; numerically 0.59635). Within 0.5 %
  // at NoV 1 / 0.6 / 0.2; walks per case chosen so that the standard error is
  // <= 0.15 % (checked), the count of cases too.
  const double n = 1.5;
  const double Fi = hemisphericalFresnel(n, 1);
  EXPECT_NEAR(Fi, 0.59635, 1e-4);
  EXPECT_NEAR(iorFromF0(0.04), n, 1e-12);
  int cases = 0;
  for (double a : {0.2, 0.5, 0.8, 1.0}) {
    WalkLayer slab;
    slab.f0 = grey(0.04);
    slab.roughness = 0;
    slab.diffuseAlbedo = grey(a);
    slab.opaqueBase = true;
    for (double mu : {1.0, 0.6, 0.2}) {
      const double F = fresnel(mu, 1, n);
      const double R = F + (1 - F) * a * (1 - Fi) / (1 - a * Fi);
      const int walks = a < 0.4 ? 200000 : (a < 0.7 ? 160000 : (a < 0.9 ? 60000 : 40000));
      const Estimate e = layeredAlbedoEstimate({slab}, dir(mu, 0), opts(walks, 7));
      EXPECT_REL(e.value[0], R, 0.005) << "a " << a << " mu " << mu << " se " << e.standardError[0];
      EXPECT_LT(e.standardError[0], 0.0015 * R) << "a " << a << " mu " << mu;
      ++cases;
    }
  }
  EXPECT_EQ(cases, 12);
}

TEST(RandomWalkSmooth, AConductorIsItsMicrofacetLobe) {
  // A conductor (WalkLayer::conductor), single-scattering mode: GGX (alpha =
  // r^2), height-correlated Smith, exact conductor Fresnel of the complex IOR
  // of Gulbrandsen 2014 (r = F0, edge tint g = F90); nothing below, so the walk
  // is exact. Fresnel computed here with complex arithmetic.
  WalkLayer m = gold();
  m.f90 = {1, 0.9, 0.8};
  D3 wo = dir(0.7, 0.2), wi = dir(0.4, 2.5);
  D3 h = {wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]};
  double l = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  double voh = (wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]) / l;
  double a = 0.4 * 0.4;
  double G = 1 / (1 + smithLambda(a, wo[2]) + smithLambda(a, wi[2]));
  WalkOptions o = opts(16);
  o.singleScatteringInterfaces = true;
  D3 f = layeredEval({m}, wo, wi, o);
  for (int c = 0; c < 3; ++c) {
    auto [cn, ck] = rwGulbrandsen(m.f0[c], m.f90[c] * (1 - std::pow(1 - m.f0[c], 2.75)));
    double F = rwConductorFresnel(voh, cn, ck);
    double expected = F * ggxD(a, h[2] / l) * G / (4 * wo[2] * wi[2]) * wi[2];
    EXPECT_NEAR(f[c], expected, 1e-9 * expected);
  }
}

TEST(RandomWalkSmooth, TheConductorsEdgeTintOneIsCloseToSchlick) {
  // The edge tint from F90, g = F90 (1 - (1 - F0)^2.75): with the default F90
  // = 1, Gulbrandsen's curve against Schlick's F0 + (1 - F0)(1 - mu)^5, max over
  // mu of |difference| (512 angles). Measured 0.056 / 0.027 / 0.024 / 0.012 /
  // 0.014 / 0.006 at F0 0.02 / 0.04 / 0.3 / 0.56 / 0.9 / 0.97; bound 0.06.
  int cases = 0;
  for (double f0 : {0.02, 0.04, 0.3, 0.56, 0.9, 0.97}) {
    auto [cn, ck] = rwGulbrandsen(f0, 1 - std::pow(1 - f0, 2.75));
    double worst = 0;
    for (int i = 0; i <= 512; ++i) {
      const double mu = i / 512.0;
      worst = std::max(worst, std::fabs(rwConductorFresnel(std::max(mu, 1e-9), cn, ck) - (f0 + (1 - f0) * std::pow(1 - mu, 5))));
    }
    std::printf("F0 %.2f: max |Gulbrandsen(g 1) - Schlick(F90 1)| = %.4f\n", f0, worst);
    EXPECT_LT(worst, 0.06) << f0;
    ++cases;
  }
  EXPECT_EQ(cases, 6);
}

TEST(RandomWalkConventions, AlbedoSeenThroughTheInterfaceIsTheArtistsAlbedo) {
  // WalkOptions::albedoSeenThroughInterface: the Lambertian under a smooth
  // interface gets A' = A / (1 - R21 + R21 A), so by the closed form above the
  // slab's albedo is R12 + T12 A: what leaves of the light that enters is A,
  // the analytic model's meaning. 30000 walks; tolerance 3 % (measured <= 0.9 %).
  const double R21 = hemisphericalFresnel(1.5, 1);
  EXPECT_NEAR(internalReflectance(1.5), R21, 1e-6);
  for (double A : {0.3, 0.8})
    for (double mu : {1.0, 0.4}) {
      WalkLayer slab;
      slab.f0 = grey(0.04);
      slab.roughness = 0;
      slab.diffuseAlbedo = grey(A);
      slab.opaqueBase = true;
      WalkOptions o = opts(30000, 18);
      o.albedoSeenThroughInterface = true;
      double R12 = fresnel(mu, 1, 1.5);
      const double albedo = layeredAlbedo({slab}, dir(mu, 0), o)[0];
      EXPECT_REL(albedo, R12 + (1 - R12) * A, 0.03) << "A " << A << " mu " << mu;
    }
}

TEST(RandomWalkConventions, AlbedoSeenThroughARoughInterfaceIsTheArtistsAlbedoToo) {
  // The same meaning under a rough interface (roughness 0.7, F0 0.04): what
  // leaves of the light that enters is A, so the slab's albedo is
  // R12 + (1 - R12) A, R12 the albedo over a black base (same walks' seed).
  // The rough interface lets more of the light from below out than a smooth
  // one (R21 0.575 against 0.596); with the smooth R21 the diffuse part read
  // +3.5 % at A 0.3 and +4.2 / +5.1 % at A 0.1 (this test before the fix;
  // after: -0.7 … +0.1 %).
  // 200000 walks; tolerance 1.2 % of the diffuse part.
  int cases = 0;
  for (double A : {0.1, 0.3})
    for (double mu : {1.0, 0.3}) {
      WalkLayer slab;
      slab.f0 = grey(0.04);
      slab.roughness = 0.7;
      slab.diffuseAlbedo = grey(A);
      slab.opaqueBase = true;
      WalkOptions o = opts(200000, 23);
      o.albedoSeenThroughInterface = true;
      const double albedo = layeredAlbedo({slab}, dir(mu, 0), o)[0];
      slab.diffuseAlbedo = grey(0);
      const double R12 = layeredAlbedo({slab}, dir(mu, 0), o)[0];
      const double diffuse = albedo - R12, expected = (1 - R12) * A;
      std::printf("A %.1f mu %.1f: R12 %.4f diffuse %.4f expected %.4f (%+.2f %%)\n", A, mu, R12, diffuse, expected,
                  100 * (diffuse / expected - 1));
      EXPECT_REL(diffuse, expected, 0.012) << "A " << A << " mu " << mu;
      ++cases;
    }
  EXPECT_EQ(cases, 4);
}

TEST(RandomWalkConventions, AbsoluteIorsIndexMatchEqualSlabs) {
  // WalkOptions::absoluteIor: F0 0.04 over F0 0.04 is n 1.5 over n 1.5, an
  // index-matched boundary: the same walks, bit for bit, as the default
  // convention with the base's F0 at 0.
  WalkLayer base = plastic(), matched = plastic();
  matched.f0 = grey(0);
  WalkOptions absolute = opts(1024, 19);
  absolute.absoluteIor = true;
  D3 wo = dir(0.7, 0.1), wi = dir(0.4, 2.0);
  D3 a = layeredEval({clearCoat(), base}, wo, wi, absolute);
  D3 b = layeredEval({clearCoat(), matched}, wo, wi, opts(1024, 19));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a[c], b[c]);
  // ... and a base of lower IOR under the coat (eta < 1 at its boundary) is a
  // valid stack: reciprocal (8192 walks, tolerance 6 %), and brighter than with
  // the default convention, where its IOR is 1.5 x 1.33 and traps more light.
  WalkLayer water = plastic();
  water.f0 = grey(0.02);
  D3 fab = layeredEval({clearCoat(), water}, wo, wi, opts(8192, 20));
  absolute.samples = 8192;
  D3 x = layeredEval({clearCoat(), water}, wo, wi, absolute);
  D3 y = layeredEval({clearCoat(), water}, wi, wo, absolute);
  for (int c = 0; c < 3; ++c) {
    EXPECT_REL(x[c] / wi[2], y[c] / wo[2], 0.06);
    EXPECT_GT(x[c], fab[c]);
  }
}

// ---------------------------------------------------------------------------
// Energy.

TEST(RandomWalkFurnace, ANonAbsorbingStackConservesEnergy) {
  // Scattering coat (albedo 1, optical thickness 1, g 0.3) over a white
  // Lambertian, dielectric interfaces F0 0.04 at roughness 0.1 (alpha 0.01).
  // 10000 walks, maxDepth 1024: measured 0.9941 .. 0.9958 (the rest is the
  // rough interfaces' single-scattering loss, next test); tolerance [0.985, 1.005].
  // (A white semi-infinite medium is no furnace for a unit test: its walks are
  // heavy-tailed; under a smooth coat it keeps 0.93 / 0.98 / 0.99 of the energy
  // at maxDepth 1e4 / 1e5 / 1e6.)
  WalkLayer coat;
  coat.f0 = grey(0.04);
  coat.roughness = 0.1;
  coat.diffuseAlbedo = grey(1);
  coat.mfp = grey(1e-3);
  coat.thickness = 1e-3;
  coat.phaseAnisotropy = 0.3;
  WalkLayer base;
  base.f0 = grey(0.04);
  base.roughness = 0.1;
  base.diffuseAlbedo = grey(1);
  base.opaqueBase = true;
  for (double mu : {1.0, 0.5, 0.2}) {
    double a = layeredAlbedo({coat, base}, dir(mu, 0), opts(10000, 11, 1024))[0];
    EXPECT_GT(a, 0.985) << mu;
    EXPECT_LT(a, 1.005) << mu;
  }
  // Absorbing media lose energy: the same stacks at albedo 0.5 (measured 0.251).
  coat.diffuseAlbedo = grey(0.5);
  base.diffuseAlbedo = grey(0.5);
  double absorbed = layeredAlbedo({coat, base}, dir(0.6, 0), opts(10000, 13, 1024))[0];
  EXPECT_LT(absorbed, 0.6);
  EXPECT_GT(absorbed, 0.2);
}

TEST(RandomWalkFurnace, SingleScatteringMatchesQuadrature) {
  // singleScatteringInterfaces: a white conductor (F0 = F90 = 1) reflects
  // E(mu) = integral of D G / (4 mu) over the hemisphere, < 1 at high roughness.
  // Quadrature here (600 x 1200 midpoints: E(0.5) = 0.8933 at roughness 0.45);
  // the walk's albedo within 0.2 % (and its standard error below 0.07 %).
  int cases = 0;
  for (double r : {0.45, 0.8}) {
    const double a = r * r, mu = 0.5;
    D3 wo = dir(mu, 0);
    const int nt = 600, np = 1200;
    double E = 0;
    for (int i = 0; i < nt; ++i)
      for (int j = 0; j < np; ++j) {
        double th = (i + 0.5) / nt * std::numbers::pi / 2, ph = (j + 0.5) / np * 2 * std::numbers::pi;
        D3 wi = {std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)};
        D3 h = {wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]};
        double l = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
        double G = 1 / (1 + smithLambda(a, wo[2]) + smithLambda(a, wi[2]));
        E += ggxD(a, h[2] / l) * G / (4 * mu) * std::sin(th) * (std::numbers::pi / 2 / nt) * (2 * std::numbers::pi / np);
      }
    if (r == 0.45) EXPECT_NEAR(E, 0.893, 0.002);
    WalkLayer white;
    white.f0 = grey(1);
    white.roughness = r;
    white.opaqueBase = true;
    white.conductor = true;
    WalkOptions o = opts(r < 0.5 ? 150000 : 800000, 14);
    o.singleScatteringInterfaces = true;
    const Estimate walked = layeredAlbedoEstimate({white}, wo, o);
    EXPECT_REL(walked.value[0], E, 0.002);
    EXPECT_LT(walked.standardError[0], 0.0007 * E);
    ++cases;
  }
  EXPECT_EQ(cases, 2);
}

/// The white-furnace grid of issue 18: non-absorbing stacks (rough dielectric
/// over a white Lambertian, white conductors of every roughness and
/// anisotropy, clear coats over both), at NoV 1 / 0.6 / 0.2.
std::vector<std::vector<WalkLayer>> furnaceGrid() {
  std::vector<std::vector<WalkLayer>> out;
  for (double r : {0.1, 0.3, 0.5, 0.8, 1.0}) {
    WalkLayer dielectric;
    dielectric.f0 = grey(0.04);
    dielectric.roughness = r;
    dielectric.diffuseAlbedo = grey(1);
    dielectric.opaqueBase = true;
    WalkLayer white;
    white.f0 = grey(1);
    white.roughness = r;
    white.opaqueBase = true;
    white.conductor = true;
    WalkLayer aniso = white;
    aniso.anisotropy = 0.8;
    aniso.tangentAngle = 0.7;
    WalkLayer coat;
    coat.f0 = grey(0.04);
    coat.roughness = r;
    coat.mfp = grey(1e6);
    coat.thickness = 1e-3;
    out.push_back({dielectric});
    out.push_back({white});
    out.push_back({aniso});
    out.push_back({coat, dielectric});
    out.push_back({coat, white});
  }
  return out;
}

TEST(RandomWalkFurnace, EveryNonAbsorbingStackReturnsAllTheLight) {
  // Default options (microsurface walks at rough interfaces): 1 +- 0.5 %.
  // 400 walks each: a non-absorbing walk leaves with weight 1 (or is lost at
  // maxDepth / the microsurface's order bound), so the noise is tiny.
  int cases = 0;
  double lo = 2, hi = 0;
  for (const auto& stack : furnaceGrid())
    for (double mu : {1.0, 0.6, 0.2}) {
      WalkOptions o = opts(400, 21);
      o.maxDepth = WalkOptions{}.maxDepth;
      const Estimate e = layeredAlbedoEstimate(stack, dir(mu, 0.3), o);
      EXPECT_NEAR(e.value[0], 1.0, 0.005) << stack.size() << " layers, roughness " << stack.back().roughness
                                           << (stack.back().conductor ? " conductor" : " dielectric") << " mu " << mu;
      lo = std::min(lo, e.value[0]);
      hi = std::max(hi, e.value[0]);
      ++cases;
    }
  std::printf("furnace: %d cases, %.4f .. %.4f\n", cases, lo, hi);
  EXPECT_EQ(cases, 75);
}

TEST(RandomWalkFurnace, WhiteFuzzReturnsAllTheLight) {
  // White fuzz (colour 1) on a white dielectric over a white Lambertian, on a
  // white conductor, on a clear coat over them, and on a velvet (fuzz on an
  // F0-0 pass-through over a white Lambertian): what the fuzz catches from
  // below goes back down (random_walk.h), so nothing is lost but what the
  // sheen catches (amount min(E, 1), E the runtime's table) beyond what its
  // lobe reflects (the lobe's integral, up to 5 % below the table at grazing
  // views and low fuzz roughness). Issue 19 step 8: before, the fuzz on a
  // real interface absorbed what it caught from below (the fuzzy coat
  // control's truth returned 0.96 / 0.94 at NoV 1 / 0.2). 16000 walks, maxDepth
  // 1024: measured 0.983 .. 1.003 (standard errors ~0.004: the sheen's sampling
  // weights vary); held to [0.965, 1.005] widened by 4 standard errors.
  int cases = 0;
  double lo = 2, hi = 0;
  for (double fuzzRoughness : {0.3, 0.8}) {
    auto fuzzy = [&](WalkLayer L) {
      L.fuzzAmount = 0.6;
      L.fuzzRoughness = fuzzRoughness;
      L.fuzzColor = grey(1);
      return L;
    };
    WalkLayer dielectric;
    dielectric.f0 = grey(0.04);
    dielectric.roughness = 0.3;
    dielectric.diffuseAlbedo = grey(1);
    dielectric.opaqueBase = true;
    WalkLayer white;
    white.f0 = grey(1);
    white.roughness = 0.3;
    white.opaqueBase = true;
    white.conductor = true;
    WalkLayer coat;
    coat.f0 = grey(0.04);
    coat.roughness = 0.1;
    coat.mfp = grey(1e6);
    coat.thickness = 1e-3;
    WalkLayer velvet = dielectric;
    velvet.f0 = grey(0);
    const std::vector<std::vector<WalkLayer>> stacks = {
        {fuzzy(dielectric)}, {fuzzy(white)}, {fuzzy(coat), dielectric}, {fuzzy(coat), white}, {fuzzy(velvet)}};
    for (const auto& stack : stacks)
      for (double mu : {1.0, 0.5, 0.2}) {
        const Estimate e = layeredAlbedoEstimate(stack, dir(mu, 0.3), opts(16000, 70 + cases, 1024));
        const double a = e.value[0], band = 4 * e.standardError[0];
        EXPECT_GE(a, 0.965 - band) << stack.size() << " layers, fuzz roughness " << fuzzRoughness << ", mu " << mu;
        EXPECT_LE(a, 1.005 + band) << stack.size() << " layers, fuzz roughness " << fuzzRoughness << ", mu " << mu;
        lo = std::min(lo, a);
        hi = std::max(hi, a);
        ++cases;
      }
  }
  std::printf("white fuzz furnace: %d cases, %.4f .. %.4f\n", cases, lo, hi);
  EXPECT_EQ(cases, 30);
}

TEST(RandomWalkFurnace, SingleScatteringLosesEnergyAtRoughInterfaces) {
  // The same grid, singleScatteringInterfaces: the rough cases (roughness >=
  // 0.5) lose more than 0.5 % (the failure the default mode fixes).
  int cases = 0, failing = 0;
  WalkOptions o = opts(400, 21);
  o.singleScatteringInterfaces = true;
  for (const auto& stack : furnaceGrid()) {
    if (stack.back().roughness < 0.5) continue;
    const double e = layeredAlbedo(stack, dir(0.6, 0.3), o)[0];
    failing += e < 0.995;
    ++cases;
  }
  EXPECT_EQ(cases, 15);
  EXPECT_EQ(failing, cases);
}

// ---------------------------------------------------------------------------
// The estimators agree with each other and with reciprocity.

TEST(RandomWalkEval, IntegratesToTheForwardWalksAlbedo) {
  // layeredEval (next-event estimation through the interfaces, MIS at the top)
  // and layeredAlbedo (forward walks, no connection) are different estimators:
  // the integral of the first over wi (cosine-stratified directions) must be
  // the second. Rough tops (roughness 0.5)
  // keep the top reflection lobe wide enough for the grid; for a smooth top
  // (roughness 0) the grid skips 0.05 rad around the mirror direction and the
  // smooth Fresnel reflectance R12(mu) is taken off the albedo instead.
  // A polished conductor under a rough coat is the case where the walk's own
  // sampling (strategy A) carries the paths: an error of 10 % in A fails here.
  // 24 x 24 directions, 64 walks each, against 40000 walks, maxDepth 1024 (the
  // default: eval and albedo truncate differently at 64). Measured -1.6 % ..
  // +2.1 % on 1, 2 and 3 layer stacks (with 256 walks per direction and 160000
  // albedo walks: -0.3 % .. +0.8 %); tolerance 4 %.
  WalkLayer dusty = dustyCoat();
  dusty.roughness = 0.5;
  dusty.mfp = grey(0.004);
  WalkLayer smooth = clearCoat();
  smooth.roughness = 0;
  struct Case {
    std::vector<WalkLayer> stack;
    bool smoothTop;
  };
  WalkLayer polished = gold();
  polished.roughness = 0;  // under a rough coat: strategy A carries the paths
  WalkLayer fuzzy = plastic();  // the sheen layer: its sampling against its f
  fuzzy.fuzzAmount = 0.8;
  fuzzy.fuzzRoughness = 0.6;
  fuzzy.fuzzColor = {1, 0.6, 0.3};
  WalkLayer velvet = fuzzy;  // the same sheen on a pass-through (F0 0)
  velvet.f0 = grey(0);
  const std::vector<Case> cases = {{{plastic()}, false},
                                   {{fuzzy}, false},
                                   {{velvet}, false},
                                   {{dusty, velvet}, false},  // the fuzz on a pass-through under a coat
                                   {{dusty, sssBase()}, false},
                                   {{dusty, gold()}, false},
                                   {{dusty, polished}, false},
                                   {{smooth, dusty, sssBase()}, true}};
  const D3 wo = dir(0.6, 0.4), mirror = {-wo[0], -wo[1], wo[2]};
  for (const Case& k : cases) {
    const int m = 24;
    D3 integral{0, 0, 0};
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        double u1 = (i + 0.5) / m, u2 = (j + 0.5) / m;
        D3 wi = dir(std::sqrt(1 - u1), 2 * std::numbers::pi * u2);  // cosine-distributed: estimator pi f = pi eval / cos
        if (k.smoothTop && wi[0] * mirror[0] + wi[1] * mirror[1] + wi[2] * mirror[2] > std::cos(0.05)) continue;
        D3 f = layeredEval(k.stack, wo, wi, opts(64, 100 + i * m + j, 1024));
        for (int c = 0; c < 3; ++c) integral[c] += std::numbers::pi * f[c] / wi[2] / (m * m);
      }
    D3 albedo = layeredAlbedo(k.stack, wo, opts(40000, 15, 1024));
    const double r12 = k.smoothTop ? fresnel(wo[2], 1, 1.5) : 0;
    for (int c = 0; c < 3; ++c)
      EXPECT_REL(integral[c], albedo[c] - r12, 0.04) << k.stack.size() << " layers, channel " << c;
    std::printf("eval vs albedo: %zu layers: %+.2f %+.2f %+.2f %%\n", k.stack.size(), 100 * (integral[0] / (albedo[0] - r12) - 1),
                100 * (integral[1] / (albedo[1] - r12) - 1), 100 * (integral[2] / (albedo[2] - r12) - 1));
  }
}

TEST(RandomWalkReciprocity, FIsSymmetricInViewAndLight) {
  // f(wo, wi) = layeredEval(wo, wi) / cos(wi) against layeredEval(wi, wo) /
  // cos(wo): equal within 4 combined standard errors (the Estimates'), 4096 walks.
  const std::vector<std::vector<WalkLayer>> stacks = {
      {sssBase()}, {dustyCoat(), sssBase()}, {clearCoat(), plastic()}, {dustyCoat(), gold()},
      {clearCoat(), dustyCoat(), sssBase()}};
  int cases = 0;
  for (const auto& stack : stacks)
    for (auto [a, b] : {std::pair{dir(0.8, 0.1), dir(0.3, 2.0)}, std::pair{dir(0.95, 0), dir(0.2, 1.0)}}) {
      const Estimate fab = layeredEvalEstimate(stack, a, b, opts(4096, 16, 1024));
      const Estimate fba = layeredEvalEstimate(stack, b, a, opts(4096, 17, 1024));
      for (int c = 0; c < 3; ++c) {
        const double x = fab.value[c] / b[2], y = fba.value[c] / a[2];
        const double se = std::hypot(fab.standardError[c] / b[2], fba.standardError[c] / a[2]);
        EXPECT_NEAR(x, y, 4 * se) << stack.size() << " layers, channel " << c;
        EXPECT_GT(se, 0);
        ++cases;
      }
    }
  EXPECT_EQ(cases, 30);
}

TEST(RandomWalkFeatures, TheTangentRotatesTheAnisotropicLobe) {
  // An anisotropic conductor whose tangent is rotated by t, seen from
  // directions rotated by t, is the unrotated one (same walks: same bits up
  // to rounding). And anisotropy stretches the lobe: along the tangent
  // (alpha_x > alpha_y for anisotropy > 0) the reflection spreads wider.
  WalkLayer m = gold();
  m.anisotropy = 0.6;
  WalkLayer turned = m;
  turned.tangentAngle = 0.9;
  const D3 wo = dir(0.7, 0.3), wi = dir(0.5, 2.9);
  const D3 wo2 = dir(0.7, 1.2), wi2 = dir(0.5, 3.8);
  const D3 a = layeredEval({m}, wo, wi, opts(512, 30)), b = layeredEval({turned}, wo2, wi2, opts(512, 30));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6 * a[c]);
  // Off-specular along x (the tangent) against along y: wider along x.
  const D3 v = dir(0.8, 0), offX = dir(0.35, std::numbers::pi);
  const D3 lx = layeredEval({m}, v, offX, opts(512, 31));
  const D3 v90 = dir(0.8, std::numbers::pi / 2), offY2 = dir(0.35, 3 * std::numbers::pi / 2);
  const D3 ly = layeredEval({m}, v90, offY2, opts(512, 31));
  EXPECT_GT(lx[0], ly[0]);
}

TEST(RandomWalkFeatures, HazeTintAndF90) {
  int cases = 0;
  // Haze of weight 1 at roughness r is the lobe of roughness r.
  WalkLayer p = plastic(), hazy = plastic();
  hazy.roughness = 0.9;
  hazy.secondRoughness = p.roughness;
  hazy.secondRoughnessWeight = 1;
  const D3 wo = dir(0.7, 0.3), wi = dir(0.5, 2.9);
  const Estimate e1 = layeredEvalEstimate({p}, wo, wi, opts(4096, 40));
  const Estimate e2 = layeredEvalEstimate({hazy}, wo, wi, opts(4096, 41));
  for (int c = 0; c < 3; ++c, ++cases)
    EXPECT_NEAR(e1.value[c], e2.value[c], 4 * std::hypot(e1.standardError[c], e2.standardError[c]));
  // A tint of 0 removes a conductor's reflection; a tint of 0.5 halves it.
  WalkLayer g = gold(), dark = gold();
  dark.specularTint = {0, 0.5, 1};
  const D3 a = layeredAlbedo({g}, wo, opts(2048, 42)), b = layeredAlbedo({dark}, wo, opts(2048, 42));
  EXPECT_EQ(b[0], 0);
  EXPECT_NEAR(b[1], 0.5 * a[1], 1e-12);
  EXPECT_EQ(b[2], a[2]);
  cases += 3;
  // F90 < 1 of a dielectric darkens its grazing reflection.
  WalkLayer coat = clearCoat();
  coat.roughness = 0;  // F90 acts on single-scattering lobes only (random_walk.h)
  WalkLayer dim = coat;
  dim.f90 = grey(0.5);
  const double r1 = layeredAlbedo({coat}, dir(0.1, 0), opts(4096, 43))[0];
  const double r2 = layeredAlbedo({dim}, dir(0.1, 0), opts(4096, 43))[0];
  EXPECT_LT(r2, r1);
  ++cases;
  EXPECT_EQ(cases, 7);
}

TEST(RandomWalkFeatures, HardCasesAreFinite) {
  // Roughness 0, F0 = 1, MFP 0 / huge, grazing directions: finite estimates.
  std::vector<WalkLayer> layers;
  for (double r : {0.0, 1.0})
    for (double f0 : {0.0, 1.0}) {
      WalkLayer L;
      L.roughness = r;
      L.f0 = grey(f0);
      L.diffuseAlbedo = grey(1);
      L.mfp = grey(f0 > 0 ? 0 : 1e30);
      L.thickness = 1e-3;
      L.anisotropy = r > 0 ? -1 : 1;
      L.secondRoughnessWeight = 0.5;
      L.fuzzAmount = 1;
      L.fuzzRoughness = r;
      L.fuzzColor = grey(1);
      layers.push_back(L);
    }
  WalkLayer metal = gold();
  metal.f0 = grey(1);
  metal.roughness = 0;
  int cases = 0;
  for (const WalkLayer& top : layers)
    for (const WalkLayer& base : {sssBase(), plastic(), metal})
      for (double mu : {1.0, 1e-4}) {
        const D3 wo = dir(mu, 0.2), wi = dir(mu > 0.5 ? 1e-4 : 1.0, 2.0);
        const Estimate e = layeredEvalEstimate({top, base}, wo, wi, opts(64, 50));
        const Estimate a = layeredAlbedoEstimate({top, base}, wo, opts(64, 51));
        for (int c = 0; c < 3; ++c) {
          EXPECT_TRUE(std::isfinite(e.value[c]) && std::isfinite(e.standardError[c]));
          EXPECT_TRUE(std::isfinite(a.value[c]) && a.value[c] >= 0 && a.value[c] <= 1.01);
        }
        ++cases;
      }
  EXPECT_EQ(cases, 24);
}

TEST(RandomWalkDeterminism, TheSeedFixesEveryBit) {
  const std::vector<WalkLayer> stack = {dustyCoat(), sssBase()};
  D3 wo = dir(0.7, 0), wi = dir(0.5, 2);
  D3 a = layeredEval(stack, wo, wi, opts(2048, 42));
  D3 b = layeredEval(stack, wo, wi, opts(2048, 42));
  D3 c = layeredEval(stack, wo, wi, opts(2048, 43));
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a[k], b[k]);      // bit for bit
    EXPECT_NE(a[k], c[k]);      // another seed, other walks
    EXPECT_REL(c[k], a[k], 0.1);  // ... within the noise (~2 % at 2048 walks; measured <= 1.1 %)
  }
  D3 x = layeredAlbedo(stack, wo, opts(2048, 42)), y = layeredAlbedo(stack, wo, opts(2048, 42));
  for (int k = 0; k < 3; ++k) EXPECT_EQ(x[k], y[k]);
}

// The walk's cost (docs/performance.md), not a test: run it with
//   build/bin/unit_tests --gtest_also_run_disabled_tests --gtest_filter='RandomWalkCost.*'
// ms per layeredEval / layeredAlbedo at the default options (4096 samples,
// maxDepth 1024), and in the single-scattering mode at maxDepth 64 (the walk
// of issue 17 and before), one core.
TEST(RandomWalkCost, DISABLED_MsPerEvaluation) {
  WalkLayer coat = clearCoat();
  coat.mfp = grey(1e6);
  const std::vector<std::pair<const char*, std::vector<WalkLayer>>> stacks = {
      {"coat over plastic", {coat, plastic()}}, {"SSS base", {sssBase()}}, {"conductor", {gold()}},
      {"coat over conductor", {coat, gold()}}};
  const D3 wo = dir(0.8, 0), wi = dir(0.8124, 2.1);
  for (bool single : {false, true}) {
    WalkOptions o;
    if (single) {
      o.singleScatteringInterfaces = true;
      o.maxDepth = 64;
    }
    std::printf("samples %d, maxDepth %d%s\n", o.samples, o.maxDepth, single ? ", single scattering" : "");
    for (const auto& [name, stack] : stacks) {
      const int n = 10;
      double sink = 0;
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < n; ++i) sink += layeredEval(stack, wo, wi, o)[0];
      const auto t1 = std::chrono::steady_clock::now();
      for (int i = 0; i < n; ++i) sink += layeredAlbedo(stack, wo, o)[0];
      const auto t2 = std::chrono::steady_clock::now();
      std::printf("  %-20s eval %7.2f ms  albedo %7.2f ms  (%g)\n", name,
                  std::chrono::duration<double, std::milli>(t1 - t0).count() / n,
                  std::chrono::duration<double, std::milli>(t2 - t1).count() / n, sink);
    }
  }
}

}  // namespace
}  // namespace substratec
