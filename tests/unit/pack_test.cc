// Tests for per-pixel packing (compiler/core/storage/pack.h, docs/storage.md):
// every encoding round-trips within the error the field table claims (exact
// fields exactly) for many random values and the dither at 0, 0.5 and 0.999;
// the dither is centred (the decoded mean converges to the input); every
// layout of every example packs into layout.words() words and the generic
// unpacker recovers the layout and the values from the stream alone.
#include "storage/pack.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <numbers>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"

namespace substratec {
namespace pack_test {

constexpr double kDithers[] = {0.0, 0.5, 0.999};
constexpr double kEps = 1e-9;

// Error bounds of docs/storage.md, "Field table". The octahedral normals are
// the worst case of a dithered code (up to one step on each coordinate): at
// the centre of an octahedron face, p = (1/3, 1/3), one step on both
// coordinates turns the normal by sqrt(18) steps of p, i.e. 0.00742 degrees
// for snorm16 (step 1/32767) and 0.1187 degrees for unorm12 (step 2/4095).
// (The table's 0.006 and 0.09 degrees hold for most normals, not all.)
constexpr double kNormalBoundDeg = 0.0075;    // basis normal, octahedral 2 x snorm16
constexpr double kTopNormalBoundDeg = 0.119;  // top-layer word, octahedral 2 x unorm12
constexpr double kIrisPlaneBoundDeg = 1.91;   // an eye's iris plane normal, octahedral 2 x unorm8 (step 2/255)
constexpr double kTangentBoundDeg = 0.022;   // tangent angle unorm14
constexpr double kMfpBoundStops = 32.0 / 255.0;
constexpr double kHalfRelative = 1.0 / 2048.0;  // 2^-11

double colorBound(double c, int channel) {
  const double q = channel < 2 ? 1.0 / 127 : 1.0 / 63;
  return 2 * std::sqrt(c) * q + q * q + kEps;
}

double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3d normalize(const Vec3d& v) {
  const double l = std::sqrt(dot(v, v));
  return {v[0] / l, v[1] / l, v[2] / l};
}
double angleDeg(const Vec3d& a, const Vec3d& b) {
  // atan2 of |a x b| and a.b: accurate for tiny angles, unlike acos.
  const Vec3d c = cross(a, b);
  return std::atan2(std::sqrt(dot(c, c)), dot(a, b)) * 180.0 / std::numbers::pi;
}

struct Rng {
  std::mt19937_64 gen;
  explicit Rng(std::uint64_t seed) : gen(seed) {}
  double uniform(double lo = 0, double hi = 1) { return std::uniform_real_distribution<double>(lo, hi)(gen); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(gen); }
  Vec3d color() { return {uniform(), uniform(), uniform()}; }
  Vec3d unit() {
    std::normal_distribution<double> n(0, 1);
    for (;;) {
      Vec3d v{n(gen), n(gen), n(gen)};
      if (dot(v, v) > 1e-6) return normalize(v);
    }
  }
  Vec3d tangentOf(const Vec3d& n) {
    for (;;) {
      const Vec3d t = cross(n, unit());
      if (dot(t, t) > 1e-6) return normalize(t);
    }
  }
  double logUniform(double lo, double hi) { return std::exp2(uniform(std::log2(lo), std::log2(hi))); }
};

// ---------------------------------------------------------------------------
// Scalars

TEST(Pack, UnormRoundTripWithinOneStep) {
  Rng rng(1);
  for (int bits : {6, 8, 12, 14, 16}) {
    const double step = 1.0 / ((1u << bits) - 1);
    for (double u : kDithers) {
      for (int i = 0; i < 20000; ++i) {
        const double x = rng.uniform();
        const std::uint32_t code = quantizeUnorm(x, bits, u);
        ASSERT_LT(code, 1u << bits);
        ASSERT_LE(std::abs(dequantizeUnorm(code, bits) - x), step + kEps) << bits << " " << x << " " << u;
      }
      // The ends are exact and out-of-range values clamp.
      EXPECT_EQ(quantizeUnorm(0.0, bits, u), 0u);
      EXPECT_EQ(quantizeUnorm(1.0, bits, u), (1u << bits) - 1);
      EXPECT_EQ(quantizeUnorm(-3.0, bits, u), 0u);
      EXPECT_EQ(quantizeUnorm(7.0, bits, u), (1u << bits) - 1);
      EXPECT_EQ(quantizeUnorm(std::numeric_limits<double>::quiet_NaN(), bits, u), 0u);
      EXPECT_EQ(dequantizeUnorm((1u << bits) - 1, bits), 1.0);
    }
  }
}

TEST(Pack, SnormRoundTripWithinOneStepAndZeroIsExact) {
  Rng rng(2);
  for (int bits : {4, 8, 16}) {
    const double s = (1u << (bits - 1)) - 1;
    for (double u : kDithers) {
      for (int i = 0; i < 20000; ++i) {
        const double x = rng.uniform(-1, 1);
        const std::uint32_t code = quantizeSnorm(x, bits, u);
        ASSERT_LE(code, 2 * s);
        ASSERT_LE(std::abs(dequantizeSnorm(code, bits) - x), 1 / s + kEps) << bits << " " << x << " " << u;
      }
      // Anisotropy's convention: code = round(127 a) + 127; 0 and the ends are exact.
      EXPECT_EQ(quantizeSnorm(0.0, bits, u), s);
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(0.0, bits, u), bits), 0.0);
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(1.0, bits, u), bits), 1.0);
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(-1.0, bits, u), bits), -1.0);
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(5.0, bits, u), bits), 1.0);
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(-5.0, bits, u), bits), -1.0);
      EXPECT_EQ(quantizeSnorm(std::numeric_limits<double>::quiet_NaN(), bits, u), s);
    }
  }
  EXPECT_EQ(quantizeSnorm(0.5, 8, 0.5), 191u);  // round(63.5) + 127
  EXPECT_EQ(dequantizeSnorm(255u, 8), 1.0);     // the unused code clamps
}

