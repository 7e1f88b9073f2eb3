// The importers (compiler/tools/import/), read like their specification
// (docs/import.md): the .glb container, the glTF and MaterialX errors (each
// located), and the mapping formulas, checked on the closures the CPU
// reference evaluates from the imported material at its inputs' defaults.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <random>
#include <set>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/generate.h"
#include "import/glb_container.h"
#include "import/gltf_resources.h"
#include "import/import.h"
#include "passes/resolve.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace importer_test {
using namespace substratec;
using namespace substratec::import;

struct Imported {
  std::optional<std::vector<ImportedMaterial>> materials;
  std::string diags;
};

Imported importAs(SourceKind kind, const std::string& text, const std::string& file = "test") {
  Diagnostics d(file);
  Imported r;
  r.materials = importText(kind, file, text, ".", ReadLimits{}, d, ImportForm::Expanded);  // the mapping's nodes
  r.diags = d.formatAll();
  return r;
}

/// The mapping alone: read as an extract (the resources a .gltf refers to are
/// checked by the GltfResources tests).
Imported gltf(const std::string& materialsJson, const std::string& rest = "") {
  return importAs(SourceKind::GltfMaterials, "{\"materials\": " + materialsJson + rest + "}", "t.gltf");
}

Imported mtlx(const std::string& body) {
  return importAs(SourceKind::MaterialX, "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\">\n" + body + "</materialx>\n",
                  "t.mtlx");
}

CompileResult compiled(const ImportedMaterial& m) {
  Diagnostics d(m.name);
  auto r = compileText(m.name, m.text, CompileOptions{}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll() << m.text;
  return r ? std::move(*r) : CompileResult{};
}

/// The closures of the material, evaluated by the CPU reference at a view
/// along the normal, inputs at their defaults, textures at the constant 0.5.
std::vector<reference::Closure<double>> closures(const ImportedMaterial& m, const CompileResult& r) {
  (void)m;
  reference::Geometry g;
  const reference::TextureFn tex = [](int, double, double) { return std::array<double, 4>{0.5, 0.5, 0.5, 0.5}; };
  return reference::evaluateMaterial<double>(r, g, {}, tex).closures;
}

void expectNear3(const std::array<double, 3>& a, double x, double y, double z, double tol = 1e-6) {
  EXPECT_NEAR(a[0], x, tol);
  EXPECT_NEAR(a[1], y, tol);
  EXPECT_NEAR(a[2], z, tol);
}

std::string glb(const std::string& json, bool pad = true, std::uint32_t version = 2, int lengthDelta = 0) {
  std::string chunk = json;
  while (pad && chunk.size() % 4) chunk += ' ';
  auto le = [](std::uint32_t v) {
    std::string s(4, '\0');
    for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    return s;
  };
  std::string body = le(static_cast<std::uint32_t>(chunk.size())) + "JSON" + chunk;
  return "glTF" + le(version) + le(static_cast<std::uint32_t>(12 + body.size() + lengthDelta)) + body;
}

// --- .glb -------------------------------------------------------------------

TEST(Glb, TheJsonChunkOfAWellFormedContainerIsImported) {
  const std::string json = R"({"asset": {"version": "2.0"}, "materials": [{"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]}}]})";
  Imported r = importAs(SourceKind::Glb, glb(json), "m.glb");
  ASSERT_TRUE(r.materials) << r.diags;
  ASSERT_EQ(r.materials->size(), 1u);
  EXPECT_EQ((*r.materials)[0].name, "red");
}

TEST(Glb, EveryMalformedHeaderIsAnErrorAtItsByte) {
  const std::string json = R"({"materials": [{}]})";
  struct Case {
    std::string bytes, message;
  } cases[] = {
      {"glTF", "m.glb: error: malformed .glb container: 4 bytes, shorter than the 12-byte header [byte 0]"},
      {"glTX" + glb(json).substr(4), "m.glb: error: malformed .glb container: the magic is not \"glTF\" [byte 0]"},
      {glb(json, true, 1), "m.glb: error: malformed .glb container: version 1 (only glTF 2 containers are read) [byte 4]"},
      {glb(json, true, 2, 4), "m.glb: error: malformed .glb container: the header says 44 bytes, the file has 40 [byte 8]"},
      {glb(json, false), "m.glb: error: malformed .glb container: chunk 0 is 19 bytes, not a multiple of 4 [byte 12]"},
  };
  for (const auto& c : cases) {
    Imported r = importAs(SourceKind::Glb, c.bytes, "m.glb");
    EXPECT_FALSE(r.materials);
    EXPECT_NE(r.diags.find(c.message), std::string::npos) << r.diags;
  }
  std::string truncated = glb(json);
  truncated[12] = '\x7f';  // the chunk claims more than the file holds
  Imported r = importAs(SourceKind::Glb, truncated, "m.glb");
  EXPECT_NE(r.diags.find("chunk 0 claims 127 bytes"), std::string::npos) << r.diags;
}

// --- glTF errors and warnings ---------------------------------------------

TEST(GltfImport, WrongValuesAreErrorsAtTheirPointer) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0]}},
                   {"pbrMetallicRoughness": {"baseColorTexture": {"index": 3}}},
                   {"alphaMode": "CUTOUT"}])");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("t.gltf:1:61: error: expected an array of 4 numbers"),
            std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("error: expected the index of one of the document's 0 textures "
                         "[/materials/1/pbrMetallicRoughness/baseColorTexture/index]"), std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("error: expected \"OPAQUE\", \"MASK\" or \"BLEND\" [/materials/2/alphaMode]"), std::string::npos);
  EXPECT_NE(gltf("3").diags.find("error: expected a \"materials\" array"), std::string::npos);
}

TEST(GltfImport, WhatCannotBeRepresentedIsAWarningNamingTheMaterial) {
  Imported r = gltf(R"([{"name": "glass", "occlusionTexture": {"index": 0},
                    "pbrMetallicRoughness": {"roughnessFactor": 1.5},
                    "extensions": {"KHR_materials_dispersion": {"dispersion": 0.1}, "EXT_custom": {}}}])",
               R"(, "textures": [{"source": 0}], "images": [{"uri": "ao.png"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  EXPECT_NE(r.diags.find("t.gltf:1:54: warning: material \"glass\": occlusionTexture: ambient occlusion"),
            std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("warning: material \"glass\": roughnessFactor "
                         "is 1.5, outside [0, 1]: clamped to 1 [/materials/0/pbrMetallicRoughness/roughnessFactor]"), std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("warning: material \"glass\": "
                         "KHR_materials_dispersion: dispersion"), std::string::npos);
  EXPECT_NE(r.diags.find("extension EXT_custom is not imported; ignored"), std::string::npos);
}

