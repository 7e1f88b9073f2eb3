// The UE4 shading models as building blocks (the course notes' "UE4 Default
// Shading", "UE4 Unlit Shading", the abstracted "Clear Coat" and "Cloth"
// nodes, and seed 004's Legacy Conversion node), with UE's material-attribute
// defaults (BaseColor 0, Metallic 0, Specular 0.5, Roughness 0.5, Opacity 1):
//   ue4_default_lit    one slab: diffuse and F0 from metalness_to_diffuse_f0
//                      (diffuse = base·(1 − metallic), F0 = lerp(0.08·specular,
//                      base, metallic)), the legacy path's 12 bytes
//   clear_coat         the default-lit slab under a coat of F0 0.04 (IOR 1.5),
//                      its weight clear_coat and roughness clear_coat_roughness
//   cloth              the default-lit slab with fuzz: amount `cloth`, colour
//                      fuzz_color, the slab's roughness
//   ue4_unlit          the unlit BSDF: emissive_color, no closure
//   legacy_conversion  one of UE4's shading models (`shading_model`) from the
//                      attributes it reads (docs/format.md has the table)
// each under a coverage weight when an opacity other than 1 is given (but the
// water's, whose opacity is its top material's).
#include "blocks/blocks.h"
#include "blocks/gltf_pbr.h"
#include "blocks/layered_surface.h"

