// The pass registry: the compiler's passes in pipeline order, each with its
// name, a one-line doc and the function that runs it (in the spirit of
// SPIRV-Tools' optimizer pass registry). It is the one list of the pass
// order: the pipeline runs it (compileText), the pass tests stop in it
// (tests/unit/test_util.h: runUntil), simplify re-runs its analyses after
// every rewrite (repriceMaterial), and --print-after / --stop-after name its
// passes. The list and its ordering reasons are in pipeline.cc (passList).
#pragma once
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "passes/build_values.h"
#include "passes/resolve.h"
#include "pipeline/pipeline.h"
#include "storage/layout.h"

namespace substratec {

/// What the passes of one compile share: the input and options, and what
/// each pass hands the next (the document, the resolved document, the value
/// table, then the material in `result`).
struct PassContext {
  PassContext(const std::string& t, const CompileOptions& o, Diagnostics& d, CompileResult& r)
      : text(t), options(o), diags(d), result(r) {}
  const std::string& text;
  const CompileOptions& options;
  Diagnostics& diags;
  CompileResult& result;               // result.material is the IR the passes rewrite
  std::optional<Json> doc;             // parse's
  std::optional<ResolvedDoc> resolved;  // resolve's
  ValueTable values;                   // build-values'
};

struct Pass {
  std::string_view name;  // as --print-after, --stop-after and runUntil name it
  std::string_view doc;   // what it does, one line
  /// Runs the pass; false stops the compile (its diagnostics say why).
  bool (*run)(PassContext&);
  /// Set for an analysis of the material that simplify re-runs after every
  /// rewrite, in registry order, before re-pricing (repriceMaterial).
  void (*reanalyze)(Material&) = nullptr;
};

/// Every pass, in pipeline order.
std::span<const Pass> passRegistry();

/// The pass called `name`, or nullptr.
const Pass* findPass(std::string_view name);

/// The passes' names in order, comma separated (for usage messages).
std::string passNames();

/// Runs the passes in order through `last` (every pass when empty; `last`
/// must be a registry name), timing them and dumping the IR after them into
/// c.result as c.options asks. False when a pass fails.
bool runPasses(PassContext& c, std::string_view last = {});

/// Re-runs the analyses (every pass with `reanalyze`, in order) after a
/// rewrite of `m` and prices the result: what simplify does after each step.
StorageLayout repriceMaterial(Material& m);

}  // namespace substratec
