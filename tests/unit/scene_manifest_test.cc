// Scenes and platforms (docs/scenes.md): the built-in platform table, a
// project's platforms file (extending and overriding it, every mistake
// located), the substrate-scene/1 manifest, and a material simplified for a
// platform (budget and closures capped, disallowed features disabled).
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "pipeline/pipeline.h"
#include "scene/manifest.h"
#include "pipeline/platform.h"

namespace substratec {
namespace {

std::string readExample(const std::string& rel) {
  std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/" + rel, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Platforms, TheBuiltInTableIsTheDocumentedOne) {
  const PlatformTable t = PlatformTable::builtin();
  EXPECT_EQ(t.names(), "mobile, console, pc-high");
  const Platform* mobile = t.find("mobile");
  ASSERT_NE(mobile, nullptr);
  EXPECT_EQ(mobile->bytesPerPixel, 20);
  EXPECT_EQ(mobile->maxClosures, 1);
  for (std::uint16_t f : {kFeatSss, kFeatFuzz, kFeatGlint, kFeatSpecularProfile})
    EXPECT_TRUE(mobile->disallowedFeatures() & f) << f;
  EXPECT_EQ(mobile->allowedFeatures, kFeatF90 | kFeatAnisotropy | kFeatHaze | kFeatEmissive);
  const Platform* console = t.find("console");
  ASSERT_NE(console, nullptr);
  EXPECT_EQ(console->bytesPerPixel, 48);
  EXPECT_EQ(console->maxClosures, 4);
  EXPECT_EQ(console->disallowedFeatures(), kFeatGlint);
  const Platform* pc = t.find("pc-high");
  ASSERT_NE(pc, nullptr);
  EXPECT_EQ(pc->bytesPerPixel, 80);
  EXPECT_EQ(pc->maxClosures, 8);
  EXPECT_EQ(pc->disallowedFeatures(), 0);
  EXPECT_EQ(t.find("ps2"), nullptr);
}

TEST(Platforms, AFileExtendsAndOverridesTheTable) {
  PlatformTable t = PlatformTable::builtin();
  Diagnostics d("examples/platforms/studio.json");
  ASSERT_TRUE(t.applyText(readExample("examples/platforms/studio.json"), ReadLimits{}, d)) << d.formatAll();
  EXPECT_EQ(t.names(), "mobile, console, pc-high, handheld");
  const Platform* handheld = t.find("handheld");
  ASSERT_NE(handheld, nullptr);
  EXPECT_EQ(handheld->bytesPerPixel, 28);
  EXPECT_EQ(handheld->maxClosures, 1);  // from mobile
  EXPECT_EQ(handheld->allowedFeatures, kFeatF90 | kFeatAnisotropy | kFeatHaze | kFeatFuzz | kFeatEmissive);
  const Platform* console = t.find("console");
  EXPECT_EQ(console->maxClosures, 6);     // overridden
  EXPECT_EQ(console->bytesPerPixel, 48);  // kept
  EXPECT_EQ(console->disallowedFeatures(), kFeatGlint);
}

TEST(Platforms, EveryMistakeIsLocatedAndNothingIsApplied) {
  PlatformTable t = PlatformTable::builtin();
  Diagnostics d("p.json");
  const std::string text = R"({
  "format": "substrate-platforms/1",
  "platforms": {
    "tv": {"bytes_per_pixel": 4, "max_closures": 2, "features": ["fuzz", "sheen", "fuzz"]},
    "Big": {"max_closures": 1},
    "watch": {"max_closures": 1},
    "car": {"extends": "plane", "budget": 3}
  }
})";
  EXPECT_FALSE(t.applyText(text, ReadLimits{}, d));
  const std::string all = d.formatAll();
  EXPECT_NE(all.find("p.json:4:31: error: expected an integer in [8,1024], got 4"),
            std::string::npos) << all;
  EXPECT_NE(all.find("p.json:4:74: error: expected a feature name"), std::string::npos) << all;
  EXPECT_NE(all.find("p.json:4:83: error: feature \"fuzz\" is listed twice"), std::string::npos)
      << all;
  EXPECT_NE(all.find("p.json:5:12: error: platform name \"Big\""), std::string::npos) << all;
  EXPECT_NE(all.find("p.json:6:14: error: a new platform needs \"bytes_per_pixel\""), std::string::npos)
      << all;
  EXPECT_NE(all.find("p.json:7:24: error: expected the name of a platform defined before"),
            std::string::npos) << all;
  EXPECT_EQ(t.names(), "mobile, console, pc-high");  // unchanged
  Diagnostics syntax("p.json");
  EXPECT_FALSE(t.applyText("{\"format\": \"substrate-platforms/1\",\n \"platforms\": {,}}", ReadLimits{}, syntax));
  EXPECT_NE(syntax.formatAll().find("p.json:2:"), std::string::npos) << syntax.formatAll();
}

