// `substratec sweep` (issue 6): cost against error at the full budget and at
// each simplification step; and the CIEDE2000 it reports.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "sweep/sweep.h"

namespace {

namespace fs = std::filesystem;
using substratec::runCli;

struct CliRun {
  int status;
  std::string out, err;
};

CliRun cli(std::vector<std::string> args) {
  std::ostringstream out, err;
  int status = runCli(args, out, err);
  return CliRun{status, out.str(), err.str()};
}

std::string example(const char* name) { return (fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / name).string(); }

TEST(DeltaE2000, MatchesSharmasTestData) {
  // Sharma, Wu & Dalal 2005, Table 1: pairs 1, 7, 13, 19, 25 and 34.
  struct Pair {
    std::array<double, 3> a, b;
    double dE;
  } pairs[] = {
      {{50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}, 2.0425},
      {{50.0, 0.0, 0.0}, {50.0, -1.0, 2.0}, 2.3669},
      {{50.0, 2.5, 0.0}, {56.0, -27.0, -3.0}, 31.9030},
      {{50.0, 2.5, 0.0}, {50.0, 0.0, -2.5}, 4.3065},
      {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
      {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
  };
  for (const Pair& p : pairs) {
    EXPECT_NEAR(substratec::sweep::deltaE2000Lab(p.a, p.b), p.dE, 5e-5);
    EXPECT_NEAR(substratec::sweep::deltaE2000Lab(p.b, p.a), p.dE, 5e-5) << "symmetric";
  }
  EXPECT_EQ(substratec::sweep::deltaE2000({0.2, 0.4, 0.6}, {0.2, 0.4, 0.6}), 0.0);
}

TEST(Sweep, RowsGoFromTheFullBudgetDownWithCostAndError) {
  CliRun r = cli({"sweep", example("row40_coating.json"), "--json", "--pixels", "4096", "--runs", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["material"], "row40_coating");
  const auto& rows = j["rows"];
  ASSERT_GE(rows.size(), 2u) << "a coating over a base simplifies at least once";
  // The full budget fits the whole tree: no error.
  EXPECT_EQ(rows[0]["rel_mse"], 0.0);
  EXPECT_EQ(rows[0]["max_abs"], 0.0);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(i);
    for (const char* key : {"budget", "bytes", "closures", "spirv_instructions", "gpu_ns_per_pixel", "rel_mse",
                            "max_abs", "p99_abs", "delta_e2000", "rel_mse_vs_ground_truth"})
      EXPECT_TRUE(rows[i].contains(key)) << key;
    const double vsTruth = rows[i]["rel_mse_vs_ground_truth"].get<double>();
    EXPECT_TRUE(vsTruth > 0 && vsTruth < 1) << vsTruth;
    EXPECT_GT(rows[i]["gpu_ns_per_pixel"].get<double>(), 0.0);
    EXPECT_GT(rows[i]["spirv_instructions"].get<int>(), 0);
    EXPECT_LE(rows[i]["p99_abs"].get<double>(), rows[i]["max_abs"].get<double>());
    if (i > 0) {
      EXPECT_LT(rows[i]["bytes"].get<int>(), rows[i - 1]["bytes"].get<int>() + 1) << "ordered from the full budget down";
      EXPECT_LE(rows[i]["closures"].get<int>(), rows[i - 1]["closures"].get<int>());
    }
  }
  EXPECT_EQ(rows.back()["closures"], 1) << "down to one closure";
  // The coat's layering, as the analytic model does it, against the random
  // walk through the same stack (measured 0.028; the one-closure row 0.079).
  EXPECT_LT(rows[0]["rel_mse_vs_ground_truth"].get<double>(), 0.05);
  EXPECT_GT(rows.back()["rel_mse_vs_ground_truth"].get<double>(), rows[0]["rel_mse_vs_ground_truth"].get<double>())
      << "collapsing the coat moves away from the truth";
}

TEST(Sweep, TheGroundTruthAgreesWhereTheModelIsExact) {
  // A conductor: one GGX lobe, the same in the walk (single scattering) and in
  // the runtime, which adds only the energy compensation of the bounces between
  // microfacets — next to nothing at low roughness, more as it grows.
  auto vsTruth = [](double roughness) {
    const fs::path file = fs::temp_directory_path() / "substratec_sweep_conductor.json";
    std::ofstream(file) << R"({"format": "substrate-material/1", "name": "conductor", "nodes": {"root": {"kind": "slab",
      "diffuse_albedo": [0, 0, 0], "f0": [0.95, 0.64, 0.54], "roughness": )"
                        << roughness << R"(}}, "output": "root"})";
    CliRun r = cli({"sweep", file.string(), "--json", "--pixels", "4096", "--runs", "1"});
    fs::remove(file);
    EXPECT_EQ(r.status, 0) << r.err;
    return r.status == 0 ? nlohmann::json::parse(r.out)["rows"][0]["rel_mse_vs_ground_truth"].get<double>() : 1.0;
  };
  const double smooth = vsTruth(0.1), medium = vsTruth(0.35), rough = vsTruth(0.6);
  EXPECT_LT(smooth, 1e-5);  // measured 2.7e-7
  EXPECT_LT(medium, 2e-3);  // 3.8e-4
  EXPECT_LT(rough, 2e-2);   // 9.5e-3: the energy the walk's single-scattering interface loses
  EXPECT_LT(smooth, medium);
  EXPECT_LT(medium, rough);
}

TEST(Sweep, MaxErrorChoosesTheCheapestRowWithinIt) {
  CliRun any = cli({"sweep", example("row40_coating.json"), "--pixels", "4096", "--runs", "1", "--max-error", "1e30"});
  ASSERT_EQ(any.status, 0) << any.err;
  CliRun exact = cli({"sweep", example("row40_coating.json"), "--pixels", "4096", "--runs", "1", "--max-error", "0"});
  ASSERT_EQ(exact.status, 0) << exact.err;
  // Anything goes: the smallest row; nothing but exactness: the full budget.
  EXPECT_NE(any.out.find("budget "), std::string::npos) << any.out;
  EXPECT_NE(exact.out.find("(full budget:"), std::string::npos) << exact.out;
  EXPECT_NE(any.out.find("closures, rel_mse"), std::string::npos);
  EXPECT_EQ(any.out.find("(full budget:"), std::string::npos) << any.out;
}

TEST(Sweep, CsvAndPlot) {
  const fs::path svg = fs::temp_directory_path() / "substratec_sweep_test.svg";
  fs::remove(svg);
  CliRun r = cli({"sweep", example("row12_simple.json"), "--csv", "--pixels", "4096", "--runs", "1", "--plot",
                  svg.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("label,budget,bytes,closures,spirv_instructions,gpu_ns_per_pixel,rel_mse,", 0), 0u) << r.out;
  std::ifstream in(svg);
  std::ostringstream s;
  s << in.rdbuf();
  EXPECT_NE(s.str().find("<svg"), std::string::npos);
  EXPECT_NE(s.str().find("full budget"), std::string::npos) << "points are labelled";
  fs::remove(svg);
}

TEST(Sweep, ABrokenMaterialIsBadInput) {
  const fs::path broken = fs::temp_directory_path() / "substratec_sweep_broken.json";
  std::ofstream(broken) << "{";
  CliRun r = cli({"sweep", broken.string()});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("substratec_sweep_broken.json:"), std::string::npos) << r.err;
  fs::remove(broken);
}

}  // namespace
