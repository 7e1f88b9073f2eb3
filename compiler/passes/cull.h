// Pass 5 — static culling: removes matter that can never show.
//  * horizontal with a constant mix of 0 keeps its background, of 1 its foreground;
//  * coverage_weight of constant 0 removes its subtree, of constant 1 disappears;
//  * select whose value (and threshold) are constant keeps the chosen side;
//  * an operator left with one empty side is rewritten: vertical/add keep the
//    other side; horizontal becomes a coverage_weight of the other side by its
//    weight (w for the foreground, 1-w for the background); select keeps the
//    other side weighted by the run-time condition.
// Every removal is recorded in Material::culled with the reason.
// Must run after buildSubstrateTree and before the analyses (features, bases,
// pricing), which must only see what can show.
#pragma once
#include "diag/diagnostics.h"
#include "ir/material.h"

namespace substratec {

/// Returns false (with an error) if nothing visible is left.
bool cullStaticMatter(Material& m, Diagnostics& diags);

}  // namespace substratec