TEST(Pack, ColorRoundTripWithinOneSqrtStep) {
  Rng rng(3);
  double worst[3] = {0, 0, 0};
  for (double u : kDithers) {
    for (int i = 0; i < 30000; ++i) {
      Vec3d c = rng.color();
      if (i % 3 == 0) c = {c[0] * c[0] * c[0], c[1] * c[1], c[2] * 0.01};  // dark values
      const std::uint32_t code = quantizeColor(c, u);
      ASSERT_LT(code, 1u << 20);
      const Vec3d d = dequantizeColor(code);
      for (int k = 0; k < 3; ++k) {
        const double e = std::abs(d[k] - c[k]);
        ASSERT_LE(e, colorBound(c[k], k)) << k << " " << c[k] << " " << u;
        worst[k] = std::max(worst[k], e);
      }
    }
    EXPECT_EQ(dequantizeColor(quantizeColor({0, 0, 0}, u)), (Vec3d{0, 0, 0}));
    EXPECT_EQ(dequantizeColor(quantizeColor({1, 1, 1}, u)), (Vec3d{1, 1, 1}));
    EXPECT_EQ(dequantizeColor(quantizeColor({-1, 2, 1e9}, u)), (Vec3d{0, 1, 1}));
  }
  EXPECT_LE(worst[0], 0.0158);
  EXPECT_LE(worst[1], 0.0158);
  EXPECT_LE(worst[2], 0.0320);
  // Channel layout: r bits 0-6, g 7-13, b 14-19.
  EXPECT_EQ(quantizeColor({1, 0, 0}, 0), 0x7fu);
  EXPECT_EQ(quantizeColor({0, 1, 0}, 0), 0x7fu << 7);
  EXPECT_EQ(quantizeColor({0, 0, 1}, 0), 0x3fu << 14);
}

TEST(Pack, SssRoundTripWithinTheLogStepAndPhaseStep) {
  Rng rng(4);
  const double lo = std::exp2(packfmt::kMfpLog2Min + kMfpBoundStops), hi = 256.0;
  for (double u : kDithers) {
    for (int i = 0; i < 20000; ++i) {
      const Vec3d mfp{rng.logUniform(lo, hi), rng.logUniform(lo, hi), rng.logUniform(1e-4, 1e-1)};
      const double phase = rng.uniform(-1, 1);
      const std::uint32_t code = quantizeSss(mfp, phase, u);
      ASSERT_LT(code, 1u << 28);
      Vec3d m;
      double p;
      dequantizeSss(code, m, p);
      for (int k = 0; k < 3; ++k) {
        ASSERT_LE(std::abs(std::log2(m[k]) - std::log2(mfp[k])), kMfpBoundStops + kEps) << mfp[k] << " " << u;
        ASSERT_LE(std::abs(m[k] / mfp[k] - 1), 0.091) << mfp[k];  // "relative 9.1 %"
      }
      ASSERT_LE(std::abs(p - phase), 1.0 / 7 + kEps);
    }
  }
}

TEST(Pack, MfpZeroMeansNoMediumAndTheRangeEndsSaturate) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double u : kDithers) {
    EXPECT_EQ(quantizeMfp(0.0, u), 0u);
    EXPECT_EQ(dequantizeMfp(quantizeMfp(0.0, u)), 0.0);
    EXPECT_EQ(quantizeMfp(-1.0, u), 0u);
    EXPECT_EQ(quantizeMfp(nan, u), 0u);
    // Below the range: the smallest medium, never "no medium".
    for (double tiny : {1e-300, 1e-30, std::exp2(-24.0), std::exp2(-23.99)}) {
      EXPECT_EQ(quantizeMfp(tiny, u), 1u) << tiny;
      const double d = dequantizeMfp(quantizeMfp(tiny, u));
      EXPECT_TRUE(std::isfinite(d) && d > 0) << tiny;
    }
    // Above: 2^8 m.
    for (double big : {256.0, 1e4, 1e300, inf}) {
      EXPECT_EQ(quantizeMfp(big, u), 255u) << big;
      EXPECT_EQ(dequantizeMfp(quantizeMfp(big, u)), 256.0);
    }
    Vec3d m;
    double p;
    dequantizeSss(quantizeSss({0, inf, 1e-40}, nan, u), m, p);
    EXPECT_EQ(m[0], 0.0);
    EXPECT_EQ(m[1], 256.0);
    EXPECT_GT(m[2], 0.0);
    EXPECT_EQ(p, 0.0);
    for (double x : m) EXPECT_FALSE(std::isnan(x));
  }
  for (std::uint32_t code = 0; code < 256; ++code) EXPECT_TRUE(std::isfinite(dequantizeMfp(code)));
}

TEST(Pack, HalfIsRoundToNearestWithinTwoToTheMinus11) {
  Rng rng(5);
  for (int i = 0; i < 50000; ++i) {
    const double x = (i % 2 ? -1 : 1) * rng.logUniform(std::exp2(-14), 65504);
    const double d = halfToFloat(floatToHalf(x));
    ASSERT_LE(std::abs(d - x), std::abs(x) * kHalfRelative * (1 + 1e-9)) << x;
  }
  // Subnormals: absolute error at most half a unit of 2^-24.
  for (int i = 0; i < 10000; ++i) {
    const double x = rng.uniform(-std::exp2(-14), std::exp2(-14));
    // (The value is first rounded to float, hence the tiny relative slack.)
    ASSERT_LE(std::abs(halfToFloat(floatToHalf(x)) - x), std::exp2(-25) + std::abs(x) * 1e-7) << x;
  }
  for (double x : {0.0, 1.0, -2.0, 0.5, 1024.0, 65504.0, std::exp2(-24), std::exp2(-14)})
    EXPECT_EQ(halfToFloat(floatToHalf(x)), x);
  EXPECT_EQ(floatToHalf(1.0), 0x3c00u);
  EXPECT_EQ(floatToHalf(-2.0), 0xc000u);
  EXPECT_EQ(halfToFloat(floatToHalf(1e9)), 65504.0);  // clamped, not infinite
  EXPECT_EQ(halfToFloat(floatToHalf(-1e9)), -65504.0);
  EXPECT_EQ(floatToHalf(std::numeric_limits<double>::quiet_NaN()), 0u);
  EXPECT_EQ(floatToHalf(1.0 + std::exp2(-11)), 0x3c00u);  // a tie rounds to even
  EXPECT_EQ(floatToHalf(1.0 + 3 * std::exp2(-11)), 0x3c02u);
#if defined(__FLT16_MAX__)
  // Against the compiler's IEEE half (round to nearest even).
  for (int i = 0; i < 50000; ++i) {
    const float x = static_cast<float>((i % 2 ? -1 : 1) * rng.logUniform(std::exp2(-26), 65504));
    const _Float16 h = static_cast<_Float16>(x);
    ASSERT_EQ(floatToHalf(x), std::bit_cast<std::uint16_t>(h)) << x;
  }
  for (std::uint32_t b = 0; b < 0x7c00u; ++b) {
    const auto h = static_cast<std::uint16_t>(b);
    ASSERT_EQ(halfToFloat(h), static_cast<double>(std::bit_cast<_Float16>(h))) << b;
    ASSERT_EQ(floatToHalf(halfToFloat(h)), h) << b;
  }
#endif
}

