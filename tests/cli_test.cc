// The substratec command line: exit codes, output forms, and hostile inputs
// (run through the real binary, each in its own process).
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"

namespace fs = std::filesystem;
using substratec::runCli;

namespace {

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

struct CliRun {
  int status;
  std::string out, err;
};

CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  int status = runCli(args, out, err);
  return {status, out.str(), err.str()};
}

/// Runs the built binary in a child process (stdout captured, stderr to a file).
CliRun binary(const std::string& args) {
  fs::create_directories(SUBSTRATEC_WORK_DIR);
  std::string errFile = std::string(SUBSTRATEC_WORK_DIR) + "/stderr.txt";
  std::string cmd = std::string(SUBSTRATEC_BINARY) + " " + args + " 2>" + errFile;
  CliRun r{-1, "", ""};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  std::ifstream e(errFile);
  std::ostringstream s;
  s << e.rdbuf();
  r.err = s.str();
  return r;
}

std::string example(const char* name) { return (kSource / "examples" / name).string(); }

}  // namespace

TEST(Cli, ReportOfAnExampleExitsZero) {
  CliRun r = cli({"report", example("row12_simple.json")});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("Requested bytes before simplification: 12"), std::string::npos);
  EXPECT_EQ(r.err, "");
}

TEST(Cli, ReportTakesSeveralFiles) {
  CliRun r = cli({"report", example("row12_simple.json"), example("row16_single_sss_wrap.json")});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("SUBSTRATE - row12_simple"), std::string::npos);
  EXPECT_NE(r.out.find("SUBSTRATE - row16_single_sss_wrap"), std::string::npos);
}

