// Tests for the storage layout and its pricing (compiler/core/storage/layout.h):
// the byte figures and layout classes of the SIGGRAPH course table (the
// examples/row*.json materials), then each storage rule on a small document:
// which fields a closure stores, when a basis normal is elided, and
// bytes = 4 * ceil(bits / 32) + 4 bytes of top-layer data.
#include "storage/layout.h"

#include <gtest/gtest.h>

#include <fstream>
#include <numeric>
#include <sstream>

#include "ir/tree_info.h"
#include "test_util.h"

namespace substratec {
namespace layout_test {

using test::buildMaterial;
using test::material;

constexpr const char* kInputs = R"({
  "m": {"type": "float", "default": 0.5},
  "w": {"type": "float", "default": 0.5},
  "nA": {"type": "vec3", "default": [0, 0, 1]},
  "nB": {"type": "vec3", "default": [0, 0.6, 0.8]}
})";

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Priced {
  Material m;
  StorageLayout layout;
};

Priced price(const std::string& json) {
  Priced p;
  p.m = buildMaterial(json);
  if (p.m.root >= 0) p.layout = computeLayout(p.m, analyzeTree(p.m));
  return p;
}

/// Field names in stream order, space separated.
std::string fields(const StorageLayout& L) {
  std::string out;
  for (const auto& f : L.fields) out += (out.empty() ? "" : " ") + f.name;
  return out;
}

/// The arithmetic every layout must satisfy.
void expectConsistent(const StorageLayout& L) {
  int sum = 0;
  for (const auto& f : L.fields) sum += f.bits;
  EXPECT_EQ(L.totalBits, sum);
  EXPECT_EQ(L.words(), (L.totalBits + 31) / 32);
  EXPECT_EQ(L.bytes(), L.words() * 4 + 4);
}

// ---------------------------------------------------------------------------
// The course table

struct Row {
  const char* file;
  int bytes;
  const char* layoutClass;
  int closures;
};

class CourseTable : public ::testing::TestWithParam<Row> {};

TEST_P(CourseTable, BytesAndLayoutClass) {
  const Row& row = GetParam();
  const std::string text = readFile(std::string(SUBSTRATEC_SOURCE_DIR "/examples/") + row.file + ".json");
  ASSERT_FALSE(text.empty()) << row.file;
  Priced p = price(text);
  EXPECT_EQ(p.layout.bytes(), row.bytes);
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), row.layoutClass);
  EXPECT_EQ(static_cast<int>(p.layout.closures.size()), row.closures);
  expectConsistent(p.layout);
}

INSTANTIATE_TEST_SUITE_P(Layout, CourseTable,
                         ::testing::Values(Row{"row12_simple", 12, "SIMPLE", 1},
                                           Row{"row16_single_sss_wrap", 16, "SINGLE", 1},
                                           Row{"row20_haze_f90", 20, "SINGLE", 1},
                                           Row{"row24_fuzz", 24, "SINGLE", 1},
                                           Row{"row28_anisotropy", 28, "COMPLEX", 1},
                                           Row{"row40_coating", 40, "COMPLEX", 2},
                                           Row{"row44_specular_profile", 44, "SPECIAL", 2},
                                           Row{"row60_glint", 60, "SPECIAL", 2},
                                           Row{"worked_example_72", 72, "COMPLEX", 3}),
                         [](const ::testing::TestParamInfo<Row>& info) { return std::string(info.param.file); });

TEST(Layout, CoatingRowFieldByField) {
  Priced p = price(readFile(SUBSTRATEC_SOURCE_DIR "/examples/row40_coating.json"));
  // The clear coat stores only its basics (its medium costs nothing); the base
  // stores the coat's transmittance and its features; the shared basis is the
  // top-layer normal plus the base's tangent angle.
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness closure1.top_transmittance "
            "closure1.f90 closure1.sss closure1.haze closure1.fuzz closure1.anisotropy "
            "basis0.tangent_angle");
  EXPECT_EQ(p.layout.totalBits, 282);
  EXPECT_EQ(p.layout.words(), 9);
  EXPECT_TRUE(p.layout.basis0NormalElided);
}

// ---------------------------------------------------------------------------
// A lone closure

