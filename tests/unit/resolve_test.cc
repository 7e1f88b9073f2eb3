// Tests for pass 2, resolve (compiler/core/passes/resolve.h), written as the
// "Errors" section of material-format.md: a good document resolves with every
// reference turned into an index; every kind of mistake is one located
// diagnostic (`file:line:col: error: ... [/json/pointer]`), and all of them are
// reported in one run.
#include "passes/resolve.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_util.h"

namespace substratec {
namespace {

using test::diagnosticsOf;
using test::material;

constexpr const char* kInputs = R"({
  "mask": {"type": "float", "default": 0.5, "min": 0, "max": 1},
  "tint": {"type": "color", "default": [0.8, 0.1, 0.1]},
  "uv": {"type": "vec2", "default": [0, 0]},
  "weave": {"type": "texture2d"}
})";

/// A document whose only node is the slab "root" with the given pins.
std::string slab(const std::string& pins) {
  return material(R"("root": {"kind": "slab")" + (pins.empty() ? "" : ", " + pins) + "}", kInputs);
}

std::optional<ResolvedDoc> resolveText(const std::string& json, Diagnostics& d) {
  auto doc = parseJsonDocument(json, ReadLimits{}, d);
  if (!doc) return std::nullopt;
  return resolveDocument(*doc, d);
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// ---------------------------------------------------------------------------
// Good documents

TEST(Resolve, GoodDocumentHasNoDiagnostics) {
  const std::string doc = R"({
    "$schema": "../schema/substrate-material.schema.json",
    "format": "substrate-material/1",
    "name": "good",
    "description": "every section used once",
    "settings": {"bytes_per_pixel": 64, "max_closures": 4, "thin_surface": true,
                 "surface_thickness": 0.001, "blend_mode": "masked"},
    "inputs": {
      "mask": {"type": "float", "default": 0.5, "min": 0, "max": 1},
      "tint": {"type": "color", "default": [0.8, 0.1, 0.1]},
      "weave": {"type": "texture2d"}
    },
    "nodes": {
      "metal": {"kind": "metalness_to_diffuse_f0", "base_color": "$tint", "metallic": "$mask"},
      "weave_tex": {"kind": "texture", "texture": "$weave"},
      "rough": {"kind": "multiply", "a": "weave_tex.r", "b": 0.5},
      "base": {"kind": "slab", "diffuse_albedo": "metal", "f0": "metal.f0", "roughness": "rough"},
      "coat": {"kind": "slab", "roughness": 0.1, "sss_mfp": 10, "diffuse_albedo": 0},
      "root": {"kind": "vertical", "top": "coat", "thickness": 0.0002,
               "base": {"kind": "horizontal", "background": "base", "mix": "$mask",
                        "foreground": {"kind": "slab", "roughness": {"kind": "one_minus", "x": "$mask"}}}}
    },
    "output": "root"
  })";
  EXPECT_EQ(diagnosticsOf(doc), "");
}

TEST(Resolve, EveryExampleResolves) {
  int count = 0;
  for (const auto& e : std::filesystem::directory_iterator(SUBSTRATEC_SOURCE_DIR "/examples")) {
    if (e.path().extension() != ".json") continue;
    ++count;
    EXPECT_EQ(diagnosticsOf(readFile(e.path().string())), "") << e.path();
  }
  EXPECT_GE(count, 9);
}

