#include "pipeline/pipeline.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "passes/build_values.h"
#include "passes/cull.h"
#include "passes/features.h"
#include "passes/shared_bases.h"
#include "ir/dump.h"

namespace substratec {

namespace {

/// Runs one pass, timing it and dumping the IR after it when asked.
class PassRunner {
 public:
  PassRunner(const CompileOptions& o, CompileResult& r) : options_(o), result_(r) {}

  template <typename F>
  auto run(const char* name, F&& pass) {
    auto t0 = std::chrono::steady_clock::now();
    auto out = pass();
    if (options_.timePasses) {
      double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      result_.timings.push_back({name, ms});
    }
    if (options_.printAfterAll)
      result_.debugLog += fmt::format("; IR after {}\n{}\n", name, dumpMaterial(result_.material));
    return out;
  }

 private:
  const CompileOptions& options_;
  CompileResult& result_;
};

}  // namespace

std::optional<CompileResult> compileText(const std::string& displayName, const std::string& text,
                                         const CompileOptions& options, Diagnostics& diags) {
  (void)displayName;  // diagnostics already carry the file name
  CompileResult result;
  Material& m = result.material;
  m.file = diags.file();
  PassRunner pass(options, result);

  // 1. parse: text -> JSON document (syntax errors carry line:col).
  auto doc = pass.run("parse", [&] { return parseJsonDocument(text, options.read, diags); });
  if (!doc) return std::nullopt;
  // 2. resolve: keys, kinds, types, ranges, references, cycles (JSON pointers).
  auto resolved = pass.run("resolve", [&] { return resolveDocument(*doc, diags, options.resolve); });
  if (!resolved) return std::nullopt;
  // 3. value DAG: structural hashing + constant folding. Culling (5) and
  //    feature analysis (6) rely on folded constants, so this comes first.
  auto table = pass.run("build-values", [&] { return buildValueDag(*resolved, m); });
  // 4. Substrate tree: instance the Substrate graph from the output.
  if (!pass.run("build-tree", [&] { return buildSubstrateTree(*resolved, table, m, diags, options.tree); }))
    return std::nullopt;
  // 5. static culling (constant weights, bases under opaque tops): before any
  //    analysis, so culled matter costs nothing.
  if (!pass.run("cull", [&] { return cullStaticMatter(m, diags); })) return std::nullopt;
  // 6. features per slab (needs the culled tree: top/bottom positions).
  pass.run("features", [&] { analyzeFeatures(m); return true; });
  // 7. shared local bases (needs the anisotropy flags from 6).
  pass.run("shared-bases", [&] { shareLocalBases(m); return true; });
  // 8. layout and pricing.
  result.budgetBytes = options.budgetOverride.value_or(m.settings.bytesPerPixel);
  result.maxClosures = options.maxClosuresOverride.value_or(m.settings.maxClosures);
  if (options.platform) {  // the platform caps what the material asks for
    result.budgetBytes = std::min(result.budgetBytes, options.platform->bytesPerPixel);
    result.maxClosures = std::min(result.maxClosures, options.platform->maxClosures);
  }
  pass.run("price", [&] {
    result.before = computeLayout(m, analyzeTree(m));
    return true;
  });
  // 9. simplify to the budget (re-runs 6-8 after each step, so it comes last).
  result.after = result.before;
  SimplifyBudget budget{result.budgetBytes, result.maxClosures, options.fullSimplification, options.blendRule,
                        options.platform ? options.platform->disallowedFeatures() : std::uint16_t{0},
                        options.platform ? options.platform->name : std::string()};
  if (!pass.run("simplify", [&] { return simplifyToBudget(m, budget, result.after, result.steps, diags); }))
    return std::nullopt;
  result.tree = analyzeTree(m);
  return result;
}

std::optional<CompileResult> compileFile(const std::string& path, const CompileOptions& options,
                                         Diagnostics& diags) {
  auto text = readSourceFile(path, options.read, diags);
  if (!text) return std::nullopt;
  return compileText(path, *text, options, diags);
}

}  // namespace substratec
