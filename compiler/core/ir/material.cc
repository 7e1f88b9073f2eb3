#include "ir/material.h"

#include <fmt/format.h>

namespace substratec {

std::string_view blendModeName(BlendMode m) { return enumName(kBlendModeNames, m, "opaque"); }

namespace {
constexpr double kInf = 1e300;
constexpr int kNoGeo = -1;
constexpr std::uint8_t kAll = kPinOfSlab | kPinOfUnlit | kPinOfHair | kPinOfFogCloud | kPinOfEye | kPinOfWater,
                       kSlabHair = kPinOfSlab | kPinOfHair, kSlabEye = kPinOfSlab | kPinOfEye;
// name, type, color, default, geometry default, lo, hi, kinds
const SlabPinInfo kPins[kSlabPinCount] = {
    {"diffuse_albedo", VType::Vec3, true, 0.18, kNoGeo, 0, 1, kSlabEye},  // an eye's: the sclera's and iris's
    {"f0", VType::Vec3, true, 0.04, kNoGeo, 0, 1},
    {"f90", VType::Vec3, true, 1.0, kNoGeo, 0, 1},
    // A hair's: longitudinal (Chiang's beta_m); an eye's: the cornea's.
    {"roughness", VType::Float, false, 0.5, kNoGeo, 0, 1, kSlabHair | kPinOfEye | kPinOfWater},
    {"anisotropy", VType::Float, false, 0.0, kNoGeo, -1, 1},
    // An eye's: the cornea's and sclera's (UE's Cornea Normal).
    {"normal", VType::Vec3, false, 0.0, static_cast<int>(GeometryAttr::Normal), -1, 1, kPinOfSlab | kPinOfUnlit | kPinOfEye | kPinOfWater},
    {"tangent", VType::Vec3, false, 0.0, static_cast<int>(GeometryAttr::Tangent), -1, 1, kSlabHair},  // a hair's fibre
    // An eye's: the sclera's (UE's subsurface profile, by its mean free path).
    {"sss_mfp", VType::Vec3, true, 0.0, kNoGeo, 0, kInf, kSlabEye},
    {"sss_mfp_scale", VType::Float, false, 1.0, kNoGeo, 0, kInf, kSlabEye},
    {"sss_phase_anisotropy", VType::Float, false, 0.0, kNoGeo, -1, 1, kSlabEye},
    {"emissive", VType::Vec3, true, 0.0, kNoGeo, 0, kInf, kAll},
    {"second_roughness", VType::Float, false, 0.5, kNoGeo, 0, 1},
    {"second_roughness_weight", VType::Float, false, 0.0, kNoGeo, 0, 1},
    {"fuzz_amount", VType::Float, false, 0.0, kNoGeo, 0, 1},
    {"fuzz_color", VType::Vec3, true, 0.0, kNoGeo, 0, 1},
    {"fuzz_roughness", VType::Float, false, 0.5, kNoGeo, 0, 1},
    {"glint_value", VType::Float, false, 1.0, kNoGeo, 0, 1},
    {"glint_uv", VType::Vec2, false, 0.0, static_cast<int>(GeometryAttr::Uv0), -kInf, kInf},
    // The unlit's: what it lets through from behind (or below), along the normal.
    {"transmittance", VType::Vec3, true, 1.0, kNoGeo, 0, 1, kPinOfUnlit},
    // The hair's (runtime_shaders/substrate_hair.h; UE's Hair BSDF, Chiang et al. 2016's parameters):
    // the colour of dense hair (its absorption follows), azimuthal roughness (beta_n), the fibre's
    // index of refraction, its cuticle scales' tilt in degrees, and the dense-hair scattering.
    {"base_color", VType::Vec3, true, 0.0, kNoGeo, 0, 1, kPinOfHair | kPinOfWater},  // a water's: its top material's
    {"azimuthal_roughness", VType::Float, false, 0.5, kNoGeo, 0, 1, kPinOfHair},
    {"ior", VType::Float, false, 1.55, kNoGeo, 1, 3, kPinOfHair},
    {"cuticle_angle", VType::Float, false, 2.0, kNoGeo, -20, 20, kPinOfHair},
    {"scatter", VType::Float, false, 0.0, kNoGeo, 0, 1, kPinOfHair},
    // The volumetric fog cloud's (runtime_shaders/substrate_fog_cloud.h; UE's Volumetric Fog Cloud
    // BSDF): single-scattering albedo, extinction in 1/m (the medium's density) and the ambient
    // occlusion of the ambient light it scatters. Its emissive is radiance emitted per metre.
    {"albedo", VType::Vec3, true, 0.0, kNoGeo, 0, 1, kPinOfFogCloud},
    {"extinction", VType::Vec3, true, 0.0, kNoGeo, 0, kInf, kPinOfFogCloud},
    {"ambient_occlusion", VType::Float, false, 1.0, kNoGeo, 0, 1, kPinOfFogCloud},
    // The eye's (runtime_shaders/substrate_eye.h; UE's Eye BSDF): the iris's normal (its lighting),
    // the iris plane's normal (the caustic's axis), the iris mask (1: iris, 0: sclera) and the
    // iris distance (how deep the iris sits behind the cornea: the caustic's concavity).
    {"iris_normal", VType::Vec3, false, 0.0, static_cast<int>(GeometryAttr::Normal), -1, 1, kPinOfEye},
    {"iris_plane_normal", VType::Vec3, false, 0.0, static_cast<int>(GeometryAttr::Normal), -1, 1, kPinOfEye},
    {"iris_mask", VType::Float, false, 0.0, kNoGeo, 0, 1, kPinOfEye},
    {"iris_distance", VType::Float, false, 0.0, kNoGeo, 0, 1, kPinOfEye},
    // The single-layer water's (runtime_shaders/substrate_water.h; UE's Single Layer Water BSDF):
    // its top material's metalness and specular (F0 = 0.08 specular, the water's own too), that
    // top material's opacity over the water, the water body's single-scattering albedo, extinction
    // in 1/m, Henyey-Greenstein phase anisotropy, and the scale of what is seen behind the water.
    {"metallic", VType::Float, false, 0.0, kNoGeo, 0, 1, kPinOfWater},
    {"specular", VType::Float, false, 0.5, kNoGeo, 0, 1, kPinOfWater},
    {"top_material_opacity", VType::Float, false, 0.0, kNoGeo, 0, 1, kPinOfWater},
    {"water_albedo", VType::Vec3, true, 0.0, kNoGeo, 0, 1, kPinOfWater},
    {"water_extinction", VType::Vec3, true, 0.0, kNoGeo, 0, kInf, kPinOfWater},
    {"water_phase_g", VType::Float, false, 0.0, kNoGeo, -1, 1, kPinOfWater},
    {"color_scale_behind_water", VType::Vec3, true, 1.0, kNoGeo, 0, kInf, kPinOfWater},
};
}  // namespace

const SlabPinInfo& slabPinInfo(SlabPin p) { return kPins[static_cast<int>(p)]; }

std::optional<SlabPin> slabPinByName(std::string_view name) {
  for (int i = 0; i < kSlabPinCount; ++i)
    if (kPins[i].name == name) return static_cast<SlabPin>(i);
  return std::nullopt;
}

bool bsdfTakesPin(BsdfKind k, SlabPin p) {
  static constexpr std::uint8_t kBit[] = {kPinOfSlab, kPinOfUnlit, kPinOfHair, kPinOfFogCloud, kPinOfEye, kPinOfWater};  // BsdfKind order
  return (kPins[static_cast<int>(p)].kinds & kBit[static_cast<int>(k)]) != 0;
}

std::string_view bsdfKindName(BsdfKind k) {
  static constexpr std::string_view kNames[] = {"slab", "unlit", "hair", "volumetric_fog_cloud", "eye",
                                                 "single_layer_water"};  // BsdfKind order
  return kNames[static_cast<int>(k)];
}

bool bsdfIsClosure(BsdfKind k) { return k != BsdfKind::Unlit && k != BsdfKind::FogCloud; }
bool bsdfIsWholeMaterial(BsdfKind k) { return k != BsdfKind::Slab && k != BsdfKind::Unlit; }

std::optional<BsdfKind> bsdfKindByName(std::string_view name) {
  for (BsdfKind k : {BsdfKind::Slab, BsdfKind::Unlit, BsdfKind::Hair, BsdfKind::FogCloud, BsdfKind::Eye, BsdfKind::Water})
    if (bsdfKindName(k) == name) return k;
  return std::nullopt;
}

std::string_view sssTypeName(SssType t) { return enumName(kSssTypeNames, t, "none"); }

std::string_view featureName(int bit) {
  static constexpr std::string_view names[kFeatureCount] = {
      "f90", "anisotropy", "sss", "haze", "fuzz", "glint", "specular_profile", "emissive", "medium", "hair", "eye", "water"};
  return bit >= 0 && bit < kFeatureCount ? names[bit] : "?";
}

std::string_view treeOpName(TreeOp op) { return enumName(kTreeOpNames, op, "?"); }

bool isUnlitLeaf(const Material& m, const TreeNode& n) { return isLeafOfKind(m, n, BsdfKind::Unlit); }

bool isHairLeaf(const Material& m, const TreeNode& n) { return isLeafOfKind(m, n, BsdfKind::Hair); }

bool isLeafOfKind(const Material& m, const TreeNode& n, BsdfKind k) {
  return n.op == TreeOp::Slab && n.slab >= 0 && m.slabs[n.slab].kind == k;
}

bool isWaterMaterial(const Material& m) {
  return m.root >= 0 && isLeafOfKind(m, m.nodes[m.root], BsdfKind::Water);
}

bool isVolumeMaterial(const Material& m) {
  return m.root >= 0 && isLeafOfKind(m, m.nodes[m.root], BsdfKind::FogCloud);
}

std::string_view nodeOpName(const Material& m, const TreeNode& n) {
  static constexpr std::string_view kLeafNames[] = {"SLAB", "UNLIT", "HAIR", "FOG_CLOUD", "EYE", "WATER"};  // BsdfKind order
  if (n.op != TreeOp::Slab || n.slab < 0) return treeOpName(n.op);
  return kLeafNames[static_cast<int>(m.slabs[n.slab].kind)];
}

int Material::inputIndex(std::string_view n) const {
  for (std::size_t i = 0; i < inputs.size(); ++i)
    if (inputs[i].name == n) return static_cast<int>(i);
  return -1;
}

std::string renderValue(const Material& m, ValueId v, int budget) {
  const ValueNode& n = m.values.node(v);
  if (n.op == Op::Input) return "$" + m.inputs[n.attr].name;
  if (n.op == Op::Const || n.op == Op::Geometry) return m.values.render(v, 0);
  if (budget <= 0) return "...";
  std::string s;
  if (n.op == Op::Sample) {
    s = fmt::format("texture(${}, ", m.inputs[n.attr].name);
    return s + renderValue(m, n.args[0], budget - 1) + ")";
  }
  s = std::string(opName(n.op));
  if (n.op == Op::Swizzle) {
    s += ".";
    int k = componentCount(n.type);
    for (int i = 0; i < k; ++i) s += "xyzw"[(n.attr >> (2 * i)) & 3];
  } else if (isHelper(n.op) && (n.op == Op::MetalnessToDiffuseF0 || n.op == Op::HazinessToSecondRoughness ||
                                n.op == Op::TransmittanceToMfp || n.op == Op::ThinFilm)) {
    s += fmt::format("[{}]", n.attr);
  }
  s += "(";
  for (int i = 0; i < n.argCount; ++i) s += (i ? ", " : "") + renderValue(m, n.args[i], budget - 1);
  return s + ")";
}

std::vector<int> slabsInTreeOrder(const Material& m) {
  std::vector<int> out;
  if (m.root < 0) return out;
  std::vector<int> stack{m.root};
  while (!stack.empty()) {
    int i = stack.back();
    stack.pop_back();
    const TreeNode& n = m.nodes[i];
    if (n.op == TreeOp::Slab) {
      out.push_back(n.slab);
      continue;
    }
    if (n.right >= 0) stack.push_back(n.right);
    if (n.left >= 0) stack.push_back(n.left);
  }
  return out;
}

}  // namespace substratec
