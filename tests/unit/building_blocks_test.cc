// The building blocks (docs/format.md, "Building blocks"; issue 23): nodes
// that stand for the slabs, operators and value nodes an author would write
// by hand, expanded by the expand-blocks pass before the resolve. Each block
// is held to what its documentation says it expands into, through the whole
// compiler and the CPU reference (the GPU suites hold the shaders to that
// reference); pricing sees through the expansion.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "blocks/blocks.h"
#include "blocks/expand.h"
#include "reference/reference.h"
#include "substrate_constants.h"  // runtime_shaders/
#include "test_util.h"

namespace substratec {
namespace building_blocks_test {

using test::compiled;
using test::material;

reference::MaterialResult<double> evaluated(const CompileResult& r, double nov = 1.0) {
  reference::Geometry g;
  g.V = {std::sqrt(1 - nov * nov), 0, nov};
  return reference::evaluateMaterial<double>(r, g, {}, {});
}

void expectNear3(const std::array<double, 3>& got, const std::array<double, 3>& want, double tol, const char* what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol) << what << " channel " << c;
}

TEST(BuildingBlocks, AUe4DefaultLitIsOneSlabOfTheLegacyPathsTwelveBytes) {
  const CompileResult r = compiled(material(R"("root": {"kind": "ue4_default_lit", "base_color": [0.8, 0.2, 0.1],
      "metallic": 0.3, "specular": 0.6, "roughness": 0.4})"));
  EXPECT_EQ(r.after.bytes(), 12);  // the course's table: the legacy path, one closure, SIMPLE
  EXPECT_EQ(r.after.closures.size(), 1u);
  EXPECT_EQ(r.after.layoutClass, LayoutClass::Simple);
  // diffuse = base (1 − metallic), F0 = lerp(0.08 specular, base, metallic): UE's DefaultLit.
  const auto m = evaluated(r);
  ASSERT_EQ(m.closures.size(), 1u);
  const double base[3] = {0.8, 0.2, 0.1};
  std::array<double, 3> diffuse{}, f0{};
  for (int c = 0; c < 3; ++c) {
    diffuse[c] = base[c] * 0.7;
    f0[c] = 0.08 * 0.6 + (base[c] - 0.08 * 0.6) * 0.3;
  }
  expectNear3(m.closures[0].diffuseAlbedo, diffuse, 1e-12, "diffuse");
  expectNear3(m.closures[0].f0, f0, 1e-12, "f0");
  EXPECT_NEAR(m.closures[0].roughness, 0.4, 1e-12);
}

TEST(BuildingBlocks, AUe4DefaultLitTakesUesDefaults) {
  // BaseColor 0 (not the metalness helper's 0.18), Specular 0.5, Roughness 0.5.
  const auto m = evaluated(compiled(material(R"("root": {"kind": "ue4_default_lit"})")));
  ASSERT_EQ(m.closures.size(), 1u);
  expectNear3(m.closures[0].diffuseAlbedo, {0, 0, 0}, 1e-12, "diffuse");
  expectNear3(m.closures[0].f0, {0.04, 0.04, 0.04}, 1e-12, "f0");
  EXPECT_NEAR(m.closures[0].roughness, 0.5, 1e-12);
}

TEST(BuildingBlocks, AUe4UnlitEmitsAndStoresNothing) {
  const CompileResult r = compiled(material(R"("root": {"kind": "ue4_unlit", "emissive_color": [2, 1, 0.5],
      "opacity": 0.25})"));
  EXPECT_EQ(r.after.closures.size(), 0u);
  const auto m = evaluated(r);
  expectNear3(m.emission, {0.5, 0.25, 0.125}, 1e-12, "emission (weighted by the opacity)");
  EXPECT_NEAR(m.coverage, 0.25, 1e-12);
}

TEST(BuildingBlocks, ACoatedLayerPutsADielectricCoatOverItsBase) {
  const std::string base = R"("base": {"kind": "slab", "diffuse_albedo": [0.5, 0.4, 0.3], "roughness": 0.6})";
  const CompileResult r = compiled(material(R"("root": {"kind": "coated_layer", )" + base +
                                            R"(, "coat_roughness": 0.1, "coat_f0": 0.05})"));
  ASSERT_EQ(r.after.closures.size(), 2u);
  const auto m = evaluated(r);
  ASSERT_EQ(m.closures.size(), 2u);
  // The coat on top: no diffuse, its own F0 and roughness; the base under it.
  EXPECT_TRUE(m.closures[0].isTop);
  expectNear3(m.closures[0].diffuseAlbedo, {0, 0, 0}, 1e-12, "coat diffuse");
  expectNear3(m.closures[0].f0, {0.05, 0.05, 0.05}, 1e-12, "coat f0");
  EXPECT_NEAR(m.closures[0].roughness, 0.1, 1e-12);
  EXPECT_FALSE(m.closures[1].isTop);
  expectNear3(m.closures[1].diffuseAlbedo, {0.5, 0.4, 0.3}, 1e-12, "base diffuse");
  // A coat of weight 0 is no coat: it costs what its base costs.
  const CompileResult none = compiled(material(R"("root": {"kind": "coated_layer", )" + base +
                                               R"(, "coat_weight": 0})"));
  const CompileResult plain = compiled(material(R"("root": {"kind": "slab", "diffuse_albedo": [0.5, 0.4, 0.3],
      "roughness": 0.6})"));
  EXPECT_EQ(none.after.bytes(), plain.after.bytes());
  EXPECT_EQ(none.after.closures.size(), 1u);
}

TEST(BuildingBlocks, AClearCoatIsTheDefaultLitSlabUnderACoatOfIor15) {
  const CompileResult r = compiled(material(R"("root": {"kind": "clear_coat", "base_color": [0.9, 0.1, 0.1],
      "metallic": 1, "roughness": 0.3, "clear_coat": 1, "clear_coat_roughness": 0.05})"));
  ASSERT_EQ(r.after.closures.size(), 2u);
  const auto m = evaluated(r);
  expectNear3(m.closures[0].f0, {0.04, 0.04, 0.04}, 1e-12, "coat f0");
  EXPECT_NEAR(m.closures[0].roughness, 0.05, 1e-12);
  expectNear3(m.closures[1].f0, {0.9, 0.1, 0.1}, 1e-12, "metal f0");
  // clear_coat 0: the default-lit slab, 12 bytes.
  EXPECT_EQ(compiled(material(R"("root": {"kind": "clear_coat", "clear_coat": 0})")).after.bytes(), 12);
}

TEST(BuildingBlocks, ClothIsTheDefaultLitSlabWithFuzz) {
  const CompileResult r = compiled(material(R"("root": {"kind": "cloth", "base_color": [0.3, 0.3, 0.6],
      "roughness": 0.7, "cloth": 0.8, "fuzz_color": [0.9, 0.8, 0.7]})"));
  ASSERT_EQ(r.after.closures.size(), 1u);
  const auto m = evaluated(r);
  EXPECT_NEAR(m.closures[0].fuzzAmount, 0.8, 1e-12);
  expectNear3(m.closures[0].fuzzColor, {0.9, 0.8, 0.7}, 1e-12, "fuzz colour");
  EXPECT_NEAR(m.closures[0].fuzzRoughness, 0.7, 1e-12) << "the slab's roughness";
  EXPECT_EQ(compiled(material(R"("root": {"kind": "cloth", "cloth": 0})")).after.bytes(), 12);
}

/// legacy_conversion of `model` with `pins` (a JSON fragment, may be empty).
CompileResult legacy(const std::string& model, const std::string& pins = "") {
  return compiled(material(R"("root": {"kind": "legacy_conversion", "shading_model": ")" + model + "\"" +
                           (pins.empty() ? "" : ", " + pins) + "}"));
}

