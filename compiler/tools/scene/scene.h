// `substratec scene SCENE.json -o DIR` (docs/scenes.md): every material of a
// substrate-scene/1 manifest compiled and simplified for the scene's
// platform (in parallel, batch/batch.h), then the lighting the scene needs and
// no more (emit/scene_emitter.h): tile classification and one lighting shader
// per tile class its pixels can have, specialized to the features, closures
// and words its materials store after simplification. Every shader is
// validated in-process in both languages before anything is returned;
// DIR/scene.json reports what was built.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "batch/batch.h"
#include "output/atomic_write.h"

namespace substratec {

struct SceneOptions {
  std::string manifest;                 // the substrate-scene/1 file, as given
  std::optional<std::string> platform;  // --platform: overrides the manifest's
  std::string platformsFile;            // --platforms: extends the built-in table
  BatchOptions batch;                   // read limits, budget overrides, targets, diffuse model, -j, --cache
};

/// How a scene build ended (the CLI maps it to its exit code).
enum class SceneStatus { Ok, BadInput, BadUsage, InternalError };

struct SceneBuild {
  SceneStatus status = SceneStatus::Ok;
  std::string messages;             // everything for stderr, in a fixed order
  std::vector<OutputFile> files;    // every output (materials, lighting, scene.json); empty unless status is 0
  std::vector<std::string> inputs;  // every file read (manifest, platforms file, materials): the depfile's
  std::vector<OutputPath> cacheEntries;  // --cache entries to write with the outputs (all or none)
  int cacheHits = 0;                // materials taken from --cache
};

SceneBuild buildScene(const SceneOptions& options);

}  // namespace substratec
