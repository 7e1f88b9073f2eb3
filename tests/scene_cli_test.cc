// `substratec scene` (docs/scenes.md): what a scene of simple materials, one of
// every example and one for mobile produce; the same bytes whatever -j is;
// every mistake located, with nothing written.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "cli_util.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace fs = std::filesystem;
using substratec::runCli;
using substratec::clitest::cli;
using substratec::clitest::CliResult;
using substratec::clitest::filesOf;
using substratec::clitest::slurp;

namespace scene_cli_test {

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

fs::path freshDir(const std::string& name) {
  fs::path d = substratec::clitest::freshDir("scene", name);
  return d;
}

std::string scene(const char* name) { return (kSource / "examples" / "scenes" / name).string(); }

nlohmann::json sceneJson(const fs::path& dir) { return nlohmann::json::parse(slurp(dir / "scene.json")); }


/// OpLoopMerge (246) instructions in a SPIR-V module.
std::size_t loops(const std::vector<uint32_t>& w) {
  std::size_t n = 0;
  for (std::size_t i = 5; i < w.size() && (w[i] >> 16) != 0; i += w[i] >> 16) n += (w[i] & 0xffffu) == 246;
  return n;
}

/// Compiles a written compute shader against the embedded runtime.
substratec::ShaderValidation compileWritten(const fs::path& file) {
  substratec::ShaderSource src;
  src.name = file.filename().string();
  src.text = slurp(file);
  src.language = file.extension() == ".comp" ? substratec::ShaderLanguage::Glsl : substratec::ShaderLanguage::Hlsl;
  src.stage = substratec::ShaderStage::Compute;
  for (const auto& f : substratec::runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  return substratec::compileAndValidate(src);
}

TEST(Scene, ASceneOfSimpleMaterialsLightsOneClosureWithoutALoopOrAFeature) {
  const fs::path dir = freshDir("simple_only");
  CliResult r = cli({"scene", scene("simple_only.json"), "-o", dir.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const auto j = sceneJson(dir);
  EXPECT_EQ(j["scene"], "simple_only");
  EXPECT_EQ(j["features"], nlohmann::json::array());
  EXPECT_EQ(j["max_bytes_per_pixel"], 12);
  EXPECT_EQ(j["max_closures"], 1);
  EXPECT_EQ(j["material_buffer_slices"], 0);
  EXPECT_EQ(j["tile_classes"], nlohmann::json::array({"simple"}));
  ASSERT_EQ(j["materials"].size(), 3u);
  for (const auto& m : j["materials"]) {
    EXPECT_EQ(m["layout"], "SIMPLE") << m["name"];
    EXPECT_EQ(m["bytes_per_pixel"], 12);
    EXPECT_EQ(m["closures"], 1);
    EXPECT_TRUE(fs::exists(dir / (m["name"].get<std::string>() + ".basepass.frag")));
  }
  const std::string glsl = slurp(dir / "simple_only.lighting_simple.comp");
  for (const char* off : {"SUBSTRATE_USE_ANISOTROPY 0", "SUBSTRATE_USE_FUZZ 0", "SUBSTRATE_USE_SSS 0",
                          "SUBSTRATE_USE_HAZE 0", "SUBSTRATE_USE_F90 0", "SUBSTRATE_USE_GLINT 0",
                          "SUBSTRATE_USE_SPECULAR_PROFILE 0", "SUBSTRATE_MAX_CLOSURES 1", "SUBSTRATE_MAX_WORDS 2"})
    EXPECT_NE(glsl.find(std::string("#define ") + off), std::string::npos) << off;
  EXPECT_NE(glsl.find("substrate_unpack_simple(words, topLayer, c);"), std::string::npos);
  EXPECT_EQ(glsl.find("materialBuffer"), std::string::npos) << "two words: no material buffer";
  for (const char* f : {"simple_only.lighting_simple.comp", "simple_only.lighting_simple.cs.hlsl"}) {
    auto v = compileWritten(dir / f);
    ASSERT_TRUE(v.ok) << v.log;
    EXPECT_EQ(loops(v.spirv), 0u) << f << ": no loop at all, the closure loop included";
    EXPECT_EQ(j["lighting"][0]["shaders"][fs::path(f).extension() == ".comp" ? "glsl" : "hlsl"]["spirv"]["instructions"],
              v.instructionCount);
  }
  EXPECT_FALSE(fs::exists(dir / "simple_only.lighting_single.comp"));
  EXPECT_FALSE(fs::exists(dir / "simple_only.lighting_complex.comp"));
}

TEST(Scene, EveryExampleGivesTheUnionOfFeaturesAndTheLargestMaterialBuffer) {
  const fs::path dir = freshDir("all_examples");
  CliResult r = cli({"scene", scene("all_examples.json"), "-o", dir.string(), "--target", "glsl"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = sceneJson(dir);
  EXPECT_EQ(j["features"], nlohmann::json::array({"f90", "anisotropy", "sss", "haze", "fuzz", "glint",
                                                  "specular_profile"}));
  EXPECT_EQ(j["max_bytes_per_pixel"], 72);
  EXPECT_EQ(j["words"], 17);
  EXPECT_EQ(j["material_buffer_slices"], 14);
  EXPECT_EQ(j["tile_classes"], nlohmann::json::array({"simple", "single", "complex", "special"}));
  // Each material as `report --json` prices it.
  for (const auto& m : j["materials"]) {
    std::ostringstream out, err;
    ASSERT_EQ(runCli({"report", "--json", (kSource / "examples" / (m["name"].get<std::string>() + ".json")).string()},
                     out, err),
              0);
    const auto rep = nlohmann::json::parse(out.str());
    EXPECT_EQ(m["bytes_per_pixel"], rep["after"]["bytes"]) << m["name"];
    EXPECT_EQ(m["closures"], rep["after"]["closures"]) << m["name"];
    EXPECT_EQ(m["layout"], rep["layout"]) << m["name"];
  }
  // Each class's shader compiles only what its materials store.
  std::size_t total = 0;
  for (const auto& e : j["lighting"]) total += e["shaders"]["glsl"]["spirv"]["instructions"].get<std::size_t>();
  EXPECT_EQ(j["lighting_spirv_instructions"], total);
  const auto& special = j["lighting"][3];
  EXPECT_EQ(special["class"], "special");
  EXPECT_EQ(special["max_closures"], 3);
  EXPECT_EQ(j["lighting"][1]["features"], nlohmann::json::array({"f90", "sss", "haze", "fuzz"}));
  EXPECT_NE(slurp(dir / "all_examples.lighting_single.comp").find("substrate_unpack_single_closure"), std::string::npos);
  EXPECT_NE(slurp(dir / "all_examples.lighting_special.comp").find("substrate_unpack_material"), std::string::npos);
  // The simple-only scene's lighting is smaller than any of these.
  const fs::path simple = freshDir("simple_only_glsl");
  ASSERT_EQ(cli({"scene", scene("simple_only.json"), "-o", simple.string(), "--target", "glsl"}).status, 0);
  const auto s = sceneJson(simple);
  for (const auto& e : j["lighting"])
    if (e["class"] != "simple")
      EXPECT_LT(s["lighting"][0]["shaders"]["glsl"]["spirv"]["optimized_instructions"],
                e["shaders"]["glsl"]["spirv"]["optimized_instructions"]);
}

TEST(Scene, APlatformSimplifiesEveryMaterialForIt) {
  const fs::path dir = freshDir("mobile"), cache = freshDir("mobile_cache");
  CliResult r = cli({"scene", scene("all_examples.json"), "-o", dir.string(), "--platform", "mobile", "--target", "glsl",
                     "--cache", cache.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = sceneJson(dir);
  EXPECT_EQ(j["platform"]["name"], "mobile");
  EXPECT_LE(j["max_bytes_per_pixel"].get<int>(), 20);
  EXPECT_EQ(j["max_closures"], 1);
  for (const auto& f : j["features"]) EXPECT_TRUE(f == "f90" || f == "anisotropy" || f == "haze") << f;
  for (const auto& m : j["materials"]) {
    EXPECT_LE(m["bytes_per_pixel"].get<int>(), 20) << m["name"];
    EXPECT_EQ(m["budget"]["bytes_per_pixel"], 20);
  }
  // The manifest's own platform gives the same materials.
  const fs::path own = freshDir("mobile_examples");
  ASSERT_EQ(cli({"scene", scene("mobile_examples.json"), "-o", own.string(), "--target", "glsl", "--cache",
                 cache.string()}).status,
            0);
  EXPECT_EQ(sceneJson(own)["materials"].dump(), j["materials"].dump());
  // A project's platforms file adds one.
  const fs::path handheld = freshDir("handheld");
  r = cli({"scene", scene("street.json"), "-o", handheld.string(), "--platform", "handheld", "--platforms",
           (kSource / "examples" / "platforms" / "studio.json").string(), "--target", "glsl"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto h = sceneJson(handheld);
  EXPECT_EQ(h["platform"]["bytes_per_pixel"], 28);
  EXPECT_LE(h["max_bytes_per_pixel"].get<int>(), 28);
  EXPECT_EQ(h["max_closures"], 1);
}

TEST(Scene, TheOutputIsTheSameWhateverJobsCompileIt) {
  const fs::path one = freshDir("street_j1"), two = freshDir("street_j2");
  ASSERT_EQ(cli({"scene", scene("street.json"), "-o", one.string(), "-j", "1"}).status, 0);
  ASSERT_EQ(cli({"scene", scene("street.json"), "-o", two.string(), "-j", "2"}).status, 0);
  const auto a = filesOf(one), b = filesOf(two);
  EXPECT_EQ(a.size(), 4u * 7 + 2 + 2 * 3 + 2);  // materials, classification, 3 lighting classes, scene.json, report.html
  EXPECT_TRUE(a == b);
  const auto j = sceneJson(one);
  for (const auto& m : j["materials"])
    if (m["name"] == "wet_asphalt" || m["name"] == "dusty_plastic") EXPECT_TRUE(m["runtime_simple"]) << m["name"];
  EXPECT_EQ(j["tile_classes"], nlohmann::json::array({"simple", "single", "complex"}));
  EXPECT_EQ(j["lighting"][0]["materials"],
            nlohmann::json::array({"plaster", "painted_metal", "wet_asphalt", "dusty_plastic"}))
      << "the SIMPLE shader lights the pixels dynamic simplification stores SIMPLE";
}

// A volume (a volumetric fog cloud) in a scene: its files are written, but it
// stores no pixel, so the lighting and the largest material buffer are the
// surfaces' alone; a scene of volumes only has nothing to light.
TEST(Scene, AVolumeIsCompiledButTheLightingIsTheSurfaces) {
  const fs::path work = freshDir("volume");
  fs::create_directories(work);
  const std::string plaster = (kSource / "examples" / "scenes" / "materials" / "plaster.json").string();
  const std::string fog = (kSource / "examples" / "fog_cloud_puff.json").string();
  std::ofstream(work / "mixed.json") << R"({"format": "substrate-scene/1", "name": "mixed", "materials": [")" + plaster +
                                            R"(", ")" + fog + R"("]})";
  CliResult r = cli({"scene", (work / "mixed.json").string(), "-o", (work / "out").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(work / "out" / "fog_cloud_puff.volume.comp"));
  const auto j = sceneJson(work / "out");
  EXPECT_EQ(j["max_bytes_per_pixel"], j["materials"][0]["bytes_per_pixel"]) << "the plaster's: the volume's froxel is not a pixel";
  EXPECT_EQ(j["materials"][1]["layout"], "VOLUME");
  for (const auto& k : j["lighting"])
    for (const auto& name : k["materials"]) EXPECT_NE(name, "fog_cloud_puff") << k.dump();

  std::ofstream(work / "only.json") << R"({"format": "substrate-scene/1", "name": "only", "materials": [")" + fog + R"("]})";
  CliResult only = cli({"scene", (work / "only.json").string(), "-o", (work / "out2").string()});
  EXPECT_EQ(only.status, 1);
  EXPECT_NE(only.err.find("every material of the scene is a volume"), std::string::npos) << only.err;
  EXPECT_FALSE(fs::exists(work / "out2"));
}

TEST(Scene, EveryMistakeIsLocatedAndNothingIsWritten) {
  const fs::path work = freshDir("bad");
  fs::create_directories(work);
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(work / name) << text;
    return (work / name).string();
  };
  const std::string plaster = (kSource / "examples" / "scenes" / "materials" / "plaster.json").string();
  const fs::path out = work / "out";
  struct Case {
    std::string manifest;
    std::vector<std::string> extra;
    int status;
    std::string message;
  };
  const std::string m1 = write("m1.json", R"({"format": "substrate-scene/1", "name": "s", "platform": "ps2",
    "materials": [")" + plaster + R"("]})");
  const std::string broken = write("broken.json", "{\n  \"format\": \"substrate-material/1\",\n  \"name\": 3\n}\n");
  const std::string m2 = write("m2.json", R"({"format": "substrate-scene/1", "name": "s", "materials": ["broken.json"]})");
  const std::string m3 = write("m3.json", R"({"format": "substrate-scene/1", "name": "s", "materials": [")" + plaster +
                                              R"(", "plaster_again.json"]})");
  std::ofstream(work / "plaster_again.json") << slurp(plaster);
  const std::string m4 = write("m4.json", "{\"format\": \"substrate-scene/1\",\n \"name\": \"s\", \"materials\": [}");
  const Case cases[] = {
      {m1, {}, 1, m1 + ":1:58: error: unknown platform \"ps2\" (known: mobile, console, pc-high) [/platform]"},
      {scene("simple_only.json"), {"--platform", "ps2"}, 2, "unknown platform \"ps2\""},
      {m2, {}, 1, (work / "broken.json").string() + ":3:11: error: expected a C identifier string, got 3 [/name]"},
      // The second entry's column follows the first's path (a checkout's absolute path).
      {m3, {}, 1, m3 + fmt::format(":1:{}: error: material \"plaster\"", 64 + plaster.size())},
      {m4, {}, 1, m4 + ":2:"},
      {scene("simple_only.json"), {"--platforms", m4}, 1, m4 + ":2:"},
      {(work / "missing.json").string(), {}, 1, "missing.json"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.manifest);
    std::vector<std::string> args = {"scene", c.manifest, "-o", out.string()};
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    CliResult r = cli(args);
    EXPECT_EQ(r.status, c.status) << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(fs::exists(out)) << "nothing written";
  }
}

TEST(Scene, EveryErrorOfOneRunIsReported) {
  // A duplicate listing, a missing material, a material with an error, an
  // unknown platform, and two materials whose names differ only in letter
  // case: one run reports all five (the manifest's errors used to stop it).
  const fs::path work = freshDir("all_errors");
  fs::create_directories(work);
  const std::string plaster = slurp(kSource / "examples" / "scenes" / "materials" / "plaster.json");
  std::ofstream(work / "a.json") << plaster;
  std::string upper = plaster;
  upper.replace(upper.find("\"name\": \"plaster\""), 17, "\"name\": \"PLASTER\"");
  std::ofstream(work / "b.json") << upper;
  std::ofstream(work / "bad.json") << slurp(kSource / "tests" / "bad" / "103_roughness_above_one.json");
  const fs::path manifest = work / "s.json";
  std::ofstream(manifest) << R"({"format": "substrate-scene/1", "name": "s", "platform": "ps2",
    "materials": ["a.json", "./a.json", "missing.json", "bad.json", "b.json"]})";
  const fs::path out = work / "out";
  CliResult r = cli({"scene", manifest.string(), "-o", out.string()});
  EXPECT_EQ(r.status, 1) << r.err;
  int found = 0;
  for (const std::string& want :
       {manifest.string() + ":2:29: error: \"./a.json\" is already listed at /materials/0 [/materials/1]",
        manifest.string() + ":1:58: error: unknown platform \"ps2\"", std::string("missing.json"),
        (work / "bad.json").string() + ":14:20: error: expected a float in [0,1], got 2 [/nodes/base/roughness]",
        manifest.string() + ":2:69: error: material \"PLASTER\" (" + (work / "b.json").string() +
            ") has the name of /materials/0 (" + (work / "a.json").string() + ") but for letter case"}) {
    EXPECT_NE(r.err.find(want), std::string::npos) << want << "\n" << r.err;
    found += r.err.find(want) != std::string::npos;
  }
  EXPECT_EQ(found, 5);
  EXPECT_FALSE(fs::exists(out)) << "nothing written";
}

}  // namespace scene_cli_test
