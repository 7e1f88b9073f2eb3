// The volumetric fog cloud BSDF's runtime (runtime_shaders/substrate_fog_cloud.h)
// through its CPU mirror in double (reference/fog_cloud.h): the RGB9E5 words of
// the froxel payload (GL_EXT_texture_shared_exponent's encoding), the payload,
// the sample's sanitizing, Hillaire 2015's step (exact for constant
// coefficients, convergent for varying ones), the Henyey-Greenstein phase; and
// that the shader header compiles and validates in GLSL and HLSL.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "reference/fog_cloud.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec {
namespace fog_cloud_test {

using reference::FogCloudSample;
using D3 = std::array<double, 3>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

double maxOf(const D3& v) { return std::max(v[0], std::max(v[1], v[2])); }

bool finite3(const D3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

/// RGB9E5's error bound: half a step of the shared exponent, which is 2^-9 of
/// the larger of the input's and the decoded largest channel (the decoded one
/// when the exponent was bumped), and at least 2^-25 (the smallest step).
double rgb9e5Bound(const D3& in, const D3& decoded) {
  return std::max(std::ldexp(std::max(maxOf(in), maxOf(decoded)), -9), std::ldexp(1.0, -25));
}

/// A colour with channels log-uniform over [lo, hi].
D3 logUniformColour(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return {std::exp(u(rng)), std::exp(u(rng)), std::exp(u(rng))};
}

// ---------------------------------------------------------------------------
// RGB9E5

TEST(FogCloudRgb9e5, RoundTripsRandomColoursWithinHalfAStep) {
  std::mt19937_64 rng(20150806);
  constexpr int kCases = 20000;
  double worstRelative = 0;  // of the input's largest channel, over colours >= 2^-15
  for (int i = 0; i < kCases; ++i) {
    const D3 c = logUniformColour(rng, 1e-6, 6e4);
    const D3 d = reference::rgb9e5Decode(reference::rgb9e5Encode(c));
    for (int k = 0; k < 3; ++k) {
      const double err = std::abs(d[k] - c[k]);
      ASSERT_LE(err, rgb9e5Bound(c, d)) << "case " << i << " channel " << k << ": " << c[k] << " -> " << d[k];
      if (maxOf(c) >= std::ldexp(1.0, -15)) worstRelative = std::max(worstRelative, err / maxOf(c));
    }
  }
  std::printf("RGB9E5: %d random colours over [1e-6, 6e4]; worst error %.6g of the largest channel (2^-9 = %.6g)\n",
              kCases, worstRelative, std::ldexp(1.0, -9));
  EXPECT_LE(worstRelative, 1.0 / 511.5);  // 2^-9 of the decoded maximum when the exponent is bumped
}

TEST(FogCloudRgb9e5, ZeroIsZeroAndNaNOrNegativeEncodeAsZero) {
  EXPECT_EQ(reference::rgb9e5Encode({0, 0, 0}), 0u);
  EXPECT_EQ(reference::rgb9e5Decode(0u), (D3{0, 0, 0}));
  EXPECT_EQ(reference::rgb9e5Encode({kNaN, -1, -kInf}), 0u);
}

TEST(FogCloudRgb9e5, ClampsAbove65408) {
  // 65408 = (511 / 512) 2^16: mantissa 511, exponent 31.
  EXPECT_EQ(reference::rgb9e5Encode({65408, 0, 0}), 0xF80001FFu);
  const D3 d = reference::rgb9e5Decode(reference::rgb9e5Encode({1e5, kInf, 7e4}));
  EXPECT_EQ(d, (D3{65408, 65408, 65408}));
  EXPECT_EQ(reference::rgb9e5Decode(reference::rgb9e5Encode({1e30, 1, 0}))[0], 65408.0);
}

TEST(FogCloudRgb9e5, MatchesHandComputedEncodings) {
  // (1, 1, 1): floor(log2 1) = 0, exponent 0 + 1 + 15 = 16, step 2^(16-24), mantissas 256.
  EXPECT_EQ(reference::rgb9e5Encode({1, 1, 1}), 256u | 256u << 9 | 256u << 18 | 16u << 27);
  EXPECT_EQ(reference::rgb9e5Encode({1, 1, 1}), 0x84020100u);
  // (0.5, 0, 0): exponent 15, step 2^-9, r = 256.
  EXPECT_EQ(reference::rgb9e5Encode({0.5, 0, 0}), 0x78000100u);
  // A tie rounds up: g = 0.5 steps -> 1.
  EXPECT_EQ(reference::rgb9e5Encode({1, std::ldexp(0.5, -8), 0}), 0x80000300u);
  // 511.75 steps of 2^-8 round to 512: the exponent is bumped to 17, r = 256 (2.0).
  EXPECT_EQ(reference::rgb9e5Encode({511.75 / 256, 0, 0}), 256u | 17u << 27);
  EXPECT_EQ(reference::rgb9e5Decode(256u | 17u << 27), (D3{2, 0, 0}));
  // Below 2^-16 the exponent stays 0 (step 2^-24).
  EXPECT_EQ(reference::rgb9e5Encode({std::ldexp(3.0, -24), 0, 0}), 3u);
}

TEST(FogCloudRgb9e5, RepresentableValuesRoundTripExactly) {
  // Every word the encoder can produce: exponent e, the largest mantissa >= 256 (or e = 0).
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::uint32_t> mant(0, 511), exp(0, 31), hi(256, 511), which(0, 2);
  int exercised = 0;
  for (int i = 0; i < 10000; ++i) {
    std::array<std::uint32_t, 3> m = {mant(rng), mant(rng), mant(rng)};
    const std::uint32_t e = exp(rng);
    if (e > 0) m[which(rng)] = std::max(m[0], std::max(m[1], std::max(m[2], hi(rng))));
    const std::uint32_t w = m[0] | m[1] << 9 | m[2] << 18 | e << 27;
    const D3 v = reference::rgb9e5Decode(w);
    ASSERT_EQ(reference::rgb9e5Encode(v), w) << std::hex << w;
    ASSERT_EQ(reference::rgb9e5Decode(reference::rgb9e5Encode(v)), v);
    ++exercised;
  }
  EXPECT_EQ(exercised, 10000);
}

// ---------------------------------------------------------------------------
// The sample and its payload

TEST(FogCloudPayload, PacksAlbedoAndAoInUnorm8AndCoefficientsInRgb9e5) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0, 1);
  for (int i = 0; i < 5000; ++i) {
    const FogCloudSample s = reference::fogCloudMake({unit(rng), unit(rng), unit(rng)}, logUniformColour(rng, 1e-4, 6e4),
                                                     logUniformColour(rng, 1e-6, 1e3), unit(rng));
    const FogCloudSample u = reference::fogCloudUnpack(reference::fogCloudPack(s));
    for (int k = 0; k < 3; ++k) {
      ASSERT_LE(std::abs(u.albedo[k] - s.albedo[k]), 0.5 / 255 + 1e-12) << i;
      ASSERT_LE(std::abs(u.extinction[k] - s.extinction[k]), rgb9e5Bound(s.extinction, u.extinction)) << i;
      ASSERT_LE(std::abs(u.emissive[k] - s.emissive[k]), rgb9e5Bound(s.emissive, u.emissive)) << i;
    }
    ASSERT_LE(std::abs(u.ambientOcclusion - s.ambientOcclusion), 0.5 / 255 + 1e-12) << i;
  }
}

