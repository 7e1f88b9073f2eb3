// The volumetric fog cloud as a material (docs/format.md, "The volumetric fog
// cloud"; docs/storage.md, "Volumetric fog cloud"): its pins, that it is the
// whole material, that it makes a volume with a 12-byte froxel payload and no
// closure whatever the budget, and what `compile` writes for it. Its runtime
// and CPU mirror: fog_cloud_test.cc; on lavapipe: gpu/fog_cloud_gpu_test.cc.
#include <gtest/gtest.h>

#include <string>

#include "diag/diagnostics.h"
#include "pipeline/generate.h"
#include "pipeline/pipeline.h"
#include "accuracy/fog_accuracy.h"
#include "report/report.h"
#include "test_util.h"

namespace substratec {
namespace fog_cloud_format_test {

using test::diagnosticsOf;
using test::material;

std::optional<CompileResult> compiled(const std::string& json, CompileOptions o = {}) {
  Diagnostics d("test.json");
  auto r = compileText("test.json", json, o, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r;
}

const char* kCloud = R"("root": {"kind": "volumetric_fog_cloud", "albedo": [0.9, 0.9, 0.95], "extinction": 3,
    "emissive": [0, 0, 0.1], "ambient_occlusion": 0.7})";

TEST(FogCloudNode, TakesAlbedoExtinctionEmissiveAndAmbientOcclusionOnly) {
  EXPECT_EQ(diagnosticsOf(material(kCloud)), "");
  const std::string d = diagnosticsOf(material(R"("root": {"kind": "volumetric_fog_cloud", "roughness": 0.5})"));
  EXPECT_NE(d.find("unknown pin \"roughness\" for a volumetric_fog_cloud node (pins: emissive, albedo, extinction, "
                   "ambient_occlusion) [/nodes/root/roughness]"),
            std::string::npos)
      << d;
  // Ranges: albedo and occlusion in [0, 1], extinction >= 0, each error at its pin.
  for (const char* pin : {R"("albedo": 1.5)", R"("extinction": -1)", R"("ambient_occlusion": 2)"}) {
    const std::string bad = diagnosticsOf(material(std::string(R"("root": {"kind": "volumetric_fog_cloud", )") + pin + "}"));
    const std::string name = std::string(pin).substr(1, std::string(pin).find('"', 1) - 1);
    EXPECT_NE(bad.find("[/nodes/root/" + name + "]"), std::string::npos) << bad;
  }
  // A slab takes none of its pins.
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "extinction": 1})")).find("unknown slab pin \"extinction\""),
            std::string::npos);
}

TEST(FogCloudNode, IsTheWholeMaterialNeverAnOperand) {
  for (const char* op : {R"("root": {"kind": "horizontal", "background": "s", "foreground": "f", "mix": 0.5})",
                         R"("root": {"kind": "coverage_weight", "a": "f", "weight": 0.5})",
                         R"("root": {"kind": "vertical", "top": "f", "base": "s"})",
                         R"("root": {"kind": "add", "a": "f", "b": "s"})"}) {
    Diagnostics d("test.json");
    const std::string json =
        material(std::string(R"("f": {"kind": "volumetric_fog_cloud", "extinction": 1}, "s": {"kind": "slab"}, )") + op);
    EXPECT_FALSE(compileText("test.json", json, {}, d).has_value()) << op;
    const std::string all = d.formatAll();
    EXPECT_NE(all.find("volumetric_fog_cloud 'f' is an operand of"), std::string::npos) << all;
    EXPECT_NE(all.find("a volumetric fog cloud must be the whole material"), std::string::npos) << all;
    EXPECT_NE(all.find("[/nodes/f]"), std::string::npos) << all;
  }
}

TEST(FogCloudNode, OneThatNeitherExtinguishesNorEmitsIsAWarning) {
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "volumetric_fog_cloud", "albedo": 0.5})"))
                .find("warning: volumetric fog cloud 'root' has extinction 0 and emissive 0: it shows nothing "
                      "[/nodes/root]"),
            std::string::npos);
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "volumetric_fog_cloud", "emissive": 0.1})")), "");
  EXPECT_EQ(diagnosticsOf(material(kCloud)), "");
}

TEST(FogCloudNode, MakesAVolumeWithATwelveByteFroxelPayloadAndNoClosure) {
  auto r = compiled(material(kCloud));
  ASSERT_TRUE(r);
  EXPECT_TRUE(isVolumeMaterial(r->material));
  EXPECT_EQ(r->after.layoutClass, LayoutClass::Volume);
  EXPECT_TRUE(r->after.closures.empty());
  std::string names;
  for (const auto& f : r->after.fields) names += f.name + ":" + std::to_string(f.bits) + " ";
  EXPECT_EQ(names, "fog.albedo:24 fog.ambient_occlusion:8 fog.extinction:32 fog.emissive:32 ");
  EXPECT_EQ(r->after.bytes(), 12) << "3 words, no top-layer word: a volume has no surface";
  EXPECT_NE(formatReportText(*r).find("Op=FOG_CLOUD"), std::string::npos);
  EXPECT_EQ(reportJson(*r)["layout"], "VOLUME");
  EXPECT_EQ(reportJson(*r)["features"], nlohmann::ordered_json::array({"emissive"}));
}