TEST(BuildingBlocks, ALegacyConversionPricesEachUe4ShadingModelAsTheCourseDoes) {
  // The course's table: the legacy Disney diffuse/specular/roughness 12 bytes,
  // the legacy shading models (a subsurface) 16 bytes.
  const std::string base = R"("base_color": [0.7, 0.4, 0.3], "roughness": 0.45)";
  EXPECT_EQ(legacy("default_lit", base).after.bytes(), 12);
  for (const char* sss : {"subsurface", "preintegrated_skin", "two_sided_foliage"}) {
    const CompileResult r = legacy(sss, base + R"(, "subsurface_color": [0.9, 0.4, 0.2])");
    EXPECT_EQ(r.after.bytes(), 16) << sss;
    ASSERT_EQ(r.material.slabs.size(), 1u);
    EXPECT_EQ(r.material.slabs[0].sssType, SssType::Wrap) << sss;
  }
  EXPECT_EQ(legacy("subsurface_profile", base + R"(, "subsurface_mfp": [0.004, 0.002, 0.001])").after.bytes(), 16);
  EXPECT_EQ(legacy("subsurface_profile", base).after.bytes(), 12) << "no profile MFP: no subsurface";
  EXPECT_EQ(legacy("cloth", base).after.bytes(), 16);
  EXPECT_EQ(legacy("unlit", R"("emissive_color": 1)").after.closures.size(), 0u);
  EXPECT_EQ(legacy("clear_coat", base).after.closures.size(), 2u);
}

