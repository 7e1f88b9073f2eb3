// Pass 5 — static culling: removes matter that can never show.
//  * horizontal with a constant mix of 0 keeps its background, of 1 its foreground;
//  * coverage_weight of constant 0 removes its subtree, of constant 1 disappears;
//  * select whose value (and threshold) are constant keeps the chosen side;
//  * vertical whose top is provably opaque (coverage 1, T = 0 whatever the
//    inputs: slabs with the constant sss_mfp 0 in a layer of positive constant
//    thickness, and mixes/adds/selects/verticals of such; see Culler::opaque)
//    is replaced by its top, its base removed — only where the top stays
//    opaque in the layer that then holds it; a located warning at the top
//    says how to make it transparent (also when only a run-time thickness
//    > 0 makes it opaque, where nothing is removed);
//  * an operator left with one empty side is rewritten: vertical/add keep the
//    other side; horizontal becomes a coverage_weight of the other side by its
//    weight (w for the foreground, 1-w for the background); select keeps the
//    other side weighted by the run-time condition;
//  * an eye whose iris mask is the constant 0 has no iris: it becomes the slab
//    its cornea and sclera are (F0 0.04; substrate_eye.h lights it so, bit for
//    bit), which stores no iris fields.
// The rules run in rounds until a round removes nothing (a top moved into
// the enclosing layer can hide more), at most one round per tree node.
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
