// The white furnace (issue 7, "Numerical stability on hard cases"): on the CPU
// reference in double, no single closure returns more energy than it receives
// under a uniform white environment, and a white rough conductor with energy
// compensation returns nearly all of it. docs/stability.md, "Energy: the white
// furnace", records what broke and how the model was fixed.
//
// What is measured is the directional albedo of a closure seen from V,
//   albedo(V) = viewThroughput(c, NoV) * envIntegrated(c, V, radiance = 1),
// envIntegrated being the reference's importance-sampled integral over the
// whole sphere of lightThroughput * BSDF * NoL (so SSS wrap, lit from below
// the horizon, is included; reference.h). The largest channel is what is bounded.
//
// The estimator is deterministic (a Hammersley set per strategy); its noise is
// bounded by EstimatesAreConvergedFarBelowTheTolerance (the same configurations
// with 4x the points and another rotation). Measured against 262,144 points:
// at most 3.5e-4 for a near-mirror lobe at 4,096 points; a sharp sheen lobe at
// a grazing view has no strategy of its own (the cosine one samples it), 2.9e-3
// at 4,096 points but 3.4e-4 at 32,768 (NoV 1e-3; 2.3e-4 at NoV 0.1 with
// 8,192), hence samplesFor(). (Since issue 16 the sheen lobe has a strategy of
// its own, its Charlie distribution; samplesFor() stays.)
#include <gtest/gtest.h>
#include <numbers>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "../stack_furnace.h"
#include "pipeline/pipeline.h"
#include "reference/bsdf.h"
#include "reference/energy_lut.h"
#include "reference/reference.h"