TEST(FogCloudPayload, LayoutOfTheFirstWord) {
  // albedo r bits 0-7, g 8-15, b 16-23, ao 24-31; the two others RGB9E5.
  const FogCloudSample s = reference::fogCloudMake({1, 0, 0.5}, {1, 1, 1}, {0.5, 0, 0}, 0.2);
  const auto w = reference::fogCloudPack(s);
  EXPECT_EQ(w[0], 0xFFu | 0x00u << 8 | 128u << 16 | 51u << 24);
  EXPECT_EQ(w[1], 0x84020100u);
  EXPECT_EQ(w[2], 0x78000100u);
}

TEST(FogCloudMake, SanitizesNaNInfinityAndNegatives) {
  const FogCloudSample s = reference::fogCloudMake({kNaN, kInf, -1}, {kNaN, kInf, -kInf}, {-3, kNaN, 1e9}, kNaN);
  EXPECT_EQ(s.albedo, (D3{0, 1, 0}));
  EXPECT_EQ(s.extinction, (D3{0, 65408, 0}));
  EXPECT_EQ(s.emissive, (D3{0, 0, 65408}));
  EXPECT_EQ(s.ambientOcclusion, 0);
  EXPECT_EQ(reference::fogCloudMake({2, 0.5, 0}, {0, 3, 0}, {0, 0, 0}, 7).albedo, (D3{1, 0.5, 0}));
  EXPECT_EQ(reference::fogCloudMake({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, -kInf).ambientOcclusion, 0);
  EXPECT_EQ(reference::fogCloudMake({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, kInf).ambientOcclusion, 1);
}

// ---------------------------------------------------------------------------
// The step (Hillaire 2015)

const D3 kInScattered = {1.0, 2.0, 3.0};
const D3 kAmbient = {0.5, 0.25, 0.125};

FogCloudSample homogeneous() {
  return reference::fogCloudMake({0.8, 0.5, 0.2}, {0.5, 2.0, 10.0}, {0.1, 0.0, 1.0}, 0.7);
}

/// The source term S = albedo sigma_t (inScattered + ambient ao) + emissive.
D3 source(const FogCloudSample& s) {
  D3 S;
  for (int k = 0; k < 3; ++k)
    S[k] = s.albedo[k] * s.extinction[k] * (kInScattered[k] + kAmbient[k] * s.ambientOcclusion) + s.emissive[k];
  return S;
}

TEST(FogCloudStep, HomogeneousMediumIsExactAtAnyStepCount) {
  const FogCloudSample s = homogeneous();
  const double L = 3.0;
  const D3 S = source(s);
  for (int steps : {1, 7, 64}) {
    SCOPED_TRACE(steps);
    const auto m = reference::marchFogCloud([&](const D3&) { return s; }, {0, 0, 0}, {0, 0, 1}, L, steps, kInScattered,
                                            kAmbient);
    for (int k = 0; k < 3; ++k) {
      const double T = std::exp(-s.extinction[k] * L);
      EXPECT_NEAR(m.throughput[k], T, 1e-14 * std::max(T, 1e-300) + 1e-300);
      const double closed = S[k] * (1 - T) / s.extinction[k];
      EXPECT_NEAR(m.radiance[k], closed, 1e-12 * closed);
    }
  }
}

TEST(FogCloudStep, NoExtinctionGivesSourceTimesLength) {
  FogCloudSample s = homogeneous();
  s.extinction = {0, 0, 0};
  for (int steps : {1, 7, 64}) {
    const auto m = reference::marchFogCloud([&](const D3&) { return s; }, {0, 0, 0}, {1, 0, 0}, 2.5, steps,
                                            kInScattered, kAmbient);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(m.radiance[k], s.emissive[k] * 2.5, 1e-14) << steps;  // S = emissive when sigma_t = 0
      EXPECT_EQ(m.throughput[k], 1.0);
    }
  }
}

TEST(FogCloudStep, ThinStepsUseTheSeriesAndMeetTheExactFactor) {
  // Just below and above sigma_t ds = 1e-2, the series 1 - tau/2 + tau^2/6 and
  // (1 - exp) / sigma_t agree: the series' relative error is tau^3 / 24 (4.2e-8 at the threshold).
  FogCloudSample s = homogeneous();
  for (double tau : {0.99e-2, 1.01e-2, 1e-4, 1e-7}) {
    s.extinction = {tau, tau, tau};
    D3 r = {0, 0, 0}, t = {1, 1, 1};
    reference::fogCloudStep(s, 1.0, kInScattered, kAmbient, r, t);
    const D3 S = source(s);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(r[k], S[k] * -std::expm1(-tau) / tau, (1.01 * tau * tau * tau / 24 + 1e-15) * S[k]) << tau;
  }
}

TEST(FogCloudStep, HugeExtinctionIsOpaqueAndFinite) {
  FogCloudSample s = homogeneous();
  s.extinction = {1e30, kInf, kNaN};  // not made by fogCloudMake: the step sanitizes it too
  D3 r = {0, 0, 0}, t = {1, 1, 1};
  reference::fogCloudStep(s, 1.0, kInScattered, kAmbient, r, t);
  EXPECT_TRUE(finite3(r));
  EXPECT_EQ(t[0], 0.0);
  EXPECT_EQ(t[1], 0.0);
  EXPECT_EQ(t[2], 1.0);  // NaN extinction reads 0
  // An opaque step returns the single-scattering albedo times the light, plus emissive / sigma_t.
  EXPECT_NEAR(r[0], 0.8 * (1.0 + 0.5 * 0.7) + 0.1 / 65408, 1e-12);
}

TEST(FogCloudStep, ZeroStepChangesNothingAndNoInputGivesNaNOrInf) {
  const FogCloudSample s = homogeneous();
  D3 r = {0.25, 0.5, 0.75}, t = {0.9, 0.8, 0.7};
  reference::fogCloudStep(s, 0.0, kInScattered, kAmbient, r, t);
  EXPECT_EQ(r, (D3{0.25, 0.5, 0.75}));
  EXPECT_EQ(t, (D3{0.9, 0.8, 0.7}));
  for (double ds : {kNaN, -1.0, kInf, 1e300, 1e-300})
    for (double light : {kNaN, kInf, -kInf, 1e300, 0.0}) {
      FogCloudSample bad = s;
      bad.emissive = {kInf, kNaN, 1e300};
      bad.albedo = {kNaN, 2, -1};
      D3 rr = {kNaN, kInf, 1}, tt = {1, kNaN, kInf};
      reference::fogCloudStep(bad, ds, {light, light, light}, {light, 0, 1}, rr, tt);
      EXPECT_TRUE(finite3(rr) && finite3(tt)) << ds << " " << light;
    }
}

TEST(FogCloudStep, ScatteringIsEnergyConservingForAnyMedium) {
  // Hillaire's point: with no emission, the in-scattered radiance of a march
  // is albedo L (1 - throughput) whatever the medium does within the steps
  // (to the thin-step series' truncation, tau^4 / 24 a step: the transmittance
  // stays Beer-Lambert's exp).
  const auto medium = [](const D3& p) {
    return reference::fogCloudMake({0.6, 0.6, 0.6}, {0.1 + 3 * p[2] * p[2], 5 * std::abs(std::sin(4 * p[2])), 1.0},
                                   {0, 0, 0}, 1.0);
  };
  for (int steps : {1, 3, 50}) {
    const auto m = reference::marchFogCloud(medium, {0, 0, 0}, {0, 0, 1}, 2.0, steps, {1, 1, 1}, {0, 0, 0});
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.radiance[k], 0.6 * (1 - m.throughput[k]), 1e-9) << steps;
  }
}