TEST(Resolve, ResolvedDocumentHoldsIndices) {
  const std::string json = R"({"format": "substrate-material/1", "name": "m",
    "settings": {"bytes_per_pixel": 48, "thin_surface": true, "blend_mode": "translucent_grey"},
    "inputs": {"mask": {"type": "float", "default": 0.25}, "tint": {"type": "color", "default": 0.5}},
    "nodes": {
      "r": {"kind": "one_minus", "x": "m2"},
      "m2": {"kind": "multiply", "a": "$mask", "b": 2},
      "s": {"kind": "slab", "roughness": "r"},
      "root": {"kind": "vertical", "top": "s", "base": {"kind": "slab", "diffuse_albedo": "$tint"}}
    },
    "output": "root"})";
  Diagnostics d("test.json");
  auto r = resolveText(json, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->name, "m");
  EXPECT_EQ(r->settings.bytesPerPixel, 48);
  EXPECT_EQ(r->settings.maxClosures, 8);  // default
  EXPECT_TRUE(r->settings.thinSurface);
  EXPECT_EQ(r->settings.blendMode, BlendMode::TranslucentGrey);

  ASSERT_EQ(r->inputs.size(), 2u);
  EXPECT_EQ(r->inputs[0].name, "mask");
  EXPECT_EQ(r->inputs[0].type, VType::Float);
  EXPECT_EQ(r->inputs[0].defaultValue[0], 0.25);
  EXPECT_EQ(r->inputs[1].name, "tint");
  EXPECT_EQ(r->inputs[1].type, VType::Vec3);
  EXPECT_TRUE(r->inputs[1].isColor);
  // A single number is grey.
  EXPECT_EQ(r->inputs[1].defaultValue, (std::array<double, 4>{0.5, 0.5, 0.5, 0}));

  // Substrate nodes: the named ones in file order, then the inline base named <parent>_<pin>.
  ASSERT_EQ(r->substrate.size(), 3u);
  EXPECT_EQ(r->substrate[0].id, "s");
  EXPECT_EQ(r->substrate[1].id, "root");
  EXPECT_EQ(r->substrate[2].id, "root_base");
  EXPECT_EQ(r->substrate[2].pointer, "/nodes/root/base");
  EXPECT_EQ(r->output, 1);
  EXPECT_EQ(r->substrate[1].op, TreeOp::Vertical);
  EXPECT_EQ(r->substrate[1].left, 0);
  EXPECT_EQ(r->substrate[1].right, 2);
  const PinRef& tint = r->substrate[2].slabPins[static_cast<int>(SlabPin::DiffuseAlbedo)];
  EXPECT_EQ(tint.tag, PinRef::Input);
  EXPECT_EQ(tint.index, 1);

  // Value nodes in dependency order: m2 before r, although r comes first in the file.
  ASSERT_EQ(r->values.size(), 2u);
  EXPECT_EQ(r->values[0].id, "r");
  EXPECT_EQ(r->values[1].id, "m2");
  EXPECT_EQ(r->valueOrder, (std::vector<int>{1, 0}));
  EXPECT_EQ(r->values[0].outputTypes, (std::vector<VType>{VType::Float}));
  const PinRef& rough = r->substrate[0].slabPins[static_cast<int>(SlabPin::Roughness)];
  EXPECT_EQ(rough.tag, PinRef::Node);
  EXPECT_EQ(rough.index, 0);
}

// ---------------------------------------------------------------------------
// Unknown keys and kinds

TEST(Resolve, UnknownTopLevelKey) {
  std::string doc = slab("");
  doc.insert(1, R"("colour": 1, )");
  EXPECT_EQ(diagnosticsOf(doc),
            "test.json:1:12: error: unknown key \"colour\" (expected one of: format, name, settings, inputs, nodes, output) [/colour]\n");
}

TEST(Resolve, UnknownSetting) {
  std::string doc = slab("");
  doc.insert(1, R"("settings": {"max_bytes": 40}, )");
  EXPECT_EQ(diagnosticsOf(doc),
            "test.json:1:28: error: unknown setting \"max_bytes\" (expected bytes_per_pixel, max_closures, thin_surface, surface_thickness or blend_mode) [/settings/max_bytes]\n");
}

TEST(Resolve, UnknownInputKey) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "slab", "roughness": "$r"})",
                                   R"({"r": {"type": "float", "default": 0.5, "maximum": 1}})")),
            "test.json:1:110: error: unknown input key \"maximum\" (expected type, default, min, max, description; texture2d: colorspace, file, wrap, filter) [/inputs/r/maximum]\n");
}

TEST(Resolve, UnknownSlabPin) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughnes": 0.5)")),
            "test.json:6:51: error: unknown slab pin \"roughnes\" [/nodes/root/roughnes]\n");
}

