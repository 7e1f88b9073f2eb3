// The CPU side of `substratec preview` (compiler/tools/preview): procedural
// environments, the cube maps the runtime's split-sum lighting samples
// (runtime_shaders/substrate_lighting.h), tone mapping and sRGB encoding, PNG
// output, and labelled contact sheets.
#include <gtest/gtest.h>
#include <numbers>
#include <png.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <tuple>

#include "preview/contact_sheet.h"
#include "preview/cubemap.h"
#include "preview/environment.h"
#include "preview/image.h"

namespace substratec::preview {
namespace {

namespace fs = std::filesystem;
using Vec3 = std::array<double, 3>;

Vec3 normalized(Vec3 v) {
  double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / l, v[1] / l, v[2] / l};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double luminance(const Vec3& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

/// n directions spread evenly over the sphere (Fibonacci lattice).
std::vector<Vec3> sphereDirections(int n) {
  std::vector<Vec3> dirs;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    double y = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - y * y);
    dirs.push_back({r * std::cos(golden * i), y, r * std::sin(golden * i)});
  }
  return dirs;
}

/// An orthonormal frame (t, b) around the unit vector n.
void frame(const Vec3& n, Vec3& t, Vec3& b) {
  Vec3 a = std::abs(n[1]) < 0.9 ? Vec3{0, 1, 0} : Vec3{1, 0, 0};
  t = normalized({a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0]});
  b = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
}

/// Midpoint quadrature over the hemisphere around n of L(l) k(n.l) dl
/// (nt x 2 nt cells in (theta, phi), those near the environment's hotspots
/// subdivided 48 x 48), and of k.
Vec3 hemisphereIntegral(const Environment& env, const Vec3& n, double (*kernel)(double cosTheta, double param),
                        double param, double* kernelIntegral, int nt) {
  Vec3 t, b;
  frame(n, t, b);
  const int np = 2 * nt;
  const double dt = (std::numbers::pi / 2) / nt, dp = 2 * std::numbers::pi / np;
  Vec3 sum{0, 0, 0};
  double ksum = 0.0;
  auto direction = [&](double theta, double phi) {
    Vec3 l;
    for (int c = 0; c < 3; ++c)
      l[c] = std::sin(theta) * (std::cos(phi) * t[c] + std::sin(phi) * b[c]) + std::cos(theta) * n[c];
    return l;
  };
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      Vec3 l = direction((i + 0.5) * dt, (j + 0.5) * dp);
      bool nearHotspot = false;
      for (const Hotspot& h : env.hotspots())
        nearHotspot |= std::acos(std::min(1.0, dot(l, h.direction))) < h.angularRadius + 2 * std::numbers::pi / 180;
      const int sub = nearHotspot ? 48 : 1;
      for (int a = 0; a < sub; ++a)
        for (int c = 0; c < sub; ++c) {
          double theta = (i + (a + 0.5) / sub) * dt, phi = (j + (c + 0.5) / sub) * dp;
          double k = kernel(std::cos(theta), param) * std::sin(theta) * dt * dp / (sub * sub);
          Vec3 L = env.radiance(direction(theta, phi));
          for (int ch = 0; ch < 3; ++ch) sum[ch] += L[ch] * k;
          ksum += k;
        }
    }
  if (kernelIntegral) *kernelIntegral = ksum;
  return sum;
}

double cosineKernel(double ct, double) { return ct; }
/// The split-sum prefilter kernel for N = V: D(NoH) / 4 (the pdf of l) times NoL.
double ggxKernel(double ct, double alpha) {
  double noh = std::sqrt((1.0 + ct) / 2.0), a2 = alpha * alpha;
  double d = (a2 - 1.0) * noh * noh + 1.0;
  return a2 / (std::numbers::pi * d * d) / 4.0 * ct;
}

// ---------------------------------------------------------------------------
// Environments.

TEST(PreviewEnvironment, NamesStartWithTheDefaultStudio) {
  std::vector<std::string> names = environmentNames();
  ASSERT_GE(names.size(), 3u);
  EXPECT_EQ(names[0], kDefaultEnvironment);
  EXPECT_EQ(names[0], "studio");
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), (std::set<std::string>{"studio", "sky", "white"}));
  for (const std::string& n : names) EXPECT_EQ(makeEnvironment(n).name(), n);
}

TEST(PreviewEnvironment, RadianceIsFiniteAndNonNegativeEverywhere) {
  std::vector<Vec3> dirs = sphereDirections(20000);
  for (Vec3 pole : {Vec3{0, 1, 0}, Vec3{0, -1, 0}, Vec3{1, 0, 0}, Vec3{-1, 0, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}})
    dirs.push_back(pole);
  // The sun's centre and rings around it out to beyond its disc.
  Vec3 sun = skySunDirection(), t, b;
  frame(sun, t, b);
  dirs.push_back(sun);
  for (double a = 0.1; a <= 3.0; a += 0.1)
    for (int k = 0; k < 16; ++k) {
      double ang = a * skySunAngularRadius(), phi = 2 * std::numbers::pi * k / 16;
      Vec3 d;
      for (int c = 0; c < 3; ++c)
        d[c] = std::cos(ang) * sun[c] + std::sin(ang) * (std::cos(phi) * t[c] + std::sin(phi) * b[c]);
      dirs.push_back(d);
    }
  for (const std::string& name : environmentNames()) {
    Environment env = makeEnvironment(name);
    for (const Vec3& d : dirs) {
      Vec3 L = env.radiance(d);
      for (double c : L) {
        ASSERT_TRUE(std::isfinite(c)) << name << " at (" << d[0] << ", " << d[1] << ", " << d[2] << ")";
        ASSERT_GE(c, 0.0) << name << " at (" << d[0] << ", " << d[1] << ", " << d[2] << ")";
      }
    }
  }
}

