// OpenPBR Surface 1.1 (MaterialX ND_open_pbr_surface_surfaceshader) as a
// LayeredSurface. Formulas (docs/import.md):
//   base     diffuse = base_weight · base_color (leaning to subsurface_color by
//            subsurface_weight; SSS mfp = subsurface_radius · subsurface_radius_scale ·
//            subsurface_weight, metres); metal F0 = base_weight · base_color, its F82
//            tint as the slab's F90 = specular_weight · specular_color;
//   specular dielectric F0 = specular_weight · specular_color · F0(specular_ior),
//            F90 = specular_weight · specular_color; roughness roughened by the coat
//            (vlerp(r, min(1, 2 rc⁴ + r⁴)^¼, coat_weight)); open_pbr_anisotropy:
//            at = r² sqrt(2 / (1 + (1 − a)²)), ab = (1 − a) at;
//   coat     weight coat_weight, F0(coat_ior), coat_roughness (+ anisotropy), the coat
//            normal, per-pass transmittance sqrt(coat_color);
//   fuzz     fuzz_weight, fuzz_color, fuzz_roughness; thin film thin_film_weight,
//            thin_film_thickness (µm), thin_film_ior; emission_luminance (nits) ·
//            emission_color; transmission_weight tinted by transmission_color;
//            geometry_opacity → presence; geometry_thin_walled → thin surface.
#include "blocks/mtlx_surfaces.h"

namespace substratec::blocks {

namespace {

RoughnessAnisotropy openPbrAnisotropy(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                      const std::string& prefix) {
  const Value r = namedValue(w, prefix + "roughness", roughness);
  const Value inv = namedValue(w, prefix + "anisotropy_invert", oneMinus(anisotropy));
  const Value at = namedValue(w, prefix + "alpha_t", mul(mul(r, r), vsqrt(divide(2.0, add(mul(inv, inv), 1.0)))));
  return fromAlphas(at, mul(inv, at));
}

/// The coat (coat_weight not 0): F0(coat_ior), its roughness and anisotropy,
/// normal, per-pass transmittance sqrt(coat_color).
void openPbrCoat(SurfaceParams& params, NodeWriter& w, const Value& coat, const Value& coatRoughness,
                 LayeredSurface& s) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  s.coatWeight = coat;
  s.coatF0 = iorToF0Value(P("coat_ior", "float", {1.6}));
  const Value coatAnisotropy = P("coat_roughness_anisotropy", "float", {0}, ParamKind::Switch);
  const RoughnessAnisotropy ra = roughnessPins(coatRoughness, coatAnisotropy, w, "coat_", openPbrAnisotropy);
  s.coatRoughness = ra.roughness;
  s.coatAnisotropy = ra.anisotropy;
  if (params.given("geometry_coat_normal")) s.coatNormal = P("geometry_coat_normal", "vector3", {0, 0, 1});
  const Value coatColor = P("coat_color", "color3", {1, 1, 1});
  if (!isLiteral(coatColor, 1)) s.coatTransmittance = vsqrt(coatColor);
  if (C("coat_darkening", "float", {1})[0] > 0)
    params.warn("coat_darkening: light trapped under the coat by internal reflection is not modelled; the base is "
              "seen through the coat's transmittance only");
}

}  // namespace

