// Pack/unpack bounds (issue 7, "Numerical stability on hard cases"): every
// field quantizer of compiler/core/storage/pack.h, swept over its whole range — every
// code, both sides of every code boundary (which move with the dither), 0 and 1
// — under every dither in {0, 0.25, 0.5, 0.999999}, comes back within the bound
// of docs/storage.md's field table; and the octahedral normals of both
// precisions the table lists (basis normal 2 x snorm16, top-layer word
// 2 x unorm12) are finite, unit and within their angular bound exactly at the
// octahedral poles, seams and folds, -0.0 components included.
//
// These are the CPU quantizers; runtime_shaders/substrate_pack.h is their shader
// twin, function for function (quantizeUnorm = substrate_q_unorm, quantizeSnorm
// = substrate_q_snorm, quantizeColor = substrate_q_color20, quantizeMfp =
// substrate_q_mfp, octEncodeSnorm/Unorm = substrate_oct_encode(_unorm),
// encodeTangentAngle = substrate_tangent_angle_encode, packTopLayer =
// substrate_q_top_layer, and the decoders), checked bit for bit on lavapipe by
// tests/gpu/material_gpu_test.cc's deferred path (statistically, over 4,096
// samples per material). tests/unit/pack_test.cc checks random values; this
// file checks the edges.
#include <gtest/gtest.h>
#include <numbers>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "storage/pack.h"

namespace substratec {
namespace pack_bounds_test {

constexpr double kDithers[] = {0.0, 0.25, 0.5, 0.999999};
constexpr double kSlop = 1e-12;  // double rounding in the bound itself

// docs/storage.md, "Field table".
constexpr double kNormalBoundDeg = 0.0075;    // basis normal, octahedral 2 x snorm16
constexpr double kTopNormalBoundDeg = 0.119;  // top-layer word, octahedral 2 x unorm12
constexpr double kTangentBoundDeg = 0.022;    // tangent angle, unorm14
constexpr double kMfpBoundStops = 32.0 / 255;
constexpr double kMfpBoundRelative = 0.091;   // "relative 9.1 %"

/// The largest error / bound per field, printed at the end of each test (the
/// docs quote these figures).
class Worst {
 public:
  void add(const std::string& field, double error, double bound) {
    auto& [e, b] = worst_[field];
    if (error / bound > (b > 0 ? e / b : -1)) e = error, b = bound;
  }
  void print() const {
    for (const auto& [field, eb] : worst_)
      std::printf("[ bounds   ] %-28s worst error %.4g, bound %.4g (ratio %.4f)\n", field.c_str(), eb.first, eb.second,
                  eb.first / eb.second);
  }

