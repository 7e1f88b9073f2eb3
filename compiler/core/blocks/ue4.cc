// The UE4 shading models as building blocks (the course notes' "UE4 Default
// Shading", "UE4 Unlit Shading" and the abstracted "Clear Coat" node), with
// UE's material-attribute defaults (BaseColor 0, Metallic 0, Specular 0.5,
// Roughness 0.5, Opacity 1):
//   ue4_default_lit  one slab: diffuse and F0 from metalness_to_diffuse_f0
//                    (diffuse = base·(1 − metallic), F0 = lerp(0.08·specular,
//                    base, metallic)), the legacy path's 12 bytes
//   clear_coat       the default-lit slab under a coat of F0 0.04 (IOR 1.5),
//                    its weight clear_coat and roughness clear_coat_roughness
//   ue4_unlit        the unlit BSDF: emissive_color, no closure
// each under a coverage weight when an opacity other than 1 is given.
#include "blocks/blocks.h"
#include "blocks/layered_surface.h"

namespace substratec::blocks {

namespace {

using Kind = BlockPin::Kind;

/// The pins of UE4's default-lit model.
std::vector<BlockPin> defaultLitPins() {
  return {{"base_color", Kind::Color, 0, 1}, {"metallic", Kind::Float, 0, 1},
          {"specular", Kind::Float, 0, 1},   {"roughness", Kind::Float, 0, 1},
          {"anisotropy", Kind::Float, -1, 1}, {"tangent", Kind::Vec3},
          {"normal", Kind::Vec3},             {"emissive_color", Kind::Color, 0, 1e300},
          {"opacity", Kind::Float, 0, 1}};
}

/// `root` under a coverage weight of the block's opacity (none when absent or 1).
Value withOpacity(const Json& block, NodeWriter& w, const Value& root) {
  const Value opacity = pinOf(block, "opacity");
  if (opacity.is_null() || isLiteral(opacity, 1)) return root;
  return w.node("presence", Json{{"kind", "coverage_weight"}, {"a", root}, {"weight", opacity}});
}

/// The default-lit slab (without its opacity); `normal` its normal.
Value defaultLitSlab(const Json& block, NodeWriter& w, const Value& normal) {
  Json helper = {{"kind", "metalness_to_diffuse_f0"}};
  const Value base = pinOf(block, "base_color");
  helper["base_color"] = base.is_null() ? Value(0.0) : base;  // UE's BaseColor default, not the helper's 0.18
  for (const char* pin : {"metallic", "specular"})
    if (const Value v = pinOf(block, pin); !v.is_null()) helper[pin] = v;
  const Value metalness = w.node("metalness", helper);
  Json slab = {{"kind", "slab"},
               {"diffuse_albedo", outputOf(metalness, "diffuse_albedo")},
               {"f0", outputOf(metalness, "f0")}};
  const Value roughness = pinOf(block, "roughness");
  slab["roughness"] = roughness.is_null() ? Value(0.5) : roughness;
  const Value anisotropy = pinOf(block, "anisotropy");
  if (!anisotropy.is_null() && !isLiteral(anisotropy, 0)) {
    slab["anisotropy"] = anisotropy;
    if (const Value t = pinOf(block, "tangent"); !t.is_null()) slab["tangent"] = t;
  }
  if (!normal.is_null()) slab["normal"] = normal;
  const Value emissive = pinOf(block, "emissive_color");
  if (!emissive.is_null() && !isLiteral(emissive, 0)) slab["emissive"] = emissive;
  return w.node("slab", slab);
}

Value expandDefaultLit(const Json& block, NodeWriter& w) {
  return withOpacity(block, w, defaultLitSlab(block, w, pinOf(block, "normal")));
}

/// UE4's ClearCoat model: the coat takes `normal`, the base `bottom_normal`
/// (the coat's normal when absent).
Value expandClearCoat(const Json& block, NodeWriter& w) {
  const Value bottom = pinOf(block, "bottom_normal");
  const Value normal = pinOf(block, "normal");
  Value root = defaultLitSlab(block, w, bottom.is_null() ? normal : bottom);
  LayeredSurface coat;
  coat.coatWeight = pinOf(block, "clear_coat");
  if (coat.coatWeight.is_null()) coat.coatWeight = 1.0;
  if (!isLiteral(coat.coatWeight, 0)) {
    coat.coatF0 = 0.04;
    const Value r = pinOf(block, "clear_coat_roughness");
    coat.coatRoughness = r.is_null() ? Value(0.1) : r;  // UE's ClearCoatRoughness default
    coat.coatNormal = normal;
    root = coatedRoot(coat, w, root);
  }
  return withOpacity(block, w, root);
}

Value expandUnlit(const Json& block, NodeWriter& w) {
  Json unlit = {{"kind", "unlit"}};
  const Value emissive = pinOf(block, "emissive_color");
  if (!emissive.is_null()) unlit["emissive"] = emissive;
  return withOpacity(block, w, w.node("unlit", unlit));
}

}  // namespace

BuildingBlock ue4DefaultLitBlock() { return {{"ue4_default_lit", defaultLitPins()}, expandDefaultLit}; }

BuildingBlock clearCoatBlock() {
  std::vector<BlockPin> pins = defaultLitPins();
  pins.push_back({"clear_coat", Kind::Float, 0, 1});
  pins.push_back({"clear_coat_roughness", Kind::Float, 0, 1});
  pins.push_back({"bottom_normal", Kind::Vec3});
  return {{"clear_coat", pins}, expandClearCoat};
}

BuildingBlock ue4UnlitBlock() {
  return {{"ue4_unlit", {{"emissive_color", Kind::Color, 0, 1e300}, {"opacity", Kind::Float, 0, 1}}}, expandUnlit};
}

}  // namespace substratec::blocks
