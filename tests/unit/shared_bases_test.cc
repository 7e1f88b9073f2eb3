// Tests for pass 7, shared local bases (compiler/core/passes/shared_bases.h):
// slabs whose normal (and, when anisotropic, tangent) are the same value-DAG
// node share one basis; isotropic slabs join the first basis with their
// normal; bases are numbered in closure (pre-)order. Dump before the pass,
// the pass, dump after.
#include "passes/shared_bases.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace substratec {
namespace shared_bases_test {

using test::material;
using test::runUntil;

constexpr const char* kInputs = R"({
  "m": {"type": "float", "default": 0.5},
  "nA": {"type": "vec3", "default": [0, 0, 1]},
  "nB": {"type": "vec3", "default": [0, 0.6, 0.8]},
  "tA": {"type": "vec3", "default": [1, 0, 0]},
  "tB": {"type": "vec3", "default": [0, 1, 0]},
  "nm": {"type": "texture2d"}
})";

class SharedBasesTest : public ::testing::Test {
 protected:
  std::string run(const std::string& nodes, const std::string& before) {
    m = runUntil(material(nodes, kInputs), "features");
    EXPECT_EQ(dumpMaterial(m), before) << "(input dump)";
    shareLocalBases(m);
    return dumpMaterial(m);
  }
  Material m;
};