TEST(GltfImport, NamesBecomeUniqueIdentifiers) {
  Imported r = gltf(R"([{"name": "Car Paint"}, {"name": "Car Paint"}, {}, {"name": "01 rust"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  EXPECT_EQ((*r.materials)[0].name, "Car_Paint");
  EXPECT_EQ((*r.materials)[1].name, "Car_Paint_2");
  EXPECT_EQ((*r.materials)[2].name, "material_2");
  EXPECT_EQ((*r.materials)[3].name, "m_01_rust");
  Diagnostics d("t.gltf");
  EXPECT_EQ(pickMaterial(*r.materials, "Car_Paint_2", d), &(*r.materials)[1]);  // by its identifier
  EXPECT_EQ(pickMaterial(*r.materials, "01 rust", d), &(*r.materials)[3]);      // or its source name
  EXPECT_EQ(pickMaterial(*r.materials, "", d), nullptr);
  EXPECT_NE(d.formatAll().find("the file holds 4 materials; choose one with --material NAME:\n  Car_Paint (\"Car Paint\")"),
            std::string::npos) << d.formatAll();
}

// --- Names (issue 16): every name that reaches generated code --------------

TEST(ImportNames, TheSanitizerMakesUsableIdentifiersDirectly) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"gl_Pos", "m_gl_Pos"},      {"GL_x", "m_GL_x"},    {"gL_Material", "m_gL_Material"},
      {"gl_", "gl"},               {"__x", "x"},          {"a__b", "a_b"},
      {"x_", "x"},                 {"_", ""},             {"float", "m_float"},
      {"main", "m_main"},          {"sin", "m_sin"},      {"texture", "m_texture"},
      {"cbuffer", "m_cbuffer"},    {"01 rust", "m_01_rust"}, {"Car Paint", "Car_Paint"},
      {"M\xc3\xa9tal", "M_tal"},   {"\xe9\x87\x91", ""},  {"", ""}};
  for (const auto& [in, want] : cases) {
    EXPECT_EQ(sanitizeIdentifier(in), want) << in;
    if (!want.empty()) EXPECT_TRUE(isUsableIdentifier(want)) << want;
  }
  const std::string longName(1000, 'a');
  EXPECT_EQ(sanitizeIdentifier(longName), std::string(kMaxSanitizedIdentifier, 'a'));
  EXPECT_EQ(sanitizeIdentifier(std::string(119, 'a') + "__b"), std::string(119, 'a'));  // cut, no trailing '_'
}

TEST(ImportNames, EveryStringSanitizesToAUsableIdentifierOrNothing) {
  // Random names made of the pieces that break identifiers.
  const std::vector<std::string> pieces = {"gl_", "GL_", "Gl", "_", "__", "float", "sin", "main", "9", "a", "Z",
                                           "\xc3\xa9", " ", "-", "$", "texture", "lerp", "x"};
  std::mt19937 rng(16);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    std::string s;
    for (int n = static_cast<int>(rng() % 6); n >= 0; --n) s += pieces[rng() % pieces.size()];
    const std::string id = sanitizeIdentifier(s);
    if (id.empty()) continue;
    ASSERT_TRUE(isUsableIdentifier(id)) << "\"" << s << "\" -> \"" << id << "\"";
    ++checked;
  }
  EXPECT_GT(checked, 15000);  // most strings keep something
}

TEST(ImportNames, FreeNameSearchesAreLinearAndBounded) {
  NameSet names;
  std::set<std::string> seen;
  for (int i = 0; i < 20000; ++i) {  // 20 000 collisions: O(n) in all, not O(n^2)
    const std::string id = names.claim("a");
    ASSERT_TRUE(isUsableIdentifier(id)) << id;
    ASSERT_TRUE(seen.insert(id).second) << id;
  }
  EXPECT_EQ(names.size(), 20000u);
  const std::string longBase(kMaxSanitizedIdentifier, 'b');
  EXPECT_EQ(names.claim(longBase), longBase);
  const std::string second = names.claim(longBase);
  EXPECT_EQ(second, longBase + "_2");
  EXPECT_LE(second.size(), 128u);
  // Material names collide case-insensitively (file names, upper-case macros).
  NameSet materials(/*caseInsensitive=*/true);
  EXPECT_EQ(materials.claim("Gold"), "Gold");
  EXPECT_EQ(materials.claim("gold"), "gold_2");
  // The search gives up past its bound (unreachable with the default bound:
  // at most size() + 1 tries are ever needed).
  NameSet small(false, 3);
  for (const char* n : {"c_2", "c_3", "c_4", "c_5"}) small.insert(n);
  EXPECT_EQ(small.claim("c"), "c");
  EXPECT_THROW(small.claim("c"), std::length_error);
}

/// Every file the material generates validates (glslang + spirv-val, GLSL and HLSL).
void expectValidShaders(const ImportedMaterial& m) {
  const CompileResult r = compiled(m);
  Generated gen = generateFiles(r, GenerateOptions{});
  validateGenerated(gen);
  EXPECT_TRUE(gen.valid) << m.name << ": " << gen.failure;
  EXPECT_FALSE(gen.files.empty());
}

TEST(ImportNames, ReservedGltfNamesImportInBoundedTimeAndValidate) {
  // The material names that made the sanitizer loop forever (gl_), and every
  // other kind of reserved name, each twice.
  std::string list;
  for (const char* n : {"gl_Pos", "gl_Pos", "Gl_Pos", "GL_POS", "float", "float", "sin", "__x", "_x_", "main",
                        "cbuffer", "gl_", "\xe9\x87\x91\xe5\xb1\x9e"})
    list += std::string(list.empty() ? "" : ", ") + R"({"name": ")" + n +
            R"(", "pbrMetallicRoughness": {"roughnessFactor": 0.4, "baseColorTexture": {"index": 0}}})";
  Imported r = gltf("[" + list + "]", R"(, "textures": [{"source": 0}], "images": [{"uri": "gl_Tex.png"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  std::vector<std::string> names;
  for (const auto& m : *r.materials) names.push_back(m.name);
  EXPECT_EQ(names, (std::vector<std::string>{"m_gl_Pos", "m_gl_Pos_2", "m_Gl_Pos_3", "m_GL_POS_4", "m_float", "m_float_2",
                                             "m_sin", "x", "x_2", "m_main", "m_cbuffer", "gl", "material_12"}));
  for (const auto& m : *r.materials) {
    ASSERT_TRUE(isUsableIdentifier(m.name)) << m.name;
    compiled(m);
  }
  expectValidShaders((*r.materials)[2]);  // "Gl_Pos": its macros would begin with GL_
}