// ---------------------------------------------------------------------------
// Directions

std::vector<Vec3d> specialNormals() {
  const double r2 = 1 / std::sqrt(2.0), r3 = 1 / std::sqrt(3.0);
  std::vector<Vec3d> out = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0}) {
      out.push_back({sx * r2, sy * r2, 0});
      out.push_back({sx * r2, 0, sy * r2});
      out.push_back({0, sx * r2, sy * r2});
      for (double sz : {-1.0, 1.0}) out.push_back({sx * r3, sy * r3, sz * r3});
      // Seams: just above and below the equator, near the octahedron's edges.
      for (double z : {1e-9, -1e-9, 1e-5, -1e-5, 1e-3, -1e-3}) {
        out.push_back(normalize({sx * 0.6, sy * 0.8, z}));
        out.push_back(normalize({sx * 1.0, sy * 1e-7, z}));
        out.push_back(normalize({sx * 1e-7, sy * 1.0, z}));
      }
      // Near the poles.
      out.push_back(normalize({sx * 1e-6, sy * 1e-6, 1}));
      out.push_back(normalize({sx * 1e-6, sy * 1e-6, -1}));
    }
  return out;
}

TEST(Pack, OctahedralNormalsPolesAndSeams) {
  for (double u : kDithers) {
    for (const Vec3d& n : specialNormals()) {
      const Vec3d a = dequantizeNormal(quantizeNormal(n, u));
      EXPECT_LE(angleDeg(a, n), kNormalBoundDeg) << n[0] << " " << n[1] << " " << n[2] << " u=" << u;
      const Vec3d b = unpackTopLayer(packTopLayer({n, 0.5}, u)).normal;
      EXPECT_LE(angleDeg(b, n), kTopNormalBoundDeg) << n[0] << " " << n[1] << " " << n[2] << " u=" << u;
    }
    // The poles and the axes are exact in snorm (0 and +-1 are codes).
    for (const Vec3d& n : std::vector<Vec3d>{{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}})
      EXPECT_EQ(dequantizeNormal(quantizeNormal(n, u)), n);
  }
  // The projection is continuous across the equator and inverts exactly.
  for (const Vec3d& n : specialNormals()) EXPECT_LE(angleDeg(octUnproject(octProject(n)), n), 1e-9);
  // A zero vector does not produce NaN.
  const Vec3d z = dequantizeNormal(quantizeNormal({0, 0, 0}, 0.5));
  for (double c : z) EXPECT_FALSE(std::isnan(c));
}

TEST(Pack, OctahedralNormalsRandom) {
  Rng rng(6);
  double worst = 0, worstTop = 0;
  for (double u : kDithers)
    for (int i = 0; i < 50000; ++i) {
      const Vec3d n = rng.unit();
      const double e = angleDeg(dequantizeNormal(quantizeNormal(n, u)), n);
      const double t = angleDeg(unpackTopLayer(packTopLayer({n, 0.5}, u)).normal, n);
      ASSERT_LE(e, kNormalBoundDeg);
      ASSERT_LE(t, kTopNormalBoundDeg);
      worst = std::max(worst, e);
      worstTop = std::max(worstTop, t);
    }
  RecordProperty("worst_normal_deg", std::to_string(worst));
  RecordProperty("worst_top_normal_deg", std::to_string(worstTop));
}

TEST(Pack, TopLayerWordFields) {
  Rng rng(7);
  for (double u : kDithers)
    for (int i = 0; i < 5000; ++i) {
      const TopLayerValues t{rng.unit(), rng.uniform()};
      const TopLayerValues d = unpackTopLayer(packTopLayer(t, u));
      ASSERT_LE(std::abs(d.roughness - t.roughness), 1.0 / 255 + kEps);
      ASSERT_LE(angleDeg(d.normal, t.normal), kTopNormalBoundDeg);
    }
  // Roughness in bits 24-31, the normal's x in 0-11, y in 12-23.
  EXPECT_EQ(packTopLayer({{0, 0, 1}, 1.0}, 0) >> 24, 255u);
  EXPECT_EQ(packTopLayer({{1, 0, 0}, 0.0}, 0) & 0xfffu, 4095u);
  EXPECT_EQ((packTopLayer({{0, -1, 0}, 0.0}, 0) >> 12) & 0xfffu, 0u);
}

TEST(Pack, OrthonormalBasisIsTheDuffFrame) {
  Rng rng(8);
  std::vector<Vec3d> normals = specialNormals();
  for (int i = 0; i < 2000; ++i) normals.push_back(rng.unit());
  for (const Vec3d& n : normals) {
    Vec3d t, b;
    orthonormalBasis(n, t, b);
    EXPECT_NEAR(dot(t, t), 1, 1e-12);
    EXPECT_NEAR(dot(b, b), 1, 1e-12);
    EXPECT_NEAR(dot(t, b), 0, 1e-12);
    EXPECT_NEAR(dot(t, n), 0, 1e-12);
    EXPECT_NEAR(dot(b, n), 0, 1e-12);
    const Vec3d c = cross(t, b);  // right-handed: T x B = N
    EXPECT_LE(angleDeg(c, n), 1e-6);
  }
  Vec3d t, b;
  orthonormalBasis({0, 0, 1}, t, b);
  EXPECT_EQ(t, (Vec3d{1, 0, 0}));
  EXPECT_EQ(b, (Vec3d{0, 1, 0}));
  // s is copysign(1, z), as in the runtime's substrate_orthonormal_basis: -0 is negative.
  orthonormalBasis({0.6, 0.8, -0.0}, t, b);
  Vec3d tm, bm;
  orthonormalBasis({0.6, 0.8, -1e-300}, tm, bm);
  EXPECT_EQ(t, tm);
  EXPECT_EQ(b, bm);
  orthonormalBasis({0.6, 0.8, 0.0}, t, b);
  EXPECT_NE(t, tm);
}