// A medium whose extinction grows linearly along the ray, sigma(t) = a + b t
// (a, b per channel), with constant albedo, light and emission: its radiance
// is albedo L (1 - T(len)) + e sqrt(pi / 2b) exp(a^2 / 2b)
// (erfc(a / sqrt 2b) - erfc((a + b len) / sqrt 2b)), T(t) = exp(-(a t + b t^2 / 2)).
constexpr D3 kA = {0.1, 0.5, 2.0}, kB = {0.2, 1.0, 0.5};
constexpr double kLength = 4.0, kAlbedo = 0.7, kEmissive = 0.3;

D3 linearMediumClosedForm(D3& throughput) {
  D3 r;
  for (int k = 0; k < 3; ++k) {
    const double a = kA[k], b = kB[k], q = std::sqrt(2 * b);
    throughput[k] = std::exp(-(a * kLength + 0.5 * b * kLength * kLength));
    const double emitted = std::sqrt(std::numbers::pi / (2 * b)) * std::exp(a * a / (2 * b)) *
                           (std::erfc(a / q) - std::erfc((a + b * kLength) / q));
    r[k] = kAlbedo * kInScattered[k] * (1 - throughput[k]) + kEmissive * emitted;
  }
  return r;
}

double linearMediumError(int steps) {
  const auto medium = [](const D3& p) {
    const double t = p[2];
    return reference::fogCloudMake({kAlbedo, kAlbedo, kAlbedo}, {kA[0] + kB[0] * t, kA[1] + kB[1] * t, kA[2] + kB[2] * t},
                                   {kEmissive, kEmissive, kEmissive}, 1.0);
  };
  const auto m = reference::marchFogCloud(medium, {0, 0, 0}, {0, 0, 1}, kLength, steps, kInScattered, {0, 0, 0});
  D3 T;
  const D3 closed = linearMediumClosedForm(T);
  double err = 0;
  for (int k = 0; k < 3; ++k) {
    err = std::max(err, std::abs(m.radiance[k] - closed[k]) / closed[k]);
    EXPECT_NEAR(m.throughput[k], T[k], 1e-13 * T[k]);  // the midpoint integrates a linear sigma exactly
  }
  return err;
}

