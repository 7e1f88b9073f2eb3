#include "import/import.h"

#include <filesystem>

#include <fmt/format.h>

#include "import/glb_container.h"
#include "import/gltf_import.h"
#include "import/mtlx_import.h"

namespace substratec::import {

namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i) {
    char a = s[s.size() - suffix.size() + i];
    if (a >= 'A' && a <= 'Z') a = static_cast<char>(a - 'A' + 'a');
    if (a != suffix[i]) return false;
  }
  return true;
}

}  // namespace

SourceKind sourceKindOf(const std::string& path) {
  if (endsWith(path, ".materials.json")) return SourceKind::GltfMaterials;
  if (endsWith(path, ".gltf")) return SourceKind::Gltf;
  if (endsWith(path, ".glb")) return SourceKind::Glb;
  if (endsWith(path, ".mtlx")) return SourceKind::MaterialX;
  return SourceKind::Substrate;
}

std::optional<std::vector<ImportedMaterial>> importText(SourceKind kind, const std::string& fileName,
                                                        const std::string& text, const std::string& baseDir,
                                                        const ReadLimits& limits, Diagnostics& diags) {
  std::vector<ImportedMaterial> out;
  bool ok = false;
  if (kind == SourceKind::MaterialX) {
    ok = importMaterialXDocument(text, fileName, baseDir, limits, diags, &out);
  } else {
    std::string json = text;
    if (kind == SourceKind::Glb || (kind == SourceKind::Gltf && looksLikeGlb(text))) {
      auto chunk = glbJsonChunk(text, diags);
      if (!chunk) return std::nullopt;
      json = std::move(*chunk);
    }
    auto doc = parseJsonDocument(json, limits, diags);
    if (!doc) return std::nullopt;
    ok = importGltfDocument(*doc, fileName, diags, &out);
  }
  if (!ok || diags.hasErrors()) return std::nullopt;
  if (out.empty()) {
    diags.error("", "the file holds no material");
    return std::nullopt;
  }
  return out;
}

std::optional<std::vector<ImportedMaterial>> importFile(const std::string& path, const ReadLimits& limits,
                                                        Diagnostics& diags) {
  auto text = readSourceFile(path, limits, diags);
  if (!text) return std::nullopt;
  const std::filesystem::path p(path);
  return importText(sourceKindOf(path), p.filename().string(), *text, p.parent_path().string(), limits, diags);
}

const ImportedMaterial* pickMaterial(const std::vector<ImportedMaterial>& all, const std::string& wanted,
                                     Diagnostics& diags) {
  if (wanted.empty() && all.size() == 1) return &all[0];
  if (!wanted.empty()) {
    for (const auto& m : all)
      if (m.name == wanted) return &m;
    for (const auto& m : all)
      if (m.sourceName == wanted) return &m;
  }
  std::string list;
  for (const auto& m : all) {
    list += fmt::format("\n  {}", m.name);
    if (!m.sourceName.empty() && m.sourceName != m.name) list += fmt::format(" ({})", quoteForDiagnostic(m.sourceName));
  }
  diags.error("", wanted.empty()
                      ? fmt::format("the file holds {} materials; choose one with --material NAME:{}", all.size(), list)
                      : fmt::format("no material named {}; the file holds:{}", quoteForDiagnostic(wanted), list));
  return nullptr;
}

std::optional<std::vector<MaterialSource>> loadMaterialSources(const std::string& path, const std::string& material,
                                                               bool all, const ReadLimits& limits,
                                                               Diagnostics& diags) {
  std::vector<MaterialSource> out;
  if (sourceKindOf(path) == SourceKind::Substrate) {
    if (!material.empty()) {
      diags.error("", "--material chooses among the materials of a .gltf, .glb, .materials.json or .mtlx file");
      return std::nullopt;
    }
    auto text = readSourceFile(path, limits, diags);
    if (!text) return std::nullopt;
    out.push_back({path, std::move(*text), false});
    return out;
  }
  auto imported = importFile(path, limits, diags);
  if (!imported) return std::nullopt;
  if (all && material.empty()) {
    for (auto& m : *imported) out.push_back({path + "[" + m.name + "]", std::move(m.text), true});
    return out;
  }
  const ImportedMaterial* m = pickMaterial(*imported, material, diags);
  if (!m) return std::nullopt;
  out.push_back({path + "[" + m->name + "]", m->text, true});
  return out;
}

}  // namespace substratec::import