TEST(Pack, TangentAngleRoundTrip) {
  Rng rng(9);
  const double step = 360.0 / 16383;
  std::vector<Vec3d> normals = specialNormals();
  for (int i = 0; i < 20000; ++i) normals.push_back(rng.unit());
  for (double u : kDithers)
    for (const Vec3d& n : normals) {
      const Vec3d t = rng.tangentOf(n);
      const std::uint32_t code = encodeTangentAngle(t, n, u);
      ASSERT_LT(code, 1u << 14);
      const Vec3d d = decodeTangentAngle(code, n);
      ASSERT_NEAR(dot(d, n), 0, 1e-9);
      ASSERT_LE(angleDeg(d, t), kTangentBoundDeg) << n[0] << " " << n[1] << " " << n[2];
      ASSERT_LE(angleDeg(d, t), step + 1e-9);
    }
  // The canonical tangent is angle 0; a quarter turn is the bitangent.
  Vec3d t0, b0;
  const Vec3d n = normalize({0.3, -0.2, 0.9});
  orthonormalBasis(n, t0, b0);
  EXPECT_EQ(encodeTangentAngle(t0, n, 0.0), 0u);
  EXPECT_LE(angleDeg(decodeTangentAngle(encodeTangentAngle(b0, n, 0.5), n), b0), step / 2 + 1e-9);
  // Angles just below 2 pi wrap onto 0 (the last code is a full turn).
  const double a = -1e-6;
  const Vec3d almost{std::cos(a) * t0[0] + std::sin(a) * b0[0], std::cos(a) * t0[1] + std::sin(a) * b0[1],
                     std::cos(a) * t0[2] + std::sin(a) * b0[2]};
  EXPECT_LE(angleDeg(decodeTangentAngle(encodeTangentAngle(almost, n, 0.999), n), t0), step);
}

// ---------------------------------------------------------------------------
// Centred dither: averaging over the dither recovers the value.

template <class F>
double meanOverDither(F decodeOfDither, int samples, bool stratified, Rng& rng) {
  double sum = 0;
  for (int k = 0; k < samples; ++k) sum += decodeOfDither(stratified ? (k + 0.5) / samples : rng.uniform());
  return sum / samples;
}

TEST(Pack, DitherIsZeroMean) {
  Rng rng(10);
  for (bool stratified : {true, false}) {
    const int n = stratified ? 4096 : 40000;
    // In steps of the code: stratified, the mean of floor(y + (k + 1/2)/n) is y
    // to within 1/(2n); random, 4 sigma of the mean of n errors of at most one step.
    const double tol = stratified ? 0.5 / n + 1e-9 : 4.0 * 0.5 / std::sqrt(static_cast<double>(n));
    for (int i = 0; i < 40; ++i) {
      const double x = rng.uniform();
      const double m8 = meanOverDither([&](double u) { return dequantizeUnorm(quantizeUnorm(x, 8, u), 8); }, n,
                                       stratified, rng);
      EXPECT_NEAR(m8, x, tol / 255 + 1e-12) << x;
      const double a = rng.uniform(-1, 1);
      const double ms = meanOverDither([&](double u) { return dequantizeSnorm(quantizeSnorm(a, 8, u), 8); }, n,
                                       stratified, rng);
      EXPECT_NEAR(ms, a, tol / 127 + 1e-12) << a;
      const double ms4 = meanOverDither([&](double u) { return dequantizeSnorm(quantizeSnorm(a, 4, u), 4); }, n,
                                        stratified, rng);
      EXPECT_NEAR(ms4, a, tol / 7 + 1e-12) << a;
      // Colours are dithered in the sqrt domain; squaring adds at most the
      // variance of one step, q^2/4 (6.3e-5 for blue).
      const Vec3d c = rng.color();
      for (int k = 0; k < 3; ++k) {
        const double q = k < 2 ? 1.0 / 127 : 1.0 / 63;
        const double mc = meanOverDither([&](double u) { return dequantizeColor(quantizeColor(c, u))[k]; }, n,
                                         stratified, rng);
        EXPECT_NEAR(mc, c[k], q * q / 4 + 2 * std::sqrt(c[k]) * q * tol + 1e-9) << k << " " << c[k];
      }
      // The top-layer roughness and the normal's octahedral coordinates.
      const Vec3d nrm = rng.unit();
      const auto p = octProject(nrm);
      const double mp = meanOverDither(
          [&](double u) { return dequantizeSnorm(octEncodeSnorm(nrm, 16, u)[0], 16); }, n, stratified, rng);
      EXPECT_NEAR(mp, p[0], tol / 32767 + 1e-12);
    }
  }
  // Without dither (u = 0.5 is rounding) the error of a fixed value does not average out.
  EXPECT_NE(dequantizeUnorm(quantizeUnorm(0.3, 8, 0.5), 8), 0.3);
}

// ---------------------------------------------------------------------------
// The bit stream

TEST(Pack, BitStreamStraddlesWords) {
  Rng rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<std::uint32_t> words(12, 0u);
    std::vector<std::pair<int, std::uint32_t>> fields;
    std::size_t pos = 0;
    while (true) {
      const int bits = rng.integer(1, 32);
      if (pos + bits > words.size() * 32) break;
      const std::uint32_t v = static_cast<std::uint32_t>(rng.gen()) & (bits == 32 ? ~0u : (1u << bits) - 1);
      writeBits(words, pos, bits, v);
      fields.push_back({bits, v});
      pos += bits;
    }
    pos = 0;
    for (auto [bits, v] : fields) {
      ASSERT_EQ(readBits(words.data(), words.size(), pos, bits), v);
      pos += bits;
    }
  }
  std::vector<std::uint32_t> w(2, 0u);
  writeBits(w, 28, 8, 0xabu);  // straddles: low nibble in word 0, high nibble in word 1
  EXPECT_EQ(w[0], 0xb0000000u);
  EXPECT_EQ(w[1], 0xau);
  EXPECT_THROW(readBits(w.data(), w.size(), 40, 32), std::out_of_range);
}

// ---------------------------------------------------------------------------
// Materials

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::optional<CompileResult> compile(const std::string& name, const std::string& text) {
  Diagnostics d(name);
  auto r = compileText(name, text, CompileOptions{}, d);
  EXPECT_TRUE(r) << d.formatAll();
  return r;
}

struct Pixel {
  std::vector<ClosureValues> closures;
  std::vector<BasisValues> bases;
  TopLayerValues top;
};

