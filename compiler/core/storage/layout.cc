#include "storage/layout.h"

#include <fmt/format.h>

namespace substratec {

std::string_view layoutClassName(LayoutClass c) {
  switch (c) {
    case LayoutClass::Simple: return "SIMPLE";
    case LayoutClass::Single: return "SINGLE";
    case LayoutClass::Complex: return "COMPLEX";
    case LayoutClass::Special: return "SPECIAL";
    case LayoutClass::Volume: return "VOLUME";
  }
  return "?";
}

namespace {

/// The class, basis-0 elision and field list of a layout whose closures and
/// basis count are set (docs/storage.md, "Layout classes" and "Order of fields").
void finishLayout(StorageLayout& L) {
  std::uint16_t all = 0;
  for (const auto& c : L.closures) all |= c.storedFeatures;
  const int count = static_cast<int>(L.closures.size());
  const bool multi = count > 1;
  // Class.
  if (all & (kFeatGlint | kFeatSpecularProfile | kFeatHair | kFeatEye)) L.layoutClass = LayoutClass::Special;
  else if (multi || (all & kFeatAnisotropy)) L.layoutClass = LayoutClass::Complex;
  else if (all || (count > 0 && L.closures[0].storesWeight)) L.layoutClass = LayoutClass::Single;
  else L.layoutClass = LayoutClass::Simple;

  // Bases: a lone closure's normal is the top-layer normal; with several,
  // basis 0's normal is elided when every top-layer closure uses basis 0.
  bool topShare = true;
  for (const auto& c : L.closures)
    if (c.isTop && c.basis != 0) topShare = false;
  L.basis0NormalElided = topShare;

  auto add = [&](std::string name, int b, std::string enc, int closure = -1, int basis = -1,
                 std::uint16_t feature = 0) {
    L.fields.push_back({std::move(name), b, std::move(enc), closure, basis, feature});
    L.totalBits += b;
  };
  add("header", bits::kHeader,
      multi        ? "layout class 2 | closure count-1 3 | basis count 4 | reserved 7"
      : count == 0 ? "layout class 2 (SIMPLE) | no closure (bit 14): an unlit material"
      : (all & kFeatHair) ? "layout class 2 (SPECIAL) | feature bits 8 | sss type 2 | hair (bit 12) | reserved 3"
      : (all & kFeatEye)  ? "layout class 2 (SPECIAL) | feature bits 8 | sss type 2 | reserved 1 | eye (bit 13) | reserved 2"
                   : "layout class 2 | feature bits 8 | sss type 2 | reserved 4");
  for (int i = 0; i < count; ++i) {
    const ClosureLayout& c = L.closures[i];
    const std::string p = fmt::format("closure{}.", i);
    if (multi)
      add(p + "header", bits::kClosureHeader,
          "basis id 3 | is top 1 | feature bits 8 | sss type 2 | extra interfaces 2", i);
    add(p + "diffuse_albedo", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);  // a hair's base colour
    if (c.storedFeatures & kFeatHair) {  // a fibre has no F0: its lobes' own parameters instead
      add(p + "hair", bits::kHair,
          "azimuthal roughness unorm8 | (ior - 1) / 2 unorm8 | cuticle angle snorm8 over 20 deg | scatter unorm8", i,
          -1, kFeatHair);
    } else if (c.storedFeatures & kFeatEye) {  // a cornea's F0 is fixed (0.04): the iris instead
      add(p + "iris_normal", bits::kIrisNormal, "octahedral 2 x snorm16", i, -1, kFeatEye);
      add(p + "iris", bits::kIris, "iris plane normal octahedral 2 x unorm8 | iris mask unorm8 | iris distance unorm8",
          i, -1, kFeatEye);
    } else {
      add(p + "f0", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    }
    add(p + "roughness", bits::kRoughness, "unorm8", i);
    if (c.storesWeight) add(p + "weight", bits::kGreyWeight, "unorm8", i);
    if (!c.isTop) add(p + "top_transmittance", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    if (c.storesCoverageAbove) add(p + "coverage_above", bits::kCoverageAbove, "unorm8", i);
    const std::uint16_t f = c.storedFeatures;
    if (f & kFeatF90) add(p + "f90", bits::kColor, "unorm 7/7/6 of sqrt(c)", i, -1, kFeatF90);
    if (f & kFeatSss)
      add(p + "sss", bits::kSss, "mfp: 3 x unorm8 of log2(mfp) in [-24, 8]; phase: snorm4", i, -1, kFeatSss);
    if (f & kFeatHaze) add(p + "haze", bits::kHaze, "second roughness unorm8 | weight unorm8", i, -1, kFeatHaze);
    if (f & kFeatFuzz)
      add(p + "fuzz", bits::kFuzz, "amount unorm6 | color 7/7/6 sqrt | roughness unorm6", i, -1, kFeatFuzz);
    if (f & kFeatAnisotropy) add(p + "anisotropy", bits::kAnisotropy, "snorm8", i, -1, kFeatAnisotropy);
    if (f & kFeatSpecularProfile)
      add(p + "specular_profile", bits::kSpecularProfile, "profile index uint8", i, -1, kFeatSpecularProfile);
    if (f & kFeatGlint)
      add(p + "glint", bits::kGlint, "density unorm8 | uv 2 x float32 | duv/dx, duv/dy 4 x half", i, -1, kFeatGlint);
  }
  for (int b = 0; b < L.basisCount; ++b) {
    const std::string p = fmt::format("basis{}.", b);
    bool anisotropic = false;
    for (const auto& c : L.closures)
      if (c.basis == b && (c.storedFeatures & kTangentFeatures)) anisotropic = true;
    bool elided = !multi || (b == 0 && L.basis0NormalElided);
    if (!elided) add(p + "normal", bits::kNormal, "octahedral 2 x snorm16", -1, b);
    if (anisotropic) add(p + "tangent_angle", bits::kTangentAngle, "unorm14 of angle/2pi around the normal", -1, b);
  }
}

/// A volume's froxel payload: what `<name>_sample` returns, as
/// substrate_fog_cloud_pack stores it (docs/storage.md, "Volumetric fog cloud").
StorageLayout volumeLayout() {
  StorageLayout L;
  L.layoutClass = LayoutClass::Volume;
  auto add = [&](std::string name, int b, std::string enc) {
    L.fields.push_back({std::move(name), b, std::move(enc)});
    L.totalBits += b;
  };
  add("fog.albedo", bits::kFogAlbedo, "unorm8 x 3, linear");
  add("fog.ambient_occlusion", bits::kFogOcclusion, "unorm8");
  add("fog.extinction", bits::kRgb9e5, "RGB9E5 shared exponent (1/m, up to 65408)");
  add("fog.emissive", bits::kRgb9e5, "RGB9E5 shared exponent (radiance per metre, up to 65408)");
  return L;
}

}  // namespace

StorageLayout computeLayout(const Material& m, const TreeInfo& info) {
  if (isVolumeMaterial(m)) return volumeLayout();  // no closure: the sample's payload
  StorageLayout L;
  for (int s : info.slabOrder) {
    const Slab& slab = m.slabs[s];
    const int node = info.slabNode[s];
    ClosureLayout c;
    c.slab = s;
    c.basis = slab.basis;
    c.isTop = info.isTop[node];
    c.storedFeatures = slab.features & kStoredFeatureMask;
    c.storesWeight = !info.unitWeight[node];
    c.storesCoverageAbove = !c.isTop && !info.unitCoverageAbove[node];
    c.extraInterfaces = storedExtraInterfaces(info.interfacesAbove[node]);
    L.closures.push_back(c);
  }
  L.basisCount = static_cast<int>(m.bases.size());  // 0 without closures (an unlit material)
  finishLayout(L);
  return L;
}

StorageLayout simpleLayoutOf(const StorageLayout& L, int k) {
  StorageLayout S;
  ClosureLayout c = L.closures.at(k);
  c.basis = 0;
  c.isTop = true;
  c.storesWeight = c.storesCoverageAbove = false;
  c.storedFeatures = 0;
  c.extraInterfaces = 0;
  S.closures = {c};
  S.basisCount = 1;
  finishLayout(S);
  return S;
}

namespace {

/// The product of mix and coverage weights on the path of slab node `node`
/// to the root is a constant (every factor is): it is never 0 or 1 at run
/// time unless it is so statically. Not under a fuzzy layer, whose factor
/// follows the view (tree_info.h, fuzzyLayer).
bool constantWeight(const Material& m, const TreeInfo& t, int node) {
  const Slab& s = m.slabs[m.nodes[node].slab];
  if (s.coverage != kNoValue && !m.values.isConst(s.coverage)) return false;
  for (int x = node, p = t.parent[node]; p >= 0; x = p, p = t.parent[p]) {
    const TreeNode& op = m.nodes[p];
    switch (op.op) {
      case TreeOp::Vertical:
        if (op.right == x && fuzzyLayer(t, op.left)) return false;
        break;
      case TreeOp::Horizontal:
      case TreeOp::CoverageWeight:
        if (!m.values.isConst(op.a)) return false;
        break;
      case TreeOp::Select:
        if (!m.values.isConst(op.a) || !m.values.isConst(op.b)) return false;
        break;
      default: break;
    }
  }
  return true;
}

}  // namespace

std::vector<int> runtimeSimpleClosures(const Material& m, const StorageLayout& L) {
  std::vector<int> out;
  if (L.layoutClass == LayoutClass::Simple) return out;
  const TreeInfo t = analyzeTree(m);
  auto pinVaries = [&](const Slab& s, SlabPin p) { return !m.values.isConst(s.pin(p)); };
  for (int k = 0; k < static_cast<int>(L.closures.size()); ++k) {
    const ClosureLayout& c = L.closures[k];
    const Slab& s = m.slabs[c.slab];
    bool possible = !(c.storesWeight && constantWeight(m, t, t.slabNode[c.slab]));  // its weight can be 1
    possible = possible && (c.isTop || c.storesCoverageAbove);                        // nothing above it can remain
    for (int j = 0; j < static_cast<int>(L.closures.size()) && possible; ++j)
      if (j != k)  // every other closure's weight can be 0
        possible = L.closures[j].storesWeight && !constantWeight(m, t, t.slabNode[L.closures[j].slab]);
    const std::uint16_t f = c.storedFeatures;
    if (f & kFeatF90) possible = possible && pinVaries(s, SlabPin::F90);
    if (f & kFeatAnisotropy) possible = possible && pinVaries(s, SlabPin::Anisotropy);
    // Wrap lighting replaces the diffuse model even without a medium; the
    // other SSS types light as the diffuse model does.
    if (f & kFeatSss) possible = possible && s.sssType != SssType::Wrap && pinVaries(s, SlabPin::SssMfp);
    if (f & kFeatHaze) possible = possible && pinVaries(s, SlabPin::SecondRoughnessWeight);
    if (f & kFeatFuzz) possible = possible && pinVaries(s, SlabPin::FuzzAmount);
    if (f & kFeatGlint) possible = possible && pinVaries(s, SlabPin::GlintValue);
    if (f & (kFeatSpecularProfile | kFeatHair | kFeatEye)) possible = false;  // a static choice; a fibre is never a slab
    if (possible) out.push_back(k);
  }
  return out;
}

}  // namespace substratec