TEST(PreviewEnvironment, WhiteIsOneEverywhere) {
  Environment env = makeEnvironment("white");
  for (const Vec3& d : sphereDirections(1000)) EXPECT_EQ(env.radiance(d), (Vec3{1, 1, 1}));
}

TEST(PreviewEnvironment, SkyHasASmallBrightFiniteSunAboveTheHorizon) {
  Environment env = makeEnvironment("sky");
  Vec3 sun = skySunDirection();
  EXPECT_GT(sun[1], 0.0);
  EXPECT_NEAR(skySunAngularRadius() * 2 * 180 / std::numbers::pi, 0.5, 1e-9);  // a 0.5 degree disc
  double centre = luminance(env.radiance(sun));
  EXPECT_GT(centre, 1e3);
  EXPECT_LT(centre, 1e4);
  // One degree off the sun: sky and aureole only.
  Vec3 t, b;
  frame(sun, t, b);
  double off = std::numbers::pi / 180;
  Vec3 d;
  for (int c = 0; c < 3; ++c) d[c] = std::cos(off) * sun[c] + std::sin(off) * t[c];
  EXPECT_LT(luminance(env.radiance(d)), 10.0);
  // Zenith blue, hazy (whiter, brighter) horizon, darker ground.
  Vec3 zenith = env.radiance({0, 1, 0}), horizon = env.radiance(normalized({0, 0.01, -1}));
  Vec3 ground = env.radiance({0, -1, 0});
  EXPECT_GT(zenith[2], 1.5 * zenith[0]);
  EXPECT_GT(luminance(horizon), luminance(zenith));
  EXPECT_LT(luminance(ground), 0.5 * luminance(zenith));
}

TEST(PreviewEnvironment, StudioIsADarkRoomWithBrightSoftBoxes) {
  Environment env = makeEnvironment("studio");
  std::vector<double> lum;
  double maxLum = 0.0;
  for (const Vec3& d : sphereDirections(20000)) {
    lum.push_back(luminance(env.radiance(d)));
    maxLum = std::max(maxLum, lum.back());
  }
  std::nth_element(lum.begin(), lum.begin() + lum.size() / 2, lum.end());
  EXPECT_LT(lum[lum.size() / 2], 0.2);  // the background is dark grey
  EXPECT_GE(maxLum, 5.0);               // the boxes are bright ...
  EXPECT_LE(maxLum, 25.0);              // ... but not a sun
  // The floor bounces light: straight down is brighter than the walls.
  EXPECT_GT(luminance(env.radiance({0, -1, 0})), 2.0 * luminance(env.radiance(normalized({0, 0.05, -1}))));
}

TEST(PreviewEnvironment, UnknownNameIsAnErrorListingTheNames) {
  try {
    makeEnvironment("beach");
    FAIL() << "no error for an unknown environment";
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    EXPECT_NE(what.find("beach"), std::string::npos) << what;
    for (const std::string& n : environmentNames()) EXPECT_NE(what.find(n), std::string::npos) << what;
  }
}

// ---------------------------------------------------------------------------
// Cube conventions (Vulkan spec, "Cube map face selection").

TEST(PreviewCube, FaceCentresPointAlongTheirAxes) {
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (int f = 0; f < 6; ++f) {
    Vec3 d = cubeDirection(f, 0.5, 0.5);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(d[c], axes[f][c], 1e-15) << "face " << f;
  }
}

TEST(PreviewCube, CornersFollowTheVulkanFaceTable) {
  // (s, t) = (0, 0) is (sc, tc) = (-1, -1); the table's sc/tc per face.
  auto expectDir = [](int face, double s, double t, Vec3 want) {
    Vec3 d = cubeDirection(face, s, t);
    want = normalized(want);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(d[c], want[c], 1e-12) << "face " << face << " s " << s << " t " << t;
  };
  expectDir(0, 0, 0, {1, 1, 1});     // +X: sc = -rz, tc = -ry
  expectDir(1, 0, 0, {-1, 1, -1});   // -X: sc = +rz, tc = -ry
  expectDir(2, 0, 0, {-1, 1, -1});   // +Y: sc = +rx, tc = +rz
  expectDir(3, 0, 0, {-1, -1, 1});   // -Y: sc = +rx, tc = -rz
  expectDir(4, 0, 0, {-1, 1, 1});    // +Z: sc = +rx, tc = -ry
  expectDir(5, 0, 0, {1, 1, -1});    // -Z: sc = -rx, tc = -ry
  expectDir(4, 1, 0.5, {1, 0, 1});   // s grows to the right on +Z
  expectDir(4, 0.5, 1, {0, -1, 1});  // t grows downward (top row first)
}