/// Random values consistent with the layout: stored fields random, the others
/// at the neutral values the unpacker reports.
Pixel randomPixel(const StorageLayout& L, Rng& rng) {
  Pixel px;
  for (const ClosureLayout& c : L.closures) {
    ClosureValues v;
    const auto f = c.storedFeatures;
    v.diffuseAlbedo = rng.color();
    if (f & kFeatHair) {
      v.hair = {rng.uniform(), rng.uniform(1, 3), rng.uniform(-20, 20), rng.uniform()};
    } else if (f & kFeatEye) {
      v.irisN = rng.unit();
      v.irisPlaneN = rng.unit();
      v.iris = {rng.uniform(), rng.uniform()};
    } else {
      v.f0 = rng.color();
    }
    v.roughness = rng.uniform();
    if (c.storesWeight) v.weight = rng.uniform();
    if (!c.isTop) v.topTransmittance = rng.color();
    v.coverageAbove = c.storesCoverageAbove ? rng.uniform() : (c.isTop ? 0.0 : 1.0);
    if (f & kFeatF90) v.f90 = rng.color();
    if (f & kFeatSss) {
      for (double& m : v.sssMfp) m = rng.integer(0, 9) == 0 ? 0.0 : rng.logUniform(1e-6, 100);
      v.sssPhaseAnisotropy = rng.uniform(-1, 1);
      v.sssType = static_cast<std::uint32_t>(rng.integer(1, 3));
    }
    if (f & kFeatHaze) {
      v.secondRoughness = rng.uniform();
      v.secondRoughnessWeight = rng.uniform();
    }
    if (f & kFeatFuzz) {
      v.fuzzAmount = rng.uniform();
      v.fuzzColor = rng.color();
      v.fuzzRoughness = rng.uniform();
    }
    if (f & kFeatAnisotropy) v.anisotropy = rng.uniform(-1, 1);
    if (f & kFeatSpecularProfile) v.specularProfile = static_cast<std::uint32_t>(rng.integer(1, 256));
    if (f & kFeatGlint) {
      v.glintValue = rng.uniform();
      v.glintUv = {rng.uniform(-1e3, 1e3), rng.uniform(-10, 10)};
      for (double& d : v.glintUvDerivatives) d = (rng.integer(0, 1) ? 1 : -1) * rng.logUniform(1e-4, 1e3);
    }
    v.emissive = rng.color();  // never stored
    v.isTop = c.isTop;
    v.basis = c.basis;
    v.features = closureHeaderFeatures(c);
    px.closures.push_back(v);
  }
  for (int b = 0; b < L.basisCount; ++b) {
    BasisValues bv;
    bv.normal = rng.unit();
    bv.tangent = rng.tangentOf(bv.normal);
    px.bases.push_back(bv);
  }
  const bool single = L.closures.size() == 1;
  // The top-layer word holds basis 0's normal when it is elided; otherwise the
  // caller's coverage-weighted mean (any normal here).
  px.top.normal = (single || L.basis0NormalElided) ? px.bases[0].normal : rng.unit();
  px.top.roughness = px.closures[0].roughness;
  return px;
}

void expectColor(const Vec3d& got, const Vec3d& want, const std::string& what) {
  for (int k = 0; k < 3; ++k) EXPECT_LE(std::abs(got[k] - want[k]), colorBound(want[k], k)) << what << "[" << k << "]";
}

void expectUnorm(double got, double want, int bits, const std::string& what) {
  EXPECT_LE(std::abs(got - want), 1.0 / ((1u << bits) - 1) + kEps) << what;
}