TEST(FogCloudNode, NoBudgetSimplifiesIt) {
  // The budget is the GBuffer's; a volume stores none, so neither a small
  // budget nor full simplification is an error or a step.
  CompileOptions small;
  small.budgetOverride = 4;
  small.maxClosuresOverride = 1;
  CompileOptions full;
  full.fullSimplification = true;
  for (const CompileOptions& o : {small, full}) {
    auto r = compiled(material(kCloud), o);
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->steps.empty());
    EXPECT_EQ(r->after.bytes(), 12);
  }
}

TEST(FogCloudNode, CompilesToASampleFunctionAndAFroxelPassInBothLanguages) {
  auto r = compiled(material(kCloud));
  ASSERT_TRUE(r);
  Generated g = generateFiles(*r, GenerateOptions{});
  std::string names;
  for (const OutputFile& f : g.files) names += f.name + " ";
  EXPECT_EQ(names, "m.material.glsl m.volume.comp m.material.hlsl m.volume.cs.hlsl m.layout.json ");
  EXPECT_NE(g.files[0].contents.find("SubstrateFogCloudSample m_sample(SubstrateGeometry g)"), std::string::npos);
  EXPECT_NE(g.files[0].contents.find("void m_pack(SubstrateFogCloudSample s, out uint words[M_WORD_COUNT])"),
            std::string::npos);
  validateGenerated(g);
  EXPECT_TRUE(g.valid) << g.failure;
  EXPECT_EQ(g.entries.size(), 2u) << "the froxel pass in GLSL and HLSL, compiled and validated";
}

// ---------------------------------------------------------------------------
// `substratec accuracy` of a volume (accuracy/fog_accuracy.h): its march
// against step counts, and the froxel payload's own error.

TEST(FogCloudAccuracy, AHomogeneousMediumIsExactAtAnyStepCount) {
  auto r = compiled(material(R"("root": {"kind": "volumetric_fog_cloud", "albedo": 0.3,
      "extinction": [0.5, 1, 2], "emissive": 0.1})"));
  ASSERT_TRUE(r);
  const accuracy::FogReport a = accuracy::fogAccuracy(r->material, r->after.bytes());
  EXPECT_EQ(a.rays, 64) << "every ray has radiance";
  ASSERT_EQ(a.rows.size(), 6u);
  for (const accuracy::FogRow& row : a.rows) {
    // The step is exact for constant coefficients; thin steps use the series (tau^3 / 24).
    EXPECT_LT(row.maxError, 1e-6) << row.steps;
    // The payload: albedo 0.3 in unorm8 is off by up to 0.5 / 255 / 0.3 = 0.65 %, and 0.5 shares
    // its RGB9E5 exponent with 2 (measured 0.54 %).
    EXPECT_LT(row.payloadMaxError, 1e-2) << row.steps << ": RGB9E5 and unorm8";
    EXPECT_GT(row.payloadMaxError, 0.0) << "quantized";
  }
}

TEST(FogCloudAccuracy, AVaryingMediumConvergesAtSecondOrder) {
  auto r = compiled(material(R"("root": {"kind": "volumetric_fog_cloud", "albedo": 0.9,
      "extinction": {"kind": "multiply", "a": 4, "b": {"kind": "saturate", "x": {"kind": "one_minus",
        "x": {"kind": "length", "x": {"kind": "geometry", "attribute": "position"}}}}}})"));
  ASSERT_TRUE(r);
  const accuracy::FogReport a = accuracy::fogAccuracy(r->material, r->after.bytes());
  ASSERT_GT(a.rays, 0);
  ASSERT_EQ(a.rows.size(), 6u);  // 4 ... 128 steps
  for (std::size_t i = 1; i < a.rows.size(); ++i) EXPECT_LT(a.rows[i].maxError, a.rows[i - 1].maxError) << a.rows[i].steps;
  EXPECT_GT(a.rows[1].maxError / a.rows[4].maxError, 20.0) << "8 vs 64 steps: second order gives ~64";
}

TEST(FogCloudAccuracy, NothingToMeasureIsNoRay) {
  auto r = compiled(material(R"("root": {"kind": "volumetric_fog_cloud", "extinction": 1})"));
  ASSERT_TRUE(r);
  EXPECT_EQ(accuracy::fogAccuracy(r->material, r->after.bytes()).rays, 0) << "black: no radiance to compare";
}

}  // namespace fog_cloud_format_test
}  // namespace substratec
