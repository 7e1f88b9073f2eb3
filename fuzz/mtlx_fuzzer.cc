// libFuzzer target: the MaterialX importer. Arbitrary bytes as a .mtlx file:
// pugixml, the document index and includes, the node-graph mapping and the
// shading models, then every imported material through the pipeline
// (import_fuzz_common.h says what is checked).
#include <cstddef>
#include <cstdint>
#include <string>

#include "import_fuzz_common.h"

using namespace substratec;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (fuzz::namesSystemFiles(text)) return 0;
  Diagnostics diags("fuzz.mtlx");
  auto materials = import::importText(import::SourceKind::MaterialX, "fuzz.mtlx", text, fuzz::kNoDirectory,
                                      ReadLimits{}, diags);
  fuzz::checkImported(materials, diags);
  return 0;
}