/// Packs `px` into `L`, unpacks it generically and checks the layout and every value.
void roundTrip(const StorageLayout& L, const Pixel& px, double u, const std::string& name) {
  SCOPED_TRACE(name + " u=" + std::to_string(u));
  const std::vector<std::uint32_t> words = packMaterial(L, px.closures, px.bases, u);
  ASSERT_EQ(static_cast<int>(words.size()), L.words());
  if (L.totalBits % 32) {
    EXPECT_EQ(words.back() >> (L.totalBits % 32), 0u) << "padding bits are zero";
  }
  const std::uint32_t top = packTopLayer(px.top, u);
  const UnpackedMaterial m = unpackMaterial(words.data(), words.size(), top);

  // The layout, read back from the headers alone.
  EXPECT_EQ(m.cls, L.layoutClass);
  EXPECT_EQ(m.layout.layoutClass, L.layoutClass);
  EXPECT_EQ(m.layout.totalBits, L.totalBits);
  EXPECT_EQ(m.layout.words(), L.words());
  EXPECT_EQ(m.layout.basisCount, L.basisCount);
  if (L.closures.size() > 1) {
    EXPECT_EQ(m.layout.basis0NormalElided, L.basis0NormalElided);
  }
  ASSERT_EQ(m.layout.fields.size(), L.fields.size());
  for (std::size_t i = 0; i < L.fields.size(); ++i) {
    EXPECT_EQ(m.layout.fields[i].name, L.fields[i].name);
    EXPECT_EQ(m.layout.fields[i].bits, L.fields[i].bits);
    EXPECT_EQ(m.layout.fields[i].closure, L.fields[i].closure);
    EXPECT_EQ(m.layout.fields[i].basis, L.fields[i].basis);
  }
  ASSERT_EQ(m.closures.size(), L.closures.size());
  ASSERT_EQ(m.layout.closures.size(), L.closures.size());
  ASSERT_EQ(static_cast<int>(m.bases.size()), L.basisCount);

  for (std::size_t i = 0; i < L.closures.size(); ++i) {
    SCOPED_TRACE("closure " + std::to_string(i));
    const ClosureLayout& c = L.closures[i];
    const ClosureValues& want = px.closures[i];
    const ClosureValues& got = m.closures[i];
    EXPECT_EQ(m.layout.closures[i].basis, c.basis);
    EXPECT_EQ(m.layout.closures[i].isTop, c.isTop);
    EXPECT_EQ(m.layout.closures[i].storesWeight, c.storesWeight);
    EXPECT_EQ(m.layout.closures[i].storesCoverageAbove, c.storesCoverageAbove);
    EXPECT_EQ(m.layout.closures[i].storedFeatures, c.storedFeatures);
    EXPECT_EQ(m.layout.closures[i].extraInterfaces, c.extraInterfaces);
    EXPECT_EQ(got.extraInterfaces, static_cast<std::uint32_t>(c.extraInterfaces));
    EXPECT_EQ(got.basis, c.basis);
    EXPECT_EQ(got.isTop, c.isTop);
    EXPECT_EQ(got.features, closureHeaderFeatures(c));
    EXPECT_EQ(got.sssType, want.sssType);
    expectColor(got.diffuseAlbedo, want.diffuseAlbedo, "diffuse_albedo");
    if (c.storedFeatures & kFeatHair) {  // a fibre's hair field in place of F0
      expectUnorm(got.hair[0], want.hair[0], 8, "hair azimuthal roughness");
      EXPECT_LE(std::abs(got.hair[1] - want.hair[1]), 2.0 / 255 + kEps) << "hair ior";
      EXPECT_LE(std::abs(got.hair[2] - want.hair[2]), 20.0 / 127 + kEps) << "hair cuticle angle";
      expectUnorm(got.hair[3], want.hair[3], 8, "hair scatter");
      EXPECT_EQ(got.f0, ClosureValues{}.f0) << "a fibre stores no F0";
    } else if (c.storedFeatures & kFeatEye) {  // an eye's iris fields in place of F0
      EXPECT_LE(angleDeg(got.irisN, want.irisN), kNormalBoundDeg) << "iris normal";
      EXPECT_LE(angleDeg(got.irisPlaneN, want.irisPlaneN), kIrisPlaneBoundDeg) << "iris plane normal";
      expectUnorm(got.iris[0], want.iris[0], 8, "iris mask");
      expectUnorm(got.iris[1], want.iris[1], 8, "iris distance");
      EXPECT_EQ(got.f0, ClosureValues{}.f0) << "an eye stores no F0: its cornea's is 0.04";
    } else {
      expectColor(got.f0, want.f0, "f0");
    }
    expectColor(got.f90, want.f90, "f90");
    expectColor(got.topTransmittance, want.topTransmittance, "top_transmittance");
    expectUnorm(got.roughness, want.roughness, 8, "roughness");
    expectUnorm(got.weight, want.weight, 8, "weight");
    expectUnorm(got.coverageAbove, want.coverageAbove, 8, "coverage_above");
    EXPECT_LE(std::abs(got.anisotropy - want.anisotropy), 1.0 / 127 + kEps) << "anisotropy";
    for (int k = 0; k < 3; ++k) {
      if (want.sssMfp[k] == 0) {
        EXPECT_EQ(got.sssMfp[k], 0.0) << "mfp 0 is no medium";
      } else {
        EXPECT_LE(std::abs(std::log2(got.sssMfp[k] / want.sssMfp[k])), kMfpBoundStops + kEps) << "mfp";
      }
    }
    EXPECT_LE(std::abs(got.sssPhaseAnisotropy - want.sssPhaseAnisotropy), 1.0 / 7 + kEps) << "phase";
    expectUnorm(got.secondRoughness, want.secondRoughness, 8, "second_roughness");
    expectUnorm(got.secondRoughnessWeight, want.secondRoughnessWeight, 8, "haze weight");
    expectUnorm(got.fuzzAmount, want.fuzzAmount, 6, "fuzz amount");
    expectUnorm(got.fuzzRoughness, want.fuzzRoughness, 6, "fuzz roughness");
    expectColor(got.fuzzColor, want.fuzzColor, "fuzz colour");
    EXPECT_EQ(got.specularProfile, want.specularProfile) << "specular profile";
    expectUnorm(got.glintValue, want.glintValue, 8, "glint density");
    for (int k = 0; k < 2; ++k)
      EXPECT_EQ(got.glintUv[k], static_cast<double>(static_cast<float>(want.glintUv[k]))) << "glint uv exact";
    for (int k = 0; k < 4; ++k)
      EXPECT_LE(std::abs(got.glintUvDerivatives[k] - want.glintUvDerivatives[k]),
                std::abs(want.glintUvDerivatives[k]) * kHalfRelative * (1 + 1e-6))
          << "glint derivative " << k;
    EXPECT_EQ(got.emissive, (Vec3d{0, 0, 0})) << "emissive is not stored";
  }

  const bool single = L.closures.size() == 1;
  for (int b = 0; b < L.basisCount; ++b) {
    SCOPED_TRACE("basis " + std::to_string(b));
    const bool elided = single || (b == 0 && L.basis0NormalElided);
    const double normalBound = elided ? kTopNormalBoundDeg : kNormalBoundDeg;
    EXPECT_LE(angleDeg(m.bases[b].normal, px.bases[b].normal), normalBound);
    bool aniso = false;
    for (const auto& c : L.closures)
      if (c.basis == b && (c.storedFeatures & kTangentFeatures)) aniso = true;  // a fibre's tangent too
    EXPECT_NEAR(dot(m.bases[b].tangent, m.bases[b].normal), 0, 1e-9);
    if (aniso) {
      // The angle step, plus the tilt of the decoded normal's plane.
      EXPECT_LE(angleDeg(m.bases[b].tangent, px.bases[b].tangent), kTangentBoundDeg + normalBound);
    } else {
      Vec3d t0, b0;
      orthonormalBasis(m.bases[b].normal, t0, b0);
      EXPECT_EQ(m.bases[b].tangent, t0) << "an isotropic basis gets the canonical tangent";
    }
  }
  expectUnorm(m.topLayer.roughness, px.top.roughness, 8, "top roughness");
  EXPECT_LE(angleDeg(m.topLayer.normal, px.top.normal), kTopNormalBoundDeg);
}

bool representable(const StorageLayout& L) {
  return !L.closures.empty() && L.closures.size() <= 8 && L.basisCount >= 1 && L.basisCount <= 8;
}

TEST(PackMaterial, EveryLayoutOfEveryExampleRoundTrips) {
  int layouts = 0;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(SUBSTRATEC_SOURCE_DIR "/examples"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 9u);
  Rng rng(12);
  for (const auto& path : files) {
    const std::string name = path.filename().string();
    auto r = compile(name, readFile(path.string()));
    ASSERT_TRUE(r) << name;
    for (const StorageLayout* L : {&r->before, &r->after}) {
      if (!representable(*L)) continue;
      ++layouts;
      for (int trial = 0; trial < 40; ++trial)
        for (double u : kDithers) roundTrip(*L, randomPixel(*L, rng), u, name);
    }
  }
  EXPECT_GE(layouts, 2 * 9);
}

