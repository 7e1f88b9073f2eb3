// Tests for pass 6, feature analysis (compiler/core/passes/features.h), written as
// the format's rule: "Opt-in features ... are *used* only when their pin is
// present and not a constant equal to the neutral default. A material pays
// only for what it uses." Dump before the pass, the pass, dump after.
#include "passes/features.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace substratec {
namespace {

using test::runUntil;

std::string document(const std::string& nodes, const std::string& inputs = "{}",
                     const std::string& settings = "{}") {
  return R"({"format": "substrate-material/1", "name": "m", "settings": )" + settings + R"(, "inputs": )" +
         inputs + R"(, "nodes": {)" + nodes + R"(}, "output": "root"})";
}

class FeaturesTest : public ::testing::Test {
 protected:
  /// Builds up to culling, checks the dump is `before`, runs the pass and
  /// returns the dump after it.
  std::string run(const std::string& json, const std::string& before) {
    m = runUntil(json, "cull");
    EXPECT_EQ(dumpMaterial(m), before) << "(input dump)";
    analyzeFeatures(m);
    return dumpMaterial(m);
  }
  /// Features of the single slab "root" with `pins`.
  std::string featuresOf(const std::string& pins, const std::string& inputs = "{}") {
    Material s = runUntil(document(R"("root": {"kind": "slab", )" + pins + "}", inputs), "cull");
    analyzeFeatures(s);
    if (s.slabs.size() != 1) return "?";
    return featureList(s.slabs[0].features);
  }
  int slabNamed(const std::string& id) const {
    for (std::size_t i = 0; i < m.slabs.size(); ++i)
      if (m.slabs[i].id == id) return static_cast<int>(i);
    return -1;
  }

  Material m;
};

// ---------------------------------------------------------------------------
// Each gate: absent, constant neutral, constant non-neutral, input

struct Gate {
  const char* pin;
  const char* feature;
  const char* neutral;     // a literal equal to the neutral default
  const char* other;       // a literal that is not
  const char* inputType;   // an input of this type whose default is neutral
  const char* inputDefault;
};

const Gate kGates[] = {
    {"f90", "f90", "1", "0.5", "color", "1"},
    {"anisotropy", "anisotropy", "0", "-0.5", "float", "0"},
    {"sss_mfp", "sss", "0", "0.01", "color", "0"},
    {"second_roughness_weight", "haze", "0", "0.3", "float", "0"},
    {"fuzz_amount", "fuzz", "0", "0.5", "float", "0"},
    {"glint_value", "glint", "1", "0.5", "float", "1"},
    {"emissive", "emissive", "0", "[1, 0.5, 0]", "color", "0"},
};

TEST_F(FeaturesTest, AbsentGatePinIsNotUsed) {
  EXPECT_EQ(featuresOf(R"("roughness": 0.3)"), "");
}

TEST_F(FeaturesTest, GatePinEqualToTheNeutralConstantIsNotUsed) {
  for (const Gate& g : kGates)
    EXPECT_EQ(featuresOf("\"" + std::string(g.pin) + "\": " + g.neutral), "") << g.pin;
}

TEST_F(FeaturesTest, GatePinWithAnotherConstantIsUsed) {
  for (const Gate& g : kGates)
    EXPECT_EQ(featuresOf("\"" + std::string(g.pin) + "\": " + g.other), g.feature) << g.pin;
}

TEST_F(FeaturesTest, GatePinFromAnInputIsUsedEvenIfItsDefaultIsNeutral) {
  for (const Gate& g : kGates) {
    std::string inputs = std::string(R"({"p": {"type": ")") + g.inputType + R"(", "default": )" + g.inputDefault + "}}";
    EXPECT_EQ(featuresOf("\"" + std::string(g.pin) + "\": \"$p\"", inputs), g.feature) << g.pin;
  }
}

TEST_F(FeaturesTest, GatePinFoldingToTheNeutralConstantIsNotUsed) {
  // 0.5 * 2 is folded to 1 when the value DAG is built.
  EXPECT_EQ(featuresOf(R"("f90": {"kind": "multiply", "a": 0.5, "b": 2})"), "");
  EXPECT_EQ(featuresOf(R"("fuzz_amount": {"kind": "subtract", "a": 0.25, "b": 0.25})"), "");
}

TEST_F(FeaturesTest, OneNonNeutralComponentIsEnough) {
  EXPECT_EQ(featuresOf(R"("f90": [1, 1, 0.9])"), "f90");
  EXPECT_EQ(featuresOf(R"("sss_mfp": [0, 0, 0.001])"), "sss");
}

TEST_F(FeaturesTest, SpecularProfileIsUsedWhenGiven) {
  EXPECT_EQ(featuresOf(R"("specular_profile": "$lut")", R"({"lut": {"type": "texture2d"}})"), "specular_profile");
}

TEST_F(FeaturesTest, EveryFeatureAtOnce) {
  auto after = run(document(R"("root": {"kind": "slab", "f90": 0.9, "anisotropy": 0.5, "sss_mfp": 0.01,
    "second_roughness_weight": 0.3, "fuzz_amount": 0.2, "glint_value": 0.5, "emissive": 2,
    "specular_profile": "$lut"})",
                                     R"({"lut": {"type": "texture2d"}})"),
                   R"(SLAB root
    f90 = 0.9
    anisotropy = 0.5
    sss_mfp = 0.01
    emissive = 2
    second_roughness_weight = 0.3
    fuzz_amount = 0.2
    glint_value = 0.5
    specular_profile = $lut
)");
  EXPECT_EQ(after, R"(SLAB root
    f90 = 0.9
    anisotropy = 0.5
    sss_mfp = 0.01
    emissive = 2
    second_roughness_weight = 0.3
    fuzz_amount = 0.2
    glint_value = 0.5
    specular_profile = $lut
    sss_type = diffusion
    features = f90,anisotropy,sss,haze,fuzz,glint,specular_profile,emissive
)");
}