TEST(Layout, LoneSlabIsSimple) {
  Priced p = price(material(R"("root": {"kind": "slab", "roughness": 0.3, "normal": "$nA"})", kInputs));
  // A lone closure's normal is the top-layer normal: no basis field.
  EXPECT_EQ(fields(p.layout), "header closure0.diffuse_albedo closure0.f0 closure0.roughness");
  EXPECT_EQ(p.layout.totalBits, 64);
  EXPECT_EQ(p.layout.bytes(), 12);
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "SIMPLE");
}

TEST(Layout, LoneClosureUnderARunTimeCoverageWeightStoresAWeightAndIsSingle) {
  Priced p = price(material(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": "$w"})",
                            kInputs));
  EXPECT_EQ(fields(p.layout), "header closure0.diffuse_albedo closure0.f0 closure0.roughness closure0.weight");
  ASSERT_EQ(p.layout.closures.size(), 1u);
  EXPECT_TRUE(p.layout.closures[0].storesWeight);
  EXPECT_EQ(p.layout.totalBits, 72);
  EXPECT_EQ(p.layout.bytes(), 16);
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "SINGLE");
  expectConsistent(p.layout);
}

TEST(Layout, NoModify_ConstantWeightOneIsCulledAndStaysSimple) {
  Priced p = price(material(R"(
    "s": {"kind": "slab", "roughness": 0.3},
    "root": {"kind": "coverage_weight", "a": "s", "weight": 1})",
                            kInputs));
  EXPECT_EQ(fields(p.layout), "header closure0.diffuse_albedo closure0.f0 closure0.roughness");
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "SIMPLE");
}

TEST(Layout, LoneClosureLeftByAHorizontalStoresTheWeight) {
  // The foreground is culled; the background is weighted by 1 - mix.
  Priced p = price(material(R"(
    "a": {"kind": "slab", "roughness": 0.3},
    "b": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "horizontal", "background": "a", "mix": "$m",
             "foreground": {"kind": "coverage_weight", "a": "b", "weight": 0}})",
                            kInputs));
  EXPECT_EQ(fields(p.layout), "header closure0.diffuse_albedo closure0.f0 closure0.roughness closure0.weight");
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "SINGLE");
}

TEST(Layout, EmissiveCostsNoBytes) {
  Priced p = price(material(R"("root": {"kind": "slab", "emissive": [1, 0.5, 0]})", kInputs));
  EXPECT_EQ(fields(p.layout), "header closure0.diffuse_albedo closure0.f0 closure0.roughness");
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "SIMPLE");
}

// ---------------------------------------------------------------------------
// Layers: top transmittance and coverage above

TEST(Layout, VerticalBaseStoresTopTransmittance) {
  Priced p = price(material(R"(
    "coat": {"kind": "slab", "roughness": 0.1, "sss_mfp": 10},
    "base": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": "coat", "base": "base"})",
                            kInputs));
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness closure1.top_transmittance");
  EXPECT_EQ(p.layout.totalBits, 164);
  EXPECT_EQ(p.layout.bytes(), 28);
  EXPECT_EQ(layoutClassName(p.layout.layoutClass), "COMPLEX");
  ASSERT_EQ(p.layout.closures.size(), 2u);
  EXPECT_TRUE(p.layout.closures[0].isTop);
  EXPECT_FALSE(p.layout.closures[1].isTop);
}

TEST(Layout, NoModify_AddStoresNoTransmittance) {
  Priced p = price(material(R"(
    "a": {"kind": "slab", "roughness": 0.1},
    "b": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                            kInputs));
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness");
  EXPECT_EQ(p.layout.bytes(), 24);
}

TEST(Layout, CoverageAboveIsStoredUnderAPartlyCoveringLayer) {
  Priced p = price(material(R"(
    "coat": {"kind": "slab", "roughness": 0.1},
    "base": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": {"kind": "coverage_weight", "a": "coat", "weight": "$w"}, "base": "base"})",
                            kInputs));
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness closure0.weight "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness closure1.top_transmittance "
            "closure1.coverage_above");
  EXPECT_EQ(p.layout.totalBits, 180);
  EXPECT_TRUE(p.layout.closures[1].storesCoverageAbove);
  EXPECT_FALSE(p.layout.closures[1].storesWeight);
}

