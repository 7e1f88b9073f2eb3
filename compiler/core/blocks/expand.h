// Pass "expand-blocks": a document's building blocks (blocks.h) replaced by
// the slabs, operators and value nodes they stand for.
//
// Rewrite: JSON document -> JSON document without building blocks. The
// blocks are checked first (a resolve that knows their signatures: every
// error located at the block's own pins, all of them reported); then each
// block's unit writes its nodes. A named block's root takes the block's id
// (references to it are unchanged); an inline block becomes a reference to
// its root; the other nodes are named "<block id>_<part>" and placed before
// the block. A block inside a block (a coated_layer's base) is expanded in
// turn. A block whose presence folds to 0 (a glTF alpha of 0) gets an input
// "<block id>_presence" of 0, as an imported invisible material does. A
// document without blocks is left as it is.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "passes/resolve.h"

namespace substratec::blocks {

/// One block of the document and what it became (the tree dump and the
/// report name both).
struct ExpandedBlock {
  std::string id;       // the block's id: its named id, or "<node>_<pin>" inline
  std::string kind;     // "gltf_pbr", ...
  std::string pointer;  // where the document has it
  std::vector<std::string> nodes;  // the named nodes it expanded into, in document order
};

/// True when `doc` has a building block (named or inline) anywhere in its nodes.
bool hasBuildingBlocks(const Json& doc);

/// The pass: nullopt (with located errors in `diags`) when the blocks do not
/// check; otherwise the expanded document, `expanded` listing the blocks.
std::optional<Json> expandBuildingBlocks(const Json& doc, Diagnostics& diags, const ResolveLimits& limits,
                                         std::vector<ExpandedBlock>& expanded);

}  // namespace substratec::blocks