namespace substratec {
namespace furnace_test {

using namespace reference;
using D3 = V3<double>;

constexpr double kTolerance = 1.001;       // "no more than 1.001 of the energy it receives"
constexpr double kConductorFloor = 0.98;  // "a white rough conductor returns >= 0.98"
constexpr double kMixFloor = 0.97;        // issue 19's goal: a white furnace >= 0.97
constexpr int kSamples = 4096;             // per strategy (2 to 4 strategies)

constexpr double kRoughness[] = {0, 1e-4, 0.02, 0.1, 0.25, 0.5, 0.75, 1};
constexpr double kF0[] = {0, 0.04, 0.5, 1};
constexpr double kNoV[] = {1, 0.5, 0.1, 1e-3};
constexpr int kModels[] = {kDiffuseLambert, kDiffuseChan2018, kDiffuseChan2024, kDiffuseEon};

double elapsedSeconds(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The view at cosine NoV from +Z (the closure's normal), at azimuth phi from
/// +X (its tangent).
D3 viewAt(double NoV, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - NoV * NoV));
  return {s * std::cos(phi), s * std::sin(phi), NoV};
}

/// A white closure: every channel of F0 and of the diffuse albedo equal.
Closure<double> whiteClosure(double f0, double albedo, double roughness) {
  Closure<double> c;
  c.f0 = {f0, f0, f0};
  c.diffuseAlbedo = {albedo, albedo, albedo};
  c.roughness = roughness;
  c.N = {0, 0, 1};
  c.T_ = {1, 0, 0};
  return c;
}

struct Config {
  std::string axis;  // which slice of the grid
  Closure<double> c;
  int model = kDiffuseLambert;
  double NoV = 1;
  double phi = 0.3;
};

std::string describe(const Config& k) {
  const Closure<double>& c = k.c;
  std::string s = fmt::format("{} [{}] r={} F0={} albedo={}", k.axis, diffuseModelName(static_cast<DiffuseModel>(k.model)), c.roughness, c.f0[0],
                              c.diffuseAlbedo[0]);
  if (c.features & kFeatureF90) s += fmt::format(" F90={}", c.f90[0]);
  if (c.features & kFeatureAnisotropy) s += fmt::format(" A={}", c.anisotropy);
  if (c.features & kFeatureHaze)
    s += fmt::format(" haze(r2={}, w={})", c.secondRoughness, c.secondRoughnessWeight);
  if (c.features & kFeatureFuzz) s += fmt::format(" fuzz(amount={}, r={})", c.fuzzAmount, c.fuzzRoughness);
  if (c.sssType != kSssNone) s += fmt::format(" sss(type={}, mfp={})", c.sssType, c.sssMfp[0]);
  if (!c.isTop) s += fmt::format(" under(cover={}, T={})", c.coverageAbove, c.topTransmittance[0]);
  return s + fmt::format(" NoV={} phi={:.3f}", k.NoV, k.phi);
}

/// Points per strategy for a configuration: kSamples, more for fuzz seen at
/// grazing (see the file comment).
int samplesFor(const Config& k) {
  if (!(k.c.features & kFeatureFuzz) || k.NoV > 0.2) return kSamples;
  return k.NoV < 0.01 ? 8 * kSamples : 2 * kSamples;
}

/// The directional albedo (largest channel) under a unit white environment.
double albedoOf(const Config& k, int samples, std::uint32_t seed = 7) {
  const D3 V = viewAt(k.NoV, k.phi);
  const D3 e = envIntegrated(k.c, V, [](const D3&) { return D3{1, 1, 1}; }, k.model, samples, seed);
  const D3 t = viewThroughput(k.c, k.NoV, V);
  return std::max({e[0] * t[0], e[1] * t[1], e[2] * t[2]});
}

/// Every NoV; an anisotropic closure also at three view azimuths (along its
/// tangent, its bitangent and between: its albedo depends on the azimuth), or
/// only the two axes (`axesOnly`), where the stretch is extreme.
void addViews(std::vector<Config>& out, const std::string& axis, const Closure<double>& c, int model,
              bool axesOnly = false) {
  const bool aniso = (c.features & kFeatureAnisotropy) && c.anisotropy != 0;
  std::vector<double> phis{0.3};
  if (aniso) phis = axesOnly ? std::vector<double>{0.0, std::numbers::pi / 2} : std::vector<double>{0.0, std::numbers::pi / 4, std::numbers::pi / 2};
  for (double NoV : kNoV)
    for (double phi : phis) out.push_back({axis, c, model, NoV, phi});
}

// The grid. A full cross product of every axis is ~10^7 configurations; this
// one keeps what can interact:
//  - "base": every roughness x F0 x diffuse albedo x diffuse model (the model
//    matters only under a non-zero albedo) x NoV — the specular/diffuse energy
//    split every other feature goes through;
//  - each opt-in feature on its own, over every roughness and NoV, for the two
//    closures that stress the split from both sides: a white conductor
//    (F0 = 1, albedo 0: compensation) and a dielectric over a white diffuse
//    (F0 = 0.04, albedo 1: what the diffuse receives) — F90 also over every F0
//    and albedo, fuzz also alone (F0 = 0);
//  - SSS (wrap is lit over the whole sphere; diffusion / simple volume use the
//    diffuse model) and closures under a clear coat on fewer roughnesses (their
//    energy paths do not depend on it);
//  - every feature at once, for each diffuse model (anisotropic views along the
//    axes only): the features interact only through the shared terms (E_spec,
//    the fuzz attenuation), which this slice exercises together.
std::vector<Config> furnaceGrid() {
  std::vector<Config> out;
  const std::pair<double, double> kPairs[] = {{1.0, 0.0}, {0.04, 1.0}};
  for (double r : kRoughness)
    for (double f0 : kF0) {
      addViews(out, "base", whiteClosure(f0, 0, r), kDiffuseLambert);
      for (int model : kModels) addViews(out, "base", whiteClosure(f0, 1, r), model);
    }
  for (double r : kRoughness)
    for (double f0 : kF0)
      for (double albedo : {0.0, 1.0})
        for (double f90 : {0.0, 1.0}) {
          Closure<double> c = whiteClosure(f0, albedo, r);
          c.features |= kFeatureF90;
          c.f90 = {f90, f90, f90};
          addViews(out, "f90", c, kDiffuseLambert);
        }
  for (double r : kRoughness)
    for (double A : {-1.0, 0.5, 1.0})
      for (auto [f0, albedo] : kPairs) {
        Closure<double> c = whiteClosure(f0, albedo, r);
        c.features |= kFeatureAnisotropy;
        c.anisotropy = A;
        addViews(out, "anisotropy", c, kDiffuseLambert);
      }
  for (double r : kRoughness)
    for (double w : {0.5, 1.0})
      for (double r2 : {0.0, 1.0})
        for (auto [f0, albedo] : kPairs) {
          Closure<double> c = whiteClosure(f0, albedo, r);
          c.features |= kFeatureHaze;
          c.secondRoughnessWeight = w;
          c.secondRoughness = r2;
          addViews(out, "haze", c, kDiffuseLambert);
        }
  for (double r : kRoughness)
    for (double fr : {0.1, 1.0})
      for (auto [f0, albedo] : {std::pair{1.0, 0.0}, std::pair{0.04, 1.0}, std::pair{0.0, 0.0}}) {
        Closure<double> c = whiteClosure(f0, albedo, r);
        c.features |= kFeatureFuzz;
        c.fuzzAmount = 1;
        c.fuzzColor = {1, 1, 1};
        c.fuzzRoughness = fr;
        addViews(out, "fuzz", c, kDiffuseLambert);
      }
  for (double r : {0.0, 0.5, 1.0})
    for (std::uint32_t type : {kSssWrap, kSssDiffusion, kSssSimpleVolume})
      for (double mfp : {0.0, 0.001, 0.005, 1.0})
        for (double f0 : {0.0, 0.04, 1.0}) {
          Closure<double> c = whiteClosure(f0, 1, r);
          c.sssType = type;
          c.sssMfp = {mfp, mfp, mfp};
          addViews(out, "sss", c, kDiffuseLambert);
        }
  // A wrap lobe under layers meets them at its own cosine, from the mean of
  // its channels' wrap amounts: channels that wrap unequally (MFP 0, 5 mm, 1 m).
  for (double r : {0.0, 0.5, 1.0})
    for (double cover : {0.5, 1.0})
      for (double f0 : {0.04, 1.0}) {
        Closure<double> c = whiteClosure(f0, 1, r);
        c.sssType = kSssWrap;
        c.sssMfp = {0.0, 0.005, 1.0};
        c.isTop = false;
        c.coverageAbove = cover;
        addViews(out, "wrap under a coat", c, kDiffuseLambert);
      }
  for (double r : {0.0, 0.25, 0.5, 1.0})
    for (double cover : {0.5, 1.0})
      for (double t : {1.0, 0.9})
        for (auto [f0, albedo] : kPairs) {
          Closure<double> c = whiteClosure(f0, albedo, r);
          c.isTop = false;
          c.coverageAbove = cover;
          c.topTransmittance = {t, t, t};
          addViews(out, "under a coat", c, kDiffuseLambert);
        }
  for (int model : kModels)
    for (double r : {0.1, 0.5, 1.0})
      for (auto [f0, albedo] : kPairs) {
        Closure<double> c = whiteClosure(f0, albedo, r);
        c.features = kFeatureF90 | kFeatureAnisotropy | kFeatureHaze | kFeatureFuzz;
        c.f90 = {1, 1, 1};
        c.anisotropy = 0.5;
        c.secondRoughness = 1;
        c.secondRoughnessWeight = 0.5;
        c.fuzzAmount = 1;
        c.fuzzColor = {1, 1, 1};
        c.fuzzRoughness = 0.1;
        c.sssType = kSssWrap;
        c.sssMfp = {0.005, 0.005, 0.005};
        c.isTop = false;
        c.coverageAbove = 1;
        c.topTransmittance = {1, 1, 1};
        addViews(out, "everything", c, model, /*axesOnly=*/true);
      }
  return out;
}

struct Measured {
  Config config;
  double albedo;
};

/// The grid, measured once for the tests that read it (sorted, largest first).
const std::vector<Measured>& measuredGrid() {
  static const std::vector<Measured> measured = [] {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Measured> m;
    for (const Config& k : furnaceGrid()) m.push_back({k, albedoOf(k, samplesFor(k))});
    std::sort(m.begin(), m.end(), [](const Measured& a, const Measured& b) { return a.albedo > b.albedo; });
    std::printf("[ furnace  ] %zu configurations, %d points per strategy (fuzz at grazing: up to %d): %.1f s\n",
                m.size(), kSamples, 8 * kSamples, elapsedSeconds(t0));
    return m;
  }();
  return measured;
}

TEST(Furnace, NoClosureReturnsMoreEnergyThanItReceives) {
  const auto& grid = measuredGrid();
  ASSERT_FALSE(grid.empty());
  int over = 0;
  for (const Measured& m : grid) {
    EXPECT_TRUE(std::isfinite(m.albedo)) << describe(m.config);
    if (m.albedo > kTolerance) {
      ++over;
      ADD_FAILURE() << "returns " << m.albedo << " of the energy it receives: " << describe(m.config);
    }
  }
  std::printf("[ furnace  ] worst: %.5f  %s\n", grid.front().albedo, describe(grid.front().config).c_str());
  for (std::size_t i = 1; i < 5 && i < grid.size(); ++i)
    std::printf("[ furnace  ]        %.5f  %s\n", grid[i].albedo, describe(grid[i].config).c_str());
  EXPECT_EQ(over, 0);
}

TEST(Furnace, RandomStacksOfTwoToEightSlabsNeverGainEnergy) {
  // Issue 16: every interface of a stack reflects its share; what it passes on
  // must shrink with it at every depth (substrate_extra_interfaces). Before the
  // fix, three white transparent slabs returned 1.08 at NoV 0.1, six 1.38.
  // Random stacks (tests/stack_furnace.h) of every depth the test reaches, both
  // shapes, each compiled twice: with every closure kept (the layering model
  // itself) and with the default budget (what simplification ships).
  using namespace stackfurnace;
  const auto t0 = std::chrono::steady_clock::now();
  constexpr int kCasesPerMaterial = 5;
  long cases = 0, views = 0, closures = 0;
  double worst = 0;
  std::string where;
  for (int depth = 2; depth <= 8; ++depth)
    for (Shape shape : kShapes)
      for (bool everyClosure : {true, false}) {
        CompileOptions o;
        if (everyClosure) {
          o.budgetOverride = 4096;
          o.maxClosuresOverride = 8;
        }
        Diagnostics d("stack.json");
        auto r = compileText("stack.json", stackMaterial(depth, shape), o, d);
        ASSERT_TRUE(r.has_value()) << d.formatAll();
        if (everyClosure) ASSERT_EQ(r->after.closures.size(), static_cast<std::size_t>(depth)) << shapeName(shape);
        Rng rng{0x5eed0000u + static_cast<std::uint64_t>(depth) * 8 + static_cast<std::uint64_t>(shape) * 2 +
                (everyClosure ? 1 : 0)};
        for (int k = 0; k < kCasesPerMaterial; ++k) {
          const Case c = randomCase(depth, shape, rng);
          ++cases;
          for (double mu : kNoV) {
            reference::Geometry g;
            g.V = stackfurnace::viewAt(mu);
            const auto m = reference::evaluateMaterial<double>(*r, g, c.inputs, {});
            closures += static_cast<long>(m.closures.size());
            const double a = furnace(m.closures, g.V, 7 + static_cast<std::uint32_t>(views++));
            const std::string what = fmt::format("depth {} ({}, {}), NoV {}: {}", depth, shapeName(shape),
                                                 everyClosure ? "every closure" : "default budget", mu, c.text);
            EXPECT_TRUE(std::isfinite(a)) << what;
            EXPECT_LE(a, kTolerance) << what;
            if (a > worst) worst = a, where = what;
          }
        }
      }
  std::printf("[ furnace  ] random stacks: %ld cases (depth 2..8, 3 shapes, 2 budgets), %ld views, %ld closures; "
              "largest %.5f at %s (%.1f s)\n",
              cases, views, closures, worst, where.c_str(), elapsedSeconds(t0));
  ASSERT_GT(cases, 0);
  ASSERT_GT(closures, cases);
}

TEST(Furnace, StackClosuresCarryUpToFourInterfacesAndFoldTheRest) {
  // Eight clear slabs (F0 0, thickness 0: every layer lets 1 through along the
  // normal). Closure k lies under k interfaces: it stores min(k - 1, 3) extra
  // ones, which the lighting applies as (1 - (1 - mu)^5)^(1 + extra), and its
  // top transmittance carries Q = 0.91 (substrate_extra_interfaces) for each
  // interface past the fourth only: 1, 1, 1, 1, 1, 0.91, 0.91^2, 0.91^3.
  using namespace stackfurnace;
  CompileOptions o;
  o.budgetOverride = 4096;
  o.maxClosuresOverride = 8;
  Diagnostics d("stack.json");
  auto r = compileText("stack.json", stackMaterial(8, Shape::NestedBases), o, d);
  ASSERT_TRUE(r.has_value()) << d.formatAll();
  ASSERT_EQ(r->after.closures.size(), 8u);
  reference::Geometry g;
  g.V = stackfurnace::viewAt(0.5);
  const auto m = reference::evaluateMaterial<double>(*r, g, {}, {});
  ASSERT_EQ(m.closures.size(), 8u);
  int checked = 0;
  for (int k = 0; k < 8; ++k) {
    const auto& c = m.closures[static_cast<std::size_t>(k)];
    const int extra = std::min(std::max(k - 1, 0), 3);
    EXPECT_EQ(c.isTop, k == 0) << k;
    EXPECT_EQ(c.extraInterfaces, static_cast<std::uint32_t>(extra)) << k;
    EXPECT_EQ(r->after.closures[static_cast<std::size_t>(k)].extraInterfaces, extra) << k;
    EXPECT_NEAR(c.topTransmittance[0], std::pow(0.91, std::max(k - 4, 0)), 1e-12) << k;
    if (k > 0) {  // the lighting: the interface term to the power 1 + extra, the media
      // along the cosine refracted into the layers (IOR 1.5)
      const double mu = 0.3, gmu = interfaceTerm(mu), mut = std::sqrt(1 - (1 - mu * mu) / 2.25);
      const double want = std::pow(c.topTransmittance[0], 1 / mut) * std::pow(gmu, 1 + extra);
      const reference::V3<double> w = stackfurnace::viewAt(mu);
      EXPECT_NEAR(reference::viewThroughput<double>(c, mu, w)[0], want, 1e-9) << k;
      const auto crossing = reference::layersCrossing<double>(c, mu, w);
      EXPECT_NEAR(crossing[0], want, 1e-9) << k;
      EXPECT_NEAR(reference::lightThroughput<double>(c, crossing, crossing)[0], want, 1e-9) << k;
    }
    ++checked;
  }
  ASSERT_EQ(checked, 8);
}

TEST(Furnace, StacksOfWhiteTransparentSlabsAtEveryDepth) {
  // The issue's own case: white slabs (albedo 1, F0 0, roughness ~0), every
  // one but the bottom transparent (sss_mfp 1e6, thickness 0), every closure
  // kept. Prints the furnace per depth (docs/stability.md records them).
  using namespace stackfurnace;
  int measured = 0;
  for (int depth = 2; depth <= 8; ++depth) {
    CompileOptions o;
    o.budgetOverride = 4096;
    o.maxClosuresOverride = 8;
    Diagnostics d("stack.json");
    auto r = compileText("stack.json", stackMaterial(depth, Shape::NestedBases), o, d);
    ASSERT_TRUE(r.has_value()) << d.formatAll();
    const reference::InputValues in = whiteStack(depth, Shape::NestedBases).inputs;
    std::string line;
    for (double mu : kNoV) {
      reference::Geometry g;
      g.V = stackfurnace::viewAt(mu);
      const double a = furnace(reference::evaluateMaterial<double>(*r, g, in, {}).closures, g.V, 11);
      ++measured;
      EXPECT_LE(a, kTolerance) << "depth " << depth << ", NoV " << mu;
      line += fmt::format("  NoV {}: {:.4f}", mu, a);
    }
    std::printf("[ furnace  ] %d white slabs:%s\n", depth, line.c_str());
  }
  ASSERT_EQ(measured, 7 * 4);
}

TEST(Furnace, AWhiteBaseUnderAClearCoatOfAnyDielectricF0ReturnsNearlyAllOfIt) {
  // Issue 19, step 18: the layers' term read every top as IOR 1.5's (1 - F0 =
  // 0.96), so a clear coat of F0 0.06 left T_N 0.94, read as media of
  // transmittance 0.98 whose trapped light the diffuse lost: a white base
  // under it returned 0.879 head-on, 0.695 under a coat of IOR 2 (F0 0.111).
  // The top's own F0 (substrate_coat_interface) gives it back. Goal (issue
  // 19): >= 0.97 for the plausible dielectrics (F0 up to 0.1, IOR 1.93) at
  // NoV 1 / 0.5 / 0.1; never above 1.001 at any F0 (read up to
  // SUBSTRATE_COAT_TOP_F0_MAX 0.18: read up to 0.25, a smooth top of F0 0.2,
  // whose own curve has left chi for Schlick's, returned 1.0018 at NoV 0.1).
  using namespace stackfurnace;
  CompileOptions o;
  o.budgetOverride = 4096;
  o.maxClosuresOverride = 8;
  Diagnostics d("coat.json");
  auto r = compileText("coat.json", stackMaterial(2, Shape::NestedBases), o, d);
  ASSERT_TRUE(r.has_value()) << d.formatAll();
  int measured = 0;
  double lowest = 2;
  std::string where;
  for (double f0 : {0.0, 0.02, 0.04, 0.06, 0.08, 0.1, 0.111, 0.14, 0.18, 0.19, 0.2, 0.25, 0.5, 1.0})
    for (double rough : {1e-4, 0.1}) {
      reference::InputValues in;
      // s0: a clear coat (MFP 1e6, thickness 0); s1: a white Lambertian-like base.
      for (double v : {1.0, f0, rough, 1e6, 1.0, 0.04, 0.5, 0.0, 0.0}) in.values.push_back({v, v, v, v});
      std::string line;
      for (double mu : {1.0, 0.5, 0.1}) {
        reference::Geometry g;
        g.V = stackfurnace::viewAt(mu);
        const double a = furnace(reference::evaluateMaterial<double>(*r, g, in, {}).closures, g.V, 11);
        ++measured;
        const std::string at = fmt::format("coat F0 {}, r {}, NoV {}", f0, rough, mu);
        EXPECT_LE(a, kTolerance) << at;
        if (f0 <= 0.1) {
          EXPECT_GE(a, kMixFloor) << at;
          if (a < lowest) lowest = a, where = at;
        }
        line += fmt::format("  {:.4f}", a);
      }
      std::printf("[ furnace  ] white base under a clear coat of F0 %g, r %g, NoV 1 / 0.5 / 0.1:%s\n", f0, rough,
                  line.c_str());
    }
  ASSERT_EQ(measured, 14 * 2 * 3);
  std::printf("[ furnace  ] clear coats of F0 0 .. 0.1: lowest %.4f  %s\n", lowest, where.c_str());
}

TEST(Furnace, AWhiteBaseUnderAStretchedClearCoatIsLitThroughItsRoughAxis) {
  // Issue 19, step 19: a stretched (anisotropic) top had no rough floor: the
  // layers' term read it as smooth at every azimuth, so a white base under a
  // clear coat of roughness 0.6 and anisotropy 1 returned 0.49 of a white
  // furnace at NoV 0.1 seen along the coat's rough axis, 0.48 ... 0.68 over
  // this test's coats (glTF CoatParameterSweep's coat: -53 % against the truth). The floor follows the
  // direction's azimuth (substrate_coat_floor_along), and the diffuse's
  // normalization takes its mean over the azimuths (substrate_coat_aniso_share),
  // so that it never returns more than 1.001 at any azimuth. Along the rough
  // axis it returns >= 0.9 down to NoV 0.1. (Seen along the smooth axis at
  // grazing, the stretched top's own lobe still loses light: its compensation
  // is the largest albedo over the azimuths, docs/accuracy.md "Anisotropy".)
  using namespace stackfurnace;
  constexpr double kRoughAxisFloor = 0.9;
  int measured = 0, alongRoughAxis = 0;
  double worst = 0, lowest = 2;
  std::string where;
  for (double rough : {0.3, 0.6, 1.0})
    for (double aniso : {-1.0, -0.5, 0.5, 1.0}) {
      const std::string text = fmt::format(
          R"({{"format": "substrate-material/1", "name": "stretched_coat", "output": "root", "nodes": {{
            "coat": {{"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": {}, "anisotropy": {},
                      "sss_mfp": 1e6}},
            "base": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0.04, "roughness": 0.5}},
            "root": {{"kind": "vertical", "top": "coat", "base": "base", "thickness": 0}}}}}})",
          rough, aniso);
      Diagnostics d("stretched_coat.json");
      auto r = compileText("stretched_coat.json", text, CompileOptions{}, d);
      ASSERT_TRUE(r.has_value()) << d.formatAll();
      ASSERT_EQ(r->after.closures.size(), 2u);
      // The view along the tangent (phi 0), between (pi/4) and along the bitangent (pi/2);
      // the rough axis is the tangent for anisotropy > 0.
      for (double phi : {0.0, std::numbers::pi / 4, std::numbers::pi / 2})
        for (double mu : {1.0, 0.5, 0.2, 0.1}) {
          reference::Geometry g;
          g.V = viewAt(mu, phi);
          const double a = furnace(reference::evaluateMaterial<double>(*r, g, {}, {}).closures, g.V, 11);
          ++measured;
          worst = std::max(worst, a);
          const std::string at = fmt::format("coat r {}, A {}, view azimuth {:.3f}, NoV {}", rough, aniso, phi, mu);
          EXPECT_LE(a, kTolerance) << at;
          if ((aniso > 0 && phi == 0.0) || (aniso < 0 && phi == std::numbers::pi / 2)) {
            ++alongRoughAxis;
            EXPECT_GE(a, kRoughAxisFloor) << at;
            if (a < lowest) lowest = a, where = at;
          }
        }
    }
  std::printf("[ furnace  ] white base under a stretched clear coat: largest %.5f over %d; along the rough axis "
              "lowest %.4f over %d (%s)\n",
              worst, measured, lowest, alongRoughAxis, where.c_str());
  ASSERT_EQ(measured, 3 * 4 * 3 * 4);
  ASSERT_EQ(alongRoughAxis, 3 * 4 * 4);
}