 private:
  std::map<std::string, std::pair<double, double>> worst_;
};

/// x in [0, 1] values that exercise an n-bit field quantized as
/// floor(x (2^n - 1) + u): every code's value, and both sides of every code
/// boundary for this dither (x (2^n - 1) + u crossing an integer), plus 0 and 1.
std::vector<double> unitSweep(int bits, double u) {
  const double n = std::ldexp(1.0, bits) - 1;
  std::vector<double> xs = {0.0, 1.0, std::nextafter(0.0, 1.0), std::nextafter(1.0, 0.0)};
  for (int k = 0; k <= static_cast<int>(n) + 1; ++k) {
    const double code = k / n;
    const double edge = (k - u) / n;  // where floor(x n + u) steps from k - 1 to k
    for (double x : {code, edge}) {
      for (double d : {0.0, 1e-12, -1e-12, 1e-7 / n, -1e-7 / n}) {
        const double y = x + d;
        if (y >= 0 && y <= 1) xs.push_back(y);
      }
      if (x > 0 && x <= 1) xs.push_back(std::nextafter(x, 0.0));
      if (x >= 0 && x < 1) xs.push_back(std::nextafter(x, 1.0));
    }
  }
  return xs;
}

// ---------------------------------------------------------------------------
// Scalars

TEST(PackBounds, UnormFieldsComeBackWithinOneStep) {
  // roughness, weight, coverage above, second roughness, haze weight, glint
  // density, top roughness (8 bits); fuzz amount and roughness (6); the
  // tangent angle's unorm14: "1/(2^n - 1)" (one dithered step).
  Worst worst;
  for (int bits : {6, 8, 14}) {
    const double step = 1 / (std::ldexp(1.0, bits) - 1);
    const std::string field = "unorm" + std::to_string(bits);
    for (double u : kDithers)
      for (double x : unitSweep(bits, u)) {
        const std::uint32_t code = quantizeUnorm(x, bits, u);
        ASSERT_LT(code, 1u << bits) << x << " u=" << u;
        const double e = std::fabs(dequantizeUnorm(code, bits) - x);
        ASSERT_LE(e, step * (1 + kSlop)) << field << " x=" << x << " u=" << u;
        worst.add(field, e, step);
      }
    // The ends are exact codes at every dither.
    for (double u : kDithers) {
      EXPECT_EQ(dequantizeUnorm(quantizeUnorm(0.0, bits, u), bits), 0.0);
      EXPECT_EQ(dequantizeUnorm(quantizeUnorm(1.0, bits, u), bits), 1.0);
    }
  }
  worst.print();
}

TEST(PackBounds, SnormFieldsComeBackWithinOneStepAndZeroIsExact) {
  // anisotropy (snorm8, "1/127"), SSS phase (snorm4, "1/7").
  Worst worst;
  for (int bits : {4, 8, 16}) {
    const double s = std::ldexp(1.0, bits - 1) - 1;
    const std::string field = "snorm" + std::to_string(bits);
    for (double u : kDithers) {
      std::vector<double> xs = {-1.0, 1.0, 0.0, -0.0, std::nextafter(-1.0, 0.0), std::nextafter(1.0, 0.0)};
      for (int k = 0; k <= 2 * static_cast<int>(s) + 1; ++k)
        for (double x : {k / s - 1, (k - u) / s - 1})  // codes and boundaries of floor(s x + s + u)
          for (double d : {0.0, 1e-12, -1e-12, 1e-7 / s, -1e-7 / s})
            if (x + d >= -1 && x + d <= 1) xs.push_back(x + d);
      for (double x : xs) {
        const std::uint32_t code = quantizeSnorm(x, bits, u);
        ASSERT_LE(code, static_cast<std::uint32_t>(2 * s)) << x;
        const double e = std::fabs(dequantizeSnorm(code, bits) - x);
        ASSERT_LE(e, (1 / s) * (1 + kSlop)) << field << " x=" << x << " u=" << u;
        worst.add(field, e, 1 / s);
      }
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(0.0, bits, u), bits), 0.0) << u;
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(-0.0, bits, u), bits), 0.0) << u;
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(1.0, bits, u), bits), 1.0) << u;
      EXPECT_EQ(dequantizeSnorm(quantizeSnorm(-1.0, bits, u), bits), -1.0) << u;
    }
  }
  worst.print();
}

TEST(PackBounds, ColoursComeBackWithinOneStepOfTheSqrtCode) {
  // diffuse albedo, F0, F90, top transmittance, fuzz colour: per channel
  // |dc| <= 2 sqrt(c) q + q^2, q = 1/127 (r, g) and 1/63 (b).
  Worst worst;
  const char* names[] = {"colour.r", "colour.g", "colour.b"};
  for (int ch = 0; ch < 3; ++ch) {
    const int bits = ch < 2 ? 7 : 6;
    const double q = 1 / (std::ldexp(1.0, bits) - 1);
    for (double u : kDithers) {
      std::vector<double> cs;
      for (double s : unitSweep(bits, u)) cs.push_back(s * s);  // the boundaries live in the sqrt domain
      for (double c : {0.0, 1e-300, 1e-12, 1e-6, 1.0, std::nextafter(1.0, 0.0)}) cs.push_back(c);
      for (double c : cs) {
        Vec3d v{0.5, 0.5, 0.5};
        v[ch] = c;
        const Vec3d d = dequantizeColor(quantizeColor(v, u));
        const double bound = 2 * std::sqrt(c) * q + q * q;
        const double e = std::fabs(d[ch] - c);
        ASSERT_LE(e, bound * (1 + kSlop) + kSlop) << names[ch] << " c=" << c << " u=" << u;
        worst.add(names[ch], e, bound);
      }
    }
  }
  // The table's worst case over the whole range: 0.0158 (r, g), 0.0320 (b).
  for (double u : kDithers)
    for (int k = 0; k <= 4096; ++k) {
      const double c = k / 4096.0;
      const Vec3d d = dequantizeColor(quantizeColor({c, c, c}, u));
      EXPECT_LE(std::fabs(d[0] - c), 0.0158);
      EXPECT_LE(std::fabs(d[2] - c), 0.0320);
    }
  worst.print();
}