TEST(PreviewCube, DirectionAndCoordinatesRoundTrip) {
  for (int f = 0; f < 6; ++f)
    for (double s = 0.01; s < 1.0; s += 0.07)
      for (double t = 0.02; t < 1.0; t += 0.09) {
        CubeCoord c = cubeCoord(cubeDirection(f, s, t));
        EXPECT_EQ(c.face, f);
        EXPECT_NEAR(c.s, s, 1e-12);
        EXPECT_NEAR(c.t, t, 1e-12);
      }
  for (const Vec3& d : sphereDirections(5000)) {
    CubeCoord c = cubeCoord({d[0] * 3, d[1] * 3, d[2] * 3});  // need not be unit
    ASSERT_GE(c.s, 0.0);
    ASSERT_LE(c.s, 1.0);
    ASSERT_GE(c.t, 0.0);
    ASSERT_LE(c.t, 1.0);
    Vec3 back = cubeDirection(c.face, c.s, c.t);
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(back[k], d[k], 1e-12);
  }
  EXPECT_THROW(cubeDirection(6, 0.5, 0.5), std::invalid_argument);
}

TEST(PreviewCube, TexelSolidAnglesCoverTheSphere) {
  for (int n : {1, 2, 7, 64}) {
    double sum = 0.0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) sum += texelSolidAngle(n, x, y);
    EXPECT_NEAR(6 * sum, 4 * std::numbers::pi, 1e-12) << n;
  }
  EXPECT_GT(texelSolidAngle(8, 4, 4), 2.5 * texelSolidAngle(8, 0, 0));  // centres are bigger than corners
}

TEST(PreviewCube, MipRoughnessInvertsSubstrateEnvMip) {
  // substrate_env_mip(r, mipCount) = saturate(r) * max(mipCount - 1, 0).
  auto envMip = [](double r, double mipCount) { return std::clamp(r, 0.0, 1.0) * std::max(mipCount - 1.0, 0.0); };
  for (int mips : {1, 2, 6, 8})
    for (int level = 0; level < mips; ++level)
      EXPECT_NEAR(envMip(mipRoughness(level, mips), mips), level, 1e-12) << mips << " mips";
  EXPECT_EQ(mipRoughness(0, 6), 0.0);
  EXPECT_EQ(mipRoughness(5, 6), 1.0);
}

// ---------------------------------------------------------------------------
// Prefiltered radiance and irradiance.

TEST(PreviewPrefilter, MipChainHasVulkanSizesAndLayout) {
  CubeMap m = prefilterRadiance(makeEnvironment("studio"), 48, 5, 8);
  EXPECT_EQ(m.size, 48);
  ASSERT_EQ(m.mipCount(), 5);
  const int sizes[] = {48, 24, 12, 6, 3};
  for (int l = 0; l < 5; ++l) {
    EXPECT_EQ(m.mipSize(l), sizes[l]);
    EXPECT_EQ(m.mips[l].size(), 6u * sizes[l] * sizes[l] * 4);
    for (size_t i = 3; i < m.mips[l].size(); i += 4) ASSERT_EQ(m.mips[l][i], 1.0f);  // alpha
  }
  EXPECT_THROW(prefilterRadiance(makeEnvironment("white"), 64, 8, 8), std::invalid_argument);  // 64 has 7 levels
  EXPECT_THROW(prefilterRadiance(makeEnvironment("white"), 0, 1, 8), std::invalid_argument);
  EXPECT_THROW(prefilterRadiance(makeEnvironment("white"), 64, 6, 0), std::invalid_argument);
  EXPECT_THROW(irradianceMap(makeEnvironment("white"), 0, 8), std::invalid_argument);
}

TEST(PreviewPrefilter, WhiteEnvironmentIsOneAtEveryMip) {
  // The default sizes, and 128 / 8 mips, where mip 1 is importance sampled.
  for (auto [size, mips] : {std::pair{64, 6}, std::pair{128, 8}}) {
    CubeMap m = prefilterRadiance(makeEnvironment("white"), size, mips, 64);
    ASSERT_EQ(m.mipCount(), mips);
    for (int l = 0; l < m.mipCount(); ++l)
      for (size_t i = 0; i < m.mips[l].size(); ++i)
        ASSERT_NEAR(m.mips[l][i], 1.0f, 1e-3) << size << "^2, mip " << l << " at " << i;
  }
}

TEST(PreviewPrefilter, WhiteIrradianceIsPi) {
  // substrate_env_split_sum takes E = integral of L cos (it divides by pi
  // itself), so a white environment must give pi, not 1.
  CubeMap m = irradianceMap(makeEnvironment("white"), 16, 32);
  ASSERT_EQ(m.mipCount(), 1);
  EXPECT_EQ(m.size, 16);
  for (size_t i = 0; i < m.mips[0].size(); ++i)
    ASSERT_NEAR(m.mips[0][i], i % 4 == 3 ? 1.0 : std::numbers::pi, 1e-3) << "at " << i;
}