TEST(ImportNames, ReservedMaterialXNamesImportAndValidate) {
  Imported r = mtlx(R"(  <nodegraph name="gl_NG">
    <input name="gl_tint" type="color3" value="0.8, 0.5, 0.2" />
    <input name="__gain" type="float" value="0.5" />
    <tiledimage name="gl_img" type="color3">
      <input name="file" type="filename" value="gl_color.png" />
    </tiledimage>
    <multiply name="float" type="color3">
      <input name="in1" type="color3" interfacename="gl_tint" />
      <input name="in2" type="color3" nodename="gl_img" />
    </multiply>
    <multiply name="sin" type="color3">
      <input name="in1" type="color3" nodename="float" />
      <input name="in2" type="float" interfacename="__gain" />
    </multiply>
    <output name="out" type="color3" nodename="sin" />
  </nodegraph>
  <standard_surface name="gl_SR" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="gl_NG" output="out" />
    <input name="specular_roughness" type="float" value="0.3" />
  </standard_surface>
  <surfacematerial name="gl_Material" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="gl_SR" />
  </surfacematerial>
  <surfacematerial name="GL_MATERIAL" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="gl_SR" />
  </surfacematerial>
)");
  ASSERT_TRUE(r.materials) << r.diags;
  ASSERT_EQ(r.materials->size(), 2u);
  EXPECT_EQ((*r.materials)[0].name, "m_gl_Material");
  EXPECT_EQ((*r.materials)[1].name, "m_GL_MATERIAL_2");  // names differ in more than letter case
  const std::string& text = (*r.materials)[0].text;
  for (const char* id : {"\"m_gl_tint\": {", "\"gain\": {", "\"m_gl_color\"", "\"m_float\": {", "\"m_sin\": {"})
    EXPECT_NE(text.find(id), std::string::npos) << id << "\n" << text;
  const auto doc = nlohmann::json::parse(text);
  int ids = 0;
  for (const char* section : {"inputs", "nodes"})
    for (const auto& [id, body] : doc[section].items()) {
      EXPECT_TRUE(isIdentifier(id) && !hasReservedPrefix(id)) << id;
      ++ids;
    }
  EXPECT_GE(ids, 6);
  expectValidShaders((*r.materials)[1]);
}

TEST(ImportNames, NonAsciiNamesStayUtf8InDescriptions) {
  Imported r = gltf(R"([{"name": "金属 Métal"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  EXPECT_NE((*r.materials)[0].text.find(R"(materials[0] \"金属 Métal\" (glTF 2.0 PBR).)"), std::string::npos)
      << (*r.materials)[0].text;
  EXPECT_EQ((*r.materials)[0].text.find("\\\\x"), std::string::npos);
  Imported x = mtlx(R"(  <standard_surface name="SR" type="surfaceshader" />
  <surfacematerial name="Ébène_木" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR" />
  </surfacematerial>
)");
  ASSERT_TRUE(x.materials) << x.diags;
  EXPECT_NE((*x.materials)[0].text.find(R"(surfacematerial \"Ébène_木\" (MaterialX).)"), std::string::npos)
      << (*x.materials)[0].text;
  // Bytes that are not UTF-8 (an XML file need not be) are escaped, never written raw.
  EXPECT_EQ(descriptionText("a\xff" "b\xc3"), "a\\xffb\\xc3");
  EXPECT_EQ(descriptionText("\xed\xa0\x80"), "\\xed\\xa0\\x80");  // a UTF-8-encoded surrogate
  EXPECT_EQ(descriptionText("tab\there"), "tab\\x09here");
  EXPECT_EQ(descriptionText("金属金属", 7), "金属...");  // cut at a character boundary
}

// --- glTF mapping -----------------------------------------------------------

TEST(GltfImport, MetallicRoughnessGoesThroughTheMetalnessHelper) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.4, 0.2, 1], "metallicFactor": 0.25,
                                             "roughnessFactor": 0.6}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  EXPECT_NE(m.text.find("\"metalness_to_diffuse_f0\""), std::string::npos);
  EXPECT_NE(m.text.find("\"baseColorFactor\": {\n      \"type\": \"color\""), std::string::npos) << m.text;
  const auto c = closures(m, compiled(m));
  ASSERT_EQ(c.size(), 1u);
  // diffuse = base (1 − m), F0 = lerp(0.04, base, m)
  expectNear3(c[0].diffuseAlbedo, 0.8 * 0.75, 0.4 * 0.75, 0.2 * 0.75);
  expectNear3(c[0].f0, 0.04 + (0.8 - 0.04) * 0.25, 0.04 + (0.4 - 0.04) * 0.25, 0.04 + (0.2 - 0.04) * 0.25);
  EXPECT_NEAR(c[0].roughness, 0.6, 1e-6);
}

TEST(GltfImport, SpecularAndIorSetF0AndF90) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorFactor": [0.5, 0.5, 0.5, 1]},
                    "extensions": {"KHR_materials_ior": {"ior": 2.0},
                                   "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 4]}}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto c = closures((*r.materials)[0], compiled((*r.materials)[0]));
  const double f0 = 1.0 / 9.0;  // ((2 − 1) / (2 + 1))²
  // F0 = min(f0 · specularColor, 1) · specular; F90 = specular
  expectNear3(c[0].f0, f0 * 0.5, f0 * 0.5 * 0.5, std::min(f0 * 4, 1.0) * 0.5);
  expectNear3(c[0].f90, 0.5, 0.5, 0.5);
}

TEST(GltfImport, ClearcoatIsAVerticalCoatWithItsOwnNormal) {
  Imported r = gltf(R"([{"normalTexture": {"index": 0}, "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 0.5,
                    "clearcoatRoughnessFactor": 0.1, "clearcoatNormalTexture": {"index": 1}}}}])",
               R"(, "textures": [{"source": 0}, {"source": 1}], "images": [{"uri": "n.png"}, {"uri": "cn.png"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  const CompileResult res = compiled(m);
  ASSERT_EQ(res.after.closures.size(), 2u);
  EXPECT_NE(m.text.find("\"kind\": \"vertical\""), std::string::npos);
  EXPECT_NE(m.text.find("\"kind\": \"coverage_weight\""), std::string::npos);  // weight 0.5 on the coat
  EXPECT_NE(m.text.find("\"clearcoatNormalTexture\""), std::string::npos);
  const auto c = closures(m, res);
  // The coat: colourless dielectric, IOR 1.5 (F0 0.04), its own roughness.
  bool coat = false;
  for (const auto& k : c)
    if (k.isTop && k.diffuseAlbedo[0] == 0) {
      coat = true;
      expectNear3(k.f0, 0.04, 0.04, 0.04);
      EXPECT_NEAR(k.roughness, 0.1, 1e-6);
    }
  EXPECT_TRUE(coat);
}

TEST(GltfImport, SheenIsFuzzWithItsLargestChannelAsAmount) {
  Imported r = gltf(R"([{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.8, 0.4, 0.2], "sheenRoughnessFactor": 0.3}}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto c = closures((*r.materials)[0], compiled((*r.materials)[0]));
  EXPECT_NEAR(c[0].fuzzAmount, 0.8, 1e-6);
  expectNear3(c[0].fuzzColor, 1.0, 0.5, 0.25);
  EXPECT_NEAR(c[0].fuzzRoughness, 0.3, 1e-6);
}

TEST(GltfImport, TransmissionAndVolumeAreATranslucentSlabWithTheirTransmittance) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 0},
                    "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                   "KHR_materials_volume": {"thicknessFactor": 0.02, "attenuationDistance": 0.01,
                                                            "attenuationColor": [0.5, 0.8, 1.0]}}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const CompileResult res = compiled((*r.materials)[0]);
  EXPECT_EQ(res.material.settings.blendMode, BlendMode::TranslucentColored);
  ASSERT_EQ(res.after.closures.size(), 1u);  // transmission 1 and no metal: the transmitting slab alone
  reference::Geometry g;
  const auto m = reference::evaluateMaterial<double>(res, g, {}, {});
  // T = baseColor · attenuationColor^(thickness / distance), along the normal.
  expectNear3(m.transmittance, 0.9 * 0.25, 0.9 * 0.64, 0.9, 1e-5);
}

