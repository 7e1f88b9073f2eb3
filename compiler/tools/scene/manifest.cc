#include "scene/manifest.h"

#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "passes/resolve.h"

namespace substratec {

std::optional<SceneManifest> parseSceneManifest(const std::string& manifestPath, const std::string& text,
                                                const ReadLimits& limits, Diagnostics& diags) {
  const std::size_t errorsBefore = diags.errorCount();
  auto scene = readSceneManifest(manifestPath, text, limits, diags);
  if (!scene || diags.errorCount() > errorsBefore) return std::nullopt;
  return scene;
}

std::optional<SceneManifest> readSceneManifest(const std::string& manifestPath, const std::string& text,
                                               const ReadLimits& limits, Diagnostics& diags) {
  auto doc = parseJsonDocument(text, limits, diags);
  if (!doc) return std::nullopt;
  if (!doc->is_object()) {
    diags.error("", fmt::format("expected the scene object at the top level, got {}", kindOfJson(*doc)));
    return std::nullopt;
  }
  SceneManifest scene;
  scene.locator = diags.locator();
  for (auto it = doc->begin(); it != doc->end(); ++it) {
    const std::string& key = it.key();
    if (key == "$schema" || key == "description") {
      if (!it->is_string()) diags.error("/" + pointerToken(key), "expected a string");
    } else if (key != "format" && key != "name" && key != "materials" && key != "platform") {
      diags.error("/" + pointerToken(key),
                  fmt::format("unknown key {} (expected one of: format, name, materials, platform, description)",
                              quoteForDiagnostic(key)));
    }
  }
  auto fmtIt = doc->find("format");
  if (fmtIt == doc->end())
    diags.error("", "missing required key \"format\" (expected \"substrate-scene/1\")");
  else if (!fmtIt->is_string() || fmtIt->get<std::string>() != "substrate-scene/1")
    diags.error("/format", fmt::format("expected \"substrate-scene/1\", got {}", kindOfJson(*fmtIt)));

  auto nameIt = doc->find("name");
  if (nameIt == doc->end()) {
    diags.error("", "missing required key \"name\"");
  } else if (!nameIt->is_string() || !isUsableIdentifier(nameIt->get<std::string>())) {
    diags.error("/name", fmt::format("expected a C identifier of at most 128 bytes without \"__\", not beginning "
                                     "with '_' or \"gl_\", not ending with '_', not a keyword (it names the "
                                     "scene's shaders), got {}",
                                     kindOfJson(*nameIt)));
  } else {
    scene.name = nameIt->get<std::string>();
  }

  if (auto p = doc->find("platform"); p != doc->end()) {
    if (!p->is_string()) diags.error("/platform", fmt::format("expected a platform name, got {}", kindOfJson(*p)));
    else scene.platform = p->get<std::string>();
    scene.platformPointer = "/platform";
  }

  auto matIt = doc->find("materials");
  if (matIt == doc->end()) {
    diags.error("", "missing required key \"materials\" (an array of material file paths)");
  } else if (!matIt->is_array() || matIt->empty()) {
    diags.error("/materials", fmt::format("expected a non-empty array of material file paths, got {}", kindOfJson(*matIt)));
  } else if (matIt->size() > kMaxSceneMaterials) {
    diags.error("/materials", fmt::format("a scene lists at most {} materials, this one {}", kMaxSceneMaterials,
                                          matIt->size()));
  } else {
    const std::filesystem::path dir = std::filesystem::path(manifestPath).parent_path();
    std::map<std::string, std::string> seen;  // normalized path -> pointer
    for (std::size_t i = 0; i < matIt->size(); ++i) {
      const std::string ptr = fmt::format("/materials/{}", i);
      const Json& e = (*matIt)[i];
      if (!e.is_string() || e.get_ref<const std::string&>().empty() ||
          e.get_ref<const std::string&>().find('\0') != std::string::npos) {
        diags.error(ptr, fmt::format("expected a material file path (relative to the manifest), got {}", kindOfJson(e)));
        continue;
      }
      const std::string written = e.get<std::string>();
      std::string path = (dir / written).lexically_normal().string();
      if (auto [at, inserted] = seen.emplace(path, ptr); !inserted) {
        diags.error(ptr, fmt::format("{} is already listed at {}", quoteForDiagnostic(written), at->second));
        continue;
      }
      scene.materials.push_back({written, path, ptr});
    }
  }
  return scene;
}

}  // namespace substratec
