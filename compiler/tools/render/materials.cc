#include "render/materials.h"

#include <filesystem>
#include <map>

namespace substratec::render {

namespace {

/// glTF's default material (glTF 2.0, 3.9.6: base colour 1, metallic 1,
/// roughness 1), as the importer reads a material with no properties.
std::optional<import::MaterialSource> defaultMaterial(const ReadLimits& limits, Diagnostics& diags) {
  const std::string doc = R"({"asset":{"version":"2.0"},"materials":[{"name":"gltf_default_material"}]})";
  auto imported = import::importText(import::SourceKind::Gltf, "default material", doc, ".", limits, diags);
  if (!imported || imported->size() != 1) return std::nullopt;
  return import::MaterialSource{"glTF default material", (*imported)[0].text, true, ".", {}};
}

}  // namespace

std::optional<SceneSources> gltfSceneSources(const std::string& modelPath, const mesh::Scene& scene,
                                             const ReadLimits& limits, Diagnostics& diags) {
  SceneSources out;
  bool anyMaterial = false;
  for (const mesh::Primitive& p : scene.primitives) anyMaterial = anyMaterial || p.material >= 0;
  std::vector<import::ImportedMaterial> imported;
  if (anyMaterial) {
    auto all = import::importFile(modelPath, limits, diags);
    if (!all) return std::nullopt;
    imported = std::move(*all);
  }
  const std::string baseDir = std::filesystem::path(modelPath).parent_path().string();
  std::map<int, int> sourceOf;  // glTF material index (-1: the default) -> index in out.sources
  for (const mesh::Primitive& p : scene.primitives) {
    auto it = sourceOf.find(p.material);
    if (it == sourceOf.end()) {
      const import::ImportedMaterial* m = nullptr;
      for (const import::ImportedMaterial& candidate : imported)
        if (p.material >= 0 && candidate.location == "/materials/" + std::to_string(p.material)) m = &candidate;
      if (m) {
        out.sources.push_back({modelPath + "[" + m->name + "]", m->text, true, baseDir.empty() ? "." : baseDir,
                               m->images});
      } else {
        auto fallback = defaultMaterial(limits, diags);
        if (!fallback) return std::nullopt;
        out.sources.push_back(std::move(*fallback));
      }
      it = sourceOf.emplace(p.material, static_cast<int>(out.sources.size()) - 1).first;
    }
    out.primitiveMaterial.push_back(it->second);
  }
  return out;
}

SceneSources oneMaterialSources(import::MaterialSource source, const mesh::Scene& scene) {
  SceneSources out;
  out.sources.push_back(std::move(source));
  out.primitiveMaterial.assign(scene.primitives.size(), 0);
  return out;
}

}  // namespace substratec::render