TEST(Resolve, UnknownPinOnAMathNode) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": {"kind": "multiply", "a": "$mask", "b": 2, "c": 3})")),
            "test.json:6:100: error: unknown pin \"c\" for a multiply node (pins: a, b) [/nodes/root/roughness/c]\n");
}

TEST(Resolve, UnknownPinOnASubstrateOperator) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": "s", "mix": 0.5})")),
            "test.json:3:66: error: unknown pin \"mix\" for a vertical node (pins: top, base, thickness) [/nodes/root/mix]\n");
}

TEST(Resolve, UnknownNodeKind) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "slub"})")),
            "test.json:1:90: error: unknown node kind \"slub\" [/nodes/root/kind]\n");
}

TEST(Resolve, UnknownInlineNodeKind) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": {"kind": "mystery", "x": 1})")),
            "test.json:6:61: error: unknown node kind \"mystery\" [/nodes/root/roughness/kind]\n");
}

TEST(Resolve, UnknownGeometryAttribute) {
  EXPECT_EQ(diagnosticsOf(slab(R"("normal": {"kind": "geometry", "attribute": "bitangent"})")),
            "test.json:6:83: error: expected one of normal, tangent, uv0, uv1, vertex_color, position, view; got \"bitangent\" [/nodes/root/normal/attribute]\n");
}

// ---------------------------------------------------------------------------
// Wrong types

TEST(Resolve, WrongType_FloatPinGivenAVec3Literal) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": [0.1, 0.2, 0.3])")),
            "test.json:6:52: error: expected a float, got a vec3 [/nodes/root/roughness]\n");
}

TEST(Resolve, WrongType_ColorPinGivenAVec2Literal) {
  EXPECT_EQ(diagnosticsOf(slab(R"("diffuse_albedo": [0.1, 0.2])")),
            "test.json:6:57: error: expected a color, got a vec2 [/nodes/root/diffuse_albedo]\n");
}

TEST(Resolve, WrongType_DirectionIsNeverGrey) {
  EXPECT_EQ(diagnosticsOf(slab(R"("normal": 1)")),
            "test.json:6:49: error: expected a vec3, got a float [/nodes/root/normal]\n");
}

TEST(Resolve, WrongType_FloatPinGivenAColorInput) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": "$tint")")),
            "test.json:6:52: error: expected a float, got a vec3 [/nodes/root/roughness]\n");
}

TEST(Resolve, WrongType_TextureInputUsedAsAValue) {
  EXPECT_EQ(diagnosticsOf(slab(R"("diffuse_albedo": "$weave")")),
            "test.json:6:57: error: \"$weave\" is a texture2d input; sample it with a \"texture\" node [/nodes/root/diffuse_albedo]\n");
}

TEST(Resolve, WrongType_VectorsOfDifferentSizesDoNotCombine) {
  EXPECT_EQ(diagnosticsOf(slab(R"("diffuse_albedo": {"kind": "add", "a": "$uv", "b": "$tint"})")),
            "test.json:6:57: error: cannot combine vec2 \"a\" with vec3 \"b\" (a float broadcasts; vectors must match) [/nodes/root/diffuse_albedo]\n");
}

TEST(Resolve, WrongType_SettingNotABoolean) {
  std::string doc = slab("");
  doc.insert(1, R"("settings": {"thin_surface": "yes"}, )");
  EXPECT_EQ(diagnosticsOf(doc), "test.json:1:31: error: expected true or false, got \"yes\" [/settings/thin_surface]\n");
}

TEST(Resolve, WrongType_NumberWrittenAsAString) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": "0.5")")),
            "test.json:6:52: error: expected a number, got the string \"0.5\" (remove the quotes) [/nodes/root/roughness]\n");
}