TEST_F(FeaturesTest, NoModify_NonGatePinsEnableNothing) {
  // The pins that only parametrise a feature do not turn it on.
  auto after = run(document(R"("root": {"kind": "slab", "second_roughness": 0.9, "fuzz_color": 0.7,
    "fuzz_roughness": 0.2, "sss_mfp_scale": 2, "sss_phase_anisotropy": 0.5, "glint_uv": [0.25, 0.75],
    "roughness": 0.1, "diffuse_albedo": 0.9, "f0": 0.5})"),
                   R"(SLAB root
    diffuse_albedo = 0.9
    f0 = 0.5
    roughness = 0.1
    sss_mfp_scale = 2
    sss_phase_anisotropy = 0.5
    second_roughness = 0.9
    fuzz_color = 0.7
    fuzz_roughness = 0.2
    glint_uv = [0.25, 0.75]
)");
  EXPECT_EQ(after, R"(SLAB root
    diffuse_albedo = 0.9
    f0 = 0.5
    roughness = 0.1
    sss_mfp_scale = 2
    sss_phase_anisotropy = 0.5
    second_roughness = 0.9
    fuzz_color = 0.7
    fuzz_roughness = 0.2
    glint_uv = [0.25, 0.75]
)");
}

// ---------------------------------------------------------------------------
// SSS: scale and sss_type gates

TEST_F(FeaturesTest, NoModify_MfpWithAZeroScaleIsNoSss) {
  EXPECT_EQ(featuresOf(R"("sss_mfp": 0.01, "sss_mfp_scale": 0)"), "");
}

TEST_F(FeaturesTest, NoModify_MfpWithSssTypeNoneIsNoSss) {
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": 0.01, "sss_type": "none"})"),
                   R"(SLAB root
    sss_mfp = 0.01
)");
  EXPECT_EQ(after, R"(SLAB root
    sss_mfp = 0.01
)");
  EXPECT_EQ(m.slabs[0].sssType, SssType::None);
}

