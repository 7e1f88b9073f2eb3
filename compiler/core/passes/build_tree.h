// Pass 4 — build the Substrate tree: the Substrate graph (a DAG after
// resolve) is instanced into a tree from the output node. A node referenced
// twice is instanced twice; instances after the first get a unique suffix
// ("coat", "coat_2", ...). Slab pins become value ids (defaults included).
//
// Rewrite: ResolvedDoc Substrate nodes  ->  Material::nodes/slabs/root.
// Must run after buildValueDag (pins reference value ids).
#pragma once
#include "diag/diagnostics.h"
#include "passes/build_values.h"

namespace substratec {

struct TreeLimits {
  std::size_t maxTreeNodes = 1024;  // after instancing
};

bool buildSubstrateTree(const ResolvedDoc& doc, const ValueTable& table, Material& m, Diagnostics& diags,
                        const TreeLimits& limits = {});

}  // namespace substratec
