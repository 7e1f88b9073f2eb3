// Tests for pass 5, static culling (compiler/core/passes/cull.h), in the Tint
// style: the IR dump of a small material before the pass, the pass, the dump
// after it. Each rule of cull.h has its test; the NoModify_ tests show what
// the pass must leave alone (anything whose weight is not a constant 0 or 1).
#include "passes/cull.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "test_util.h"

namespace substratec {
namespace cull_test {

using test::diagnosticsOf;
using test::material;
using test::runUntil;

constexpr const char* kInputs = R"({
  "m": {"type": "float", "default": 0.5, "min": 0, "max": 1},
  "v": {"type": "float", "default": 0},
  "w": {"type": "float", "default": 0.5, "min": 0, "max": 1}
})";

class CullTest : public ::testing::Test {
 protected:
  /// Builds the tree of `nodes` (output "root"), checks its dump is `before`,
  /// culls it and returns the dump after.
  std::string cull(const std::string& nodes, const std::string& before) {
    m = runUntil(material(nodes, kInputs), "build-tree");
    EXPECT_EQ(dumpMaterial(m), before) << "(input dump)";
    Diagnostics d("test.json");
    ok = cullStaticMatter(m, d);
    diags = d.formatAll();
    return dumpMaterial(m);
  }
  /// For NoModify_ tests: the dump must be the same before and after.
  void expectUnchanged(const std::string& nodes, const std::string& dump) {
    EXPECT_EQ(cull(nodes, dump), dump);
    EXPECT_TRUE(ok);
    EXPECT_EQ(diags, "");
    EXPECT_TRUE(m.culled.empty());
  }

  Material m;
  bool ok = false;
  std::string diags;
};

// ---------------------------------------------------------------------------
// horizontal with a constant mix

TEST_F(CullTest, HorizontalMixConstantZeroKeepsTheBackground) {
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "foreground": "fg", "mix": 0})",
                    R"(HORIZONTAL root mix=0
  SLAB bg
      roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB bg
    roughness = 0.2
culled fg: foreground of horizontal 'root': mix is constant 0
culled root: horizontal with constant mix 0 replaced by its background
)");
  EXPECT_TRUE(ok);
}

TEST_F(CullTest, HorizontalMixConstantOneKeepsTheForeground) {
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "foreground": "fg", "mix": 1})",
                    R"(HORIZONTAL root mix=1
  SLAB bg
      roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB fg
    roughness = 0.8
culled bg: background of horizontal 'root': mix is constant 1
culled root: horizontal with constant mix 1 replaced by its foreground
)");
}

TEST_F(CullTest, HorizontalMixThatFoldsToAConstantIsConstant) {
  // one_minus(1) is folded to 0 when the value DAG is built.
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "foreground": "fg",
             "mix": {"kind": "one_minus", "x": 1}})",
                    R"(HORIZONTAL root mix=0
  SLAB bg
      roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB bg
    roughness = 0.2
culled fg: foreground of horizontal 'root': mix is constant 0
culled root: horizontal with constant mix 0 replaced by its background
)");
}

TEST_F(CullTest, KeptSideIsCulledToo) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "kept": {"kind": "coverage_weight", "a": "b", "weight": 1},
    "root": {"kind": "horizontal", "background": "a", "foreground": "kept", "mix": 1})",
                    R"(HORIZONTAL root mix=1
  SLAB a
      roughness = 0.2
  WEIGHT kept weight=1
    SLAB b
        roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB b
    roughness = 0.8
culled a: background of horizontal 'root': mix is constant 1
culled root: horizontal with constant mix 1 replaced by its foreground
culled kept: coverage_weight with constant weight 1 removed (no effect)
)");
}

TEST_F(CullTest, NoModify_HorizontalWithARunTimeMix) {
  expectUnchanged(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "foreground": "fg", "mix": "$m"})",
                  R"(HORIZONTAL root mix=$m
  SLAB bg
      roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
}

