// The building blocks (docs/format.md, "Building blocks"): format nodes that
// stand for the slabs, operators and value nodes an author would otherwise
// write by hand. Each block is a signature (its pins, checked by the resolver
// like any node's) and an expansion (the nodes it stands for), one mapping
// unit per model:
//   coated_layer                          coated_layer.cc
//   clear_coat, cloth, ue4_default_lit, ue4_unlit,
//   legacy_conversion                     ue4.cc
//   gltf_pbr                              gltf_pbr.cc (shared with the importers)
//   standard_surface, open_pbr_surface,
//   disney_principled                     mtlx_blocks.cc over mtlx_surfaces.h's units
//                                         (shared with the MaterialX importer)
// The expansion pass (blocks/expand.h) rewrites a document's blocks into
// these nodes before the resolve of the pipeline.
#pragma once
#include <string_view>
#include <vector>

#include "blocks/material_writer.h"
#include "passes/resolve.h"

namespace substratec::blocks {

/// What a block's unit is given besides its pins.
struct BlockContext {
  NodeWriter& w;                      // where its nodes go
  const Json& document;               // the document it is in (its inputs' values)
  std::vector<std::string> warnings;  // what it cannot represent (reported at the block)
};

struct BuildingBlock {
  BlockSignature signature;
  /// Writes the nodes `block` (a checked node of this kind) stands for into
  /// c.w and returns its root: a reference to one of them, or a Substrate pin
  /// of the block as it was given (a coat of weight 0 is its base).
  Value (*expand)(const Json& block, BlockContext& c);
};

/// Every building block, in the order docs/format.md lists them.
const std::vector<BuildingBlock>& buildingBlocks();
/// Their signatures (ResolveLimits::blocks).
const std::vector<BlockSignature>& blockSignatures();
/// The block of kind `kind`, or null.
const BuildingBlock* findBuildingBlock(std::string_view kind);

/// A block's pin as given, or null when absent.
Value pinOf(const Json& block, const char* name);

// The units (one per model).
BuildingBlock coatedLayerBlock();
BuildingBlock clearCoatBlock();
BuildingBlock ue4DefaultLitBlock();
BuildingBlock clothBlock();
BuildingBlock ue4UnlitBlock();
BuildingBlock legacyConversionBlock();
BuildingBlock gltfPbrBuildingBlock();
BuildingBlock standardSurfaceBlock();
BuildingBlock openPbrSurfaceBlock();
BuildingBlock disneyPrincipledBlock();

}  // namespace substratec::blocks
