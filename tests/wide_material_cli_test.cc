// Issue 16, severe 6: the widest material the limits allow costs memory
// linear in its tree. 512 slabs mixed in pairs (1023 tree nodes; the limit is
// 1024), every mix weight and every slab's albedo an input (1023 inputs; the
// limit is 1024), as bench/gen_wide_mix.py writes it. `report --spirv` runs
// SPIRV-Tools' performance passes on every entry shader: 3.3 GB and 142 s
// before (a block per inlined division, and the redundancy elimination's
// value tables copied along the dominator tree), a few hundred MB after.
#include <sys/resource.h>
#include <sys/wait.h>
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

// A named namespace: cli_tests is a unity build.
namespace substratec::widematerialtest {

namespace fs = std::filesystem;

/// bench/gen_wide_mix.py's material (the same shape; values from a simple LCG).
std::string wideMix(int slabs) {
  nlohmann::ordered_json inputs = nlohmann::ordered_json::object(), nodes = nlohmann::ordered_json::object();
  std::uint32_t seed = 16;
  auto next = [&] {
    seed = seed * 1664525u + 1013904223u;
    return (seed >> 8) / 16777216.0;
  };
  std::vector<std::string> level;
  for (int i = 0; i < slabs; ++i) {
    const std::string albedo = fmt::format("albedo{}", i);
    inputs[albedo] = {{"type", "color"},
                      {"default", {0.05 + 0.9 * next(), 0.05 + 0.9 * next(), 0.05 + 0.9 * next()}},
                      {"min", 0},
                      {"max", 1}};
    nodes[fmt::format("s{}", i)] = {{"kind", "slab"},
                                    {"diffuse_albedo", "$" + albedo},
                                    {"f0", 0.02 + 0.06 * next()},
                                    {"roughness", 0.1 + 0.8 * next()}};
    level.push_back(fmt::format("s{}", i));
  }
  for (int depth = 0; level.size() > 1; ++depth) {
    std::vector<std::string> up;
    for (std::size_t j = 0; j < level.size(); j += 2) {
      const std::string key = fmt::format("m{}_{}", depth, j / 2), weight = "w_" + key;
      inputs[weight] = {{"type", "float"}, {"default", 0.2 + 0.6 * next()}, {"min", 0}, {"max", 1}};
      nodes[key] = {{"kind", "horizontal"}, {"background", level[j]}, {"foreground", level[j + 1]}, {"mix", "$" + weight}};
      up.push_back(key);
    }
    level = up;
  }
  nlohmann::ordered_json doc = {{"format", "substrate-material/1"}, {"name", fmt::format("wide_mix_{}", slabs)},
                                {"inputs", inputs},                 {"nodes", nodes},
                                {"output", level.front()}};
  return doc.dump(1);
}

struct Measured {
  int status = -1;
  long maxRssKb = 0;
  std::string out;
};

/// SUBSTRATEC_BINARY with `args` in a child process: exit status, peak RSS (wait4), stdout.
Measured measure(const std::vector<std::string>& args) {
  const fs::path dir = fs::path(SUBSTRATEC_WORK_DIR) / "wide";
  fs::create_directories(dir);
  const fs::path outFile = dir / ("out." + std::to_string(::getpid()));
  std::vector<std::string> argv{SUBSTRATEC_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> cargv;
  for (auto& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  Measured m;
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int out = ::open(outFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_WRONLY);
    if (out < 0 || null < 0) ::_exit(126);
    ::dup2(out, 1);
    ::dup2(null, 2);
    ::execv(cargv[0], cargv.data());
    ::_exit(127);
  }
  int st = 0;
  struct rusage ru {};
  if (pid > 0 && ::wait4(pid, &st, 0, &ru) == pid) {
    m.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    m.maxRssKb = ru.ru_maxrss;
  }
  std::ifstream in(outFile);
  m.out.assign(std::istreambuf_iterator<char>(in), {});
  fs::remove(outFile);
  return m;
}

// GCC defines __SANITIZE_ADDRESS__; clang (the asan preset's clang 14) answers
// __has_feature(address_sanitizer) instead.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SUBSTRATEC_TEST_UNDER_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(SUBSTRATEC_TEST_UNDER_ASAN)
constexpr long kRssLimitMb = 3000;  // ASan's shadow memory and quarantine (1,197 MB measured)
#else
constexpr long kRssLimitMb = 1000;
#endif

TEST(WideMaterial, ReportSpirvOfTheWidestMaterialStaysUnderAGigabyte) {
  const fs::path file = fs::path(SUBSTRATEC_WORK_DIR) / "wide" / "wide_mix_512.json";
  fs::create_directories(file.parent_path());
  std::ofstream(file) << wideMix(512);
  const Measured m = measure({"report", "--spirv", "--json", file.string()});
  ASSERT_EQ(m.status, 0);
  const auto j = nlohmann::json::parse(m.out);
  EXPECT_EQ(j["spirv"].size(), 4u) << "two GLSL and two HLSL entries, each counted after the performance passes";
  for (const auto& e : j["spirv"]) EXPECT_GT(e["optimized_instructions"].get<long>(), 0) << e.dump();
  EXPECT_LT(m.maxRssKb / 1024, kRssLimitMb) << "peak RSS of report --spirv (3.3 GB before issue 16)";
  std::printf("[ wide     ] report --spirv of 512 slabs mixed in pairs: peak RSS %ld MB\n", m.maxRssKb / 1024);
}

/// The stability harness adds its forcing inputs (two per kind) and nodes to
/// the material; at 1023 inputs that went over the input-count limit, an
/// internal error (exit 3). The harness's own additions raise the limits.
TEST(WideMaterial, StabilityOfAMaterialAtTheInputLimitRuns) {
  const fs::path file = fs::path(SUBSTRATEC_WORK_DIR) / "wide" / "wide_mix_512_stability.json";
  fs::create_directories(file.parent_path());
  std::ofstream(file) << wideMix(512);
  const Measured m = measure({"stability", file.string(), "--no-gpu", "--evaluations", "200", "--json"});
  ASSERT_EQ(m.status, 0) << m.out;
  const auto j = nlohmann::json::parse(m.out);
  EXPECT_GT(j["evaluations"].get<long>(), 0);
  EXPECT_GT(j["furnace_lit"].get<long>(), 0);
  EXPECT_EQ(j["nonfinite"], 0);
}

}  // namespace substratec::widematerialtest
