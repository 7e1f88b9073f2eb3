// Disney principled (MaterialX ND_disney_principled, after Burley 2012/2015)
// as a LayeredSurface. Formulas (docs/import.md):
//   base colour baseColor, metallic; dielectric F0 = 0.08 · specular ·
//   vlerp(1, baseColor, specularTint) (F90 1, Disney's Schlick);
//   roughness with roughness_anisotropy(anisotropic) along the tangent;
//   sheen → fuzz (colour vlerp(1, baseColor, sheenTint), roughness 0.3 as
//   MaterialX's sheen_bsdf); clearcoat → coat (F0 0.04, roughness 1 −
//   clearcoatGloss); specTrans → transmission tinted by baseColor;
//   subsurface → SSS mfp = subsurfaceDistance · subsurface (metres).
#include "blocks/mtlx_surfaces.h"

namespace substratec::blocks {

LayeredSurface disneyPrincipled(SurfaceParams& params, NodeWriter& w) {
  const MtlxParam P{params};
  LayeredSurface s;
  const Value baseColor = namedValue(w, "base_color_value", P("baseColor", "color3", {0.16, 0.16, 0.16}));
  s.baseColor = baseColor;
  s.metallic = P("metallic", "float", {0}, ParamKind::Switch);
  const Value specular = P("specular", "float", {0.5});
  const Value specularTint = P("specularTint", "float", {0}, ParamKind::Switch);
  if (!isLiteral(specular, 0.5) || !isLiteral(specularTint, 0))
    s.specularF0 = mul(mul(specular, 0.08), vlerp(literal3(1, 1, 1), baseColor, specularTint));
  const Value roughness = P("roughness", "float", {0.5});
  const Value anisotropic = P("anisotropic", "float", {0}, ParamKind::Switch);
  const RoughnessAnisotropy ra = roughnessPins(roughness, anisotropic, w, "specular_");
  s.roughness = ra.roughness;
  s.anisotropy = ra.anisotropy;
  const Value sheen = P("sheen", "float", {0}, ParamKind::Switch);
  if (!isLiteral(sheen, 0)) {
    s.fuzzAmount = sheen;
    s.fuzzColor = vlerp(literal3(1, 1, 1), baseColor, P("sheenTint", "float", {0.5}));
    s.fuzzRoughness = 0.3;
  }
  const Value clearcoat = P("clearcoat", "float", {0}, ParamKind::Switch);
  if (!isLiteral(clearcoat, 0)) {
    s.coatWeight = clearcoat;
    s.coatF0 = 0.04;
    s.coatRoughness = oneMinus(P("clearcoatGloss", "float", {1}));
  }
  const Value specTrans = P("specTrans", "float", {0}, ParamKind::Switch);
  if (!isLiteral(specTrans, 0)) {
    s.transmission = specTrans;
    s.transmittance = baseColor;
    const Value ior = P("ior", "float", {1.5});
    if (!isLiteral(ior, 1.5) && s.specularF0.is_null()) s.specularF0 = iorToF0Value(ior);
    params.warn(std::string("specTrans: ") + kTransmissionNote);
  }
  const Value subsurface = P("subsurface", "float", {0}, ParamKind::Switch);
  if (!isLiteral(subsurface, 0)) s.sssMfp = mul(P("subsurfaceDistance", "color3", {1, 1, 1}), subsurface);
  return s;
}

}  // namespace substratec::blocks
