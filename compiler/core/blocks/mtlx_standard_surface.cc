// Autodesk Standard Surface (MaterialX ND_standard_surface_surfaceshader,
// version 1.0.1 defaults) as a LayeredSurface. Formulas (docs/import.md):
//   diffuse    = base · base_color^(1 + coat · coat_affect_color), leaning to
//                subsurface_color by subsurface; SSS mfp = subsurface_radius ·
//                subsurface_scale · subsurface (metres);
//   metal F0   = base · base_color, edge tint (F90) = specular · specular_color;
//   dielectric F0 = specular · specular_color · F0(specular_IOR), F90 = specular · specular_color;
//   roughness  = vlerp(specular_roughness, 1, coat · coat_affect_roughness · coat_roughness),
//                with MaterialX's roughness_anisotropy and the tangent rotated by
//                specular_rotation · 2π;
//   coat       = weight coat, F0(coat_IOR), coat_roughness/anisotropy/rotation, coat_normal,
//                per-pass transmittance sqrt(coat_color) (the base is seen tinted by coat_color);
//   sheen → fuzz; thin_film_thickness (nm) → thin film; emission · emission_color;
//   transmission → the transmitting dielectric tinted by transmission_color;
//   opacity (luminance) → presence.
#include <fmt/format.h>

#include "blocks/mtlx_surfaces.h"

namespace substratec::blocks {

namespace {
constexpr double kTwoPi = 6.28318530717958647692;

/// The coat (coat not 0): F0(coat_IOR), its roughness, anisotropy and rotation,
/// normal, and per-pass transmittance sqrt(coat_color).
void standardCoat(SurfaceParams& params, NodeWriter& w, const Value& coat, LayeredSurface& s) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  auto off = [](const Value& x, double neutral) { return x.is_null() || isLiteral(x, neutral); };
  s.coatWeight = coat;
  s.coatF0 = iorToF0Value(P("coat_IOR", "float", {1.5}));
  const Value coatRoughness = P("coat_roughness", "float", {0.1});
  const Value coatAnisotropy = P("coat_anisotropy", "float", {0}, ParamKind::Switch);
  const RoughnessAnisotropy ra = roughnessPins(coatRoughness, coatAnisotropy, w, "coat_");
  s.coatRoughness = ra.roughness;
  s.coatAnisotropy = ra.anisotropy;
  if (!off(coatAnisotropy, 0)) s.coatTangent = rotatedTangent(C("coat_rotation", "float", {0})[0] * kTwoPi);
  if (params.given("coat_normal")) s.coatNormal = P("coat_normal", "vector3", {0, 0, 1});
  const Value coatColor = P("coat_color", "color3", {1, 1, 1});
  if (!isLiteral(coatColor, 1)) s.coatTransmittance = vsqrt(coatColor);
}

/// Thin film (thickness in nm), emission and transmission.
void standardFilmEmissionTransmission(SurfaceParams& params, LayeredSurface& s) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  auto off = [](const Value& x, double neutral) { return x.is_null() || isLiteral(x, neutral); };
  const double film = C("thin_film_thickness", "float", {0})[0];
  if (film > 0 || (params.given("thin_film_thickness") && !params.constant("thin_film_thickness", "float", {0}))) {
    s.filmWeight = 1.0;
    s.filmThickness = mul(P("thin_film_thickness", "float", {0}), 1e-9);
    s.filmIor = P("thin_film_IOR", "float", {1.5});
  }

  const Value emission = P("emission", "float", {0}, ParamKind::Switch);
  if (!off(emission, 0)) s.emissive = mul(emission, P("emission_color", "color3", {1, 1, 1}));

  const Value transmission = P("transmission", "float", {0}, ParamKind::Switch);
  if (!off(transmission, 0)) {
    mtlxTransmission(params, transmission, "transmission_dispersion", s);
    if (C("transmission_extra_roughness", "float", {0})[0] != 0)
      params.warn("transmission_extra_roughness: the transmitted light is not blurred; ignored");
  }
}

}  // namespace