TEST(Layout, CoverageAboveIsStoredUnderAHorizontalWithAPartlyCoveringSide) {
  Priced p = price(material(R"(
    "a": {"kind": "slab", "roughness": 0.1},
    "b": {"kind": "slab", "roughness": 0.2},
    "base": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "base": "base",
             "top": {"kind": "horizontal", "background": "a", "mix": "$m",
                     "foreground": {"kind": "coverage_weight", "a": "b", "weight": "$w"}}})",
                            kInputs));
  ASSERT_EQ(p.layout.closures.size(), 3u);
  EXPECT_TRUE(p.layout.closures[2].storesCoverageAbove);
  EXPECT_NE(fields(p.layout).find("closure2.coverage_above"), std::string::npos);
}

TEST(Layout, CoverageAboveIsStoredUnderEveryLayerBelowAPartlyCoveringOne) {
  Priced p = price(material(R"(
    "coat": {"kind": "slab", "roughness": 0.1},
    "mid": {"kind": "slab", "roughness": 0.3, "sss_mfp": 10},
    "base": {"kind": "slab", "roughness": 0.6},
    "root": {"kind": "vertical", "top": {"kind": "coverage_weight", "a": "coat", "weight": "$w"},
             "base": {"kind": "vertical", "top": "mid", "base": "base"}})",
                            kInputs));
  ASSERT_EQ(p.layout.closures.size(), 3u);
  EXPECT_FALSE(p.layout.closures[0].storesCoverageAbove);
  EXPECT_TRUE(p.layout.closures[1].storesCoverageAbove);
  EXPECT_TRUE(p.layout.closures[2].storesCoverageAbove);
}

TEST(Layout, ClosuresCountTheInterfacesAboveThemUpToFourInTheirHeader) {
  // The closure header's last two bits hold the interfaces above a closure
  // beyond the first, up to 3 (docs/storage.md): the lighting applies the
  // angular part of that many more. A top counts its slabs' interfaces on
  // the longest path down (a vertical top its top and base, a mix its larger
  // side); a top closure and one under a single interface store 0.
  Priced p = price(material(R"(
    "c0": {"kind": "slab", "roughness": 0.1, "sss_mfp": 10},
    "c1": {"kind": "slab", "roughness": 0.2, "sss_mfp": 10},
    "c2": {"kind": "slab", "roughness": 0.3, "sss_mfp": 10},
    "m0": {"kind": "slab", "roughness": 0.4, "sss_mfp": 10},
    "m1": {"kind": "slab", "roughness": 0.5, "sss_mfp": 10},
    "base": {"kind": "slab", "roughness": 0.6},
    "coats": {"kind": "vertical", "top": "c0", "base": {"kind": "vertical", "top": "c1", "base": "c2"}},
    "root": {"kind": "vertical", "top": "coats",
             "base": {"kind": "vertical", "top": {"kind": "horizontal", "background": "m0", "foreground": "m1", "mix": "$m"},
                      "base": "base"}})",
                            kInputs));
  ASSERT_EQ(p.layout.closures.size(), 6u);
  // Pre-order: c0 (top), c1 (under c0), c2 (under c0, c1), m0 and m1 (under
  // the three coats), base (under the coats and the mix: 4 interfaces).
  const int want[] = {0, 0, 1, 2, 2, 3};
  for (int k = 0; k < 6; ++k) EXPECT_EQ(p.layout.closures[k].extraInterfaces, want[k]) << "closure " << k;
  expectConsistent(p.layout);
  int headers = 0;
  for (const auto& f : p.layout.fields)
    if (f.name.ends_with(".header")) {
      ++headers;
      EXPECT_EQ(f.encoding, "basis id 3 | is top 1 | feature bits 8 | sss type 2 | extra interfaces 2");
    }
  EXPECT_EQ(headers, 6);
  EXPECT_EQ(storedExtraInterfaces(0), 0);
  EXPECT_EQ(storedExtraInterfaces(1), 0);
  EXPECT_EQ(storedExtraInterfaces(4), 3);
  EXPECT_EQ(storedExtraInterfaces(9), 3);
}

