// Simplification: the blending rules' properties over many random slabs,
// the loop's order on a deep stack, and the course's worked example.
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "ir/value_eval.h"
#include "passes/blend.h"
#include "passes/features.h"
#include "passes/simplify.h"
#include "pipeline/pipeline.h"
#include "ir/dump.h"
#include "test_util.h"

namespace substratec {
namespace {

using V4 = std::array<double, 4>;

/// A slab whose pins are random constants in their legal ranges.
Slab randomSlab(Material& m, std::mt19937& rng, bool features = true) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto color = [&] { return m.values.constant(VType::Vec3, {u(rng), u(rng), u(rng), 0}); };
  auto scalar = [&](double lo, double hi) { return m.values.scalar(lo + (hi - lo) * u(rng)); };
  Slab s;
  s.id = "s";
  s.pin(SlabPin::DiffuseAlbedo) = color();
  s.pin(SlabPin::F0) = color();
  s.pin(SlabPin::F90) = features ? color() : m.values.splat(VType::Vec3, 1);
  s.pin(SlabPin::Roughness) = scalar(0, 1);
  s.pin(SlabPin::Anisotropy) = features ? scalar(-1, 1) : m.values.scalar(0);
  double z = 0.2 + 0.8 * u(rng), phi = 6.283185307179586 * u(rng), r = std::sqrt(1 - z * z);
  s.pin(SlabPin::Normal) = m.values.constant(VType::Vec3, {r * std::cos(phi), r * std::sin(phi), z, 0});
  s.pin(SlabPin::Tangent) = m.values.constant(VType::Vec3, {-std::sin(phi), std::cos(phi), 0, 0});
  s.pin(SlabPin::SssMfp) = m.values.constant(VType::Vec3, {1e-3 * u(rng), 1e-3 * u(rng), 1e-3 * u(rng), 0});
  s.pin(SlabPin::SssMfpScale) = m.values.scalar(1);
  s.pin(SlabPin::SssPhaseAnisotropy) = scalar(-1, 1);
  s.pin(SlabPin::Emissive) = color();
  s.pin(SlabPin::SecondRoughness) = scalar(0, 1);
  s.pin(SlabPin::SecondRoughnessWeight) = features ? scalar(0, 1) : m.values.scalar(0);
  s.pin(SlabPin::FuzzAmount) = features ? scalar(0, 1) : m.values.scalar(0);
  s.pin(SlabPin::FuzzColor) = color();
  s.pin(SlabPin::FuzzRoughness) = scalar(0, 1);
  s.pin(SlabPin::GlintValue) = features ? scalar(0, 1) : m.values.scalar(1);
  s.pin(SlabPin::GlintUv) = m.values.constant(VType::Vec2, {u(rng), u(rng), 0, 0});
  return s;
}

V4 eval(const Material& m, ValueId v) { return evaluateValue(m, v); }

/// Directional albedo per channel, in the model the blends preserve:
/// F + (1 - F)·folded diffuse, with F the hemispherical Schlick average.
V4 albedo(const Material& m, const Slab& s) {
  V4 f0 = eval(m, s.pin(SlabPin::F0)), f90 = eval(m, s.pin(SlabPin::F90)), d = eval(m, s.pin(SlabPin::DiffuseAlbedo)),
     fc = eval(m, s.pin(SlabPin::FuzzColor));
  double fa = eval(m, s.pin(SlabPin::FuzzAmount))[0] * kFuzzAlbedo;
  V4 a{};
  for (int c = 0; c < 3; ++c) {
    double f = f0[c] + (f90[c] - f0[c]) / 21.0;
    a[c] = f + (1 - f) * (d[c] + (fc[c] - d[c]) * fa);
  }
  return a;
}

double coverage(const Material& m, const Slab& s) { return s.coverage == kNoValue ? 1.0 : eval(m, s.coverage)[0]; }

/// Every pin of two slabs agrees within tol (fuzz colour only where there is fuzz).
void expectSameSlab(const Material& m, const Slab& a, const Slab& b, double tol, const std::string& what) {
  for (int p = 0; p < kSlabPinCount; ++p) {
    SlabPin sp = static_cast<SlabPin>(p);
    if (sp == SlabPin::FuzzColor && eval(m, a.pin(SlabPin::FuzzAmount))[0] < 1e-9) continue;
    V4 x = eval(m, a.pin(sp)), y = eval(m, b.pin(sp));
    for (int c = 0; c < 4; ++c)
      ASSERT_NEAR(x[c], y[c], tol) << what << ": pin " << slabPinInfo(sp).name << " channel " << c;
  }
}

constexpr int kTrials = 300;

TEST(Blend, HorizontalOfASlabWithItselfIsTheIdentity) {
  std::mt19937 rng(1);
  for (int i = 0; i < kTrials; ++i) {
    Material m;  // one per trial: evaluating a value costs the size of its DAG
    Slab s = randomSlab(m, rng);
    // Normals of randomSlab are unit, so normalize() keeps them.
    Slab r = blendHorizontal(m, s, s, m.values.scalar(std::uniform_real_distribution<double>(0, 1)(rng)));
    expectSameSlab(m, r, s, 1e-9, "identity");
    EXPECT_NEAR(coverage(m, r), 1.0, 1e-12);
  }
}

TEST(Blend, HorizontalWithWeightZeroOrOneIsOneSide) {
  std::mt19937 rng(2);
  for (int i = 0; i < kTrials; ++i) {
    Material m;  // one per trial: evaluating a value costs the size of its DAG
    Slab bg = randomSlab(m, rng), fg = randomSlab(m, rng);
    expectSameSlab(m, blendHorizontal(m, bg, fg, m.values.scalar(0)), bg, 1e-9, "w=0");
    expectSameSlab(m, blendHorizontal(m, bg, fg, m.values.scalar(1)), fg, 1e-9, "w=1");
  }
}

TEST(Blend, VerticalWithATopOfCoverageZeroIsTheBase) {
  std::mt19937 rng(3);
  for (int i = 0; i < kTrials; ++i) {
    Material m;  // one per trial: evaluating a value costs the size of its DAG
    Slab top = randomSlab(m, rng), base = randomSlab(m, rng, /*features=*/i % 2 == 0);
    top.coverage = m.values.scalar(0);
    Slab r = blendVertical(m, top, base, m.values.scalar(1e-3));
    // The collapse drops anisotropy only where the top is present: here nowhere.
    expectSameSlab(m, r, base, 1e-9, "Ct=0");
  }
}

TEST(Blend, VerticalUnderAFullyTransparentTopKeepsTheBasesEnergy) {
  // A fully transparent top: the pair is the top's interface (here one that
  // reflects nothing) returning exactly the base's single-interface albedo as
  // the runtime reads it under a layer (interfaceUnderLayers: its interface
  // relative to the layer above, whose diffuse it gets back whole).
  std::mt19937 rng(4);
  for (int i = 0; i < kTrials; ++i) {
    Material m;  // one per trial: evaluating a value costs the size of its DAG
    Slab top = randomSlab(m, rng), base = randomSlab(m, rng, /*features=*/false);
    top.pin(SlabPin::F0) = m.values.splat(VType::Vec3, 0);
    top.pin(SlabPin::F90) = m.values.splat(VType::Vec3, 0);  // reflects at no angle
    top.pin(SlabPin::DiffuseAlbedo) = m.values.splat(VType::Vec3, 0);
    top.pin(SlabPin::FuzzAmount) = m.values.scalar(0);
    top.pin(SlabPin::Emissive) = m.values.splat(VType::Vec3, 0);
    top.pin(SlabPin::SssMfp) = m.values.splat(VType::Vec3, 1e9);
    Slab r = blendVertical(m, top, base, m.values.scalar(1e-3));
    ValueId scale;
    Slab expected = interfaceUnderLayers(m, foldToSingleInterface(m, base), scale),
         topFolded = foldToSingleInterface(m, top);
    V4 x = albedo(m, r), y = albedo(m, expected);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(x[c], y[c], 1e-4) << "albedo";
    for (SlabPin p : {SlabPin::Emissive, SlabPin::SssMfp}) {
      V4 a = eval(m, r.pin(p)), b = eval(m, expected.pin(p));
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(a[c], b[c], 1e-4) << slabPinInfo(p).name;
    }
    for (SlabPin p : {SlabPin::F0, SlabPin::F90, SlabPin::Roughness, SlabPin::Normal}) {
      V4 a = eval(m, r.pin(p)), b = eval(m, topFolded.pin(p));
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(a[c], b[c], 1e-4) << slabPinInfo(p).name;
    }
  }
}

TEST(Blend, CoverageAndEnergyNeverGrow) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < kTrials; ++i) {
    Material m;  // one per trial: evaluating a value costs the size of its DAG
    Slab a = randomSlab(m, rng), b = randomSlab(m, rng);
    double ca = u(rng), cb = u(rng), w = u(rng), d = 2e-3 * u(rng);
    a.coverage = m.values.scalar(ca);
    b.coverage = m.values.scalar(cb);
    V4 A = albedo(m, a), B = albedo(m, b);

    Slab h = blendHorizontal(m, a, b, m.values.scalar(w));
    double ch = coverage(m, h);
    EXPECT_LE(ch, std::max(ca, cb) + 1e-12);
    V4 H = albedo(m, h);
    for (int c = 0; c < 3; ++c) EXPECT_LE(ch * H[c], (1 - w) * ca * A[c] + w * cb * B[c] + 1e-3) << "horizontal";

    Slab ad = blendAdd(m, a, b);
    double cadd = coverage(m, ad);
    EXPECT_LE(cadd, std::min(1.0, ca + cb) + 1e-12);
    V4 AD = albedo(m, ad);
    for (int c = 0; c < 3; ++c) EXPECT_LE(cadd * AD[c], std::min(cadd, ca * A[c] + cb * B[c]) + 1e-3) << "add";

    Slab v = blendVertical(m, a, b, m.values.scalar(d));
    double cv = coverage(m, v);
    EXPECT_NEAR(cv, ca + cb * (1 - ca), 1e-12);
    V4 VV = albedo(m, v), mfp = eval(m, a.pin(SlabPin::SssMfp)), f0 = eval(m, a.pin(SlabPin::F0)),
       f90 = eval(m, a.pin(SlabPin::F90)), da = eval(m, a.pin(SlabPin::DiffuseAlbedo)),
       fca = eval(m, a.pin(SlabPin::FuzzColor));
    double faa = eval(m, a.pin(SlabPin::FuzzAmount))[0] * kFuzzAlbedo;
    for (int c = 0; c < 3; ++c) {
      double t2 = std::exp(-2 * d / std::max(mfp[c], 1e-30));
      double ft = f0[c] + (f90[c] - f0[c]) / 21.0;
      double volume = da[c] + (fca[c] - da[c]) * faa;  // the top's albedo, its fuzz folded in
      double stack = ft + (1 - ft) * (volume * (1 - t2) + t2 * cb * B[c]);
      EXPECT_LE(cv * VV[c], ca * stack + (1 - ca) * cb * B[c] + 1e-3) << "vertical channel " << c;
    }
  }
}