TEST(PreviewPrefilter, MirrorMipReproducesTheSkyAtTexelCentres) {
  // Mip 0 is the texel average: within 1 % of the centre value where the sky
  // is smooth; in the horizon fade (the ground fades in over 0 > y > -0.15)
  // the curvature makes the two differ, and mip 0 must be the average.
  Environment env = makeEnvironment("sky");
  CubeMap m = prefilterRadiance(env, 64, 6, 16);
  const int n = m.mipSize(0), k = 16;
  double worst = 0.0;
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        Vec3 d = cubeDirection(f, (x + 0.5) / n, (y + 0.5) / n);
        if (std::acos(std::min(1.0, dot(d, skySunDirection()))) < 10 * std::numbers::pi / 180) continue;
        const bool horizon = std::abs(d[1]) < 0.17;
        Vec3 want = env.radiance(d);
        if (horizon) {
          want = {0, 0, 0};
          for (int j = 0; j < k; ++j)
            for (int i = 0; i < k; ++i) {
              Vec3 L = env.radiance(cubeDirection(f, (x + (i + 0.5) / k) / n, (y + (j + 0.5) / k) / n));
              for (int c = 0; c < 3; ++c) want[c] += L[c] / (k * k);
            }
        }
        const float* got = m.texel(0, f, x, y);
        for (int c = 0; c < 3; ++c) {
          double err = std::abs(got[c] - want[c]) / want[c];
          if (!horizon) worst = std::max(worst, err);
          ASSERT_LT(err, horizon ? 0.005 : 0.01) << "face " << f << " texel " << x << "," << y << " channel " << c;
        }
      }
  EXPECT_GT(worst, 0.0);  // the texel average is not a point sample
}

TEST(PreviewPrefilter, MirrorMipKeepsTheSunsEnergy) {
  // The sun is a fraction of a texel: its texels' averages must neither miss
  // nor inflate it. Reference: 96 x 96 samples per texel near the sun.
  Environment env = makeEnvironment("sky");
  CubeMap m = prefilterRadiance(env, 64, 1, 1);
  const int n = m.size, k = 96;
  double got = 0.0, ref = 0.0;
  int texels = 0;
  for (int f = 0; f < 6; ++f)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        Vec3 d = cubeDirection(f, (x + 0.5) / n, (y + 0.5) / n);
        if (std::acos(std::min(1.0, dot(d, skySunDirection()))) > 3 * std::numbers::pi / 180) continue;
        ++texels;
        double w = texelSolidAngle(n, x, y), sum = 0.0;
        for (int j = 0; j < k; ++j)
          for (int i = 0; i < k; ++i) sum += luminance(env.radiance(cubeDirection(f, (x + (i + 0.5) / k) / n, (y + (j + 0.5) / k) / n)));
        ref += sum / (k * k) * w;
        got += luminance({m.texel(0, f, x, y)[0], m.texel(0, f, x, y)[1], m.texel(0, f, x, y)[2]}) * w;
      }
  ASSERT_GT(texels, 4);
  // The disc's own energy: peak radiance x solid angle x 5/6 (the mean of the
  // limb darkening 1 - (1 - sqrt(1 - rho^2)) / 2).
  double rs = skySunAngularRadius();
  double sunEnergy = luminance(env.radiance(skySunDirection())) * std::numbers::pi * rs * rs * 5.0 / 6.0;
  EXPECT_GT(sunEnergy, 0.2 * ref);  // the sun matters here
  EXPECT_NEAR(got, ref, 0.03 * sunEnergy);
}

TEST(PreviewPrefilter, RougherMipsAreSmoother) {
  CubeMap m = prefilterRadiance(makeEnvironment("sky"), 64, 6, 64);
  double previous = 1e300;
  for (int l = 0; l < m.mipCount(); ++l) {
    double peak = 0.0;
    for (size_t i = 0; i < m.mips[l].size(); i += 4) peak = std::max(peak, static_cast<double>(m.mips[l][i + 1]));
    EXPECT_LT(peak, previous) << "mip " << l;
    previous = peak;
  }
}

TEST(PreviewPrefilter, PrefilteringConservesEnergy) {
  // A normalised, rotation-invariant kernel keeps the integral over the sphere.
  for (const char* name : {"studio", "sky"}) {
    CubeMap m = prefilterRadiance(makeEnvironment(name), 64, 6, 128);
    Vec3 base = meanRadiance(m, 0);
    for (int l = 1; l < m.mipCount(); ++l) {
      Vec3 mean = meanRadiance(m, l);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c] / base[c], 1.0, 0.03) << name << " mip " << l << " channel " << c;
    }
  }
}

