// Tests for the helper value nodes (compiler/core/ir/helper_math.h), written as the
// specification of docs/value-nodes.md, "Helpers".
#include "ir/helper_math.h"

#include <gtest/gtest.h>
#include <numbers>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace substratec::helpers {
namespace {


Vec3 grey(double v) { return {v, v, v}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 normalized(const Vec3& v) {  // scaled first: works for 1e-300 and 1e300 components
  const double m = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2])});
  const Vec3 s{v[0] / m, v[1] / m, v[2] / m};
  const double l = std::sqrt(dot(s, s));
  return {s[0] / l, s[1] / l, s[2] / l};
}
bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }
bool inUnit(double x) { return x >= 0.0 && x <= 1.0; }
bool inUnit(const Vec3& v) { return inUnit(v[0]) && inUnit(v[1]) && inUnit(v[2]); }

// ---------------------------------------------------------------------------
// ior_to_f0

TEST(IorToF0, GlassIs4Percent) { EXPECT_NEAR(iorToF0(1.5), 0.04, 1e-12); }

TEST(IorToF0, IorOneIsNoReflection) { EXPECT_EQ(iorToF0(1.0), 0.0); }

TEST(IorToF0, KnownMaterials) {
  EXPECT_NEAR(iorToF0(1.33), 0.0200593, 1e-6);  // water
  EXPECT_NEAR(iorToF0(2.42), 0.1723949, 1e-6);  // diamond
}

TEST(IorToF0, BelowOneIsTheSameInterfaceFromTheDenseSide) {
  for (double n : {1.1, 1.5, 2.0, 3.7}) EXPECT_NEAR(iorToF0(1.0 / n), iorToF0(n), 1e-12) << n;
}

TEST(IorToF0, NonPositiveAndHugeTendToAMirror) {
  EXPECT_EQ(iorToF0(0.0), 1.0);
  EXPECT_EQ(iorToF0(-3.0), 1.0);
  EXPECT_NEAR(iorToF0(1e300), 1.0, 1e-12);
  EXPECT_NEAR(iorToF0(DBL_MAX), 1.0, 1e-12);
}

TEST(IorToF0, MonotoneAwayFromOne) {
  double prev = 0.0;
  for (double n = 1.0; n < 10.0; n += 0.01) {
    const double f = iorToF0(n);
    EXPECT_GE(f, prev);
    prev = f;
  }
}

// ---------------------------------------------------------------------------
// metalness_to_diffuse_f0

TEST(MetalnessToDiffuseF0, DefaultsGiveGreyPlastic) {
  const DiffuseF0 r = metalnessToDiffuseF0(grey(0.18), 0.0, 0.5);
  for (int c = 0; c < 3; ++c) {
    EXPECT_DOUBLE_EQ(r.diffuse_albedo[c], 0.18);
    EXPECT_DOUBLE_EQ(r.f0[c], 0.04);
  }
}

TEST(MetalnessToDiffuseF0, DielectricEndpointKeepsBaseColorAsDiffuse) {
  const Vec3 base{0.8, 0.1, 0.3};
  for (double spec : {0.0, 0.5, 1.0}) {
    const DiffuseF0 r = metalnessToDiffuseF0(base, 0.0, spec);
    for (int c = 0; c < 3; ++c) {
      EXPECT_DOUBLE_EQ(r.diffuse_albedo[c], base[c]);
      EXPECT_DOUBLE_EQ(r.f0[c], 0.08 * spec);
    }
  }
}

TEST(MetalnessToDiffuseF0, MetalEndpointHasNoDiffuseAndBaseColorF0) {
  const Vec3 base{0.95, 0.64, 0.54};  // copper-ish
  const DiffuseF0 r = metalnessToDiffuseF0(base, 1.0, 0.5);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(r.diffuse_albedo[c], 0.0);
    EXPECT_DOUBLE_EQ(r.f0[c], base[c]);
  }
}

TEST(MetalnessToDiffuseF0, HalfMetalLerps) {
  const DiffuseF0 r = metalnessToDiffuseF0({1.0, 0.5, 0.0}, 0.5, 0.5);
  EXPECT_DOUBLE_EQ(r.diffuse_albedo[0], 0.5);
  EXPECT_DOUBLE_EQ(r.diffuse_albedo[1], 0.25);
  EXPECT_DOUBLE_EQ(r.diffuse_albedo[2], 0.0);
  EXPECT_DOUBLE_EQ(r.f0[0], 0.52);
  EXPECT_DOUBLE_EQ(r.f0[1], 0.27);
  EXPECT_DOUBLE_EQ(r.f0[2], 0.02);
}