TEST(Blend, CoverageWeightScalesCoverageOnly) {
  std::mt19937 rng(6);
  Material m;
  Slab a = randomSlab(m, rng);
  Slab r = blendCoverageWeight(m, a, m.values.scalar(0.25));
  EXPECT_DOUBLE_EQ(coverage(m, r), 0.25);
  for (int p = 0; p < kSlabPinCount; ++p) EXPECT_EQ(r.pins[p], a.pins[p]);
}

// --- the loop -------------------------------------------------------------

std::string deepStack() {
  // 13 slabs under 12 operators, alternating vertical and horizontal, each
  // operator's left child a slab and its right child the next operator.
  std::string nodes, inputs = R"({"w": {"type": "float", "default": 0.5}})";
  for (int i = 0; i < 13; ++i)
    nodes += fmt::format(R"("s{}": {{"kind": "slab", "diffuse_albedo": {:.2f}, "roughness": {:.2f}, "sss_mfp": 10}},)",
                         i, 0.05 * i, 0.3 + 0.05 * i);
  for (int i = 0; i < 12; ++i) {
    std::string next = i == 11 ? "s12" : fmt::format("op{}", i + 1);
    if (i % 2 == 0)
      nodes += fmt::format(R"("op{}": {{"kind": "vertical", "top": "s{}", "base": "{}"}})", i, i, next);
    else
      nodes += fmt::format(R"("op{}": {{"kind": "horizontal", "background": "s{}", "foreground": "{}", "mix": "$w"}})",
                           i, i, next);
    if (i != 11) nodes += ",";
  }
  return test::material(nodes, inputs, "op0");
}