TEST(BuildingBlocks, ALegacyConversionBuildsTheUe4ModelsOwnBsdf) {
  int models = 0;
  for (const char* model : {"default_lit", "unlit", "subsurface", "preintegrated_skin", "clear_coat",
                            "subsurface_profile", "two_sided_foliage", "cloth", "hair", "eye", "single_layer_water",
                            "thin_translucent"}) {
    SCOPED_TRACE(model);
    const CompileResult r = legacy(model, R"("base_color": [0.5, 0.5, 0.5])");
    EXPECT_FALSE(r.material.nodes.empty());
    ++models;
  }
  EXPECT_EQ(models, 12);
  EXPECT_EQ(legacy("hair").material.slabs[0].kind, BsdfKind::Hair);
  EXPECT_EQ(legacy("eye", R"("iris_mask": 0.5)").material.slabs[0].kind, BsdfKind::Eye);
  // The water: extinction = scattering + absorption, albedo = scattering / extinction.
  const CompileResult water = legacy("single_layer_water", R"("water_scattering": [0.1, 0.2, 0.3],
      "water_absorption": [0.3, 0.2, 0.1])");
  ASSERT_EQ(water.material.slabs.size(), 1u);
  EXPECT_EQ(water.material.slabs[0].kind, BsdfKind::Water);
  const auto m = evaluated(water);
  ASSERT_TRUE(m.water.has_value());
  expectNear3(m.water->extinction, {0.4, 0.4, 0.4}, 1e-12, "extinction");
  expectNear3(m.water->albedo, {0.25, 0.5, 0.75}, 1e-12, "albedo");
  // Subsurface: a wrap of per-channel amount min(subsurface colour, 0.95).
  // (A medium needs a diffuse albedo to scatter: UE's BaseColor default 0 has none.)
  const auto sss = evaluated(legacy("subsurface", R"("base_color": 0.8, "subsurface_color": [1, 0.5, 0])"));
  ASSERT_EQ(sss.closures.size(), 1u);
  for (int c = 0; c < 3; ++c) {
    const double w = std::min(std::array<double, 3>{1, 0.5, 0}[c], 0.95);
    EXPECT_NEAR(sss.closures[0].sssMfp[c], SUBSTRATE_SSS_WRAP_MFP_SCALE * w / (1 - w), 1e-12) << c;
  }
}

