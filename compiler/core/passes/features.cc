#include "passes/features.h"

#include "ir/tree_info.h"

namespace substratec {

namespace {

/// The feature bit of a BSDF whose closure kind is fixed, else 0.
std::uint16_t wholeKindFeature(BsdfKind kind) {
  switch (kind) {
    case BsdfKind::Hair: return kFeatHair;
    case BsdfKind::Eye: return kFeatEye;
    case BsdfKind::Water: return kFeatWater;
    default: return 0;
  }
}

}  // namespace

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
    const bool hasMfp = used(SlabPin::SssMfp, 0.0) && used(SlabPin::SssMfpScale, 0.0);
    const bool sssOff = s.sssTypeExplicit && s.sssType == SssType::None;  // by the author or simplification
    // A hair's lobes, an eye's cornea, sclera and iris, a water's surface (a
    // plain slab; its body a forward term): one closure kind each, with no
    // optional part but emission and an eye's subsurface scattering (its
    // sclera's mean free path under a scattering albedo: always the bottom).
    if (const std::uint16_t kind = wholeKindFeature(s.kind); kind != 0) {
      const bool sss = s.kind == BsdfKind::Eye && hasMfp && !sssOff && used(SlabPin::DiffuseAlbedo, 0.0);
      s.sssType = !sss ? SssType::None : m.settings.thinSurface ? SssType::SimpleVolume : SssType::Diffusion;
      s.features = kind | (used(SlabPin::Emissive, 0.0) ? kFeatEmissive : 0) | (sss ? kFeatSss : 0);
      continue;
    }
    if (used(SlabPin::F90, 1.0)) f |= kFeatF90;
    if (used(SlabPin::Anisotropy, 0.0)) f |= kFeatAnisotropy;
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
