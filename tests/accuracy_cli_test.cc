// `substratec accuracy` (docs/accuracy.md, "The accuracy metric"): its JSON
// has every key of every row; it reads MaterialX like report does; a file that
// does not load exits non-zero with a located message. Cheap: low --samples.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.h"

namespace accuracy_cli_test {

using substratec::clitest::cli;
using substratec::clitest::CliResult;

const std::string kSourceDir = SUBSTRATEC_SOURCE_DIR;

TEST(AccuracyCli, JsonHasEveryKeyOfEveryNoV) {
  CliResult r = cli({"accuracy", kSourceDir + "/examples/row12_simple.json", "--json", "--samples", "256",
                     "--eval-samples", "32", "-j", "2"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["truth_samples"], 256);
  EXPECT_TRUE(j.contains("excluded"));
  EXPECT_TRUE(j.contains("truth_compiled"));
  ASSERT_EQ(j["rows"].size(), 6u);
  int checked = 0;
  for (const auto& row : j["rows"]) {
    for (const char* key : {"nov", "analytic", "truth", "truth_stderr", "rel_error", "brdf_median_rel_error",
                            "brdf_p95_rel_error", "reciprocity_max_ratio", "furnace_analytic", "furnace_truth"})
      EXPECT_TRUE(row.contains(key)) << key;
    EXPECT_TRUE(row["rel_error"].is_number());
    ++checked;
  }
  EXPECT_EQ(checked, 6);
  // Deterministic for a given --samples.
  EXPECT_EQ(cli({"accuracy", kSourceDir + "/examples/row12_simple.json", "--json", "--samples", "256",
                 "--eval-samples", "32", "-j", "1"}).out,
            r.out);
}

TEST(AccuracyCli, ReadsMaterialX) {
  const std::string mtlx =
      kSourceDir + "/tests/import/corpus/materialx/UsdPreviewSurface/usd_preview_surface_plastic.mtlx";
  CliResult r = cli({"accuracy", mtlx, "--samples", "128", "--eval-samples", "16"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("rel_err"), std::string::npos) << r.out;
}

// A material of unlit nodes only reflects nothing: no BRDF to measure, said
// as such (not a black truth compared with itself).
TEST(AccuracyCli, AnUnlitMaterialHasNoAccuracyAndSaysWhy) {
  CliResult r = cli({"accuracy", kSourceDir + "/examples/unlit_hologram.json", "--samples", "64"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("unlit_hologram.json: no accuracy to report: the material has no closure (unlit nodes only)"),
            std::string::npos)
      << r.err;
  // Mixed with a slab, the unlit is left out of the truth: the slab alone is measured.
  CliResult mixed = cli({"accuracy", kSourceDir + "/examples/unlit_display.json", "--json", "--samples", "256",
                         "--eval-samples", "32"});
  ASSERT_EQ(mixed.status, 0) << mixed.err;
  // The truth's white furnace is the reflecting share: the glass's 1 - fill
  // (0.65), not 1 (the unlit counted as matter).
  const auto j = nlohmann::json::parse(mixed.out);
  ASSERT_FALSE(j["rows"].empty());
  for (const auto& row : j["rows"]) EXPECT_NEAR(row["furnace_truth"][0].get<double>(), 0.65, 1e-9) << row.dump();
}

TEST(AccuracyCli, ABadFileFailsWithAMessage) {
  CliResult missing = cli({"accuracy", kSourceDir + "/examples/no_such_material.json"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("no_such_material.json"), std::string::npos) << missing.err;
  EXPECT_EQ(missing.out, "");
  const std::string bad = kSourceDir + "/tests/bad/282_include_cycle.mtlx";
  CliResult cycle = cli({"accuracy", bad});
  EXPECT_EQ(cycle.status, 1);
  EXPECT_NE(cycle.err.find("282_include_cycle"), std::string::npos) << cycle.err;
}

// A volume (a volumetric fog cloud) has no BRDF: its accuracy is its march
// against step counts and its froxel payload's error (accuracy/fog_accuracy.h).
TEST(AccuracyCli, AVolumeReportsItsMarchAgainstStepCounts) {
  CliResult r = cli({"accuracy", kSourceDir + "/examples/fog_cloud_puff.json", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["domain"], "volume");
  EXPECT_EQ(j["bytes_per_froxel"], 12);
  EXPECT_GT(j["rays"].get<int>(), 0);
  ASSERT_EQ(j["rows"].size(), 6u);
  EXPECT_LT(j["rows"][5]["max_rel_error"].get<double>(), j["rows"][0]["max_rel_error"].get<double>());
  CliResult black = cli({"accuracy", kSourceDir + "/examples/fog_cloud_puff.json"});
  EXPECT_NE(black.out.find("steps  median rel err"), std::string::npos) << black.out;
}

// The commands that shade a surface refuse a volume, saying what it has instead.
TEST(AccuracyCli, SurfaceCommandsRefuseAVolumeAndSayWhy) {
  const std::string fog = kSourceDir + "/examples/fog_neon_haze.json";
  CliResult r = cli({"stability", fog, "--no-gpu"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("'fog_neon_haze' is a volume (volumetric fog cloud 'haze'): stability's grid shades surfaces"),
            std::string::npos)
      << r.err;
  // sweep measures a volume's march (tests/gpu/sweep_test.cc); what chooses among simplification steps is a usage error.
  CliResult csv = cli({"sweep", fog, "--csv"});
  EXPECT_EQ(csv.status, 2);
  EXPECT_NE(csv.err.find("'fog_neon_haze' is a volume: its sweep is step counts of its march"), std::string::npos)
      << csv.err;
}

}  // namespace accuracy_cli_test