TEST(BuildingBlocks, AStandardSurfaceIsTheMaterialXImportersUnitOnItsPins) {
  // Standard Surface's defaults but base_color and a rough specular: one slab,
  // diffuse = base · base_color, F0 of IOR 1.5, roughness specular_roughness.
  const CompileResult r = compiled(material(R"("root": {"kind": "standard_surface", "base": 0.9,
      "base_color": [0.5, 0.25, 0.125], "specular_roughness": 0.35})"));
  EXPECT_EQ(r.after.bytes(), 12);
  const auto m = evaluated(r);
  ASSERT_EQ(m.closures.size(), 1u);
  expectNear3(m.closures[0].diffuseAlbedo, {0.45, 0.225, 0.1125}, 1e-12, "diffuse");
  expectNear3(m.closures[0].f0, {0.04, 0.04, 0.04}, 1e-12, "f0");
  EXPECT_NEAR(m.closures[0].roughness, 0.35, 1e-12);
  // A coat adds its closure; OpenPBR and Disney principled read their own names.
  EXPECT_EQ(compiled(material(R"("root": {"kind": "standard_surface", "coat": 1})")).after.closures.size(), 2u);
  EXPECT_EQ(compiled(material(R"("root": {"kind": "open_pbr_surface", "coat_weight": 1})")).after.closures.size(), 2u);
  EXPECT_EQ(compiled(material(R"("root": {"kind": "disney_principled", "clearcoat": 1})")).after.closures.size(), 2u);
}

TEST(BuildingBlocks, AMaterialXBlockReadsAnInputAtItsValueWhereItsModelNeedsAConstant) {
  // specular_rotation is read as a constant (it decides the tangent): "$rot"
  // is read at its default, a quarter turn, as MaterialX's import reads it.
  const std::string inputs = R"({"rot": {"type": "float", "default": 0.25}})";
  const auto m = evaluated(compiled(material(R"("root": {"kind": "standard_surface", "specular_anisotropy": 0.5,
      "specular_rotation": "$rot"})", inputs)));
  ASSERT_EQ(m.closures.size(), 1u);
  expectNear3(m.closures[0].T_, {0, 1, 0}, 1e-9, "the tangent a quarter turn round the normal");
}

TEST(BuildingBlocks, WhatAMaterialXBlockCannotRepresentIsAWarningAtTheBlock) {
  Diagnostics d("test.json");
  const auto r = compileText("test.json", material(R"("root": {"kind": "standard_surface",
      "diffuse_roughness": 0.5})"), {}, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_NE(d.formatAll().find("warning: standard_surface: diffuse_roughness: a slab's diffuse roughness is its "
                               "specular roughness; ignored [/nodes/root]"),
            std::string::npos)
      << d.formatAll();
}

TEST(BuildingBlocks, AGltfPbrWithoutItsExtensionsCostsAPlainSlab) {
  const CompileResult r = compiled(material(R"("root": {"kind": "gltf_pbr", "base_color": [0.7, 0.7, 0.2],
      "metallic": 0, "roughness": 0.5, "clearcoat": 0, "sheen_color": 0, "transmission": 0})"));
  EXPECT_EQ(r.after.bytes(), 12);
  EXPECT_EQ(r.after.closures.size(), 1u);
  const auto m = evaluated(r);
  expectNear3(m.closures[0].diffuseAlbedo, {0.7, 0.7, 0.2}, 1e-12, "diffuse");
  expectNear3(m.closures[0].f0, {0.04, 0.04, 0.04}, 1e-12, "f0 of IOR 1.5");
}

