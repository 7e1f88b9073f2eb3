// Accuracy of parameter blending (docs/accuracy.md, "Parameter blending vs
// plain lerp"): every example at every simplification step, the project's
// blending rules against the plain-lerp baseline, measured with the CPU
// reference (compiler/tools/reference/blend_error.h). Prints the table of
// docs/accuracy.md:  build/bin/unit_tests --gtest_filter=BlendAccuracy.*
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "reference/blend_error.h"

namespace substratec {
namespace {

using reference::BlendStepError;

std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::filesystem::path> examples() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(SUBSTRATEC_SOURCE_DIR "/examples"))
    if (e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(BlendAccuracy, RelativeMseIsTheDocumentedMetric) {
  EXPECT_EQ(reference::relativeMse({1, 2, 0}, {1, 2, 0}), 0.0);
  // (0.5 - 0.4)^2 / (0.16 + 0.01) and (0 - 0.1)^2 / (0.01 + 0.01), averaged.
  EXPECT_NEAR(reference::relativeMse({0.5, 0.0}, {0.4, 0.1}), (0.01 / 0.17 + 0.01 / 0.02) / 2, 1e-15);
  EXPECT_TRUE(std::isnan(reference::relativeMse({1}, {1, 2})));
}

TEST(BlendAccuracy, ProbesAreDeterministicAndSeeTheMaterial) {
  const std::string path = SUBSTRATEC_SOURCE_DIR "/examples/row40_coating.json";
  Diagnostics d(path);
  CompileOptions none;
  none.budgetOverride = 1 << 20;
  auto a = compileText(path, readText(path), none, d);
  ASSERT_TRUE(a) << d.formatAll();
  CompileOptions full;
  full.fullSimplification = true;
  auto b = compileText(path, readText(path), full, d);
  ASSERT_TRUE(b) << d.formatAll();
  const std::vector<double> ya = reference::blendProbeRadiance(*a), yb = reference::blendProbeRadiance(*b);
  ASSERT_EQ(ya.size(), 64u * 4 * 4 * 3);
  EXPECT_EQ(ya, reference::blendProbeRadiance(*a));
  EXPECT_TRUE(std::all_of(ya.begin(), ya.end(), [](double x) { return std::isfinite(x) && x >= 0; }));
  EXPECT_GT(reference::relativeMse(yb, ya), 0.0);  // the collapse is visible to the probes
}

// The table: for each example and step, both rules at the same step (same
// collapses, same byte and closure budget).
TEST(BlendAccuracy, ProjectRulesBeatPlainLerp) {
  std::string table =
      "| example | step | bytes | closures | rel_mse plain lerp | rel_mse project rules | ratio |\n"
      "|---|---|---|---|---|---|---|\n";
  double sumPlain = 0, sumProject = 0, sumLogRatio = 0;
  int measured = 0;
  std::string worst;
  double worstRatio = INFINITY;
  for (const auto& path : examples()) {
    const std::string name = path.stem().string(), text = readText(path);
    SCOPED_TRACE(name);
    Diagnostics d(path.string());
    // The budgets are those of the project rules' steps; both rules are held to them.
    auto budgets = reference::simplificationBudgets(text, BlendRule::ProjectRules, d);
    ASSERT_TRUE(budgets) << d.formatAll();
    auto plain = reference::measureBlendError(text, *budgets, BlendRule::PlainLerp, d);
    auto project = reference::measureBlendError(text, *budgets, BlendRule::ProjectRules, d);
    ASSERT_TRUE(plain && project) << d.formatAll();
    ASSERT_EQ(plain->size(), budgets->size());
    ASSERT_EQ(project->size(), budgets->size());
    if (project->empty()) continue;
    double examplePlain = 0, exampleProject = 0;
    for (std::size_t k = 0; k < project->size(); ++k) {
      const BlendStepError &p = (*plain)[k], &q = (*project)[k];
      // Equal budgets: both fit the bytes and closures of the step.
      const reference::BlendBudget& b = (*budgets)[k];
      if (!b.full) {
        EXPECT_TRUE(p.bytes <= b.bytes && p.closures <= b.closures && q.bytes <= b.bytes && q.closures <= b.closures);
      }
      EXPECT_TRUE(std::isfinite(p.relMse) && std::isfinite(q.relMse));
      const double ratio = p.relMse / std::max(q.relMse, 1e-12);
      auto both = [](int x, int y) { return x == y ? fmt::format("{}", x) : fmt::format("{} / {}", x, y); };
      table += fmt::format("| {} | {}{}: {} | {} | {} | {:.3e} | {:.3e} | {:.2f} |\n", name, q.step,
                           q.full ? " (full)" : "", q.action, both(p.bytes, q.bytes), both(p.closures, q.closures),
                           p.relMse, q.relMse, ratio);
      // Never markedly worse than the baseline at any step.
      EXPECT_LE(q.relMse, 1.1 * p.relMse + 1e-4) << "step " << q.step << " " << q.action;
      examplePlain += p.relMse / project->size();
      exampleProject += q.relMse / project->size();
    }
    const double ratio = examplePlain / std::max(exampleProject, 1e-12);
    if (ratio < worstRatio) worstRatio = ratio, worst = name;
    sumPlain += examplePlain;
    sumProject += exampleProject;
    sumLogRatio += std::log(ratio);
    ++measured;
  }
  ASSERT_GE(measured, 8);
  const double meanPlain = sumPlain / measured, meanProject = sumProject / measured;
  table += fmt::format(
      "\nexamples measured: {}; mean rel_mse (per-example mean over its steps, then over the examples): "
      "plain lerp {:.3e}, project rules {:.3e}, ratio {:.2f}; geometric mean of the per-example ratios {:.2f}; "
      "worst example {} (ratio {:.2f})\n",
      measured, meanPlain, meanProject, meanPlain / meanProject, std::exp(sumLogRatio / measured), worst, worstRatio);
  std::printf("%s", table.c_str());
  EXPECT_GE(meanPlain / meanProject, 2.0);
}

}  // namespace
}  // namespace substratec