TEST(Furnace, AFuzzyCoatTakesWhatItsFuzzReflectsFromTheLayersUnderIt) {
  // A transparent coat with fuzz over a white Lambertian base. The fuzz
  // reflects a share of the view's light; the base under it must not be lit
  // whole as well (issue 19 step 7: 1.017 ... 1.067 of the light before, at
  // fuzz 0.2, roughness 0.7, coat F0 0).
  using namespace stackfurnace;
  int measured = 0;
  double worst = 0;
  for (double f0 : {0.0, 0.04})
    for (double amount : {0.2, 0.6, 1.0})
      for (double fuzzRoughness : {0.2, 0.5, 0.9}) {
        const std::string text = fmt::format(
            R"({{"format": "substrate-material/1", "name": "fuzzy_coat", "output": "root", "nodes": {{
              "coat": {{"kind": "slab", "diffuse_albedo": 0, "f0": {}, "roughness": 0.1, "sss_mfp": 1e6,
                        "fuzz_amount": {}, "fuzz_color": 1, "fuzz_roughness": {}}},
              "base": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 0.5}},
              "root": {{"kind": "vertical", "top": "coat", "base": "base", "thickness": 0}}}}}})",
            f0, amount, fuzzRoughness);
        Diagnostics d("fuzzy_coat.json");
        auto r = compileText("fuzzy_coat.json", text, CompileOptions{}, d);
        ASSERT_TRUE(r.has_value()) << d.formatAll();
        ASSERT_EQ(r->after.closures.size(), 2u);
        for (double mu : kNoV) {
          reference::Geometry g;
          g.V = stackfurnace::viewAt(mu);
          const double a = furnace(reference::evaluateMaterial<double>(*r, g, {}, {}).closures, g.V, 11);
          ++measured;
          worst = std::max(worst, a);
          EXPECT_LE(a, kTolerance) << "F0 " << f0 << ", fuzz " << amount << " r " << fuzzRoughness << ", NoV " << mu;
        }
      }
  std::printf("[ furnace  ] a fuzzy coat over a white base: largest %.5f over %d\n", worst, measured);
  ASSERT_EQ(measured, 2 * 3 * 3 * 4);
}