namespace substratec::blocks {

namespace {

using Kind = BlockPin::Kind;
constexpr double kBig = 1e300;

/// The pins of UE4's default-lit model.
std::vector<BlockPin> defaultLitPins() {
  return {{"base_color", Kind::Color, 0, 1}, {"metallic", Kind::Float, 0, 1},
          {"specular", Kind::Float, 0, 1},   {"roughness", Kind::Float, 0, 1},
          {"anisotropy", Kind::Float, -1, 1}, {"tangent", Kind::Vec3},
          {"normal", Kind::Vec3},             {"emissive_color", Kind::Color, 0, kBig},
          {"opacity", Kind::Float, 0, 1}};
}

bool given(const Value& v, double neutral) { return !v.is_null() && !isLiteral(v, neutral); }

/// `root` under a coverage weight of the block's opacity (none when absent or 1).
Value withOpacity(const Json& block, NodeWriter& w, const Value& root) {
  const Value opacity = pinOf(block, "opacity");
  if (!given(opacity, 1)) return root;
  return w.node("presence", Json{{"kind", "coverage_weight"}, {"a", root}, {"weight", opacity}});
}

/// The default-lit slab's body (without its opacity); `normal` its normal.
Json defaultLitSlab(const Json& block, NodeWriter& w, const Value& normal) {
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
  if (given(anisotropy, 0)) {
    slab["anisotropy"] = anisotropy;
    if (const Value t = pinOf(block, "tangent"); !t.is_null()) slab["tangent"] = t;
  }
  if (!normal.is_null()) slab["normal"] = normal;
  const Value emissive = pinOf(block, "emissive_color");
  if (given(emissive, 0)) slab["emissive"] = emissive;
  return slab;
}

Value expandDefaultLit(const Json& block, NodeWriter& w) {
  return withOpacity(block, w, w.node("slab", defaultLitSlab(block, w, pinOf(block, "normal"))));
}

/// UE4's ClearCoat model: the coat takes `normal`, the base `bottom_normal`
/// (the coat's normal when absent).
Value expandClearCoat(const Json& block, NodeWriter& w) {
  const Value bottom = pinOf(block, "bottom_normal");
  const Value normal = pinOf(block, "normal");
  Value root = w.node("slab", defaultLitSlab(block, w, bottom.is_null() ? normal : bottom));
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

/// UE4's Cloth model: the fuzz's colour is `colorPin` (UE's Fuzz Color).
Value clothOf(const Json& block, NodeWriter& w, const char* colorPin) {
  Json slab = defaultLitSlab(block, w, pinOf(block, "normal"));
  const Value amount = pinOf(block, "cloth");
  if (!amount.is_null() && isLiteral(amount, 0)) return withOpacity(block, w, w.node("slab", slab));
  const Value color = pinOf(block, colorPin);
  slab["fuzz_amount"] = amount.is_null() ? Value(1.0) : amount;
  slab["fuzz_color"] = color.is_null() ? Value(1.0) : color;
  slab["fuzz_roughness"] = slab["roughness"];
  return withOpacity(block, w, w.node("slab", slab));
}

Value expandCloth(const Json& block, NodeWriter& w) { return clothOf(block, w, "fuzz_color"); }

Value expandUnlit(const Json& block, NodeWriter& w) {
  Json unlit = {{"kind", "unlit"}};
  const Value emissive = pinOf(block, "emissive_color");
  if (!emissive.is_null()) unlit["emissive"] = emissive;
  return withOpacity(block, w, w.node("unlit", unlit));
}

// --- legacy_conversion: one unit per UE4 shading model ----------------------

/// Subsurface, PreintegratedSkin, TwoSidedFoliage: the default-lit slab whose
/// medium lets light wrap from behind the horizon, per channel w =
/// min(subsurface_color, 0.95), mfp = SUBSTRATE_SSS_WRAP_MFP_SCALE·w/(1 − w)
/// (the glTF diffuse transmission's wrap): the course's 16-byte legacy path.
Value legacySubsurface(const Json& block, NodeWriter& w) {
  Json slab = defaultLitSlab(block, w, pinOf(block, "normal"));
  const Value color = pinOf(block, "subsurface_color");
  const Value wrap = namedValue(w, "wrap", vmin(color.is_null() ? Value(1.0) : color, 0.95));
  slab["sss_mfp"] = divide(mul(wrap, kWrapMfpScale), oneMinus(wrap));
  slab["sss_type"] = "wrap";
  return w.node("slab", slab);  // the opacity is UE4's subsurface density here, not a presence
}

/// SubsurfaceProfile: the profile stood for by its mean free path
/// (subsurface_mfp, metres), diffused in screen space (sss_type diffusion).
Value legacySubsurfaceProfile(const Json& block, NodeWriter& w) {
  Json slab = defaultLitSlab(block, w, pinOf(block, "normal"));
  if (const Value mfp = pinOf(block, "subsurface_mfp"); given(mfp, 0)) {
    slab["sss_mfp"] = mfp;
    slab["sss_type"] = "diffusion";
  }
  return withOpacity(block, w, w.node("slab", slab));
}

/// Hair: UE4's BaseColor, Scatter, Roughness and Tangent as the hair BSDF's.
Value legacyHair(const Json& block, NodeWriter& w) {
  Json hair = {{"kind", "hair"}};
  const Value base = pinOf(block, "base_color");
  hair["base_color"] = base.is_null() ? Value(0.0) : base;
  for (const auto& [from, to] : {std::pair{"scatter", "scatter"}, {"roughness", "roughness"}, {"tangent", "tangent"},
                                 {"emissive_color", "emissive"}})
    if (const Value v = pinOf(block, from); !v.is_null()) hair[to] = v;
  return withOpacity(block, w, w.node("hair", hair));
}

/// Eye: the sclera and iris colour base_color, the cornea's roughness and
/// normal, the iris's mask, distance and normals, the sclera's subsurface_mfp.
Value legacyEye(const Json& block, NodeWriter& w) {
  Json eye = {{"kind", "eye"}};
  const Value base = pinOf(block, "base_color");
  eye["diffuse_albedo"] = base.is_null() ? Value(0.0) : base;
  for (const auto& [from, to] : {std::pair{"roughness", "roughness"}, {"normal", "normal"}, {"iris_mask", "iris_mask"},
                                 {"iris_distance", "iris_distance"}, {"iris_normal", "iris_normal"},
                                 {"iris_plane_normal", "iris_plane_normal"}, {"subsurface_mfp", "sss_mfp"},
                                 {"emissive_color", "emissive"}})
    if (const Value v = pinOf(block, from); !v.is_null()) eye[to] = v;
  return withOpacity(block, w, w.node("eye", eye));
}

/// SingleLayerWater: the top material and UE4's water coefficients:
/// extinction = scattering + absorption, albedo = scattering / extinction;
/// the opacity is the top material's over the water.
Value legacyWater(const Json& block, NodeWriter& w) {
  Json water = {{"kind", "single_layer_water"}};
  const Value base = pinOf(block, "base_color");
  water["base_color"] = base.is_null() ? Value(0.0) : base;
  for (const auto& [from, to] : {std::pair{"metallic", "metallic"}, {"specular", "specular"}, {"roughness", "roughness"},
                                 {"normal", "normal"}, {"opacity", "top_material_opacity"},
                                 {"water_phase_g", "water_phase_g"}, {"color_scale_behind_water", "color_scale_behind_water"},
                                 {"emissive_color", "emissive"}})
    if (const Value v = pinOf(block, from); !v.is_null()) water[to] = v;
  const Value scattering = pinOf(block, "water_scattering"), absorption = pinOf(block, "water_absorption");
  if (!scattering.is_null() || !absorption.is_null()) {
    const Value s = namedValue(w, "water_scattering", scattering.is_null() ? Value(0.0) : scattering);
    const Value extinction = namedValue(w, "water_extinction", add(s, absorption.is_null() ? Value(0.0) : absorption));
    water["water_extinction"] = extinction;
    water["water_albedo"] = divide(s, vmax(extinction, 1e-6));
  }
  return w.node("water", water);
}

/// ThinTranslucent: the default-lit slab whose medium lets transmittance_color
/// through the surface once (transmittance_to_mfp over 0.1 mm).
Value legacyThinTranslucent(const Json& block, NodeWriter& w) {
  Json slab = defaultLitSlab(block, w, pinOf(block, "normal"));
  const Value t = pinOf(block, "transmittance_color");
  const Value medium = w.node("transmission_medium", Json{{"kind", "transmittance_to_mfp"},
                                                          {"transmittance", t.is_null() ? Value(1.0) : t},
                                                          {"thickness", 0.0001}});
  slab["sss_mfp"] = outputOf(medium, "mfp");
  return withOpacity(block, w, w.node("slab", slab));
}

constexpr const char* kShadingModels[] = {"default_lit", "unlit", "subsurface", "preintegrated_skin", "clear_coat",
                                          "subsurface_profile", "two_sided_foliage", "cloth", "hair", "eye",
                                          "single_layer_water", "thin_translucent"};

Value expandLegacy(const Json& block, NodeWriter& w) {
  const std::string model = block.value("shading_model", std::string("default_lit"));
  if (model == "unlit") return expandUnlit(block, w);
  if (model == "clear_coat") return expandClearCoat(block, w);
  if (model == "subsurface" || model == "preintegrated_skin" || model == "two_sided_foliage")
    return legacySubsurface(block, w);
  if (model == "subsurface_profile") return legacySubsurfaceProfile(block, w);
  if (model == "cloth") return clothOf(block, w, "subsurface_color");  // UE4's Fuzz Color is its SubsurfaceColor
  if (model == "hair") return legacyHair(block, w);
  if (model == "eye") return legacyEye(block, w);
  if (model == "single_layer_water") return legacyWater(block, w);
  if (model == "thin_translucent") return legacyThinTranslucent(block, w);
  return expandDefaultLit(block, w);
}

}  // namespace

BuildingBlock ue4DefaultLitBlock() {
  return {{"ue4_default_lit", defaultLitPins()}, [](const Json& b, BlockContext& c) { return expandDefaultLit(b, c.w); }};
}

BuildingBlock clearCoatBlock() {
  std::vector<BlockPin> pins = defaultLitPins();
  pins.push_back({"clear_coat", Kind::Float, 0, 1});
  pins.push_back({"clear_coat_roughness", Kind::Float, 0, 1});
  pins.push_back({"bottom_normal", Kind::Vec3});
  return {{"clear_coat", pins}, [](const Json& b, BlockContext& c) { return expandClearCoat(b, c.w); }};
}

BuildingBlock clothBlock() {
  std::vector<BlockPin> pins = defaultLitPins();
  pins.push_back({"cloth", Kind::Float, 0, 1});
  pins.push_back({"fuzz_color", Kind::Color, 0, 1});
  return {{"cloth", pins}, [](const Json& b, BlockContext& c) { return expandCloth(b, c.w); }};
}

BuildingBlock ue4UnlitBlock() {
  return {{"ue4_unlit", {{"emissive_color", Kind::Color, 0, kBig}, {"opacity", Kind::Float, 0, 1}}},
          [](const Json& b, BlockContext& c) { return expandUnlit(b, c.w); }};
}

BuildingBlock legacyConversionBlock() {
  std::vector<BlockPin> pins = {{"shading_model", Kind::Choice, -kBig, kBig, /*required=*/true,
                                 std::vector<const char*>(std::begin(kShadingModels), std::end(kShadingModels))}};
  for (const BlockPin& p : defaultLitPins()) pins.push_back(p);
  const std::vector<BlockPin> more = {
      {"subsurface_color", Kind::Color, 0, 1},  {"subsurface_mfp", Kind::Color, 0, kBig},
      {"clear_coat", Kind::Float, 0, 1},        {"clear_coat_roughness", Kind::Float, 0, 1},
      {"bottom_normal", Kind::Vec3},            {"cloth", Kind::Float, 0, 1},
      {"scatter", Kind::Float, 0, 1},           {"iris_mask", Kind::Float, 0, 1},
      {"iris_distance", Kind::Float, 0, 1},     {"iris_normal", Kind::Vec3},
      {"iris_plane_normal", Kind::Vec3},        {"water_scattering", Kind::Color, 0, kBig},
      {"water_absorption", Kind::Color, 0, kBig}, {"water_phase_g", Kind::Float, -1, 1},
      {"color_scale_behind_water", Kind::Color, 0, kBig}, {"transmittance_color", Kind::Color, 0, 1}};
  pins.insert(pins.end(), more.begin(), more.end());
  return {{"legacy_conversion", pins}, [](const Json& b, BlockContext& c) { return expandLegacy(b, c.w); }};
}

}  // namespace substratec::blocks
