#include "import/import.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "import/glb_container.h"
#include "import/gltf_import.h"
#include "import/gltf_resources.h"
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
                                                        const ReadLimits& limits, Diagnostics& diags,
                                                        ImportForm form) {
  std::vector<ImportedMaterial> out;
  bool ok = false;
  if (kind == SourceKind::MaterialX) {
    ok = importMaterialXDocument(text, fileName, baseDir, limits, diags, &out, form);
  } else {
    std::string json = text;
    std::optional<std::size_t> binBytes;
    std::optional<std::string> bin;
    const bool glb = kind == SourceKind::Glb || (kind == SourceKind::Gltf && looksLikeGlb(text));
    if (glb) {
      auto chunk = glbJsonChunk(text, diags);
      if (!chunk) return std::nullopt;
      json = std::move(*chunk);
      binBytes = glbBinChunkSize(text);
      bin = glbBinChunk(text);
    }
    auto doc = parseJsonDocument(json, limits, diags);
    if (!doc) return std::nullopt;
    // A .glb's JSON chunk: its lines are not the file's, so its pointers stay unlocated.
    if (glb) diags.setLocator(nullptr);
    ok = importGltfDocument(*doc, fileName, diags, &out, bin ? &*bin : nullptr, form);
    // The buffers and images a .gltf or .glb refers to (gltf_resources.h);
    // a .materials.json extract has none.
    if (kind != SourceKind::GltfMaterials) ok = checkGltfResources(*doc, baseDir, binBytes, diags) && ok;
  }
  if (!ok || diags.hasErrors()) return std::nullopt;
  if (out.empty()) {
    diags.error("", "the file holds no material");
    return std::nullopt;
  }
  return out;
}

std::optional<std::vector<ImportedMaterial>> importFile(const std::string& path, const ReadLimits& limits,
                                                        Diagnostics& diags, ImportForm form) {
  auto text = readSourceFile(path, limits, diags);
  if (!text) return std::nullopt;
  const std::filesystem::path p(path);
  return importText(sourceKindOf(path), p.filename().string(), *text, p.parent_path().string(), limits, diags,
                    form);
}

const ImportedMaterial* pickMaterial(const std::vector<ImportedMaterial>& all, const std::string& wanted,
                                     Diagnostics& diags) {
  if (wanted.empty() && all.size() == 1) return &all[0];
  std::vector<const ImportedMaterial*> matches;
  if (!wanted.empty())
    for (const auto& m : all)
      if (m.name == wanted || m.sourceName == wanted) matches.push_back(&m);
  if (matches.size() == 1) return matches[0];
  auto describe = [](const ImportedMaterial& m) {
    std::string line = fmt::format("\n  {}", m.name);
    if (!m.sourceName.empty() && m.sourceName != m.name) line += fmt::format(" ({})", quoteForDiagnostic(m.sourceName));
    return line;
  };
  if (matches.size() > 1) {
    // Two materials answer to the name (two of the same source name, or one's
    // source name is another's identifier): choosing either would be a guess.
    std::string list;
    for (const ImportedMaterial* m : matches) list += describe(*m) + fmt::format(" at {}", m->location);
    diags.error("", fmt::format("{} materials are called {}; choose one by its identifier:{}", matches.size(),
                                quoteForDiagnostic(wanted), list));
    return nullptr;
  }
  std::string list;
  for (const auto& m : all) list += describe(m);
  diags.error("", wanted.empty()
                      ? fmt::format("the file holds {} materials; choose one with --material NAME:{}", all.size(), list)
                      : fmt::format("no material named {}; the file holds:{}", quoteForDiagnostic(wanted), list));
  return nullptr;
}

namespace {
/// The directory of `path` ("" for one in the working directory).
std::string baseDirOf(const std::string& path) { return std::filesystem::path(path).parent_path().string(); }
}  // namespace

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
    out.push_back({path, std::move(*text), false, baseDirOf(path), {}});
    return out;
  }
  auto imported = importFile(path, limits, diags);
  if (!imported) return std::nullopt;
  if (all && material.empty()) {
    for (auto& m : *imported)
      out.push_back({path + "[" + m.name + "]", std::move(m.text), true, baseDirOf(path), std::move(m.images)});
    return out;
  }
  const ImportedMaterial* m = pickMaterial(*imported, material, diags);
  if (!m) return std::nullopt;
  out.push_back({path + "[" + m->name + "]", m->text, true, baseDirOf(path), m->images});
  return out;
}