TEST_F(CullTest, NoModify_HorizontalWithAConstantMixStrictlyBetweenZeroAndOne) {
  expectUnchanged(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "foreground": "fg", "mix": 0.001})",
                  R"(HORIZONTAL root mix=0.001
  SLAB bg
      roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
}

// ---------------------------------------------------------------------------
// coverage_weight with a constant weight

TEST_F(CullTest, CoverageWeightZeroRemovesItsSubtree) {
  auto after = cull(R"(
    "coat": {"kind": "slab", "roughness": 0.1},
    "base": {"kind": "slab", "roughness": 0.6},
    "worn": {"kind": "coverage_weight", "a": "coat", "weight": 0},
    "root": {"kind": "vertical", "top": "worn", "base": "base"})",
                    R"(VERTICAL root thickness=0.0001
  WEIGHT worn weight=0
    SLAB coat
        roughness = 0.1
  SLAB base
      roughness = 0.6
)");
  EXPECT_EQ(after, R"(SLAB base
    roughness = 0.6
culled coat: under coverage_weight 'worn': weight is constant 0
culled worn: coverage_weight with constant weight 0 removed with its subtree
culled root: VERTICAL 'root' removed: one side is empty
)");
}

TEST_F(CullTest, CoverageWeightOneDisappears) {
  auto after = cull(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": 1})",
                    R"(WEIGHT root weight=1
  SLAB s
      roughness = 0.3
)");
  EXPECT_EQ(after, R"(SLAB s
    roughness = 0.3
culled root: coverage_weight with constant weight 1 removed (no effect)
)");
}

TEST_F(CullTest, NoModify_CoverageWeightOneHalf) {
  expectUnchanged(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": 0.5})",
                  R"(WEIGHT root weight=0.5
  SLAB s
      roughness = 0.3
)");
}

TEST_F(CullTest, NoModify_CoverageWeightOfAnInput) {
  // The input's default is 0.5, but it is a run-time value: nothing is constant.
  expectUnchanged(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": "$w"})",
                  R"(WEIGHT root weight=$w
  SLAB s
      roughness = 0.3
)");
}

// ---------------------------------------------------------------------------
// select with a constant value

TEST_F(CullTest, SelectWithAConstantValueAtMostTheThresholdKeepsA) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "b": "b", "value": 0.2})",
                    R"(SELECT root value=0.2 threshold=0.5
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB a
    roughness = 0.2
culled b: side b of select 'root': the constant value always picks a
culled root: select with a constant value replaced by side a
)");
}

TEST_F(CullTest, SelectWithAConstantValueAboveTheThresholdKeepsB) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "b": "b", "value": 0.3, "threshold": 0.25})",
                    R"(SELECT root value=0.3 threshold=0.25
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB b
    roughness = 0.8
culled a: side a of select 'root': the constant value always picks b
culled root: select with a constant value replaced by side b
)");
}

TEST_F(CullTest, SelectValueEqualToTheThresholdKeepsA) {
  // "a when value <= threshold".
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "b": "b", "value": 0.5})",
                    R"(SELECT root value=0.5 threshold=0.5
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB a
    roughness = 0.2
culled b: side b of select 'root': the constant value always picks a
culled root: select with a constant value replaced by side a
)");
}

TEST_F(CullTest, NoModify_SelectOnAnInput) {
  expectUnchanged(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "b": "b", "value": "$v"})",
                  R"(SELECT root value=$v threshold=0.5
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
}

TEST_F(CullTest, NoModify_SelectWithAConstantValueAndARunTimeThreshold) {
  expectUnchanged(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "b": "b", "value": 0.2, "threshold": "$v"})",
                  R"(SELECT root value=0.2 threshold=$v
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
}

// ---------------------------------------------------------------------------
// Operators left with one empty side