/// Texel centres to check a level of edge n at: `perFace` on each face, a
/// corner one and the rest spread over the face (Fibonacci pattern).
std::vector<std::tuple<int, int, int>> someTexels(int n, int perFace) {
  std::vector<std::tuple<int, int, int>> texels;
  for (int f = 0; f < 6; ++f) {
    texels.emplace_back(f, 0, 0);
    for (int i = 1; i < perFace; ++i) {
      double u = (i + 0.5 * f) / perFace, v = std::fmod(i * 0.6180339887498949 + 0.37 * f, 1.0);
      texels.emplace_back(f, std::min(n - 1, static_cast<int>(u * n)), std::min(n - 1, static_cast<int>(v * n)));
    }
  }
  return texels;
}

TEST(PreviewPrefilter, MipsMatchTheGgxConvolutionOfTheEnvironment) {
  // Reference: integral of L(l) D(NoH)/4 NoL over l / integral of the kernel,
  // by quadrature of the analytic environment, at texel centres.
  Environment env = makeEnvironment("studio");
  CubeMap m = prefilterRadiance(env);
  ASSERT_EQ(m.mipCount(), 6);
  for (int l : {1, 2, 3, 5}) {
    double r = mipRoughness(l, m.mipCount());
    int n = m.mipSize(l);
    // The narrowest lobe, near the soft boxes' edges, is the hardest.
    for (auto [f, x, y] : someTexels(n, l == 1 ? 8 : 2)) {
      double kernelSum = 0.0;
      Vec3 d = cubeDirection(f, (x + 0.5) / n, (y + 0.5) / n);
      Vec3 ref = hemisphereIntegral(env, d, ggxKernel, r * r, &kernelSum, l == 1 ? 256 : 128);
      const float* got = m.texel(l, f, x, y);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c] / (ref[c] / kernelSum), 1.0, 0.03)
            << "mip " << l << " (r " << r << ") face " << f << " texel " << x << "," << y << " channel " << c;
    }
  }
}

TEST(PreviewPrefilter, IrradianceMatchesACosineQuadrature) {
  for (const char* name : {"studio", "sky"}) {
    Environment env = makeEnvironment(name);
    CubeMap m = irradianceMap(env);
    ASSERT_EQ(m.size, kDefaultIrradianceSize);
    for (auto [f, x, y] : someTexels(m.size, 3)) {
      Vec3 n = cubeDirection(f, (x + 0.5) / m.size, (y + 0.5) / m.size);
      Vec3 ref = hemisphereIntegral(env, n, cosineKernel, 0.0, nullptr, 96);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(m.texel(0, f, x, y)[c] / ref[c], 1.0, 0.02) << name << " face " << f << " texel " << x << "," << y;
    }
  }
}

TEST(PreviewPrefilter, IsDeterministic) {
  Environment env = makeEnvironment("sky");
  EXPECT_EQ(prefilterRadiance(env, 32, 6, 32).mips, prefilterRadiance(env, 32, 6, 32).mips);
  EXPECT_EQ(irradianceMap(env, 8, 16).mips, irradianceMap(env, 8, 16).mips);
}

// ---------------------------------------------------------------------------
// Tone mapping and sRGB.

Image onePixel(float r, float g, float b, float a) {
  Image img(1, 1);
  img.rgba = {r, g, b, a};
  return img;
}

TEST(PreviewImage, TonemapLeavesColoursInRangeAloneAndShouldersTheRestTowardWhite) {
  // Below a peak channel of 0.76: the colour itself (after exposure and gains).
  Image out = tonemap(onePixel(0.7f, 0.18f, 0.0f, 0.25f), 0.0);
  EXPECT_FLOAT_EQ(out.rgba[0], 0.7f);
  EXPECT_FLOAT_EQ(out.rgba[1], 0.18f);
  EXPECT_EQ(out.rgba[2], 0.0f);
  EXPECT_EQ(out.rgba[3], 0.25f);  // alpha kept
  // +1 stop doubles the input; a gain scales its channel.
  EXPECT_FLOAT_EQ(tonemap(onePixel(0.35f, 0.09f, 0, 1), 1.0).rgba[0], 0.7f);
  EXPECT_FLOAT_EQ(tonemap(onePixel(0.7f, 0.36f, 0, 1), 0.0, {1, 0.5, 1}).rgba[1], 0.18f);
  // Above: Khronos PBR Neutral's shoulder, 1 − 0.24² / (peak − 0.52), and the
  // pixel pulled toward white (grey stays grey).
  const double peak = 2.0, newPeak = 1 - 0.24 * 0.24 / (peak - 0.52);
  Image grey = tonemap(onePixel(2.0f, 2.0f, 2.0f, 1), 0.0);
  EXPECT_NEAR(grey.rgba[0], newPeak, 1e-6);
  EXPECT_NEAR(grey.rgba[2], newPeak, 1e-6);
  Image red = tonemap(onePixel(2.0f, 0.0f, 0.0f, 1), 0.0);
  EXPECT_NEAR(red.rgba[0], newPeak, 1e-6);
  EXPECT_GT(red.rgba[1], 0.0f) << "desaturated toward white";
  EXPECT_LT(red.rgba[1], red.rgba[0]);
  // Bounded, monotone, negative to 0, +inf near 1, NaN kept for the encoder to count.
  Image edge = tonemap(onePixel(1e30f, -3.0f, INFINITY, NAN), 0.0);
  EXPECT_LE(edge.rgba[0], 1.0f);
  EXPECT_GT(edge.rgba[0], 0.99f);
  EXPECT_GE(edge.rgba[1], 0.0f);
  EXPECT_LE(edge.rgba[2], 1.0f);
  EXPECT_TRUE(std::isnan(edge.rgba[3]));  // alpha untouched
  EXPECT_TRUE(std::isnan(tonemap(onePixel(NAN, 0, 0, 1), 0.0).rgba[0]));
  float previous = -1.0f;
  for (float x = 0.0f; x < 100.0f; x = x * 1.1f + 0.001f) {
    float y = tonemap(onePixel(x, x, x, 1), 0.0).rgba[0];
    EXPECT_GE(y, previous) << x;
    EXPECT_LE(y, 1.0f) << x;
    previous = y;
  }
}