TEST(Furnace, FuzzInAnOperatorOnTopTakesItsShareFromTheLayersUnderIt) {
  // The fuzzy coat is one part of the top layer: mixed with a clear coat,
  // under a coverage weight, selected, or the top of a vertical that is itself
  // the top. The base under it takes what the layer's fuzz lets through, by
  // the same operators as its transmittance (issue 19 step 8: 1.074 ... 1.132
  // of the light before, when only a fuzzy slab directly on top counted).
  using namespace stackfurnace;
  const char* tops[] = {
      R"("top": {{"kind": "horizontal", "background": "clear", "foreground": "fuzzy", "mix": 0.7}})",
      R"("top": {{"kind": "coverage_weight", "a": "fuzzy", "weight": 0.6}})",
      R"("top": {{"kind": "select", "a": "clear", "b": "fuzzy", "value": "$v", "threshold": 0.5}})",
      R"("top": {{"kind": "vertical", "top": "fuzzy", "base": "clear", "thickness": 0}})",
  };
  int measured = 0;
  double worst = 0;
  for (const char* top : tops)
    for (double f0 : {0.0, 0.04})
      for (double amount : {0.5, 1.0})
        for (double fuzzRoughness : {0.3, 0.8}) {
          const std::string text = fmt::format(
              fmt::runtime(std::string(R"({{"format": "substrate-material/1", "name": "fuzzy_top", "output": "root",
              "inputs": {{"v": {{"type": "float", "default": 0.8}}}}, "nodes": {{
                "fuzzy": {{"kind": "slab", "diffuse_albedo": 0, "f0": {0}, "roughness": 0.1, "sss_mfp": 1e6,
                           "fuzz_amount": {1}, "fuzz_color": 1, "fuzz_roughness": {2}}},
                "clear": {{"kind": "slab", "diffuse_albedo": 0, "f0": {0}, "roughness": 0.1, "sss_mfp": 1e6}},
                )") + top + R"(,
                "base": {{"kind": "slab", "diffuse_albedo": 1, "f0": 0, "roughness": 0.5}},
                "root": {{"kind": "vertical", "top": "top", "base": "base", "thickness": 0}}}}}})"),
              f0, amount, fuzzRoughness);
          Diagnostics d("fuzzy_top.json");
          CompileOptions o;
          o.budgetOverride = 4096;  // every closure kept
          auto r = compileText("fuzzy_top.json", text, o, d);
          ASSERT_TRUE(r.has_value()) << d.formatAll();
          ASSERT_GE(r->after.closures.size(), 2u) << top;
          for (double mu : kNoV) {
            reference::Geometry g;
            g.V = stackfurnace::viewAt(mu);
            const double a = furnace(reference::evaluateMaterial<double>(*r, g, {}, {}).closures, g.V, 11);
            ++measured;
            worst = std::max(worst, a);
            EXPECT_LE(a, kTolerance) << top << "\nF0 " << f0 << ", fuzz " << amount << " r " << fuzzRoughness
                                     << ", NoV " << mu;
          }
        }
  std::printf("[ furnace  ] fuzz in an operator on top of a white base: largest %.5f over %d\n", worst, measured);
  ASSERT_EQ(measured, 4 * 2 * 2 * 2 * 4);
}