TEST_F(SharedBasesTest, SlabsWithTheSameNormalShareABasis) {
  auto after = run(R"(
    "a": {"kind": "slab", "normal": "$nA", "roughness": 0.2},
    "b": {"kind": "slab", "normal": "$nA", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
                   R"(HORIZONTAL root mix=$m
  SLAB a
      roughness = 0.2
      normal = $nA
  SLAB b
      roughness = 0.8
      normal = $nA
)");
  EXPECT_EQ(after, R"(HORIZONTAL root mix=$m
  SLAB a
      roughness = 0.2
      normal = $nA
      basis = 0
  SLAB b
      roughness = 0.8
      normal = $nA
      basis = 0
basis 0: normal = $nA
)");
  ASSERT_EQ(m.bases.size(), 1u);
  EXPECT_EQ(m.bases[0].slabs, (std::vector<int>{0, 1}));
  EXPECT_EQ(m.bases[0].tangent, kNoValue);
}

// The verticals below have a thickness of 0: their tops have no medium
// (sss_mfp), so with a thickness they would hide their bases (cull.h).
TEST_F(SharedBasesTest, DefaultNormalsShareABasis) {
  auto after = run(R"(
    "a": {"kind": "slab", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "vertical", "top": "a", "base": "b", "thickness": 0})",
                   R"(VERTICAL root thickness=0
  SLAB a
      roughness = 0.2
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(VERTICAL root thickness=0
  SLAB a
      roughness = 0.2
      basis = 0
  SLAB b
      roughness = 0.8
      basis = 0
basis 0: normal = normal
)");
}

TEST_F(SharedBasesTest, StructurallyEqualNormalExpressionsShareABasis) {
  // Two inline expressions, written separately, are one DAG node.
  auto after = run(R"(
    "a": {"kind": "slab", "roughness": 0.2,
          "normal": {"kind": "normalize", "x": {"kind": "texture", "texture": "$nm"}}},
    "b": {"kind": "slab", "roughness": 0.8,
          "normal": {"kind": "normalize", "x": {"kind": "texture", "texture": "$nm"}}},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                   R"(ADD root
  SLAB a
      roughness = 0.2
      normal = normalize(swizzle.xyz(texture($nm, uv0)))
  SLAB b
      roughness = 0.8
      normal = normalize(swizzle.xyz(texture($nm, uv0)))
)");
  EXPECT_EQ(after, R"(ADD root
  SLAB a
      roughness = 0.2
      normal = normalize(swizzle.xyz(texture($nm, uv0)))
      basis = 0
  SLAB b
      roughness = 0.8
      normal = normalize(swizzle.xyz(texture($nm, uv0)))
      basis = 0
basis 0: normal = normalize(swizzle.xyz(texture($nm, uv0)))
)");
}

TEST_F(SharedBasesTest, DifferentNormalsDoNotShare) {
  auto after = run(R"(
    "a": {"kind": "slab", "normal": "$nA", "roughness": 0.2},
    "b": {"kind": "slab", "normal": "$nB", "roughness": 0.8},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
                   R"(HORIZONTAL root mix=$m
  SLAB a
      roughness = 0.2
      normal = $nA
  SLAB b
      roughness = 0.8
      normal = $nB
)");
  EXPECT_EQ(after, R"(HORIZONTAL root mix=$m
  SLAB a
      roughness = 0.2
      normal = $nA
      basis = 0
  SLAB b
      roughness = 0.8
      normal = $nB
      basis = 1
basis 0: normal = $nA
basis 1: normal = $nB
)");
}

TEST_F(SharedBasesTest, NormalsWithTheSameValueButDifferentExpressionsDoNotShare) {
  // $nA defaults to (0, 0, 1), the geometric normal in tangent space, but it is
  // another expression: sharing is structural, not numerical.
  auto after = run(R"(
    "a": {"kind": "slab", "normal": "$nA", "roughness": 0.2},
    "b": {"kind": "slab", "roughness": 0.8},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                   R"(ADD root
  SLAB a
      roughness = 0.2
      normal = $nA
  SLAB b
      roughness = 0.8
)");
  EXPECT_EQ(after, R"(ADD root
  SLAB a
      roughness = 0.2
      normal = $nA
      basis = 0
  SLAB b
      roughness = 0.8
      basis = 1
basis 0: normal = $nA
basis 1: normal = normal
)");
}

// ---------------------------------------------------------------------------
// Tangents

TEST_F(SharedBasesTest, AnisotropicSlabsWithDifferentTangentsGetDifferentBases) {
  auto after = run(R"(
    "a": {"kind": "slab", "anisotropy": 0.5, "tangent": "$tA"},
    "b": {"kind": "slab", "anisotropy": 0.5, "tangent": "$tB"},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
                   R"(HORIZONTAL root mix=$m
  SLAB a
      anisotropy = 0.5
      tangent = $tA
      features = anisotropy
  SLAB b
      anisotropy = 0.5
      tangent = $tB
      features = anisotropy
)");
  EXPECT_EQ(after, R"(HORIZONTAL root mix=$m
  SLAB a
      anisotropy = 0.5
      tangent = $tA
      features = anisotropy
      basis = 0
  SLAB b
      anisotropy = 0.5
      tangent = $tB
      features = anisotropy
      basis = 1
basis 0: normal = normal, tangent = $tA
basis 1: normal = normal, tangent = $tB
)");
}

TEST_F(SharedBasesTest, AnisotropicSlabsWithTheSameNormalAndTangentShare) {
  auto after = run(R"(
    "a": {"kind": "slab", "anisotropy": 0.5},
    "b": {"kind": "slab", "anisotropy": -0.5},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
                   R"(HORIZONTAL root mix=$m
  SLAB a
      anisotropy = 0.5
      features = anisotropy
  SLAB b
      anisotropy = -0.5
      features = anisotropy
)");
  EXPECT_EQ(after, R"(HORIZONTAL root mix=$m
  SLAB a
      anisotropy = 0.5
      features = anisotropy
      basis = 0
  SLAB b
      anisotropy = -0.5
      features = anisotropy
      basis = 0
basis 0: normal = normal, tangent = tangent
)");
}

TEST_F(SharedBasesTest, AnisotropicSlabsWithTheSameTangentButDifferentNormalsDoNotShare) {
  auto after = run(R"(
    "a": {"kind": "slab", "anisotropy": 0.5, "normal": "$nA"},
    "b": {"kind": "slab", "anisotropy": 0.5, "normal": "$nB"},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                   R"(ADD root
  SLAB a
      anisotropy = 0.5
      normal = $nA
      features = anisotropy
  SLAB b
      anisotropy = 0.5
      normal = $nB
      features = anisotropy
)");
  EXPECT_EQ(after, R"(ADD root
  SLAB a
      anisotropy = 0.5
      normal = $nA
      features = anisotropy
      basis = 0
  SLAB b
      anisotropy = 0.5
      normal = $nB
      features = anisotropy
      basis = 1
basis 0: normal = $nA, tangent = tangent
basis 1: normal = $nB, tangent = tangent
)");
}

TEST_F(SharedBasesTest, IsotropicSlabJoinsAnAnisotropicBasisWithTheSameNormal) {
  // The isotropic coat comes first in closure order, the anisotropic base
  // fixes the tangent; the coat's own tangent pin does not matter.
  auto after = run(R"(
    "coat": {"kind": "slab", "roughness": 0.1, "tangent": "$tB"},
    "base": {"kind": "slab", "anisotropy": 0.7, "tangent": "$tA"},
    "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0})",
                   R"(VERTICAL root thickness=0
  SLAB coat
      roughness = 0.1
      tangent = $tB
  SLAB base
      anisotropy = 0.7
      tangent = $tA
      features = anisotropy
)");
  EXPECT_EQ(after, R"(VERTICAL root thickness=0
  SLAB coat
      roughness = 0.1
      tangent = $tB
      basis = 0
  SLAB base
      anisotropy = 0.7
      tangent = $tA
      features = anisotropy
      basis = 0
basis 0: normal = normal, tangent = $tA
)");
}

TEST_F(SharedBasesTest, NoModify_IsotropicSlabsIgnoreTheirTangent) {
  auto after = run(R"(
    "a": {"kind": "slab", "tangent": "$tA"},
    "b": {"kind": "slab", "tangent": "$tB"},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                   R"(ADD root
  SLAB a
      tangent = $tA
  SLAB b
      tangent = $tB
)");
  EXPECT_EQ(after, R"(ADD root
  SLAB a
      tangent = $tA
      basis = 0
  SLAB b
      tangent = $tB
      basis = 0
basis 0: normal = normal
)");
}

TEST_F(SharedBasesTest, IsotropicSlabJoinsTheFirstOfSeveralBasesWithItsNormal) {
  auto after = run(R"(
    "a": {"kind": "slab", "anisotropy": 0.5, "tangent": "$tA"},
    "b": {"kind": "slab", "anisotropy": 0.5, "tangent": "$tB"},
    "c": {"kind": "slab", "roughness": 0.9},
    "root": {"kind": "add", "a": "c", "b": {"kind": "add", "a": "b", "b": "a"}})",
                   R"(ADD root
  SLAB c
      roughness = 0.9
  ADD root_b
    SLAB b
        anisotropy = 0.5
        tangent = $tB
        features = anisotropy
    SLAB a
        anisotropy = 0.5
        tangent = $tA
        features = anisotropy
)");
  // Closure order c, b, a: c joins b's basis (the first anisotropic one in
  // closure order), which therefore is basis 0.
  EXPECT_EQ(after, R"(ADD root
  SLAB c
      roughness = 0.9
      basis = 0
  ADD root_b
    SLAB b
        anisotropy = 0.5
        tangent = $tB
        features = anisotropy
        basis = 0
    SLAB a
        anisotropy = 0.5
        tangent = $tA
        features = anisotropy
        basis = 1
basis 0: normal = normal, tangent = $tB
basis 1: normal = normal, tangent = $tA
)");
}

