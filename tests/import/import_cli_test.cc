// `substratec import` and the importable files of report/compile (issue 10),
// in-process through runCli: what is written, exit statuses, and the
// --material choice among a file's materials.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"

namespace fs = std::filesystem;
using substratec::runCli;

namespace import_cli_test {

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

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

fs::path scratch(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("substratec_import_cli_" + std::to_string(::getpid())) / name;
  fs::remove_all(p);
  return p;
}

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

/// `import` writes each glTF material as what its author wrote, one gltf_pbr
/// building block (issue 23); `--expand` writes the slabs, operators and value
/// nodes that block stands for. Both report the same bytes and closures.
TEST(ImportCli, WritesAGltfPbrBlockOrWithExpandTheNodesItStandsFor) {
  const fs::path blocks = scratch("blocks"), flat = scratch("flat");
  const std::string source = (kCorpus / "gltf/ClearCoatTest.materials.json").string();
  CliRun r = cli({"import", source, "-o", blocks.string(), "--material", "Simple_Coated"});
  ASSERT_EQ(r.status, 0) << r.err;
  CliRun e = cli({"import", source, "-o", flat.string(), "--material", "Simple_Coated", "--expand"});
  ASSERT_EQ(e.status, 0) << e.err;
  const std::string asBlock = readText(blocks / "Simple_Coated.json"), expanded = readText(flat / "Simple_Coated.json");
  EXPECT_NE(asBlock.find("\"kind\": \"gltf_pbr\""), std::string::npos) << asBlock;
  EXPECT_NE(asBlock.find("\"clearcoat\": 1"), std::string::npos) << asBlock;
  EXPECT_EQ(expanded.find("gltf_pbr"), std::string::npos) << expanded;
  EXPECT_NE(expanded.find("\"kind\": \"vertical\""), std::string::npos) << expanded;
  CliRun a = cli({"report", (blocks / "Simple_Coated.json").string(), "--json"});
  CliRun b = cli({"report", (flat / "Simple_Coated.json").string(), "--json"});
  ASSERT_EQ(a.status, 0) << a.err;
  ASSERT_EQ(b.status, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(ja["after"], jb["after"]);
  EXPECT_EQ(ja["storage"], jb["storage"]);
  EXPECT_EQ(ja["building_blocks"][0]["kind"], "gltf_pbr");
  EXPECT_FALSE(jb.contains("building_blocks"));
}

/// A MaterialX Standard Surface is written as the standard_surface block, its
/// given inputs as pins under their MaterialX names; --expand writes its nodes.
TEST(ImportCli, WritesAStandardSurfaceAsItsBlock) {
  const fs::path blocks = scratch("mtlx_blocks"), flat = scratch("mtlx_flat");
  const std::string source = (kCorpus / "materialx/StandardSurface/standard_surface_carpaint.mtlx").string();
  CliRun r = cli({"import", source, "-o", blocks.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  CliRun e = cli({"import", source, "-o", flat.string(), "--expand"});
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_EQ(r.err, e.err) << "the same warnings either way";
  std::vector<fs::path> written;
  for (const auto& f : fs::directory_iterator(blocks)) written.push_back(f.path());
  ASSERT_EQ(written.size(), 1u);
  const auto block = nlohmann::json::parse(readText(written[0]));
  EXPECT_EQ(block["nodes"]["surface"]["kind"], "standard_surface") << block.dump(1);
  EXPECT_TRUE(block["nodes"]["surface"].contains("coat")) << "a car paint's coat, under its MaterialX name";
  EXPECT_EQ(readText(flat / written[0].filename()).find("standard_surface\""), std::string::npos);
}

/// An imported texture keeps its image as the input's `file` (issue 20), made
/// relative to where the material is written, so that the written material
/// finds the image the source document named.
TEST(ImportCli, ATexturesImageIsTheInputsFileRelativeToTheWrittenMaterial) {
  const fs::path src = scratch("textured_source"), out = scratch("textured_out") / "materials";
  fs::create_directories(src / "maps");
  std::ofstream(src / "scene.gltf") << R"({"asset": {"version": "2.0"},
    "images": [{"uri": "maps/bricks%20red.png"}, {"uri": "data:image/png;base64,iVBORw0KGgo="}],
    "samplers": [{"wrapS": 33071, "wrapT": 33648, "magFilter": 9728}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
    "materials": [{"name": "Wall", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
                   "metallicRoughnessTexture": {"index": 1}}}]})";
  std::ofstream(src / "maps/bricks red.png") << "not decoded by import";
  CliRun r = cli({"import", (src / "scene.gltf").string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(out / "Wall.json");
  const nlohmann::json wall = nlohmann::json::parse(in);
  EXPECT_EQ(wall["inputs"]["baseColorTexture"]["file"], "../../textured_source/maps/bricks red.png");
  EXPECT_EQ(wall["inputs"]["baseColorTexture"]["colorspace"], "srgb");
  EXPECT_EQ(wall["inputs"]["baseColorTexture"]["wrap"], nlohmann::json::array({"clamp", "mirror"})) << "its sampler";
  EXPECT_EQ(wall["inputs"]["baseColorTexture"]["filter"], "nearest");
  EXPECT_FALSE(wall["inputs"]["metallicRoughnessTexture"].contains("wrap")) << "no sampler: repeat";
  EXPECT_EQ(wall["inputs"]["metallicRoughnessTexture"]["file"], "scene_image1.png") << "an embedded image";
  EXPECT_TRUE(fs::exists(out / "scene_image1.png"));
  EXPECT_TRUE(fs::exists(out / wall["inputs"]["baseColorTexture"]["file"].get<std::string>()));
}

/// A .glb whose JSON is `json` and whose binary chunk is `bin`.
std::string glbOf(std::string json, std::string bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  auto le32 = [](std::uint32_t v) {
    std::string b(4, '\0');
    for (int i = 0; i < 4; ++i) b[i] = static_cast<char>(v >> (8 * i));
    return b;
  };
  const std::uint32_t total = static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size());
  return le32(0x46546C67) + le32(2) + le32(total) + le32(static_cast<std::uint32_t>(json.size())) + le32(0x4E4F534A) +
         json + le32(static_cast<std::uint32_t>(bin.size())) + le32(0x004E4942) + bin;
}

/// An image embedded in a .glb's binary chunk or in a data: URI is written
/// beside the imported material, as the file its input names.
TEST(ImportCli, AnEmbeddedImageIsWrittenBesideTheMaterialThatNamesIt) {
  const fs::path src = scratch("embedded_source"), out = scratch("embedded_out");
  fs::create_directories(src);
  const std::string image = "\x89PNG\r\n\x1a\n-the-bytes-of-an-image";
  std::ofstream(src / "crate.glb", std::ios::binary) << glbOf(
      R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": )" + std::to_string(image.size()) +
          R"(}], "bufferViews": [{"buffer": 0, "byteLength": )" + std::to_string(image.size()) +
          R"(}], "images": [{"bufferView": 0, "mimeType": "image/png"}, {"uri": "data:image/jpeg;base64,/9j/4AAQ"}],
          "textures": [{"source": 0}, {"source": 1}],
          "materials": [{"name": "Crate", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                         "emissiveTexture": {"index": 1}, "emissiveFactor": [1, 1, 1]}]})",
      image);
  CliRun r = cli({"import", (src / "crate.glb").string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(out / "Crate.json");
  const nlohmann::json crate = nlohmann::json::parse(in);
  EXPECT_EQ(crate["inputs"]["baseColorTexture"]["file"], "crate_image0.png");
  EXPECT_EQ(crate["inputs"]["emissiveTexture"]["file"], "crate_image1.jpg");
  std::ifstream png(out / "crate_image0.png", std::ios::binary), jpg(out / "crate_image1.jpg", std::ios::binary);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(png), {}), image);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(jpg), {}), std::string("\xFF\xD8\xFF\xE0\x00\x10", 6));
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
  CliRun missing = cli({"report", "no_such_file.gltf"});
  EXPECT_EQ(missing.status, 1);
  CliRun materialOnJson = cli({"report", "--material", "x", (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples/car_paint.json").string()});
  EXPECT_EQ(materialOnJson.status, 1);
  EXPECT_NE(materialOnJson.err.find("--material chooses among the materials of"), std::string::npos);
}

// SimpleHair (the MaterialX corpus' hair): its simple_hair shader is a nodedef
// whose graph ends in chiang_hair_bsdf, imported as the format's hair node
// (docs/import.md, "chiang_hair_bsdf").
TEST(ImportCli, SimpleHairImportsAsAHairNode) {
  const fs::path out = scratch("hair");
  CliRun r = cli({"import", (kCorpus / "materialx/SimpleHair/simple_hair_default.mtlx").string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("simple_hair_default.mtlx:44:6: warning: material \"simple_hair_default\": chiang_hair_bsdf "
                       "'chiang_bsdf' in nodegraph 'NG_simple_hair_shader': roughness_R and absorption_coefficient: "
                       "evaluated at import with the material inputs they read at their values (longitudinalRoughness, "
                       "azimuthalRoughness, melaninConcentration, melaninRedness, baseColor, melaninMix)"),
            std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("tint_"), std::string::npos) << r.err;         // the tints are white
  EXPECT_EQ(r.err.find("roughness_TT"), std::string::npos) << r.err;  // pbrt's ratios: scale_TT 0.5, scale_TRT 2
  std::ifstream in(out / "simple_hair_default.json");
  const nlohmann::json doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["output"], "hair");
  const nlohmann::json& hair = doc["nodes"]["hair"];
  EXPECT_EQ(hair["kind"], "hair");
  // roughness_R = chiang_hair_roughness(0.1, 0.1)'s (v, s) = ((0.726·0.1 + 0.812·0.01 + 3.7·0.1^20)^2,
  // 0.265·0.1 + 1.194·0.01 + 5.372·0.1^22) = (0.0065157184, 0.03844): inverted, the artist's 0.1 and 0.1.
  EXPECT_DOUBLE_EQ(hair["roughness"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(hair["azimuthal_roughness"].get<double>(), 0.1);
  // absorption_coefficient = mix(melanin, from_color(white) = 0, melaninMix 1) = deon_hair_absorption_from_melanin(0.5, 0.5):
  //   melanin = −ln(1 − 0.5) = 0.693147, eumelanin = pheomelanin = 0.346574;
  //   sigma = 0.346574 · ((0.419, 0.697, 1.37) + (0.187, 0.4, 1.05)) = (0.210024, 0.380191, 0.838708)
  //   (−ln of MaterialX's default pigment colours (0.657704, 0.498077, 0.254107) and (0.829444, 0.67032, 0.349938));
  //   P(0.1) = 5.969 − 0.0215 + 0.02532 − 0.01073 + 0.0005574 + 0.00000245 = 5.96264985;
  //   base_color = exp(−sqrt(sigma) · P(0.1)) = exp(−(0.458283, 0.616597, 0.915810) · 5.96265)
  //              = (0.0650511, 0.0253101, 0.00425078): dark brown.
  ASSERT_EQ(hair["base_color"].size(), 3u);
  EXPECT_NEAR(hair["base_color"][0].get<double>(), 0.0650511, 1e-6);
  EXPECT_NEAR(hair["base_color"][1].get<double>(), 0.0253101, 1e-6);
  EXPECT_NEAR(hair["base_color"][2].get<double>(), 0.00425078, 1e-7);
  // ior and cuticleAngle stay inputs: ior 1.55, and (0.5 − cuticleAngle) · 180 = 0 degrees at 0.5.
  EXPECT_EQ(hair["ior"], "$ior");
  EXPECT_EQ(doc["inputs"]["ior"]["default"], 1.55);
  EXPECT_EQ(doc["inputs"]["cuticleAngle"]["default"], 0.5);
  EXPECT_EQ(hair["cuticle_angle"], nlohmann::json::parse(R"({"kind": "multiply", "a": {"kind": "subtract", "a": 0.5,
                                                           "b": "$cuticleAngle"}, "b": 180.0})"));
  EXPECT_FALSE(hair.contains("tangent"));  // curve_direction unconnected: the geometric tangent
  // What was written is an ordinary material: report reads it back, one hair closure.
  CliRun back = cli({"report", (out / "simple_hair_default.json").string()});
  EXPECT_EQ(back.status, 0) << back.err;
  EXPECT_NE(back.out.find("Op=HAIR"), std::string::npos) << back.out;
}

// --- issue 16 ----------------------------------------------------------------

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(ImportCli, ReplacesOnlyWhatAnImportOfTheSameSourceWrote) {
  const fs::path out = scratch("replace");
  const std::string file = (kCorpus / "gltf/CompareVolume.materials.json").string();
  ASSERT_EQ(cli({"import", file, "-o", out.string()}).status, 0);
  const std::string gold = slurp(out / "gold.json");
  EXPECT_EQ(cli({"import", file, "-o", out.string()}).status, 0);  // the same text again
  // A stale import of the same source (its marker) is replaced.
  spit(out / "gold.json", "{\n  \"format\": \"substrate-material/1\",\n  \"name\": \"gold\",\n  \"description\": "
                          "\"Imported from CompareVolume.materials.json materials[2] (an older import).\",\n  \"nodes\": {}\n}\n");
  EXPECT_EQ(cli({"import", file, "-o", out.string()}).status, 0);
  EXPECT_EQ(slurp(out / "gold.json"), gold);
  // A file the user wrote, an import of another source, a non-JSON file, a
  // directory: refused, exit 2, nothing written (checker.json stays deleted).
  const std::vector<std::string> foreign = {
      "{\"format\": \"substrate-material/1\", \"name\": \"gold\", \"description\": \"my own gold\", \"nodes\": {}}\n",
      "{\"format\": \"substrate-material/1\", \"name\": \"gold\", \"description\": \"Imported from Other.gltf "
      "materials[0].\", \"nodes\": {}}\n",
      "{\"format\": \"substrate-material/1\", \"name\": \"gold\", \"description\": \"Imported from "
      "CompareVolume.materials.jsonx materials[0].\", \"nodes\": {}}\n",
      "not json at all", ""};
  int refused = 0;
  for (const std::string& text : foreign) {
    spit(out / "gold.json", text);
    fs::remove(out / "checker.json");
    CliRun r = cli({"import", file, "-o", out.string()});
    EXPECT_EQ(r.status, 2) << text;
    EXPECT_NE(r.err.find((out / "gold.json").string() + " exists and was not written by importing "
                         "CompareVolume.materials.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--force replaces it"), std::string::npos);
    EXPECT_EQ(slurp(out / "gold.json"), text);
    EXPECT_FALSE(fs::exists(out / "checker.json"));  // nothing written
    refused += r.status == 2;
  }
  EXPECT_EQ(refused, 5);
  fs::remove(out / "gold.json");
  fs::create_directory(out / "gold.json");
  EXPECT_EQ(cli({"import", file, "-o", out.string()}).status, 2);
  fs::remove(out / "gold.json");
  spit(out / "gold.json", foreign[0]);
  CliRun forced = cli({"import", file, "-o", out.string(), "--force"});
  EXPECT_EQ(forced.status, 0) << forced.err;
  EXPECT_EQ(slurp(out / "gold.json"), gold);
  EXPECT_TRUE(fs::exists(out / "checker.json"));
}

TEST(ImportCli, ReadsSeveralFilesAndDirectoriesInPathOrder) {
  const fs::path tree = scratch("tree");
  const fs::path volume = kCorpus / "gltf/CompareVolume.materials.json";
  spit(tree / "b/volume.materials.json", slurp(volume));
  spit(tree / "a/deeper/brass.mtlx", slurp(kCorpus / "materialx/StandardSurface/standard_surface_brass_tiled.mtlx"));
  spit(tree / "a/notes.txt", "not a material");
  spit(tree / "a/plain.json", slurp(fs::path(SUBSTRATEC_SOURCE_DIR) / "examples/car_paint.json"));  // not importable
  fs::path deep = tree / "c";
  for (int i = 0; i < 20; ++i) deep /= "d";  // past the depth bound (16 levels)
  spit(deep / "deep.materials.json", slurp(volume));
  const fs::path out = scratch("tree_out");
  CliRun r = cli({"import", tree.string(), volume.string(), "-o", out.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("deeper than 16 levels below"), std::string::npos) << r.err;
  // a/deeper/brass.mtlx, then b/volume.materials.json, then the file given:
  // its four materials again, renamed.
  EXPECT_EQ(listing(out), (std::vector<std::string>{"Tiled_Brass.json", "checker.json", "checker_2.json",
                                                    "glTF_Transmission.json", "glTF_Transmission_2.json",
                                                    "glTF_Volume.json", "glTF_Volume_2.json", "gold.json",
                                                    "gold_2.json"}))
      << r.out << r.err;
  EXPECT_NE(r.err.find("warning: material \"gold\" is written as gold_2.json: an earlier file has a material named gold"),
            std::string::npos) << r.err;
  EXPECT_NE(slurp(out / "gold_2.json").find("\"name\": \"gold_2\""), std::string::npos);
  // The same file twice is read once.
  const fs::path once = scratch("once");
  EXPECT_EQ(cli({"import", volume.string(), volume.string(), "-o", once.string()}).status, 0);
  EXPECT_EQ(listing(once).size(), 4u);
  // A directory with nothing importable is an error, and nothing is written.
  const fs::path empty = scratch("empty_dir");
  spit(empty / "x.txt", "");
  CliRun none = cli({"import", empty.string(), volume.string(), "-o", scratch("none_out").string()});
  EXPECT_EQ(none.status, 1);
  EXPECT_NE(none.err.find(empty.string() + ": is a directory holding no .gltf, .glb, .materials.json or .mtlx file"),
            std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(scratch("none_out")));
}

TEST(ImportCli, ADirectoryWhereAFileIsExpectedSaysSo) {
  const fs::path dir = scratch("a_directory");
  fs::create_directories(dir);
  const std::vector<std::vector<std::string>> commands = {
      {"report", dir.string()},
      {"compile", dir.string(), "-o", scratch("d1").string()},
      {"preview", dir.string(), "-o", scratch("d2.png").string()},
      {"sweep", dir.string()},
      {"stability", dir.string(), "--no-gpu"},
      {"scene", dir.string(), "-o", scratch("d3").string()},
      {"compile", (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples/car_paint.json").string(), "--platforms", dir.string(),
       "-o", scratch("d4").string()}};
  int checked = 0;
  for (const auto& args : commands) {
    CliRun r = cli(args);
    EXPECT_EQ(r.status, 1) << args[0] << "\n" << r.err;
    EXPECT_NE(r.err.find("is a directory"), std::string::npos) << args[0] << "\n" << r.err;
    ++checked;
  }
  EXPECT_EQ(checked, 7);
}

TEST(ImportCli, AMaterialNameTwoMaterialsAnswerToIsAnErrorListingBoth) {
  const fs::path file = scratch("twice") / "twice.gltf";
  spit(file, R"({"asset": {"version": "2.0"}, "materials": [{"name": "Gold"}, {"name": "Silver"}, {"name": "Gold"}]})");
  for (const char* command : {"import", "compile"}) {
    CliRun r = cli({command, file.string(), "--material", "Gold", "-o", scratch("twice_out").string()});
    EXPECT_EQ(r.status, 1) << command;
    EXPECT_NE(r.err.find("2 materials are called \"Gold\"; choose one by its identifier:\n  Gold at /materials/0\n"
                         "  Gold_2 (\"Gold\") at /materials/2"),
              std::string::npos) << command << "\n" << r.err;
    EXPECT_FALSE(fs::exists(scratch("twice_out")));
  }
  const fs::path out = scratch("twice_out");
  CliRun ok = cli({"import", file.string(), "--material", "Gold_2", "-o", out.string()});
  EXPECT_EQ(ok.status, 0) << ok.err;
  EXPECT_EQ(listing(out), std::vector<std::string>{"Gold_2.json"});
}

}  // namespace import_cli_test
