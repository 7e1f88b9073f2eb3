// The unlit BSDF (docs/format.md, "BSDF nodes other than the slab"; docs/storage.md,
// "No closure"): it emits and lets light through, reflects nothing, is no
// closure, may be mixed with matter but never layered, and a material of unlit
// nodes only stores its no-closure header.
#include <gtest/gtest.h>

#include <string>

#include "diag/diagnostics.h"
#include "emit/entry_emitter.h"
#include "emit/material_emitter.h"
#include "emit/syntax.h"
#include "ir/tree_info.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"
#include "storage/pack.h"
#include "test_util.h"

namespace substratec {
namespace unlit_test {

using test::diagnosticsOf;
using test::material;

CompileResult compiled(const std::string& json, CompileOptions o = {}) {
  Diagnostics d("test.json");
  auto r = compileText("test.json", json, o, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? *r : CompileResult{};
}

std::string compileErrors(const std::string& json, CompileOptions o = {}) {
  Diagnostics d("test.json");
  auto r = compileText("test.json", json, o, d);
  EXPECT_FALSE(r.has_value());
  return d.formatAll();
}

/// The reference's evaluation at the default geometry, inputs at their defaults.
reference::MaterialResult<double> evaluated(const CompileResult& r) {
  return reference::evaluateMaterial<double>(r, reference::Geometry{}, {}, {});
}

const char* kGlass = R"("glass": {"kind": "slab", "diffuse_albedo": 0.02, "f0": 0.04, "roughness": 0.1})";

// ---------------------------------------------------------------------------
// The node

TEST(Unlit, TakesEmissiveTransmittanceAndNormalOnly) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "unlit", "emissive": [1, 2, 3], "transmittance": 0.5,
                                              "normal": [0, 0, 1]})")),
            "");
  const std::string d = diagnosticsOf(material(R"("root": {"kind": "unlit", "f0": 0.04})"));
  EXPECT_NE(d.find("test.json:1:"), std::string::npos) << d;
  EXPECT_NE(d.find("unknown pin \"f0\" for an unlit node (pins: normal, emissive, transmittance) [/nodes/root/f0]"),
            std::string::npos)
      << d;
  // and a slab does not take an unlit's pin
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "transmittance": 0.5})")).find("unknown slab pin \"transmittance\""),
            std::string::npos);
}

TEST(Unlit, ItsTransmittanceIsAColourInZeroToOne) {
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "unlit", "transmittance": 1.5})")).find("/nodes/root/transmittance"),
            std::string::npos);
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "unlit", "emissive": -1})")).find("/nodes/root/emissive"),
            std::string::npos);
}

TEST(Unlit, CannotBeLayeredInTheTopOrTheBaseOfAVertical) {
  for (const char* side : {"top", "base"}) {
    SCOPED_TRACE(side);
    const std::string other = std::string(side) == "top" ? "base" : "top";
    const std::string d = diagnosticsOf(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit", "emissive": 1},
        "root": {"kind": "vertical", ")" + side + R"(": "glow", ")" + other + R"(": "glass"})"));
    EXPECT_NE(d.find(std::string("error: unlit 'glow' is in the ") + (other == "base" ? "top layer" : "base") +
                     " of vertical 'root': an unlit BSDF cannot be layered"),
              std::string::npos)
        << d;
    EXPECT_NE(d.find("[/nodes/glow]"), std::string::npos) << d;
  }
  // nested under a mix in the top layer too, once per unlit node
  const std::string d = diagnosticsOf(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit"},
      "mix": {"kind": "horizontal", "background": "glass", "foreground": "glow", "mix": 0.5},
      "root": {"kind": "vertical", "top": "mix", "base": "glass"})"));
  EXPECT_NE(d.find("unlit 'glow' is in the top layer of vertical 'root'"), std::string::npos) << d;
}

// ---------------------------------------------------------------------------
// No closure, no bytes

TEST(Unlit, IsNoClosureAndStoresNothing) {
  const CompileResult mixed = compiled(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit", "emissive": 2},
      "root": {"kind": "horizontal", "background": "glass", "foreground": "glow", "mix": 0.3})"));
  ASSERT_EQ(mixed.after.closures.size(), 1u);  // the glass
  EXPECT_EQ(mixed.material.slabs[mixed.after.closures[0].slab].id, "glass");
  // header 16 + the glass's albedo, F0, roughness 48 + its mix weight 8
  EXPECT_EQ(mixed.after.totalBits, 72);
  EXPECT_EQ(mixed.tree.slabOrder.size(), 1u);
  const TreeNode& glow = mixed.material.nodes[mixed.material.nodes[mixed.material.root].right];
  EXPECT_EQ(glow.id, "glow");
  EXPECT_EQ(mixed.tree.bsdfId[glow.slab], -1) << "no BSDF id: not a closure";
}