TEST(MetalnessToDiffuseF0, ClampsInputsToTheUnitRange) {
  const DiffuseF0 r = metalnessToDiffuseF0({2.0, -1.0, 0.5}, -0.5, 3.0);  // metallic 0, specular 1
  EXPECT_EQ(r.diffuse_albedo[0], 1.0);
  EXPECT_EQ(r.diffuse_albedo[1], 0.0);
  EXPECT_EQ(r.diffuse_albedo[2], 0.5);
  for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(r.f0[c], 0.08);
}

// ---------------------------------------------------------------------------
// haziness_to_second_roughness

TEST(HazinessToSecondRoughness, NoHazeMeansNoSecondLobe) {
  for (double r : {0.0, 0.1, 0.5, 1.0})
    EXPECT_EQ(hazinessToSecondRoughness(r, 0.0).second_roughness_weight, 0.0);
}

TEST(HazinessToSecondRoughness, FullHazeMeansOnlyTheHazeLobe) {
  for (double r : {0.0, 0.1, 0.5, 1.0})
    EXPECT_DOUBLE_EQ(hazinessToSecondRoughness(r, 1.0).second_roughness_weight, 1.0);
}

TEST(HazinessToSecondRoughness, HazeLobeIsTwiceAsRoughUpToOne) {
  EXPECT_DOUBLE_EQ(hazinessToSecondRoughness(0.1, 0.5).second_roughness, 0.2);
  EXPECT_DOUBLE_EQ(hazinessToSecondRoughness(0.25, 0.5).second_roughness, 0.5);
  EXPECT_DOUBLE_EQ(hazinessToSecondRoughness(0.7, 0.5).second_roughness, 1.0);
  for (double r = 0.0; r <= 1.0; r += 0.01) {
    const double r2 = hazinessToSecondRoughness(r, 0.3).second_roughness;
    EXPECT_GE(r2, r);
    EXPECT_LE(r2, 1.0);
  }
}

TEST(HazinessToSecondRoughness, HazinessIsTheHazeShareOfTheHighlightPeak) {
  // GGX D(0) ~ 1/alpha^2: the haze lobe's peak relative to the core's is p.
  for (double r : {0.05, 0.2, 0.5, 0.6, 0.9})
    for (double h : {0.01, 0.2, 0.5, 0.9}) {
      const SecondRoughness s = hazinessToSecondRoughness(r, h);
      const double ac = r * r, ah = s.second_roughness * s.second_roughness;
      const double p = (ac / ah) * (ac / ah);
      const double w = s.second_roughness_weight;
      EXPECT_NEAR(w * p / ((1.0 - w) + w * p), h, 1e-12) << r << " " << h;
    }
}

TEST(HazinessToSecondRoughness, WeightIsMonotoneInHaziness) {
  for (double r : {0.0, 0.3, 0.8}) {
    double prev = -1.0;
    for (double h = 0.0; h <= 1.0; h += 0.01) {
      const double w = hazinessToSecondRoughness(r, h).second_roughness_weight;
      EXPECT_GT(w, prev);
      EXPECT_TRUE(inUnit(w));
      prev = w;
    }
  }
}

TEST(HazinessToSecondRoughness, RoughnessOneHasIdenticalLobesAndLinearWeight) {
  const SecondRoughness s = hazinessToSecondRoughness(1.0, 0.3);
  EXPECT_EQ(s.second_roughness, 1.0);
  EXPECT_DOUBLE_EQ(s.second_roughness_weight, 0.3);
}

// ---------------------------------------------------------------------------
// transmittance_to_mfp

TEST(TransmittanceToMfp, RoundTripsBeerLambert) {
  for (double t : {1e-6, 1e-4, 0.01, 1.0})
    for (double T : {1e-300, 1e-9, 0.001, 0.1, 0.5, 0.9, 0.999999}) {
      const Mfp m = transmittanceToMfp({T, T, T}, t);
      ASSERT_LT(m.mfp[0], 1e9);
      EXPECT_NEAR(std::exp(-t / m.mfp[0]), T, 1e-12) << "T=" << T << " thickness=" << t;
    }
}

