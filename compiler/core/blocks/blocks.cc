#include "blocks/blocks.h"

namespace substratec::blocks {

const std::vector<BuildingBlock>& buildingBlocks() {
  static const std::vector<BuildingBlock> blocks = {coatedLayerBlock(),   clearCoatBlock(), clothBlock(),
                                                    ue4DefaultLitBlock(), ue4UnlitBlock(),  legacyConversionBlock(),
                                                    gltfPbrBuildingBlock(), standardSurfaceBlock(),
                                                    openPbrSurfaceBlock(),  disneyPrincipledBlock()};
  return blocks;
}

const std::vector<BlockSignature>& blockSignatures() {
  static const std::vector<BlockSignature> signatures = [] {
    std::vector<BlockSignature> v;
    for (const BuildingBlock& b : buildingBlocks()) v.push_back(b.signature);
    return v;
  }();
  return signatures;
}

const BuildingBlock* findBuildingBlock(std::string_view kind) {
  for (const BuildingBlock& b : buildingBlocks())
    if (kind == b.signature.kind) return &b;
  return nullptr;
}

Value pinOf(const Json& block, const char* name) {
  auto it = block.find(name);
  return it == block.end() ? Value() : *it;
}

}  // namespace substratec::blocks