TEST(GltfImport, AlphaModesChooseTheBlendModeAndCoverage) {
  Imported r = gltf(R"([{"alphaMode": "MASK", "alphaCutoff": 0.3, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.4]}},
                   {"alphaMode": "MASK", "alphaCutoff": 0.3, "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.2]}},
                   {"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.25]}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const double expected[] = {1.0, 0.0, 0.25};
  const BlendMode modes[] = {BlendMode::Masked, BlendMode::Masked, BlendMode::TranslucentGrey};
  for (int i = 0; i < 3; ++i) {
    const CompileResult res = compiled((*r.materials)[i]);
    EXPECT_EQ(res.material.settings.blendMode, modes[i]);
    reference::Geometry g;
    EXPECT_NEAR(reference::evaluateMaterial<double>(res, g, {}, {}).coverage, expected[i], 1e-9) << i;
  }
}

TEST(GltfImport, TextureTransformAndTexcoordSetsBecomeUvArithmetic) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1,
                    "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "scale": [2, 3]}}}}}])",
               R"(, "textures": [{"source": 0}], "images": [{"uri": "c.png"}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const CompileResult res = compiled((*r.materials)[0]);
  reference::Geometry g;
  g.uv1 = {0.1, 0.2};
  double u = -1, v = -1;
  const reference::TextureFn tex = [&](int, double a, double b) {
    u = a;
    v = b;
    return std::array<double, 4>{0.5, 0.5, 0.5, 1};
  };
  reference::evaluateMaterial<double>(res, g, {}, tex);
  EXPECT_NEAR(u, 0.1 * 2 + 0.5, 1e-12);  // uv1 · scale + offset
  EXPECT_NEAR(v, 0.2 * 3 + 0.25, 1e-12);
}

TEST(GltfImport, AnisotropyMatchesGltfAlphasAlongTheRotatedTangent) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"roughnessFactor": 0.5},
                    "extensions": {"KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": 1.5707963267948966}}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto c = closures((*r.materials)[0], compiled((*r.materials)[0]));
  const double a = 0.25, at = a + (1 - a) * 0.36;  // alpha_t = mix(alpha, 1, strength²), alpha_b = alpha
  const double r2 = c[0].roughness * c[0].roughness;
  EXPECT_NEAR(r2 * (1 + c[0].anisotropy), at, 1e-9);
  EXPECT_NEAR(r2 * (1 - c[0].anisotropy), a, 1e-9);
  expectNear3(c[0].T_, 0, 1, 0, 1e-9);  // the tangent turned by 90 degrees
}

// KHR_materials_unlit is the unlit BSDF: no closure (8 bytes, nothing lit),
// its base colour emitted, its alpha the presence.
TEST(GltfImport, UnlitIsItsBaseColourEmittedByAnUnlitNode) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 0.5]}, "alphaMode": "BLEND",
                        "extensions": {"KHR_materials_unlit": {}}}])");
  ASSERT_TRUE(r.materials) << r.diags;
  const ImportedMaterial& m = (*r.materials)[0];
  EXPECT_NE(m.text.find("\"kind\": \"unlit\""), std::string::npos) << m.text;
  const CompileResult c = compiled(m);
  EXPECT_TRUE(c.after.closures.empty());
  EXPECT_EQ(c.after.bytes(), 8);
  reference::Geometry g;
  const auto e = reference::evaluateMaterial<double>(c, g, {}, {});
  expectNear3(e.emission, 0.2 * 0.5, 0.4 * 0.5, 0.6 * 0.5);  // presence 0.5 weights the emission
  EXPECT_NEAR(e.coverage, 0.5, 1e-12);
}

// --- MaterialX ----------------------------------------------------------------

TEST(MaterialXImport, SyntaxErrorsAreAtTheirLineAndColumn) {
  Imported r = importAs(SourceKind::MaterialX, "<?xml version=\"1.0\"?>\n<materialx>\n  <nodegraph name=\"a\">\n</materialx>\n", "t.mtlx");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("t.mtlx:4:"), std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("error: XML: "), std::string::npos) << r.diags;
}

TEST(MaterialXImport, AnUnsupportedNodeIsAnErrorNamingItAndItsLine) {
  Imported r = mtlx(R"(  <nodegraph name="NG">
    <my_custom_noise name="n1" type="float" />
    <output name="out" type="float" nodename="n1" />
  </nodegraph>
  <standard_surface name="SR" type="surfaceshader">
    <input name="specular_roughness" type="float" nodegraph="NG" output="out" />
  </standard_surface>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR" />
  </surfacematerial>
)");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("t.mtlx:4:6: error: my_custom_noise 'n1' in nodegraph 'NG': unsupported node 'my_custom_noise'"),
            std::string::npos) << r.diags;
}

TEST(MaterialXImport, BrokenConnectionsAndCyclesAreErrors) {
  Imported r = mtlx(R"(  <nodegraph name="NG">
    <multiply name="a" type="float"><input name="in1" type="float" nodename="b" /></multiply>
    <multiply name="b" type="float"><input name="in1" type="float" nodename="a" /></multiply>
    <output name="out" type="float" nodename="a" />
  </nodegraph>
  <standard_surface name="SR" type="surfaceshader">
    <input name="specular_roughness" type="float" nodegraph="NG" output="out" />
    <input name="base" type="float" nodegraph="NG" output="missing" />
  </standard_surface>
  <surfacematerial name="M" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR" />
  </surfacematerial>
  <surfacematerial name="N" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="nowhere" />
  </surfacematerial>
)");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("the node depends on itself (a cycle)"), std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("node graph 'NG' has no output 'missing'"), std::string::npos) << r.diags;
  EXPECT_NE(r.diags.find("its surfaceshader 'nowhere' is not in the document"), std::string::npos) << r.diags;
}

TEST(MaterialXImport, StandardSurfaceParametersBecomeInputsNamedAfterThem) {
  Imported r = mtlx(R"(  <standard_surface name="SR" type="surfaceshader">
    <input name="base" type="float" value="0.5" />
    <input name="base_color" type="color3" value="0.8, 0.6, 0.4" />
    <input name="metalness" type="float" value="0" />
    <input name="specular_roughness" type="float" value="0.3" />
  </standard_surface>
  <surfacematerial name="Paint" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR" />
  </surfacematerial>
)");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  for (const char* input : {"\"base\": {", "\"base_color\": {", "\"specular_roughness\": {"})
    EXPECT_NE(m.text.find(input), std::string::npos) << input << "\n" << m.text;
  EXPECT_EQ(m.text.find("\"metalness\": {"), std::string::npos);  // 0: a static switch, no metal
  const auto c = closures(m, compiled(m));
  expectNear3(c[0].diffuseAlbedo, 0.4, 0.3, 0.2);  // base · base_color
  expectNear3(c[0].f0, 0.04, 0.04, 0.04);
  EXPECT_NEAR(c[0].roughness, 0.3, 1e-6);
}

