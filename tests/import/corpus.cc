#include "corpus.h"

#include <algorithm>

#include "import/import.h"

namespace fs = std::filesystem;

namespace substratec::importtest {

std::vector<CorpusFile> corpusFiles() {
  const fs::path root = fs::path(SUBSTRATEC_SOURCE_DIR) / "tests/import/corpus";
  std::vector<CorpusFile> out;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    const import::SourceKind k = import::sourceKindOf(e.path().string());
    if (k == import::SourceKind::Substrate) continue;
    out.push_back({e.path().lexically_relative(root).generic_string(), e.path()});
  }
  std::sort(out.begin(), out.end(), [](const CorpusFile& a, const CorpusFile& b) { return a.display < b.display; });
  return out;
}

CorpusImport importCorpusFile(const CorpusFile& f) {
  Diagnostics diags(f.display);
  ReadLimits limits;
  CorpusImport r;
  auto text = readSourceFile(f.path.string(), limits, diags);
  if (text) {
    auto m = import::importText(import::sourceKindOf(f.display), f.path.filename().string(), *text,
                                f.path.parent_path().string(), limits, diags, import::ImportForm::Expanded);
    if (m) {
      r.ok = true;
      r.materials = std::move(*m);
    }
  }
  r.diagnostics = diags.formatAll();
  return r;
}

const std::map<std::string, std::string>& corpusExceptions() {
  // None: SimpleHair, the last one, imports its chiang_hair_bsdf as a hair node.
  static const std::map<std::string, std::string> list = {};
  return list;
}

}  // namespace substratec::importtest
