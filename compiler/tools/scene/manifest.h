// The scene manifest, `substrate-scene/1` (schema/substrate-scene.schema.json,
// docs/scenes.md): a name, the material files the scene uses, and optionally
// the platform it is built for. Read with the materials' strict JSON reader;
// every problem is located at its line:col (and named by JSON pointer).
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"

namespace substratec {

/// Most materials one scene may list.
inline constexpr std::size_t kMaxSceneMaterials = 4096;

struct SceneMaterialRef {
  std::string written;  // the path as the manifest writes it
  std::string path;     // relative to the manifest's directory, lexically normalized (what is opened)
  std::string pointer;  // "/materials/3"
};

struct SceneManifest {
  std::string name;                    // a C identifier: names the scene's output files
  std::vector<SceneMaterialRef> materials;
  std::optional<std::string> platform;  // "platform", when given
  std::string platformPointer;          // "/platform"
  std::shared_ptr<const SourceLocator> locator;  // locates the pointers above in the manifest's text
};

/// Parses the manifest text; `manifestPath` locates relative material paths.
/// Duplicate material paths (after normalization) are errors. Every error is
/// reported (one does not hide the others); nullopt when there is any.
std::optional<SceneManifest> parseSceneManifest(const std::string& manifestPath, const std::string& text,
                                                const ReadLimits& limits, Diagnostics& diags);

/// The same, but what could be read even when there are errors (nullopt only
/// when the text is not a JSON object): the materials listed correctly, each
/// once, and the name and platform when they are usable. A scene build uses it
/// to go on to its materials' errors after the manifest's.
std::optional<SceneManifest> readSceneManifest(const std::string& manifestPath, const std::string& text,
                                               const ReadLimits& limits, Diagnostics& diags);

}  // namespace substratec
