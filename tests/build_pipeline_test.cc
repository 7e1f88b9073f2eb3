// substratec in a build pipeline (docs/scenes.md, "Build pipelines"): several
// files compiled at once give the same bytes whatever -j is; --depfile writes
// what glslc -MD would; --cache takes an unchanged material from the cache
// (proved by an entry edited consistently, whose edit then reaches the
// output), ignores an entry that does not read back whole, and misses when
// the input, an option or the compiler differs.
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "batch/cache.h"
#include "cli/cli.h"
#include "cli_util.h"

namespace fs = std::filesystem;
using substratec::runCli;
using substratec::clitest::cli;
using substratec::clitest::CliResult;
using substratec::clitest::filesOf;
using substratec::clitest::slurp;

namespace build_pipeline_test {

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

void spit(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

fs::path freshDir(const std::string& name) {
  fs::path d = substratec::clitest::freshDir("pipeline", name);
  fs::create_directories(d);
  return d;
}

std::vector<fs::path> cacheEntries(const fs::path& cache) {
  std::vector<fs::path> entries;
  if (!fs::exists(cache)) return entries;
  for (const auto& e : fs::recursive_directory_iterator(cache))
    if (e.path().extension() == ".entry") entries.push_back(e.path());
  std::sort(entries.begin(), entries.end());
  return entries;
}

std::string example(const char* stem) { return (kSource / "examples" / (std::string(stem) + ".json")).string(); }

TEST(BuildPipeline, SeveralFilesCompileToTheSameBytesWhateverJobsAndAsOneByOne) {
  const fs::path dir = freshDir("jobs");
  const std::vector<std::string> files = {example("row12_simple"), example("worked_example_72"),
                                          example("row60_glint"), example("skin_coated")};
  std::vector<std::string> args = {"compile", "--target", "glsl"};
  args.insert(args.end(), files.begin(), files.end());
  for (const char* j : {"1", "2"}) {
    std::vector<std::string> a = args;
    a.insert(a.end(), {"-o", (dir / j).string(), "-j", j});
    CliResult r = cli(a);
    ASSERT_EQ(r.status, 0) << r.err;
  }
  for (const std::string& f : files)
    ASSERT_EQ(cli({"compile", f, "-o", (dir / "one").string(), "--target", "glsl"}).status, 0);
  const auto one = filesOf(dir / "1");
  EXPECT_EQ(one.size(), 4u * 4);
  EXPECT_TRUE(one == filesOf(dir / "2"));
  EXPECT_TRUE(one == filesOf(dir / "one"));
  // A name twice: nothing is written.
  CliResult twice = cli({"compile", files[0], files[0], "-o", (dir / "twice").string()});
  EXPECT_EQ(twice.status, 1);
  EXPECT_NE(twice.err.find("/name: error: material \"row12_simple\" has the name of"), std::string::npos) << twice.err;
  EXPECT_FALSE(fs::exists(dir / "twice"));
  // One broken file among good ones: the others' errors are not hidden, and nothing is written.
  spit(dir / "broken.json", "{\"format\": \"substrate-material/1\",\n \"name\": \"x\", \"nodes\": {}, }");
  CliResult bad = cli({"compile", files[0], (dir / "broken.json").string(), "-o", (dir / "bad").string(), "-j", "2"});
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.err.find((dir / "broken.json").string() + ":2:"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

TEST(BuildPipeline, TheDepfileNamesEveryOutputAndEveryInputInMakeSyntax) {
  const fs::path dir = freshDir("depfile");
  fs::create_directories(dir / "with space");
  spit(dir / "with space" / "m$1.json", slurp(example("row12_simple")));
  const std::string input = (dir / "with space" / "m$1.json").string();
  const std::string platforms = (kSource / "examples" / "platforms" / "studio.json").string();
  CliResult r = cli({"compile", input, "-o", (dir / "out").string(), "--target", "glsl", "--depfile",
                     (dir / "out.d").string(), "--platform", "handheld", "--platforms", platforms});
  ASSERT_EQ(r.status, 0) << r.err;
  auto escaped = [](std::string p) {
    std::string s;
    for (char c : p) s += c == ' ' ? std::string("\\ ") : c == '$' ? std::string("$$") : std::string(1, c);
    return s;
  };
  std::string want;
  const char* outs[] = {"row12_simple.material.glsl", "row12_simple.basepass.frag", "row12_simple.forward.frag",
                        "row12_simple.layout.json"};
  for (const char* o : outs) want += (want.empty() ? "" : " \\\n  ") + escaped((dir / "out" / o).string());
  want += ": \\\n  " + escaped(input) + " \\\n  " + escaped(platforms) + "\n";
  EXPECT_EQ(slurp(dir / "out.d"), want);
  // Every output the command listed on stdout is a target, in that order.
  std::string listed;
  for (const char* o : outs) listed += (dir / "out" / o).string() + "\n";
  EXPECT_EQ(r.out, listed);
  // A scene: the manifest, the platforms file and every material.
  r = cli({"scene", (kSource / "examples" / "scenes" / "simple_only.json").string(), "-o", (dir / "scene").string(),
           "--target", "glsl", "--depfile", (dir / "scene.d").string(), "--platforms", platforms});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string d = slurp(dir / "scene.d");
  const std::string deps = d.substr(d.find(':'));
  for (const char* in : {"examples/scenes/simple_only.json", "examples/platforms/studio.json",
                         "examples/scenes/materials/plaster.json", "examples/scenes/materials/painted_metal.json",
                         "examples/row12_simple.json"})
    EXPECT_NE(deps.find(in), std::string::npos) << in << "\n" << d;
  EXPECT_EQ(d.substr(0, d.find(':')), (dir / "scene" / "scene.json").string())
      << "scene.json is the one target (the lighting files depend on the materials)";
  EXPECT_EQ(d.rfind(".."), std::string::npos) << "material paths normalized";
}

/// The entry's JSON body, and a function that writes a body back with a checksum that matches.
nlohmann::ordered_json readEntry(const fs::path& p) {
  const std::string text = slurp(p);
  return nlohmann::ordered_json::parse(text.substr(text.find('\n') + 1));
}
void writeEntry(const fs::path& p, const nlohmann::ordered_json& body) {
  const std::string b = body.dump();
  spit(p, "substratec-cache/1 " + substratec::hash128(b) + "\n" + b);
}

TEST(BuildPipeline, AnUnchangedMaterialComesFromTheCacheAndIsNotRecompiled) {
  const fs::path dir = freshDir("cache");
  const fs::path cache = dir / "cache";
  spit(dir / "m.json", slurp(example("worked_example_72")));
  const std::vector<std::string> base = {"compile", (dir / "m.json").string(), "--cache", cache.string(), "--target",
                                         "glsl", "-o"};
  auto compile = [&](const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> a = base;
    a.push_back((dir / out).string());
    a.insert(a.end(), extra.begin(), extra.end());
    return cli(a);
  };
  ASSERT_EQ(compile("cold").status, 0);
  const auto entries = cacheEntries(cache);
  ASSERT_EQ(entries.size(), 1u);
  const std::string pristine = slurp(entries[0]);
  ASSERT_EQ(compile("warm").status, 0);
  EXPECT_TRUE(filesOf(dir / "cold") == filesOf(dir / "warm"));
  EXPECT_EQ(slurp(entries[0]), pristine) << "a hit does not rewrite the entry";

  // Proof that the second compile did not recompile: an entry edited
  // consistently (its checksum recomputed) is what the output gets.
  auto body = readEntry(entries[0]);
  ASSERT_EQ(body["files"][0]["name"], "worked_example_72.material.glsl");
  body["files"][0]["contents"] = body["files"][0]["contents"].get<std::string>() + "// taken from the cache\n";
  writeEntry(entries[0], body);
  ASSERT_EQ(compile("edited").status, 0);
  EXPECT_EQ(slurp(dir / "edited" / "worked_example_72.material.glsl"),
            slurp(dir / "cold" / "worked_example_72.material.glsl") + "// taken from the cache\n");

  // An entry that does not read back whole is ignored, recompiled and rewritten.
  const std::string edited = slurp(entries[0]);
  const std::vector<std::pair<const char*, std::string>> corrupt = {
      {"truncated", edited.substr(0, edited.size() / 2)},
      {"one byte flipped", [&] { std::string s = edited; s[s.size() - 40] ^= 1; return s; }()},
      {"empty", ""},
      {"another format", "substratec-cache/0" + edited.substr(18)},
      {"valid checksum, not JSON", "substratec-cache/1 " + substratec::hash128("{oops") + "\n{oops"},
  };
  for (const auto& [what, text] : corrupt) {
    SCOPED_TRACE(what);
    spit(entries[0], text);
    CliResult r = compile(std::string("corrupt_") + std::to_string(text.size()));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.err, "");
    EXPECT_TRUE(filesOf(dir / (std::string("corrupt_") + std::to_string(text.size()))) == filesOf(dir / "cold"));
    EXPECT_EQ(slurp(entries[0]), pristine) << "rewritten";
  }
  // Another key in this entry's place (a collision): ignored.
  body = readEntry(entries[0]);
  body["key"] = body["key"].get<std::string>() + "x";
  body["files"][0]["contents"] = "collision";
  writeEntry(entries[0], body);
  ASSERT_EQ(compile("collision").status, 0);
  EXPECT_TRUE(filesOf(dir / "collision") == filesOf(dir / "cold"));

  // A changed option or input misses: a new entry, and the output follows.
  ASSERT_EQ(compile("budget", {"--budget", "48"}).status, 0);
  EXPECT_EQ(cacheEntries(cache).size(), 2u);
  EXPECT_NE(filesOf(dir / "budget"), filesOf(dir / "cold"));
  const std::string text = slurp(dir / "m.json") + "\n";  // other bytes, the same material
  spit(dir / "m.json", text);
  ASSERT_EQ(compile("edited_input").status, 0);
  EXPECT_EQ(cacheEntries(cache).size(), 3u);
  EXPECT_TRUE(filesOf(dir / "edited_input") == filesOf(dir / "cold"));
  // The compiler is part of the key: this executable's build id.
  const std::string& id = substratec::compilerIdentity();
  EXPECT_NE(id.find(" build "), std::string::npos) << id;
  EXPECT_GE(id.size() - id.find(" build ") - 7, 32u) << id;
  substratec::BatchOptions o;
  EXPECT_NE(substratec::cacheKeyText("m.json", text, o).find(id), std::string::npos);
}

TEST(BuildPipeline, ASceneTakesItsMaterialsFromTheCache) {
  const fs::path dir = freshDir("scene_cache");
  const std::string manifest = (kSource / "examples" / "scenes" / "street.json").string();
  for (const char* out : {"cold", "warm"}) {
    CliResult r = cli({"scene", manifest, "-o", (dir / out).string(), "--cache", (dir / "cache").string(), "--target",
                       "glsl"});
    ASSERT_EQ(r.status, 0) << r.err;
  }
  EXPECT_EQ(cacheEntries(dir / "cache").size(), 4u);
  EXPECT_TRUE(filesOf(dir / "cold") == filesOf(dir / "warm"));
}

}  // namespace build_pipeline_test