TEST(TransmittanceToMfp, DefaultGreyHalf) {
  const Mfp m = transmittanceToMfp(grey(0.5), 0.0001);
  for (double v : m.mfp) EXPECT_NEAR(v, 0.0001 / std::log(2.0), 1e-18);
  EXPECT_EQ(m.thickness, 0.0001);
}

TEST(TransmittanceToMfp, ClearIsTheTransparentSentinelAndOpaqueIsZero) {
  const Mfp m = transmittanceToMfp({1.0, 0.0, 0.5}, 0.01);
  EXPECT_EQ(m.mfp[0], 1e9);
  EXPECT_EQ(m.mfp[1], 0.0);
  EXPECT_GT(m.mfp[2], 0.0);
  EXPECT_LT(m.mfp[2], 1e9);
}

TEST(TransmittanceToMfp, MfpIsCappedAtTheSentinelAndMonotone) {
  double prev = 0.0;
  for (double T : {0.0, 1e-12, 0.2, 0.7, 0.99, 1.0 - 1e-9, 1.0 - 1e-15, 1.0}) {
    const double mfp = transmittanceToMfp(grey(T), 1.0).mfp[0];
    EXPECT_GE(mfp, prev) << T;
    EXPECT_LE(mfp, 1e9);
    prev = mfp;
  }
}

TEST(TransmittanceToMfp, NonPositiveThicknessUsesTheDefaultSurfaceThickness) {
  for (double t : {0.0, -0.0, -1.0, -1e300}) {
    const Mfp m = transmittanceToMfp(grey(0.5), t);
    EXPECT_EQ(m.thickness, 0.0001);
    EXPECT_NEAR(m.mfp[0], 0.0001 / std::log(2.0), 1e-18);
  }
}

TEST(TransmittanceToMfp, ThicknessPassesThrough) {
  EXPECT_EQ(transmittanceToMfp(grey(0.5), 0.25).thickness, 0.25);
}

TEST(TransmittanceToMfp, TransmittanceOutsideTheUnitRangeIsClamped) {
  const Mfp m = transmittanceToMfp({-0.5, 1.5, 0.5}, 0.01);
  EXPECT_EQ(m.mfp[0], 0.0);
  EXPECT_EQ(m.mfp[1], 1e9);
}

// ---------------------------------------------------------------------------
// thin_film

TEST(ThinFilm, ZeroThicknessIsIdentity) {
  const Vec3 f0{0.04, 0.9, 0.5}, f90{1.0, 0.7, 0.2};
  for (double d : {0.0, -0.0, -1e-7, -1e300})
    for (double nov : {0.0, 0.3, 1.0, -2.0, 7.0})
      for (double ior : {1.0, 1.5, 2.4}) {
        const F0F90 r = thinFilm(nov, f0, f90, d, ior);
        EXPECT_EQ(r.f0, f0);
        EXPECT_EQ(r.f90, f90);
      }
  // Even values outside [0, 1] come back bit for bit: no film, no change.
  const F0F90 r = thinFilm(0.5, {-1.0, 2.0, 0.5}, {3.0, 0.0, -0.0}, 0.0, 1.5);
  EXPECT_EQ(r.f0, (Vec3{-1.0, 2.0, 0.5}));
  EXPECT_EQ(r.f90, (Vec3{3.0, 0.0, -0.0}));
}

TEST(ThinFilm, F90IsUnchanged) {
  const Vec3 f90{0.9, 0.8, 0.7};
  for (double d : {100e-9, 500e-9, 1e-6}) EXPECT_EQ(thinFilm(0.7, grey(0.5), f90, d, 1.5).f90, f90);
}

TEST(ThinFilm, ContinuousAtZeroThickness) {
  const Vec3 f0{0.04, 0.5, 0.95};
  const F0F90 r = thinFilm(0.8, f0, grey(1.0), 1e-12, 1.8);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.f0[c], f0[c], 1e-6);
}