TEST(PreviewImage, SrgbEncodeIsTheExactOetfRoundedAndClamped) {
  auto oetf = [](double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055; };
  Image img(4, 2);
  img.rgba = {0.0f, 0.0031308f, 0.5f, 0.5f,  1.0f, 2.0f, -1.0f, 1.0f,  // clamps
              0.2f, 0.8f, 0.01f, 0.0f,       NAN, 0.5f, 0.5f, 1.0f,     //
              0.5f, NAN, NAN, NAN,           0.25f, 0.75f, 0.04f, 2.0f, //
              INFINITY, -INFINITY, 1.0f, 1.0f, 0.0f, 0.0f, 0.0f, -1.0f};
  Srgb8 out = encodeSrgb8(img);
  ASSERT_EQ(out.rgba.size(), 32u);
  EXPECT_EQ(out.rgba[0], 0);
  EXPECT_EQ(out.rgba[1], 10);   // 255 * 12.92 * 0.0031308 = 10.31
  EXPECT_EQ(out.rgba[2], 188);  // 255 * 0.7354 = 187.5
  EXPECT_EQ(out.rgba[3], 128);  // alpha is linear: 127.5
  EXPECT_EQ(out.rgba[4], 255);
  EXPECT_EQ(out.rgba[5], 255);
  EXPECT_EQ(out.rgba[6], 0);
  const int general[] = {8, 9, 10, 20, 21, 22};
  for (int i : general)
    EXPECT_EQ(out.rgba[i], static_cast<int>(std::floor(oetf(img.rgba[i]) * 255 + 0.5))) << "channel " << i;
  EXPECT_EQ(out.rgba[11], 0);
  EXPECT_EQ(out.rgba[12], 0);  // NaN -> 0 ...
  EXPECT_EQ(out.rgba[17], 0);
  EXPECT_EQ(out.rgba[19], 0);
  EXPECT_EQ(out.rgba[23], 255);
  EXPECT_EQ(out.rgba[24], 255);
  EXPECT_EQ(out.rgba[25], 0);
  EXPECT_EQ(out.rgba[31], 0);
  EXPECT_EQ(out.nanCount, 2u);  // ... and counted per pixel
}

// ---------------------------------------------------------------------------
// PNG output.

/// A fresh empty directory for one test, removed afterwards.
class PreviewPng : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("substratec_preview_test_" + std::to_string(::getpid()) + "_" +
            testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<fs::path> entries() const {
    return {fs::directory_iterator(dir_), fs::directory_iterator()};
  }
  fs::path dir_;
};

/// A 7x5 test pattern with varying alpha.
std::vector<uint8_t> pattern(int w, int h) {
  std::vector<uint8_t> px(static_cast<size_t>(w) * h * 4);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>((i * 37 + i / 4 * 11) & 0xFF);
  return px;
}

std::vector<uint8_t> fileBytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The chunk types of a PNG file, in order.
std::vector<std::string> chunkTypes(const std::vector<uint8_t>& png) {
  std::vector<std::string> types;
  for (size_t p = 8; p + 8 <= png.size();) {
    uint32_t len = (uint32_t{png[p]} << 24) | (uint32_t{png[p + 1]} << 16) | (uint32_t{png[p + 2]} << 8) | png[p + 3];
    types.emplace_back(reinterpret_cast<const char*>(&png[p + 4]), 4);
    p += 12 + len;
  }
  return types;
}

TEST_F(PreviewPng, ReadsBackToTheSamePixels) {
  const int w = 7, h = 5;
  std::vector<uint8_t> px = pattern(w, h);
  fs::path file = dir_ / "out.png";
  Diagnostics diags("test");
  ASSERT_TRUE(writePng(file.string(), w, h, px, diags)) << diags.errorMessages();
  EXPECT_EQ(entries(), std::vector<fs::path>{file});  // no temporary left

  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, file.c_str())) << image.message;
  EXPECT_EQ(image.width, static_cast<png_uint_32>(w));
  EXPECT_EQ(image.height, static_cast<png_uint_32>(h));
  EXPECT_EQ(image.format & PNG_FORMAT_FLAG_ALPHA, static_cast<png_uint_32>(PNG_FORMAT_FLAG_ALPHA));
  image.format = PNG_FORMAT_RGBA;
  std::vector<uint8_t> back(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, back.data(), 0, nullptr)) << image.message;
  EXPECT_EQ(back, px);

  std::vector<std::string> chunks = chunkTypes(fileBytes(file));
  ASSERT_GE(chunks.size(), 3u);
  EXPECT_EQ(chunks.front(), "IHDR");
  EXPECT_EQ(chunks.back(), "IEND");
  EXPECT_NE(std::find(chunks.begin(), chunks.end(), "sRGB"), chunks.end());
  EXPECT_EQ(std::find(chunks.begin(), chunks.end(), "tIME"), chunks.end());
}