TEST_F(CullTest, VerticalWithAnEmptyBaseKeepsItsTop) {
  auto after = cull(R"(
    "coat": {"kind": "slab", "roughness": 0.1},
    "base": {"kind": "slab", "roughness": 0.6},
    "gone": {"kind": "coverage_weight", "a": "base", "weight": 0},
    "root": {"kind": "vertical", "top": "coat", "base": "gone"})",
                    R"(VERTICAL root thickness=0.0001
  SLAB coat
      roughness = 0.1
  WEIGHT gone weight=0
    SLAB base
        roughness = 0.6
)");
  EXPECT_EQ(after, R"(SLAB coat
    roughness = 0.1
culled base: under coverage_weight 'gone': weight is constant 0
culled gone: coverage_weight with constant weight 0 removed with its subtree
culled root: VERTICAL 'root' removed: one side is empty
)");
}

TEST_F(CullTest, AddWithAnEmptySideKeepsTheOtherSide) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "add", "a": {"kind": "coverage_weight", "a": "a", "weight": 0}, "b": "b"})",
                    R"(ADD root
  WEIGHT root_a weight=0
    SLAB a
        roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(SLAB b
    roughness = 0.8
culled a: under coverage_weight 'root_a': weight is constant 0
culled root_a: coverage_weight with constant weight 0 removed with its subtree
culled root: ADD 'root' removed: one side is empty
)");
}

TEST_F(CullTest, HorizontalWithAnEmptyForegroundWeighsTheBackgroundByOneMinusMix) {
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "mix": "$m",
             "foreground": {"kind": "coverage_weight", "a": "fg", "weight": 0}})",
                    R"(HORIZONTAL root mix=$m
  SLAB bg
      roughness = 0.2
  WEIGHT root_foreground weight=0
    SLAB fg
        roughness = 0.8
)");
  EXPECT_EQ(after, R"(WEIGHT root weight=one_minus($m)
  SLAB bg
      roughness = 0.2
culled fg: under coverage_weight 'root_foreground': weight is constant 0
culled root_foreground: coverage_weight with constant weight 0 removed with its subtree
culled root: horizontal 'root' with an empty side is a coverage_weight
)");
}

TEST_F(CullTest, HorizontalWithAnEmptyBackgroundWeighsTheForegroundByMix) {
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "foreground": "fg", "mix": "$m",
             "background": {"kind": "coverage_weight", "a": "bg", "weight": 0}})",
                    R"(HORIZONTAL root mix=$m
  WEIGHT root_background weight=0
    SLAB bg
        roughness = 0.2
  SLAB fg
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(WEIGHT root weight=$m
  SLAB fg
      roughness = 0.8
culled bg: under coverage_weight 'root_background': weight is constant 0
culled root_background: coverage_weight with constant weight 0 removed with its subtree
culled root: horizontal 'root' with an empty side is a coverage_weight
)");
}

TEST_F(CullTest, HorizontalWithAnEmptySideAndAConstantMixFoldsTheWeight) {
  auto after = cull(R"(
    "bg": {"kind": "slab", "roughness": 0.2},
    "fg": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "bg", "mix": 0.25,
             "foreground": {"kind": "coverage_weight", "a": "fg", "weight": 0}})",
                    R"(HORIZONTAL root mix=0.25
  SLAB bg
      roughness = 0.2
  WEIGHT root_foreground weight=0
    SLAB fg
        roughness = 0.8
)");
  EXPECT_EQ(after, R"(WEIGHT root weight=0.75
  SLAB bg
      roughness = 0.2
culled fg: under coverage_weight 'root_foreground': weight is constant 0
culled root_foreground: coverage_weight with constant weight 0 removed with its subtree
culled root: horizontal 'root' with an empty side is a coverage_weight
)");
}