TEST(PackMaterial, HeadersDecodeToTheClassClosureCountAndFeatures) {
  struct Row {
    const char* file;
    LayoutClass cls;
    std::size_t closures;
  };
  for (const Row& row : {Row{"row12_simple", LayoutClass::Simple, 1}, Row{"row16_single_sss_wrap", LayoutClass::Single, 1},
                         Row{"row20_haze_f90", LayoutClass::Single, 1}, Row{"row24_fuzz", LayoutClass::Single, 1},
                         Row{"row28_anisotropy", LayoutClass::Complex, 1}, Row{"row40_coating", LayoutClass::Complex, 2},
                         Row{"row44_specular_profile", LayoutClass::Special, 2},
                         Row{"row60_glint", LayoutClass::Special, 2}, Row{"worked_example_72", LayoutClass::Complex, 3}}) {
    SCOPED_TRACE(row.file);
    auto r = compile(row.file, readFile(std::string(SUBSTRATEC_SOURCE_DIR "/examples/") + row.file + ".json"));
    ASSERT_TRUE(r);
    const StorageLayout& L = r->after;
    Rng rng(13);
    const Pixel px = randomPixel(L, rng);
    const auto words = packMaterial(L, px.closures, px.bases, 0.5);
    // The lighting pass classifies tiles from bits 0-1 of word 0.
    EXPECT_EQ(static_cast<LayoutClass>(words[0] & 3u), row.cls);
    const std::uint32_t header = words[0] & 0xffffu;
    EXPECT_EQ((header & packfmt::kMultiClosureHeaderBit) != 0, row.closures > 1);
    if (row.closures > 1) {
      EXPECT_EQ(((header >> 2) & 7u) + 1, row.closures);
      EXPECT_EQ(static_cast<int>((header >> 5) & 15u), L.basisCount);
    } else {
      EXPECT_EQ((header >> 2) & 0xffu, closureHeaderFeatures(L.closures[0]));
      EXPECT_EQ((header >> 12) & 0xfu, 0u) << "reserved";
    }
    const UnpackedMaterial m = unpackMaterial(words.data(), words.size(), packTopLayer(px.top, 0.5));
    EXPECT_EQ(m.cls, row.cls);
    ASSERT_EQ(m.closures.size(), row.closures);
    for (std::size_t i = 0; i < row.closures; ++i)
      EXPECT_EQ(m.closures[i].features, closureHeaderFeatures(L.closures[i])) << i;
  }
  // Explicit bits for two rows.
  {
    auto r = compile("row12_simple", readFile(SUBSTRATEC_SOURCE_DIR "/examples/row12_simple.json"));
    Rng rng(14);
    const Pixel px = randomPixel(r->after, rng);
    EXPECT_EQ(packMaterial(r->after, px.closures, px.bases, 0.5)[0] & 0xffffu, 0u);  // SIMPLE, nothing else
  }
  {
    auto r = compile("row28_anisotropy", readFile(SUBSTRATEC_SOURCE_DIR "/examples/row28_anisotropy.json"));
    Rng rng(15);
    Pixel px = randomPixel(r->after, rng);
    px.closures[0].sssType = kSssTypeWrap;
    const std::uint32_t h = packMaterial(r->after, px.closures, px.bases, 0.5)[0] & 0xffffu;
    // COMPLEX | F90, anisotropy, haze, fuzz | SSS wrap; bit 15 clear (single-closure header).
    EXPECT_EQ(h, 2u | ((kClosureF90 | kClosureAnisotropy | kClosureHaze | kClosureFuzz) << 2) | (kSssTypeWrap << 10));
  }
}

constexpr const char* kManyInputs = R"({
  "w": {"type": "float", "default": 0.5},
  "an": {"type": "float", "default": 0.5},
  "c": {"type": "float", "default": 0.5},
  "lut": {"type": "texture2d"},
  "mfp": {"type": "color", "default": [0.01, 0.02, 0.03]},
  "n0": {"type": "vec3", "default": [0, 0, 1]}, "n1": {"type": "vec3", "default": [0, 0.6, 0.8]},
  "n2": {"type": "vec3", "default": [0.6, 0, 0.8]}, "n3": {"type": "vec3", "default": [0, 1, 0]},
  "n4": {"type": "vec3", "default": [1, 0, 0]}, "n5": {"type": "vec3", "default": [0, 0, -1]},
  "n6": {"type": "vec3", "default": [0.6, 0.8, 0]}, "n7": {"type": "vec3", "default": [0, -0.8, 0.6]},
  "t0": {"type": "vec3", "default": [1, 0, 0]}, "t1": {"type": "vec3", "default": [1, 0, 0]},
  "t2": {"type": "vec3", "default": [0, 1, 0]}, "t7": {"type": "vec3", "default": [1, 0, 0]}
})";

std::string document(const std::string& nodes, const std::string& output = "root") {
  return R"({"format": "substrate-material/1", "name": "m", "settings": {"bytes_per_pixel": 1024, "max_closures": 8},
             "inputs": )" +
         std::string(kManyInputs) + R"(, "nodes": {)" + nodes + R"(}, "output": ")" + output + R"("})";
}

TEST(PackMaterial, TopClosuresOnSeveralBasesStoreBasisZerosNormal) {
  // Two top closures with different normals: basis 0 is not elided; the
  // anisotropic one stores a tangent too.
  auto r = compile("mix.json", document(R"(
    "a": {"kind": "slab", "roughness": 0.3, "normal": "$n1", "anisotropy": "$an", "tangent": "$t1"},
    "b": {"kind": "slab", "roughness": 0.6, "normal": "$n2", "f90": [1, 0.5, 0.5]},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$w"})"));
  ASSERT_TRUE(r);
  const StorageLayout& L = r->after;
  ASSERT_EQ(L.closures.size(), 2u);
  EXPECT_FALSE(L.basis0NormalElided);
  EXPECT_EQ(L.basisCount, 2);
  Rng rng(16);
  for (int trial = 0; trial < 100; ++trial)
    for (double u : kDithers) roundTrip(L, randomPixel(L, rng), u, "mix");
}