TEST(BuildingBlocks, ANamedBlocksRootTakesItsIdAndTheReportNamesBoth) {
  const CompileResult r = compiled(material(R"(
      "paint": {"kind": "ue4_default_lit", "base_color": [0.8, 0.1, 0.1]},
      "root": {"kind": "horizontal", "background": {"kind": "coated_layer", "base": "paint"},
               "foreground": {"kind": "ue4_unlit", "emissive_color": 1}, "mix": 0.5})"));
  ASSERT_EQ(r.blocks.size(), 3u);
  EXPECT_EQ(r.blocks[0].id, "paint");
  EXPECT_EQ(r.blocks[0].kind, "ue4_default_lit");
  EXPECT_EQ(r.blocks[0].pointer, "/nodes/paint");
  EXPECT_EQ(r.blocks[0].nodes, (std::vector<std::string>{"paint_metalness", "paint"}));
  EXPECT_EQ(r.blocks[1].id, "root_background");  // inline: named by its place, like any inline node
  EXPECT_EQ(r.blocks[1].kind, "coated_layer");
  EXPECT_EQ(r.blocks[1].pointer, "/nodes/root/background");
  EXPECT_EQ(r.blocks[2].kind, "ue4_unlit");
  // The slab the paint block became is the base of the coat's vertical.
  bool paintSlab = false;
  for (const auto& s : r.material.slabs) paintSlab = paintSlab || s.id == "paint";
  EXPECT_TRUE(paintSlab);
  EXPECT_EQ(r.after.closures.size(), 2u);
}

TEST(BuildingBlocks, ABlockInsideABlockIsExpandedInTurn) {
  const CompileResult r = compiled(material(R"("root": {"kind": "coated_layer", "coat_roughness": 0.2,
      "base": {"kind": "gltf_pbr", "base_color": [0.2, 0.5, 0.9], "metallic": 0, "roughness": 0.7}})"));
  ASSERT_EQ(r.blocks.size(), 2u);
  EXPECT_EQ(r.blocks[0].kind, "coated_layer");
  EXPECT_EQ(r.blocks[1].kind, "gltf_pbr");
  const auto m = evaluated(r);
  ASSERT_EQ(m.closures.size(), 2u);
  expectNear3(m.closures[1].diffuseAlbedo, {0.2, 0.5, 0.9}, 1e-12, "the inner block's diffuse");
}

TEST(BuildingBlocks, ABlockWhoseRootIsItsBaseStandsForItsBase) {
  // coat_weight 0: the expansion is the base as given; a named block's id then
  // names a coverage weight of 1 over it, which culling removes.
  const CompileResult r = compiled(material(R"(
      "under": {"kind": "slab", "diffuse_albedo": 0.3},
      "root": {"kind": "coated_layer", "base": "under", "coat_weight": 0})"));
  const CompileResult plain = compiled(material(R"("root": {"kind": "slab", "diffuse_albedo": 0.3})"));
  EXPECT_EQ(r.after.closures.size(), 1u);
  EXPECT_EQ(r.after.bytes(), plain.after.bytes());
  ASSERT_EQ(r.blocks.size(), 1u);
  EXPECT_TRUE(r.blocks[0].nodes.empty());
  const auto m = evaluated(r);
  ASSERT_EQ(m.closures.size(), 1u);
  EXPECT_EQ(m.closures[0].diffuseAlbedo, evaluated(plain).closures[0].diffuseAlbedo);
}

TEST(BuildingBlocks, PinsAreCheckedLikeAnyNodesWithLocatedErrors) {
  Diagnostics d("test.json");
  const std::string json = material(R"(
      "paint": {"kind": "ue4_default_lit", "metallic": 2, "roughnes": 0.4, "specular": [1, 1, 1]},
      "coat": {"kind": "coated_layer", "coat_roughness": 0.1},
      "g": {"kind": "gltf_pbr", "alpha_mode": "maybe", "attenuation_distance": "$n", "unlit": 1},
      "root": {"kind": "horizontal", "background": "coat", "foreground": "g", "mix": 0.5})",
                                    R"({"n": {"type": "float", "default": 1}})");
  EXPECT_FALSE(compileText("test.json", json, {}, d));
  const std::string all = d.formatAll();
  int found = 0;
  for (const char* want :
       {"expected a float in [0,1], got 2 [/nodes/paint/metallic]",
        "unknown pin \"roughnes\" for a ue4_default_lit node (pins: base_color, metallic, specular, roughness",
        "expected a float, got a vec3 [/nodes/paint/specular]", "missing required pin \"base\" [/nodes/coat]",
        "expected one of \"opaque\", \"mask\", \"blend\", got \"maybe\" [/nodes/g/alpha_mode]",
        "expected a literal number (it decides the gltf_pbr's expansion), got \"$n\" [/nodes/g/attenuation_distance]",
        "expected true or false, got 1 [/nodes/g/unlit]"}) {
    EXPECT_NE(all.find(want), std::string::npos) << want << "\nin:\n" << all;
    ++found;
  }
  EXPECT_EQ(found, 7);
  EXPECT_EQ(d.errorCount(), 7u) << all;
}

TEST(BuildingBlocks, AnExpandedDocumentHoldsNoBlockAndCompilesAlike) {
  const std::string json = material(R"("root": {"kind": "clear_coat", "base_color": [0.3, 0.6, 0.2],
      "roughness": 0.45, "clear_coat": 0.5})");
  Diagnostics d("test.json");
  const auto doc = parseJsonDocument(json, {}, d);
  ASSERT_TRUE(doc);
  EXPECT_TRUE(blocks::hasBuildingBlocks(*doc));
  std::vector<blocks::ExpandedBlock> expanded;
  const auto flat = blocks::expandBuildingBlocks(*doc, d, {}, expanded);
  ASSERT_TRUE(flat) << d.formatAll();
  EXPECT_FALSE(blocks::hasBuildingBlocks(*flat));
  EXPECT_EQ((*flat)["nodes"]["root"]["kind"], "vertical");  // the root keeps the block's id
  const auto a = evaluated(compiled(json), 0.5), b = evaluated(compiled(flat->dump()), 0.5);
  ASSERT_EQ(a.closures.size(), b.closures.size());
  for (std::size_t i = 0; i < a.closures.size(); ++i) {
    EXPECT_EQ(a.closures[i].f0, b.closures[i].f0);
    EXPECT_EQ(a.closures[i].weight, b.closures[i].weight);
  }
}

