#include "import/mtlx_import.h"

#include <cmath>

#include <fmt/format.h>

#include "import/mtlx_document.h"
#include "import/mtlx_surfaces.h"

namespace substratec::import {

RoughnessAnisotropy mtlxRoughnessAnisotropy(const Value& roughness, const Value& anisotropy, MaterialWriter& w,
                                            const std::string& prefix) {
  const Value r = namedValue(w, prefix + "roughness", roughness);
  const Value a = namedValue(w, prefix + "alpha", vmax(mul(r, r), 1e-6));
  const Value aspect = namedValue(w, prefix + "aspect", vsqrt(oneMinus(vmin(anisotropy, 0.98))));
  const Value at = namedValue(w, prefix + "alpha_t", vmin(divide(a, aspect), 1.0));
  const Value ab = namedValue(w, prefix + "alpha_b", mul(a, aspect));
  return fromAlphas(at, ab);
}

RoughnessAnisotropy roughnessPins(const Value& roughness, const Value& anisotropy, MaterialWriter& w,
                                  const std::string& prefix, AnisotropyModel model) {
  if (anisotropy.is_null() || isLiteral(anisotropy, 0)) return {roughness, Value()};
  const RoughnessAnisotropy ra = model(roughness, anisotropy, w, prefix);
  return {namedValue(w, (prefix == "specular_" ? "" : prefix) + "anisotropic_roughness", ra.roughness), ra.anisotropy};
}

void mtlxTransmission(pugi::xml_node n, MtlxValues& v, const Value& weight, const char* dispersion,
                      LayeredSurface& s) {
  auto C = [&](const char* name, const char* type, std::vector<double> def) {
    return v.constant(n, name, type, def).value_or(def);
  };
  s.transmission = weight;
  s.transmittance = v.param(n, "transmission_color", "color3", {1, 1, 1});
  v.warn(n, std::string("transmission: ") + kTransmissionNote);
  if (C("transmission_depth", "float", {0})[0] > 0)
    v.warn(n, "transmission_depth: a surface material does not know the object's thickness; transmission_color "
              "is applied once, as if the light crossed one depth");
  const auto scatter = C("transmission_scatter", "color3", {0, 0, 0});
  if (scatter[0] != 0 || scatter[1] != 0 || scatter[2] != 0)
    v.warn(n, "transmission_scatter: volume scattering inside the transmitting medium is not represented");
  if (C(dispersion, "float", {0})[0] != 0) v.warn(n, std::string(dispersion) + ": one IOR for every colour; dispersion ignored");
}

namespace {

using SurfaceFn = LayeredSurface (*)(pugi::xml_node, MtlxValues&, MaterialWriter&);

SurfaceFn modelOf(const std::string& kind) {
  if (kind == "standard_surface") return standardSurface;
  if (kind == "open_pbr_surface") return openPbrSurface;
  if (kind == "gltf_pbr") return mtlxGltfPbr;
  if (kind == "UsdPreviewSurface") return usdPreviewSurface;
  if (kind == "disney_principled") return disneyPrincipled;
  return nullptr;
}

}  // namespace

bool importMaterialXDocument(const std::string& text, const std::string& fileName, const std::string& baseDir,
                             const ReadLimits& limits, Diagnostics& diags, std::vector<ImportedMaterial>* out) {
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
    SurfaceFn model = modelOf(shader.name());
    if (!model) {
      std::string what = fmt::format("unsupported shading model '{}'", shader.name());
      if (std::string(shader.name()) == "surface") {
        pugi::xml_node bsdf = shader.find_child_by_attribute("input", "name", "bsdf");
        pugi::xml_node b = bsdf ? values.resolveNodeName(shader, bsdf.attribute("nodename").as_string()) : pugi::xml_node();
        if (b) {
          shader = b;
          what = fmt::format("unsupported node '{}': a {} is not a Substrate slab (no import rule for it)", b.name(),
                             std::string(b.name()).find("hair") != std::string::npos ? "hair fibre BSDF" : "BSDF node");
        }
      }
      values.error(shader, what + fmt::format(" (material {})", quoteForDiagnostic(sourceName)));
      ok = false;
      continue;
    }
    LayeredSurface s = model(shader, values, w);
    for (std::size_t i = 0; i < bound.size(); ++i) values.popBinding();
    if (!values.ok()) {
      ok = false;
      continue;
    }
    writeLayeredSurface(s, w);
    out->push_back({sourceName, name, fmt::format("line {}", line), w.text(), {}});
  }
  return ok;
}

}  // namespace substratec::import