TEST(Furnace, AWhiteRoughConductorReturnsNearlyAllOfIt) {
  // F0 = 1, no diffuse, isotropic: Turquin's compensation brings the lobe to
  // ~1 at every roughness (single scattering alone falls to 0.33 at r = 1).
  double lowest = 2;
  std::string where;
  for (double r : kRoughness)
    for (double NoV : {1.0, 0.5, 0.1}) {
      const Config k{"conductor", whiteClosure(1, 0, r), kDiffuseLambert, NoV, 0.3};
      const double a = albedoOf(k, kSamples);
      EXPECT_GE(a, kConductorFloor) << describe(k);
      EXPECT_LE(a, kTolerance) << describe(k);
      if (a < lowest) lowest = a, where = describe(k);
    }
  std::printf("[ furnace  ] white conductor, NoV 1 / 0.5 / 0.1: lowest %.5f  %s\n", lowest, where.c_str());
  // For the record (not bounded below: the tables cannot follow E's dip near
  // NoV ~ alpha, and a stretched lobe is compensated by its largest albedo over
  // the azimuths: AStretchedWhiteConductorIsCompensatedByItsLargestAlbedo).
  double grazing = 2, stretched = 2;
  for (const Measured& m : measuredGrid()) {
    const Closure<double>& c = m.config.c;
    if (c.f0[0] != 1 || c.diffuseAlbedo[0] != 0 || c.features & ~kFeatureAnisotropy || !c.isTop) continue;
    if (c.features & kFeatureAnisotropy) stretched = std::min(stretched, m.albedo);
    else if (m.config.NoV < 0.1) grazing = std::min(grazing, m.albedo);
  }
  std::printf("[ furnace  ] white conductor at NoV 1e-3: lowest %.5f; anisotropic (|A| 0.5..1): lowest %.5f\n", grazing,
              stretched);
}