TEST(FogCloudStep, HeterogeneousMediumConvergesToTheClosedForm) {
  double previous = 0;
  for (int steps = 1; steps <= 1024; steps *= 2) {
    const double e = linearMediumError(steps);
    std::printf("linear extinction, %4d steps: worst relative radiance error %.3e\n", steps, e);
    if (steps > 1) EXPECT_LT(e, previous) << steps;
    previous = e;
  }
  const double e8 = linearMediumError(8), e64 = linearMediumError(64);
  EXPECT_LT(e64, e8);
  EXPECT_GT(e8 / e64, 40.0);  // second order: 64x fewer error for 8x the steps
  EXPECT_LT(e64, 6e-5);       // measured 5.15e-5 (3.25e-3 at 8 steps, 2.0e-7 at 1024)
}

// ---------------------------------------------------------------------------
// Henyey-Greenstein

/// 2 pi times the integral of p over cos in [-1, 1]: panels graded geometrically
/// toward cos = 1 (the forward peak, (1 - g)^2 wide) and toward -1, 8-point
/// Gauss-Legendre each.
double hgSphereIntegral(double g) {
  static constexpr double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static constexpr double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  const auto panel = [&](double lo, double hi) {
    const double c = 0.5 * (lo + hi), h = 0.5 * (hi - lo);
    double s = 0;
    for (int i = 0; i < 4; ++i) s += w[i] * (reference::hgPhase(c + h * x[i], g) + reference::hgPhase(c - h * x[i], g));
    return s * h;
  };
  double sum = 0;
  // distance from +1: [0, 1e-8], then doubling to 1; same from -1.
  for (int side : {1, -1}) {
    double d0 = 0, d1 = 1e-8;
    for (int guard = 0; guard < 64 && d0 < 1.0; ++guard) {
      const double a = side * (1 - std::min(d1, 1.0)), b = side * (1 - d0);
      sum += panel(std::min(a, b), std::max(a, b));
      d0 = std::min(d1, 1.0);
      d1 *= 2;
    }
  }
  return 2 * std::numbers::pi * sum;
}

