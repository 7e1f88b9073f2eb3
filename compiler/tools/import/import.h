// `substratec import` and the on-the-fly import of report/compile/preview/
// sweep: recognises a source by its name (.gltf, .glb, .mtlx, and the corpus'
// <Model>.materials.json extracts), reads it within the input-size limit, and
// turns each of its materials into substrate-material/1 text (gltf_import.h,
// mtlx_import.h). The text is then compiled like any hand-written material
// (compileText): the importer never builds IR itself.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "blocks/material_writer.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

enum class SourceKind { Substrate, Gltf, Glb, GltfMaterials, MaterialX };

/// What `path`'s name says it is (".materials.json" before ".json").
SourceKind sourceKindOf(const std::string& path);

/// Imports every material of the file at `path` (warnings and errors into
/// `diags`, which should name the file as the user gave it). nullopt on any
/// error: nothing is returned half-imported.
std::optional<std::vector<ImportedMaterial>> importFile(const std::string& path, const ReadLimits& limits,
                                                        Diagnostics& diags, ImportForm form = ImportForm::Blocks);

/// Imports `text` read from a file named `fileName` (no directories; it goes
/// into the descriptions). MaterialX includes are read relative to `baseDir`.
std::optional<std::vector<ImportedMaterial>> importText(SourceKind kind, const std::string& fileName,
                                                        const std::string& text, const std::string& baseDir,
                                                        const ReadLimits& limits, Diagnostics& diags,
                                                        ImportForm form = ImportForm::Blocks);

/// The material called `wanted` (its source name or its identifier), or the
/// only one when `wanted` is empty; otherwise an error listing the materials
/// (or, when several answer to `wanted`, those, with their locations).
const ImportedMaterial* pickMaterial(const std::vector<ImportedMaterial>& all, const std::string& wanted,
                                     Diagnostics& diags);

// ---------------------------------------------------------------------------
// `substratec import FILE|DIR... -o DIR` (docs/import.md).

/// How deep `import` searches a directory, and how many files it imports at most.
inline constexpr int kMaxImportDepth = 16;
inline constexpr std::size_t kMaxImportFiles = 1024;

struct ImportInput {
  std::string path;            // as given, or found under a directory given
  bool fromDirectory = false;  // found by searching a directory
};

/// The files `import` reads for its arguments: a file as given; a directory
/// searched (at most kMaxImportDepth levels; symbolic links to directories
/// not followed) for .gltf, .glb, .materials.json and .mtlx files, in path
/// order; every file once (the same file named twice is read once). nullopt
/// with the errors in `messages` when an argument is a substrate-material/1
/// file, a directory holds nothing importable, or there are more than
/// kMaxImportFiles files; warnings (directories not searched) go there too.
std::optional<std::vector<ImportInput>> collectImportInputs(const std::vector<std::string>& args,
                                                            std::string& messages);

/// Whether `import` may write `text` to `path`, which exists or not: it
/// replaces only what an import of the same source wrote — a file holding
/// exactly `text`, or a substrate-material/1 document whose description
/// begins "Imported from <sourceFileName> " (the importer's marker) —
/// unless forced.
enum class Replace { Absent, Identical, Imported, Foreign };
Replace replaceCheck(const std::string& path, const std::string& text, const std::string& sourceFileName);

/// Gives `m` the identifier `name`, in the text too (the document's "name").
void renameMaterial(ImportedMaterial& m, const std::string& name);

/// An imported material's texture `file`s, which are relative to the
/// document it came from (`fromDir`), made relative to `toDir` (where the
/// material is written); absolute ones, and embedded images (written beside
/// the material), are kept. Lexical on absolute paths: nothing needs to exist.
void rebaseImageFiles(ImportedMaterial& m, const std::string& fromDir, const std::string& toDir);

/// One material to compile: the text and how diagnostics call it.
struct MaterialSource {
  std::string displayName;  // the file, or "file[material]" for an imported one
  std::string text;
  bool imported = false;    // a compile error in it is the importer's (an internal error)
  std::string baseDir;      // the directory its texture inputs' `file`s are relative to (the file's)
  std::map<std::string, std::string> images;  // embedded images by `file` (ImportedMaterial::images)
};

/// The material(s) `path` holds: a substrate-material/1 file as it is, or its
/// imported materials — the one called `material`, the only one, or (with
/// `all`) every one of them. nullopt with diagnostics in `diags`.
std::optional<std::vector<MaterialSource>> loadMaterialSources(const std::string& path, const std::string& material,
                                                               bool all, const ReadLimits& limits,
                                                               Diagnostics& diags);

}  // namespace substratec::import
