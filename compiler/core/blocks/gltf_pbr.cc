#include "blocks/gltf_pbr.h"

#include <algorithm>
#include <cmath>

#include "blocks/blocks.h"

namespace substratec::blocks {

namespace {

bool off(const Value& v, double neutral) { return v.is_null() || isLiteral(v, neutral); }

/// KHR_materials_anisotropy's lobe: alpha_t = mix(alpha, 1, strength²) along
/// the direction, alpha_b = alpha, as the slab's (roughness, anisotropy).
RoughnessAnisotropy anisotropic(NodeWriter& w, const std::string& prefix, const Value& roughness,
                                const Value& strength) {
  const Value r = namedValue(w, prefix + "roughness", roughness);
  const Value alpha = namedValue(w, prefix + "alpha", mul(r, r));
  const Value alphaT = namedValue(w, prefix + "alpha_t", vlerp(alpha, 1.0, mul(strength, strength)));
  RoughnessAnisotropy ra = fromAlphas(alphaT, alpha);
  ra.roughness = namedValue(w, prefix + "anisotropic_roughness", ra.roughness);
  return ra;
}

/// The dielectric Fresnel and the specular anisotropy.
void gltfSpecular(const GltfPbr& g, NodeWriter& w, LayeredSurface& s) {
  // Dielectric Fresnel (KHR_materials_ior, KHR_materials_specular):
  //   F0 = min(((ior − 1)/(ior + 1))² · specularColor, 1) · specular,  F90 = specular.
  if (!g.ior.is_null() || !off(g.specular, 1) || !off(g.specularColor, 1)) {
    Value f0 = iorToF0Value(g.ior.is_null() ? Value(1.5) : g.ior);
    if (!off(g.specularColor, 1)) f0 = vmin(mul(f0, g.specularColor), 1.0);
    if (!off(g.specular, 1)) {
      const Value specular = namedValue(w, "specular", g.specular);
      f0 = mul(f0, specular);
      s.specularF90 = specular;
    }
    s.specularF0 = f0;
  }

  // Anisotropy: alpha_t = mix(alpha, 1, strength²) along the direction, alpha_b = alpha.
  if (!off(g.anisotropyStrength, 0)) {
    const RoughnessAnisotropy ra = anisotropic(w, "", s.roughness, g.anisotropyStrength);
    s.roughness = ra.roughness;
    s.anisotropy = ra.anisotropy;
    if (g.anisotropyDirection.is_null()) {
      s.tangent = rotatedTangent(g.anisotropyRotation);
    } else {
      const double c = std::cos(g.anisotropyRotation), sn = std::sin(g.anisotropyRotation);
      const Value d = namedValue(w, "anisotropy_direction", g.anisotropyDirection);
      const Value x = swizzle(d, "x"), y = swizzle(d, "y");
      Value tx = x, ty = y;
      if (g.anisotropyRotation != 0) {
        tx = sub(mul(x, c), mul(y, sn));
        ty = add(mul(x, sn), mul(y, c));
      }
      s.tangent = vnormalize(combine({tx, ty, 0.0}));
    }
  }
}

/// Sheen (KHR_materials_sheen) or fuzz (KHR_materials_fuzz) as the slab's fuzz.
void gltfFuzz(const GltfPbr& g, NodeWriter& w, LayeredSurface& s) {
  // Sheen: Charlie lobe over the base with albedo scaling
  //   fuzz_amount = max(sheenColor), fuzz_color = sheenColor / fuzz_amount.
  if (!off(g.sheenColor, 0)) {
    if (auto c = literalOf(g.sheenColor)) {
      const double m = c->size() == 1 ? (*c)[0] : std::max({(*c)[0], (*c)[1], (*c)[2]});
      s.fuzzAmount = m;
      s.fuzzColor = divide(g.sheenColor, m);
    } else {
      const Value color = namedValue(w, "sheen_color", g.sheenColor);
      const Value amount = namedValue(w, "sheen_amount", max3(color));
      s.fuzzAmount = amount;
      s.fuzzColor = divide(color, amount);
    }
    s.fuzzRoughness = g.sheenRoughness.is_null() ? Value(0.0) : g.sheenRoughness;
  }
  if (!off(g.fuzz, 0)) {  // KHR_materials_fuzz: weight, colour, roughness as they are
    s.fuzzAmount = g.fuzz;
    s.fuzzColor = g.fuzzColor.is_null() ? Value(1.0) : g.fuzzColor;
    s.fuzzRoughness = g.fuzzRoughness.is_null() ? Value(0.5) : g.fuzzRoughness;
  }
}

/// KHR_materials_clearcoat, then KHR_materials_coat over it.
void gltfCoat(const GltfPbr& g, NodeWriter& w, LayeredSurface& s) {
  // Clearcoat: a colourless dielectric (IOR 1.5) on top, its own roughness and normal.
  if (!off(g.clearcoat, 0)) {
    s.coatWeight = g.clearcoat;
    s.coatF0 = 0.04;
    s.coatRoughness = g.clearcoatRoughness.is_null() ? Value(0.0) : g.clearcoatRoughness;
    s.coatNormal = g.clearcoatNormal;
  }
  // KHR_materials_coat: the same with its IOR, an absorbing colour (one pass
  // each way: per-pass transmittance sqrt(coatColor)) and anisotropy.
  if (!off(g.coat, 0)) {
    s.coatWeight = g.coat;
    s.coatF0 = iorToF0Value(g.coatIor.is_null() ? Value(1.5) : g.coatIor);
    s.coatRoughness = g.coatRoughness.is_null() ? Value(0.0) : g.coatRoughness;
    s.coatNormal = g.coatNormal;
    if (!off(g.coatColor, 1)) s.coatTransmittance = vsqrt(g.coatColor);
    if (!off(g.coatAnisotropyStrength, 0)) {
      const RoughnessAnisotropy ra = anisotropic(w, "coat_", s.coatRoughness, g.coatAnisotropyStrength);
      s.coatRoughness = ra.roughness;
      s.coatAnisotropy = ra.anisotropy;
      s.coatTangent = rotatedTangent(g.coatAnisotropyRotation);
    }
  }
}

}  // namespace

LayeredSurface gltfPbrSurface(const GltfPbr& g, NodeWriter& w) {
  LayeredSurface s;
  const Value baseColor = namedValue(w, "base_color", g.baseColor.is_null() ? literal3(1, 1, 1) : g.baseColor);
  s.baseColor = baseColor;
  s.metallic = g.metallic.is_null() ? Value(1.0) : g.metallic;
  s.roughness = g.roughness.is_null() ? Value(1.0) : g.roughness;
  s.normal = g.normal;

  if (g.unlit) {
    // KHR_materials_unlit: the base colour is the radiance; nothing reflects:
    // the unlit BSDF (no closure).
    s.unlit = true;
    s.emissive = baseColor;
    s.opacity = g.alpha;
    s.alphaMode = g.alphaMode;
    s.alphaCutoff = g.alphaCutoff;
    return s;
  }

  gltfSpecular(g, w, s);
  gltfFuzz(g, w, s);

  // Thin-film iridescence: F0 = vlerp(F0, thin_film(F0, F90, d, ior).f0, factor), d in metres.
  if (!off(g.iridescence, 0)) {
    s.filmWeight = g.iridescence;
    s.filmThickness = mul(g.iridescenceThickness.is_null() ? Value(400.0) : g.iridescenceThickness, 1e-9);
    s.filmIor = g.iridescenceIor.is_null() ? Value(1.3) : g.iridescenceIor;
  }

  // Transmission: the dielectric transmits, tinted by the base colour, and the
  // volume attenuates over its thickness: T = baseColor · attenuationColor^(thickness / distance).
  if (!off(g.transmission, 0)) {
    s.transmission = g.transmission;
    Value t = baseColor;
    if (g.attenuationDistance > 0 && !off(g.thickness, 0) && !off(g.attenuationColor, 1))
      t = mul(t, vpow(g.attenuationColor, divide(g.thickness, g.attenuationDistance)));
    s.transmittance = t;
  }

  // Diffuse transmission: the closest slab medium is wrap lighting (light from
  // below the horizon): per-channel wrap w = factor · colour (at most 0.95),
  // mfp = scale · w / (1 − w); the diffuse colour leans to the transmission colour.
  if (!off(g.diffuseTransmission, 0)) {
    const Value color = g.diffuseTransmissionColor.is_null() ? literal3(1, 1, 1) : g.diffuseTransmissionColor;
    const Value wrap = namedValue(w, "diffuse_transmission_wrap", vmin(mul(g.diffuseTransmission, color), 0.95));
    s.sssMfp = divide(mul(wrap, kWrapMfpScale), oneMinus(wrap));
    s.sssType = "wrap";
    s.diffuseColor = vlerp(baseColor, color, mul(g.diffuseTransmission, 0.5));
  }

  gltfCoat(g, w, s);

  s.emissive = g.emissive;
  s.opacity = g.alpha;
  s.alphaMode = g.alphaMode;
  s.alphaCutoff = g.alphaCutoff;
  return s;
}

namespace {

using Kind = BlockPin::Kind;

/// The Value members of GltfPbr as the block's pins.
struct GltfValuePin {
  BlockPin pin;
  Value GltfPbr::*member;
};

const std::vector<GltfValuePin>& gltfValuePins() {
  constexpr double kBig = 1e300;
  static const std::vector<GltfValuePin> pins = {
      {{"base_color", Kind::Color, 0, 1}, &GltfPbr::baseColor},
      {{"alpha", Kind::Float, 0, 1}, &GltfPbr::alpha},
      {{"metallic", Kind::Float, 0, 1}, &GltfPbr::metallic},
      {{"roughness", Kind::Float, 0, 1}, &GltfPbr::roughness},
      {{"normal", Kind::Vec3}, &GltfPbr::normal},
      {{"emissive", Kind::Color, 0, kBig}, &GltfPbr::emissive},
      {{"ior", Kind::Float, 1, kBig}, &GltfPbr::ior},
      {{"specular", Kind::Float, 0, 1}, &GltfPbr::specular},
      {{"specular_color", Kind::Color, 0, kBig}, &GltfPbr::specularColor},
      {{"clearcoat", Kind::Float, 0, 1}, &GltfPbr::clearcoat},
      {{"clearcoat_roughness", Kind::Float, 0, 1}, &GltfPbr::clearcoatRoughness},
      {{"clearcoat_normal", Kind::Vec3}, &GltfPbr::clearcoatNormal},
      {{"coat", Kind::Float, 0, 1}, &GltfPbr::coat},
      {{"coat_roughness", Kind::Float, 0, 1}, &GltfPbr::coatRoughness},
      {{"coat_ior", Kind::Float, 1, kBig}, &GltfPbr::coatIor},
      {{"coat_color", Kind::Color, 0, 1}, &GltfPbr::coatColor},
      {{"coat_normal", Kind::Vec3}, &GltfPbr::coatNormal},
      {{"coat_anisotropy_strength", Kind::Float, 0, 1}, &GltfPbr::coatAnisotropyStrength},
      {{"coat_anisotropy_rotation", Kind::Float}, &GltfPbr::coatAnisotropyRotation},
      {{"sheen_color", Kind::Color, 0, 1}, &GltfPbr::sheenColor},
      {{"sheen_roughness", Kind::Float, 0, 1}, &GltfPbr::sheenRoughness},
      {{"fuzz", Kind::Float, 0, 1}, &GltfPbr::fuzz},
      {{"fuzz_color", Kind::Color, 0, 1}, &GltfPbr::fuzzColor},
      {{"fuzz_roughness", Kind::Float, 0, 1}, &GltfPbr::fuzzRoughness},
      {{"transmission", Kind::Float, 0, 1}, &GltfPbr::transmission},
      {{"thickness", Kind::Float, 0, kBig}, &GltfPbr::thickness},
      {{"attenuation_color", Kind::Color, 0, 1}, &GltfPbr::attenuationColor},
      {{"iridescence", Kind::Float, 0, 1}, &GltfPbr::iridescence},
      {{"iridescence_ior", Kind::Float, 1, kBig}, &GltfPbr::iridescenceIor},
      {{"iridescence_thickness", Kind::Float, 0, kBig}, &GltfPbr::iridescenceThickness},
      {{"anisotropy_strength", Kind::Float, 0, 1}, &GltfPbr::anisotropyStrength},
      {{"anisotropy_direction", Kind::Vec2}, &GltfPbr::anisotropyDirection},
      {{"diffuse_transmission", Kind::Float, 0, 1}, &GltfPbr::diffuseTransmission},
      {{"diffuse_transmission_color", Kind::Color, 0, 1}, &GltfPbr::diffuseTransmissionColor},
  };
  return pins;
}

constexpr const char* kAlphaModes[] = {"opaque", "mask", "blend"};

}  // namespace

BlockSignature gltfPbrSignature() {
  BlockSignature sig{"gltf_pbr", {}};
  for (const GltfValuePin& p : gltfValuePins()) sig.pins.push_back(p.pin);
  sig.pins.push_back({"attenuation_distance", Kind::Number, 0, 1e300});
  sig.pins.push_back({"anisotropy_rotation", Kind::Number});
  sig.pins.push_back({"unlit", Kind::Flag});
  sig.pins.push_back({"alpha_mode", Kind::Choice, -1e300, 1e300, false, {kAlphaModes[0], kAlphaModes[1], kAlphaModes[2]}});
  sig.pins.push_back({"alpha_cutoff", Kind::Number, 0, 1e300});  // glTF's: at least 0, no maximum
  return sig;
}

Json gltfPbrBlock(const GltfPbr& g) {
  Json block = {{"kind", "gltf_pbr"}};
  for (const GltfValuePin& p : gltfValuePins())
    if (!(g.*p.member).is_null()) block[p.pin.name] = g.*p.member;
  if (g.attenuationDistance != 0) block["attenuation_distance"] = g.attenuationDistance;
  if (g.anisotropyRotation != 0) block["anisotropy_rotation"] = g.anisotropyRotation;
  if (g.unlit) block["unlit"] = true;
  if (g.alphaMode != AlphaMode::Opaque) block["alpha_mode"] = kAlphaModes[static_cast<int>(g.alphaMode)];
  if (g.alphaCutoff != 0.5) block["alpha_cutoff"] = g.alphaCutoff;
  return block;
}

BuildingBlock gltfPbrBuildingBlock() {
  return {gltfPbrSignature(), [](const Json& block, BlockContext& c) {
            return layeredSurfaceNodes(gltfPbrSurface(gltfPbrOfBlock(block), c.w), c.w);
          }};
}

void writeGltfPbrBlock(GltfPbr g, MaterialWriter& w) {
  DiscardingNodeWriter scratch;  // the surface, for its settings and presence only
  const LayeredSurface s = gltfPbrSurface(g, scratch);
  if (presenceFoldsToZero(s)) g.alpha = w.invisiblePresence();
  writeSurfaceOutput(s, w.node("surface", gltfPbrBlock(g)), w);
}

GltfPbr gltfPbrOfBlock(const Json& block) {
  GltfPbr g;
  for (const GltfValuePin& p : gltfValuePins())
    if (auto it = block.find(p.pin.name); it != block.end()) g.*p.member = *it;
  g.attenuationDistance = block.value("attenuation_distance", 0.0);
  g.anisotropyRotation = block.value("anisotropy_rotation", 0.0);
  g.unlit = block.value("unlit", false);
  const std::string mode = block.value("alpha_mode", std::string("opaque"));
  g.alphaMode = mode == "mask" ? AlphaMode::Mask : mode == "blend" ? AlphaMode::Blend : AlphaMode::Opaque;
  g.alphaCutoff = block.value("alpha_cutoff", 0.5);
  return g;
}

}  // namespace substratec::blocks