TEST(FogCloudPhase, HenyeyGreensteinIntegratesToOne) {
  for (double g : {-0.9, 0.0, 0.5, 0.99}) EXPECT_NEAR(hgSphereIntegral(g), 1.0, 1e-9) << g;
  EXPECT_NEAR(reference::hgPhase(0.3, 0.0), 1 / (4 * std::numbers::pi), 1e-15);
  EXPECT_GT(reference::hgPhase(1.0, 0.5), reference::hgPhase(-1.0, 0.5));  // forward scattering
  // g = +-1 is clamped to +-0.99 (still normalized); NaN inputs stay finite.
  EXPECT_EQ(reference::hgPhase(1.0, 1.0), reference::hgPhase(1.0, 0.99));
  EXPECT_NEAR(hgSphereIntegral(-5.0), 1.0, 1e-9);
  EXPECT_TRUE(std::isfinite(reference::hgPhase(kNaN, kNaN)));
  EXPECT_TRUE(std::isfinite(reference::hgPhase(2.0, -kInf)));
}

// ---------------------------------------------------------------------------
// The shader compiles

constexpr const char* kGlslFog = R"(#version 450
#include "substrate_prelude.glsl"
#include "substrate_fog_cloud.h"
layout(local_size_x = 8, local_size_y = 1) in;
layout(set = 0, binding = 0, std430) buffer Io { vec4 v[]; } io;
layout(set = 0, binding = 1, std430) buffer Words { uint w[]; } words;
void main() {
  uint i = gl_GlobalInvocationID.x;
  SubstrateFogCloudSample s = substrate_fog_cloud_make(io.v[i].xyz, io.v[i + 1u].xyz, io.v[i + 2u].xyz, io.v[i].w);
  uint p[3];
  substrate_fog_cloud_pack(s, p);
  for (uint k = 0u; k < 3u; ++k) words.w[3u * i + k] = p[k];
  SubstrateFogCloudSample u = substrate_fog_cloud_unpack(p[0], p[1], p[2]);
  vec3 radiance = vec3(0.0);
  vec3 throughput = vec3(1.0);
  float phase = substrate_fog_hg_phase(io.v[i + 3u].x, io.v[i + 3u].y);
  substrate_fog_cloud_step(u, io.v[i + 3u].z, io.v[i + 4u].xyz * phase, io.v[i + 5u].xyz, radiance, throughput);
  io.v[i + 6u] = vec4(radiance + substrate_rgb9e5_decode(substrate_rgb9e5_encode(io.v[i + 7u].xyz)), throughput.x);
}
)";

