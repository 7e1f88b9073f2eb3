// The compiler pipeline: JSON text to a priced material, through the passes
// of the pass registry (pipeline/pass_registry.h) in order. Each step is a
// pass with one job (see passes/*.h).
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "blocks/expand.h"
#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "ir/material.h"
#include "ir/tree_info.h"
#include "passes/build_tree.h"
#include "passes/resolve.h"
#include "passes/simplify.h"
#include "pipeline/platform.h"
#include "storage/layout.h"

namespace substratec {

struct CompileOptions {
  ReadLimits read;
  ResolveLimits resolve;
  TreeLimits tree;
  std::optional<int> budgetOverride;       // --budget
  std::optional<int> maxClosuresOverride;  // --max-closures
  bool fullSimplification = false;         // --full-simplification
  std::optional<Platform> platform;        // --platform: caps budget and closures, disallows features
  BlendRule blendRule = BlendRule::ProjectRules;  // collapse rules (PlainLerp: the accuracy baseline)
  bool printAfterAll = false;              // dump the IR after every pass into debugLog
  std::string printAfter;                  // --print-after: dump the IR after this pass into debugLog
  std::string stopAfter;                   // --stop-after: run the passes through this one only
  bool timePasses = false;                 // record per-pass wall time
};

/// `base` without any simplification: a byte and closure budget nothing
/// exceeds, no full simplification. What the authored tree compiles to (the
/// reference of sweep's and accuracy's comparisons); it may hold more closures
/// than the storage format packs (packfmt::kMaxClosures), so its code cannot
/// always be generated.
CompileOptions unsimplifiedOptions(CompileOptions base);

struct PassTiming {
  std::string pass;
  double milliseconds = 0;
};

struct CompileResult {
  Material material;
  TreeInfo tree;            // of the final material
  StorageLayout before;     // priced before simplification
  StorageLayout after;      // priced after simplification
  int budgetBytes = 80;
  int maxClosures = 8;
  std::vector<SimplifyStep> steps;
  std::vector<blocks::ExpandedBlock> blocks;  // the building blocks and what they expanded into
  std::vector<PassTiming> timings;
  std::string debugLog;     // --print-after(-all) output
};

/// Compiles JSON text. `displayName` is what diagnostics call the file. With
/// options.stopAfter (a pass name) the result is partial: only the passes
/// through that one ran (it is for their dumps, not for emitting).
std::optional<CompileResult> compileText(const std::string& displayName, const std::string& text,
                                         const CompileOptions& options, Diagnostics& diags);

/// Reads (within the input-size limit) and compiles a file.
std::optional<CompileResult> compileFile(const std::string& path, const CompileOptions& options,
                                         Diagnostics& diags);

}  // namespace substratec