TEST(Unlit, AMaterialOfUnlitNodesOnlyIsTheNoClosureHeaderAndTheTopLayerWord) {
  const CompileResult r = compiled(material(R"("root": {"kind": "unlit", "emissive": [0.2, 0.4, 0.6]})"));
  EXPECT_TRUE(r.after.closures.empty());
  EXPECT_EQ(r.after.totalBits, 16);
  EXPECT_EQ(r.after.bytes(), 8);
  EXPECT_EQ(r.after.layoutClass, LayoutClass::Simple);
  // The CPU packer writes the no-closure header; the unpacker reads no closure back.
  const std::vector<std::uint32_t> words = packMaterial(r.after, {}, {}, 0.5);
  ASSERT_EQ(words.size(), 1u);
  EXPECT_EQ(words[0], packfmt::kNoClosureHeaderBit);  // class SIMPLE (0), bit 14
  const UnpackedMaterial u = unpackMaterial(words.data(), words.size(), 0u);
  EXPECT_TRUE(u.closures.empty());
  EXPECT_EQ(u.cls, LayoutClass::Simple);
  // The generated base pass packs the same header (runtime_shaders/substrate_pack.h).
  const std::string glsl = emitMaterial(r.material, r.tree, r.after, syntaxFor(Target::Glsl), {}) +
                           emitPackFunction(r.material, r.after, syntaxFor(Target::Glsl), true);
  EXPECT_NE(glsl.find("substrate_material_header_unlit()"), std::string::npos);
  EXPECT_NE(glsl.find("out SubstrateClosure closures[1]"), std::string::npos) << "one neutral slot";
}

TEST(Unlit, FullSimplificationLeavesItAlone) {
  CompileOptions full;
  full.fullSimplification = true;
  const CompileResult r = compiled(material(R"("root": {"kind": "unlit", "emissive": 1})"), full);
  EXPECT_TRUE(r.steps.empty());
  EXPECT_TRUE(r.after.closures.empty());
}

TEST(Unlit, SimplificationCollapsesAroundItButNeverOverIt) {
  CompileOptions full;
  full.fullSimplification = true;
  // The vertical under the mix collapses to one closure; the mix over the unlit stays.
  const CompileResult r = compiled(material(R"("clear": {"kind": "slab", "diffuse_albedo": 0, "sss_mfp": 1000000},
      "paint": {"kind": "slab", "diffuse_albedo": 0.5},
      "coat": {"kind": "vertical", "top": "clear", "base": "paint"}, "glow": {"kind": "unlit", "emissive": 1},
      "root": {"kind": "horizontal", "background": "coat", "foreground": "glow", "mix": 0.5})"),
                                   full);
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_EQ(r.steps[0].node, "coat");
  EXPECT_EQ(r.after.closures.size(), 1u);
  // Two slabs mixed beside an unlit, one level down: the unlit's operator
  // cannot collapse, so neither can the root, and the error says why.
  const std::string d = compileErrors(material(std::string(kGlass) + R"(, "paint": {"kind": "slab", "diffuse_albedo": 0.5},
      "glow": {"kind": "unlit", "emissive": 1},
      "lit": {"kind": "horizontal", "background": "glass", "foreground": "glow", "mix": 0.5},
      "root": {"kind": "horizontal", "background": "lit", "foreground": "paint", "mix": 0.5})"),
                                      full);
  EXPECT_NE(d.find("an operator over an unlit node is never collapsed"), std::string::npos) << d;
}

// ---------------------------------------------------------------------------
// What it does to the tree and the light

TEST(Unlit, EmitsItsEmissiveWeightedByTheOperatorsAboveIt) {
  const CompileResult r = compiled(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit", "emissive": [1, 2, 4]},
      "w": {"kind": "coverage_weight", "a": "glow", "weight": 0.5},
      "root": {"kind": "horizontal", "background": "glass", "foreground": "w", "mix": 0.25})"));
  const auto e = evaluated(r);
  for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(e.emission[c], 0.25 * 0.5 * (1 << c));
  ASSERT_EQ(e.closures.size(), 1u);
  EXPECT_DOUBLE_EQ(e.closures[0].weight, 0.75);
  EXPECT_TRUE(unlitEmission(r.material));
  // An unlit that emits nothing adds no `emission` to the generated code.
  const CompileResult dark = compiled(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit", "transmittance": 0.5},
      "root": {"kind": "horizontal", "background": "glass", "foreground": "glow", "mix": 0.25})"));
  EXPECT_FALSE(unlitEmission(dark.material));
  EXPECT_EQ(emitMaterial(dark.material, dark.tree, dark.after, syntaxFor(Target::Glsl), {}).find("emission"),
            std::string::npos);
}

TEST(Unlit, ItsTransmittanceIsWhatTheMaterialLetsThroughWhereItCovers) {
  const CompileResult r = compiled(material(std::string(kGlass) + R"(, "veil": {"kind": "unlit", "transmittance": [0.2, 0.4, 0.8]},
      "root": {"kind": "horizontal", "background": "glass", "foreground": "veil", "mix": 0.5})"));
  const auto e = evaluated(r);
  EXPECT_DOUBLE_EQ(e.coverage, 1.0);
  // substrate_op_horizontal: the glass is opaque (T 0), the veil lets T through; half each.
  EXPECT_NEAR(e.transmittance[0], 0.1, 1e-12);
  EXPECT_NEAR(e.transmittance[1], 0.2, 1e-12);
  EXPECT_NEAR(e.transmittance[2], 0.4, 1e-12);
}

TEST(Unlit, TheReportNamesItUnlitAndItsFeatureEmissive) {
  const CompileResult r = compiled(material(std::string(kGlass) + R"(, "glow": {"kind": "unlit", "emissive": 1},
      "root": {"kind": "add", "a": "glass", "b": "glow"})"));
  int unlit = -1;
  for (int n : r.tree.preorder)
    if (std::string(nodeOpName(r.material, r.material.nodes[n])) == "UNLIT") unlit = n;
  ASSERT_GE(unlit, 0);
  EXPECT_EQ(r.material.nodes[unlit].id, "glow");
  EXPECT_EQ(r.material.slabs[r.material.nodes[unlit].slab].features, kFeatEmissive);
  EXPECT_EQ(r.tree.interfaces[unlit], 0);  // no interface
}

}  // namespace unlit_test
}  // namespace substratec