TEST(Layout, NoModify_NoCoverageAboveUnderFullyCoveringLayers) {
  // A horizontal of two slabs covers fully ((1-m)*1 + m*1); an add covers
  // fully when either side does; a vertical when either its top or base does.
  for (const char* top : {
           R"({"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
           R"({"kind": "add", "a": {"kind": "coverage_weight", "a": "a", "weight": "$w"}, "b": "b"})",
           R"({"kind": "vertical", "top": {"kind": "coverage_weight", "a": "a", "weight": "$w"}, "base": "b"})",
           R"("a")",
       }) {
    Priced p = price(material(std::string(R"(
      "a": {"kind": "slab", "roughness": 0.1, "sss_mfp": 10},
      "b": {"kind": "slab", "roughness": 0.2, "sss_mfp": 10},
      "base": {"kind": "slab", "roughness": 0.6},
      "root": {"kind": "vertical", "base": "base", "top": )") + top + "}",
                              kInputs));
    const std::string f = fields(p.layout);
    const int last = static_cast<int>(p.layout.closures.size()) - 1;
    EXPECT_FALSE(p.layout.closures[last].storesCoverageAbove) << top;
    EXPECT_NE(f.find("closure" + std::to_string(last) + ".top_transmittance"), std::string::npos) << top;
    EXPECT_EQ(f.find(std::to_string(last) + ".coverage_above"), std::string::npos) << top << "\n" << f;
  }
}

// ---------------------------------------------------------------------------
// Bases

TEST(Layout, Basis0NormalIsElidedWhenEveryTopClosureUsesBasis0) {
  Priced p = price(material(R"(
    "a": {"kind": "slab", "normal": "$nA", "roughness": 0.1, "sss_mfp": 10},
    "b": {"kind": "slab", "normal": "$nA", "roughness": 0.2, "sss_mfp": 10},
    "base": {"kind": "slab", "normal": "$nB", "roughness": 0.6},
    "root": {"kind": "vertical", "base": "base",
             "top": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"}})",
                            kInputs));
  EXPECT_EQ(p.layout.basisCount, 2);
  EXPECT_TRUE(p.layout.basis0NormalElided);
  const std::string f = fields(p.layout);
  EXPECT_EQ(f.find("basis0.normal"), std::string::npos) << f;
  EXPECT_EQ(f.substr(f.rfind(' ') + 1), "basis1.normal");
  EXPECT_EQ(p.layout.fields.back().bits, 32);
  EXPECT_EQ(p.layout.fields.back().basis, 1);
}

TEST(Layout, Basis0NormalIsStoredWhenTopClosuresUseSeveralBases) {
  Priced p = price(material(R"(
    "a": {"kind": "slab", "normal": "$nA", "roughness": 0.1},
    "b": {"kind": "slab", "normal": "$nB", "roughness": 0.2},
    "root": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": "$m"})",
                            kInputs));
  EXPECT_EQ(p.layout.basisCount, 2);
  EXPECT_FALSE(p.layout.basis0NormalElided);
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness closure0.weight "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness closure1.weight "
            "basis0.normal basis1.normal");
  EXPECT_EQ(p.layout.totalBits, 16 + 2 * (16 + 20 + 20 + 8 + 8) + 2 * 32);
  expectConsistent(p.layout);
}

TEST(Layout, SharedAnisotropicBasisStoresOneTangentAngle) {
  Priced p = price(material(R"(
    "a": {"kind": "slab", "anisotropy": 0.5, "roughness": 0.1},
    "b": {"kind": "slab", "anisotropy": 0.8, "roughness": 0.2},
    "root": {"kind": "add", "a": "a", "b": "b"})",
                            kInputs));
  EXPECT_EQ(fields(p.layout),
            "header "
            "closure0.header closure0.diffuse_albedo closure0.f0 closure0.roughness closure0.anisotropy "
            "closure1.header closure1.diffuse_albedo closure1.f0 closure1.roughness closure1.anisotropy "
            "basis0.tangent_angle");
}

// ---------------------------------------------------------------------------
// Bytes

TEST(Layout, BytesAreWordsTimesFourPlusTheTopLayerWord) {
  StorageLayout L;
  for (int bits : {0, 1, 31, 32, 33, 64, 65, 282}) {
    L.totalBits = bits;
    EXPECT_EQ(L.words(), (bits + 31) / 32) << bits;
    EXPECT_EQ(L.bytes(), L.words() * 4 + 4) << bits;
  }
  L.totalBits = 64;
  EXPECT_EQ(L.bytes(), 12);
  L.totalBits = 65;
  EXPECT_EQ(L.bytes(), 16);
}

}  // namespace layout_test
}  // namespace substratec
