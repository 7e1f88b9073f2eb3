#include "batch/batch.h"

#include <filesystem>

#include <fmt/format.h>

#include "batch/cache.h"
#include "emit/material_emitter.h"
#include "util/parallel.h"

namespace substratec {

MaterialSummary summarize(const CompileResult& r) {
  MaterialSummary s;
  const StorageLayout& L = r.after;
  s.name = r.material.name;
  s.bytes = L.bytes();
  s.words = L.words();
  s.closures = static_cast<int>(L.closures.size());
  s.layoutClass = L.layoutClass;
  for (const ClosureLayout& c : L.closures) {
    s.features |= r.material.slabs[c.slab].features;
    s.storedFeatures |= c.storedFeatures;
  }
  s.runtimeSimple = !runtimeSimpleClosures(r.material, L).empty();
  s.budgetBytes = r.budgetBytes;
  s.maxClosures = r.maxClosures;
  s.simplificationSteps = static_cast<int>(r.steps.size());
  s.metalnessMix = r.material.metalnessMix;
  s.conductorCurve = usesConductorCurve(r.material, r.after);
  s.lowIorCurve = usesLowIorCurve(r.material, r.after);
  return s;
}

nlohmann::ordered_json summaryJson(const MaterialSummary& s) {
  return {{"name", s.name},
          {"bytes", s.bytes},
          {"words", s.words},
          {"closures", s.closures},
          {"layout", std::string(layoutClassName(s.layoutClass))},
          {"features", s.features},
          {"stored_features", s.storedFeatures},
          {"runtime_simple", s.runtimeSimple},
          {"budget_bytes", s.budgetBytes},
          {"max_closures", s.maxClosures},
          {"simplification_steps", s.simplificationSteps},
          {"metalness_mix", s.metalnessMix},
          {"conductor_curve", s.conductorCurve},
          {"low_ior_curve", s.lowIorCurve}};
}

std::optional<MaterialSummary> summaryFromJson(const nlohmann::ordered_json& j) {
  try {
    MaterialSummary s;
    s.name = j.at("name").get<std::string>();
    s.bytes = j.at("bytes").get<int>();
    s.words = j.at("words").get<int>();
    s.closures = j.at("closures").get<int>();
    const std::string layout = j.at("layout").get<std::string>();
    bool known = false;
    for (LayoutClass c :
         {LayoutClass::Simple, LayoutClass::Single, LayoutClass::Complex, LayoutClass::Special, LayoutClass::Volume})
      if (layoutClassName(c) == layout) s.layoutClass = c, known = true;
    s.features = j.at("features").get<std::uint16_t>();
    s.storedFeatures = j.at("stored_features").get<std::uint16_t>();
    s.runtimeSimple = j.at("runtime_simple").get<bool>();
    s.budgetBytes = j.at("budget_bytes").get<int>();
    s.maxClosures = j.at("max_closures").get<int>();
    s.simplificationSteps = j.at("simplification_steps").get<int>();
    s.metalnessMix = j.at("metalness_mix").get<bool>();
    s.conductorCurve = j.at("conductor_curve").get<bool>();
    s.lowIorCurve = j.at("low_ior_curve").get<bool>();
    const int leastClosures = s.layoutClass == LayoutClass::Volume ? 0 : 1;  // a volume has none
    if (!known || s.name.empty() || s.words < 1 || s.closures < leastClosures || s.closures > 8) return std::nullopt;
    return s;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

namespace {

/// Reads, compiles, generates and (optionally) validates one material, or
/// takes it from the cache.
MaterialBuild buildOne(const std::string& path, const BatchOptions& o, std::size_t validationThreads) {
  MaterialBuild b;
  b.path = path;
  Diagnostics diags(path);
  std::optional<BatchSource> source;
  if (o.load) {
    source = o.load(path, o.compile.read, diags);
  } else if (auto text = readSourceFile(path, o.compile.read, diags)) {
    source = BatchSource{path, std::move(*text), false};
  }
  std::optional<MaterialCache> cache;
  std::string keyText;
  if (source && !o.cacheDir.empty()) {
    cache.emplace(o.cacheDir);
    keyText = cacheKeyText(path, source->text, o);
    if (auto hit = cache->load(keyText)) {
      b.ok = b.fromCache = true;
      b.files = std::move(hit->files);
      b.summary = std::move(hit->summary);
      b.messages = std::move(hit->messages);
      return b;
    }
  }
  std::optional<CompileResult> r;
  b.messages = diags.formatAll();  // reading (and importing) it
  if (source) {
    Diagnostics compileDiags(source->displayName);
    r = compileText(source->displayName, source->text, o.compile, compileDiags);
    b.messages += compileDiags.formatAll();
    if (r) b.messages += r->debugLog;  // --print-after
  }
  if (!r) {
    if (source && source->imported) {
      b.internalError = true;
      b.messages += fmt::format("substratec: internal compiler error: the material imported from {} does not compile\n",
                                source->displayName);
    }
    return b;
  }
  if (!o.compile.stopAfter.empty()) {  // --stop-after: the passes' dumps only, nothing generated
    b.ok = true;
    return b;
  }
  GenerateOptions go = o.generate;
  go.emit.sourceName = std::filesystem::path(path).filename().string();
  Generated gen = generateFiles(*r, go);
  // Validate in-process before anything is written: a shader that does not
  // compile is the compiler's bug (exit 3), and the output stays as it was.
  if (o.validate) validateGenerated(gen, {}, validationThreads);
  if (!gen.valid) {
    b.internalError = true;
    b.messages += fmt::format("substratec: internal compiler error: generated code of {} does not validate\n{}\n", path,
                              gen.failure);
    return b;
  }
  b.ok = true;
  b.files = std::move(gen.files);
  b.summary = summarize(*r);
  if (cache) {  // written by the command with its outputs (all or none)
    std::string error;
    b.cacheEntry = cache->entryFile(keyText, {b.files, b.summary, b.messages}, &error);
    if (!error.empty()) b.messages += "substratec: warning: --cache: " + error + "\n";
  }
  return b;
}

}  // namespace

std::vector<MaterialBuild> buildMaterials(const std::vector<std::string>& paths, const BatchOptions& options) {
  std::vector<MaterialBuild> out(paths.size());
  const std::size_t jobs = static_cast<std::size_t>(std::max(0, options.jobs));
  // One material: its entries validate in parallel instead.
  const std::size_t validationThreads = paths.size() > 1 ? 1 : jobs;
  parallelFor(paths.size(), jobs, [&](std::size_t i) { out[i] = buildOne(paths[i], options, validationThreads); });
  return out;
}

}  // namespace substratec
