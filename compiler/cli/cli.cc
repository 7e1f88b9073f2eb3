#include "cli/cli.h"

#include <ostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "pipeline/pipeline.h"
#include "report/report.h"
#include "validate/toolchain.h"
#include "pipeline/generate.h"
#include "output/atomic_write.h"
#include "output/depfile.h"
#include "cli/cli_options.h"
#include "cli/command_outputs.h"
#include "batch/batch.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "preview/contact_sheet.h"
#include "preview/environment.h"
#include "preview/render.h"
#include "scene/scene.h"
#include "stability/stability.h"
#include "sweep/sweep.h"
#include "import/import.h"

#include <filesystem>
#include <map>
#include <memory>

namespace substratec {

namespace {

/// The one material `file` holds (a substrate-material/1 file, or the
/// --material of an importable one), diagnostics printed; nullopt on error.
std::optional<import::MaterialSource> loadMaterial(const std::string& file, const std::string& material,
                                                   const ReadLimits& read, std::ostream& err) {
  Diagnostics diags(file);
  auto sources = import::loadMaterialSources(file, material, false, read, diags);
  err << diags.formatAll();
  if (!sources) return std::nullopt;
  return std::move(sources->front());
}

/// The exit status of a material that does not compile: the user's input, or
/// (for an imported one) the importer's bug.
int compileFailure(const import::MaterialSource& s, std::ostream& err) {
  if (!s.imported) return kExitBadInput;
  err << "substratec: internal compiler error: the material imported from " << s.displayName
      << " does not compile\n";
  return kExitInternal;
}

struct ReportArgs {
  std::vector<std::string> files;
  std::string material;
  int budget = 0;
  int maxClosures = 0;
  bool fullSimplification = false;
  bool json = false;
  std::size_t maxInputSize = 16u << 20;
  bool printAfterAll = false;
  bool timePasses = false;
  bool spirv = false;
};

CompileOptions optionsFrom(const ReportArgs& a) {
  CompileOptions o;
  if (a.budget > 0) o.budgetOverride = a.budget;
  if (a.maxClosures > 0) o.maxClosuresOverride = a.maxClosures;
  o.fullSimplification = a.fullSimplification;
  o.read.maxInputBytes = a.maxInputSize;
  o.printAfterAll = a.printAfterAll;
  o.timePasses = a.timePasses;
  return o;
}

int runReport(const ReportArgs& a, std::ostream& out, std::ostream& err) {
  int status = kExitOk;
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  bool first = true;
  std::vector<import::MaterialSource> sources;
  CommandOutputs outputs(out);  // writes only standard output
  for (const auto& file : a.files) outputs.input(file);
  if (int status = outputs.check(err); status != kExitOk) return status;
  for (const auto& file : a.files) {
    Diagnostics diags(file);
    auto loaded = import::loadMaterialSources(file, a.material, true, optionsFrom(a).read, diags);
    err << diags.formatAll();
    if (!loaded) status = kExitBadInput;
    else for (auto& s : *loaded) sources.push_back(std::move(s));
  }
  if (int usage = outputs.check(err); usage != kExitOk) return usage;
  for (const auto& source : sources) {
    const std::string& file = source.displayName;
    Diagnostics diags(file);
    auto result = compileText(file, source.text, optionsFrom(a), diags);
    err << diags.formatAll();
    if (!result) {
      status = std::max(status, compileFailure(source, err));
      continue;
    }
    if (a.printAfterAll) err << result->debugLog;
    if (a.timePasses)
      for (const auto& t : result->timings) err << fmt::format("{}: pass {:<14} {:8.3f} ms\n", file, t.pass, t.milliseconds);
    std::vector<EntryReport> entries;
    if (a.spirv) {  // compile every entry shader to count its SPIR-V instructions
      Generated gen = generateFiles(*result, GenerateOptions{});
      validateGenerated(gen, {.optimize = true});
      if (!gen.valid) {
        err << "substratec: internal compiler error: generated code does not validate\n" << gen.failure << "\n";
        return kExitInternal;
      }
      entries = gen.entries;
    }
    if (a.json) {
      auto j = reportJson(*result);
      if (a.spirv) {
        nlohmann::ordered_json list = nlohmann::ordered_json::array();
        for (const auto& e : entries)
          list.push_back({{"file", e.file}, {"instructions", e.instructions}, {"optimized_instructions", e.optimizedInstructions}});
        j["spirv"] = list;
      }
      all.push_back(j);
    } else {
      if (!first) out << "\n";
      out << formatReportText(*result);
      if (a.spirv) {
        out << fmt::format("----- SPIR-V - {} -----\n", result->material.name);
        for (const auto& e : entries)
          out << fmt::format("{:<40} {:>6} instructions, {:>6} after SPIRV-Tools' performance passes\n", e.file,
                             e.instructions, e.optimizedInstructions);
      }
    }
    first = false;
  }
  if (a.json) out << (a.files.size() == 1 && all.size() == 1 ? all[0] : all).dump(2) << "\n";
  return status;
}

/// The model a --diffuse name selects (ir/enums.h; CLI11 has checked the name).
DiffuseModel diffuseModelOf(const std::string& name) { return parseDiffuseModel(name).value_or(kDefaultDiffuseModel); }

/// --precision (compile, preview, sweep, stability): the runtime's lighting in float32 or half.
void addPrecisionOption(CLI::App* command, std::string& precision) {
  command->add_option("--precision", precision,
                      "Lighting precision: float, or half (float16 colours, weights and throughputs; "
                      "docs/stability.md)")
      ->check(CLI::IsMember({"float", "half"}))->capture_default_str();
}
Precision precisionOf(const std::string& name) { return name == "half" ? Precision::Half : Precision::Float; }

struct CompileArgs {
  std::vector<std::string> files;
  std::string material;
  std::string outDir;
  std::string target = "all";
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  int budget = 0;
  int maxClosures = 0;
  bool fullSimplification = false;
  bool skipValidation = false;
  std::size_t maxInputSize = 16u << 20;
  std::string precision = "float";
  int jobs = 0;
  std::string platform;
  std::string platforms;
  std::string cache;
  std::string depfile;
};

/// Commits `files` into `dir`, the depfile when asked (its targets: every
/// file written, or only `depTarget` when given, depending on `inputs` and
/// every other file read, the MaterialX includes) and
/// the --cache entries, all or none (cli/command_outputs.h); then lists what
/// was written on stdout.
int writeOutputs(const CommandOutputs& outputs, const std::string& dir, const std::vector<OutputFile>& files,
                 const std::string& depfile, const std::vector<std::string>& inputs,
                 const std::vector<OutputPath>& cacheEntries, std::ostream& out, std::ostream& err,
                 const std::string& depTarget = "") {
  std::vector<OutputPath> paths;
  if (std::string error = outputPathsIn(dir, files, &paths); !error.empty()) {
    err << "substratec: error: " << error << "\n";
    return kExitBadInput;
  }
  std::vector<std::string> written;
  for (const auto& p : paths) written.push_back(p.path);
  const std::vector<std::string> targets =
      depTarget.empty() ? written : std::vector<std::string>{(std::filesystem::path(dir) / depTarget).string()};
  if (!depfile.empty()) paths.push_back({depfile, makeDepfile(targets, outputs.prerequisites(inputs))});
  paths.insert(paths.end(), cacheEntries.begin(), cacheEntries.end());
  if (int status = outputs.commit(paths, err); status != kExitOk) return status;
  for (const auto& w : written) out << w << "\n";
  return kExitOk;
}

/// The options every material of a compile or a scene is built with.
BatchOptions batchOptions(int budget, int maxClosures, std::size_t maxInputSize, const std::string& target,
                          const std::string& diffuse, int jobs, const std::string& cache,
                          const std::string& material = "") {
  BatchOptions o;
  if (budget > 0) o.compile.budgetOverride = budget;
  if (maxClosures > 0) o.compile.maxClosuresOverride = maxClosures;
  o.compile.read.maxInputBytes = maxInputSize;
  o.generate.glsl = target != "hlsl";
  o.generate.hlsl = target != "glsl";
  o.generate.emit.diffuseModel = diffuseModelOf(diffuse);
  o.jobs = jobs;
  o.cacheDir = cache;
  // glTF and MaterialX files are imported on the fly (the --material one, or
  // the only one); substrate-material/1 files are read as they are.
  o.load = [material](const std::string& path, const ReadLimits& read,
                      Diagnostics& diags) -> std::optional<BatchSource> {
    auto sources = import::loadMaterialSources(path, material, false, read, diags);
    if (!sources) return std::nullopt;
    import::MaterialSource& s = sources->front();
    return BatchSource{std::move(s.displayName), std::move(s.text), s.imported};
  };
  return o;
}

/// Without --material, what `compile` builds of `files`: a glTF or MaterialX
/// file holding several materials gives every one of them (like `report`),
/// each its own input "FILE[NAME]" named by its material; the others are
/// themselves. The files are imported here once, and `o.load` hands out what
/// was imported. Import errors are printed and make `*status` bad input.
std::vector<std::string> everyMaterialOf(const std::vector<std::string>& files, BatchOptions& o, std::ostream& err,
                                         int* status) {
  auto imported = std::make_shared<std::map<std::string, BatchSource>>();
  std::vector<std::string> units;
  for (const std::string& file : files) {
    if (import::sourceKindOf(file) == import::SourceKind::Substrate || imported->count(file)) {
      units.push_back(file);
      continue;
    }
    Diagnostics diags(file);
    auto sources = import::loadMaterialSources(file, "", true, o.compile.read, diags);
    err << diags.formatAll();
    if (!sources) {
      *status = kExitBadInput;
      continue;
    }
    for (import::MaterialSource& s : *sources) {
      const std::string unit = sources->size() == 1 ? file : s.displayName;
      (*imported)[unit] = BatchSource{s.displayName, std::move(s.text), s.imported};
      units.push_back(unit);
    }
  }
  o.load = [imported, load = o.load](const std::string& path, const ReadLimits& read,
                                     Diagnostics& diags) -> std::optional<BatchSource> {
    if (auto it = imported->find(path); it != imported->end()) return it->second;
    return load(path, read, diags);
  };
  return units;
}

/// Every file compiled (in parallel with -j, from --cache when unchanged) into
/// one output directory; all of them are written, or none. Every material of
/// a file that holds several, without --material (everyMaterialOf).
int runCompile(const CompileArgs& a, std::ostream& out, std::ostream& err) {
  BatchOptions o =
      batchOptions(a.budget, a.maxClosures, a.maxInputSize, a.target, a.diffuse, a.jobs, a.cache, a.material);
  o.compile.fullSimplification = a.fullSimplification;
  o.generate.emit.precision = precisionOf(a.precision);
  o.validate = !a.skipValidation;
  std::vector<std::string> inputs = a.files;
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  outputs.namedFile(a.depfile);
  outputs.directory(a.cache);
  for (const auto& f : a.files) outputs.input(f);
  outputs.input(a.platforms);
  if (int status = outputs.check(err); status != kExitOk) return status;
  if (!a.platform.empty() || !a.platforms.empty()) {
    std::string messages;
    auto table = loadPlatformTable(a.platforms, o.compile.read, messages);
    err << messages;
    if (!table) return kExitBadInput;
    if (!a.platforms.empty()) inputs.push_back(a.platforms);
    if (!a.platform.empty()) {
      const Platform* p = table->find(a.platform);
      if (!p) {
        err << fmt::format("substratec: error: unknown platform {} (known: {})\n", quoteForDiagnostic(a.platform),
                           table->names());
        return kExitUsage;
      }
      o.compile.platform = *p;
    }
  }
  int status = kExitOk;
  const std::vector<std::string> units = a.material.empty() ? everyMaterialOf(a.files, o, err, &status) : a.files;
  std::vector<MaterialBuild> built = buildMaterials(units, o);
  std::map<std::string, std::string> names;  // material name -> file
  std::vector<OutputFile> files;
  std::vector<OutputPath> cacheEntries;
  for (MaterialBuild& b : built) {
    err << b.messages;
    if (b.internalError) status = kExitInternal;
    if (!b.ok) {
      if (status == kExitOk) status = kExitBadInput;
      continue;
    }
    if (auto [at, fresh] = names.emplace(b.summary.name, b.path); !fresh) {
      err << fmt::format("{}: /name: error: material {} has the name of {}: their outputs would overwrite each other\n",
                         b.path, quoteForDiagnostic(b.summary.name), at->second);
      if (status == kExitOk) status = kExitBadInput;
    }
    for (OutputFile& f : b.files) files.push_back(std::move(f));
    if (b.cacheEntry) cacheEntries.push_back(std::move(*b.cacheEntry));
  }
  if (status != kExitOk) return status;
  return writeOutputs(outputs, a.outDir, files, a.depfile, inputs, cacheEntries, out, err);
}

struct PreviewArgs {
  std::string file;
  std::string material;
  std::string output;
  int budget = 0;
  int maxClosures = 0;
  bool fullSimplification = false;
  int size = 256;
  std::string environment = preview::kDefaultEnvironment;
  bool sweep = false;
  std::string target = "glsl";
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  double exposure = 0;
  std::size_t maxInputSize = 16u << 20;
  std::string precision = "float";
};

/// Renders the material (or, with --sweep, a labelled contact sheet of its
/// simplification steps) on lavapipe and writes an 8-bit sRGB PNG.
int runPreview(const PreviewArgs& a, std::ostream& out, std::ostream& err) {
  CompileOptions o;
  if (a.budget > 0) o.budgetOverride = a.budget;
  if (a.maxClosures > 0) o.maxClosuresOverride = a.maxClosures;
  o.fullSimplification = a.fullSimplification;
  o.read.maxInputBytes = a.maxInputSize;
  CommandOutputs outputs(out);
  outputs.namedFile(a.output);
  outputs.input(a.file);
  if (int status = outputs.check(err); status != kExitOk) return status;
  auto source = loadMaterial(a.file, a.material, o.read, err);
  if (!source) return kExitBadInput;
  if (int status = outputs.check(err); status != kExitOk) return status;  // its includes too, before rendering
  const std::string& text = source->text;
  std::vector<sweep::Step> entries;
  Diagnostics failure(source->displayName);  // what a tool reports (printed below, in the command's own words)
  if (a.sweep) {
    CompileResult full;
    if (!sweep::simplificationSteps(source->displayName, text, o, &entries, &full, failure)) {
      err << failure.formatAll();
      return compileFailure(*source, err);
    }
  } else {
    Diagnostics diags(source->displayName);
    auto r = compileText(source->displayName, text, o, diags);
    err << diags.formatAll();
    if (!r) return compileFailure(*source, err);
    entries.push_back({std::move(*r), "", 0});
  }
  gpu::Context::Options go;
  auto ctx = gpu::Context::create(go, failure);
  if (!ctx || !gpu::canRun(*ctx, precisionOf(a.precision), failure)) {
    err << "substratec: error: preview renders on Vulkan (Mesa lavapipe): " << failure.errorMessages() << "\n";
    return kExitBadInput;
  }
  preview::RenderOptions ro;
  ro.size = a.size;
  ro.environment = a.environment;
  ro.target = a.target == "hlsl" ? Target::Hlsl : Target::Glsl;
  ro.diffuseModel = diffuseModelOf(a.diffuse);
  ro.precision = precisionOf(a.precision);
  ro.exposure = a.exposure;
  std::vector<preview::Image> tiles;
  std::vector<std::string> labels;
  for (const auto& e : entries) {
    preview::Image hdr;
    if (!preview::renderSphere(*ctx, e.result, ro, &hdr, failure)) {
      err << "substratec: internal compiler error: " << failure.errorMessages() << "\n";
      return kExitInternal;
    }
    tiles.push_back(preview::tonemap(hdr, a.exposure));
    const int closures = static_cast<int>(e.result.after.closures.size());
    labels.push_back(fmt::format("{}: {} B, {} cl", e.label, e.result.after.bytes(), closures));
  }
  preview::Image image = a.sweep ? preview::contactSheet(tiles, labels, std::min<int>(4, static_cast<int>(tiles.size())))
                                 : tiles.front();
  preview::Srgb8 srgb = preview::encodeSrgb8(image);
  if (srgb.nanCount > 0) {
    err << "substratec: internal compiler error: " << srgb.nanCount << " pixels of the preview are NaN\n";
    return kExitInternal;
  }
  std::vector<uint8_t> png;
  if (!preview::encodePng(image.width, image.height, srgb.rgba, png, failure)) {
    err << "substratec: internal compiler error: cannot encode the PNG: " << failure.errorMessages() << "\n";
    return kExitInternal;
  }
  if (int status = outputs.commit({{a.output, std::string(png.begin(), png.end())}}, err); status != kExitOk)
    return status;
  out << a.output << "\n";
  return kExitOk;
}

struct SweepArgs {
  std::string file;
  std::string material;
  bool json = false;
  bool csv = false;
  std::string plot;
  double maxError = -1;
  int pixels = 1 << 20;
  int runs = 5;
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  std::size_t maxInputSize = 16u << 20;
  int groundTruthProbes = 128;
  int groundTruthSamples = 1024;
  std::string precision = "float";
};

/// The material at its full budget and at each simplification step: cost
/// (bytes, closures, instructions, lavapipe time) against error (vs the
/// unsimplified tree). --max-error chooses the cheapest row within the error.
int runSweep(const SweepArgs& a, std::ostream& out, std::ostream& err) {
  CompileOptions o;
  o.read.maxInputBytes = a.maxInputSize;
  CommandOutputs outputs(out);
  outputs.namedFile(a.plot);
  outputs.input(a.file);
  if (int status = outputs.check(err); status != kExitOk) return status;
  auto source = loadMaterial(a.file, a.material, o.read, err);
  if (!source) return kExitBadInput;
  if (int status = outputs.check(err); status != kExitOk) return status;  // its includes too, before measuring
  std::vector<sweep::Step> steps;
  CompileResult full;
  Diagnostics failure(source->displayName);  // what a tool reports (printed in the command's own words)
  if (!sweep::simplificationSteps(source->displayName, source->text, o, &steps, &full, failure)) {
    err << failure.formatAll();
    return compileFailure(*source, err);
  }
  auto ctx = gpu::Context::create(gpu::Context::Options{}, failure);
  if (!ctx || !gpu::canRun(*ctx, precisionOf(a.precision), failure)) {
    err << "substratec: error: sweep times the generated code on Vulkan (Mesa lavapipe): " << failure.errorMessages()
        << "\n";
    return kExitBadInput;
  }
  sweep::Options so;
  so.pixels = a.pixels;
  so.timedRuns = a.runs;
  so.diffuseModel = diffuseModelOf(a.diffuse);
  so.groundTruthProbes = a.groundTruthProbes;
  so.groundTruthSamples = a.groundTruthSamples;
  so.precision = precisionOf(a.precision);
  std::vector<sweep::Row> rows;
  if (!sweep::measure(*ctx, steps, full, so, &rows, failure)) {
    err << "substratec: internal compiler error: " << failure.errorMessages() << "\n";
    return kExitInternal;
  }
  const std::string& name = full.material.name;
  if (!a.plot.empty())
    if (int status = outputs.commit({{a.plot, sweep::plotSvg(name, rows)}}, err); status != kExitOk) return status;
  if (a.json) out << sweep::formatJson(name, rows);
  else if (a.csv) out << sweep::formatCsv(rows);
  else out << sweep::formatTable(name, rows);
  if (a.maxError >= 0) {
    auto best = sweep::cheapestWithin(rows, a.maxError);
    if (!best) {
      err << fmt::format("substratec: error: no step of '{}' is within rel_mse {} (the full budget's is {:.3e})\n", name,
                         a.maxError, rows.empty() ? 0.0 : rows.front().relMse);
      return kExitBadInput;
    }
    (a.json || a.csv ? err : out) << fmt::format("budget {} ({}: {} B, {} closures, rel_mse {:.3e})\n",
                                                 rows[*best].budget, rows[*best].label, rows[*best].bytes,
                                                 rows[*best].closures, rows[*best].relMse);
  }
  return kExitOk;
}

struct StabilityArgs {
  std::string file;
  std::string material;
  bool json = false;
  long evaluations = 100000;
  bool noGpu = false;
  bool gpuOnly = false;
  std::optional<int> budget, maxClosures;
  bool fullSimplification = false;
  std::size_t maxInputSize = 16u << 20;
  std::string precision = "float";
  bool stressTextures = false;
};

/// The material on the hard-case grid (compiler/tools/stability/stability.h): counts
/// of non-finite values on the CPU reference and on lavapipe, and the white
/// furnace. Exit 4 when anything is non-finite or the furnace exceeds 1.001.
int runStability(const StabilityArgs& a, std::ostream& out, std::ostream& err) {
  CompileOptions o;
  o.read.maxInputBytes = a.maxInputSize;
  o.budgetOverride = a.budget;
  o.maxClosuresOverride = a.maxClosures;
  o.fullSimplification = a.fullSimplification;
  CommandOutputs outputs(out);  // writes only standard output
  outputs.input(a.file);
  if (int status = outputs.check(err); status != kExitOk) return status;
  // Every material of a glTF or MaterialX file without --material (like `report`).
  Diagnostics loadDiags(a.file);
  auto sources = import::loadMaterialSources(a.file, a.material, true, o.read, loadDiags);
  err << loadDiags.formatAll();
  if (!sources) return kExitBadInput;
  if (int status = outputs.check(err); status != kExitOk) return status;  // the includes read, too
  std::unique_ptr<gpu::Context> ctx;
  if (!a.noGpu) {
    Diagnostics failure(a.file);
    ctx = gpu::Context::create(gpu::Context::Options{}, failure);
    if (!ctx || !gpu::canRun(*ctx, precisionOf(a.precision), failure)) {
      err << "substratec: error: stability runs the generated code on Vulkan (Mesa lavapipe; --no-gpu skips it): "
          << failure.errorMessages() << "\n";
      return kExitBadInput;
    }
  }
  stability::Options so;
  so.evaluations = a.evaluations;
  so.gpu = !a.noGpu;
  so.cpu = !a.gpuOnly;
  so.precision = precisionOf(a.precision);
  so.textures = a.stressTextures ? gpu::TextureSet::Checker : gpu::TextureSet::Neutral;
  int status = kExitOk;
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  bool first = true;
  for (const import::MaterialSource& source : *sources) {
    const std::string& text = source.text;
    {  // The material as written: its diagnostics name its own lines.
      Diagnostics diags(source.displayName);
      if (!compileText(source.displayName, text, o, diags)) {
        err << diags.formatAll();
        status = std::max(status, compileFailure(source, err));
        continue;
      }
    }
    std::string forceable;
    std::vector<stability::ForcedKind> kinds;
    Diagnostics failure(source.displayName);
    if (!stability::forceableText(text, &forceable, &kinds, failure)) {
      err << "substratec: error: " << source.displayName << ": " << failure.errorMessages() << "\n";
      status = std::max(status, static_cast<int>(kExitBadInput));
      continue;
    }
    const std::string forcingName = source.displayName + " (with forcing inputs)";
    Diagnostics diags(forcingName);
    auto r = compileText(forcingName, forceable, stability::forcingOptions(o, kinds), diags);
    if (!r) {
      err << "substratec: internal compiler error: the material with forcing inputs does not compile\n"
          << diags.formatAll();
      return kExitInternal;
    }
    stability::Report report;
    if (!stability::run(*r, kinds, so, ctx.get(), &report, failure)) {
      err << "substratec: internal compiler error: " << failure.errorMessages() << "\n";
      return kExitInternal;
    }
    if (a.json) {
      all.push_back(stability::toJson(report));
    } else {
      if (!first) out << "\n";
      out << stability::formatText(report);
    }
    first = false;
    if (!stability::furnaceExercised(report))
      err << fmt::format("substratec: error: {}: the furnace was never exercised: none of its {} evaluations returned "
                         "any light{}\n",
                         source.displayName, report.furnaceEvaluations,
                         a.stressTextures ? " (--stress-textures binds a checker that, read as a normal map, points "
                                            "below the surface)"
                                          : "");
    if (!stability::passed(report)) status = std::max(status, static_cast<int>(kExitUnstable));
  }
  // One material: its object (as before); several: an array, in file order.
  if (a.json && !all.empty()) out << (sources->size() == 1 ? all[0] : all).dump(2) << "\n";
  return status;
}

struct ImportArgs {
  std::vector<std::string> files;
  std::string outDir;
  std::string material;
  bool force = false;
  std::size_t maxInputSize = 16u << 20;
};

/// `import`: every material of glTF / MaterialX files and of the importable
/// files under directories (or the --material one) as substrate-material/1
/// files in the output directory, all or none; each is compiled first, so what
/// is written is known to compile. A file in the way is replaced only when an
/// import of the same source wrote it (import::replaceCheck), or with --force.
int runImport(const ImportArgs& a, std::ostream& out, std::ostream& err) {
  ReadLimits read;
  read.maxInputBytes = a.maxInputSize;
  std::string messages;
  auto inputs = import::collectImportInputs(a.files, messages);
  err << messages;
  if (!inputs) return kExitBadInput;
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  for (const import::ImportInput& in : *inputs) outputs.input(in.path);
  if (int status = outputs.check(err); status != kExitOk) return status;
  // Every file's materials, named uniquely across the files (case-insensitively:
  // they become file names), located by file.
  std::vector<import::ImportedMaterial> materials;
  std::vector<std::string> sourceOf;  // the input each material comes from
  import::NameSet names(/*caseInsensitive=*/true);
  bool failed = false;
  for (const import::ImportInput& in : *inputs) {
    Diagnostics diags(in.path);
    auto imported = import::importFile(in.path, read, diags);
    if (!imported && in.fromDirectory && diags.errorCount() == 1 &&
        diags.all().back().message == "the file holds no material") {
      err << in.path << ": warning: the file holds no material; skipped\n";  // e.g. a MaterialX library
      continue;
    }
    err << diags.formatAll();
    if (!imported) {
      failed = true;
      continue;
    }
    for (auto& m : *imported) {
      const std::string wanted = m.name;
      const std::string name = names.claim(wanted);
      if (name != wanted) {
        err << fmt::format("{}: warning: material {} is written as {}.json: an earlier file has a material named {}\n",
                           in.path, quoteForDiagnostic(m.sourceName.empty() ? wanted : m.sourceName), name, wanted);
        import::renameMaterial(m, name);
      }
      if (inputs->size() > 1) m.location = in.path + " " + m.location;
      materials.push_back(std::move(m));
      sourceOf.push_back(in.path);
    }
  }
  if (failed) return kExitBadInput;
  if (!a.material.empty()) {
    Diagnostics diags(inputs->size() == 1 ? inputs->front().path : "");
    const import::ImportedMaterial* m = import::pickMaterial(materials, a.material, diags);
    if (inputs->size() == 1) err << diags.formatAll();
    else for (const Diagnostic& d : diags.all()) err << "substratec: error: " << d.message << "\n";  // several files
    if (!m) return kExitBadInput;
    const std::size_t i = static_cast<std::size_t>(m - materials.data());
    materials = {materials[i]};
    sourceOf = {sourceOf[i]};
  }
  std::vector<OutputFile> files;
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const import::ImportedMaterial& m = materials[i];
    const import::MaterialSource source{sourceOf[i] + "[" + m.name + "]", m.text, true};
    Diagnostics compileDiags(source.displayName);
    if (!compileText(source.displayName, m.text, CompileOptions{}, compileDiags)) {
      err << compileDiags.formatAll();
      return compileFailure(source, err);
    }
    files.push_back({m.name + ".json", m.text});
  }
  // Nothing is replaced that an import of the same source did not write. An
  // output that is one of the files read is refused first (writeOutputs):
  // that it is an input is the truer message.
  std::vector<std::string> foreign;
  const std::vector<InputFile> inputsRead = outputs.inputs();
  for (std::size_t i = 0; i < files.size() && !a.force; ++i) {
    const std::string path = (std::filesystem::path(a.outDir) / files[i].name).string();
    if (!sameFileAsInput({path}, inputsRead).empty()) continue;
    const std::string source = std::filesystem::path(sourceOf[i]).filename().string();
    if (import::replaceCheck(path, files[i].contents, source) == import::Replace::Foreign)
      foreign.push_back(fmt::format("substratec: error: {} exists and was not written by importing {} (it is not the "
                                    "same text, nor a material whose description begins \"Imported from {} \"): not "
                                    "replaced; --force replaces it\n",
                                    path, source, source));
  }
  if (!foreign.empty()) {
    for (const auto& f : foreign) err << f;
    return kExitUsage;
  }
  return writeOutputs(outputs, a.outDir, files, "", {}, {}, out, err);
}

struct SceneArgs {
  std::string manifest;
  std::string outDir;
  std::string platform;
  std::string platforms;
  std::string target = "all";
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  int jobs = 0;
  int budget = 0;
  int maxClosures = 0;
  std::size_t maxInputSize = 16u << 20;
  std::string cache;
  std::string depfile;
};

/// Every material of a scene for its platform, and the lighting the scene
/// needs (scene/scene.h), written atomically into the output directory.
/// The exit code of a scene build's status (the scene floor knows no exit codes).
int exitCode(SceneStatus s) {
  switch (s) {
    case SceneStatus::Ok: return kExitOk;
    case SceneStatus::BadInput: return kExitBadInput;
    case SceneStatus::BadUsage: return kExitUsage;
    case SceneStatus::InternalError: return kExitInternal;
  }
  return kExitInternal;
}

int runScene(const SceneArgs& a, std::ostream& out, std::ostream& err) {
  SceneOptions o;
  o.manifest = a.manifest;
  if (!a.platform.empty()) o.platform = a.platform;
  o.platformsFile = a.platforms;
  o.batch = batchOptions(a.budget, a.maxClosures, a.maxInputSize, a.target, a.diffuse, a.jobs, a.cache);
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  outputs.namedFile(a.depfile);
  outputs.directory(a.cache);
  outputs.input(a.manifest);
  outputs.input(a.platforms);
  if (int status = outputs.check(err); status != kExitOk) return status;
  SceneBuild b = buildScene(o);
  err << b.messages;
  if (b.status != SceneStatus::Ok) return exitCode(b.status);
  // The scene's depfile has one target, scene.json: which lighting files a
  // scene has depends on its materials, so a build system cannot list them
  // beforehand; it depends on scene.json (written with them, atomically).
  return writeOutputs(outputs, a.outDir, b.files, a.depfile, b.inputs, b.cacheEntries, out, err, "scene.json");
}

}  // namespace

int runCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  CLI::App app{"substratec: compiles Substrate material graphs (substrate-material/1) into priced, simplified, "
               "flattened shaders",
               "substratec"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "substratec 0.1.0 (" + toolchainVersions() + ")");

  ReportArgs report;
  CLI::App* rep = app.add_subcommand("report", "Print the tree, features, byte budget and layout of materials");
  rep->add_option("files", report.files, "Material files (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx: every material)")->required();
  rep->add_option("--material", report.material, "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)");
  rep->add_option("--budget", report.budget, "Bytes per pixel budget (overrides settings.bytes_per_pixel)")
      ->transform(cli::inRange(8, 1024, "bytes"))->default_str("the file's settings.bytes_per_pixel");
  rep->add_option("--max-closures", report.maxClosures, "Closure budget (overrides settings.max_closures)")
      ->transform(cli::inRange(1, 8, "closures"))->default_str("the file's settings.max_closures");
  rep->add_flag("--full-simplification", report.fullSimplification, "Collapse everything into one closure");
  rep->add_flag("--json", report.json, "Print the report as JSON (docs/report.md)");
  rep->add_option("--max-input-size", report.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  rep->add_flag("--print-after-all", report.printAfterAll, "Dump the IR after every pass (stderr)");
  rep->add_flag("--time-passes", report.timePasses, "Print the time of every pass (stderr)");
  rep->add_flag("--spirv", report.spirv,
                "Also compile every entry shader and print its SPIR-V instruction count (before and after "
                "SPIRV-Tools' performance passes)");

  CompileArgs compile;
  CLI::App* comp = app.add_subcommand("compile", "Generate flattened GLSL/HLSL, the packing layout and entry shaders");
  comp->add_option("files", compile.files,
                  "Material files (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)")->required();
  comp->add_option("--material", compile.material, "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)");
  comp->add_option("-o,--output", compile.outDir, "Output directory")->required();
  comp->add_option("--target", compile.target, "glsl, hlsl or all")->check(CLI::IsMember({"glsl", "hlsl", "all"}))->capture_default_str();
  comp->add_option("--diffuse", compile.diffuse, "Diffuse model")
      ->check(CLI::IsMember(diffuseModelNames()))->capture_default_str();
  comp->add_option("--budget", compile.budget, "Bytes per pixel budget")->transform(cli::inRange(8, 1024, "bytes"))->default_str("the file's settings.bytes_per_pixel");
  comp->add_option("--max-closures", compile.maxClosures, "Closure budget")->transform(cli::inRange(1, 8, "closures"))->default_str("the file's settings.max_closures");
  comp->add_flag("--full-simplification", compile.fullSimplification, "Collapse everything into one closure");
  comp->add_flag("--skip-validation", compile.skipValidation,
                 "Write the outputs without compiling them with glslang (debugging the generator)");
  comp->add_option("--max-input-size", compile.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  addPrecisionOption(comp, compile.precision);
  comp->add_option("-j,--jobs", compile.jobs, "Materials compiled at once (default: the machine's threads)")
      ->transform(cli::inRange(1, 256, "threads"))->default_str("the machine's threads");
  comp->add_option("--platform", compile.platform,
                   "Simplify for this platform (built in: " + PlatformTable::builtin().names() +
                       "; more with --platforms; docs/scenes.md)");
  comp->add_option("--platforms", compile.platforms, "A substrate-platforms/1 file extending the built-in platforms");
  comp->add_option("--cache", compile.cache,
                   "Content-hash cache directory: an unchanged material (bytes, options, compiler) is not recompiled");
  comp->add_option("--depfile", compile.depfile, "Write a Make-syntax dependency file (like glslc -MD -MF)");

  PreviewArgs prev;
  CLI::App* pre = app.add_subcommand("preview", "Render the material on a sphere (Vulkan, Mesa lavapipe) into a PNG");
  pre->add_option("file", prev.file, "Material file (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)")->required();
  pre->add_option("--material", prev.material, "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)");
  pre->add_option("-o,--output", prev.output, "PNG file to write")->required();
  pre->add_option("--budget", prev.budget, "Bytes per pixel budget")->transform(cli::inRange(8, 1024, "bytes"))->default_str("the file's settings.bytes_per_pixel");
  pre->add_option("--max-closures", prev.maxClosures, "Closure budget")->transform(cli::inRange(1, 8, "closures"))->default_str("the file's settings.max_closures");
  pre->add_flag("--full-simplification", prev.fullSimplification, "Collapse everything into one closure");
  pre->add_option("--size", prev.size, "Image width and height in pixels")->transform(cli::inRange(16, 2048, "pixels"))->capture_default_str();
  pre->add_option("--env", prev.environment, "Procedural environment")->check(CLI::IsMember(preview::environmentNames()))->capture_default_str();
  pre->add_flag("--sweep", prev.sweep,
                "A contact sheet: the material at each simplification step, labelled with bytes and closures");
  pre->add_option("--target", prev.target, "Which generated language renders: glsl or hlsl")
      ->check(CLI::IsMember({"glsl", "hlsl"}))->capture_default_str();
  pre->add_option("--diffuse", prev.diffuse, "Diffuse model")
      ->check(CLI::IsMember(diffuseModelNames()))->capture_default_str();
  pre->add_option("--exposure", prev.exposure, "Exposure in stops before the tone curve")->transform(cli::inRange(-16.0, 16.0, "stops"))->capture_default_str();
  pre->add_option("--max-input-size", prev.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  addPrecisionOption(pre, prev.precision);

  SweepArgs sw;
  CLI::App* swp = app.add_subcommand("sweep", "Cost against error at the full budget and at each simplification step");
  swp->add_option("file", sw.file, "Material file (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)")->required();
  swp->add_option("--material", sw.material, "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)");
  CLI::Option* swJson = swp->add_flag("--json", sw.json, "Print {\"material\": ..., \"rows\": [...]}");
  swp->add_flag("--csv", sw.csv, "Print the rows as CSV (not with --json: one format on stdout)")->excludes(swJson);
  swp->add_option("--plot", sw.plot, "Also write an SVG plot of error against cost");
  swp->add_option("--max-error", sw.maxError, "Choose the cheapest row with rel_mse <= E and print its budget")
      ->transform(cli::inRange(0.0, 1e30, "(relative MSE)"));
  swp->add_option("--pixels", sw.pixels, "Shading points per timed dispatch")->transform(cli::inRange(64, 1 << 24, "shading points"))->capture_default_str();
  swp->add_option("--runs", sw.runs, "Timed dispatches after the warm-up (the median is reported)")
      ->transform(cli::inRange(1, 100, "runs"))->capture_default_str();
  swp->add_option("--diffuse", sw.diffuse, "Diffuse model")
      ->check(CLI::IsMember(diffuseModelNames()))->capture_default_str();
  swp->add_option("--max-input-size", sw.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  swp->add_option("--ground-truth-probes", sw.groundTruthProbes,
                  "Shading points walked for rel_mse_vs_ground_truth (0: skip the column)")
      ->transform(cli::inRange(0, 1024, "shading points"))->capture_default_str();
  swp->add_option("--ground-truth-samples", sw.groundTruthSamples, "Random walks per shading point and channel group")
      ->transform(cli::inRange(1, 1 << 20, "walks"))->capture_default_str();
  addPrecisionOption(swp, sw.precision);

  StabilityArgs stab;
  CLI::App* sta = app.add_subcommand("stability", "Hard cases: non-finite values on the CPU and on lavapipe, white furnace");
  sta->add_option("file", stab.file, "Material file (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)")->required();
  sta->add_option("--material", stab.material, "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)");
  sta->add_flag("--json", stab.json, "Print the counts and the worst cases as JSON");
  sta->add_option("--evaluations", stab.evaluations, "Shading points to evaluate at least (each path)")
      ->transform(cli::inRange(1L, 100000000L, "shading points"))->capture_default_str();
  sta->add_flag("--no-gpu", stab.noGpu, "CPU reference only");
  sta->add_flag("--gpu-only", stab.gpuOnly, "The generated shaders only (no CPU reference, no furnace)")
      ->excludes("--no-gpu");
  sta->add_option("--budget", stab.budget, "Bytes per pixel budget")->transform(cli::inRange(8, 1024, "bytes"))->default_str("the file's settings.bytes_per_pixel");
  sta->add_option("--max-closures", stab.maxClosures, "Closures per pixel")->transform(cli::inRange(1, 8, "closures"))->default_str("the file's settings.max_closures");
  sta->add_flag("--full-simplification", stab.fullSimplification, "Collapse to one closure first");
  sta->add_option("--max-input-size", stab.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  addPrecisionOption(sta, stab.precision);
  sta->add_flag("--stress-textures", stab.stressTextures,
                "Bind every texture to the GPU tests' checker (normal maps tilt, half below the surface) instead of "
                "its neutral value (flat normal, mid-grey)");

  ImportArgs imp;
  CLI::App* impc = app.add_subcommand("import", "Import glTF 2.0 (.gltf, .glb, .materials.json) or MaterialX (.mtlx) "
                                                 "materials as substrate-material/1 files (docs/import.md)");
  impc->add_option("files", imp.files,
                   "The .gltf, .glb, .materials.json or .mtlx files, and directories to search for them")
      ->required();
  impc->add_option("-o,--output", imp.outDir, "Output directory (one <material>.json per material)")->required();
  impc->add_option("--material", imp.material, "Import only this material (by name or identifier)");
  impc->add_flag("--force", imp.force,
                 "Replace files in the output directory that an import of the same source did not write");
  impc->add_option("--max-input-size", imp.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();

  SceneArgs scn;
  CLI::App* sce = app.add_subcommand(
      "scene", "Compile a scene's materials for its platform and the lighting it needs (docs/scenes.md)");
  sce->add_option("manifest", scn.manifest, "Scene manifest (substrate-scene/1 JSON)")->required();
  sce->add_option("-o,--output", scn.outDir, "Output directory")->required();
  sce->add_option("--platform", scn.platform,
                  "Platform to build for, overriding the manifest's (built in: " + PlatformTable::builtin().names() +
                      "; more with --platforms)");
  sce->add_option("--platforms", scn.platforms, "A substrate-platforms/1 file extending the built-in platforms");
  sce->add_option("-j,--jobs", scn.jobs, "Materials compiled at once (default: the machine's threads)")
      ->transform(cli::inRange(1, 256, "threads"))->default_str("the machine's threads");
  sce->add_option("--target", scn.target, "glsl, hlsl or all")->check(CLI::IsMember({"glsl", "hlsl", "all"}))->capture_default_str();
  sce->add_option("--diffuse", scn.diffuse, "Diffuse model")
      ->check(CLI::IsMember(diffuseModelNames()))->capture_default_str();
  sce->add_option("--budget", scn.budget, "Bytes per pixel budget of every material (the platform still caps it)")
      ->transform(cli::inRange(8, 1024, "bytes"))->default_str("the file's settings.bytes_per_pixel");
  sce->add_option("--max-closures", scn.maxClosures, "Closure budget of every material")->transform(cli::inRange(1, 8, "closures"))->default_str("the file's settings.max_closures");
  sce->add_option("--max-input-size", scn.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
  sce->add_option("--cache", scn.cache, "Content-hash cache directory for the materials");
  sce->add_option("--depfile", scn.depfile,
                  "Write a Make-syntax dependency file: the outputs depend on the manifest, the platforms file and "
                  "every material");

  // No command, or a word that is none of them: say so and list them (CLI11
  // alone says "A subcommand is required" or "arguments were not expected").
  std::string commands;
  bool known = false;
  for (const CLI::App* c : app.get_subcommands({})) {
    commands += (commands.empty() ? "" : ", ") + c->get_name();
    known = known || (!args.empty() && c->check_name(args[0]));
  }
  if (args.empty() || (!known && !args[0].empty() && args[0][0] != '-')) {
    err << "substratec: error: "
        << (args.empty() ? std::string("a command is required") : "unknown command " + quoteForDiagnostic(args[0]))
        << " (the commands: " << commands << ")\n";
    err << "Run 'substratec --help' for usage.\n";
    return kExitUsage;
  }
  std::vector<std::string> argv = args;
  std::reverse(argv.begin(), argv.end());  // CLI11 parses a reversed vector
  try {
    app.parse(argv);
  } catch (const CLI::CallForHelp&) {
    out << app.help();
    return kExitOk;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return kExitOk;
  } catch (const CLI::CallForVersion&) {
    out << "substratec 0.1.0 (" << toolchainVersions() << ")\n";
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    err << "substratec: error: " << e.what() << "\n";
    err << "Run 'substratec --help' for usage.\n";
    return kExitUsage;
  }
  try {
    if (rep->parsed()) return runReport(report, out, err);
    if (comp->parsed()) return runCompile(compile, out, err);
    if (pre->parsed()) return runPreview(prev, out, err);
    if (swp->parsed()) return runSweep(sw, out, err);
    if (sta->parsed()) return runStability(stab, out, err);
    if (impc->parsed()) return runImport(imp, out, err);
    if (sce->parsed()) return runScene(scn, out, err);
  } catch (const std::exception& e) {
    err << "substratec: internal compiler error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitUsage;
}

}  // namespace substratec