TEST(ThinFilm, SoapBubbleIsIridescent) {
  // A 1.33 film in air (base F0 0): colour depends on thickness and angle.
  const F0F90 a = thinFilm(1.0, grey(0.0), grey(1.0), 300e-9, 1.33);
  const F0F90 b = thinFilm(1.0, grey(0.0), grey(1.0), 500e-9, 1.33);
  const F0F90 c = thinFilm(0.4, grey(0.0), grey(1.0), 300e-9, 1.33);
  EXPECT_TRUE(inUnit(a.f0));
  EXPECT_GT(a.f0[0] + a.f0[1] + a.f0[2], 0.01);
  EXPECT_GT(std::fabs(a.f0[0] - a.f0[2]), 0.005);  // coloured, not grey
  EXPECT_GT(std::fabs(a.f0[1] - b.f0[1]) + std::fabs(a.f0[0] - b.f0[0]), 0.005);
  EXPECT_GT(std::fabs(a.f0[1] - c.f0[1]) + std::fabs(a.f0[0] - c.f0[0]), 0.005);
}

TEST(ThinFilm, AnAirFilmIsInvisible) {
  const Vec3 f0{0.04, 0.5, 0.95};
  const F0F90 r = thinFilm(0.6, f0, grey(1.0), 400e-9, 1.0);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.f0[c], f0[c], 1e-12);
}

TEST(ThinFilm, AnIndexMatchedFilmIsInvisibleHeadOn) {
  // F0 0.04 is IOR 1.5: a 1.5 film on it has no second interface.
  const F0F90 r = thinFilm(1.0, grey(0.04), grey(1.0), 400e-9, 1.5);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.f0[c], 0.04, 1e-9);
}

TEST(ThinFilm, AThickFilmLosesItsColour) {
  // Beyond the coherence length only the incoherent (grey) layering remains.
  const F0F90 r = thinFilm(0.9, grey(0.6), grey(1.0), 100e-6, 1.5);
  EXPECT_NEAR(r.f0[0], r.f0[1], 1e-9);
  EXPECT_NEAR(r.f0[1], r.f0[2], 1e-9);
  EXPECT_TRUE(inUnit(r.f0));
}

TEST(ThinFilm, StaysInTheUnitRangeOverTypicalFilms) {
  for (double d = 50e-9; d <= 1200e-9; d += 25e-9)
    for (double nov : {0.0, 0.05, 0.3, 0.7, 1.0})
      for (double ior : {1.2, 1.5, 2.0, 2.6})
        for (double f : {0.0, 0.04, 0.5, 1.0}) {
          const F0F90 r = thinFilm(nov, grey(f), grey(1.0), d, ior);
          ASSERT_TRUE(inUnit(r.f0)) << d << " " << nov << " " << ior << " " << f;
        }
}

// ---------------------------------------------------------------------------
// rotation_to_tangent

void expectUnitAndOrthogonal(double angle, const Vec3& normal) {
  const Vec3 t = rotationToTangent(angle, normal);
  const Vec3 n = normalized(normal);
  ASSERT_TRUE(finite(t));
  EXPECT_NEAR(dot(t, t), 1.0, 1e-14) << normal[0] << " " << normal[1] << " " << normal[2];
  EXPECT_NEAR(dot(t, n), 0.0, 1e-14) << normal[0] << " " << normal[1] << " " << normal[2];
}

TEST(RotationToTangent, UnitAndOrthogonalForRandomNormalsAndThePoles) {
  std::mt19937_64 rng(20170131);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> angle(-10.0, 10.0);
  std::vector<Vec3> normals = {{0, 0, 1},    {0, 0, -1},      {-0.0, 0, -1},       {1e-9, 0, -1},
                               {1e-9, 0, 1}, {0, 1e-9, -1},   {-1e-12, 1e-12, -1}, {1, 0, 0},
                               {0, -1, 0},   {1, 1, -1e-300}, {1e-300, 0, 0},      {1e300, -1e300, 1e300}};
  while (normals.size() < 1000) normals.push_back({gauss(rng), gauss(rng), gauss(rng)});
  for (const Vec3& n : normals) {
    expectUnitAndOrthogonal(angle(rng), n);
    expectUnitAndOrthogonal(0.0, n);
  }
}

TEST(RotationToTangent, CanonicalTangentOnPlusZIsPlusX) {
  const Vec3 t = rotationToTangent(0.0, {0, 0, 1});
  EXPECT_DOUBLE_EQ(t[0], 1.0);
  EXPECT_EQ(t[1], 0.0);
  EXPECT_EQ(t[2], 0.0);
}

TEST(RotationToTangent, QuarterTurnIsCounterClockwiseAroundTheNormal) {
  const Vec3 t = rotationToTangent(std::numbers::pi / 2, {0, 0, 1});
  EXPECT_NEAR(t[0], 0.0, 1e-15);
  EXPECT_NEAR(t[1], 1.0, 1e-15);
  EXPECT_NEAR(t[2], 0.0, 1e-15);
}

