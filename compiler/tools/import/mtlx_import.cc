#include "import/mtlx_import.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "import/mtlx_document.h"
#include "import/mtlx_hair.h"
#include "import/mtlx_surfaces.h"

namespace substratec::import {

// ---- chiang_hair_bsdf (under a `surface`) as the format's hair node ----
// The formulas and their sources: mtlx_hair.h. In short:
//   roughness, azimuthal_roughness = the inverses of chiang_hair_roughness's
//     polynomials at roughness_R = (v, s) (clamped to [0.001, 1] as the BSDF
//     does); when roughness_R varies, it must be chiang_hair_roughness's
//     roughness_R, whose longitudinal and azimuthal roughness are then the
//     pins (clamped to what the BSDF's clamp leaves of them);
//   base_color = exp(−sqrt(absorption_coefficient) · P(azimuthal_roughness)),
//     written pow(e, ·) when it varies (the format has no exp), and for
//     chiang_hair_absorption_from_color(c, bn') connected straight to it,
//     clamp(c, 0.001, 1)^(P(azimuthal_roughness) / P(bn')) (c when bn' is
//     the hair's: no logarithm);
//   ior = ior (clamped to [1, 3]); cuticle_angle = (0.5 − cuticle_angle) ·
//     180 degrees (clamped to [−20, 20]); tangent = curve_direction (the
//     geometric tangent when unconnected or a `tangent` node); emissive = the
//     surface's uniform_edf colour.
// roughness_R and absorption_coefficient are constants at import whenever the
// document's values make them so (material inputs they read frozen, with a
// warning naming them). Warnings for what the hair node cannot express: tints
// other than 1, TT and TRT lobes that are not R's with pbrt's ratios
// (variance / 4 and · 4, the same azimuthal scale; 5% on the deviation and
// the scale), a normal, an opacity, another EDF.

namespace {

/// The R lobe as the hair node takes it, and what it was read from.
struct HairRoughness {
  Value longitudinal, azimuthal;
  double variance = -1, scale = -1;  // roughness_R's (v, s) when constant
  pugi::xml_node helper;             // the chiang_hair_roughness it reads otherwise
};

double clampRoughness(double x) { return std::clamp(x, hair::kMinRoughness, hair::kMaxRoughness); }

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

/// The hair node's roughness pins from roughness_R; `frozen` gains the
/// material inputs read at their values.
HairRoughness hairRoughness(pugi::xml_node bsdf, MtlxValues& v, std::vector<std::string>& frozen) {
  const std::size_t mark = v.frozenReads();
  if (const auto r = v.constant(bsdf, "roughness_R", "vector2", {0.1, 0.1})) {
    for (const auto& n : v.frozenInputsSince(mark)) frozen.push_back(n);
    HairRoughness h;
    h.variance = clampRoughness((*r)[0]);
    h.scale = clampRoughness((*r)[1]);
    h.longitudinal = tidy(hair::roughnessOfVariance(h.variance));
    h.azimuthal = tidy(hair::azimuthalRoughnessOfScale(h.scale));
    return h;
  }
  const auto [src, output] = v.upstream(bsdf, "roughness_R");
  if (src && std::string(src.name()) == "chiang_hair_roughness" && output == "roughness_R") {
    // The BSDF clamps v and s to [0.001, 1]: what is left of [0.001, 1] for l and a.
    const double lo = tidy(hair::roughnessOfVariance(hair::kMinRoughness));
    const double hi = tidy(hair::roughnessOfVariance(hair::kMaxRoughness));
    const double alo = tidy(hair::azimuthalRoughnessOfScale(hair::kMinRoughness));
    const double ahi = tidy(hair::azimuthalRoughnessOfScale(hair::kMaxRoughness));
    HairRoughness h;
    h.longitudinal = vclamp(v.value(src, "longitudinal", "float", {0.1}), lo, hi);
    h.azimuthal = vclamp(v.value(src, "azimuthal", "float", {0.2}), alo, ahi);
    h.helper = src;
    return h;
  }
  v.error(bsdf, "roughness_R varies: the hair node takes Chiang's roughness, and no value node inverts "
                "chiang_hair_roughness's polynomials (connect chiang_hair_roughness's roughness_R to it, or give it "
                "a constant value)");
  return {};
}

/// Warnings for TT and TRT lobes other than R's with pbrt's ratios.
void checkHairLobes(pugi::xml_node bsdf, MtlxValues& v, const HairRoughness& r) {
  struct Lobe {
    const char *name, *scaleName, *ratio;
    double k;  // variance ratio to R's
    std::vector<double> def;
  };
  const Lobe lobes[] = {{"roughness_TT", "scale_TT", "R's / 4", 0.25, {0.05, 0.05}},
                        {"roughness_TRT", "scale_TRT", "R's * 4", 4.0, {0.2, 0.2}}};
  auto differs = [](double a, double b) { return std::fabs(a - b) > 0.05 * std::max(std::fabs(b), 1e-6); };
  for (const Lobe& l : lobes) {
    const std::string follows =
        fmt::format("the hair node's lobe has {} longitudinal variance and R's azimuthal scale", l.ratio);
    if (r.variance >= 0) {
      const auto c = v.constant(bsdf, l.name, "vector2", l.def);
      if (!c) {
        v.warn(bsdf, fmt::format("{} varies: {}; not represented", l.name, follows));
        continue;
      }
      const double ev = clampRoughness(r.variance * l.k), av = clampRoughness((*c)[0]), as = clampRoughness((*c)[1]);
      if (differs(std::sqrt(av), std::sqrt(ev)) || differs(as, r.scale))
        v.warn(bsdf, fmt::format("{} ({:.6g}, {:.6g}): {}, ({:.6g}, {:.6g}) here; the authored lobe is not represented",
                                 l.name, (*c)[0], (*c)[1], follows, ev, r.scale));
      continue;
    }
    if (!r.helper) continue;
    const auto [src, output] = v.upstream(bsdf, l.name);
    if (src != r.helper || output != l.name) {
      v.warn(bsdf, fmt::format("{} does not read chiang_hair_roughness '{}' as roughness_R does: {}; not represented",
                               l.name, r.helper.attribute("name").as_string(), follows));
      continue;
    }
    const double pbrtScale = std::sqrt(l.k);
    const auto sc = v.constant(src, l.scaleName, "float", {pbrtScale});
    if (!sc || differs(std::fabs((*sc)[0]), pbrtScale))
      v.warn(src, fmt::format("{} {}: {} (a scale of {}); not represented", l.scaleName,
                              sc ? fmt::format("{:.6g}", (*sc)[0]) : std::string("varies"), follows, pbrtScale));
  }
}

/// Chiang's P(b) of eq. 9 (Horner), folded for a literal.
Value absorptionDenominator(const Value& b) {
  if (const auto c = literalOf(b); c && c->size() == 1) return tidy(hair::absorptionDenominator((*c)[0]));
  Value p = add(mul(b, 0.245), 5.574);
  for (const double k : {-10.73, 2.532, -0.215, 5.969}) p = add(mul(p, b), k);
  return p;
}

/// The hair node's base colour of absorption `sigma` at azimuthal roughness
/// `bn`: exp(−sqrt(sigma) P(bn)), as pow(e, ·) (the format has no exp).
Value colorOfAbsorption(const Value& sigma, const Value& bn) {
  const auto s = literalOf(sigma);
  const auto b = literalOf(bn);
  if (s && s->size() == 3 && b && b->size() == 1) {
    const hair::Vec3 c = hair::colorOfAbsorption({(*s)[0], (*s)[1], (*s)[2]}, (*b)[0]);
    return literal3(tidy(c[0]), tidy(c[1]), tidy(c[2]));
  }
  return vpow(std::numbers::e, mul(vsqrt(vmax(sigma, 0.0)), mul(absorptionDenominator(bn), -1.0)));
}

/// The hair node's base colour from absorption_coefficient; `frozen` gains the
/// material inputs read at their values.
Value hairBaseColor(pugi::xml_node bsdf, MtlxValues& v, const Value& bn, std::vector<std::string>& frozen) {
  const std::size_t mark = v.frozenReads();
  if (const auto s = v.constant(bsdf, "absorption_coefficient", "vector3", {0, 0, 0})) {
    for (const auto& n : v.frozenInputsSince(mark)) frozen.push_back(n);
    return colorOfAbsorption(literal(*s), bn);
  }
  const auto [src, output] = v.upstream(bsdf, "absorption_coefficient");
  if (src && std::string(src.name()) == "chiang_hair_absorption_from_color") {
    // sigma = (ln c / P(bn'))^2 into exp(−sqrt(sigma) P(bn)): c^(P(bn) / P(bn')), no logarithm.
    const Value c = vclamp(v.value(src, "color", "color3", {1, 1, 1}), hair::kMinColor, 1.0);
    const Value bnFrom = v.value(src, "azimuthal_roughness", "float", {0.2});
    return vpow(c, divide(absorptionDenominator(bn), absorptionDenominator(bnFrom)));
  }
  return colorOfAbsorption(v.param(bsdf, "absorption_coefficient", "vector3", {0, 0, 0}), bn);
}

/// The hair node's cuticle angle (degrees) from cuticle_angle.
Value hairCuticleAngle(pugi::xml_node bsdf, MtlxValues& v) {
  Value degrees = mul(sub(0.5, v.param(bsdf, "cuticle_angle", "float", {0.5})), 180.0);
  const auto c = v.constant(bsdf, "cuticle_angle", "float", {0.5});
  if (c && std::fabs(hair::cuticleDegrees((*c)[0])) <= hair::kMaxCuticleDegrees) return degrees;
  if (c)
    v.warn(bsdf, fmt::format("cuticle_angle {:.6g} ({:.6g} degrees of tilt): outside the hair node's [-20, 20] degrees; "
                             "clamped", (*c)[0], hair::cuticleDegrees((*c)[0])));
  return vclamp(degrees, -hair::kMaxCuticleDegrees, hair::kMaxCuticleDegrees);
}

/// Warnings for the inputs of the BSDF and its surface the hair node has no
/// pin for; the tangent (null: the geometric one) and the emission (null: none).
void hairExtras(pugi::xml_node surface, pugi::xml_node bsdf, MtlxValues& v, Value& tangent, Value& emissive) {
  for (const char* t : {"tint_R", "tint_TT", "tint_TRT"}) {
    const auto c = v.constant(bsdf, t, "color3", {1, 1, 1});
    if (!c) v.warn(bsdf, fmt::format("{} varies: the hair node has no per-lobe tint; not represented", t));
    else if (std::any_of(c->begin(), c->end(), [](double x) { return std::fabs(x - 1) > 1e-6; }))
      v.warn(bsdf, fmt::format("{} ({:.6g}, {:.6g}, {:.6g}): the hair node has no per-lobe tint; ignored (white)", t,
                               (*c)[0], (*c)[1], (*c)[2]));
  }
  const auto [dir, dirOutput] = v.upstream(bsdf, "curve_direction");
  if (v.given(bsdf, "curve_direction") && !(dir && std::string(dir.name()) == "tangent")) {
    tangent = v.param(bsdf, "curve_direction", "vector3", {1, 0, 0});
    v.warn(bsdf, "curve_direction: read as the hair node's tangent, a tangent-space direction (MaterialX's is in "
                 "world space)");
  }
  if (v.given(bsdf, "normal"))
    v.warn(bsdf, "normal: the hair node has no normal (a fibre scatters around its direction); ignored");
  const auto [edf, edfOutput] = v.upstream(surface, "edf");
  if (edf && std::string(edf.name()) == "uniform_edf") emissive = v.value(edf, "color", "color3", {1, 1, 1});
  else if (v.given(surface, "edf"))
    v.warn(surface, "edf: only a uniform_edf's colour becomes the hair node's emission; not imported");
  const auto opacity = v.constant(surface, "opacity", "float", {1});
  if (!opacity || (*opacity)[0] != 1)
    v.warn(surface, "opacity: a hair node is the whole material, without a presence; ignored (opaque)");
}

}  // namespace

void chiangHairSurface(pugi::xml_node surface, pugi::xml_node bsdf, MtlxValues& v, MaterialWriter& w) {
  std::vector<std::string> frozen;  // material inputs read at their values
  const HairRoughness r = hairRoughness(bsdf, v, frozen);
  if (r.longitudinal.is_null()) return;  // an error
  const bool roughnessFrozen = !frozen.empty();
  checkHairLobes(bsdf, v, r);
  const Value bn = namedValue(w, "azimuthal_roughness", r.azimuthal);
  const std::size_t beforeColor = frozen.size();
  const Value baseColor = namedValue(w, "base_color", hairBaseColor(bsdf, v, bn, frozen));
  const bool colorFrozen = frozen.size() > beforeColor;
  if (roughnessFrozen || colorFrozen) {
    std::vector<std::string> names;
    for (const auto& n : frozen)
      if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    const bool both = roughnessFrozen && colorFrozen;
    v.warn(bsdf, fmt::format("{}: evaluated at import with the material inputs {} at their values ({}), into the "
                             "hair node's {}; changing those inputs at run time does not change this",
                             both ? "roughness_R and absorption_coefficient"
                                  : roughnessFrozen ? "roughness_R" : "absorption_coefficient",
                             both ? "they read" : "it reads", joined(names),
                             both ? "roughness and base colour" : roughnessFrozen ? "roughness" : "base colour"));
  }
  Value ior = v.param(bsdf, "ior", "float", {1.55});
  if (const auto c = v.constant(bsdf, "ior", "float", {1.55}); c && ((*c)[0] < 1 || (*c)[0] > 3)) {
    v.warn(bsdf, fmt::format("ior {:.6g}: outside the hair node's [1, 3]; clamped", (*c)[0]));
    ior = vclamp(ior, 1.0, 3.0);
  }
  Value tangent, emissive;
  hairExtras(surface, bsdf, v, tangent, emissive);
  Json node = {{"kind", "hair"},
               {"base_color", baseColor},
               {"roughness", r.longitudinal},
               {"azimuthal_roughness", bn},
               {"ior", ior},
               {"cuticle_angle", hairCuticleAngle(bsdf, v)}};
  if (!tangent.is_null()) node["tangent"] = tangent;
  if (!emissive.is_null() && !isLiteral(emissive, 0)) node["emissive"] = emissive;
  w.setOutput(w.node("hair", node));
}

namespace {

SurfaceUnit modelOf(const std::string& kind) {
  if (kind == "standard_surface") return standardSurface;
  if (kind == "open_pbr_surface") return openPbrSurface;
  if (kind == "gltf_pbr") return mtlxGltfPbr;
  if (kind == "UsdPreviewSurface") return usdPreviewSurface;
  if (kind == "disney_principled") return disneyPrincipled;
  return nullptr;
}

/// A shader whose model is a building block, written as that block (node
/// "surface", the output): its given parameters as pins, and the settings
/// and warnings of the block's expansion (run here on a scratch writer: the
/// unit is the same, so they are the flat import's).
void writeModelBlock(pugi::xml_node shader, ShaderParams& params, MtlxValues& values, MaterialWriter& w) {
  const Json block = blockModelBlock(shader.name(), params);
  std::vector<std::string> warnings;
  const Json document = {{"inputs", w.inputs()}};
  BlockParams pins(block, document, warnings);
  DiscardingNodeWriter scratch;
  const LayeredSurface s = blockModelUnit(shader.name())(pins, scratch);
  for (const std::string& warning : warnings) values.warn(shader, warning);
  writeSurfaceOutput(s, w.node("surface", block), w);
}

/// The chiang_hair_bsdf a `surface` shader scatters with (its bsdf input), or a null node.
pugi::xml_node hairBsdfOf(MtlxValues& values, pugi::xml_node shader) {
  if (std::string(shader.name()) != "surface") return {};
  const auto [bsdf, output] = values.upstream(shader, "bsdf");
  return bsdf && std::string(bsdf.name()) == "chiang_hair_bsdf" ? bsdf : pugi::xml_node();
}

/// The error for a shader that is none of the models: at the BSDF of a
/// `surface`, naming it, else at the shader.
void unsupportedShader(MtlxValues& values, pugi::xml_node shader, const std::string& material) {
  std::string what = fmt::format("unsupported shading model '{}'", shader.name());
  if (std::string(shader.name()) == "surface") {
    pugi::xml_node bsdf = shader.find_child_by_attribute("input", "name", "bsdf");
    pugi::xml_node b = bsdf ? values.resolveNodeName(shader, bsdf.attribute("nodename").as_string()) : pugi::xml_node();
    if (b) {
      shader = b;
      what = fmt::format("unsupported node '{}': a BSDF node is not a Substrate slab (no import rule for it; a "
                         "surface imports a chiang_hair_bsdf alone)", b.name());
    }
  }
  values.error(shader, what + fmt::format(" (material {})", quoteForDiagnostic(material)));
}

}  // namespace

bool importMaterialXDocument(const std::string& text, const std::string& fileName, const std::string& baseDir,
                             const ReadLimits& limits, Diagnostics& diags, std::vector<ImportedMaterial>* out,
                             ImportForm form) {
  MtlxDocument doc;
  if (!doc.load(text, fileName, baseDir, limits, diags)) return false;
  bool ok = true;
  NameSet used(/*caseInsensitive=*/true);
  for (pugi::xml_node material : doc.topLevel()) {
    if (std::string(material.name()) != "surfacematerial") continue;
    const std::string sourceName = material.attribute("name").as_string();
    const std::string name = uniqueMaterialName(used, sourceName, "material");
    int line = 0, column = 0;
    doc.lineColumn(material, line, column);
    MaterialWriter w(name);
    w.setDescription(fmt::format("Imported from {} surfacematerial {} (MaterialX).", fileName, quoteForDescription(sourceName)));
    MtlxValues values(doc, w, diags, quoteForDiagnostic(sourceName));
    for (const char* other : {"displacementshader", "volumeshader"})
      if (material.find_child_by_attribute("input", "name", other))
        values.warn(material, fmt::format("its {} is not imported (a Substrate material is a surface)", other));
    pugi::xml_node in = material.find_child_by_attribute("input", "name", "surfaceshader");
    pugi::xml_node shader;
    if (in && in.attribute("nodename")) shader = values.resolveNodeName(material, in.attribute("nodename").as_string());
    if (!shader) {
      values.error(material, in ? fmt::format("its surfaceshader '{}' is not in the document",
                                              in.attribute("nodename").as_string())
                                : std::string("it has no surfaceshader input"));
      ok = false;
      continue;
    }
    // A shader the document defines with a nodedef: follow its graph to the model inside.
    std::vector<MtlxValues::Binding> bound;
    for (int guard = 0; !modelOf(shader.name()) && guard < 8; ++guard) {
      auto impl = values.implementation(shader);
      if (!impl) break;
      auto [node, output] = values.resolveGraphOutput(impl->graph, "", shader);
      if (!node) break;
      values.pushBinding(*impl);
      bound.push_back(*impl);
      shader = node;
    }
    // The shading models, or a surface of a hair BSDF (written as the hair node).
    const SurfaceUnit model = modelOf(shader.name());
    const pugi::xml_node hairBsdf = model ? pugi::xml_node() : hairBsdfOf(values, shader);
    if (!model && !hairBsdf) {
      unsupportedShader(values, shader, sourceName);
      ok = false;
      continue;
    }
    LayeredSurface s;
    ShaderParams params(shader, values);
    const bool gltfBlock = form == ImportForm::Blocks && std::string(shader.name()) == "gltf_pbr";
    const bool asBlock = gltfBlock || (form == ImportForm::Blocks && blockModelUnit(shader.name()));
    if (gltfBlock) writeGltfPbrBlock(mtlxGltfPbrParams(params), w);
    else if (asBlock) writeModelBlock(shader, params, values, w);
    else if (model) s = model(params, w);
    else chiangHairSurface(shader, hairBsdf, values, w);
    for (std::size_t i = 0; i < bound.size(); ++i) values.popBinding();
    if (!values.ok()) {
      ok = false;
      continue;
    }
    if (model && !asBlock) writeLayeredSurface(s, w);
    out->push_back({sourceName, name, fmt::format("line {}", line), w.text(), {}});
  }
  return ok;
}

}  // namespace substratec::import