TEST(MaterialXImport, ImagesAreTextureInputsAndProceduralsAreBaked) {
  Imported r = mtlx(R"(  <nodegraph name="NG">
    <tiledimage name="img" type="color3">
      <input name="file" type="filename" value="tex/wood_color.png" colorspace="srgb_texture" />
      <input name="uvtiling" type="vector2" value="4, 2" />
    </tiledimage>
    <noise2d name="grain" type="float" />
    <multiply name="m" type="color3">
      <input name="in1" type="color3" nodename="img" />
      <input name="in2" type="float" nodename="grain" />
    </multiply>
    <output name="out" type="color3" nodename="m" />
  </nodegraph>
  <standard_surface name="SR" type="surfaceshader">
    <input name="base_color" type="color3" nodegraph="NG" output="out" />
  </standard_surface>
  <surfacematerial name="Wood" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="SR" />
  </surfacematerial>
)");
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  EXPECT_NE(m.text.find("\"wood_color\": {\n      \"type\": \"texture2d\",\n      \"colorspace\": \"srgb\""),
            std::string::npos) << m.text;
  EXPECT_NE(m.text.find("\"grain_baked\""), std::string::npos);
  EXPECT_NE(r.diags.find("t.mtlx:8:6: warning: material \"Wood\": noise2d 'grain' in nodegraph 'NG': the procedural noise2d "
                         "has no value node: replaced by the texture input 'grain_baked'"),
            std::string::npos) << r.diags;
  const CompileResult res = compiled(m);
  reference::Geometry g;
  g.uv0 = {0.1, 0.3};
  std::vector<std::array<double, 2>> uvs;
  const reference::TextureFn tex = [&](int, double u, double v) {
    uvs.push_back({u, v});
    return std::array<double, 4>{0.5, 0.5, 0.5, 1};
  };
  reference::evaluateMaterial<double>(res, g, {}, tex);
  bool tiled = false;
  for (const auto& uv : uvs) tiled |= std::fabs(uv[0] - 0.4) < 1e-12 && std::fabs(uv[1] - 0.6) < 1e-12;
  EXPECT_TRUE(tiled);  // uv · uvtiling
}

// chiang_hair_bsdf under a surface: the format's hair node (docs/import.md,
// "chiang_hair_bsdf"); the expected values from the formulas of MaterialX's
// genglsl implementation and of the hair node, worked here.

/// Chiang 2016's eq. 9 denominator.
double chiangP(double b) { return 5.969 - 0.215 * b + 2.532 * b * b - 10.73 * b * b * b + 5.574 * std::pow(b, 4) + 0.245 * std::pow(b, 5); }

const char* const kHairSurface = R"(  <surface name="surf" type="surfaceshader">
    <input name="bsdf" type="BSDF" nodename="fibre" />
  </surface>
  <surfacematerial name="Hair" type="material">
    <input name="surfaceshader" type="surfaceshader" nodename="surf" />
  </surfacematerial>
)";

const char* const kHairRoughness = R"(  <chiang_hair_roughness name="rough" type="multioutput">
    <input name="longitudinal" type="float" %s />
    <input name="azimuthal" type="float" value="%s" />
    <output name="roughness_R" type="vector2" />
    <output name="roughness_TT" type="vector2" />
    <output name="roughness_TRT" type="vector2" />
  </chiang_hair_roughness>
)";

std::string hairRoughness(const std::string& longitudinal, const std::string& azimuthal) {
  char buf[1024];
  std::snprintf(buf, sizeof buf, kHairRoughness, longitudinal.c_str(), azimuthal.c_str());
  return buf;
}

const char* const kLobesOfRough = R"(    <input name="roughness_R" type="vector2" nodename="rough" output="roughness_R" />
    <input name="roughness_TT" type="vector2" nodename="rough" output="roughness_TT" />
    <input name="roughness_TRT" type="vector2" nodename="rough" output="roughness_TRT" />
)";

TEST(MaterialXImport, ChiangHairIsAHairNodeWithChiangsParameters) {
  Imported r = mtlx(hairRoughness("value=\"0.3\"", "0.4") + R"(  <deon_hair_absorption_from_melanin name="melanin" type="vector3">
    <input name="melanin_concentration" type="float" value="0.8" />
    <input name="melanin_redness" type="float" value="0.2" />
  </deon_hair_absorption_from_melanin>
  <chiang_hair_bsdf name="fibre" type="BSDF">
    <input name="tint_R" type="color3" value="0.9, 0.8, 0.7" />
    <input name="ior" type="float" value="1.6" />
    <input name="cuticle_angle" type="float" value="0.52" />
)" + kLobesOfRough + R"(    <input name="absorption_coefficient" type="vector3" nodename="melanin" />
  </chiang_hair_bsdf>
)" + kHairSurface);
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  const auto doc = nlohmann::ordered_json::parse(m.text);
  const auto& hair = doc["nodes"]["hair"];
  ASSERT_EQ(hair["kind"], "hair") << m.text;
  // roughness_R folds to chiang_hair_roughness's (v, s), inverted back to the artist's roughness.
  EXPECT_EQ(hair["roughness"], 0.3);
  EXPECT_EQ(hair["azimuthal_roughness"], 0.4);
  // melanin = −ln(1 − 0.8); sigma = melanin · (0.8 · (0.419, 0.697, 1.37) + 0.2 · (0.187, 0.4, 1.05))
  // = (0.599677, 1.02618, 2.10193); base colour exp(−sqrt(sigma) · P(0.4)) = (0.0116774, 0.00296365, 0.000240826).
  const double melanin = -std::log(0.2);
  const double eu[3] = {-std::log(0.657704), -std::log(0.498077), -std::log(0.254107)};
  const double pheo[3] = {-std::log(0.829444), -std::log(0.67032), -std::log(0.349938)};
  double color[3];
  for (int i = 0; i < 3; ++i) color[i] = std::exp(-std::sqrt(melanin * (0.8 * eu[i] + 0.2 * pheo[i])) * chiangP(0.4));
  EXPECT_NEAR(color[0], 0.0116774, 1e-7);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(hair["base_color"][i].get<double>(), color[i], 1e-9 * color[i] + 1e-12);
  // The tint is not represented; the lobes keep pbrt's ratios (the default scales): no warning for them.
  EXPECT_NE(r.diags.find("t.mtlx:14:4: warning: material \"Hair\": chiang_hair_bsdf 'fibre': tint_R (0.9, 0.8, 0.7): "
                         "the hair node has no per-lobe tint; ignored (white)"),
            std::string::npos) << r.diags;
  EXPECT_EQ(r.diags.find("roughness_T"), std::string::npos) << r.diags;
  EXPECT_EQ(r.diags.find("evaluated at import"), std::string::npos) << r.diags;  // no material input is frozen
  // The closure at the inputs' defaults: ior 1.6 and cuticle_angle 0.52 are inputs, the tilt
  // (0.5 − 0.52) · 180 = −3.6 degrees (MaterialX's R lobe peaks at theta_i + theta_o = −2 alpha,
  // the hair node's at +2 alpha: the opposite angle).
  const auto c = closures(m, compiled(m));
  ASSERT_EQ(c.size(), 1u);
  expectNear3(c[0].diffuseAlbedo, color[0], color[1], color[2], 1e-9);
  EXPECT_NEAR(c[0].roughness, 0.3, 1e-12);
  EXPECT_NEAR(c[0].hair[0], 0.4, 1e-12);
  EXPECT_NEAR(c[0].hair[1], 1.6, 1e-12);
  EXPECT_NEAR(c[0].hair[2], -3.6, 1e-9);
  EXPECT_NEAR(c[0].hair[3], 0.0, 1e-12);  // scatter: MaterialX has none
}