TEST(PackMaterial, EightClosuresOnEightBasesWithEveryFeature) {
  auto r = compile("eight.json", document(R"(
    "coat": {"kind": "slab", "roughness": 0.1, "normal": "$n0", "anisotropy": "$an", "tangent": "$t0",
             "second_roughness_weight": "$w", "fuzz_amount": "$w", "f90": [1, 0.9, 0.8], "glint_value": "$c",
             "glint_uv": {"kind": "geometry", "attribute": "uv0"}},
    "s1": {"kind": "slab", "normal": "$n1", "anisotropy": "$an", "tangent": "$t1", "sss_mfp": "$mfp", "sss_type": "wrap"},
    "s2": {"kind": "slab", "normal": "$n2", "anisotropy": "$an", "tangent": "$t2", "specular_profile": "$lut"},
    "s3": {"kind": "slab", "normal": "$n3", "sss_mfp": "$mfp", "second_roughness_weight": "$w"},
    "s4": {"kind": "slab", "normal": "$n4", "fuzz_amount": "$w", "glint_value": "$c",
           "glint_uv": {"kind": "geometry", "attribute": "uv0"}},
    "s5": {"kind": "slab", "normal": "$n5", "sss_mfp": "$mfp", "sss_type": "simple_volume"},
    "s6": {"kind": "slab", "normal": "$n6", "f90": [0.5, 0.5, 1]},
    "s7": {"kind": "slab", "normal": "$n7", "anisotropy": "$an", "tangent": "$t7", "specular_profile": "$lut"},
    "h6": {"kind": "horizontal", "background": "s6", "foreground": "s7", "mix": "$w"},
    "h5": {"kind": "horizontal", "background": "s5", "foreground": "h6", "mix": "$w"},
    "h4": {"kind": "horizontal", "background": "s4", "foreground": "h5", "mix": "$w"},
    "h3": {"kind": "horizontal", "background": "s3", "foreground": "h4", "mix": "$w"},
    "h2": {"kind": "horizontal", "background": "s2", "foreground": "h3", "mix": "$w"},
    "h1": {"kind": "horizontal", "background": "s1", "foreground": "h2", "mix": "$w"},
    "worn": {"kind": "coverage_weight", "a": "coat", "weight": "$c"},
    "root": {"kind": "vertical", "top": "worn", "base": "h1"})"));
  ASSERT_TRUE(r);
  const StorageLayout& L = r->after;
  ASSERT_EQ(L.closures.size(), 8u);
  EXPECT_EQ(L.basisCount, 8);
  EXPECT_EQ(L.layoutClass, LayoutClass::Special);
  EXPECT_GT(L.words(), 32) << "wider than the shader's default SUBSTRATE_MAX_WORDS";
  bool coverageAbove = false;
  for (const auto& c : L.closures) coverageAbove |= c.storesCoverageAbove;
  EXPECT_TRUE(coverageAbove);
  Rng rng(17);
  for (int trial = 0; trial < 100; ++trial)
    for (double u : kDithers) roundTrip(L, randomPixel(L, rng), u, "eight");
}

TEST(PackMaterial, ClosureHeadersHoldTheExtraInterfacesAbove) {
  // Six nested slabs: closure k lies under k interfaces and stores
  // min(k - 1, 3) in closure header bits 14-15 (docs/storage.md).
  std::string nodes;
  for (int k = 0; k < 6; ++k)
    nodes += fmt::format(R"("s{0}": {{"kind": "slab", "roughness": 0.{0}, "sss_mfp": 1e6}}, )", k);
  for (int j = 1; j < 6; ++j)
    nodes += fmt::format(R"({}"{}": {{"kind": "vertical", "top": "s{}", "base": "{}", "thickness": 0}})", j == 1 ? "" : ", ",
                         j == 1 ? "root" : fmt::format("v{}", j), j - 1, j == 5 ? "s5" : fmt::format("v{}", j + 1));
  auto r = compile("stack.json", document(nodes));
  ASSERT_TRUE(r);
  const StorageLayout& L = r->after;
  ASSERT_EQ(L.closures.size(), 6u);
  const int want[] = {0, 0, 1, 2, 3, 3};
  Rng rng(21);
  const Pixel px = randomPixel(L, rng);
  const auto words = packMaterial(L, px.closures, px.bases, 0.5);
  int checked = 0;
  for (std::size_t i = 0; i < L.fields.size(); ++i) {
    const LayoutField& f = L.fields[i];
    if (f.closure < 0 || f.name != fmt::format("closure{}.header", f.closure)) continue;
    std::size_t at = 0;
    for (std::size_t j = 0; j < i; ++j) at += static_cast<std::size_t>(L.fields[j].bits);
    EXPECT_EQ(L.closures[f.closure].extraInterfaces, want[f.closure]) << f.name;
    EXPECT_EQ((readBits(words.data(), words.size(), at, 16) >> 14) & 3u, static_cast<std::uint32_t>(want[f.closure]))
        << f.name;
    ++checked;
  }
  EXPECT_EQ(checked, 6);
  for (int trial = 0; trial < 20; ++trial)
    for (double u : kDithers) roundTrip(L, randomPixel(L, rng), u, "stack");
  StorageLayout bad = L;
  bad.closures[5].extraInterfaces = 4;
  EXPECT_THROW(packMaterial(bad, px.closures, px.bases, 0.5), std::invalid_argument);
}

TEST(PackMaterial, StructureComesFromTheLayout) {
  auto r = compile("row16", readFile(SUBSTRATEC_SOURCE_DIR "/examples/row16_single_sss_wrap.json"));
  ASSERT_TRUE(r);
  const StorageLayout& L = r->after;
  ASSERT_TRUE(L.closures[0].storedFeatures & kFeatSss);
  Rng rng(18);
  Pixel px = randomPixel(L, rng);
  // A closure that stores SSS keeps the stream decodable when its values say "none".
  px.closures[0].sssType = kSssTypeNone;
  // Features, is-top and basis in the values are ignored by the packer.
  px.closures[0].features = 0xffu;
  px.closures[0].isTop = false;
  px.closures[0].basis = 5;
  const auto words = packMaterial(L, px.closures, px.bases, 0.25);
  const UnpackedMaterial m = unpackMaterial(words.data(), words.size(), packTopLayer(px.top, 0.25));
  EXPECT_EQ(m.closures[0].sssType, kSssTypeDiffusion);
  EXPECT_EQ(m.layout.totalBits, L.totalBits);
  EXPECT_TRUE(m.closures[0].isTop);
  EXPECT_EQ(m.closures[0].basis, 0);
}

TEST(PackMaterial, RejectsWhatTheFormatCannotHoldAndMalformedStreams) {
  auto r = compile("row40", readFile(SUBSTRATEC_SOURCE_DIR "/examples/row40_coating.json"));
  ASSERT_TRUE(r);
  const StorageLayout& L = r->after;
  Rng rng(19);
  const Pixel px = randomPixel(L, rng);
  EXPECT_THROW(packMaterial(L, {}, px.bases, 0.5), std::invalid_argument);
  EXPECT_THROW(packMaterial(L, px.closures, {}, 0.5), std::invalid_argument);
  StorageLayout many = L;
  while (many.closures.size() <= 8) many.closures.push_back(L.closures[1]);
  EXPECT_THROW(packMaterial(many, std::vector<ClosureValues>(many.closures.size()), px.bases, 0.5),
               std::invalid_argument);
  StorageLayout unknown = L;
  unknown.fields.push_back({"closure0.sparkle", 4, "", 0, -1});
  unknown.totalBits += 4;
  EXPECT_THROW(packMaterial(unknown, px.closures, px.bases, 0.5), std::invalid_argument);

  const auto words = packMaterial(L, px.closures, px.bases, 0.5);
  EXPECT_NO_THROW(unpackMaterial(words.data(), words.size(), 0u));
  EXPECT_THROW(unpackMaterial(words.data(), words.size() - 1, 0u), std::runtime_error);
  std::vector<std::uint32_t> bad = words;
  bad[0] = (bad[0] & ~(0xfu << 5)) | (0u << 5);  // basis count 0
  EXPECT_THROW(unpackMaterial(bad.data(), bad.size(), 0u), std::runtime_error);
  bad = words;
  bad[0] |= 7u << 16;  // closure 0's basis id 7 of 1 basis
  EXPECT_THROW(unpackMaterial(bad.data(), bad.size(), 0u), std::runtime_error);
}

}  // namespace pack_test
}  // namespace substratec