TEST_F(PreviewPng, SameInputsGiveByteIdenticalFiles) {
  std::vector<uint8_t> px = pattern(16, 9);
  Diagnostics diags("test");
  ASSERT_TRUE(writePng((dir_ / "a.png").string(), 16, 9, px, diags)) << diags.errorMessages();
  ASSERT_TRUE(writePng((dir_ / "b.png").string(), 16, 9, px, diags)) << diags.errorMessages();
  std::vector<uint8_t> a = fileBytes(dir_ / "a.png");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, fileBytes(dir_ / "b.png"));
  std::vector<uint8_t> mem;
  ASSERT_TRUE(encodePng(16, 9, px, mem, diags)) << diags.errorMessages();
  EXPECT_EQ(mem, a);
}

TEST_F(PreviewPng, FailedWriteLeavesNothingBehind) {
  std::vector<uint8_t> px = pattern(4, 4);
  Diagnostics diags("test");
  // The directory does not exist.
  EXPECT_FALSE(writePng((dir_ / "missing" / "out.png").string(), 4, 4, px, diags));
  EXPECT_NE(diags.errorMessages().find("out.png"), std::string::npos) << diags.errorMessages();
  EXPECT_FALSE(fs::exists(dir_ / "missing"));
  EXPECT_TRUE(entries().empty());
  // The temporary is written but cannot replace a directory: it is removed.
  fs::create_directory(dir_ / "taken.png");
  diags = Diagnostics("test");
  EXPECT_FALSE(writePng((dir_ / "taken.png").string(), 4, 4, px, diags));
  EXPECT_TRUE(diags.hasErrors());
  EXPECT_EQ(entries(), std::vector<fs::path>{dir_ / "taken.png"});
  EXPECT_TRUE(fs::is_directory(dir_ / "taken.png"));
  // Too few pixels: nothing is written, an existing file is untouched.
  ASSERT_TRUE(writePng((dir_ / "keep.png").string(), 4, 4, px, diags)) << diags.errorMessages();
  std::vector<uint8_t> before = fileBytes(dir_ / "keep.png");
  diags = Diagnostics("test");
  EXPECT_FALSE(writePng((dir_ / "keep.png").string(), 5, 4, px, diags));
  EXPECT_TRUE(diags.hasErrors());
  EXPECT_EQ(fileBytes(dir_ / "keep.png"), before);
  EXPECT_EQ(entries().size(), 2u);
}

// ---------------------------------------------------------------------------
// Font and contact sheets.

int popcount(const std::array<uint8_t, kGlyphHeight>& rows) {
  int n = 0;
  for (uint8_t r : rows) n += std::popcount(static_cast<unsigned>(r));
  return n;
}

bool lit(const Image& img, int x, int y) { return img.pixel(x, y)[0] > 0.5f; }

TEST(PreviewText, FontCoversTheLabelCharacters) {
  const std::string required = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789 .,:;-+=/()[]%#_<>'\"";
  std::set<std::array<uint8_t, kGlyphHeight>> seen;
  for (char c : required) {
    EXPECT_TRUE(hasGlyph(c)) << "'" << c << "'";
    if (c != ' ') EXPECT_GT(popcount(glyph(c)), 0) << "'" << c << "'";
    EXPECT_TRUE(seen.insert(glyph(c)).second) << "'" << c << "' looks like another glyph";
    for (uint8_t row : glyph(c)) EXPECT_LT(row, 1u << kGlyphWidth) << "'" << c << "'";
  }
  EXPECT_EQ(popcount(glyph(' ')), 0);
  for (char c = 'a'; c <= 'z'; ++c) EXPECT_EQ(glyph(c), glyph(static_cast<char>(c - 'a' + 'A')));
  EXPECT_FALSE(hasGlyph('~'));
  EXPECT_EQ(glyph('~'), glyph('?'));
}

TEST(PreviewText, DrawTextLightsExactlyTheGlyphPixels) {
  Image img(30, 20, {0, 0, 0, 1});
  drawText(img, 3, 2, "A#", {1, 1, 1, 1}, 2);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      bool want = false;
      int gx = x - 3, gy = (y - 2) / 2;
      if (y >= 2 && gy < kGlyphHeight && gx >= 0) {
        int cell = gx / (kGlyphAdvance * 2), col = (gx % (kGlyphAdvance * 2)) / 2;
        if (cell < 2 && col < kGlyphWidth) want = glyph("A#"[cell])[gy] & (1u << (kGlyphWidth - 1 - col));
      }
      EXPECT_EQ(lit(img, x, y), want) << "pixel " << x << "," << y;
    }
  EXPECT_EQ(textWidth("A#", 2), 22);
  EXPECT_EQ(textWidth("ab\nabcd", 1), 23);
  EXPECT_EQ(textWidth("", 3), 0);
  // Clipped at the borders, no crash.
  drawText(img, -4, 17, "WW", {1, 1, 1, 1}, 3);
}