TEST(BuildingBlocks, EveryBlockIsListedOnceWithItsPins) {
  std::set<std::string> kinds;
  for (const auto& b : blocks::buildingBlocks()) {
    EXPECT_TRUE(kinds.insert(b.signature.kind).second) << b.signature.kind;
    EXPECT_FALSE(b.signature.pins.empty()) << b.signature.kind;
    EXPECT_EQ(blocks::findBuildingBlock(b.signature.kind), &b);
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"coated_layer", "clear_coat", "cloth", "ue4_default_lit", "ue4_unlit",
                                          "legacy_conversion", "gltf_pbr", "standard_surface", "open_pbr_surface",
                                          "disney_principled"}));
}

TEST(BuildingBlocks, TheSchemaTakesEveryBlockWithTheResolversPins) {
  std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/schema/substrate-material.schema.json");
  const auto schema = nlohmann::json::parse(in);
  int checked = 0;
  for (const auto& b : blocks::buildingBlocks()) {
    SCOPED_TRACE(b.signature.kind);
    const auto& def = schema["$defs"]["kind_" + std::string(b.signature.kind)];
    ASSERT_TRUE(def.is_object()) << "no kind_" << b.signature.kind << " in the schema";
    std::set<std::string> pins{"kind", "comment"}, required{"kind"}, schemaPins, schemaRequired;
    for (const auto& p : b.signature.pins) {
      pins.insert(p.name);
      if (p.required) required.insert(p.name);
    }
    for (const auto& [name, _] : def["properties"].items()) schemaPins.insert(name);
    for (const auto& r : def["required"]) schemaRequired.insert(r.get<std::string>());
    EXPECT_EQ(schemaPins, pins);
    EXPECT_EQ(schemaRequired, required);
    bool listed = false;
    for (const auto& k : schema["$defs"]["substrate_node"]["properties"]["kind"]["enum"]) listed = listed || k == b.signature.kind;
    EXPECT_TRUE(listed) << "substrate_node's kinds";
    ++checked;
  }
  EXPECT_EQ(checked, 10);
}

}  // namespace building_blocks_test
}  // namespace substratec