TEST(Resolve, WrongType_ValueNodeRules) {
  // Unused nodes are checked too; each rule of docs/value-nodes.md is one error.
  EXPECT_EQ(diagnosticsOf(material(R"(
    "sw": {"kind": "swizzle", "x": "$uv", "channels": "xz"},
    "d": {"kind": "dot", "a": "$uv", "b": "$tint"},
    "cb": {"kind": "combine", "x": 1, "y": 2, "w": 3},
    "l": {"kind": "lerp", "a": "$tint", "b": 1, "t": "$uv"},
    "tex": {"kind": "texture", "texture": "$mask"},
    "root": {"kind": "slab"})",
                                   kInputs)),
            "test.json:11:43: error: input \"$mask\" is a float, expected a texture2d input [/nodes/tex/texture]\ntest.json:7:55: error: channel out of range for a vec2 [/nodes/sw/channels]\ntest.json:8:10: error: dot needs two values of one type, got vec2 and vec3 [/nodes/d]\ntest.json:9:52: error: \"w\" given without \"z\" [/nodes/cb/w]\ntest.json:10:54: error: expected a float or a vec3, got a vec2 [/nodes/l/t]\n");
}

TEST(Resolve, MissingOutput) {
  EXPECT_EQ(diagnosticsOf(R"({"format": "substrate-material/1", "name": "m", "nodes": {"root": {"kind": "slab"}}})"),
            "test.json:1:1: error: missing required key \"output\" (the id of the root Substrate node) [/]\n");
}

// A named (or inline) value node plugged into a slab pin must have the pin's
// type, like a literal or an input. BUG: resolve never checks the type of a
// pin that references a value node (readValuePin leaves PinRef::type Invalid
// for Node pins, and expectPinType skips Invalid), so a vec3 is accepted as a
// roughness, and build_tree plugs a vec3 DAG node into a float pin.
TEST(Resolve, WrongType_FloatPinGivenAVec3ValueNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "v": {"kind": "multiply", "a": [1, 1, 1], "b": 0.5},
    "root": {"kind": "slab", "roughness": "v"})")),
            "test.json:3:43: error: expected a float, got a vec3 [/nodes/root/roughness]\n");
  EXPECT_EQ(diagnosticsOf(slab(R"("anisotropy": {"kind": "add", "a": [0.1, 0.2], "b": 0.1})")),
            "test.json:6:53: error: expected a float, got a vec2 [/nodes/root/anisotropy]\n");
  EXPECT_EQ(diagnosticsOf(material(R"(
    "v": {"kind": "multiply", "a": [1, 1, 1], "b": 0.5},
    "s": {"kind": "slab"},
    "root": {"kind": "horizontal", "background": "s", "foreground": "s", "mix": "v"})")),
            "test.json:4:81: error: expected a float, got a vec3 [/nodes/root/mix]\n");
}

// ---------------------------------------------------------------------------
// Out-of-range literals

TEST(Resolve, OutOfRange_RoughnessAboveOne) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": 1.5)")),
            "test.json:6:52: error: expected a float in [0,1], got 1.5 [/nodes/root/roughness]\n");
}

TEST(Resolve, OutOfRange_AnisotropyBelowMinusOne) {
  EXPECT_EQ(diagnosticsOf(slab(R"("anisotropy": -1.5)")),
            "test.json:6:53: error: expected a float in [-1,1], got -1.5 [/nodes/root/anisotropy]\n");
}

TEST(Resolve, OutOfRange_OneColorComponentAboveOne) {
  EXPECT_EQ(diagnosticsOf(slab(R"("f0": [0.5, 1.2, 0.1])")),
            "test.json:6:45: error: expected a color with components in [0,1], got an array of 3 [/nodes/root/f0]\n");
}

TEST(Resolve, OutOfRange_NegativeMeanFreePath) {
  EXPECT_EQ(diagnosticsOf(slab(R"("sss_mfp": -0.001)")),
            "test.json:6:50: error: expected a color with components >= 0, got -0.001 [/nodes/root/sss_mfp]\n");
}

TEST(Resolve, OutOfRange_OperatorValues) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "horizontal", "background": "s", "foreground": "s", "mix": 2})")),
            "test.json:3:81: error: expected a float in [0,1], got 2 [/nodes/root/mix]\n");
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": "s", "thickness": -1})")),
            "test.json:3:72: error: expected a float >= 0, got -1 [/nodes/root/thickness]\n");
}