TEST(SceneManifest, ReadsTheExampleScenes) {
  for (const char* rel : {"examples/scenes/simple_only.json", "examples/scenes/all_examples.json",
                          "examples/scenes/mobile_examples.json", "examples/scenes/street.json"}) {
    Diagnostics d(rel);
    auto s = parseSceneManifest(rel, readExample(rel), ReadLimits{}, d);
    ASSERT_TRUE(s.has_value()) << d.formatAll();
    EXPECT_FALSE(s->materials.empty());
    for (const auto& m : s->materials) {
      std::ifstream in(std::string(SUBSTRATEC_SOURCE_DIR) + "/" + m.path);
      EXPECT_TRUE(in.good()) << m.path;
      EXPECT_EQ(m.path.find(".."), std::string::npos) << "normalized against the manifest's directory: " << m.path;
    }
  }
  Diagnostics d("examples/scenes/simple_only.json");
  auto s = parseSceneManifest("examples/scenes/simple_only.json", readExample("examples/scenes/simple_only.json"),
                              ReadLimits{}, d);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->name, "simple_only");
  EXPECT_EQ(s->platform.value_or(""), "pc-high");
  ASSERT_EQ(s->materials.size(), 3u);
  EXPECT_EQ(s->materials[0].path, "examples/scenes/materials/plaster.json");
  EXPECT_EQ(s->materials[2].path, "examples/row12_simple.json");
  EXPECT_EQ(s->materials[2].written, "../row12_simple.json");
  EXPECT_EQ(s->materials[2].pointer, "/materials/2");
}

TEST(SceneManifest, EveryMistakeIsLocated) {
  Diagnostics d("dir/s.json");
  auto s = parseSceneManifest("dir/s.json", R"({
  "format": "substrate-scene/2", "name": "two words", "platform": 3, "lights": [],
  "materials": ["a.json", "", "./a.json", 7]
})",
                              ReadLimits{}, d);
  EXPECT_FALSE(s.has_value());
  const std::string all = d.formatAll();
  for (const char* want :
       {"dir/s.json:2:13: error: expected \"substrate-scene/1\", got \"substrate-scene/2\"",
        "dir/s.json:2:42: error: expected a C identifier", "dir/s.json:2:67: error: expected a platform name, got 3",
        "dir/s.json:2:80: error: unknown key \"lights\"",
        "dir/s.json:3:27: error: expected a material file path",
        "dir/s.json:3:31: error: \"./a.json\" is already listed at /materials/0",
        "dir/s.json:3:43: error: expected a material file path (relative to the manifest), got 7"})
    EXPECT_NE(all.find(want), std::string::npos) << want << "\n" << all;
  // What could be read is kept for the scene build, which goes on to the
  // materials' errors: a.json once, the name and platform dropped.
  Diagnostics again("dir/s.json");
  auto partial = readSceneManifest("dir/s.json", R"({"format": "substrate-scene/1", "name": "s",
    "materials": ["a.json", "./a.json", 7, "b.json"]})", ReadLimits{}, again);
  ASSERT_TRUE(partial.has_value());
  EXPECT_EQ(again.errorCount(), 2u) << again.formatAll();
  ASSERT_EQ(partial->materials.size(), 2u);
  EXPECT_EQ(partial->materials[0].pointer, "/materials/0");
  EXPECT_EQ(partial->materials[1].pointer, "/materials/3");
  Diagnostics empty("s.json");
  EXPECT_FALSE(parseSceneManifest("s.json", R"({"format": "substrate-scene/1", "name": "x", "materials": []})",
                                  ReadLimits{}, empty));
  EXPECT_NE(empty.formatAll().find("s.json:1:59: error: expected a non-empty array"), std::string::npos);
  Diagnostics syntax("s.json");
  EXPECT_FALSE(parseSceneManifest("s.json", "{\n  \"name\": \"x\",,\n}", ReadLimits{}, syntax));
  EXPECT_NE(syntax.formatAll().find("s.json:2:"), std::string::npos) << syntax.formatAll();
}

