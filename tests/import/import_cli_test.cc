// `substratec import` and the importable files of report/compile (issue 10),
// in-process through runCli: what is written, exit statuses, and the
// --material choice among a file's materials.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/cli.h"

namespace fs = std::filesystem;
using substratec::runCli;

namespace {

const fs::path kCorpus = fs::path(SUBSTRATEC_SOURCE_DIR) / "tests/import/corpus";

struct CliRun {
  int status;
  std::string out, err;
};

CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  const int status = runCli(args, out, err);
  return {status, out.str(), err.str()};
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("substratec_import_cli_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

}  // namespace

TEST(ImportCli, WritesOneFilePerMaterialThatCompiles) {
  const fs::path out = scratch("compare_volume");
  CliRun r = cli({"import", (kCorpus / "gltf/CompareVolume.materials.json").string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: material \"glTF Volume\": KHR_materials_transmission"), std::string::npos) << r.err;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"checker.json", "glTF_Transmission.json", "glTF_Volume.json", "gold.json"}));
  // What was written is an ordinary material: report reads it back.
  CliRun back = cli({"report", (out / "gold.json").string()});
  EXPECT_EQ(back.status, 0) << back.err;
}

TEST(ImportCli, MaterialChoosesOneAndAnUnknownNameListsThem) {
  const fs::path out = scratch("one");
  const std::string file = (kCorpus / "gltf/CompareVolume.materials.json").string();
  CliRun r = cli({"import", file, "-o", out.string(), "--material", "glTF Volume"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "glTF_Volume.json"));
  EXPECT_FALSE(fs::exists(out / "gold.json"));
  CliRun bad = cli({"import", file, "-o", scratch("none").string(), "--material", "silver"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find("no material named \"silver\"; the file holds:\n  checker\n  glTF_Transmission (\"glTF Transmission\")"),
            std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(scratch("none")));  // nothing half-written
}

TEST(ImportCli, CompileTakesEveryMaterialOfAFileThatHoldsSeveral) {
  const std::string file = (kCorpus / "gltf/CompareVolume.materials.json").string();
  const fs::path all = scratch("c");
  CliRun r = cli({"compile", file, "-o", all.string(), "--target", "glsl"});
  EXPECT_EQ(r.status, 0) << r.err;  // issue 16: like `report`, every material (it was an error)
  for (const char* name : {"checker", "glTF_Transmission", "gold", "glTF_Volume"})
    EXPECT_TRUE(fs::exists(all / (std::string(name) + ".material.glsl"))) << name << "\n" << r.out;
  const fs::path out = scratch("gold");
  CliRun ok = cli({"compile", file, "--material", "gold", "-o", out.string(), "--target", "glsl"});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_TRUE(fs::exists(out / "gold.material.glsl")) << ok.out;
}

TEST(ImportCli, ReportReadsEveryMaterialOfAnImportableFile) {
  CliRun r = cli({"report", (kCorpus / "materialx/StandardSurface/standard_surface_look_brass_tiled.mtlx").string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("----- SUBSTRATE - Tiled_Brass -----"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("----- SUBSTRATE - Greysphere_Calibration -----"), std::string::npos);
}

TEST(ImportCli, BadImportsExitOne) {
  CliRun plain = cli({"import", (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples/car_paint.json").string(), "-o",
                      scratch("x").string()});
  EXPECT_EQ(plain.status, 1);
  EXPECT_NE(plain.err.find("import reads .gltf, .glb, .materials.json and .mtlx files"), std::string::npos);
  CliRun hair = cli({"import", (kCorpus / "materialx/SimpleHair/simple_hair_default.mtlx").string(), "-o",
                     scratch("y").string()});
  EXPECT_EQ(hair.status, 1);
  EXPECT_NE(hair.err.find("simple_hair_default.mtlx:44:6: error: chiang_hair_bsdf 'chiang_bsdf' in nodegraph "
                          "'NG_simple_hair_shader': unsupported node 'chiang_hair_bsdf'"),
            std::string::npos) << hair.err;
  CliRun missing = cli({"report", "no_such_file.gltf"});
  EXPECT_EQ(missing.status, 1);
  CliRun materialOnJson = cli({"report", "--material", "x", (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples/car_paint.json").string()});
  EXPECT_EQ(materialOnJson.status, 1);
  EXPECT_NE(materialOnJson.err.find("--material chooses among the materials of"), std::string::npos);
}