std::vector<std::string> stepsOf(const CompileResult& r) {
  std::vector<std::string> out;
  for (const auto& s : r.steps) out.push_back(s.action + " " + s.node);
  return out;
}

TEST(Simplify, ADeepStackSimplifiesToFourClosuresInAFixedOrder) {
  CompileOptions o;
  o.maxClosuresOverride = 4;
  Diagnostics d("stack.json");
  auto r = compileText("stack.json", deepStack(), o, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->before.closures.size(), 13u);
  EXPECT_EQ(r->after.closures.size(), 4u);
  // Deepest first: op11 is at depth 11, op10 at 10, ... each collapse makes
  // its parent the deepest operator.
  std::vector<std::string> expected;
  for (int i = 11; i >= 3; --i) expected.push_back(fmt::format("collapse op{}", i));
  EXPECT_EQ(stepsOf(*r), expected);
  Diagnostics d2("stack.json");
  auto again = compileText("stack.json", deepStack(), o, d2);
  ASSERT_TRUE(again);
  EXPECT_EQ(stepsOf(*again), stepsOf(*r));
}

TEST(Simplify, AtEqualDepthHorizontalGoesBeforeVertical) {
  std::string nodes = R"(
    "a": {"kind": "slab"}, "b": {"kind": "slab", "roughness": 0.2},
    "c": {"kind": "slab", "diffuse_albedo": 0, "sss_mfp": 5}, "d": {"kind": "slab", "roughness": 0.9},
    "v": {"kind": "vertical", "top": "c", "base": "d"},
    "h": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$w"},
    "root": {"kind": "add", "a": "v", "b": "h"})";
  CompileOptions o;
  o.maxClosuresOverride = 3;
  Diagnostics d("t.json");
  auto r = compileText("t.json", test::material(nodes, R"({"w": {"type": "float", "default": 0.5}})"), o, d);
  ASSERT_TRUE(r) << d.formatAll();
  ASSERT_EQ(r->steps.size(), 1u);
  EXPECT_EQ(r->steps[0].node, "h");
  EXPECT_EQ(r->steps[0].kind, "HORIZONTAL");
}