TEST(MaterialXImport, ChiangHairWarnsOfWhatTheHairNodeCannotExpress) {
  // The nodedef's defaults: roughness_R (0.1, 0.1), TT (0.05, 0.05) and TRT (0.2, 0.2) are not pbrt's
  // (variance / 4 and · 4, one azimuthal scale); cuticle_angle 0.9 is −72 degrees, ior 3.5 beyond the pin.
  Imported r = mtlx(R"(  <image name="tex" type="color3"><input name="file" type="filename" value="tint.png" /></image>
  <chiang_hair_bsdf name="fibre" type="BSDF">
    <input name="tint_TT" type="color3" nodename="tex" />
    <input name="ior" type="float" value="3.5" />
    <input name="cuticle_angle" type="float" value="0.9" />
  </chiang_hair_bsdf>
)" + std::string(kHairSurface));
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  const auto doc = nlohmann::ordered_json::parse(m.text);
  const auto& hair = doc["nodes"]["hair"];
  // (v, s) = (0.1, 0.1) inverted: the roughness whose Chiang variance is 0.1, and scale 0.1.
  const double b = hair["roughness"].get<double>(), a = hair["azimuthal_roughness"].get<double>();
  EXPECT_NEAR(std::pow(0.726 * b + 0.812 * b * b + 3.7 * std::pow(b, 20), 2), 0.1, 1e-9) << b;
  EXPECT_NEAR(0.265 * a + 1.194 * a * a + 5.372 * std::pow(a, 22), 0.1, 1e-9) << a;
  EXPECT_EQ(hair["base_color"], nlohmann::ordered_json::parse("[1.0, 1.0, 1.0]"));  // no absorption: white
  for (const char* w : {"tint_TT varies: the hair node has no per-lobe tint; not represented",
                        "roughness_TT (0.05, 0.05): the hair node's lobe has R's / 4 longitudinal variance and R's "
                        "azimuthal scale, (0.025, 0.1) here; the authored lobe is not represented",
                        "roughness_TRT (0.2, 0.2): the hair node's lobe has R's * 4 longitudinal variance and R's "
                        "azimuthal scale, (0.4, 0.1) here",
                        "cuticle_angle 0.9 (-72 degrees of tilt): outside the hair node's [-20, 20] degrees; clamped",
                        "ior 3.5: outside the hair node's [1, 3]; clamped"})
    EXPECT_NE(r.diags.find(w), std::string::npos) << w << "\n" << r.diags;
  EXPECT_EQ(r.diags.find("tint_R"), std::string::npos) << r.diags;
  const auto c = closures(m, compiled(m));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].hair[1], 3.0, 1e-12);
  EXPECT_NEAR(c[0].hair[2], -20.0, 1e-12);
}

TEST(MaterialXImport, ChiangHairFollowsVaryingInputsWithValueNodes) {
  // A textured longitudinal roughness through chiang_hair_roughness is the roughness pin (clamped to
  // what the BSDF's clamp of v to [0.001, 1] leaves); a textured colour through
  // chiang_hair_absorption_from_color (its azimuthal roughness 0.2) is c^(P(0.3) / P(0.2)): no logarithm.
  Imported r = mtlx(R"(  <image name="lmap" type="float"><input name="file" type="filename" value="l.png" /></image>
  <image name="cmap" type="color3"><input name="file" type="filename" value="c.png" /></image>
  <chiang_hair_absorption_from_color name="dye" type="vector3">
    <input name="color" type="color3" nodename="cmap" />
  </chiang_hair_absorption_from_color>
)" + hairRoughness("nodename=\"lmap\"", "0.3") + R"(  <chiang_hair_bsdf name="fibre" type="BSDF">
)" + kLobesOfRough + R"(    <input name="absorption_coefficient" type="vector3" nodename="dye" />
  </chiang_hair_bsdf>
)" + kHairSurface);
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  const auto doc = nlohmann::ordered_json::parse(m.text);
  const auto& hair = doc["nodes"]["hair"];
  EXPECT_EQ(hair["azimuthal_roughness"], 0.3);
  EXPECT_EQ(hair["roughness"]["kind"], "clamp") << m.text;
  EXPECT_EQ(hair["base_color"], "base_color") << m.text;
  EXPECT_EQ(doc["nodes"]["base_color"]["kind"], "pow") << m.text;
  EXPECT_EQ(r.diags.find("warning"), std::string::npos) << r.diags;  // same lobes as pbrt's, nothing frozen
  // Textures read 0.5: roughness 0.5 (inside [0.0416, 0.7442]), colour 0.5^(P(0.3) / P(0.2)) = 0.503625.
  const auto c = closures(m, compiled(m));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].roughness, 0.5, 1e-12);
  const double k = std::pow(0.5, chiangP(0.3) / chiangP(0.2));
  EXPECT_NEAR(k, 0.503625, 1e-6);
  expectNear3(c[0].diffuseAlbedo, k, k, k, 1e-9);
}