TEST(PreviewContactSheet, SizeAndTilePlacementFollowTheLayout) {
  std::vector<Image> tiles;
  for (int i = 0; i < 5; ++i) tiles.emplace_back(64, 48, std::array<float, 4>{0.1f * (i + 1), 0.5f, 0.25f, 1.0f});
  Image sheet = contactSheet(tiles, {"a", "b", "c", "d", "e"}, 3);
  const int M = kSheetMargin, band = kGlyphHeight + 8;  // scale 1 for 64 pixel tiles
  EXPECT_EQ(sheet.width, M + 3 * (64 + M));
  EXPECT_EQ(sheet.height, M + 2 * (48 + band + M));
  for (int i = 0; i < 5; ++i) {
    int x0 = M + (i % 3) * (64 + M), y0 = M + (i / 3) * (48 + band + M);
    for (auto [dx, dy] : {std::pair{0, 0}, std::pair{63, 47}, std::pair{30, 20}})
      EXPECT_FLOAT_EQ(sheet.pixel(x0 + dx, y0 + dy)[0], 0.1f * (i + 1)) << "tile " << i;
    EXPECT_EQ(sheet.pixel(x0 - 1, y0)[0], kSheetBackground[0]);  // margins are background
    EXPECT_EQ(sheet.pixel(x0 + 64, y0 + 47)[0], kSheetBackground[0]);
  }
  // The sixth cell is empty.
  EXPECT_EQ(sheet.pixel(M + 2 * (64 + M) + 30, M + (48 + band + M) + 20)[0], kSheetBackground[0]);
  EXPECT_THROW(contactSheet({}, {}, 2), std::invalid_argument);
  EXPECT_THROW(contactSheet(tiles, std::vector<std::string>(6, "x"), 2), std::invalid_argument);
  EXPECT_EQ(contactSheet(tiles, {}, 0).width, M + (64 + M));  // columns clamped to >= 1
}

TEST(PreviewContactSheet, LabelsAreLitWhereTheTextIs) {
  const std::vector<std::string> labels = {"step 2: 48 B, 3 closures", "[x] 100%", ""};
  std::vector<Image> tiles(3, Image(256, 64, {0.3f, 0.3f, 0.3f, 1.0f}));
  Image sheet = contactSheet(tiles, labels, 2);
  // 256 wide tiles: scale 2 would not fit the first label (286 pixels).
  const int M = kSheetMargin, scale = 1, band = kGlyphHeight * scale + 8;
  for (int i = 0; i < 3; ++i) {
    int x0 = M + (i % 2) * (256 + M), y0 = M + (i / 2) * (64 + band + M) + 64;
    // The label as drawText draws it, 4 pixels under the tile.
    Image want(256, band, kSheetBackground);
    drawText(want, 0, 4, labels[i], {1, 1, 1, 1}, scale);
    int litCount = 0;
    for (int y = 0; y < band; ++y)
      for (int x = 0; x < 256; ++x) {
        ASSERT_EQ(lit(sheet, x0 + x, y0 + y), lit(want, x, y)) << "label " << i << " pixel " << x << "," << y;
        litCount += lit(sheet, x0 + x, y0 + y);
      }
    int glyphPixels = 0;
    for (char c : labels[i]) glyphPixels += popcount(glyph(c));
    EXPECT_EQ(litCount, glyphPixels * scale * scale) << "label " << i;
    if (!labels[i].empty()) EXPECT_GT(litCount, 0);
    // White text.
    if (i == 0) EXPECT_TRUE(lit(sheet, x0 + 1, y0 + 4));  // the top row of 'S'
  }
}

TEST(PreviewContactSheet, LabelsScaleWithTheTileAndAreCutToFit) {
  std::vector<Image> big(1, Image(384, 32, {0, 0, 0, 1}));
  Image sheet = contactSheet(big, {"HI"}, 1);  // 384 / 128 = 3
  EXPECT_EQ(sheet.height, 2 * kSheetMargin + 32 + kGlyphHeight * 3 + 8);
  std::vector<Image> small(1, Image(40, 16, {0, 0, 0, 1}));
  Image cut = contactSheet(small, {"ABCDEFGHIJ"}, 1);  // 40 pixels fit 6 glyphs (35 wide)
  int litCount = 0;
  for (int y = kSheetMargin + 16; y < cut.height; ++y)
    for (int x = 0; x < cut.width; ++x) litCount += lit(cut, x, y);
  int want = 0;
  for (char c : std::string("ABCDEF")) want += popcount(glyph(c));
  EXPECT_EQ(litCount, want);
}

}  // namespace
}  // namespace substratec::preview
