// The materials `substratec render` draws a glTF scene's primitives with.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "format/json_document.h"
#include "import/import.h"
#include "mesh/gltf_mesh.h"

namespace substratec::render {

struct SceneSources {
  std::vector<import::MaterialSource> sources;  // each compiled once
  std::vector<int> primitiveMaterial;           // per primitive: its index in `sources`
};

/// The document's own materials, imported (import/gltf_import.h), one source
/// per /materials/N some primitive uses, and glTF's default material (the
/// importer's reading of an empty material: white, metallic 1, roughness 1)
/// for primitives without one. nullopt, with the importer's located errors.
std::optional<SceneSources> gltfSceneSources(const std::string& modelPath, const mesh::Scene& scene,
                                             const ReadLimits& limits, Diagnostics& diags);

/// `source` for every primitive (`render --material`).
SceneSources oneMaterialSources(import::MaterialSource source, const mesh::Scene& scene);

}  // namespace substratec::render