TEST(MaterialXImport, ChiangHairAbsorptionThatVariesIsAColourOfValueNodes) {
  // SimpleHair's graph with a textured melaninMix: the absorption (a mix of two constants by the
  // texture) reaches base_color as exp(−sqrt(sigma) P(bn)), written pow(e, ·) (no exp op).
  Imported r = mtlx(hairRoughness("value=\"0.2\"", "0.25") + R"(  <image name="mixmap" type="float"><input name="file" type="filename" value="m.png" /></image>
  <deon_hair_absorption_from_melanin name="melanin" type="vector3">
    <input name="melanin_concentration" type="float" value="0.5" />
  </deon_hair_absorption_from_melanin>
  <chiang_hair_absorption_from_color name="dye" type="vector3">
    <input name="color" type="color3" value="0.6, 0.3, 0.2" />
  </chiang_hair_absorption_from_color>
  <mix name="both" type="vector3">
    <input name="fg" type="vector3" nodename="melanin" />
    <input name="bg" type="vector3" nodename="dye" />
    <input name="mix" type="float" nodename="mixmap" />
  </mix>
  <chiang_hair_bsdf name="fibre" type="BSDF">
)" + kLobesOfRough + R"(    <input name="absorption_coefficient" type="vector3" nodename="both" />
  </chiang_hair_bsdf>
)" + kHairSurface);
  ASSERT_TRUE(r.materials) << r.diags;
  const auto& m = (*r.materials)[0];
  // melanin(0.5, redness 0.5) and from_color((0.6, 0.3, 0.2), 0.2), mixed half and half.
  const double melanin = -std::log(0.5);
  const double eu[3] = {-std::log(0.657704), -std::log(0.498077), -std::log(0.254107)};
  const double pheo[3] = {-std::log(0.829444), -std::log(0.67032), -std::log(0.349938)};
  const double dye[3] = {0.6, 0.3, 0.2};
  double color[3];
  for (int i = 0; i < 3; ++i) {
    const double fromColor = std::pow(std::log(dye[i]) / chiangP(0.2), 2);
    const double sigma = 0.5 * fromColor + 0.5 * melanin * 0.5 * (eu[i] + pheo[i]);
    color[i] = std::exp(-std::sqrt(sigma) * chiangP(0.25));
  }
  const auto c = closures(m, compiled(m));
  ASSERT_EQ(c.size(), 1u);
  expectNear3(c[0].diffuseAlbedo, color[0], color[1], color[2], 1e-9);
}

TEST(MaterialXImport, ChiangHairInputsWithoutAValueNodeAreErrors) {
  // A textured melanin concentration needs ln; a roughness_R of anything but chiang_hair_roughness
  // that varies needs the polynomials' inverse; a surface of another BSDF has no import rule.
  Imported r = mtlx(R"(  <image name="tex" type="float"><input name="file" type="filename" value="t.png" /></image>
  <deon_hair_absorption_from_melanin name="melanin" type="vector3">
    <input name="melanin_concentration" type="float" nodename="tex" />
  </deon_hair_absorption_from_melanin>
  <chiang_hair_bsdf name="fibre" type="BSDF">
    <input name="absorption_coefficient" type="vector3" nodename="melanin" />
  </chiang_hair_bsdf>
  <convert name="r2" type="vector2"><input name="in" type="float" nodename="tex" /></convert>
  <chiang_hair_bsdf name="fibre2" type="BSDF">
    <input name="roughness_R" type="vector2" nodename="r2" />
  </chiang_hair_bsdf>
  <dielectric_bsdf name="glass" type="BSDF" />
  <surface name="surf" type="surfaceshader"><input name="bsdf" type="BSDF" nodename="fibre" /></surface>
  <surface name="surf2" type="surfaceshader"><input name="bsdf" type="BSDF" nodename="fibre2" /></surface>
  <surface name="surf3" type="surfaceshader"><input name="bsdf" type="BSDF" nodename="glass" /></surface>
  <surfacematerial name="A" type="material"><input name="surfaceshader" type="surfaceshader" nodename="surf" /></surfacematerial>
  <surfacematerial name="B" type="material"><input name="surfaceshader" type="surfaceshader" nodename="surf2" /></surfacematerial>
  <surfacematerial name="C" type="material"><input name="surfaceshader" type="surfaceshader" nodename="surf3" /></surfacematerial>
)");
  EXPECT_FALSE(r.materials);
  for (const char* e : {"t.mtlx:4:4: error: deon_hair_absorption_from_melanin 'melanin': melanin_concentration or a "
                        "pigment colour varies, and the absorption is its logarithm, which no "
                        "value node computes",
                        "t.mtlx:11:4: error: chiang_hair_bsdf 'fibre2': roughness_R varies: the hair node takes Chiang's "
                        "roughness, and no value node inverts chiang_hair_roughness's polynomials",
                        "t.mtlx:14:4: error: dielectric_bsdf 'glass': unsupported node 'dielectric_bsdf': a BSDF node is "
                        "not a Substrate slab"})
    EXPECT_NE(r.diags.find(e), std::string::npos) << e << "\n" << r.diags;
}

TEST(MaterialXImport, AMissingIncludeIsAnErrorAtTheInclude) {
  Imported r = mtlx("  <xi:include href=\"nowhere.mtlx\" />\n");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("t.mtlx:3:4: error: xi:include 'nowhere.mtlx':"), std::string::npos) << r.diags;
}

TEST(MaterialXImport, DeepGraphsAndIncludeCyclesAreErrorsNotCrashes) {
  std::string graph = "  <nodegraph name=\"NG\">\n";
  for (int i = 0; i < 2000; ++i)
    graph += "    <multiply name=\"m" + std::to_string(i) + "\" type=\"float\"><input name=\"in1\" type=\"float\" " +
             (i + 1 < 2000 ? "nodename=\"m" + std::to_string(i + 1) + "\"" : std::string("value=\"1\"")) + " /></multiply>\n";
  graph += "    <output name=\"out\" type=\"float\" nodename=\"m0\" />\n  </nodegraph>\n";
  Imported deep = mtlx(graph + R"(  <standard_surface name="SR" type="surfaceshader">
    <input name="specular_roughness" type="float" nodegraph="NG" output="out" />
  </standard_surface>
  <surfacematerial name="M" type="material"><input name="surfaceshader" type="surfaceshader" nodename="SR" /></surfacematerial>
)");
  EXPECT_FALSE(deep.materials);
  EXPECT_NE(deep.diags.find("the graph is deeper than 256 nodes"), std::string::npos) << deep.diags.substr(0, 400);

  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("substratec_include_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const char* head = "<?xml version=\"1.0\"?>\n<materialx version=\"1.39\" xmlns:xi=\"http://www.w3.org/2001/XInclude\">\n";
  std::ofstream(dir / "a.mtlx") << head << "  <xi:include href=\"b.mtlx\" />\n</materialx>\n";
  std::ofstream(dir / "b.mtlx") << head << "  <xi:include href=\"a.mtlx\" />\n</materialx>\n";
  Diagnostics d("a.mtlx");
  auto r = importFile((dir / "a.mtlx").string(), ReadLimits{}, d);
  EXPECT_FALSE(r);
  // Located at the include that closes the cycle, in the file that holds it.
  EXPECT_EQ(d.formatAll(),
            "b.mtlx:3:4: error: xi:include 'a.mtlx' closes a cycle of includes (a.mtlx -> b.mtlx -> a.mtlx)\n");
  std::filesystem::remove_all(dir);
}

TEST(GltfImport, ATextureWithoutAnImageIsAnError) {
  Imported r = gltf(R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])", R"(, "textures": [{"source": 2}], "images": [])");
  EXPECT_FALSE(r.materials);
  EXPECT_NE(r.diags.find("t.gltf:1:103: error: expected the index of one of the document's 0 images"),
            std::string::npos) << r.diags;
}

