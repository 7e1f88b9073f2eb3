// UsdPreviewSurface (MaterialX ND_UsdPreviewSurface_surfaceshader) as a
// LayeredSurface. Formulas (docs/import.md):
//   metallic workflow (useSpecularWorkflow 0): base colour diffuseColor, metallic,
//     dielectric F0 = F0(ior);
//   specular workflow (1): no metal, dielectric F0 = specularColor (F90 1);
//   clearcoat (weight, F0 0.04, clearcoatRoughness); emissiveColor; normal as it is
//   (tangent space); opacity with opacityThreshold > 0 → a masked presence (cut-out);
//   otherwise 1 − opacity is a clear transmission (UsdPreviewSurface keeps the
//   specular response of a transparent surface, like clear glass).
#include "import/mtlx_surfaces.h"

namespace substratec::import {

LayeredSurface usdPreviewSurface(SurfaceParams& params, NodeWriter& w) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  (void)w;
  LayeredSurface s;
  s.baseColor = P("diffuseColor", "color3", {0.18, 0.18, 0.18});
  s.roughness = P("roughness", "float", {0.5});
  const bool specularWorkflow = C("useSpecularWorkflow", "integer", {0})[0] != 0;
  if (specularWorkflow) {
    s.specularF0 = P("specularColor", "color3", {0, 0, 0});
  } else {
    s.metallic = P("metallic", "float", {0}, ParamKind::Switch);
    const Value ior = P("ior", "float", {1.5});
    if (!isLiteral(ior, 1.5)) s.specularF0 = iorToF0Value(ior);
  }
  if (params.given("normal")) s.normal = P("normal", "vector3", {0, 0, 1});
  const Value emissive = P("emissiveColor", "color3", {0, 0, 0});
  if (!isLiteral(emissive, 0)) s.emissive = emissive;
  const Value clearcoat = P("clearcoat", "float", {0}, ParamKind::Switch);
  if (!isLiteral(clearcoat, 0)) {
    s.coatWeight = clearcoat;
    s.coatF0 = 0.04;
    s.coatRoughness = P("clearcoatRoughness", "float", {0.01});
  }
  const Value opacity = P("opacity", "float", {1}, ParamKind::Switch);
  const double threshold = C("opacityThreshold", "float", {0})[0];
  if (!isLiteral(opacity, 1)) {
    if (threshold > 0) {
      s.opacity = opacity;
      s.alphaMode = AlphaMode::Mask;
      s.alphaCutoff = threshold;
    } else {
      s.transmission = oneMinus(opacity);
    }
  }
  if (params.given("displacement")) params.warn("displacement is geometry, not a surface material; ignored");
  if (params.given("occlusion"))
    params.warn("occlusion: ambient occlusion is the renderer's (a Substrate material has no occlusion pin); ignored");
  return s;
}

}  // namespace substratec::import
