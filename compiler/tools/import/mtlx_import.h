// Importing a MaterialX document: every `surfacematerial` (after includes)
// whose surface shader is one of the shading models below, mapped to
// Substrate by that model's unit (mtlx_surfaces.h) and written as one
// substrate-material/1 text. A shader node the document defines itself (a
// `nodedef` with a node graph implementation) is followed into its graph. A
// shading model, node or connection that cannot be imported is an error at
// its line naming it; approximations are warnings naming the material.
#pragma once
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "blocks/material_writer.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

/// Appends the materials of the MaterialX document `text` (from `fileName`;
/// includes read from `baseDir`). A Standard Surface, OpenPBR or Disney
/// principled shader is written as its building block, or expanded (`form`).
/// False on any error.
bool importMaterialXDocument(const std::string& text, const std::string& fileName, const std::string& baseDir,
                             const ReadLimits& limits, Diagnostics& diags, std::vector<ImportedMaterial>* out,
                             ImportForm form = ImportForm::Blocks);

}  // namespace substratec::import
