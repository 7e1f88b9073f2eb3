// MaterialX's gltf_pbr (ND_gltf_pbr_surfaceshader): the glTF 2.0 parameters
// under their MaterialX names, mapped with the glTF formulas (gltf_pbr.h).
// alpha_mode is 0 opaque, 1 mask, 2 blend; iridescence_thickness is in
// nanometres; anisotropy_rotation in radians.
#include <fmt/format.h>

#include "blocks/gltf_pbr.h"
#include "import/mtlx_surfaces.h"

namespace substratec::import {

namespace {
/// The largest alpha_cutoff the gltf_pbr block takes (a literal pin; any
/// cutoff above 1 masks every texel).
constexpr double kMaxCutoff = 1e300;
}  // namespace

GltfPbr mtlxGltfPbrParams(SurfaceParams& params) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  GltfPbr g;
  g.baseColor = P("base_color", "color3", {1, 1, 1});
  g.metallic = P("metallic", "float", {1}, ParamKind::Switch);
  g.roughness = P("roughness", "float", {1});
  if (params.given("normal")) g.normal = P("normal", "vector3", {0, 0, 1});
  if (params.given("occlusion"))
    params.warn("occlusion: ambient occlusion is the renderer's (a Substrate material has no occlusion pin); ignored");
  const int mode = static_cast<int>(C("alpha_mode", "integer", {0})[0]);
  g.alphaMode = mode == 1 ? AlphaMode::Mask : mode == 2 ? AlphaMode::Blend : AlphaMode::Opaque;
  g.alphaCutoff = C("alpha_cutoff", "float", {0.5})[0];
  if (!(g.alphaCutoff >= 0 && g.alphaCutoff <= kMaxCutoff)) {  // the gltf_pbr block's range: glTF's, at least 0
    const double used = g.alphaCutoff > kMaxCutoff ? kMaxCutoff : 0.0;
    params.warn(fmt::format("alpha_cutoff: {} is outside [0, {}]; {} is used", g.alphaCutoff, kMaxCutoff, used));
    g.alphaCutoff = used;
  }
  if (g.alphaMode != AlphaMode::Opaque) g.alpha = P("alpha", "float", {1}, ParamKind::Switch);
  if (params.given("ior")) g.ior = P("ior", "float", {1.5});
  g.specular = P("specular", "float", {1}, ParamKind::Switch);
  g.specularColor = P("specular_color", "color3", {1, 1, 1});
  g.transmission = P("transmission", "float", {0}, ParamKind::Switch);
  if (!isLiteral(g.transmission, 0))
    params.warn(std::string("transmission: ") + kTransmissionNote);
  g.thickness = P("thickness", "float", {0});
  g.attenuationDistance = C("attenuation_distance", "float", {0})[0];
  // 0 is glTF's "no attenuation": what the expansion makes of a distance
  // that is not positive and finite too, so the block holds that.
  if (!(g.attenuationDistance > 0 && g.attenuationDistance < 1e30)) g.attenuationDistance = 0;
  g.attenuationColor = P("attenuation_color", "color3", {1, 1, 1});
  g.iridescence = P("iridescence", "float", {0}, ParamKind::Switch);
  g.iridescenceIor = P("iridescence_ior", "float", {1.3});
  g.iridescenceThickness = P("iridescence_thickness", "float", {100});
  g.sheenColor = P("sheen_color", "color3", {0, 0, 0});
  g.sheenRoughness = P("sheen_roughness", "float", {0});
  g.clearcoat = P("clearcoat", "float", {0}, ParamKind::Switch);
  g.clearcoatRoughness = P("clearcoat_roughness", "float", {0});
  if (params.given("clearcoat_normal")) g.clearcoatNormal = P("clearcoat_normal", "vector3", {0, 0, 1});
  g.anisotropyStrength = P("anisotropy_strength", "float", {0}, ParamKind::Switch);
  g.anisotropyRotation = C("anisotropy_rotation", "float", {0})[0];
  if (params.given("emissive")) {
    const Value e = P("emissive", "color3", {0, 0, 0});
    const Value strength = P("emissive_strength", "float", {1});
    if (!isLiteral(e, 0)) g.emissive = mul(e, strength);
  }
  if (C("dispersion", "float", {0})[0] != 0)
    params.warn("dispersion (an IOR per wavelength) is not represented; one IOR for every colour");
  return g;
}

LayeredSurface mtlxGltfPbr(SurfaceParams& params, NodeWriter& w) { return gltfPbrSurface(mtlxGltfPbrParams(params), w); }

}  // namespace substratec::import