// --- Buffers and images a .gltf or .glb refers to (issue 16) -----------------

/// A .glb with a binary chunk of `bin` bytes (zeros) after the JSON.
std::string glbWithBin(const std::string& json, std::uint32_t bin) {
  std::string chunk = json;
  while (chunk.size() % 4) chunk += ' ';
  auto le = [](std::uint32_t v) {
    std::string s(4, '\0');
    for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((v >> (8 * i)) & 0xff);
    return s;
  };
  std::string body = le(static_cast<std::uint32_t>(chunk.size())) + "JSON" + chunk + le(bin) + std::string("BIN\0", 4) +
                     std::string(bin, '\0');
  return "glTF" + le(2) + le(static_cast<std::uint32_t>(12 + body.size())) + body;
}

const char* kTwoImages = R"({"asset": {"version": "2.0"},
  "materials": [{"name": "M", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
  "textures": [{"source": 0}, {"source": 1}],
  "images": [{"uri": "used%20image.png"}, {"uri": "unused.png"}],
  "buffers": [{"uri": "geometry.bin", "byteLength": 10}, {"uri": "data:application/octet-stream;base64,AAAA", "byteLength": 3},
              {"uri": "data:application/octet-stream;base64,A$AA", "byteLength": 3}]})";

TEST(GltfResources, AMissingFileIsAWarningAndAnErrorWhereAMaterialSamplesIt) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("substratec_res_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "m.gltf") << kTwoImages;
  Diagnostics d("m.gltf");
  EXPECT_FALSE(importFile((dir / "m.gltf").string(), ReadLimits{}, d));
  const std::string all = d.formatAll();
  const std::string at = (dir / "").string();
  for (const std::string& want :
       {"m.gltf:4:22: error: images[0] \"" + at + "used image.png\" cannot be read (No such file or directory): "
        "material \"M\" samples it",
        "m.gltf:4:51: warning: images[1] \"" + at + "unused.png\" cannot be read (No such file or directory); "
        "no material samples it",
        "m.gltf:5:23: warning: buffers[0] \"" + at + "geometry.bin\" cannot be read (No such file or "
        "directory); materials do not need geometry",
        std::string("m.gltf:6:23: warning: buffers[2] \"data:application/octet-stream;base64,A$AA\" cannot "
                    "be read (a base64 data: URI with the character \"$\" at 1)")})
    EXPECT_NE(all.find(want), std::string::npos) << want << "\n" << all;
  EXPECT_EQ(all.find("buffers[1]"), std::string::npos) << all;  // a well-formed data: URI
  // With the sampled image there, only the warnings are left.
  std::ofstream(dir / "used image.png") << "png";
  Diagnostics again("m.gltf");
  auto ok = importFile((dir / "m.gltf").string(), ReadLimits{}, again);
  EXPECT_TRUE(ok) << again.formatAll();
  EXPECT_EQ(again.errorCount(), 0u);
  // A buffer shorter than its byteLength is as good as missing.
  std::ofstream(dir / "geometry.bin") << "short";
  Diagnostics shortBuffer("m.gltf");
  EXPECT_TRUE(importFile((dir / "m.gltf").string(), ReadLimits{}, shortBuffer));
  EXPECT_NE(shortBuffer.formatAll().find(": warning: buffers[0] holds 5 bytes, fewer than its "
                                         "byteLength 10; materials do not need geometry [/buffers/0/byteLength]"), std::string::npos) << shortBuffer.formatAll();
  std::filesystem::remove_all(dir);
}

TEST(GltfResources, AGlbImageInItsBinaryChunkIsReadableOnlyWhenTheChunkHoldsIt) {
  const std::string json = R"({"asset": {"version": "2.0"},
    "materials": [{"name": "M", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
    "textures": [{"source": 0}], "images": [{"bufferView": 0, "mimeType": "image/png"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 4, "byteLength": 8}], "buffers": [{"byteLength": 12}]})";
  Imported fits = importAs(SourceKind::Glb, glbWithBin(json, 12), "m.glb");
  EXPECT_TRUE(fits.materials) << fits.diags;
  EXPECT_EQ(fits.diags, "");
  Imported cut = importAs(SourceKind::Glb, glbWithBin(json, 8), "m.glb");
  EXPECT_FALSE(cut.materials);
  EXPECT_NE(cut.diags.find("m.glb: error: images[0] in bufferViews[0] cannot be read (buffers[0] "
                           "cannot be read): material \"M\" samples it"), std::string::npos) << cut.diags;
  Imported none = importAs(SourceKind::Glb, glb(json), "m.glb");  // no binary chunk at all
  EXPECT_FALSE(none.materials);
  EXPECT_NE(none.diags.find("m.glb: warning: buffers[0] has no uri and the document has no .glb binary chunk"),
            std::string::npos) << none.diags;
}

TEST(GltfResources, MissingFilesAreReportedOncePerFileAndBounded) {
  std::string buffers;
  for (int i = 0; i < 100; ++i)
    buffers += std::string(i ? ", " : "") + R"({"uri": "b)" + std::to_string(i % 50) + R"(.bin", "byteLength": 4})";
  Imported r = importAs(SourceKind::Gltf, R"({"asset": {"version": "2.0"}, "materials": [{"name": "M"}], "buffers": [)" +
                                              buffers + "]}", "m.gltf");
  ASSERT_TRUE(r.materials) << r.diags;  // geometry is never needed
  std::size_t lines = 0;
  for (char c : r.diags) lines += c == '\n';
  EXPECT_EQ(lines, static_cast<std::size_t>(kMaxResourceWarnings) + 1) << r.diags;  // 50 files: 32, then one line
  EXPECT_NE(r.diags.find("m.gltf:1:1: warning: 18 more resources cannot be read (not listed)"), std::string::npos)
      << r.diags;
}

// --- Fuzzing regressions (issue 16) -------------------------------------------

TEST(ImportFuzzRegressions, EveryInputThatOnceCrashedIsImportedOrRejected) {
  // tests/import/fuzz_regressions: inputs mtlx_fuzzer and gltf_fuzzer found
  // (fuzz/, scripts/fuzz.sh), checked as the fuzzers check them: imported, with
  // usable names and materials that compile, or rejected with an error.
  const std::filesystem::path dir = std::filesystem::path(SUBSTRATEC_SOURCE_DIR) / "tests/import/fuzz_regressions";
  int checked = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    const SourceKind kind = sourceKindOf(name);
    if (kind == SourceKind::Substrate) continue;
    std::ifstream in(e.path(), std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    Diagnostics d(name);
    auto materials = importText(kind, name, text, "/nonexistent-substratec-fuzz/dir", ReadLimits{}, d);
    if (!materials) {
      EXPECT_TRUE(d.hasErrors()) << name;
    } else {
      for (const auto& m : *materials) {
        EXPECT_TRUE(isUsableIdentifier(m.name)) << name << ": " << m.name;
        compiled(m);
      }
    }
    ++checked;
  }
  EXPECT_GE(checked, 1);
}

}  // namespace importer_test
