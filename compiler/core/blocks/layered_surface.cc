#include "blocks/layered_surface.h"

#include <algorithm>
#include <cmath>

namespace substratec::blocks {

namespace {

bool absent(const Value& v, double neutral) { return v.is_null() || isLiteral(v, neutral); }

/// The slab pins shared by the opaque base and the transmitting copy.
Json sharedPins(const LayeredSurface& s, const Value& diffuse, const Value& f0, const Value& f90,
               const Value& emissive) {
  Json slab = {{"kind", "slab"}};
  slab["diffuse_albedo"] = diffuse;
  slab["f0"] = f0;
  if (!f90.is_null()) slab["f90"] = f90;
  slab["roughness"] = s.roughness;
  if (!absent(s.anisotropy, 0)) {
    slab["anisotropy"] = s.anisotropy;
    if (!s.tangent.is_null()) slab["tangent"] = s.tangent;
  }
  if (!s.normal.is_null()) slab["normal"] = s.normal;
  if (!absent(s.fuzzAmount, 0)) {
    slab["fuzz_amount"] = s.fuzzAmount;
    slab["fuzz_color"] = s.fuzzColor.is_null() ? Value(1.0) : s.fuzzColor;
    if (!s.fuzzRoughness.is_null()) slab["fuzz_roughness"] = s.fuzzRoughness;
  }
  if (!absent(emissive, 0)) slab["emissive"] = emissive;
  return slab;
}

}  // namespace

RoughnessAnisotropy fromAlphas(const Value& alphaT, const Value& alphaB) {
  const Value sum = add(alphaT, alphaB);
  return {vsqrt(mul(sum, 0.5)), divide(sub(alphaT, alphaB), sum)};
}

Value rotatedTangent(const Value& angle) {
  if (angle.is_null() || isLiteral(angle, 0)) return Value();
  if (angle.is_number()) {
    const double a = angle.get<double>();
    auto tidy = [](double x) { return std::fabs(x) < 1e-15 ? 0.0 : x; };
    return literal3(tidy(std::cos(a)), tidy(std::sin(a)), 0.0);
  }
  return Json{{"kind", "rotation_to_tangent"}, {"angle", angle}};
}

/// The base's diffuse albedo, F0 and F90 (null: 1) from the metallic
/// workflow: the metalness helper node when the dielectric is a plain grey
/// F0 <= 0.08 (specular = F0 / 0.08), otherwise the same formulas spelled out.
void baseReflectance(const LayeredSurface& s, NodeWriter& w, bool metal, Value& diffuse, Value& f0, Value& f90) {
  const bool f90Given = !s.specularF90.is_null() || !s.metalF90.is_null();
  const auto greyF0 = literalOf(s.specularF0);
  const bool helper = metal && s.diffuseColor.is_null() &&
                      (s.specularF0.is_null() || (greyF0 && greyF0->size() == 1 && (*greyF0)[0] <= 0.08));
  if (helper) {
    Json h = {{"kind", "metalness_to_diffuse_f0"}, {"base_color", s.baseColor}, {"metallic", s.metallic}};
    if (greyF0 && (*greyF0)[0] != 0.04) h["specular"] = (*greyF0)[0] / 0.08;
    const Value metalness = w.node("metalness", h);
    diffuse = outputOf(metalness, "diffuse_albedo");
    f0 = outputOf(metalness, "f0");
  } else {
    const Value dielectricF0 = s.specularF0.is_null() ? Value(0.04) : s.specularF0;
    const Value dielectricDiffuse = s.diffuseColor.is_null() ? s.baseColor : s.diffuseColor;
    diffuse = metal ? mul(dielectricDiffuse, oneMinus(s.metallic)) : dielectricDiffuse;
    f0 = metal ? vlerp(dielectricF0, s.baseColor, s.metallic) : dielectricF0;
  }
  if (f90Given) {
    const Value d90 = s.specularF90.is_null() ? Value(1.0) : s.specularF90;
    const Value m90 = s.metalF90.is_null() ? Value(1.0) : s.metalF90;
    f90 = metal ? vlerp(d90, m90, s.metallic) : d90;
  }
}

Value coatedRoot(const LayeredSurface& s, NodeWriter& w, const Value& root) {
  Json coat = {{"kind", "slab"}, {"diffuse_albedo", 0}};
  coat["f0"] = s.coatF0.is_null() ? Value(0.04) : s.coatF0;
  coat["roughness"] = s.coatRoughness.is_null() ? Value(0.0) : s.coatRoughness;
  if (!absent(s.coatAnisotropy, 0)) {
    coat["anisotropy"] = s.coatAnisotropy;
    if (!s.coatTangent.is_null()) coat["tangent"] = s.coatTangent;
  }
  if (!s.coatNormal.is_null()) coat["normal"] = s.coatNormal;
  if (absent(s.coatTransmittance, 1)) {
    coat["sss_mfp"] = 10;  // clear: a mean free path far longer than the layer
  } else {
    const Value medium = w.node("coat_medium", Json{{"kind", "transmittance_to_mfp"},
                                                    {"transmittance", s.coatTransmittance},
                                                    {"thickness", 0.0001}});
    coat["sss_mfp"] = outputOf(medium, "mfp");
  }
  Value top = w.node("coat_slab", coat);
  if (!isLiteral(s.coatWeight, 1))
    top = w.node("coat_presence", Json{{"kind", "coverage_weight"}, {"a", top}, {"weight", s.coatWeight}});
  return w.node("coated", Json{{"kind", "vertical"}, {"top", top}, {"base", root}, {"thickness", 0.0001}});
}

namespace {

bool transmits(const LayeredSurface& s) { return !s.unlit && !absent(s.transmission, 0); }

/// The presence (opacity, alpha mode) over `root`: a coverage weight (the
/// blend mode is layeredSurfaceSettings').
Value presenceOver(const LayeredSurface& s, NodeWriter& w, Value root);

}  // namespace

Value layeredSurfaceNodes(const LayeredSurface& s, NodeWriter& w) {
  if (s.unlit) {  // no closure: the unlit BSDF, its radiance and its presence
    Json unlit = {{"kind", "unlit"}};
    if (!absent(s.emissive, 0)) unlit["emissive"] = s.emissive;
    return presenceOver(s, w, w.node("unlit", unlit));
  }
  const bool metal = !absent(s.metallic, 0);
  Value diffuse, f0, f90;
  baseReflectance(s, w, metal, diffuse, f0, f90);
  if (!absent(s.filmWeight, 0) && !s.filmThickness.is_null()) {
    Json film = {{"kind", "thin_film"}, {"f0", f0}};
    if (!f90.is_null()) film["f90"] = f90;
    film["thickness"] = s.filmThickness;
    if (!s.filmIor.is_null()) film["ior"] = s.filmIor;
    if (!s.normal.is_null()) film["normal"] = s.normal;
    const Value filmNode = w.node("thin_film", film);
    f0 = vlerp(f0, outputOf(filmNode, "f0"), s.filmWeight);
  }
  // Named when used twice (the transmitting copy), so the JSON says it once.
  const bool transmits = substratec::blocks::transmits(s);
  if (transmits && !f0.is_string() && !literalOf(f0)) f0 = w.node("f0", f0);
  if (transmits && !f90.is_null() && !f90.is_string() && !literalOf(f90)) f90 = w.node("f90", f90);
  const Value emissive = transmits ? namedValue(w, "emissive", s.emissive) : s.emissive;

  Value root;
  const bool onlyGlass = transmits && isLiteral(s.transmission, 1) && !metal;
  if (!onlyGlass) {
    Json base = sharedPins(s, diffuse, f0, f90, emissive);
    if (!absent(s.sssMfp, 0)) {
      base["sss_mfp"] = s.sssMfp;
      if (!s.sssType.empty()) base["sss_type"] = s.sssType;
    }
    root = w.node("base_slab", base);
  }
  if (transmits) {
    Json glass = sharedPins(s, 0, f0, f90, emissive);
    const Value t = s.transmittance.is_null() ? Value(1.0) : s.transmittance;
    const Value medium = w.node("transmission_medium",
                                Json{{"kind", "transmittance_to_mfp"}, {"transmittance", t}, {"thickness", 0.0001}});
    glass["sss_mfp"] = outputOf(medium, "mfp");
    const Value glassSlab = w.node("transmission_slab", glass);
    if (onlyGlass) {
      root = glassSlab;
    } else {
      const Value mix = metal ? mul(s.transmission, oneMinus(s.metallic)) : s.transmission;
      root = w.node("transmission_mix", Json{{"kind", "horizontal"}, {"background", root}, {"foreground", glassSlab}, {"mix", mix}});
    }
  }
  if (!absent(s.coatWeight, 0)) root = coatedRoot(s, w, root);
  return presenceOver(s, w, root);
}

namespace {

bool hasPresence(const LayeredSurface& s) {
  return (s.alphaMode != AlphaMode::Opaque || !absent(s.opacity, 1)) && !s.opacity.is_null();
}

/// The coverage weight of the presence of `s`.
Value presenceWeight(const LayeredSurface& s) {
  // The masked blend mode keeps coverage >= 0.5: a steep ramp puts the
  // cutoff there and keeps kept texels (nearly) fully covered.
  if (s.alphaMode == AlphaMode::Mask) return saturate(add(mul(sub(s.opacity, s.alphaCutoff), 1000.0), 0.5));
  return s.opacity;
}

bool foldsToZero(const Value& weight) {
  const auto c = literalOf(weight);
  return c && std::all_of(c->begin(), c->end(), [](double x) { return !(x > 0); });
}

Value presenceOver(const LayeredSurface& s, NodeWriter& w, Value root) {
  if (!hasPresence(s)) return root;
  Value weight = presenceWeight(s);
  // A presence that folds to a constant 0 (alpha or opacity 0 given as a
  // literal, or below a mask's cutoff) would leave the compiler no matter at
  // all ("no matter is left after static culling"): the writer says what it
  // becomes (an importer keeps the source's invisible material as one whose
  // coverage input is 0, which compiles and which an author can still raise).
  if (foldsToZero(weight)) weight = w.invisiblePresence();
  return w.node("presence", Json{{"kind", "coverage_weight"}, {"a", root}, {"weight", weight}});
}

}  // namespace

bool presenceFoldsToZero(const LayeredSurface& s) { return hasPresence(s) && foldsToZero(presenceWeight(s)); }

Json layeredSurfaceSettings(const LayeredSurface& s) {
  Json settings = Json::object();
  std::string blend = transmits(s) ? "translucent_colored" : "opaque";
  if (hasPresence(s) && s.alphaMode == AlphaMode::Mask)
    blend = "masked";
  else if (hasPresence(s) && !transmits(s))
    blend = "translucent_grey";
  if (blend != "opaque") settings["blend_mode"] = blend;
  if (s.thinWalled) settings["thin_surface"] = true;
  return settings;
}

void writeSurfaceOutput(const LayeredSurface& s, const Value& root, MaterialWriter& w) {
  const Json settings = layeredSurfaceSettings(s);  // items() holds no temporary alive
  for (const auto& [key, value] : settings.items()) w.setSetting(key, value);
  w.setOutput(root);
}

void writeLayeredSurface(const LayeredSurface& s, MaterialWriter& w) { writeSurfaceOutput(s, layeredSurfaceNodes(s, w), w); }

}  // namespace substratec::blocks