std::string readExample(const char* name) {
  std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/examples/" + name);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Simplify, TheCourseWorkedExample72To48To12) {
  CompileOptions o;
  o.maxClosuresOverride = 1;
  Diagnostics d("worked_example_72.json");
  auto r = compileText("worked_example_72.json", readExample("worked_example_72.json"), o, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->before.bytes(), 72);
  EXPECT_EQ(r->before.closures.size(), 3u);
  ASSERT_EQ(r->steps.size(), 2u);
  EXPECT_EQ(r->steps[0].kind, "HORIZONTAL");
  EXPECT_EQ(r->steps[0].bytesAfter, 48);
  EXPECT_EQ(r->steps[0].closuresAfter, 2);
  EXPECT_EQ(r->steps[1].kind, "VERTICAL");
  EXPECT_EQ(r->steps[1].bytesAfter, 12);
  EXPECT_EQ(r->steps[1].closuresAfter, 1);
  EXPECT_EQ(r->after.layoutClass, LayoutClass::Simple);
}

TEST(Simplify, FullSimplificationFitsARayTracingPayload) {
  CompileOptions o;
  o.fullSimplification = true;
  Diagnostics d("row60_glint.json");
  auto r = compileText("row60_glint.json", readExample("row60_glint.json"), o, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->after.closures.size(), 1u);
  EXPECT_LE(r->after.bytes(), kFullSimplificationBytes);
}

TEST(Simplify, AnUnreachableBudgetIsAClearError) {
  CompileOptions o;
  o.budgetOverride = 12;
  Diagnostics d("translucent_absorbing.json");
  auto r = compileText("translucent_absorbing.json", readExample("translucent_absorbing.json"), o, d);
  EXPECT_FALSE(r);
  EXPECT_EQ(d.formatAll(),
            "translucent_absorbing.json:1:1: error: material does not fit the budget of 12 bytes per pixel and 8 closures: the smallest reachable size is 16 bytes per pixel with 1 closure(s) [/]\n");
}

TEST(Simplify, DisablingFoldsHazeAndFuzzInsteadOfDroppingThem) {
  Material m = test::buildMaterial(test::material(
      R"("root": {"kind": "slab", "roughness": 0.2, "second_roughness": 0.8, "second_roughness_weight": 0.5,
                 "diffuse_albedo": 0.2, "fuzz_amount": 1, "fuzz_color": 1})"));
  disableFeature(m, kFeatHaze);
  disableFeature(m, kFeatFuzz);
  const Slab& s = m.slabs[0];
  EXPECT_NEAR(eval(m, s.pin(SlabPin::Roughness))[0], 0.5, 1e-12);
  EXPECT_NEAR(eval(m, s.pin(SlabPin::DiffuseAlbedo))[0], 0.2 + 0.8 * kFuzzAlbedo, 1e-12);
  analyzeFeatures(m);
  EXPECT_EQ(s.features & (kFeatHaze | kFeatFuzz), 0);
}

}  // namespace
}  // namespace substratec
