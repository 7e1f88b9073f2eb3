// Compiling many materials at once (`substratec compile FILE...`, `substratec
// scene`): each is read, compiled, generated and validated in-process on one
// of `jobs` worker threads. Results are kept in input order, so every output
// byte and every message is the same whatever -j is. With a cache directory
// (batch/cache.h), a material whose input bytes, options and compiler are
// unchanged is taken from the cache instead of being compiled again.
#pragma once
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/generate.h"
#include "emit/scene_emitter.h"
#include "pipeline/pipeline.h"

namespace substratec {

/// What a scene and its report need of a compiled material; kept in the
/// cache beside the material's files.
struct MaterialSummary {
  std::string name;
  int bytes = 0;
  int words = 0;
  int closures = 0;
  LayoutClass layoutClass = LayoutClass::Simple;
  std::uint16_t features = 0;        // its slabs' kFeat* bits after simplification (medium included)
  std::uint16_t storedFeatures = 0;  // those its closures store
  bool runtimeSimple = false;        // its base pass may store a pixel SIMPLE (dynamic simplification)
  int budgetBytes = 0;
  int maxClosures = 0;
  int simplificationSteps = 0;
  bool metalnessMix = false;         // Material::metalnessMix
  bool conductorCurve = false;       // usesConductorCurve (SUBSTRATE_USE_CONDUCTOR_CURVE)
  bool lowIorCurve = false;          // usesLowIorCurve (SUBSTRATE_USE_LOW_IOR_CURVE)

  SceneMaterialShape shape() const {
    return {name,  layoutClass,  runtimeSimple,  storedFeatures, closures,
            words, metalnessMix, conductorCurve, lowIorCurve};
  }
};

MaterialSummary summarize(const CompileResult& r);
nlohmann::ordered_json summaryJson(const MaterialSummary& s);
std::optional<MaterialSummary> summaryFromJson(const nlohmann::ordered_json& j);

/// One input as the batch compiles it.
struct BatchSource {
  std::string displayName;  // how its diagnostics name it
  std::string text;         // substrate-material/1 text
  bool imported = false;    // imported from glTF/MaterialX: a compile error in it is the importer's bug (exit 3)
};

struct BatchOptions {
  CompileOptions compile;
  GenerateOptions generate;  // emit.sourceName is set per material (its file name)
  bool validate = true;      // compile every entry in-process before anything is returned
  int jobs = 0;              // worker threads (-j; 0: the machine's hardware threads)
  std::string cacheDir;      // --cache ("": none)
  /// Reads one input path into the text to compile, diagnostics into `diags`;
  /// unset: the file as it is (readSourceFile). The CLI imports .gltf, .glb,
  /// .materials.json and .mtlx files here (compiler/tools/import).
  std::function<std::optional<BatchSource>(const std::string& path, const ReadLimits& limits, Diagnostics& diags)>
      load;
};

struct MaterialBuild {
  std::string path;              // as given
  bool ok = false;
  bool internalError = false;    // the generated code did not validate (a compiler bug: exit 3)
  std::string messages;          // diagnostics (and the failure dump), as printed
  std::vector<OutputFile> files; // what `compile` writes for it
  /// Its --cache entry, written with the command's outputs (all or none), not
  /// by the build; unset for a cache hit, a failure or no --cache.
  std::optional<OutputPath> cacheEntry;
  MaterialSummary summary;
  bool fromCache = false;
};

/// Builds every material of `paths`, in parallel; results in input order.
std::vector<MaterialBuild> buildMaterials(const std::vector<std::string>& paths, const BatchOptions& options);

}  // namespace substratec