TEST(Furnace, AWhiteMetalnessMixReturnsNearlyAllOfIt) {
  // Issue 19, step 15: a white metalness mix (F0 0.04 + 0.96 m, diffuse 1 - m)
  // is a white conductor beside a dielectric over a white diffuse, each of
  // which returns ~1. One lobe of the mixed F0 compensated by W = 1 + F (1 - E) / E
  // returned 0.839 at m 0.5, roughness 1; the F0-weighted mean of the parts'
  // W (substrate_closure_compensated_f0) returns the mix's.
  double lowest = 2;
  std::string where;
  int cases = 0;
  for (double r : kRoughness)
    for (double m : {0.25, 0.5, 0.75})
      for (double NoV : {1.0, 0.5, 0.1}) {
        const Config k{"metalness mix", whiteClosure(0.04 + 0.96 * m, 1 - m, r), kDiffuseLambert, NoV, 0.3};
        const double a = albedoOf(k, kSamples);
        EXPECT_GE(a, kMixFloor) << describe(k);
        EXPECT_LE(a, kTolerance) << describe(k);
        if (a < lowest) lowest = a, where = describe(k);
        ++cases;
      }
  EXPECT_EQ(cases, 72);
  std::printf("[ furnace  ] white metalness mix (m 0.25 / 0.5 / 0.75), NoV 1 / 0.5 / 0.1: %d cases, lowest %.5f  %s\n",
              cases, lowest, where.c_str());
}

TEST(Furnace, AWhiteDiffuseUnderAWhiteFuzzReturnsNearlyAllOfIt) {
  // Issue 19, step 16: a white fuzz over a white diffuse under a dielectric
  // interface (a white velvet) reflects with its fuzz what it does not pass
  // to the base, and the base returns the rest: the fuzz costs next to
  // nothing of what the closure returns without it. The base scaled by
  // 1 - amount max(E'(NoV), E'(NoL)) lost the light arriving where the fuzz
  // catches more than along the view (0.885 of the closure's own head-on at
  // fuzz roughness 1 with Lambert); the pair (1 - E'(NoV))(1 - E'(NoL)) / N
  // returns it, with every diffuse model, on top of a smooth, a mid and a
  // rough interface. Measured against the same closure without its fuzz:
  // Chan 2018 itself returns as little as 0.82 (issue 19's item 6).
  double lowest = 2, highest = 0;
  std::string whereLow, whereHigh;
  int cases = 0;
  for (int model : kModels)
    for (double r : {0.1, 0.5, 1.0})
      for (double fr : {0.3, 0.6, 1.0})
        for (double NoV : {1.0, 0.5, 0.2}) {
          Closure<double> c = whiteClosure(0.04, 1, r);
          const double bare = albedoOf({"", c, model, NoV, 0.3}, kSamples);
          c.features |= kFeatureFuzz;
          c.fuzzAmount = 1;
          c.fuzzColor = {1, 1, 1};
          c.fuzzRoughness = fr;
          const Config k{"white velvet", c, model, NoV, 0.3};
          const double a = albedoOf(k, samplesFor(k));
          EXPECT_GE(a, kMixFloor * bare) << describe(k) << ", without its fuzz " << bare;
          EXPECT_LE(a, kTolerance) << describe(k);
          if (a / bare < lowest) lowest = a / bare, whereLow = describe(k);
          highest = std::max(highest, a);
          ++cases;
        }
  EXPECT_EQ(cases, 108);
  std::printf("[ furnace  ] white velvet (4 diffuse models x 3 roughnesses x 3 fuzz roughnesses x NoV 1 / 0.5 / "
              "0.2): %d cases, highest %.5f, lowest %.5f of the closure without its fuzz  %s\n",
              cases, highest, lowest, whereLow.c_str());
}

TEST(Furnace, EstimatesAreConvergedFarBelowTheTolerance) {
  // The worst configurations again with 4x the points and another rotation of
  // the point set: the estimate moves by far less than the 1e-3 of slack.
  const auto& grid = measuredGrid();
  double largest = 0, worst = 0;
  for (std::size_t i = 0; i < 12 && i < grid.size(); ++i) {
    const double again = albedoOf(grid[i].config, 4 * samplesFor(grid[i].config), 12345);
    EXPECT_NEAR(again, grid[i].albedo, 5e-4) << describe(grid[i].config);
    EXPECT_LE(again, kTolerance) << describe(grid[i].config);
    largest = std::max(largest, std::fabs(again - grid[i].albedo));
    worst = std::max(worst, again);
  }
  std::printf("[ furnace  ] 12 worst configurations at 4x the points: largest change %.2e, largest albedo %.5f\n",
              largest, worst);
}

TEST(Furnace, DiffuseModelsReturnTheirAlbedoAndNoMore) {
  // No specular (F0 = F90 = 0), albedo 1, on a finer grid than the furnace's:
  // Chan 2018 and 2024 are divided by fitted bounds of their excess
  // (substrate_bsdf.h); this checks the fits between the grid's points. Where
  // the bound does not divide (NoV >= 0.05), Lambert, EON and Chan 2024 (with
  // its multiple-scattering lobe, issue 19 step 7: 0.94 before) return at
  // least 0.99; Chan 2018 darkens grazing views by design (its smooth term).
  constexpr double kFloor = 0.99;
  const auto t0 = std::chrono::steady_clock::now();
  for (int model : kModels) {
    double worst = 0, lowest = 2;
    std::string where, whereLowest;
    int floored = 0;
    for (double NoV : {1e-4, 1e-3, 0.005, 0.01, 0.02, 0.03, 0.05, 0.08, 0.1, 0.15, 0.3, 1.0})
      for (double r : {0.0, 0.2, 0.4, 0.43, 0.45, 0.5, 0.6, 0.74, 0.8, 0.85, 0.9, 0.95, 1.0}) {
        Closure<double> c = whiteClosure(0, 1, r);
        c.features = kFeatureF90;
        c.f90 = {0, 0, 0};
        const Config k{"diffuse", c, model, NoV, 0.3};
        const double a = albedoOf(k, 2 * kSamples);
        EXPECT_LE(a, kTolerance) << describe(k);
        if (a > worst) worst = a, where = describe(k);
        if (model == kDiffuseChan2018 || NoV < 0.05) continue;
        ++floored;
        EXPECT_GE(a, kFloor) << describe(k);
        if (a < lowest) lowest = a, whereLowest = describe(k);
      }
    std::printf("[ furnace  ] %-8s alone: largest albedo %.5f  %s\n", diffuseModelName(static_cast<DiffuseModel>(model)).data(), worst, where.c_str());
    if (floored > 0)
      std::printf("[ furnace  ] %-8s alone, NoV >= 0.05: lowest albedo %.5f over %d  %s\n",
                  diffuseModelName(static_cast<DiffuseModel>(model)).data(), lowest, floored, whereLowest.c_str());
    if (model != kDiffuseChan2018) EXPECT_EQ(floored, 6 * 13) << "every view at NoV >= 0.05 is floored";
  }
  std::printf("[ furnace  ] diffuse sweep: %.1f s\n", elapsedSeconds(t0));
}

