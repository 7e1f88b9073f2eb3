#include "scene/scene.h"

#include <algorithm>
#include <cctype>
#include <map>

#include <fmt/format.h>

#include "report/html_report.h"
#include "scene/manifest.h"

namespace substratec {

namespace {

using J = nlohmann::ordered_json;

J featureArray(std::uint16_t mask) {
  J a = J::array();
  for (int b = 0; b < kFeatureCount; ++b)
    if ((mask & kPlatformFeatures) & (1u << b)) a.push_back(std::string(featureName(b)));
  return a;
}

/// The platform the scene is built for, or an error (status set) when the
/// name is unknown: a --platform name is bad usage, a manifest's bad input
/// located at its pointer.
std::optional<Platform> choosePlatform(const SceneOptions& o, const SceneManifest& scene, const PlatformTable& table,
                                       SceneBuild& b) {
  const std::optional<std::string>& name = o.platform ? o.platform : scene.platform;
  if (!name) return std::nullopt;
  if (const Platform* p = table.find(*name)) return *p;
  if (o.platform) {
    b.status = SceneStatus::BadUsage;
    b.messages += fmt::format("substratec: error: unknown platform {} (known: {})\n", quoteForDiagnostic(*name),
                              table.names());
  } else {
    Diagnostics d(o.manifest);
    d.setLocator(scene.locator);
    d.error(scene.platformPointer,
            fmt::format("unknown platform {} (known: {})", quoteForDiagnostic(*name), table.names()));
    b.status = SceneStatus::BadInput;
    b.messages += d.formatAll();
  }
  return std::nullopt;
}

/// Every material's files go into one directory: their names must differ (also
/// in letter case: file systems that ignore it, and the upper-case macros of one
/// kernel). Reports each clash at the manifest entry; true when there was one.
bool reportSceneNameClashes(const SceneOptions& o, const SceneManifest& scene, const std::vector<MaterialBuild>& built,
                            SceneBuild& b) {
  Diagnostics d(o.manifest);
  d.setLocator(scene.locator);
  std::map<std::string, std::size_t> seen;
  for (std::size_t i = 0; i < built.size(); ++i) {
    if (!built[i].ok) continue;
    std::string key = built[i].summary.name;
    for (char& c : key) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (auto [at, fresh] = seen.emplace(key, i); !fresh)
      d.error(scene.materials[i].pointer,
              fmt::format("material {} ({}) has the name of {} ({}){}: their shaders would overwrite each other",
                          quoteForDiagnostic(built[i].summary.name), scene.materials[i].path,
                          scene.materials[at->second].pointer, scene.materials[at->second].path,
                          built[at->second].summary.name == built[i].summary.name
                              ? ""
                              : fmt::format(" but for letter case ({})",
                                            quoteForDiagnostic(built[at->second].summary.name))));
  }
  b.messages += d.formatAll();
  return d.hasErrors();
}

/// Whether the scene generates shaders for target `t`.
bool sceneGenerates(const SceneOptions& o, Target t) {
  return !((t == Target::Glsl && !o.batch.generate.glsl) || (t == Target::Hlsl && !o.batch.generate.hlsl));
}

/// The lighting: what the materials store after simplification, and no more.
/// The tile classification and one lighting shader per tile class, per target.
Generated generateSceneLighting(const SceneOptions& o, const SceneShape& shape) {
  Generated lighting;
  for (Target t : {Target::Glsl, Target::Hlsl}) {
    if (!sceneGenerates(o, t)) continue;
    const Syntax& syn = syntaxFor(t);
    lighting.files.push_back({tileClassificationFileName(shape, syn), emitTileClassification(shape, syn)});
    for (const SceneLightingClass& k : shape.classes)
      lighting.files.push_back({sceneLightingFileName(shape, k.cls, syn), emitSceneLighting(shape, k, syn)});
  }
  return lighting;
}

/// The SPIR-V instruction counts of each validated lighting file, by file name.
using SceneCounts = std::map<std::string, const EntryReport*>;

/// A file's {"instructions", "optimized_instructions"}, or {} when it was not validated.
J sceneInstructions(const SceneCounts& counts, const std::string& file) {
  J j = J::object();
  if (auto it = counts.find(file); it != counts.end())
    j = {{"instructions", it->second->instructions}, {"optimized_instructions", it->second->optimizedInstructions}};
  return j;
}

/// scene.json's "lighting" entries, one a tile class; adds the instructions of
/// the first target's lighting shaders to `total`.
J sceneLightingReport(const SceneOptions& o, const SceneShape& shape, const SceneCounts& counts, std::size_t& total) {
  const Syntax& first = syntaxFor(o.batch.generate.glsl ? Target::Glsl : Target::Hlsl);
  J entries = J::array();
  for (const SceneLightingClass& k : shape.classes) {
    J e = {{"class", tileClassName(k.cls)},
           {"features", featureArray(k.features)},
           {"max_closures", k.maxClosures},
           {"words", k.maxWords},
           {"materials", k.materials}};
    J files = J::object();
    for (Target t : {Target::Glsl, Target::Hlsl}) {
      if (!sceneGenerates(o, t)) continue;
      const std::string file = sceneLightingFileName(shape, k.cls, syntaxFor(t));
      files[std::string(syntaxFor(t).name)] = {{"file", file}, {"spirv", sceneInstructions(counts, file)}};
    }
    e["shaders"] = files;
    if (auto it = counts.find(sceneLightingFileName(shape, k.cls, first)); it != counts.end())
      total += it->second->instructions;
    entries.push_back(e);
  }
  return entries;
}

/// scene.json's "materials": one entry a material, in manifest order.
J sceneMaterialsReport(const SceneManifest& scene, const std::vector<MaterialBuild>& built) {
  J materials = J::array();
  for (std::size_t i = 0; i < built.size(); ++i) {
    const MaterialSummary& s = built[i].summary;
    materials.push_back({{"name", s.name},
                         {"file", scene.materials[i].written},
                         {"bytes_per_pixel", s.bytes},
                         {"closures", s.closures},
                         {"layout", std::string(layoutClassName(s.layoutClass))},
                         {"features", featureArray(s.features)},
                         {"runtime_simple", s.runtimeSimple},
                         {"budget", {{"bytes_per_pixel", s.budgetBytes}, {"max_closures", s.maxClosures}}},
                         {"simplification_steps", s.simplificationSteps}});
  }
  return materials;
}

/// scene.json: the platform, what the materials need at most, the lighting
/// shaders with their SPIR-V sizes, and every material's summary.
J sceneReport(const SceneOptions& o, const SceneManifest& scene, const std::optional<Platform>& platform,
              const std::vector<MaterialBuild>& built, const SceneShape& shape, const SceneCounts& counts) {
  J report;
  report["format"] = "substrate-scene-report/1";
  report["scene"] = scene.name;
  if (platform) {
    const Platform& p = *platform;
    report["platform"] = {{"name", p.name}, {"bytes_per_pixel", p.bytesPerPixel}, {"max_closures", p.maxClosures},
                          {"features", featureArray(p.allowedFeatures)}};
  } else {
    report["platform"] = nullptr;
  }
  std::uint16_t features = 0;
  int maxBytes = 0;
  for (const MaterialBuild& m : built) {
    if (m.summary.layoutClass == LayoutClass::Volume) continue;  // a volume stores no pixel (its froxels are its own)
    features |= m.summary.features;
    maxBytes = std::max(maxBytes, m.summary.bytes);
  }
  report["features"] = featureArray(features);
  report["max_bytes_per_pixel"] = maxBytes;
  report["max_closures"] = shape.maxClosures;
  report["words"] = shape.maxWords;
  report["material_buffer_slices"] = materialBufferSlices(shape);
  J classes = J::array();
  for (const SceneLightingClass& k : shape.classes) classes.push_back(tileClassName(k.cls));
  report["tile_classes"] = classes;
  std::size_t total = 0;
  J entries = sceneLightingReport(o, shape, counts, total);
  report["lighting_spirv_instructions"] = total;
  report["lighting"] = entries;
  J classify = J::object();
  for (Target t : {Target::Glsl, Target::Hlsl}) {
    if (!sceneGenerates(o, t)) continue;
    const std::string file = tileClassificationFileName(shape, syntaxFor(t));
    classify[std::string(syntaxFor(t).name)] = {{"file", file}, {"spirv", sceneInstructions(counts, file)}};
  }
  report["tile_classification"] = classify;
  report["materials"] = sceneMaterialsReport(scene, built);
  return report;
}

/// DIR/report.html: the scene's sorted byte chart and every material's page
/// (report/html_report.h), each compiled again as the batch compiled it (the
/// batch keeps summaries, and a cache hit not even that) and unsimplified
/// where its budget simplified it. Called once every material compiled.
std::string sceneHtml(const SceneManifest& scene, const BatchOptions& batch, const std::vector<std::string>& paths) {
  html::Page page;
  page.title = "substratec scene report: " + scene.name;
  html::SceneHeader header{scene.name, "", 0, 0};
  if (batch.compile.platform) {
    header.platform = batch.compile.platform->name;
    header.budgetBytes = batch.compile.platform->bytesPerPixel;
    header.maxClosures = batch.compile.platform->maxClosures;
  }
  for (const std::string& path : paths) {
    Diagnostics diags(path);
    std::optional<BatchSource> source;
    if (batch.load) source = batch.load(path, batch.compile.read, diags);
    else if (auto text = readSourceFile(path, batch.compile.read, diags)) source = BatchSource{path, *text, false};
    html::MaterialPage p;
    if (source) p = html::compiledMaterial(source->displayName, source->text, batch.compile);
    if (!source) p.file = path;
    p.diagnostics.insert(p.diagnostics.begin(), diags.all().begin(), diags.all().end());
    if (!batch.compile.platform && p.result && header.budgetBytes == 0) {  // no platform: the first one's budget
      header.budgetBytes = p.result->budgetBytes;
      header.maxClosures = p.result->maxClosures;
    }
    page.materials.push_back(std::move(p));
  }
  page.scene = header;
  return html::formatPage(page);
}

}  // namespace

SceneBuild buildScene(const SceneOptions& o) {
  SceneBuild b;
  const ReadLimits& limits = o.batch.compile.read;
  b.inputs.push_back(o.manifest);
  // Every error of one run is reported: the manifest's, the platform's, every
  // material's and the name clashes among those that compile. Only a manifest
  // that cannot be read at all (not JSON, not an object) stops here.
  bool bad = false;
  std::optional<SceneManifest> scene;
  {
    Diagnostics d(o.manifest);
    if (auto text = readSourceFile(o.manifest, limits, d)) scene = readSceneManifest(o.manifest, *text, limits, d);
    b.messages += d.formatAll();
    if (!scene) return b.status = SceneStatus::BadInput, b;
    bad = d.hasErrors();
  }
  if (!o.platformsFile.empty()) b.inputs.push_back(o.platformsFile);
  std::optional<PlatformTable> table = loadPlatformTable(o.platformsFile, limits, b.messages);
  BatchOptions batch = o.batch;
  if (!table) {
    bad = true;
  } else {
    batch.compile.platform = choosePlatform(o, *scene, *table, b);
    if (b.status == SceneStatus::BadUsage) return b;  // an unknown --platform: bad usage, before anything is built
    if (b.status != SceneStatus::Ok) bad = true;
    b.status = SceneStatus::Ok;
  }

  std::vector<std::string> paths;
  for (const SceneMaterialRef& m : scene->materials) paths.push_back(m.path);
  b.inputs.insert(b.inputs.end(), paths.begin(), paths.end());
  std::vector<MaterialBuild> built = buildMaterials(paths, batch);
  bool internal = false;
  for (const MaterialBuild& m : built) {
    b.messages += m.messages;
    internal = internal || m.internalError;
    bad = bad || !m.ok;
    b.cacheHits += m.fromCache;
  }
  if (reportSceneNameClashes(o, *scene, built, b)) bad = true;
  if (internal) return b.status = SceneStatus::InternalError, b;
  if (bad) return b.status = SceneStatus::BadInput, b;

  std::vector<SceneMaterialShape> shapes;
  for (const MaterialBuild& m : built) shapes.push_back(m.summary.shape());
  if (std::all_of(built.begin(), built.end(),
                  [](const MaterialBuild& m) { return m.summary.layoutClass == LayoutClass::Volume; })) {
    Diagnostics d(o.manifest);  // a volume's froxels are its own: nothing for a scene's lighting to read
    d.setLocator(scene->locator);
    d.error("/materials", "every material of the scene is a volume (a volumetric fog cloud), which stores no pixel: "
                          "a scene's lighting needs at least one surface material");
    b.messages += d.formatAll();
    return b.status = SceneStatus::BadInput, b;
  }
  const SceneShape shape = sceneShape(scene->name, shapes, o.batch.generate.emit.diffuseModel);
  Generated lighting = generateSceneLighting(o, shape);
  if (o.batch.validate) {
    validateGenerated(lighting, {.optimize = true}, static_cast<std::size_t>(std::max(0, o.batch.jobs)));
    if (!lighting.valid) {
      b.messages += "substratec: internal compiler error: the scene's lighting does not validate\n" + lighting.failure + "\n";
      return b.status = SceneStatus::InternalError, b;
    }
  }
  SceneCounts counts;
  for (const EntryReport& e : lighting.entries) counts[e.file] = &e;
  const J report = sceneReport(o, *scene, batch.compile.platform, built, shape, counts);

  for (MaterialBuild& m : built) {
    for (OutputFile& f : m.files) b.files.push_back(std::move(f));
    if (m.cacheEntry) b.cacheEntries.push_back(std::move(*m.cacheEntry));
  }
  for (OutputFile& f : lighting.files) b.files.push_back(std::move(f));
  b.files.push_back({"scene.json", report.dump(2) + "\n"});
  b.files.push_back({"report.html", sceneHtml(*scene, batch, paths)});
  return b;
}

}  // namespace substratec
