// The imported glTF corpus against the glTF 2.0 reference BRDF (issue 10):
// every material of tests/import/corpus/gltf without textures, imported and
// compiled (default budget), its direct light evaluated by Substrate's CPU
// reference and by the oracle (compiler/tools/reference/gltf_brdf.h) over the same
// 24 x 24 view/light pairs; rel_mse with the runtime's diffuse (chan2024) and
// with Lambert. Prints the Markdown table of docs/import.md.
//
//   build/bin/import_oracle [CORPUS_DIR]     (default: <source>/tests/import/corpus/gltf)
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "import/import.h"
#include "pipeline/pipeline.h"
#include "reference/gltf_brdf.h"
#include "reference/reference.h"

namespace fs = std::filesystem;
using namespace substratec;

int main(int argc, char** argv) {
  const fs::path dir = argc > 1 ? fs::path(argv[1]) : fs::path(SUBSTRATEC_SOURCE_DIR) / "tests/import/corpus/gltf";
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (import::sourceKindOf(e.path().string()) == import::SourceKind::GltfMaterials) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  struct Row {
    std::string model, material, features;
    reference::GltfComparison chan, lambert;
  };
  std::vector<Row> rows;
  std::map<std::string, int> skipped;
  for (const auto& f : files) {
    Diagnostics diags(f.filename().string());
    auto text = readSourceFile(f.string(), ReadLimits{}, diags);
    auto doc = text ? parseJsonDocument(*text, ReadLimits{}, diags) : std::nullopt;
    Diagnostics importDiags(f.filename().string());
    auto imported = import::importFile(f.string(), ReadLimits{}, importDiags);
    if (!doc || !imported) {
      std::fprintf(stderr, "%s: does not import\n%s%s", f.c_str(), diags.formatAll().c_str(), importDiags.formatAll().c_str());
      return 1;
    }
    const std::string model = f.filename().string().substr(0, f.filename().string().find('.'));
    for (const auto& m : *imported) {
      const Json& source = (*doc)["materials"][std::stoi(m.location.substr(m.location.rfind('/') + 1))];
      std::string why;
      const auto oracle = reference::gltfMaterialOf(source, &why);
      if (!oracle) {
        ++skipped[why];
        continue;
      }
      Diagnostics d(m.name);
      auto r = compileText(m.name, m.text, CompileOptions{}, d);
      if (!r) {
        std::fprintf(stderr, "%s [%s] does not compile\n%s", f.c_str(), m.name.c_str(), d.formatAll().c_str());
        return 1;
      }
      std::string features;
      if (source.contains("extensions"))
        for (const auto& [name, e] : source["extensions"].items()) {
          (void)e;
          features += (features.empty() ? "" : ", ") + name.substr(name.find('_', 4) + 1);
        }
      const double metallic = source.value("pbrMetallicRoughness", Json::object()).value("metallicFactor", 1.0);
      features = fmt::format("m {:.2g}, r {:.2g}{}{}", metallic,
                             source.value("pbrMetallicRoughness", Json::object()).value("roughnessFactor", 1.0),
                             features.empty() ? "" : "; ", features);
      rows.push_back({model, m.sourceName.empty() ? m.name : m.sourceName, features,
                      reference::compareWithGltf(*r, *oracle, reference::kDiffuseChan2024),
                      reference::compareWithGltf(*r, *oracle, reference::kDiffuseLambert)});
    }
  }
  std::printf("| model | material | glTF parameters | rel_mse (chan2024) | rel_mse (Lambert) | energy ratio (Lambert) |\n"
              "|---|---|---|---:|---:|---:|\n");
  std::vector<double> chan, lambert;
  for (const auto& r : rows) {
    std::printf("| %s | %s | %s | %.4f | %.4f | %.3f |\n", r.model.c_str(), r.material.c_str(), r.features.c_str(),
                r.chan.relMse, r.lambert.relMse, r.lambert.energyRatio);
    chan.push_back(r.chan.relMse);
    lambert.push_back(r.lambert.relMse);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  const auto above = [](const std::vector<double>& v) { return std::count_if(v.begin(), v.end(), [](double x) { return x > 0.05; }); };
  std::printf("\n%zu materials measured; median rel_mse %.4f (chan2024), %.4f (Lambert); above 0.05: %ld (chan2024), %ld (Lambert)\n",
              rows.size(), median(chan), median(lambert), above(chan), above(lambert));
  for (const auto& [why, n] : skipped) std::printf("not measured: %d (%s)\n", n, why.c_str());
  return 0;
}