TEST(Resolve, OutOfRange_ZeroDirection) {
  EXPECT_EQ(diagnosticsOf(slab(R"("normal": [0, 0, 0])")),
            "test.json:6:49: error: expected a non-zero direction, got an array of 3 [/nodes/root/normal]\n");
}

TEST(Resolve, OutOfRange_InputDefaultOutsideItsBounds) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "slab", "roughness": "$r"})",
                                   R"({"r": {"type": "float", "default": 2, "min": 0, "max": 1}})")),
            "test.json:1:94: error: default 2 is outside [0, 1] [/inputs/r/default]\n");
}

TEST(Resolve, NoModify_RangeLimitsAreInclusive) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": 1, "anisotropy": -1, "f0": [0, 1, 0.5], "sss_mfp": 0)")), "");
}

// ---------------------------------------------------------------------------
// Dangling references

TEST(Resolve, Dangling_UnknownInput) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": "$nope")")),
            "test.json:6:52: error: unknown input \"$nope\" [/nodes/root/roughness]\n");
}

TEST(Resolve, Dangling_UnknownValueNode) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": "nope")")),
            "test.json:6:52: error: unknown node \"nope\" [/nodes/root/roughness]\n");
}

TEST(Resolve, Dangling_InputNameWithoutDollar) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": "mask")")),
            "test.json:6:52: error: unknown node \"mask\"; to use the input write \"$mask\" [/nodes/root/roughness]\n");
}

TEST(Resolve, Dangling_UnknownSubstrateNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": "nope"})")),
            "test.json:3:54: error: unknown node \"nope\" [/nodes/root/base]\n");
}

TEST(Resolve, Dangling_UnknownOutput) {
  EXPECT_EQ(diagnosticsOf(material(R"("s": {"kind": "slab"})", "{}", "root")),
            "test.json:1:107: error: unknown node \"root\" [/output]\n");
}

TEST(Resolve, Dangling_UnknownOutputSuffix) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "metal": {"kind": "metalness_to_diffuse_f0", "metallic": 1},
    "root": {"kind": "slab", "f0": "metal.specular"})")),
            "test.json:3:36: error: node \"metal\" has no output \".specular\" (outputs: .diffuse_albedo, .f0) [/nodes/root/f0]\n");
}

TEST(Resolve, Dangling_SuffixOnASingleOutputNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "half": {"kind": "multiply", "a": "$mask", "b": 0.5},
    "root": {"kind": "slab", "roughness": "half.x"})",
                                   kInputs)),
            "test.json:8:43: error: node \"half\" has a single output; write \"half\" without a suffix [/nodes/root/roughness]\n");
}

// ---------------------------------------------------------------------------
// Value / Substrate mix-ups

TEST(Resolve, MixUp_ValuePinGivenASubstrateNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "coat": {"kind": "slab"},
    "root": {"kind": "slab", "roughness": "coat"})")),
            "test.json:3:43: error: expected a value, got Substrate node \"coat\" [/nodes/root/roughness]\n");
}

TEST(Resolve, MixUp_ValuePinGivenAnInlineSubstrateNode) {
  EXPECT_EQ(diagnosticsOf(slab(R"("roughness": {"kind": "slab"})")),
            "test.json:6:52: error: expected a value, got an inline Substrate node (slab) [/nodes/root/roughness]\n");
}

TEST(Resolve, MixUp_SubstratePinGivenANumber) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": 0.5})")),
            "test.json:3:54: error: expected a Substrate node (an id or an inline slab/operator), got 0.5 [/nodes/root/base]\n");
}

TEST(Resolve, MixUp_SubstratePinGivenAnInput) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "coverage_weight", "a": "$mask", "weight": 0.5})",
                                   kInputs)),
            "test.json:8:46: error: expected a Substrate node, got input \"$mask\" [/nodes/root/a]\n");
}

TEST(Resolve, MixUp_SubstratePinGivenAValueNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "v": {"kind": "multiply", "a": 0.5, "b": 0.5},
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "v", "base": "s"})")),
            "test.json:4:41: error: expected a Substrate node, got value node \"v\" [/nodes/root/top]\n");
}

