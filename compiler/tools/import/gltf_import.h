// Reading glTF 2.0 materials: the `materials`, `textures`, `samplers` and
// `images` of a glTF JSON document (a .gltf file, the JSON chunk of a .glb, or
// a corpus `<Model>.materials.json` extract, which holds the same arrays),
// each material turned into glTF parameters (factors as material inputs named
// after them, textures as texture2d inputs named after their slot, sampled
// with their texcoord set and KHR_texture_transform) and then into Substrate
// through gltf_pbr.h. Problems are located by JSON pointer: errors for values
// of the wrong type or out of the document, warnings (naming the material)
// for everything the mapping cannot represent and what was done instead.
#pragma once
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "blocks/material_writer.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

/// Appends every material of `doc` to `out`. `fileName` (a file name, no
/// directories) goes into each material's description. A texture's image is
/// its input's `file`: a file's URI as a path, or for an image embedded in
/// the document (a data: URI, or a bufferView of a data: buffer or of a
/// .glb's binary chunk `glbBin`) "<fileName's stem>_image<N>.<ext>" with its
/// bytes in ImportedMaterial::images. Each material is a `gltf_pbr` block, or
/// its expansion (`form`). False on any error.
bool importGltfDocument(const Json& doc, const std::string& fileName, Diagnostics& diags,
                        std::vector<ImportedMaterial>* out, const std::string* glbBin = nullptr,
                        ImportForm form = ImportForm::Blocks);

}  // namespace substratec::import