TEST(PackBounds, MfpComesBackWithinAnEighthOfAStopOverItsRange) {
  // "unorm8 of (log2(mfp) + 24) / 32, code 0 = no medium: 2^-24 m ... 2^8 m;
  // 32/255 stop (relative 9.1 %)".
  Worst worst;
  for (double u : kDithers) {
    std::vector<double> mfps;
    for (double t : unitSweep(8, u)) mfps.push_back(std::exp2(t * 32 - 24));
    for (double m : mfps) {
      if (!(m >= std::exp2(-24.0)) || !(m <= 256.0)) continue;
      const std::uint32_t code = quantizeMfp(m, u);
      ASSERT_GE(code, 1u) << "a medium never encodes as 'no medium': " << m;
      const double d = dequantizeMfp(code);
      const double stops = std::fabs(std::log2(d / m));
      ASSERT_LE(stops, kMfpBoundStops * (1 + 1e-9)) << "mfp=" << m << " u=" << u;
      ASSERT_LE(std::fabs(d / m - 1), kMfpBoundRelative) << "mfp=" << m << " u=" << u;
      worst.add("sss.mfp (stops)", stops, kMfpBoundStops);
      worst.add("sss.mfp (relative)", std::fabs(d / m - 1), kMfpBoundRelative);
    }
    EXPECT_EQ(quantizeMfp(0.0, u), 0u);
    EXPECT_EQ(dequantizeMfp(quantizeMfp(0.0, u)), 0.0);
    EXPECT_EQ(quantizeMfp(-0.0, u), 0u);
  }
  worst.print();
}

TEST(PackBounds, HalvesRoundToNearestWithinTheStatedBound) {
  // Glint derivatives: "2^-11 relative" — IEEE half, round to nearest even.
  // Below 2^-14 halves are subnormal: the bound there is absolute, half a unit
  // of 2^-24 (2^-25); beyond 65504 the encoder clamps (never infinite).
  Worst worst;
  for (std::uint32_t h = 0; h < 0x7c00u; ++h) {
    const double v = halfToFloat(static_cast<std::uint16_t>(h));
    const double next = halfToFloat(static_cast<std::uint16_t>(h + 1));
    const double mid = 0.5 * (v + next);
    std::vector<double> xs = {v};
    if (std::isfinite(next))  // 65504 is the last: its neighbour is +inf
      xs.insert(xs.end(), {mid, std::nextafter(mid, 0.0), std::nextafter(mid, 1e9), v + (next - v) * 1e-6,
                           next - (next - v) * 1e-6});
    for (double x : xs)
      for (double sign : {1.0, -1.0}) {
        const double y = sign * x;
        const double d = halfToFloat(floatToHalf(y));
        const double e = std::fabs(d - y);
        if (std::fabs(y) >= std::exp2(-14)) {
          // The encoder rounds the double to float first, then to half: the
          // double rounding can add one float ulp (2^-24 relative) at a tie.
          ASSERT_LE(e, std::fabs(y) * (std::exp2(-11) + std::exp2(-23))) << y;
          worst.add("glint.derivative (relative)", e / std::fabs(y), std::exp2(-11));
        } else {
          ASSERT_LE(e, std::exp2(-25) * (1 + 1e-6)) << y;
          worst.add("glint.derivative (subnormal)", e, std::exp2(-25));
        }
      }
  }
  EXPECT_EQ(halfToFloat(floatToHalf(1e30)), 65504.0);
  EXPECT_EQ(halfToFloat(floatToHalf(-1e30)), -65504.0);
  worst.print();
}