TEST(Resolve, MixUp_SubstratePinGivenAnInlineValueNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": {"kind": "multiply", "a": 1, "b": 2}})")),
            "test.json:3:54: error: expected a Substrate node, got an inline multiply value node [/nodes/root/base]\n");
}

TEST(Resolve, MixUp_OutputNamesAValueNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "v": {"kind": "multiply", "a": 0.5, "b": 0.5},
    "s": {"kind": "slab"})",
                                   "{}", "v")),
            "test.json:3:39: error: \"v\" is a value node; the output must be a Substrate node (slab, unlit, hair, volumetric_fog_cloud, eye, single_layer_water, horizontal, vertical, add, coverage_weight, select) [/output]\n");
}

TEST(Resolve, MixUp_OutputNamesAnInput) {
  EXPECT_EQ(diagnosticsOf(material(R"("s": {"kind": "slab"})", kInputs, "mask")),
            "test.json:6:48: error: \"mask\" is an input, not a Substrate node [/output]\n");
}

// ---------------------------------------------------------------------------
// Cycles

TEST(Resolve, Cycle_TwoValueNodes) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "a": {"kind": "multiply", "a": "b", "b": 2},
    "b": {"kind": "add", "a": "a", "b": 1},
    "root": {"kind": "slab", "roughness": "a"})")),
            "test.json:3:10: error: cycle in values: a -> b -> a [/nodes/b]\n");
}

TEST(Resolve, Cycle_ValueNodeReferencesItself) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "a": {"kind": "saturate", "x": "a"},
    "root": {"kind": "slab", "roughness": "a"})")),
            "test.json:2:10: error: cycle in values: a -> a [/nodes/a]\n");
}

TEST(Resolve, Cycle_ThroughAnInlineValueNodeIsNamedByItsPointer) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "a": {"kind": "one_minus", "x": {"kind": "abs", "x": "a"}},
    "root": {"kind": "slab", "roughness": "a"})")),
            "test.json:2:37: error: cycle in values: a -> /nodes/a/x -> a [/nodes/a/x]\n");
}

TEST(Resolve, Cycle_SubstrateSelfReference) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": "root"})")),
            "test.json:3:13: error: cycle in the Substrate graph: root -> root [/nodes/root]\n");
}

TEST(Resolve, Cycle_ThreeSubstrateNodes) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s", "base": "h"},
    "h": {"kind": "horizontal", "background": "s", "foreground": "w", "mix": 0.5},
    "w": {"kind": "coverage_weight", "a": "root", "weight": 0.5})")),
            "test.json:5:10: error: cycle in the Substrate graph: root -> h -> w -> root [/nodes/w]\n");
}

TEST(Resolve, Cycle_SubstrateThroughAnInlineNode) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "vertical", "top": "s",
             "base": {"kind": "horizontal", "background": "root", "foreground": "s", "mix": 0.5}})")),
            "test.json:4:22: error: cycle in the Substrate graph: root -> root_base -> root [/nodes/root/base]\n");
}

TEST(Resolve, NoModify_ADiamondIsNotACycle) {
  // A value or Substrate node referenced twice is shared (values) or instanced
  // twice (Substrate), never a cycle.
  EXPECT_EQ(diagnosticsOf(material(R"(
    "half": {"kind": "multiply", "a": "$mask", "b": 0.5},
    "r": {"kind": "add", "a": "half", "b": "half"},
    "s": {"kind": "slab", "roughness": "r"},
    "root": {"kind": "horizontal", "background": "s", "foreground": "s", "mix": "half"})",
                                   kInputs)),
            "");
}

// ---------------------------------------------------------------------------
// "add" is a math node on values and a Substrate operator on matter

TEST(Resolve, Add_OnValuesIsMath) {
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "sum": {"kind": "add", "a": "$mask", "b": 0.25},
    "root": {"kind": "slab", "roughness": "sum"})",
                                kInputs),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  ASSERT_EQ(r->values.size(), 1u);
  EXPECT_EQ(r->values[0].op, Op::Add);
  ASSERT_EQ(r->substrate.size(), 1u);
  EXPECT_EQ(r->substrate[0].op, TreeOp::Slab);
}