TEST(Furnace, AnisotropicLobesNeverGainEnergyAtAnyAzimuth) {
  // The anisotropic energy terms are widened by measured bounds
  // (substrate_specular_energy_aniso); this sweeps |A| (small values too: the
  // Schlick part B rises fastest there), the view azimuth and NoV more finely
  // than the furnace grid, for the conductor and the dielectric over white
  // diffuse. |A| 0.85 lies between the table's checks (step 21's first table,
  // checked on 512 points per azimuth, read 1.0017 there at r 1, head-on).
  const auto t0 = std::chrono::steady_clock::now();
  double worst = 0;
  std::string where;
  for (double A : {0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 0.85, 1.0})
    for (double r : {0.05, 0.25, 0.5, 0.75, 1.0})
      for (double NoV : {1.0, 0.5, 0.2, 0.1, 0.03, 1e-3})
        for (double phi : {0.0, std::numbers::pi / 8, std::numbers::pi / 4, std::numbers::pi / 2})
          for (auto [f0, albedo] : {std::pair{1.0, 0.0}, std::pair{0.04, 1.0}}) {
            Closure<double> c = whiteClosure(f0, albedo, r);
            c.features = kFeatureAnisotropy;
            c.anisotropy = A;
            const Config k{"anisotropy", c, kDiffuseLambert, NoV, phi};
            const double a = albedoOf(k, kSamples);
            EXPECT_LE(a, kTolerance) << describe(k);
            if (a > worst) worst = a, where = describe(k);
          }
  std::printf("[ furnace  ] anisotropic sweep: largest albedo %.5f  %s (%.1f s)\n", worst, where.c_str(),
              elapsedSeconds(t0));
}

TEST(Furnace, AStretchedWhiteConductorIsCompensatedByItsLargestAlbedo) {
  // Issue 19, item 1: W = 1 / E_max(NoV, r, |A|), the lobe's largest albedo
  // over the view's azimuth (substrate_energy_aniso). Head-on the albedo does
  // not depend on the azimuth, so a white conductor returns nearly all of it
  // (0.53 at r 0.75, |A| 1 with the compensation widened toward 1; 0.909 at
  // |A| 0.25 with the table's nodes at |A| 0.5 and 1, raised to bound the
  // values between; since step 21 its nodes at |A| 1/3, 2/3 and 1, each as low
  // as the bound allows, leave at least 0.956); away from it the azimuths below
  // the largest keep E / E_max (0.66 at worst at NoV 0.2, bench/aniso_albedo),
  // so the mean over them is what is bounded (lowest 0.876; 0.815 before
  // step 21).
  const auto t0 = std::chrono::steady_clock::now();
  double lowestHeadOn = 2, lowestMean = 2;
  std::string whereHeadOn, whereMean;
  int cases = 0;
  for (double r : {0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0})
    for (double A : {0.1, -0.25, 0.5, -0.75, 1.0}) {
      Closure<double> c = whiteClosure(1, 0, r);
      c.features = kFeatureAnisotropy;
      c.anisotropy = A;
      const Config head{"anisotropy", c, kDiffuseLambert, 1.0, 0.3};
      const double a = albedoOf(head, kSamples);
      EXPECT_GE(a, 0.95) << describe(head);
      EXPECT_LE(a, kTolerance) << describe(head);
      if (a < lowestHeadOn) lowestHeadOn = a, whereHeadOn = describe(head);
      ++cases;
      for (double NoV : {0.5, 0.2}) {
        double sum = 0;
        constexpr int kPhis = 5;
        for (int k = 0; k < kPhis; ++k) {
          const Config view{"anisotropy", c, kDiffuseLambert, NoV, k * std::numbers::pi / (2 * (kPhis - 1))};
          const double v = albedoOf(view, kSamples);
          EXPECT_LE(v, kTolerance) << describe(view);
          sum += v;
          ++cases;
        }
        const double mean = sum / kPhis;
        EXPECT_GE(mean, 0.86) << "mean over the azimuths, r " << r << ", A " << A << ", NoV " << NoV;
        if (mean < lowestMean) lowestMean = mean, whereMean = fmt::format("r {} A {} NoV {}", r, A, NoV);
      }
    }
  ASSERT_GT(cases, 0);
  std::printf("[ furnace  ] stretched white conductor (%d views): head-on lowest %.5f  %s; mean over azimuths at "
              "NoV 0.5 / 0.2 lowest %.5f  %s (%.1f s)\n",
              cases, lowestHeadOn, whereHeadOn.c_str(), lowestMean, whereMean.c_str(), elapsedSeconds(t0));
}

TEST(Furnace, TheEnergyTablesNeverUnderestimate) {
  // What the fixes rest on: every lookup of the tables (between cell centres,
  // in the extrapolated outer half cells, down to NoV = 1e-4) is at least the
  // true value, measured here by the reference's own integrator:
  //   E:     F0 = F90 = 1 returns E W with W = 1 / E_table;
  //   B_chi: F0 = 0, F90 = 1 returns the part of the albedo the Fresnel curve
  //          chi weighs (times the dielectric's 1 + MS r), at most its bound
  //          from the tables (fresnelB);
  //   E_fuzz: fuzz alone returns E_fuzz / max(1, E_fuzz table).
  const auto t0 = std::chrono::steady_clock::now();
  const double slack = 3e-4;  // the generator's margin is 2e-4; both integrators are noisy at 1e-4
  double worstX = -1, worstB = -1, worstF = -1;
  for (double NoV : {1e-4, 6e-4, 0.002, 0.005, 0.01, 0.0156, 0.025, 0.04, 0.07, 0.1, 0.17, 0.3, 0.5, 0.73, 0.9, 0.99, 1.0})
    for (double r : {0.0, 0.03, 0.06, 0.1, 0.13, 0.2, 0.33, 0.5, 0.66, 0.8, 0.93, 0.99, 1.0}) {
      const V2<double> table = energyDfg(NoV, r);
      const double e = std::clamp(table[0] + table[1], 1e-3, 1.0);
      const V2<double> dfg{e, fresnelB(table, e, fresnelPull(r), 1.0)};
      Closure<double> c = whiteClosure(1, 0, r);
      const double x = albedoOf({"table", c, kDiffuseLambert, NoV, 0.3}, kSamples) * e;
      c.features = kFeatureF90;
      c.f0 = {0, 0, 0};
      c.f90 = {1, 1, 1};
      // The dielectric's multiple scattering (1 + MS r, issue 19 step 20) is on top of the bound.
      const double b = albedoOf({"table", c, kDiffuseLambert, NoV, 0.3}, kSamples) / (1 + SUBSTRATE_DIELECTRIC_MS * r);
      Closure<double> z = whiteClosure(0, 0, r);
      z.features = kFeatureF90 | kFeatureFuzz;
      z.f90 = {0, 0, 0};
      z.fuzzAmount = 1;
      z.fuzzColor = {1, 1, 1};
      z.fuzzRoughness = r;
      const double fz = fuzzAlbedo(NoV, r);
      const double f = albedoOf({"table", z, kDiffuseLambert, NoV, 0.3}, 4 * kSamples) * std::max(1.0, fz);
      EXPECT_GE(dfg[0], x - slack) << "E at NoV " << NoV << ", r " << r;
      EXPECT_GE(dfg[1], b - slack) << "B_chi at NoV " << NoV << ", r " << r;
      // The sheen lobe is sampled by the cosine strategy only: 1e-3 relative noise at grazing.
      EXPECT_GE(fz, f - 2e-3 * std::max(1.0, f)) << "E_fuzz at NoV " << NoV << ", r " << r;
      worstX = std::max(worstX, x - dfg[0]);
      worstB = std::max(worstB, b - dfg[1]);
      worstF = std::max(worstF, f - fz);
    }
  std::printf("[ furnace  ] tables: largest (true - lookup) E %.1e, B_chi %.1e, E_fuzz %.1e (%.1f s)\n", worstX, worstB,
              worstF, elapsedSeconds(t0));
}