LayeredSurface standardSurface(SurfaceParams& params, NodeWriter& w) {
  const MtlxParam P{params};
  const MtlxConstant C{params};
  auto off = [](const Value& x, double neutral) { return x.is_null() || isLiteral(x, neutral); };
  LayeredSurface s;
  const Value base = P("base", "float", {1}, ParamKind::Switch);
  const Value baseColor = namedValue(w, "base_color_value", P("base_color", "color3", {0.8, 0.8, 0.8}));
  const Value metalness = P("metalness", "float", {0}, ParamKind::Switch);
  const Value specular = P("specular", "float", {1}, ParamKind::Switch);
  const Value specularColor = P("specular_color", "color3", {1, 1, 1});
  const Value coat = P("coat", "float", {0}, ParamKind::Switch);

  if (C("diffuse_roughness", "float", {0})[0] != 0)
    params.warn("diffuse_roughness: a slab's diffuse roughness is its specular roughness; ignored");

  const Value metalColor = mul(base, baseColor);
  s.metallic = metalness;
  Value diffuse = baseColor;
  if (!off(coat, 0) && params.given("coat_affect_color")) {
    const Value affect = P("coat_affect_color", "float", {0});
    diffuse = vpow(vmax(baseColor, 0.0), add(1.0, mul(coat, affect)));
  }
  diffuse = mul(base, diffuse);
  const Value subsurface = P("subsurface", "float", {0}, ParamKind::Switch);
  if (!off(subsurface, 0)) {
    diffuse = vlerp(diffuse, P("subsurface_color", "color3", {1, 1, 1}), subsurface);
    const Value radius = P("subsurface_radius", "color3", {1, 1, 1});
    const Value scale = P("subsurface_scale", "float", {1});
    s.sssMfp = mul(mul(radius, scale), subsurface);
    if (C("subsurface_anisotropy", "float", {0})[0] != 0)
      params.warn("subsurface_anisotropy: the slab's medium scatters isotropically in the runtime; ignored");
  }
  if (!(diffuse == metalColor)) s.diffuseColor = diffuse;
  s.baseColor = namedValue(w, "metal_color", metalColor);

  const Value tint = namedValue(w, "specular_tint", mul(specular, specularColor));
  const Value ior = P("specular_IOR", "float", {1.5});
  if (!isLiteral(tint, 1) || !isLiteral(ior, 1.5)) {
    s.specularF0 = isLiteral(tint, 1) ? iorToF0Value(ior) : mul(iorToF0Value(ior), tint);
    if (!isLiteral(tint, 1)) s.specularF90 = tint;
  }
  if (!off(metalness, 0) && !isLiteral(tint, 1)) s.metalF90 = tint;

  Value roughness = P("specular_roughness", "float", {0.2});
  if (!off(coat, 0) && params.given("coat_affect_roughness"))
    roughness = vlerp(roughness, 1.0, mul(mul(coat, P("coat_affect_roughness", "float", {0})), P("coat_roughness", "float", {0.1})));
  const Value anisotropy = P("specular_anisotropy", "float", {0}, ParamKind::Switch);
  const RoughnessAnisotropy ra = roughnessPins(roughness, anisotropy, w, "specular_");
  s.roughness = ra.roughness;
  s.anisotropy = ra.anisotropy;
  if (!off(anisotropy, 0)) s.tangent = rotatedTangent(C("specular_rotation", "float", {0})[0] * kTwoPi);
  s.normal = params.given("normal") ? P("normal", "vector3", {0, 0, 1}) : Value();
  if (params.given("tangent")) params.warn("tangent: a connected tangent is not imported; the geometric tangent is used");

  const Value sheen = P("sheen", "float", {0}, ParamKind::Switch);
  if (!off(sheen, 0)) {
    s.fuzzAmount = sheen;
    s.fuzzColor = P("sheen_color", "color3", {1, 1, 1});
    s.fuzzRoughness = P("sheen_roughness", "float", {0.3});
  }

  standardFilmEmissionTransmission(params, s);

  if (!off(coat, 0)) standardCoat(params, w, coat, s);

  if (params.given("opacity")) {
    const Value opacity = P("opacity", "color3", {1, 1, 1});
    if (!isLiteral(opacity, 1)) {
      s.opacity = vdot(opacity, literal3(0.2126, 0.7152, 0.0722));
      s.alphaMode = AlphaMode::Blend;
    }
  }
  s.thinWalled = C("thin_walled", "boolean", {0})[0] != 0;
  return s;
}

}  // namespace substratec::blocks
