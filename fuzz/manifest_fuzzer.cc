// libFuzzer target: the scene manifest (substrate-scene/1). Arbitrary bytes
// through the strict JSON reader and parseSceneManifest: every input ends in
// a manifest (with a usable name and 1..kMaxSceneMaterials distinct material
// paths) or in at least one diagnostic; never a crash or an exception.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <string>

#include "diag/diagnostics.h"
#include "passes/resolve.h"
#include "scene/manifest.h"

using namespace substratec;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Diagnostics diags("scenes/fuzz.json");
  auto scene = parseSceneManifest("scenes/fuzz.json", text, ReadLimits{}, diags);
  if (!scene) {
    if (!diags.hasErrors()) std::abort();  // rejected without saying why
  } else {
    if (diags.hasErrors()) std::abort();   // a manifest despite errors
    if (!isUsableIdentifier(scene->name)) std::abort();
    if (scene->materials.empty() || scene->materials.size() > kMaxSceneMaterials) std::abort();
    std::set<std::string> paths;
    for (const SceneMaterialRef& m : scene->materials)
      if (!paths.insert(m.path).second) std::abort();  // duplicates are errors
  }
  if (diags.formatAll().size() > (std::size_t{1} << 22)) std::abort();
  return 0;
}