TEST(Cli, JsonReportHasTheDocumentedKeys) {
  CliRun r = cli({"report", "--json", example("worked_example_72.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  for (const char* k : {"name", "budget", "before", "after", "layout", "features", "tree", "steps", "culled"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["name"], "worked_example_72");
  EXPECT_EQ(j["before"]["bytes"], 72);
  EXPECT_EQ(j["before"]["closures"], 3);
  EXPECT_EQ(j["budget"]["bytes_per_pixel"], 80);
}

TEST(Cli, BudgetFlagsOverrideSettings) {
  CliRun r = cli({"report", "--json", "--budget", "48", "--max-closures", "2", example("row12_simple.json")});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["budget"]["bytes_per_pixel"], 48);
  EXPECT_EQ(j["budget"]["max_closures"], 2);
}

TEST(Cli, BadUsageExitsTwo) {
  EXPECT_EQ(cli({}).status, 2);
  EXPECT_EQ(cli({"frobnicate"}).status, 2);
  EXPECT_EQ(cli({"report"}).status, 2);
  EXPECT_EQ(cli({"report", "--budget", "0", example("row12_simple.json")}).status, 2);
  EXPECT_EQ(cli({"report", "--no-such-flag", example("row12_simple.json")}).status, 2);
}

TEST(Cli, HelpAndVersionExitZero) {
  EXPECT_EQ(cli({"--help"}).status, 0);
  CliRun v = cli({"--version"});
  EXPECT_EQ(v.status, 0);
  EXPECT_NE(v.out.find("substratec"), std::string::npos);
}

TEST(Cli, MissingFileIsBadInput) {
  CliRun r = cli({"report", "no/such/file.json"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("no/such/file.json"), std::string::npos);
  EXPECT_NE(r.err.find("cannot open file"), std::string::npos);
}

TEST(Cli, BadInputExitsOneAndPrintsNothingOnStdout) {
  CliRun r = cli({"report", (kSource / "tests/bad/146_five_independent_errors.json").string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out, "");
  EXPECT_GE(std::count(r.err.begin(), r.err.end(), '\n'), 5);
}

TEST(Cli, InputSizeLimitIsAFlag) {
  CliRun r = cli({"report", "--max-input-size", "100", example("row12_simple.json")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("larger than the limit of 100 bytes"), std::string::npos);
}

// Hostile inputs, generated at test time (tests/bad/generate_hostile.py),
// through the real binary: each must end with a located error, never a
// crash or a hang (ctest's timeout bounds the run).
TEST(Cli, HostileInputsAreRejectedCleanly) {
  fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "hostile";
  fs::create_directories(dir);
  std::string gen = "python3 " + (kSource / "tests/bad/generate_hostile.py").string() + " " + dir.string();
  ASSERT_EQ(std::system(gen.c_str()), 0);
  const char* files[] = {"deep_array.json",       "deep_object.json", "deep_inline_nodes.json",
                         "many_nodes.json",       "huge_string.json", "big_file.json",
                         "long_identifier.json",  "wide_fanout.json"};
  for (const char* f : files) {
    SCOPED_TRACE(f);
    CliRun r = binary("report " + (dir / f).string());
    EXPECT_EQ(r.status, 1) << r.err.substr(0, 400);
    EXPECT_NE(r.err.find(": error: "), std::string::npos) << r.err.substr(0, 400);
    EXPECT_LT(r.err.size(), 20000u) << "diagnostics must stay bounded";
  }
}

// --- compile ---------------------------------------------------------------

namespace {
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    files[e.path().filename().string()] = s.str();
  }
  return files;
}
}  // namespace

TEST(Cli, CompileWritesEveryOutputAndValidatesIt) {
  fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "compile_all";
  fs::remove_all(dir);
  CliRun r = cli({"compile", example("worked_example_72.json"), "-o", dir.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"worked_example_72.material.glsl", "worked_example_72.material.hlsl",
                        "worked_example_72.basepass.frag", "worked_example_72.forward.frag",
                        "worked_example_72.basepass.ps.hlsl", "worked_example_72.forward.ps.hlsl",
                        "worked_example_72.layout.json"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  auto layout = nlohmann::json::parse(std::ifstream(dir / "worked_example_72.layout.json"));
  EXPECT_EQ(layout["bytes_per_pixel"], 72);
  EXPECT_EQ(layout["words"], 17);
}

TEST(Cli, CompileOfABrokenMaterialLeavesTheOutputFolderAsItWas) {
  fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "compile_atomic";
  fs::remove_all(dir);
  ASSERT_EQ(cli({"compile", example("row12_simple.json"), "-o", dir.string()}).status, 0);
  auto before = snapshot(dir);
  // The same name, broken.
  fs::path broken = fs::path(SUBSTRATEC_WORK_DIR) / "row12_simple.json";
  std::ifstream in(example("row12_simple.json"));
  std::ostringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  s.replace(s.find("\"$roughness\""), 12, "\"$no_such_input\"");
  std::ofstream(broken) << s;
  CliRun r = cli({"compile", broken.string(), "-o", dir.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(snapshot(dir), before);
}

TEST(Cli, CompileTargetSelectsTheLanguage) {
  fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "compile_glsl";
  fs::remove_all(dir);
  ASSERT_EQ(cli({"compile", "--target", "glsl", example("row16_single_sss_wrap.json"), "-o", dir.string()}).status, 0);
  EXPECT_TRUE(fs::exists(dir / "row16_single_sss_wrap.forward.frag"));
  EXPECT_FALSE(fs::exists(dir / "row16_single_sss_wrap.forward.ps.hlsl"));
}

// Every example, every entry shader, both languages, every diffuse model:
// glslang compiles, links and spirv-val accepts (in-process, as compile does).
TEST(Cli, EveryExampleCompilesInBothLanguages) {
  for (const auto& e : fs::directory_iterator(kSource / "examples")) {
    if (e.path().extension() != ".json") continue;
    SCOPED_TRACE(e.path().filename().string());
    fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "compile_every" / e.path().stem();
    CliRun r = cli({"compile", e.path().string(), "-o", dir.string()});
    EXPECT_EQ(r.status, 0) << r.err.substr(0, 4000);
  }
}