// ---------------------------------------------------------------------------
// Directions

double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3d normalize(const Vec3d& v) {
  const double l = std::sqrt(dot(v, v));
  return {v[0] / l, v[1] / l, v[2] / l};
}
double angleDeg(const Vec3d& a, const Vec3d& b) {
  const Vec3d c = cross(a, b);
  return std::atan2(std::sqrt(dot(c, c)), dot(a, b)) * 180.0 / std::numbers::pi;
}
bool finite(const Vec3d& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

/// The octahedral map's hard places: the poles and the axes (its corners), the
/// diagonals, the equator (the seam where the lower half folds over) from both
/// sides at 1e-7 and at ±0, the fold lines of the lower half (x = 0 or y = 0
/// with z < 0, where sign(p) flips) within 1e-6, and -0.0 in every component.
std::vector<Vec3d> seamNormals() {
  const double r2 = 1 / std::sqrt(2.0);
  std::vector<Vec3d> out;
  for (double s : {1.0, -1.0}) {
    out.push_back({s, 0, 0});
    out.push_back({0, s, 0});
    out.push_back({0, 0, s});
    out.push_back({s, -0.0, -0.0});
    out.push_back({-0.0, s, -0.0});
    out.push_back({-0.0, -0.0, s});
    out.push_back({s, 0.0, -0.0});
    out.push_back({-0.0, s, 0.0});
  }
  for (double a : {1.0, -1.0})
    for (double b : {1.0, -1.0}) {
      out.push_back({a * r2, b * r2, 0});
      out.push_back({a * r2, 0, b * r2});
      out.push_back({0, a * r2, b * r2});
      out.push_back({a * r2, b * r2, -0.0});
      out.push_back({a * r2, -0.0, b * r2});
      out.push_back({-0.0, a * r2, b * r2});
      // The equator from both sides, and at ±0.
      for (double z : {1e-7, -1e-7, 1e-6, -1e-6, 0.0, -0.0}) {
        out.push_back(normalize({a * 0.6, b * 0.8, z}));
        out.push_back(normalize({a * 1.0, b * 1e-6, z}));
        out.push_back(normalize({a * 1e-6, b * 1.0, z}));
        out.push_back(normalize({a * r2, b * r2, z}));
      }
      // The lower half's fold lines (x = 0 or y = 0, z < 0), within 1e-6 and at ±0.
      for (double e : {1e-6, 1e-7, 0.0, -0.0})
        for (double z : {-0.3, -0.8, -1e-6}) {
          out.push_back(normalize({a * e, b * 0.6, z}));
          out.push_back(normalize({b * 0.6, a * e, z}));
        }
      // Next to the poles.
      out.push_back(normalize({a * 1e-6, b * 1e-6, 1}));
      out.push_back(normalize({a * 1e-6, b * 1e-6, -1}));
      out.push_back(normalize({a * 1e-7, -0.0, -1}));
    }
  return out;
}

std::string str(const Vec3d& n) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", n[0], n[1], n[2]);
  return buf;
}

TEST(PackBounds, NormalsAtPolesSeamsAndFoldsDecodeUnitAndWithinTheirBound) {
  Worst worst;
  const auto normals = seamNormals();
  ASSERT_GT(normals.size(), 200u);
  for (double u : kDithers)
    for (const Vec3d& n : normals) {
      SCOPED_TRACE(str(n) + " u=" + std::to_string(u));
      // Basis normal: octahedral 2 x snorm16.
      const Vec3d a = dequantizeNormal(quantizeNormal(n, u));
      ASSERT_TRUE(finite(a));
      EXPECT_NEAR(std::sqrt(dot(a, a)), 1.0, 1e-6);
      EXPECT_LE(angleDeg(a, n), kNormalBoundDeg);
      worst.add("basis.normal (degrees)", angleDeg(a, n), kNormalBoundDeg);
      // Top-layer word: octahedral 2 x unorm12.
      const Vec3d b = unpackTopLayer(packTopLayer({n, 0.5}, u)).normal;
      ASSERT_TRUE(finite(b));
      EXPECT_NEAR(std::sqrt(dot(b, b)), 1.0, 1e-6);
      EXPECT_LE(angleDeg(b, n), kTopNormalBoundDeg);
      worst.add("top_layer.normal (degrees)", angleDeg(b, n), kTopNormalBoundDeg);
      // The generic encoders at the same precisions.
      const Vec3d c = octDecodeSnorm(octEncodeSnorm(n, 16, u), 16);
      const Vec3d d = octDecodeUnorm(octEncodeUnorm(n, 12, u), 12);
      EXPECT_EQ(c, a);
      EXPECT_EQ(d, b);
    }
  worst.print();
}