TEST(RotationToTangent, RotatesByTheAngleAroundAnyNormal) {
  for (const Vec3& raw : {Vec3{0.3, -0.5, 0.8}, Vec3{0, 0, -1}, Vec3{1e-9, 0, -1}, Vec3{-2, 1, 0.1}}) {
    const Vec3 n = normalized(raw);
    const Vec3 t0 = rotationToTangent(0.0, raw);
    for (double a : {0.3, 1.0, 2.5, -1.2}) {
      const Vec3 ta = rotationToTangent(a, raw);
      EXPECT_NEAR(dot(t0, ta), std::cos(a), 1e-14);
      EXPECT_NEAR(dot(cross(t0, ta), n), std::sin(a), 1e-14);
    }
  }
}

TEST(RotationToTangent, NormalIsNormalizedFirst) {
  const Vec3 a = rotationToTangent(0.7, {0.2, 0.4, 0.6}), b = rotationToTangent(0.7, {2.0, 4.0, 6.0});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-15);
}

TEST(RotationToTangent, ZeroNormalFallsBackToPlusZ) {
  const Vec3 b = rotationToTangent(0.4, {0, 0, 1});
  EXPECT_EQ(rotationToTangent(0.4, {0, 0, 0}), b);
  EXPECT_EQ(rotationToTangent(0.4, {-0.0, 0, -0.0}), b);
}

TEST(RotationToTangent, FullTurnIsIdentity) {
  const Vec3 a = rotationToTangent(0.0, {0.1, 0.2, 0.9}), b = rotationToTangent(2 * std::numbers::pi, {0.1, 0.2, 0.9});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-15);
}

// ---------------------------------------------------------------------------
// view_dependent_coverage

TEST(ViewDependentCoverage, HeadOnEqualsCoverage) {
  for (double c : {0.0, 1e-300, 0.1, 0.5, 0.999, 1.0}) EXPECT_EQ(viewDependentCoverage(c, 1.0), c);
}

TEST(ViewDependentCoverage, MatchesTheFormula) {
  for (double c : {0.1, 0.5, 0.9})
    for (double nov : {0.05, 0.3, 0.8})
      EXPECT_NEAR(viewDependentCoverage(c, nov), 1.0 - std::pow(1.0 - c, 1.0 / nov), 1e-12);
}

TEST(ViewDependentCoverage, GrowsTowardsGrazing) {
  for (double c : {0.01, 0.3, 0.8}) {
    double prev = c;
    for (double nov = 1.0; nov >= 0.0; nov -= 0.01) {
      const double v = viewDependentCoverage(c, nov);
      EXPECT_GE(v, prev) << c << " " << nov;
      EXPECT_LE(v, 1.0);
      prev = v;
    }
    EXPECT_NEAR(viewDependentCoverage(c, 0.0), 1.0, 1e-12);
  }
}

TEST(ViewDependentCoverage, MonotoneInCoverage) {
  for (double nov : {0.01, 0.5, 1.0}) {
    double prev = 0.0;
    for (double c = 0.0; c <= 1.0; c += 0.01) {
      const double v = viewDependentCoverage(c, nov);
      EXPECT_GE(v, prev);
      prev = v;
    }
  }
}

TEST(ViewDependentCoverage, EmptyStaysEmptyAndFullStaysFull) {
  for (double nov : {-1.0, 0.0, 1e-9, 0.5, 1.0, 3.0}) {
    EXPECT_EQ(viewDependentCoverage(0.0, nov), 0.0);
    EXPECT_EQ(viewDependentCoverage(1.0, nov), 1.0);
  }
}

TEST(ViewDependentCoverage, TinyCoverageKeepsPrecision) {
  EXPECT_NEAR(viewDependentCoverage(1e-12, 0.5), 2e-12 - 1e-24, 4e-27);  // 1-(1-c)^2 = 2c - c^2
}

// ---------------------------------------------------------------------------
// Hostile inputs: every function is finite (and in its documented range) for
// every finite input, and for infinities and NaN as well.

