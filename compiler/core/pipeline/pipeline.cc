#include "pipeline/pipeline.h"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "blocks/expand.h"
#include "passes/build_tree.h"
#include "passes/cull.h"
#include "passes/features.h"
#include "passes/shared_bases.h"
#include "pipeline/pass_registry.h"
#include "ir/dump.h"

namespace substratec {

namespace {

/// The budget the material is simplified to: its settings, overridden by
/// --budget / --max-closures, capped by the platform.
void chooseBudget(PassContext& c) {
  const Material& m = c.result.material;
  c.result.budgetBytes = c.options.budgetOverride.value_or(m.settings.bytesPerPixel);
  c.result.maxClosures = c.options.maxClosuresOverride.value_or(m.settings.maxClosures);
  if (c.options.platform) {  // the platform caps what the material asks for
    c.result.budgetBytes = std::min(c.result.budgetBytes, c.options.platform->bytesPerPixel);
    c.result.maxClosures = std::min(c.result.maxClosures, c.options.platform->maxClosures);
  }
}

bool simplifyPass(PassContext& c) {
  const CompileOptions& o = c.options;
  c.result.after = c.result.before;
  SimplifyBudget budget{c.result.budgetBytes, c.result.maxClosures, o.fullSimplification, o.blendRule,
                        o.platform ? o.platform->disallowedFeatures() : std::uint16_t{0},
                        o.platform ? o.platform->name : std::string()};
  return simplifyToBudget(c.result.material, budget, repriceMaterial, c.result.after, c.result.steps, c.diags);
}

/// The pipeline: every pass in order, with the reason for its place.
const std::vector<Pass>& passList() {
  static const std::vector<Pass> passes = {
      // 1. parse: text -> JSON document (syntax errors carry line:col).
      {"parse", "text -> JSON document (syntax errors at file:line:col)",
       [](PassContext& c) { return bool(c.doc = parseJsonDocument(c.text, c.options.read, c.diags)); }},
      // 2. expand-blocks: building blocks -> the slabs, operators and value
      //    nodes they stand for (a no-op without blocks). Before resolve, so that
      //    everything after it, culling and feature analysis included, sees
      //    through the expansion: a block costs what its expansion costs.
      {"expand-blocks", "building blocks -> the slabs, operators and value nodes they stand for",
       [](PassContext& c) {
         if (!blocks::hasBuildingBlocks(*c.doc)) return true;
         auto expanded = blocks::expandBuildingBlocks(*c.doc, c.diags, c.options.resolve, c.result.blocks);
         if (expanded) c.doc = std::move(*expanded);
         return expanded.has_value();
       }},
      // 3. resolve: keys, kinds, types, ranges, references, cycles (JSON pointers).
      {"resolve", "JSON -> resolved document: keys, kinds, types, ranges, references, cycles",
       [](PassContext& c) { return bool(c.resolved = resolveDocument(*c.doc, c.diags, c.options.resolve)); }},
      // 4. value DAG: structural hashing + constant folding. Culling (6) and
      //    feature analysis (7) rely on folded constants, so this comes first.
      {"build-values", "value nodes -> the hash-consed value DAG, constants folded",
       [](PassContext& c) {
         c.values = buildValueDag(*c.resolved, c.result.material);
         return true;
       }},
      // 5. Substrate tree: instance the Substrate graph from the output.
      {"build-tree", "Substrate graph -> tree (a node referenced twice is instanced twice)",
       [](PassContext& c) {
         return buildSubstrateTree(*c.resolved, c.values, c.result.material, c.diags, c.options.tree);
       }},
      // 6. static culling (constant weights, bases under opaque tops): before any
      //    analysis, so culled matter costs nothing.
      {"cull", "removes matter that can never show",
       [](PassContext& c) { return cullStaticMatter(c.result.material, c.diags); }},
      // 7. features per slab (needs the culled tree: top/bottom positions).
      {"features", "per-slab opt-in features",
       [](PassContext& c) {
         analyzeFeatures(c.result.material);
         return true;
       },
       analyzeFeatures},
      // 8. shared local bases (needs the anisotropy flags from 7).
      {"shared-bases", "slabs with equal normals (and tangents) share a basis",
       [](PassContext& c) {
         shareLocalBases(c.result.material);
         return true;
       },
       shareLocalBases},
      // 9. layout and pricing, against the budget the material asks for.
      {"price", "the storage layout and its bytes per pixel",
       [](PassContext& c) {
         chooseBudget(c);
         c.result.before = computeLayout(c.result.material, analyzeTree(c.result.material));
         return true;
       }},
      // 10. simplify to the budget (re-runs 7-9 after each step, so it comes last).
      {"simplify", "collapses operators and disables features until the material fits its budget", simplifyPass},
  };
  return passes;
}

/// Runs one pass, timing it and dumping the IR after it when asked.
bool runPass(const Pass& pass, PassContext& c) {
  auto t0 = std::chrono::steady_clock::now();
  const bool ok = pass.run(c);
  if (c.options.timePasses) {
    double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    c.result.timings.push_back({std::string(pass.name), ms});
  }
  // Before build-tree the material is empty: after expand-blocks, the
  // document the blocks expanded into is what there is to see.
  if ((c.options.printAfterAll || pass.name == c.options.printAfter) && pass.name == "expand-blocks" && c.doc)
    c.result.debugLog += fmt::format("; document after {}\n{}\n", pass.name, c.doc->dump(2));
  else if (c.options.printAfterAll || pass.name == c.options.printAfter)
    c.result.debugLog += fmt::format("; IR after {}\n{}\n", pass.name, dumpMaterial(c.result.material));
  return ok;
}

}  // namespace

std::span<const Pass> passRegistry() { return passList(); }

const Pass* findPass(std::string_view name) {
  for (const Pass& p : passList())
    if (p.name == name) return &p;
  return nullptr;
}

std::string passNames() {
  std::string names;
  for (const Pass& p : passList()) names += (names.empty() ? "" : ", ") + std::string(p.name);
  return names;
}

bool runPasses(PassContext& c, std::string_view last) {
  for (const Pass& pass : passList()) {
    if (!runPass(pass, c)) return false;
    if (pass.name == last) break;
  }
  return true;
}

StorageLayout repriceMaterial(Material& m) {
  for (const Pass& pass : passList())
    if (pass.reanalyze) pass.reanalyze(m);
  return computeLayout(m, analyzeTree(m));
}

CompileOptions unsimplifiedOptions(CompileOptions base) {
  constexpr int kNothingExceeds = 1 << 20;
  base.budgetOverride = kNothingExceeds;
  base.maxClosuresOverride = kNothingExceeds;
  base.fullSimplification = false;
  base.platform.reset();  // a platform caps the budget and disallows features
  return base;
}

std::optional<CompileResult> compileText(const std::string& displayName, const std::string& text,
                                         const CompileOptions& options, Diagnostics& diags) {
  (void)displayName;  // diagnostics already carry the file name
  CompileResult result;
  result.material.file = diags.file();
  PassContext context(text, options, diags, result);
  if (!runPasses(context, options.stopAfter)) return std::nullopt;
  if (options.stopAfter.empty()) result.tree = analyzeTree(result.material);
  return result;
}

std::optional<CompileResult> compileFile(const std::string& path, const CompileOptions& options,
                                         Diagnostics& diags) {
  auto text = readSourceFile(path, options.read, diags);
  if (!text) return std::nullopt;
  return compileText(path, *text, options, diags);
}

}  // namespace substratec
