#include "passes/features.h"

#include "ir/tree_info.h"

namespace substratec {

void analyzeFeatures(Material& m) {
  const TreeInfo info = analyzeTree(m);
  const ValueDag& v = m.values;
  for (int node : info.preorder) {
    if (m.nodes[node].op != TreeOp::Slab) continue;
    Slab& s = m.slabs[m.nodes[node].slab];
    std::uint16_t f = 0;
    auto used = [&](SlabPin p, double neutral) { return !v.isConstEqual(s.pin(p), neutral); };
    if (s.kind == BsdfKind::Unlit || s.kind == BsdfKind::FogCloud) {  // an unlit only emits (and lets through,
      // which costs nothing); a fog cloud's albedo, extinction and occlusion are what it is, not options
      s.features = used(SlabPin::Emissive, 0.0) ? kFeatEmissive : 0;
      continue;
    }
    if (s.kind == BsdfKind::Hair) {  // a hair's lobes are one closure kind, with no optional part
      s.sssType = SssType::None;
      s.features = kFeatHair | (used(SlabPin::Emissive, 0.0) ? kFeatEmissive : 0);
      continue;
    }
    if (s.kind == BsdfKind::Water) {  // its surface is a plain slab (no stored feature); its body a forward term
      s.sssType = SssType::None;
      s.features = kFeatWater | (used(SlabPin::Emissive, 0.0) ? kFeatEmissive : 0);
      continue;
    }
    if (s.kind == BsdfKind::Eye) {  // an eye's cornea, sclera and iris are one closure kind, its fields fixed
      s.sssType = SssType::None;
      s.features = kFeatEye | (used(SlabPin::Emissive, 0.0) ? kFeatEmissive : 0);
      continue;
    }
    if (used(SlabPin::F90, 1.0)) f |= kFeatF90;
    if (used(SlabPin::Anisotropy, 0.0)) f |= kFeatAnisotropy;
    bool hasMfp = used(SlabPin::SssMfp, 0.0) && used(SlabPin::SssMfpScale, 0.0);
    bool sssOff = s.sssTypeExplicit && s.sssType == SssType::None;
    if (hasMfp && !info.isBottom[node]) {
      f |= kFeatMedium;  // a coating medium: transmittance only, baked by the tree walk
    } else if (hasMfp && !sssOff && used(SlabPin::DiffuseAlbedo, 0.0)) {
      // Subsurface scattering needs scattering: with a constant zero albedo the
      // medium only absorbs (the translucent regime, Beer-Lambert), which is
      // what `medium` means.
      f |= kFeatSss;
      if (!s.sssTypeExplicit) s.sssType = m.settings.thinSurface ? SssType::SimpleVolume : SssType::Diffusion;
    }
    else if (hasMfp && !sssOff) {
      f |= kFeatMedium;
    }
    if (!(f & kFeatSss) && !s.sssTypeExplicit) s.sssType = SssType::None;
    if (used(SlabPin::SecondRoughnessWeight, 0.0)) f |= kFeatHaze;
    if (used(SlabPin::FuzzAmount, 0.0)) f |= kFeatFuzz;
    if (used(SlabPin::GlintValue, 1.0)) f |= kFeatGlint;
    if (s.specularProfileInput >= 0) f |= kFeatSpecularProfile;
    if (used(SlabPin::Emissive, 0.0)) f |= kFeatEmissive;
    s.features = f;
  }
}

}  // namespace substratec