TEST(Resolve, Add_OnMatterIsASubstrateOperator) {
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "a": {"kind": "slab"},
    "b": {"kind": "slab", "roughness": 0.2},
    "root": {"kind": "add", "a": "a", "b": "b"})"),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_TRUE(r->values.empty());
  ASSERT_EQ(r->substrate.size(), 3u);
  EXPECT_EQ(r->substrate[2].id, "root");
  EXPECT_EQ(r->substrate[2].op, TreeOp::Add);
  EXPECT_EQ(r->substrate[2].left, 0);
  EXPECT_EQ(r->substrate[2].right, 1);
}

TEST(Resolve, Add_OfAddsOfMatterIsSubstrate) {
  // "outer" and "inner2" only see other named adds; they are Substrate because "inner" is.
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "outer": {"kind": "add", "a": "inner", "b": "inner2"},
    "inner2": {"kind": "add", "a": "inner", "b": "inner"},
    "inner": {"kind": "add", "a": "s", "b": {"kind": "slab"}},
    "s": {"kind": "slab"})",
                                "{}", "outer"),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_TRUE(r->values.empty());
  ASSERT_EQ(r->substrate.size(), 5u);
  for (const SNode& s : r->substrate) EXPECT_TRUE(s.op == TreeOp::Add || s.op == TreeOp::Slab) << s.id;
  EXPECT_EQ(r->substrate[r->output].id, "outer");
}

TEST(Resolve, Add_MixingMatterAndAValueIsAnError) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "s": {"kind": "slab"},
    "root": {"kind": "add", "a": "s", "b": 0.5})")),
            "test.json:3:44: error: expected a Substrate node (an id or an inline slab/operator), got 0.5 [/nodes/root/b]\n");
}

// ---------------------------------------------------------------------------
// Multi-output helpers

TEST(Resolve, MultiOutput_UnnamedReferencePicksTheOutputNamedLikeThePin) {
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "metal": {"kind": "metalness_to_diffuse_f0", "base_color": 0.9, "metallic": "$mask"},
    "root": {"kind": "slab", "diffuse_albedo": "metal", "f0": "metal"})",
                                kInputs),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  const SNode& s = r->substrate[0];
  const PinRef& albedo = s.slabPins[static_cast<int>(SlabPin::DiffuseAlbedo)];
  const PinRef& f0 = s.slabPins[static_cast<int>(SlabPin::F0)];
  EXPECT_EQ(albedo.tag, PinRef::Node);
  EXPECT_EQ(albedo.output, 0);  // .diffuse_albedo
  EXPECT_EQ(f0.tag, PinRef::Node);
  EXPECT_EQ(f0.index, albedo.index);
  EXPECT_EQ(f0.output, 1);  // .f0
}

TEST(Resolve, MultiOutput_InlineHelperPicksTheOutputNamedLikeThePin) {
  Diagnostics d("test.json");
  auto r = resolveText(slab(R"("second_roughness_weight": {"kind": "haziness_to_second_roughness", "haziness": 0.5,
                                                            "roughness": "$mask"})"),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  const PinRef& p = r->substrate[0].slabPins[static_cast<int>(SlabPin::SecondRoughnessWeight)];
  EXPECT_EQ(p.tag, PinRef::Node);
  EXPECT_EQ(p.output, 1);  // .second_roughness_weight
}

TEST(Resolve, MultiOutput_PinsOfOperatorsAndValueNodesPickByNameToo) {
  // The vertical's "thickness" takes t.thickness; thin_film's "f0" takes metal.f0.
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "t": {"kind": "transmittance_to_mfp", "transmittance": "$tint", "thickness": "$mask"},
    "metal": {"kind": "metalness_to_diffuse_f0", "metallic": "$mask"},
    "film": {"kind": "thin_film", "f0": "metal", "thickness": 3e-7},
    "s": {"kind": "slab", "f0": "film", "sss_mfp": "t.mfp"},
    "root": {"kind": "vertical", "top": "s", "base": "s", "thickness": "t"})",
                                kInputs),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  const SNode& root = r->substrate[r->output];
  EXPECT_EQ(root.a.tag, PinRef::Node);
  EXPECT_EQ(r->values[root.a.index].id, "t");
  EXPECT_EQ(root.a.output, 1);  // .thickness
  const VNode& film = r->values[2];
  ASSERT_EQ(film.id, "film");
  EXPECT_EQ(film.pins[1].tag, PinRef::Node);  // pins: normal, f0, f90, thickness, ior
  EXPECT_EQ(r->values[film.pins[1].index].id, "metal");
  EXPECT_EQ(film.pins[1].output, 1);  // .f0
  EXPECT_EQ(r->substrate[0].slabPins[static_cast<int>(SlabPin::F0)].output, 0);  // film.f0
}