TEST(PackBounds, TangentAnglesAtPolesSeamsAndFoldsComeBackWithinTheirBound) {
  // The tangent angle is measured in the frame of the normal as decoded (the
  // Duff frame flips with the sign bit of z: -0 counts as negative).
  Worst worst;
  for (double u : kDithers)
    for (const Vec3d& n : seamNormals()) {
      for (bool top : {false, true}) {
        const Vec3d decoded = top ? unpackTopLayer(packTopLayer({n, 0.5}, u)).normal : dequantizeNormal(quantizeNormal(n, u));
        Vec3d t0, b0;
        orthonormalBasis(decoded, t0, b0);
        for (double angle : {0.0, 1e-7, std::numbers::pi / 2, std::numbers::pi, 1.5 * std::numbers::pi, 2 * std::numbers::pi - 1e-7, 2.0})
          for (double sign : {1.0, -1.0}) {
            // A unit tangent of the decoded normal at `angle` from its canonical one.
            const double a = sign * angle;
            const Vec3d t{std::cos(a) * t0[0] + std::sin(a) * b0[0], std::cos(a) * t0[1] + std::sin(a) * b0[1],
                          std::cos(a) * t0[2] + std::sin(a) * b0[2]};
            const std::uint32_t code = encodeTangentAngle(t, decoded, u);
            ASSERT_LT(code, 1u << 14);
            const Vec3d back = decodeTangentAngle(code, decoded);
            ASSERT_TRUE(finite(back)) << str(n);
            EXPECT_NEAR(std::sqrt(dot(back, back)), 1.0, 1e-6) << str(n);
            EXPECT_NEAR(dot(back, decoded), 0.0, 1e-9) << str(n);
            EXPECT_LE(angleDeg(back, t), kTangentBoundDeg) << str(n) << " angle " << a << " u=" << u;
            worst.add("basis.tangent (degrees)", angleDeg(back, t), kTangentBoundDeg);
          }
      }
    }
  worst.print();
}

TEST(PackBounds, NormalsOverTheWholeSphereStayWithinTheirBound) {
  // A dense deterministic sweep (a Fibonacci sphere of 200,000 points, each
  // also mirrored onto the lower half) at every dither: the table's worst case
  // (face centre, one dithered step on both coordinates).
  Worst worst;
  const int count = 200000;
  const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
  for (double u : kDithers)
    for (int i = 0; i < count; ++i) {
      const double z = 1 - (i + 0.5) * 2.0 / count;
      const double r = std::sqrt(std::max(0.0, 1 - z * z));
      const Vec3d n{r * std::cos(golden * i), r * std::sin(golden * i), z};
      const double ea = angleDeg(dequantizeNormal(quantizeNormal(n, u)), n);
      const double eb = angleDeg(unpackTopLayer(packTopLayer({n, 0.5}, u)).normal, n);
      ASSERT_LE(ea, kNormalBoundDeg) << str(n) << " u=" << u;
      ASSERT_LE(eb, kTopNormalBoundDeg) << str(n) << " u=" << u;
      worst.add("basis.normal (degrees)", ea, kNormalBoundDeg);
      worst.add("top_layer.normal (degrees)", eb, kTopNormalBoundDeg);
    }
  worst.print();
}

}  // namespace pack_bounds_test
}  // namespace substratec
