#include "storage/layout.h"

#include <fmt/format.h>

namespace substratec {

std::string_view layoutClassName(LayoutClass c) {
  switch (c) {
    case LayoutClass::Simple: return "SIMPLE";
    case LayoutClass::Single: return "SINGLE";
    case LayoutClass::Complex: return "COMPLEX";
    case LayoutClass::Special: return "SPECIAL";
  }
  return "?";
}

StorageLayout computeLayout(const Material& m, const TreeInfo& info) {
  StorageLayout L;
  std::uint16_t all = 0;
  for (int s : info.slabOrder) {
    const Slab& slab = m.slabs[s];
    ClosureLayout c;
    c.slab = s;
    c.basis = slab.basis;
    c.isTop = info.isTop[info.slabNode[s]];
    c.storedFeatures = slab.features & kStoredFeatureMask;
    all |= c.storedFeatures;
    L.closures.push_back(c);
  }
  const int count = static_cast<int>(L.closures.size());
  const bool multi = count > 1;
  for (auto& c : L.closures) {
    const int node = info.slabNode[c.slab];
    c.storesWeight = !info.unitWeight[node];
    c.storesCoverageAbove = !c.isTop && !info.unitCoverageAbove[node];
  }

  // Class.
  if (all & (kFeatGlint | kFeatSpecularProfile)) L.layoutClass = LayoutClass::Special;
  else if (multi || (all & kFeatAnisotropy)) L.layoutClass = LayoutClass::Complex;
  else if (all || L.closures[0].storesWeight) L.layoutClass = LayoutClass::Single;
  else L.layoutClass = LayoutClass::Simple;

  // Bases: a lone closure's normal is the top-layer normal; with several,
  // basis 0's normal is elided when every top-layer closure uses basis 0.
  L.basisCount = static_cast<int>(m.bases.size());
  bool topShare = true;
  for (const auto& c : L.closures)
    if (c.isTop && c.basis != 0) topShare = false;
  L.basis0NormalElided = topShare;

  auto add = [&](std::string name, int b, std::string enc, int closure = -1, int basis = -1) {
    L.fields.push_back({std::move(name), b, std::move(enc), closure, basis});
    L.totalBits += b;
  };
  add("header", bits::kHeader,
      multi ? "layout class 2 | closure count-1 3 | basis count 4 | reserved 7"
            : "layout class 2 | feature bits 8 | sss type 2 | reserved 4");
  for (int i = 0; i < count; ++i) {
    const ClosureLayout& c = L.closures[i];
    const std::string p = fmt::format("closure{}.", i);
    if (multi)
      add(p + "header", bits::kClosureHeader,
          "basis id 3 | is top 1 | feature bits 8 | sss type 2 | reserved 2", i);
    add(p + "diffuse_albedo", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    add(p + "f0", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    add(p + "roughness", bits::kRoughness, "unorm8", i);
    if (c.storesWeight) add(p + "weight", bits::kGreyWeight, "unorm8", i);
    if (!c.isTop) add(p + "top_transmittance", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    if (c.storesCoverageAbove) add(p + "coverage_above", bits::kCoverageAbove, "unorm8", i);
    const std::uint16_t f = c.storedFeatures;
    if (f & kFeatF90) add(p + "f90", bits::kColor, "unorm 7/7/6 of sqrt(c)", i);
    if (f & kFeatSss) add(p + "sss", bits::kSss, "mfp: 3 x unorm8 of log2(mfp) in [-24, 8]; phase: snorm4", i);
    if (f & kFeatHaze) add(p + "haze", bits::kHaze, "second roughness unorm8 | weight unorm8", i);
    if (f & kFeatFuzz) add(p + "fuzz", bits::kFuzz, "amount unorm6 | color 7/7/6 sqrt | roughness unorm6", i);
    if (f & kFeatAnisotropy) add(p + "anisotropy", bits::kAnisotropy, "snorm8", i);
    if (f & kFeatSpecularProfile) add(p + "specular_profile", bits::kSpecularProfile, "profile index uint8", i);
    if (f & kFeatGlint)
      add(p + "glint", bits::kGlint, "density unorm8 | uv 2 x float32 | duv/dx, duv/dy 4 x half", i);
  }
  for (int b = 0; b < L.basisCount; ++b) {
    const std::string p = fmt::format("basis{}.", b);
    bool anisotropic = false;
    for (const auto& c : L.closures)
      if (c.basis == b && (c.storedFeatures & kFeatAnisotropy)) anisotropic = true;
    bool elided = !multi || (b == 0 && L.basis0NormalElided);
    if (!elided) add(p + "normal", bits::kNormal, "octahedral 2 x snorm16", -1, b);
    if (anisotropic) add(p + "tangent_angle", bits::kTangentAngle, "unorm14 of angle/2pi around the normal", -1, b);
  }
  return L;
}

}  // namespace substratec
