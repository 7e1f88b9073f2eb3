// The bundled examples the suites iterate (examples/*.json, sorted by file
// name): all of them, or the surfaces only. A volume (a volumetric fog cloud,
// isVolumeMaterial) has no surface, closure or pixel: the suites that shade,
// pack or light one leave it to tests/unit/fog_cloud_test.cc and
// tests/gpu/fog_cloud_gpu_test.cc.
#pragma once
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "pipeline/pass_registry.h"

namespace substratec::test {

enum class Examples { All, Surfaces };

inline std::vector<std::filesystem::path> exampleFiles(Examples which) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(SUBSTRATEC_SOURCE_DIR) / "examples")) {
    if (e.path().extension() != ".json") continue;
    if (which != Examples::All) {
      std::ifstream in(e.path(), std::ios::binary);
      std::ostringstream read;
      read << in.rdbuf();
      const std::string text = read.str();  // the context keeps a reference to it
      Diagnostics d(e.path().string());
      CompileOptions o;
      o.stopAfter = "build-tree";  // enough to see the root
      CompileResult r;
      PassContext c(text, o, d, r);
      runPasses(c, o.stopAfter);
      if (isVolumeMaterial(r.material)) continue;
    }
    files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace substratec::test