std::optional<std::vector<ImportInput>> collectImportInputs(const std::vector<std::string>& args,
                                                            std::string& messages) {
  namespace fs = std::filesystem;
  std::vector<ImportInput> out;
  std::set<std::string> seen;  // canonical paths: each file once
  bool ok = true;
  auto add = [&](const fs::path& p, bool fromDirectory) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(p, ec);
    if (seen.insert(ec ? p.lexically_normal().string() : canonical.string()).second)
      out.push_back({p.string(), fromDirectory});
  };
  for (const std::string& arg : args) {
    std::error_code ec;
    if (!fs::is_directory(arg, ec)) {
      if (sourceKindOf(arg) == SourceKind::Substrate) {
        messages += fmt::format("substratec: error: {}: import reads .gltf, .glb, .materials.json and .mtlx files "
                                "(and directories holding them); this is not one\n", arg);
        ok = false;
        continue;
      }
      add(arg, false);  // a missing file is reported when it is read
      continue;
    }
    std::vector<fs::path> found;
    fs::recursive_directory_iterator it(arg, fs::directory_options::skip_permission_denied, ec), end;
    for (; !ec && it != end; it.increment(ec)) {
      if (it->is_directory(ec) && !it->is_symlink(ec) && it.depth() + 1 >= kMaxImportDepth) {
        messages += fmt::format("substratec: warning: {}: deeper than {} levels below {}: not searched\n",
                                it->path().string(), kMaxImportDepth, arg);
        it.disable_recursion_pending();
        continue;
      }
      if (!it->is_regular_file(ec) || sourceKindOf(it->path().string()) == SourceKind::Substrate) continue;
      found.push_back(it->path());
      if (found.size() > kMaxImportFiles) break;
    }
    if (ec) {
      messages += fmt::format("substratec: error: {}: cannot search the directory: {}\n", arg, ec.message());
      ok = false;
      continue;
    }
    if (found.empty()) {
      messages += fmt::format("substratec: error: {}: is a directory holding no .gltf, .glb, .materials.json or .mtlx "
                              "file\n", arg);
      ok = false;
    }
    std::sort(found.begin(), found.end());
    for (const fs::path& p : found) add(p, true);
    if (out.size() > kMaxImportFiles) break;
  }
  if (out.size() > kMaxImportFiles) {
    messages += fmt::format("substratec: error: more than {} files to import (the import file-count limit): import "
                            "fewer directories at once\n", kMaxImportFiles);
    return std::nullopt;
  }
  if (!ok) return std::nullopt;
  return out;
}

Replace replaceCheck(const std::string& path, const std::string& text, const std::string& sourceFileName) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (ec || st.type() == fs::file_type::not_found) return Replace::Absent;
  if (st.type() != fs::file_type::regular) return Replace::Foreign;  // a directory, a link, a device: not ours
  const auto size = fs::file_size(path, ec);
  if (ec || size > (std::uintmax_t{16} << 20)) return Replace::Foreign;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream buf;
  buf << in.rdbuf();
  if (!in) return Replace::Foreign;
  const std::string old = buf.str();
  if (old == text) return Replace::Identical;
  const Json doc = Json::parse(old, nullptr, /*allow_exceptions=*/false);
  if (!doc.is_object() || doc.value("format", Json()) != "substrate-material/1") return Replace::Foreign;
  const Json description = doc.value("description", Json());
  if (!description.is_string()) return Replace::Foreign;
  const std::string marker = "Imported from " + sourceFileName + " ";
  return description.get_ref<const std::string&>().rfind(marker, 0) == 0 ? Replace::Imported : Replace::Foreign;
}

void renameMaterial(ImportedMaterial& m, const std::string& name) {
  Json doc = Json::parse(m.text);
  doc["name"] = name;
  m.text = doc.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
  m.name = name;
}

void rebaseImageFiles(ImportedMaterial& m, const std::string& fromDir, const std::string& toDir) {
  namespace fs = std::filesystem;
  Json doc = Json::parse(m.text);
  if (!doc.contains("inputs") || !doc["inputs"].is_object()) return;
  bool changed = false;
  std::error_code ec;
  const fs::path from = fs::absolute(fromDir.empty() ? "." : fromDir, ec).lexically_normal();
  const fs::path to = fs::absolute(toDir.empty() ? "." : toDir, ec).lexically_normal();
  for (auto& [name, input] : doc["inputs"].items()) {
    if (!input.is_object() || !input.contains("file") || !input["file"].is_string()) continue;
    const fs::path file(input["file"].get<std::string>());
    if (file.is_absolute() || m.images.count(file.string())) continue;  // embedded ones are written beside it
    input["file"] = (from / file).lexically_normal().lexically_relative(to).generic_string();
    changed = true;
  }
  if (changed) m.text = doc.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
}

}  // namespace substratec::import
