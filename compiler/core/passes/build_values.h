// Pass 3 — build the value DAG: every value node of the ResolvedDoc becomes a
// node of Material::values, created through ValueDag::make, which hash-conses
// (structurally identical subexpressions are one node) and folds constants.
//
// Rewrite: ResolvedDoc value nodes  ->  ValueDag ids, one per node output.
// Must run after resolve (it relies on valueOrder being dependency-first).
#pragma once
#include <vector>

#include "ir/material.h"
#include "passes/resolve.h"

namespace substratec {

/// Value ids of each resolved value node, one per output.
struct ValueTable {
  std::vector<std::vector<ValueId>> outputs;
};

/// Fills m.settings, m.inputs, m.name and m.values from the document.
ValueTable buildValueDag(const ResolvedDoc& doc, Material& m);

/// The DAG value of a pin, converted to `want` (a Float broadcasts to a
/// vector; defaults become constants or geometry).
ValueId pinToValue(const PinRef& pin, VType want, const ValueTable& table, Material& m);

}  // namespace substratec