// ---------------------------------------------------------------------------
// Numbering

TEST_F(SharedBasesTest, BasesAreNumberedInClosureOrder) {
  // File order a, b; closure (pre-)order top before base: b, a.
  auto after = run(R"(
    "a": {"kind": "slab", "normal": "$nA"},
    "b": {"kind": "slab", "normal": "$nB"},
    "root": {"kind": "vertical", "top": "b", "base": "a", "thickness": 0})",
                   R"(VERTICAL root thickness=0
  SLAB b
      normal = $nB
  SLAB a
      normal = $nA
)");
  EXPECT_EQ(after, R"(VERTICAL root thickness=0
  SLAB b
      normal = $nB
      basis = 0
  SLAB a
      normal = $nA
      basis = 1
basis 0: normal = $nB
basis 1: normal = $nA
)");
}

TEST_F(SharedBasesTest, NumberingFollowsClosureOrderNotCreationOrder) {
  // The anisotropic slabs are placed first (y then z), then x joins z's
  // normal; x is the first closure, so z's basis becomes basis 0.
  auto after = run(R"(
    "x": {"kind": "slab", "normal": "$nA"},
    "y": {"kind": "slab", "normal": "$nB", "anisotropy": 0.3},
    "z": {"kind": "slab", "normal": "$nA", "anisotropy": 0.3, "tangent": "$tA"},
    "root": {"kind": "vertical", "top": "x", "base": {"kind": "add", "a": "y", "b": "z"}, "thickness": 0})",
                   R"(VERTICAL root thickness=0
  SLAB x
      normal = $nA
  ADD root_base
    SLAB y
        anisotropy = 0.3
        normal = $nB
        features = anisotropy
    SLAB z
        anisotropy = 0.3
        normal = $nA
        tangent = $tA
        features = anisotropy
)");
  EXPECT_EQ(after, R"(VERTICAL root thickness=0
  SLAB x
      normal = $nA
      basis = 0
  ADD root_base
    SLAB y
        anisotropy = 0.3
        normal = $nB
        features = anisotropy
        basis = 1
    SLAB z
        anisotropy = 0.3
        normal = $nA
        tangent = $tA
        features = anisotropy
        basis = 0
basis 0: normal = $nA, tangent = $tA
basis 1: normal = $nB, tangent = tangent
)");
  // Each basis lists its slabs in closure order (slab indices: x 0, y 1, z 2).
  ASSERT_EQ(m.bases.size(), 2u);
  EXPECT_EQ(m.bases[0].slabs, (std::vector<int>{0, 2}));
  EXPECT_EQ(m.bases[1].slabs, (std::vector<int>{1}));
}