TEST(Resolve, MultiOutput_NoOutputNamedLikeThePinIsAnError) {
  EXPECT_EQ(diagnosticsOf(material(R"(
    "metal": {"kind": "metalness_to_diffuse_f0", "metallic": 1},
    "root": {"kind": "slab", "fuzz_color": "metal", "fuzz_amount": 0.5})")),
            "test.json:3:44: error: node \"metal\" has several outputs; name one (.diffuse_albedo, .f0) [/nodes/root/fuzz_color]\n");
}

TEST(Resolve, MultiOutput_TextureWithoutSuffixIsRgb) {
  Diagnostics d("test.json");
  auto r = resolveText(material(R"(
    "tex": {"kind": "texture", "texture": "$weave"},
    "root": {"kind": "slab", "diffuse_albedo": "tex", "roughness": "tex.a"})",
                                kInputs),
                       d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->substrate[0].slabPins[static_cast<int>(SlabPin::DiffuseAlbedo)].output, 0);  // .rgb
  EXPECT_EQ(r->substrate[0].slabPins[static_cast<int>(SlabPin::Roughness)].output, 4);      // .a
}

// ---------------------------------------------------------------------------
// All errors in one run

TEST(Resolve, AllErrorsAreReportedInOneRun) {
  std::string doc = material(R"(
    "a": {"kind": "slab", "roughness": 2},
    "b": {"kind": "slab", "diffuse_albedo": "$nope"},
    "c": {"kind": "slab", "rougness": 0.3},
    "d": {"kind": "slab", "f0": [0.04, 0.04]},
    "e": {"kind": "slab", "roughness": {"kind": "swizzle", "x": "$tint", "channels": "q"}},
    "h1": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": 0.5},
    "h2": {"kind": "horizontal", "background": "c", "foreground": "d", "mix": 0.5},
    "h3": {"kind": "horizontal", "background": "h1", "foreground": "h2", "mix": 0.5},
    "root": {"kind": "vertical", "top": "e", "base": "h3"})",
                             kInputs);
  doc.insert(1, R"("settings": {"max_closures": 9}, )");
  EXPECT_EQ(diagnosticsOf(doc),
            "test.json:1:31: error: expected an integer in [1,8], got 9 [/settings/max_closures]\ntest.json:7:40: error: expected a float in [0,1], got 2 [/nodes/a/roughness]\ntest.json:8:45: error: unknown input \"$nope\" [/nodes/b/diffuse_albedo]\ntest.json:9:39: error: unknown slab pin \"rougness\" [/nodes/c/rougness]\ntest.json:10:33: error: expected a color, got a vec2 [/nodes/d/f0]\ntest.json:11:86: error: expected 1 to 4 channels from xyzw or rgba, got \"q\" [/nodes/e/roughness/channels]\n");
}

TEST(Resolve, ErrorsStopAtTheLimit) {
  std::string pins;
  for (int i = 0; i < 60; ++i) pins += (i ? ", " : "") + std::string("\"p") + std::to_string(i) + "\": 1";
  std::string out = diagnosticsOf(slab(pins));
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 51);
  EXPECT_NE(out.find(": error: unknown slab pin \"p49\" [/nodes/root/p49]\n"), std::string::npos) << out;
  EXPECT_EQ(out.find("/p50]"), std::string::npos);
  EXPECT_NE(out.find("test.json: error: too many errors (10 more not shown)\n"), std::string::npos);
}

}  // namespace
}  // namespace substratec