CompileResult compileFor(const std::string& rel, const char* platform) {
  CompileOptions o;
  o.platform = *PlatformTable::builtin().find(platform);
  Diagnostics d(rel);
  auto r = compileText(rel, readExample(rel), o, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

std::uint16_t featuresOf(const CompileResult& r) {
  std::uint16_t all = 0;
  for (const ClosureLayout& c : r.after.closures) all |= r.material.slabs[c.slab].features;
  return all;
}

TEST(PlatformSimplification, MobileCapsTheBudgetAndDisallowsItsFeatures) {
  // row24_fuzz (24 B, F90 + SSS + haze + fuzz) fits 80 B but not mobile: SSS
  // and fuzz are disallowed first, then it fits 20 B without losing more.
  CompileResult r = compileFor("examples/row24_fuzz.json", "mobile");
  EXPECT_EQ(r.budgetBytes, 20);
  EXPECT_EQ(r.maxClosures, 1);
  EXPECT_LE(r.after.bytes(), 20);
  EXPECT_FALSE(featuresOf(r) & (kFeatSss | kFeatFuzz | kFeatGlint | kFeatSpecularProfile));
  EXPECT_TRUE(featuresOf(r) & kFeatF90);
  EXPECT_TRUE(featuresOf(r) & kFeatHaze);
  ASSERT_GE(r.steps.size(), 2u);
  EXPECT_EQ(r.steps[0].action + " " + r.steps[0].node, "disallow fuzz");
  EXPECT_EQ(r.steps[1].action + " " + r.steps[1].node, "disallow sss");
  // Every example fits mobile, with one closure and none of its disallowed features.
  for (const char* ex : {"examples/worked_example_72.json", "examples/row60_glint.json", "examples/skin_coated.json",
                         "examples/car_paint.json", "examples/row44_specular_profile.json"}) {
    SCOPED_TRACE(ex);
    CompileResult m = compileFor(ex, "mobile");
    EXPECT_LE(m.after.bytes(), 20);
    EXPECT_EQ(m.after.closures.size(), 1u);
    EXPECT_FALSE(featuresOf(m) & PlatformTable::builtin().find("mobile")->disallowedFeatures());
  }
}

TEST(PlatformSimplification, ThePlatformNeverRaisesTheMaterialsOwnBudget) {
  CompileOptions o;
  o.platform = *PlatformTable::builtin().find("pc-high");
  o.budgetOverride = 20;
  Diagnostics d("w");
  auto r = compileText("w", readExample("examples/worked_example_72.json"), o, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(r->budgetBytes, 20);
  EXPECT_LE(r->after.bytes(), 20);
  // console: no glint, 48 B, 4 closures.
  CompileResult car = compileFor("examples/car_paint.json", "console");
  EXPECT_FALSE(featuresOf(car) & kFeatGlint);
  EXPECT_EQ(car.steps.front().action + " " + car.steps.front().node, "disallow glint");
  // pc-high changes nothing for an example (each asks for 80 B, 8 closures).
  CompileResult w = compileFor("examples/worked_example_72.json", "pc-high");
  EXPECT_EQ(w.after.bytes(), 72);
  EXPECT_TRUE(w.steps.empty());
}

TEST(PlatformSimplification, ADisallowedEmissiveIsDisabled) {
  PlatformTable t = PlatformTable::builtin();
  Diagnostics pd("p.json");
  ASSERT_TRUE(t.applyText(R"({"format": "substrate-platforms/1",
    "platforms": {"dark": {"bytes_per_pixel": 80, "max_closures": 8, "features": []}}})",
                          ReadLimits{}, pd))
      << pd.formatAll();
  CompileOptions o;
  o.platform = *t.find("dark");
  Diagnostics d("e.json");
  auto r = compileText("e.json", R"({"format": "substrate-material/1", "name": "lamp",
    "inputs": {"glow": {"type": "color", "default": [4, 3, 2]}},
    "nodes": {"s": {"kind": "slab", "emissive": "$glow", "fuzz_amount": 0.5}}, "output": "s"})",
                       o, d);
  ASSERT_TRUE(r) << d.formatAll();
  EXPECT_EQ(featuresOf(*r), 0) << "emissive and fuzz both disallowed";
  EXPECT_EQ(r->after.layoutClass, LayoutClass::Simple);
}

}  // namespace
}  // namespace substratec