/// A fuzz slab over a white F0 = 1 mirror and over a white Lambertian, the
/// corners `substratec stability` forces on glTF sheen (roughness 0, F0 1,
/// albedo 1): every fuzz amount and roughness (0 included: the sheen lobe then
/// lies along the horizon), at every NoV of the grid, at the 4,096 points per
/// strategy the stability furnace uses. Before the reference sampled the sheen
/// lobe by its own distribution the cosine strategy alone read 1.00278 on the
/// mirror under fuzz of roughness 0 at NoV 0.1 (converged: 0.977; 2 of the 504
/// cases over, worst 1.03869 at roughness 0.02, NoV 1e-3): SheenCloth and
/// CompareSheen's "glTF Logo Sheen" failed `stability` on that noise.
TEST(Furnace, FuzzOverAWhiteMirrorOrLambertianNeverGainsEnergy) {
  const auto t0 = std::chrono::steady_clock::now();
  int cases = 0, over = 0;
  double worst = 0;
  std::string worstWhat;
  for (const bool mirror : {true, false})
    for (double amount : {0.25, 0.5, 1.0})
      for (double fr : {0.0, 1e-4, 0.02, 0.1, 0.3, 0.5, 1.0})
        for (double NoV : kNoV) {
          Closure<double> c = mirror ? whiteClosure(1, 0, 0) : whiteClosure(0, 1, 1);
          c.features |= kFeatureFuzz;
          c.fuzzAmount = amount;
          c.fuzzColor = {1, 1, 1};
          c.fuzzRoughness = fr;
          const Config k{mirror ? "fuzz over a mirror" : "fuzz over a lambertian", c, kDiffuseLambert, NoV, 0.3};
          for (std::uint32_t seed : {7u, 11u, 13u}) {
            const double a = albedoOf(k, kSamples, seed);
            ++cases;
            EXPECT_TRUE(std::isfinite(a)) << describe(k);
            if (a > kTolerance) {
              ++over;
              ADD_FAILURE() << "returns " << a << " of the energy it receives: " << describe(k) << " seed " << seed;
            }
            if (a > worst) worst = a, worstWhat = describe(k);
          }
        }
  std::printf("[ furnace  ] fuzz slabs: %d cases (2 bases x 3 amounts x 7 roughnesses x 4 NoV x 3 seeds), %d over "
              "%.3f; worst %.5f %s (%.1f s)\n",
              cases, over, kTolerance, worst, worstWhat.c_str(), elapsedSeconds(t0));
  ASSERT_GT(cases, 0);
  EXPECT_EQ(over, 0);
}

/// What the fuzz reflects of a light no longer reaches the layers below: the
/// energy a white Lambertian under fuzz returns of a light from L (the integral
/// over every view of f(V, L) NoV, a midpoint rule in (NoV, azimuth)) is no
/// more than the Lambertian alone returns (its own view-only specular/diffuse
/// split already returns 1.021 at NoL 0.1). Before the base was scaled by the
/// fuzz along the light too it returned up to 1.48 at NoL 0.1 (fuzz amount 1,
/// roughness 0.3): the sheen reflected the grazing light and the base still
/// received all of it.
TEST(Furnace, FuzzTakesWhatItReflectsOfTheLightOutOfTheBase) {
  constexpr int kRings = 200, kSectors = 400;
  auto fromLight = [&](const Closure<double>& c, double NoL) {
    const D3 L = viewAt(NoL, 0.0);
    double sum = 0;
    for (int i = 0; i < kRings; ++i)
      for (int j = 0; j < kSectors; ++j) {
        const double NoV = (i + 0.5) / kRings, phi = 2 * std::numbers::pi * (j + 0.5) / kSectors;
        const D3 f = evalClosure(c, viewAt(NoV, phi), L, kDiffuseLambert);  // f NoL
        sum += f[0] / NoL * NoV;
      }
    return sum * (1.0 / kRings) * (2 * std::numbers::pi / kSectors);
  };
  int cases = 0, over = 0;
  double worstGain = -1;
  for (double NoL : {1.0, 0.5, 0.1}) {
    const double alone = fromLight(whiteClosure(0, 1, 1), NoL);
    for (double amount : {0.5, 1.0})
      for (double fr : {0.3, 0.5, 1.0}) {
        Closure<double> c = whiteClosure(0, 1, 1);
        c.features |= kFeatureFuzz;
        c.fuzzAmount = amount;
        c.fuzzColor = {1, 1, 1};
        c.fuzzRoughness = fr;
        const double withFuzz = fromLight(c, NoL);
        ++cases;
        worstGain = std::max(worstGain, withFuzz - alone);
        if (withFuzz > alone + 1e-3) {
          ++over;
          ADD_FAILURE() << "fuzz (amount " << amount << ", r " << fr << ") over a white Lambertian returns " << withFuzz
                        << " of a light at NoL " << NoL << "; the Lambertian alone " << alone;
        }
      }
  }
  std::printf("[ furnace  ] fuzz, from the light: %d cases, %d over the base alone; largest gain over it %.4f\n", cases,
              over, worstGain);
  ASSERT_GT(cases, 0);
  EXPECT_EQ(over, 0);
}

}  // namespace furnace_test
}  // namespace substratec