const std::vector<double>& hostile() {
  static const std::vector<double> v = {0.0,
                                        -0.0,
                                        1e-300,
                                        -1e-300,
                                        4.9e-324,
                                        1e300,
                                        -1e300,
                                        DBL_MAX,
                                        -DBL_MAX,
                                        1.0,
                                        -1.0,
                                        0.5,
                                        1e-9,
                                        2.0,
                                        1e-4,
                                        1.0 - 1e-16,
                                        std::numeric_limits<double>::infinity(),
                                        -std::numeric_limits<double>::infinity(),
                                        std::numeric_limits<double>::quiet_NaN()};
  return v;
}
bool isNan(double x) { return std::isnan(x); }

TEST(HostileInputs, IorToF0) {
  for (double x : hostile()) {
    const double f = iorToF0(x);
    EXPECT_TRUE(std::isfinite(f) && inUnit(f)) << x;
  }
}

TEST(HostileInputs, MetalnessToDiffuseF0) {
  for (double b : hostile())
    for (double m : hostile())
      for (double s : hostile()) {
        const DiffuseF0 r = metalnessToDiffuseF0({b, 0.5, -b}, m, s);
        EXPECT_TRUE(finite(r.diffuse_albedo) && inUnit(r.diffuse_albedo)) << b << " " << m << " " << s;
        EXPECT_TRUE(finite(r.f0) && inUnit(r.f0)) << b << " " << m << " " << s;
      }
}

TEST(HostileInputs, HazinessToSecondRoughness) {
  for (double r : hostile())
    for (double h : hostile()) {
      const SecondRoughness s = hazinessToSecondRoughness(r, h);
      EXPECT_TRUE(std::isfinite(s.second_roughness) && inUnit(s.second_roughness)) << r << " " << h;
      EXPECT_TRUE(std::isfinite(s.second_roughness_weight) && inUnit(s.second_roughness_weight))
          << r << " " << h;
    }
}

TEST(HostileInputs, TransmittanceToMfp) {
  for (double T : hostile())
    for (double t : hostile()) {
      const Mfp m = transmittanceToMfp({T, 0.5, -T}, t);
      EXPECT_TRUE(finite(m.mfp)) << T << " " << t;
      for (double v : m.mfp) EXPECT_TRUE(v >= 0.0 && v <= 1e9) << T << " " << t;
      EXPECT_TRUE(std::isfinite(m.thickness) && m.thickness > 0.0) << T << " " << t;
    }
}

TEST(HostileInputs, ThinFilm) {
  for (double nov : hostile())
    for (double f : hostile())
      for (double d : hostile())
        for (double ior : hostile()) {
          const Vec3 f0{f, 0.04, 1.0 - f}, f90{1.0, f, 0.5};
          const F0F90 r = thinFilm(nov, f0, f90, d, ior);
          if (!(d > 0.0)) {  // no film: identity (NaN stays NaN, as given)
            for (int c = 0; c < 3; ++c) {
              EXPECT_TRUE(r.f0[c] == f0[c] || (isNan(r.f0[c]) && isNan(f0[c])));
              EXPECT_TRUE(r.f90[c] == f90[c] || (isNan(r.f90[c]) && isNan(f90[c])));
            }
            continue;
          }
          EXPECT_TRUE(finite(r.f0) && inUnit(r.f0)) << nov << " " << f << " " << d << " " << ior;
        }
  // A second sweep with every argument finite: every output finite.
  for (double nov : hostile())
    for (double d : hostile())
      for (double ior : hostile()) {
        if (!std::isfinite(nov) || !std::isfinite(d) || !std::isfinite(ior)) continue;
        const F0F90 r = thinFilm(nov, {0.0, 0.5, 1.0}, {1.0, 1e300, -1e300}, d, ior);
        EXPECT_TRUE(finite(r.f0) && finite(r.f90)) << nov << " " << d << " " << ior;
      }
}

TEST(HostileInputs, RotationToTangent) {
  for (double a : hostile())
    for (double x : hostile())
      for (double z : hostile()) {
        const Vec3 t = rotationToTangent(a, {x, 0.25, z});
        ASSERT_TRUE(finite(t)) << a << " " << x << " " << z;
        EXPECT_NEAR(dot(t, t), 1.0, 1e-14) << a << " " << x << " " << z;
      }
}

TEST(HostileInputs, ViewDependentCoverage) {
  for (double c : hostile())
    for (double nov : hostile()) {
      const double v = viewDependentCoverage(c, nov);
      EXPECT_TRUE(std::isfinite(v) && inUnit(v)) << c << " " << nov;
    }
}

}  // namespace
}  // namespace substratec::helpers