constexpr const char* kHlslFog = R"(#include "substrate_prelude.hlsl"
#include "substrate_fog_cloud.h"
[[vk::binding(0, 0)]] RWStructuredBuffer<float4> v;
[[vk::binding(1, 0)]] RWStructuredBuffer<uint> words;
[numthreads(8, 1, 1)]
void main(uint3 dispatchId : SV_DispatchThreadID) {
  uint i = dispatchId.x;
  SubstrateFogCloudSample s = substrate_fog_cloud_make(v[i].xyz, v[i + 1u].xyz, v[i + 2u].xyz, v[i].w);
  uint p[3];
  substrate_fog_cloud_pack(s, p);
  for (uint k = 0u; k < 3u; ++k) words[3u * i + k] = p[k];
  SubstrateFogCloudSample u = substrate_fog_cloud_unpack(p[0], p[1], p[2]);
  float3 radiance = float3(0.0, 0.0, 0.0);
  float3 throughput = float3(1.0, 1.0, 1.0);
  float phase = substrate_fog_hg_phase(v[i + 3u].x, v[i + 3u].y);
  substrate_fog_cloud_step(u, v[i + 3u].z, v[i + 4u].xyz * phase, v[i + 5u].xyz, radiance, throughput);
  v[i + 6u] = float4(radiance + substrate_rgb9e5_decode(substrate_rgb9e5_encode(v[i + 7u].xyz)), throughput.x);
}
)";

TEST(FogCloudShader, CompilesAndValidatesInGlslAndHlsl) {
  for (ShaderLanguage language : {ShaderLanguage::Glsl, ShaderLanguage::Hlsl}) {
    ShaderSource src;
    src.language = language;
    src.stage = ShaderStage::Compute;
    src.name = language == ShaderLanguage::Glsl ? "fog.comp" : "fog.cs.hlsl";
    src.text = language == ShaderLanguage::Glsl ? kGlslFog : kHlslFog;
    for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
    ASSERT_TRUE(src.memoryFiles.count("substrate_fog_cloud.h")) << "the header is not embedded";
    const ShaderValidation v = compileAndValidate(src);
    EXPECT_TRUE(v.ok) << src.name << "\n" << v.log;
  }
}

}  // namespace fog_cloud_test
}  // namespace substratec