TEST_F(CullTest, SelectWithAnEmptyBKeepsAWeightedByTheCondition) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "a": "a", "value": "$v", "threshold": 0.25,
             "b": {"kind": "coverage_weight", "a": "b", "weight": 0}})",
                    R"(SELECT root value=$v threshold=0.25
  SLAB a
      roughness = 0.2
  WEIGHT root_b weight=0
    SLAB b
        roughness = 0.8
)");
  // step(value, threshold) = threshold >= value: 1 exactly when a is picked.
  EXPECT_EQ(after, R"(WEIGHT root weight=step($v, 0.25)
  SLAB a
      roughness = 0.2
culled b: under coverage_weight 'root_b': weight is constant 0
culled root_b: coverage_weight with constant weight 0 removed with its subtree
culled root: select 'root' with an empty side is a coverage_weight
)");
}

TEST_F(CullTest, SelectWithAnEmptyAKeepsBWeightedByTheOppositeCondition) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "select", "b": "b", "value": "$v",
             "a": {"kind": "coverage_weight", "a": "a", "weight": 0}})",
                    R"(SELECT root value=$v threshold=0.5
  WEIGHT root_a weight=0
    SLAB a
        roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(WEIGHT root weight=one_minus(step($v, 0.5))
  SLAB b
      roughness = 0.8
culled a: under coverage_weight 'root_a': weight is constant 0
culled root_a: coverage_weight with constant weight 0 removed with its subtree
culled root: select 'root' with an empty side is a coverage_weight
)");
}

TEST_F(CullTest, EmptinessPropagatesUpwards) {
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "keep": {"kind": "slab", "roughness": 0.4},
    "both": {"kind": "add", "a": {"kind": "coverage_weight", "a": "a", "weight": 0},
                            "b": {"kind": "coverage_weight", "a": "b", "weight": 0}},
    "root": {"kind": "vertical", "top": "both", "base": "keep"})",
                    R"(VERTICAL root thickness=0.0001
  ADD both
    WEIGHT both_a weight=0
      SLAB a
          roughness = 0.2
    WEIGHT both_b weight=0
      SLAB b
          roughness = 0.8
  SLAB keep
      roughness = 0.4
)");
  EXPECT_EQ(after, R"(SLAB keep
    roughness = 0.4
culled a: under coverage_weight 'both_a': weight is constant 0
culled both_a: coverage_weight with constant weight 0 removed with its subtree
culled b: under coverage_weight 'both_b': weight is constant 0
culled both_b: coverage_weight with constant weight 0 removed with its subtree
culled both: ADD 'both' removed: both sides are empty
culled root: VERTICAL 'root' removed: one side is empty
)");
}

TEST_F(CullTest, NoModify_RunTimeWeightsAllTheWayDown) {
  expectUnchanged(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "c": {"kind": "slab", "roughness": 0.4},
    "root": {"kind": "vertical", "top": {"kind": "coverage_weight", "a": "a", "weight": "$w"},
             "base": {"kind": "add", "a": "b",
                      "b": {"kind": "select", "a": "c", "b": "a", "value": "$v"}}})",
                  R"(VERTICAL root thickness=0.0001
  WEIGHT root_top weight=$w
    SLAB a
        roughness = 0.2
  ADD root_base
    SLAB b
        roughness = 0.8
    SELECT root_base_b value=$v threshold=0.5
      SLAB c
          roughness = 0.4
      SLAB a_2
          roughness = 0.2
)");
}

// "Every removal is recorded in Material::culled with the reason." BUG: a
// coverage_weight with a run-time weight whose subtree becomes empty is
// removed silently: `outer` is gone from the tree but has no CullNote.
TEST_F(CullTest, CoverageWeightWithAnEmptiedSubtreeIsRecorded) {
  cull(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "outer": {"kind": "coverage_weight", "weight": "$w",
              "a": {"kind": "coverage_weight", "a": "b", "weight": 0}},
    "root": {"kind": "add", "a": "a", "b": "outer"})",
       R"(ADD root
  SLAB a
      roughness = 0.2
  WEIGHT outer weight=$w
    WEIGHT outer_a weight=0
      SLAB b
          roughness = 0.8
)");
  std::vector<std::string> what;
  for (const CullNote& n : m.culled) what.push_back(n.what);
  EXPECT_EQ(what, (std::vector<std::string>{"b", "outer_a", "outer", "root"}));
}