TEST_F(SharedBasesTest, CulledSlabsGetNoBasis) {
  auto after = run(R"(
    "a": {"kind": "slab", "normal": "$nA"},
    "b": {"kind": "slab", "normal": "$nB"},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": 1})",
                   R"(SLAB b
    normal = $nB
culled a: background of horizontal 'root': mix is constant 1
culled root: horizontal with constant mix 1 replaced by its foreground
)");
  EXPECT_EQ(after, R"(SLAB b
    normal = $nB
    basis = 0
basis 0: normal = $nB
culled a: background of horizontal 'root': mix is constant 1
culled root: horizontal with constant mix 1 replaced by its foreground
)");
}

TEST_F(SharedBasesTest, RunningThePassTwiceGivesTheSameResult) {
  run(R"(
    "a": {"kind": "slab", "normal": "$nA"},
    "b": {"kind": "slab", "normal": "$nB", "anisotropy": 0.2},
    "root": {"kind": "add", "a": "a", "b": "b"})",
      R"(ADD root
  SLAB a
      normal = $nA
  SLAB b
      anisotropy = 0.2
      normal = $nB
      features = anisotropy
)");
  const std::string once = dumpMaterial(m);
  shareLocalBases(m);
  EXPECT_EQ(dumpMaterial(m), once);
  EXPECT_EQ(m.bases.size(), 2u);
}

}  // namespace shared_bases_test
}  // namespace substratec