LayeredSurface openPbrSurface(SurfaceParams& params, NodeWriter& w) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  auto off = [](const Value& x, double neutral) { return x.is_null() || isLiteral(x, neutral); };
  LayeredSurface s;
  const Value weight = P("base_weight", "float", {1}, ParamKind::Switch);
  const Value color = namedValue(w, "base_color_value", P("base_color", "color3", {0.8, 0.8, 0.8}));
  const Value metalColor = mul(weight, color);
  s.metallic = P("base_metalness", "float", {0}, ParamKind::Switch);
  if (C("base_diffuse_roughness", "float", {0})[0] != 0)
    params.warn("base_diffuse_roughness: a slab's diffuse roughness is its specular roughness; ignored");
  Value diffuse = metalColor;
  const Value subsurface = P("subsurface_weight", "float", {0}, ParamKind::Switch);
  if (!off(subsurface, 0)) {
    diffuse = vlerp(diffuse, P("subsurface_color", "color3", {0.8, 0.8, 0.8}), subsurface);
    s.sssMfp = mul(mul(P("subsurface_radius_scale", "color3", {1, 0.5, 0.25}), P("subsurface_radius", "float", {1})),
                   subsurface);
    if (C("subsurface_scatter_anisotropy", "float", {0})[0] != 0)
      params.warn("subsurface_scatter_anisotropy: the slab's medium scatters isotropically in the runtime; ignored");
  }
  if (!(diffuse == metalColor)) s.diffuseColor = diffuse;
  s.baseColor = namedValue(w, "metal_color", metalColor);

  const Value specularWeight = P("specular_weight", "float", {1}, ParamKind::Switch);
  const Value tint = namedValue(w, "specular_tint", mul(specularWeight, P("specular_color", "color3", {1, 1, 1})));
  const Value ior = P("specular_ior", "float", {1.5});
  if (!isLiteral(tint, 1) || !isLiteral(ior, 1.5)) {
    s.specularF0 = isLiteral(tint, 1) ? iorToF0Value(ior) : mul(iorToF0Value(ior), tint);
    if (!isLiteral(tint, 1)) s.specularF90 = tint;
  }
  if (!off(s.metallic, 0) && !isLiteral(tint, 1)) s.metalF90 = tint;

  const Value coat = P("coat_weight", "float", {0}, ParamKind::Switch);
  const Value coatRoughness = P("coat_roughness", "float", {0});
  Value roughness = P("specular_roughness", "float", {0.3});
  if (!off(coat, 0)) {
    const Value r = namedValue(w, "base_roughness", roughness);
    const Value r4 = mul(mul(r, r), mul(r, r));
    const Value c = namedValue(w, "coat_roughness_value", coatRoughness);
    const Value c4 = mul(mul(c, c), mul(c, c));
    roughness = vlerp(r, vpow(vmin(add(mul(c4, 2.0), r4), 1.0), 0.25), coat);
  }
  const Value anisotropy = P("specular_roughness_anisotropy", "float", {0}, ParamKind::Switch);
  const RoughnessAnisotropy ra = roughnessPins(roughness, anisotropy, w, "specular_", openPbrAnisotropy);
  s.roughness = ra.roughness;
  s.anisotropy = ra.anisotropy;
  if (params.given("geometry_normal")) s.normal = P("geometry_normal", "vector3", {0, 0, 1});
  for (const char* t : {"geometry_tangent", "geometry_coat_tangent"})
    if (params.given(t)) params.warn(std::string(t) + ": a connected tangent is not imported; the geometric tangent is used");

  const Value fuzz = P("fuzz_weight", "float", {0}, ParamKind::Switch);
  if (!off(fuzz, 0)) {
    s.fuzzAmount = fuzz;
    s.fuzzColor = P("fuzz_color", "color3", {1, 1, 1});
    s.fuzzRoughness = P("fuzz_roughness", "float", {0.5});
  }
  const Value film = P("thin_film_weight", "float", {0}, ParamKind::Switch);
  if (!off(film, 0)) {
    s.filmWeight = film;
    s.filmThickness = mul(P("thin_film_thickness", "float", {0.5}), 1e-6);
    s.filmIor = P("thin_film_ior", "float", {1.4});
  }
  const Value luminance = P("emission_luminance", "float", {0}, ParamKind::Switch);
  if (!off(luminance, 0)) s.emissive = mul(luminance, P("emission_color", "color3", {1, 1, 1}));

  const Value transmission = P("transmission_weight", "float", {0}, ParamKind::Switch);
  if (!off(transmission, 0)) mtlxTransmission(params, transmission, "transmission_dispersion_scale", s);

  if (!off(coat, 0)) openPbrCoat(params, w, coat, coatRoughness, s);

  const Value opacity = P("geometry_opacity", "float", {1}, ParamKind::Switch);
  if (!isLiteral(opacity, 1)) {
    s.opacity = opacity;
    s.alphaMode = AlphaMode::Blend;
  }
  s.thinWalled = C("geometry_thin_walled", "boolean", {0})[0] != 0;
  return s;
}

}  // namespace substratec::blocks