// ---------------------------------------------------------------------------
// a vertical whose top is opaque (issue 16, "A clear coat that is not clear")

TEST_F(CullTest, AnOpaqueTopHidesTheBase) {
  // No sss_mfp: no medium, so a layer of thickness 1e-4 transmits exp(-d/0) = 0.
  auto after = cull(R"(
    "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": "coat", "base": "paint"})",
                    R"(VERTICAL root thickness=0.0001
  SLAB coat
      diffuse_albedo = 0
  SLAB paint
      roughness = 0.6
)");
  EXPECT_EQ(after, R"(SLAB coat
    diffuse_albedo = 0
culled paint: base of vertical 'root': hidden by its opaque top 'coat'
culled root: vertical 'root' replaced by its top: the top is opaque
)");
  EXPECT_TRUE(ok);
  EXPECT_EQ(diags,
            "test.json: warning: 'coat' hides the base 'paint' of vertical 'root': it has no medium (sss_mfp is 0 or absent), so no light crosses it; to make it a transparent coat give it an sss_mfp (e.g. 1e6 for a clear coat), or one from a transmittance with the `transmittance_to_mfp` helper [/nodes/coat]\n");
}

TEST_F(CullTest, AnOpaqueMixOfCoatsHidesTheBase) {
  // Both sides opaque: C = 1, T = 0 whatever the mix.
  auto after = cull(R"(
    "a": {"kind": "slab", "roughness": 0.2, "sss_mfp": 0},
    "b": {"kind": "slab", "roughness": 0.8},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"},
             "base": "paint", "thickness": 0.001})",
                    R"(VERTICAL root thickness=0.001
  HORIZONTAL root_top mix=$m
    SLAB a
        roughness = 0.2
    SLAB b
        roughness = 0.8
  SLAB paint
      roughness = 0.6
)");
  EXPECT_EQ(after, R"(HORIZONTAL root_top mix=$m
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
culled paint: base of vertical 'root': hidden by its opaque top 'root_top'
culled root: vertical 'root' replaced by its top: the top is opaque
)");
  EXPECT_NE(diags.find("test.json: warning: 'root_top' hides the base 'paint'"), std::string::npos) << diags;
  EXPECT_NE(diags.find("helper [/nodes/root/top]\n"), std::string::npos) << diags;
}

TEST_F(CullTest, OpaqueTopsOverOpaqueTopsCollapseToTheVisibleOne) {
  // Thirteen slabs, each the opaque top of the next: only the first can show.
  std::string nodes;
  for (int k = 0; k < 13; ++k) nodes += fmt::format(R"("s{}": {{"kind": "slab", "roughness": 0.{}}}, )", k, k % 10);
  for (int k = 0; k < 12; ++k)
    nodes += fmt::format(R"("{}": {{"kind": "vertical", "top": "s{}", "base": "{}"}}{})", k == 0 ? "root" : fmt::format("v{}", k),
                         k, k == 11 ? "s12" : fmt::format("v{}", k + 1), k == 11 ? "" : ", ");
  m = runUntil(material(nodes, kInputs), "build-tree");
  Diagnostics d("test.json");
  ASSERT_TRUE(cullStaticMatter(m, d));
  EXPECT_EQ(dumpMaterial(m).substr(0, dumpMaterial(m).find("culled")), "SLAB s0\n    roughness = 0\n");
  // Every vertical replaced by its top, every hidden base recorded.
  int bases = 0, verticals = 0;
  for (const CullNote& n : m.culled) {
    bases += n.why.starts_with("base of vertical") ? 1 : 0;
    verticals += n.why.find("replaced by its top: the top is opaque") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(bases, 12);
  EXPECT_EQ(verticals, 12);
  EXPECT_FALSE(d.hasErrors()) << d.formatAll();
}

TEST_F(CullTest, NoModify_ATopWithAMedium) {
  expectUnchanged(R"(
    "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "sss_mfp": 1000000},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": "coat", "base": "paint"})",
                  R"(VERTICAL root thickness=0.0001
  SLAB coat
      diffuse_albedo = 0
      sss_mfp = 1e+06
  SLAB paint
      roughness = 0.6
)");
}

