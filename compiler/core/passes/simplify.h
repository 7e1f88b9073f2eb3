// Pass 9 — simplify: fits the material into its budget (bytes per pixel and
// closures) by parameter blending. While over budget it collapses one
// operator into one equivalent slab — the deepest operator first (depth =
// distance from the root; at equal depth horizontal/add/select/weight before
// vertical, then by tree id) — and re-prices. When no operator is left and it
// is still over budget, it disables opt-in features in the documented order
// (most bytes saved per unit of visual loss first). If that is not enough it
// fails with an error naming the budget and the smallest size reachable.
// Full simplification collapses everything into one slab and then disables
// features until the packed size fits a 32-byte ray-tracing payload.
// Features a platform does not allow (`disallowed`) are disabled first, in
// the same order, and again after the collapses (a blend can bring one back);
// those steps are recorded as "disallow".
//
// Rewrite: Material (priced)  ->  Material (fits), plus the list of steps.
// Must run after shared-bases and pricing; it re-runs features, bases and
// pricing after every step (the registry's analyses, handed in as `reprice`),
// so the IR stays analysed.
#pragma once
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "ir/material.h"
#include "passes/blend.h"
#include "storage/layout.h"

namespace substratec {

struct SimplifyStep {
  std::string action;     // "collapse" or "disable"
  std::string node;       // operator id, or feature name
  std::string kind;       // operator kind (HORIZONTAL, ...), or "feature"
  int depth = 0;          // operator depth (distance from the root)
  int bytesBefore = 0, bytesAfter = 0;
  int closuresBefore = 0, closuresAfter = 0;
};

struct SimplifyBudget {
  int bytesPerPixel = 80;
  int maxClosures = 8;
  bool full = false;
  BlendRule rule = BlendRule::ProjectRules;  // blending rules of the collapses
  std::uint16_t disallowed = 0;              // kFeat* bits the platform does not allow (pipeline/platform.h)
  std::string platform;                      // its name, for the diagnostic ("" without a platform)
};

/// The largest packed size of a fully simplified material (ray-tracing payload).
inline constexpr int kFullSimplificationBytes = 32;

/// Order in which features are disabled (docs/simplification.md).
const std::vector<std::uint16_t>& featureDisableOrder();

/// Re-analyses a rewritten material and prices it: the pipeline's analyses
/// and pricing, in the pipeline's order (pipeline/pass_registry.h:
/// repriceMaterial). Passed in, so that the order is written once.
using Reprice = StorageLayout (*)(Material& m);

/// Returns false (with an error) when the budget cannot be met. `layout` is
/// the current price on entry and the final one on return; `reprice` runs
/// after every step.
bool simplifyToBudget(Material& m, const SimplifyBudget& budget, Reprice reprice, StorageLayout& layout,
                      std::vector<SimplifyStep>& steps, Diagnostics& diags);

/// Disables one feature on every slab (used by simplification; exposed for tests).
/// Emissive (not in featureDisableOrder: it costs no bytes) is disabled by a
/// platform that does not allow it.
void disableFeature(Material& m, std::uint16_t feature);

}  // namespace substratec