// ---------------------------------------------------------------------------
// medium vs sss

TEST_F(FeaturesTest, MfpOnASlabThatCoatsAnotherIsAMedium) {
  auto after = run(document(R"(
    "coat": {"kind": "slab", "sss_mfp": 10, "roughness": 0.1},
    "base": {"kind": "slab", "sss_mfp": 0.01},
    "root": {"kind": "vertical", "top": "coat", "base": "base"})"),
                   R"(VERTICAL root thickness=0.0001
  SLAB coat
      roughness = 0.1
      sss_mfp = 10
  SLAB base
      sss_mfp = 0.01
)");
  EXPECT_EQ(after, R"(VERTICAL root thickness=0.0001
  SLAB coat
      roughness = 0.1
      sss_mfp = 10
      features = medium
  SLAB base
      sss_mfp = 0.01
      sss_type = diffusion
      features = sss
)");
}

TEST_F(FeaturesTest, MfpAnywhereInsideAVerticalTopIsAMedium) {
  auto after = run(document(R"(
    "a": {"kind": "slab", "sss_mfp": 0.5},
    "b": {"kind": "slab", "sss_mfp": 0.5, "sss_type": "wrap"},
    "root": {"kind": "vertical", "base": {"kind": "slab"},
             "top": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"}})",
                            R"({"m": {"type": "float", "default": 0.5}})"),
                   R"(VERTICAL root thickness=0.0001
  HORIZONTAL root_top mix=$m
    SLAB a
        sss_mfp = 0.5
    SLAB b
        sss_mfp = 0.5
        sss_type = wrap
  SLAB root_base
)");
  // An explicit sss_type is kept even where the medium does not scatter.
  EXPECT_EQ(after, R"(VERTICAL root thickness=0.0001
  HORIZONTAL root_top mix=$m
    SLAB a
        sss_mfp = 0.5
        features = medium
    SLAB b
        sss_mfp = 0.5
        sss_type = wrap
        features = medium
  SLAB root_base
)");
}

TEST_F(FeaturesTest, MfpWithAConstantZeroAlbedoIsAMedium) {
  // No scattering: the medium only absorbs (Beer-Lambert), even at the bottom.
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": [0.01, 0.02, 0.03], "diffuse_albedo": 0})"),
                   R"(SLAB root
    diffuse_albedo = 0
    sss_mfp = [0.01, 0.02, 0.03]
)");
  EXPECT_EQ(after, R"(SLAB root
    diffuse_albedo = 0
    sss_mfp = [0.01, 0.02, 0.03]
    features = medium
)");
}

TEST_F(FeaturesTest, MfpWithARunTimeAlbedoIsSss) {
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": 0.01, "diffuse_albedo": "$a"})",
                            R"({"a": {"type": "color", "default": 0}})"),
                   R"(SLAB root
    diffuse_albedo = $a
    sss_mfp = 0.01
)");
  EXPECT_EQ(after, R"(SLAB root
    diffuse_albedo = $a
    sss_mfp = 0.01
    sss_type = diffusion
    features = sss
)");
}

// ---------------------------------------------------------------------------
// sss_type derivation

TEST_F(FeaturesTest, SssTypeIsDerivedAsDiffusion) {
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": "$mfp"})",
                            R"({"mfp": {"type": "color", "default": [0.006, 0.003, 0.0015]}})"),
                   R"(SLAB root
    sss_mfp = $mfp
)");
  EXPECT_EQ(after, R"(SLAB root
    sss_mfp = $mfp
    sss_type = diffusion
    features = sss
)");
  EXPECT_FALSE(m.slabs[0].sssTypeExplicit);
}

TEST_F(FeaturesTest, SssTypeOnAThinSurfaceIsSimpleVolume) {
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": 0.01})", "{}", R"({"thin_surface": true})"),
                   R"(SLAB root
    sss_mfp = 0.01
)");
  EXPECT_EQ(after, R"(SLAB root
    sss_mfp = 0.01
    sss_type = simple_volume
    features = sss
)");
}