TEST_F(CullTest, NoModify_AnOpaqueTopOfNoThickness) {
  // Thickness 0: the layer has no extent and lets everything through (T = 1).
  expectUnchanged(R"(
    "coat": {"kind": "slab", "f0": 0.04},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": "coat", "base": "paint", "thickness": 0})",
                  R"(VERTICAL root thickness=0
  SLAB coat
  SLAB paint
      roughness = 0.6
)");
}

TEST_F(CullTest, NoModify_AnOpaqueTopOfRunTimeCoverage) {
  // Where the coat is absent the base shows.
  expectUnchanged(R"(
    "coat": {"kind": "slab"},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": {"kind": "coverage_weight", "a": "coat", "weight": "$w"}, "base": "paint"})",
                  R"(VERTICAL root thickness=0.0001
  WEIGHT root_top weight=$w
    SLAB coat
  SLAB paint
      roughness = 0.6
)");
}

TEST_F(CullTest, NoModify_AnOpaqueTopMixedWithATransparentOne) {
  expectUnchanged(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8, "sss_mfp": 10},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"},
             "base": "paint"})",
                  R"(VERTICAL root thickness=0.0001
  HORIZONTAL root_top mix=$m
    SLAB a
        roughness = 0.2
    SLAB b
        roughness = 0.8
        sss_mfp = 10
  SLAB paint
      roughness = 0.6
)");
}

TEST_F(CullTest, AnOpaqueTopOfRunTimeThicknessWarnsButStays) {
  // Hidden for every thickness > 0, shown at exactly 0: kept, with the warning.
  const std::string dump = R"(VERTICAL root thickness=$v
  SLAB coat
  SLAB paint
      roughness = 0.6
)";
  EXPECT_EQ(cull(R"(
    "coat": {"kind": "slab", "f0": 0.04},
    "paint": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": "coat", "base": "paint", "thickness": "$v"})",
                 dump),
            dump);
  EXPECT_TRUE(m.culled.empty());
  EXPECT_NE(diags.find("test.json: warning: 'coat' hides the base 'paint' of vertical 'root' whenever "
                       "its thickness is > 0"),
            std::string::npos)
      << diags;
  EXPECT_NE(diags.find("helper [/nodes/coat]\n"), std::string::npos) << diags;
}

TEST_F(CullTest, NoModify_AnOpaqueTopThatWouldTurnTransparentOutsideItsVertical) {
  // `inner`'s top is opaque at inner's thickness, but replacing `inner` by it
  // would put `coat` in the layer of `root` (thickness 0: transparent), and
  // `hidden` would show: kept, with the warning. (`root`'s top mixes in a
  // transparent slab, so `under` shows too.)
  const std::string dump = R"(VERTICAL root thickness=0
  HORIZONTAL root_top mix=$m
    VERTICAL inner thickness=0.001
      SLAB coat
      SLAB hidden
          roughness = 0.6
    SLAB clear
        sss_mfp = 10
  SLAB under
      roughness = 0.3
)";
  EXPECT_EQ(cull(R"(
    "coat": {"kind": "slab", "f0": 0.04},
    "hidden": {"kind": "slab", "roughness": 0.6},
    "clear": {"kind": "slab", "sss_mfp": 10},
    "under": {"kind": "slab", "roughness": 0.3},
    "inner": {"kind": "vertical", "top": "coat", "base": "hidden", "thickness": 0.001},
    "root": {"kind": "vertical", "top": {"kind": "horizontal", "background": "inner", "foreground": "clear", "mix": "$m"},
              "base": "under", "thickness": 0})",
                 dump),
            dump);
  EXPECT_TRUE(m.culled.empty());
  EXPECT_EQ(diags,
            "test.json: warning: 'coat' hides the base 'hidden' of vertical 'inner': it has no medium (sss_mfp is 0 or absent), so no light crosses it; to make it a transparent coat give it an sss_mfp (e.g. 1e6 for a clear coat), or one from a transmittance with the `transmittance_to_mfp` helper [/nodes/coat]\n");
}

