// The `coated_layer` building block (the course notes' "Coated Layer"): a
// dielectric coat over any Substrate node, written as layered_surface.h's
// coat: vertical(top = coverage_weight(coat slab, coat_weight), base).
#include "blocks/blocks.h"
#include "blocks/layered_surface.h"

namespace substratec::blocks {

namespace {

using Kind = BlockPin::Kind;

Value expandCoatedLayer(const Json& block, BlockContext& c) {
  NodeWriter& w = c.w;
  LayeredSurface s;
  s.coatWeight = pinOf(block, "coat_weight");
  if (s.coatWeight.is_null()) s.coatWeight = 1.0;
  const Value base = pinOf(block, "base");
  if (isLiteral(s.coatWeight, 0)) return base;  // no coat: the base as it is
  s.coatF0 = pinOf(block, "coat_f0");
  s.coatRoughness = pinOf(block, "coat_roughness");
  s.coatAnisotropy = pinOf(block, "coat_anisotropy");
  s.coatTangent = pinOf(block, "coat_tangent");
  s.coatNormal = pinOf(block, "coat_normal");
  s.coatTransmittance = pinOf(block, "coat_transmittance");
  return coatedRoot(s, w, base);
}

}  // namespace

BuildingBlock coatedLayerBlock() {
  return {{"coated_layer",
           {{"base", Kind::Substrate, 0, 0, /*required=*/true},
            {"coat_weight", Kind::Float, 0, 1},
            {"coat_f0", Kind::Color, 0, 1},
            {"coat_roughness", Kind::Float, 0, 1},
            {"coat_anisotropy", Kind::Float, -1, 1},
            {"coat_tangent", Kind::Vec3},
            {"coat_normal", Kind::Vec3},
            {"coat_transmittance", Kind::Color, 0, 1}}},
          expandCoatedLayer};
}

}  // namespace substratec::blocks