TEST_F(FeaturesTest, NoModify_ExplicitSssTypeIsKept) {
  auto after = run(document(R"("root": {"kind": "slab", "sss_mfp": 0.01, "sss_type": "diffusion"})", "{}",
                            R"({"thin_surface": true})"),
                   R"(SLAB root
    sss_mfp = 0.01
    sss_type = diffusion
)");
  EXPECT_EQ(after, R"(SLAB root
    sss_mfp = 0.01
    sss_type = diffusion
    features = sss
)");
  EXPECT_EQ(featuresOf(R"("sss_mfp": 0.01, "sss_type": "wrap")"), "sss");
}

TEST_F(FeaturesTest, NoSssMeansSssTypeNone) {
  auto after = run(document(R"("root": {"kind": "slab", "roughness": 0.2})", "{}", R"({"thin_surface": true})"),
                   R"(SLAB root
    roughness = 0.2
)");
  EXPECT_EQ(after, R"(SLAB root
    roughness = 0.2
)");
  EXPECT_EQ(m.slabs[0].sssType, SssType::None);
}

TEST_F(FeaturesTest, RunningThePassTwiceGivesTheSameResult) {
  m = runUntil(document(R"(
    "coat": {"kind": "slab", "sss_mfp": 10},
    "root": {"kind": "vertical", "top": "coat", "base": {"kind": "slab", "sss_mfp": 0.01}})"),
               "cull");
  analyzeFeatures(m);
  const std::string once = dumpMaterial(m);
  analyzeFeatures(m);
  EXPECT_EQ(dumpMaterial(m), once);
}

// ---------------------------------------------------------------------------
// After culling

TEST_F(FeaturesTest, CulledSlabsDoNotCount) {
  auto after = run(document(R"(
    "plain": {"kind": "slab", "roughness": 0.3},
    "fancy": {"kind": "slab", "fuzz_amount": 1, "glint_value": 0.2, "anisotropy": 0.9},
    "root": {"kind": "horizontal", "background": "plain", "foreground": "fancy", "mix": 0})"),
                   R"(SLAB plain
    roughness = 0.3
culled fancy: foreground of horizontal 'root': mix is constant 0
culled root: horizontal with constant mix 0 replaced by its background
)");
  EXPECT_EQ(after, R"(SLAB plain
    roughness = 0.3
culled fancy: foreground of horizontal 'root': mix is constant 0
culled root: horizontal with constant mix 0 replaced by its background
)");
  ASSERT_GE(slabNamed("fancy"), 0);
  EXPECT_EQ(m.slabs[slabNamed("fancy")].features, 0) << featureList(m.slabs[slabNamed("fancy")].features);
}

TEST_F(FeaturesTest, ACoatWhoseBaseIsCulledIsNoLongerAMedium) {
  // Culling removes the base: the coat is now the bottom of the material and
  // its medium scatters.
  auto after = run(document(R"(
    "coat": {"kind": "slab", "sss_mfp": 0.01, "diffuse_albedo": 0.8},
    "base": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "coat", "base": {"kind": "coverage_weight", "a": "base", "weight": 0}})"),
                   R"(SLAB coat
    diffuse_albedo = 0.8
    sss_mfp = 0.01
culled base: under coverage_weight 'root_base': weight is constant 0
culled root_base: coverage_weight with constant weight 0 removed with its subtree
culled root: VERTICAL 'root' removed: one side is empty
)");
  EXPECT_EQ(after, R"(SLAB coat
    diffuse_albedo = 0.8
    sss_mfp = 0.01
    sss_type = diffusion
    features = sss
culled base: under coverage_weight 'root_base': weight is constant 0
culled root_base: coverage_weight with constant weight 0 removed with its subtree
culled root: VERTICAL 'root' removed: one side is empty
)");
}

}  // namespace
}  // namespace substratec