TEST_F(CullTest, AnOpaqueTopInsideAnOpaqueTopIsCulledInTheNextRound) {
  // Round 1: `root`'s top `inner` is opaque (its top `coat` is), so `under`
  // goes and `root` becomes `inner`; `coat` could not hide `hidden` yet (it
  // sat in outer's layer of thickness 0). Round 2: `inner` is at the surface
  // (thickness 1e-4): `coat` stays opaque there, `hidden` goes.
  auto after = cull(R"(
    "coat": {"kind": "slab", "f0": 0.04},
    "hidden": {"kind": "slab", "roughness": 0.6},
    "under": {"kind": "slab", "roughness": 0.3},
    "inner": {"kind": "vertical", "top": "coat", "base": "hidden", "thickness": 0.001},
    "root": {"kind": "vertical", "top": "inner", "base": "under", "thickness": 0})",
                    R"(VERTICAL root thickness=0
  VERTICAL inner thickness=0.001
    SLAB coat
    SLAB hidden
        roughness = 0.6
  SLAB under
      roughness = 0.3
)");
  EXPECT_EQ(after, R"(SLAB coat
culled under: base of vertical 'root': hidden by its opaque top 'inner'
culled root: vertical 'root' replaced by its top: the top is opaque
culled hidden: base of vertical 'inner': hidden by its opaque top 'coat'
culled inner: vertical 'inner' replaced by its top: the top is opaque
)");
  EXPECT_TRUE(ok);
}

// ---------------------------------------------------------------------------
// Nothing left

TEST_F(CullTest, NothingLeftIsAnError) {
  cull(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": 0})",
       R"(WEIGHT root weight=0
  SLAB s
      roughness = 0.3
)");
  EXPECT_FALSE(ok);
  EXPECT_EQ(diags,
            "test.json: error: no matter is left after static culling (every slab is under a constant zero weight) [/output]\n");
}

TEST_F(CullTest, NothingLeftThroughOperatorsIsAnError) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "a": {"kind": "slab"},
    "b": {"kind": "slab"},
    "root": {"kind": "horizontal", "mix": "$m",
             "background": {"kind": "coverage_weight", "a": "a", "weight": 0},
             "foreground": {"kind": "select", "a": "b", "b": "a", "value": 0.25,
                            "threshold": {"kind": "multiply", "a": 0.5, "b": 0}}})",
                                   kInputs)),
            "");  // the select keeps its side b (0.25 > 0), so the foreground stays
  EXPECT_EQ(diagnosticsOf(material(R"(
    "a": {"kind": "slab"},
    "b": {"kind": "slab"},
    "root": {"kind": "horizontal", "mix": "$m",
             "background": {"kind": "coverage_weight", "a": "a", "weight": 0},
             "foreground": {"kind": "select", "a": "b", "b": {"kind": "coverage_weight", "a": "a", "weight": 0},
                            "value": 0.25, "threshold": 0}})",
                                   kInputs)),
            "test.json:11:73: error: no matter is left after static culling (every slab is under a constant zero weight) [/output]\n");
}

}  // namespace cull_test
}  // namespace substratec
