// libFuzzer target: the glTF importer. Arbitrary bytes as a .gltf file — JSON,
// or a .glb container (recognised by its magic, as the importer does for a
// .gltf that is binary) with its JSON and binary chunks — through the reader,
// the buffer and image checks and the glTF PBR mapping, then every imported
// material through the pipeline (import_fuzz_common.h says what is checked).
#include <cstddef>
#include <cstdint>
#include <string>

#include "import_fuzz_common.h"

using namespace substratec;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  if (fuzz::namesSystemFiles(text)) return 0;
  Diagnostics diags("fuzz.gltf");
  auto materials = import::importText(import::SourceKind::Gltf, "fuzz.gltf", text, fuzz::kNoDirectory, ReadLimits{},
                                      diags);
  fuzz::checkImported(materials, diags);
  return 0;
}
