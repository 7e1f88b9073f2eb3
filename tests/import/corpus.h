// The import corpora copied into the repository (tests/import/corpus: the
// MaterialX example documents and the glTF Sample Assets material extracts,
// with their licences), listed and imported the way the tests need them:
// diagnostics name files relative to the corpus, so goldens hold no paths.
#pragma once
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "import/import.h"

namespace substratec::importtest {

struct CorpusFile {
  std::string display;          // "gltf/BoomBox.materials.json", "materialx/OpenPbr/open_pbr_glass.mtlx"
  std::filesystem::path path;
};

/// Every corpus document, sorted by display name.
std::vector<CorpusFile> corpusFiles();

struct CorpusImport {
  bool ok = false;
  std::vector<import::ImportedMaterial> materials;
  std::string diagnostics;  // warnings (and errors) as printed
};
/// The file imported in the expanded form (ImportForm::Expanded: the nodes the
/// mapping writes, which the goldens hold).
CorpusImport importCorpusFile(const CorpusFile& f);

/// The documented exceptions (docs/import.md, "Exceptions"): corpus files that
/// do not import, each with a text its error must contain.
const std::map<std::string, std::string>& corpusExceptions();

}  // namespace substratec::importtest
