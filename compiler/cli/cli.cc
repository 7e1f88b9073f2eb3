// The substratec command line. Each option that several commands share is
// defined once, in an option group below (the material files, --material,
// the compile options, the build options, --diffuse, --precision…), and
// turned into the library's options by one function (toCompileOptions,
// toBatchOptions); each command is a struct of its arguments, a function that
// adds its options and a function that runs it by calling the library; runCli
// lists the commands and dispatches. Every message the CLI prints in its own
// name goes through cli/messages.h.
#include "cli/cli.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <ostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "accuracy/accuracy.h"
#include "accuracy/fog_accuracy.h"
#include "batch/batch.h"
#include "format/json_document.h"
#include "cli/cli_options.h"
#include "cli/argument_files.h"
#include "cli/command_outputs.h"
#include "cli/messages.h"
#include "pipeline/generate.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "import/import.h"
#include "mesh/gltf_mesh.h"
#include "output/atomic_write.h"
#include "output/depfile.h"
#include "pipeline/pass_registry.h"
#include "pipeline/pipeline.h"
#include "preview/contact_sheet.h"
#include "preview/environment.h"
#include "preview/render.h"
#include "render/materials.h"
#include "render/render.h"
#include "report/html_report.h"
#include "report/report.h"
#include "scene/scene.h"
#include "stability/stability.h"
#include "storage/pack.h"
#include "sweep/sweep.h"
#include "sweep/volume_sweep.h"
#include "validate/toolchain.h"

namespace substratec {

namespace {

using cli::printError;
using cli::printInternalError;
using cli::printUsageError;

// ----- Option groups ---------------------------------------------------------

const char* const kMaterialFileHelp = "Material file (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)";
const char* const kMaterialFilesHelp =
    "Material files (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx)";
const char* const kMaterialChoiceHelp = "Choose one material of a .gltf, .glb, .materials.json or .mtlx file (by name)";

/// The input of preview, sweep and stability: FILE and --material.
struct MaterialInput {
  std::string file;
  std::string material;  // --material: one of a file that holds several ("": the only one, or every one)
};

/// The inputs of report, compile and import: FILES and --material.
struct MaterialInputs {
  std::vector<std::string> files;
  std::string material;
};

/// FILES (positional, required).
void addMaterialFiles(CLI::App* c, std::vector<std::string>& files, const std::string& help) {
  c->add_option("files", files, help)->required();
}

/// --material: one material of a file that holds several.
void addMaterialChoice(CLI::App* c, std::string& material, const std::string& help = kMaterialChoiceHelp) {
  c->add_option("--material", material, help);
}

/// FILE and --material.
void addMaterialInput(CLI::App* c, MaterialInput& in) {
  c->add_option("file", in.file, kMaterialFileHelp)->required();
  addMaterialChoice(c, in.material);
}

/// FILES and --material.
void addMaterialInputs(CLI::App* c, MaterialInputs& in, const std::string& filesHelp = kMaterialFilesHelp) {
  addMaterialFiles(c, in.files, filesHelp);
  addMaterialChoice(c, in.material);
}

/// -o, --output: what the command writes (a directory or a file).
void addOutput(CLI::App* c, std::string& output, const std::string& help) {
  c->add_option("-o,--output", output, help)->required();
}

/// The options that decide how a material compiles (CompileOptions).
struct CompileFlags {
  int budget = 0;       // --budget (0: the file's settings)
  int maxClosures = 0;  // --max-closures (0: the file's settings)
  bool fullSimplification = false;
  std::size_t maxInputSize = 16u << 20;
  bool printAfterAll = false, timePasses = false;  // report
  std::string printAfter, stopAfter;               // report, compile
};

CompileOptions toCompileOptions(const CompileFlags& f) {
  CompileOptions o;
  if (f.budget > 0) o.budgetOverride = f.budget;
  if (f.maxClosures > 0) o.maxClosuresOverride = f.maxClosures;
  o.fullSimplification = f.fullSimplification;
  o.read.maxInputBytes = f.maxInputSize;
  o.printAfterAll = f.printAfterAll;
  o.timePasses = f.timePasses;
  o.printAfter = f.printAfter;
  o.stopAfter = f.stopAfter;
  return o;
}

/// The help of the budget options, which some commands word their own way.
struct BudgetHelp {
  std::string budget = "Bytes per pixel budget";
  std::string maxClosures = "Closure budget";
  std::string full = "Collapse everything into one closure";  // "": no --full-simplification
};

/// --budget, --max-closures, --full-simplification: the budget a material is simplified to.
void addBudgetOptions(CLI::App* c, CompileFlags& f, const BudgetHelp& help = {}) {
  c->add_option("--budget", f.budget, help.budget)->transform(cli::inRange(8, 1024, "bytes"))
      ->default_str("the file's settings.bytes_per_pixel");
  c->add_option("--max-closures", f.maxClosures, help.maxClosures)->transform(cli::inRange(1, 8, "closures"))
      ->default_str("the file's settings.max_closures");
  if (!help.full.empty()) c->add_flag("--full-simplification", f.fullSimplification, help.full);
}

/// --max-input-size: the largest input read.
void addMaxInputSize(CLI::App* c, CompileFlags& f) {
  c->add_option("--max-input-size", f.maxInputSize, "Reject inputs larger than this many bytes")
      ->transform(cli::inRange(std::size_t{1}, std::size_t{1} << 31, "bytes"))->capture_default_str();
}

/// --print-after, --stop-after: a pass of the registry (pipeline/pass_registry.h).
/// The dumps go to stderr, like --print-after-all (and LLVM's -print-after).
void addPassOptions(CLI::App* c, CompileFlags& f) {
  const CLI::Validator pass(
      [](std::string& name) {
        return findPass(name) ? std::string()
                              : fmt::format("unknown pass {} (the passes: {})", quoteForDiagnostic(name), passNames());
      },
      "PASS");
  c->add_option("--print-after", f.printAfter, "Dump the IR after this pass (stderr; the passes: " + passNames() + ")")
      ->check(pass);
  c->add_option("--stop-after", f.stopAfter, "Run the passes up to and including this one only, and emit nothing")
      ->check(pass);
}

/// --diffuse: the diffuse model's name (ir/enums.h's table).
void addDiffuseOption(CLI::App* c, std::string& diffuse) {
  c->add_option("--diffuse", diffuse, "Diffuse model")->check(CLI::IsMember(diffuseModelNames()))->capture_default_str();
}

/// The model a --diffuse name selects (CLI11 has checked the name).
DiffuseModel diffuseModelOf(const std::string& name) { return parseDiffuseModel(name).value_or(kDefaultDiffuseModel); }

/// --precision (compile, preview, sweep, stability): the runtime's lighting in float32 or half.
void addPrecisionOption(CLI::App* c, std::string& precision) {
  c->add_option("--precision", precision,
                "Lighting precision: float, or half (float16 colours, weights and throughputs; "
                "docs/stability.md)")->check(CLI::IsMember({"float", "half"}))->capture_default_str();
}
Precision precisionOf(const std::string& name) { return name == "half" ? Precision::Half : Precision::Float; }

/// The Vulkan device of preview, sweep and stability, able to run `precision`;
/// nullptr (with `what` it is for in the message) when there is none.
std::unique_ptr<gpu::Context> openGpu(const std::string& precision, const std::string& what, std::ostream& err) {
  Diagnostics failure("gpu");
  auto ctx = gpu::Context::create(gpu::Context::Options{}, failure);
  if (ctx && gpu::canRun(*ctx, precisionOf(precision), failure)) return ctx;
  printError(err, kExitBadInput, what + ": " + failure.errorMessages());
  return nullptr;
}

/// What `compile` and `scene` build every material with.
struct BuildFlags {
  std::string target = "all";
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  int jobs = 0;
  std::string platform, platforms;
  std::string cache, depfile;
};

/// --target: the languages compile and scene write.
void addTargetOption(CLI::App* c, std::string& target) {
  c->add_option("--target", target, "glsl, hlsl or all")->check(CLI::IsMember({"glsl", "hlsl", "all"}))
      ->capture_default_str();
}

/// -j, --jobs: materials compiled at once.
void addJobsOption(CLI::App* c, int& jobs) {
  c->add_option("-j,--jobs", jobs, "Materials compiled at once (default: the machine's threads)")
      ->transform(cli::inRange(1, 256, "threads"))->default_str("the machine's threads");
}

/// --platform, --platforms: the platform built for and where more are defined.
void addPlatformOptions(CLI::App* c, BuildFlags& b, const std::string& platformHelp) {
  c->add_option("--platform", b.platform, platformHelp);
  c->add_option("--platforms", b.platforms, "A substrate-platforms/1 file extending the built-in platforms");
}

/// The options every material of a compile or a scene is built with. glTF
/// and MaterialX files are imported on the fly (the `material` one, or the
/// only one); substrate-material/1 files are read as they are.
BatchOptions toBatchOptions(const CompileFlags& f, const BuildFlags& b, const std::string& material = "") {
  BatchOptions o;
  o.compile = toCompileOptions(f);
  o.generate.glsl = b.target != "hlsl";
  o.generate.hlsl = b.target != "glsl";
  o.generate.emit.diffuseModel = diffuseModelOf(b.diffuse);
  o.jobs = b.jobs;
  // A material taken from the cache runs no pass: the pass options bypass it.
  o.cacheDir = f.printAfter.empty() && f.stopAfter.empty() ? b.cache : "";
  o.load = [material](const std::string& path, const ReadLimits& read,
                      Diagnostics& diags) -> std::optional<BatchSource> {
    auto sources = import::loadMaterialSources(path, material, false, read, diags);
    if (!sources) return std::nullopt;
    import::MaterialSource& s = sources->front();
    return BatchSource{std::move(s.displayName), std::move(s.text), s.imported};
  };
  return o;
}

// ----- What the commands share -------------------------------------------------

/// The materials of a single-file command's FILE (the --material one, or
/// with `every` every one of a glTF or MaterialX file), diagnostics printed;
/// the outputs are checked before it is read and after (what it included
/// counts too). nullopt, with `status`, when it does not load or an output
/// is refused.
std::optional<std::vector<import::MaterialSource>> loadFile(const MaterialInput& in, bool every, const ReadLimits& read,
                                                            CommandOutputs& outputs, std::ostream& err, int& status) {
  outputs.input(in.file);
  if ((status = outputs.check(err)) != kExitOk) return std::nullopt;
  Diagnostics diags(in.file);
  auto sources = import::loadMaterialSources(in.file, in.material, every, read, diags);
  err << diags.formatAll();
  if (!sources) {
    status = kExitBadInput;
    return std::nullopt;
  }
  if ((status = outputs.check(err)) != kExitOk) return std::nullopt;
  return sources;
}

/// The exit status of a material that does not compile: the user's input, or
/// (for an imported one) the importer's bug.
int compileFailure(const import::MaterialSource& s, std::ostream& err) {
  if (!s.imported) return kExitBadInput;
  return printInternalError(err, fmt::format("the material imported from {} does not compile", s.displayName));
}

/// The material at each simplification step (preview --sweep, sweep), and
/// unsimplified in `full`.
/// The commands that shade surfaces (render, stability's grid) refuse a
/// volume (a volumetric fog cloud, isVolumeMaterial) with a
/// located message naming what it has instead; kExitOk for a surface.
int rejectVolume(const Material& m, const std::string& where, std::string_view command, std::ostream& err) {
  if (!isVolumeMaterial(m)) return kExitOk;
  return printError(err, kExitBadInput,
                    fmt::format("{}: '{}' is a volume (volumetric fog cloud '{}'): {} shades surfaces; `compile` "
                                "writes its froxel pass ({}.volume.comp), `accuracy` measures its march",
                                where, m.name, m.nodes[m.root].id, command, m.name));
}

int simplificationSteps(const import::MaterialSource& s, const CompileOptions& o, std::vector<sweep::Step>& steps,
                        CompileResult& full, std::ostream& err) {
  Diagnostics failure(s.displayName);  // printed as the compile's own diagnostics
  if (sweep::simplificationSteps(s.displayName, s.text, o, &steps, &full, failure)) return kExitOk;
  err << failure.formatAll();
  return compileFailure(s, err);
}

/// Removes the steps whose tree the storage format cannot hold (more than
/// packfmt::kMaxClosures closures: an authored tree; no code to render or
/// time) and says which ("'authored' (9 closures)"), or "" when none was.
std::string dropUnpackableSteps(std::vector<sweep::Step>& steps) {
  std::string dropped;
  std::erase_if(steps, [&](const sweep::Step& e) {
    const int closures = static_cast<int>(e.result.after.closures.size());
    if (closures <= packfmt::kMaxClosures) return false;
    dropped = fmt::format("'{}' ({} closures)", e.label, closures);
    return true;
  });
  return dropped;
}

/// --json of report and stability: the one material's object, or an array of them.
void printJson(const nlohmann::ordered_json& all, bool one, std::ostream& out) {
  out << (one ? all[0] : all).dump(2) << "\n";
}

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
  if (std::string error = outputPathsIn(dir, files, &paths); !error.empty())
    return printError(err, kExitBadInput, error);
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

/// `image` (tone-mapped) as an 8-bit sRGB PNG into `png`; kExitInternal, the
/// error printed ("N pixels of the <what> are NaN", or the encoder's), when
/// it cannot be. What preview, render and report --previews write.
int srgbPng(const preview::Image& image, std::string_view what, std::string* png, std::ostream& err) {
  const preview::Srgb8 srgb = preview::encodeSrgb8(image);
  if (srgb.nanCount > 0) return printInternalError(err, fmt::format("{} pixels of the {} are NaN", srgb.nanCount, what));
  std::vector<std::uint8_t> bytes;
  Diagnostics failure(std::string{what});
  if (!preview::encodePng(image.width, image.height, srgb.rgba, bytes, failure))
    return printInternalError(err, "cannot encode the PNG: " + failure.errorMessages());
  png->assign(bytes.begin(), bytes.end());
  return kExitOk;
}

// ----- textures (report --previews, preview, render) ------------------------------

/// --texture NAME=PATH and --search-path DIR: the images a render binds.
struct TextureFlags {
  std::vector<std::string> textures;  // NAME=PATH
  std::vector<std::string> searchPaths;
};

void addTextureOptions(CLI::App* c, TextureFlags& f) {
  c->add_option("--texture", f.textures,
                "Bind the image PATH (PNG or JPEG) to texture input NAME, instead of the input's own file "
                "(repeatable; an input with neither is bound to a neutral texel)")
      ->type_name("NAME=PATH")
      ->check([](const std::string& v) {
        const std::size_t eq = v.find('=');
        return eq == std::string::npos || eq == 0 || eq + 1 == v.size() ? std::string("expected NAME=PATH, got " + v)
                                                                          : std::string();
      });
  c->add_option("--search-path", f.searchPaths,
                "A directory a texture's relative file is looked for in when it is not beside the material file "
                "(repeatable, in order)")
      ->type_name("DIR");
}

/// The sources of `s`'s textures from the flags; kExitUsage (with the message)
/// for a texture input named twice.
int textureSources(const TextureFlags& f, const import::MaterialSource& s, preview::TextureSources* out,
                   std::ostream& err) {
  out->baseDir = s.baseDir;
  out->searchPaths = f.searchPaths;
  for (const std::string& t : f.textures) {
    const std::size_t eq = t.find('=');
    if (!out->overrides.emplace(t.substr(0, eq), t.substr(eq + 1)).second)
      return printError(err, kExitUsage, fmt::format("--texture binds {} twice", t.substr(0, eq)));
  }
  return kExitOk;
}

/// Binds `m`'s textures (preview::bindTextures) from the flags, its notes and
/// errors located in `s` and printed; every image read is an input of
/// `outputs`. kExitBadInput when an image cannot be used.
int bindRenderTextures(const TextureFlags& f, const import::MaterialSource& s, const Material& m, const ReadLimits& read,
                       CommandOutputs& outputs, preview::BoundTextures* out, std::ostream& err) {
  preview::TextureSources sources;
  if (int status = textureSources(f, s, &sources, err); status != kExitOk) return status;
  sources.embedded = &s.images;
  sources.imported = s.imported;
  Diagnostics diags(s.displayName);
  if (!s.imported) parseJsonDocument(s.text, read, diags);  // only for the locator: it compiled already
  const bool ok = preview::bindTextures(m, sources, out, diags);
  err << diags.formatAll();
  for (const std::string& path : out->files) outputs.input(path);
  return ok ? kExitOk : kExitBadInput;
}

// ----- report ------------------------------------------------------------------

struct ReportArgs {
  MaterialInputs in;
  CompileFlags compile;
  bool json = false;
  bool spirv = false;
  std::string html;       // --html: the page to write
  bool previews = false;  // --previews: each simplification step rendered (lavapipe)
  bool sweep = false;     // --sweep: each step's cost and error (lavapipe)
};

void addReportOptions(CLI::App* c, ReportArgs& a) {
  addMaterialInputs(c, a.in,
                    "Material files (substrate-material/1 JSON, or .gltf/.glb/.materials.json/.mtlx: every material)");
  addBudgetOptions(c, a.compile,
                   {"Bytes per pixel budget (overrides settings.bytes_per_pixel)",
                    "Closure budget (overrides settings.max_closures)"});
  c->add_flag("--json", a.json, "Print the report as JSON (docs/report.md)");
  addMaxInputSize(c, a.compile);
  c->add_flag("--print-after-all", a.compile.printAfterAll, "Dump the IR after every pass (stderr)");
  c->add_flag("--time-passes", a.compile.timePasses, "Print the time of every pass (stderr)");
  addPassOptions(c, a.compile);
  CLI::Option* spirv = c->add_flag("--spirv", a.spirv,
                                    "Also compile every entry shader and print its SPIR-V instruction count (before "
                                    "and after SPIRV-Tools' performance passes)");
  CLI::Option* html =
      c->add_option("--html", a.html,
                    "Write the report as one self-contained HTML page instead (tree diagrams, byte budget, layout, "
                    "diagnostics; docs/report.md, \"HTML\")")
          ->type_name("OUT.html")->excludes(spirv);
  html->excludes(c->get_option("--json"))->excludes(c->get_option("--stop-after"));
  c->add_flag("--previews", a.previews,
              "With --html: a preview of the material at each simplification step (renders on lavapipe)")->needs(html);
  c->add_flag("--sweep", a.sweep,
              "With --html: each simplification step's cost and error (sweep's rows, on lavapipe) and the "
              "error-against-cost plot")->needs(html);
}

/// Every material of every file (all of a glTF or MaterialX file without
/// --material); a file that does not load makes `status` bad input.
std::vector<import::MaterialSource> loadEvery(const ReportArgs& a, const ReadLimits& read, std::ostream& err,
                                              int& status) {
  std::vector<import::MaterialSource> sources;
  for (const auto& file : a.in.files) {
    Diagnostics diags(file);
    auto loaded = import::loadMaterialSources(file, a.in.material, true, read, diags);
    err << diags.formatAll();
    if (!loaded) status = kExitBadInput;
    else for (auto& s : *loaded) sources.push_back(std::move(s));
  }
  return sources;
}

/// The SPIR-V instruction counts of every entry shader of `r` (--spirv);
/// nullopt, with the internal error printed, when they do not validate.
std::optional<std::vector<EntryReport>> spirvCounts(const CompileResult& r, std::ostream& err) {
  Generated gen = generateFiles(r, GenerateOptions{});
  validateGenerated(gen, {.optimize = true});
  if (gen.valid) return gen.entries;
  printInternalError(err, "generated code does not validate\n" + gen.failure);
  return std::nullopt;
}

/// One material's report: its JSON object appended to `all` (--json), or its text on `out`.
void reportMaterial(const ReportArgs& a, const CompileResult& r, const std::vector<EntryReport>& entries,
                    bool first, nlohmann::ordered_json& all, std::ostream& out) {
  if (a.json) {
    auto j = reportJson(r);
    if (a.spirv) {
      nlohmann::ordered_json list = nlohmann::ordered_json::array();
      for (const auto& e : entries)
        list.push_back({{"file", e.file}, {"instructions", e.instructions}, {"optimized_instructions", e.optimizedInstructions}});
      j["spirv"] = list;
    }
    all.push_back(j);
    return;
  }
  if (!first) out << "\n";
  out << formatReportText(r);
  if (!a.spirv) return;
  out << fmt::format("----- SPIR-V - {} -----\n", r.material.name);
  for (const auto& e : entries)
    out << fmt::format("{:<40} {:>6} instructions, {:>6} after SPIRV-Tools' performance passes\n", e.file,
                       e.instructions, e.optimizedInstructions);
}

// --html: the report as a page (report/html_report.h). Every material is
// compiled as `report` compiles it, and again unsimplified when its budget
// simplified it (the authored tree beside the simplified one); --previews and
// --sweep add each simplification step rendered and measured on lavapipe.

/// One material's part of the page: compiled (its diagnostics, after `fileDiags`,
/// the import's), and unsimplified when simplification changed it.
html::MaterialPage htmlMaterial(const import::MaterialSource& s, const std::vector<Diagnostic>& fileDiags,
                                const CompileOptions& options, std::ostream& err, int& status) {
  std::string messages;
  html::MaterialPage p = html::compiledMaterial(s.displayName, s.text, options, &messages);
  err << messages;
  p.diagnostics.insert(p.diagnostics.begin(), fileDiags.begin(), fileDiags.end());
  if (p.result) err << p.result->debugLog;  // --print-after(-all)
  else status = std::max(status, compileFailure(s, err));
  return p;
}

/// --previews: `steps` rendered as 128-pixel spheres into the page's steps.
int previewImages(const import::MaterialSource& s, const std::vector<sweep::Step>& steps, const ReadLimits& read,
                  gpu::Context& ctx, CommandOutputs& outputs, html::MaterialPage& p, std::ostream& err) {
  preview::BoundTextures textures;
  if (int failed = bindRenderTextures(TextureFlags{}, s, steps.front().result.material, read, outputs, &textures, err);
      failed != kExitOk)
    return failed;
  preview::RenderOptions ro;
  ro.textures = &textures;
  ro.size = 128;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    preview::Image hdr;
    Diagnostics failure(s.displayName);
    if (!preview::renderSphere(ctx, steps[i].result, ro, &hdr, failure))
      return printInternalError(err, failure.errorMessages());
    const preview::Image image = preview::tonemap(hdr, 0, preview::calibrationGains(ro.environment));
    if (int failed = srgbPng(image, "preview", &p.steps[i].png, err); failed != kExitOk) return failed;
  }
  return kExitOk;
}

/// --sweep: `steps` measured (sweep::measure) into the page's cells and plot.
int sweepCells(const std::vector<sweep::Step>& steps, const CompileResult& full, gpu::Context& ctx,
               html::MaterialPage& p, std::ostream& err) {
  std::vector<sweep::Row> rows;
  Diagnostics failure(full.material.name);
  if (!sweep::measure(ctx, steps, full, sweep::Options{}, &rows, failure))
    return printInternalError(err, failure.errorMessages());
  if (rows.size() != steps.size())
    return printInternalError(err, fmt::format("{} sweep rows for {} steps", rows.size(), steps.size()));
  p.stepColumns = sweep::cellColumns();
  for (std::size_t i = 0; i < rows.size(); ++i) p.steps[i].cells = sweep::cells(rows[i]);
  p.errorPlotSvg = sweep::plotSvg(full.material.name, rows);
  return kExitOk;
}

/// --previews, --sweep: the material's simplification steps (sweep::simplificationSteps)
/// rendered and/or measured into `p`.
int measuredSteps(const ReportArgs& a, const import::MaterialSource& s, const CompileOptions& o, gpu::Context& ctx,
                  CommandOutputs& outputs, html::MaterialPage& p, std::ostream& err) {
  std::vector<sweep::Step> steps;
  CompileResult full;
  if (int failed = simplificationSteps(s, o, steps, full, err); failed != kExitOk) return failed;
  if (isVolumeMaterial(full.material)) {
    p.stepsNote = "A volume: nothing simplifies it, so it has no steps to preview or measure.";
    return kExitOk;
  }
  if (const std::string dropped = dropUnpackableSteps(steps); !dropped.empty())
    p.stepsNote = fmt::format("{} is not rendered nor measured: the storage format packs at most {}.", dropped,
                              packfmt::kMaxClosures);
  for (const auto& e : steps)
    p.steps.push_back({e.label, e.budget, e.result.after.bytes(), static_cast<int>(e.result.after.closures.size()), "",
                       {}});
  if (a.previews)
    if (int failed = previewImages(s, steps, o.read, ctx, outputs, p, err); failed != kExitOk) return failed;
  if (a.sweep)
    if (int failed = sweepCells(steps, full, ctx, p, err); failed != kExitOk) return failed;
  return kExitOk;
}

/// `report --html OUT`: the page of every material of every file (a file
/// that does not load shows its diagnostics), written atomically; its path on stdout.
int runHtmlReport(const ReportArgs& a, const CompileOptions& options, CommandOutputs& outputs, std::ostream& out,
                  std::ostream& err) {
  std::unique_ptr<gpu::Context> ctx;
  if (a.previews || a.sweep) {
    ctx = openGpu("float", "report --previews and --sweep render on Vulkan (Mesa lavapipe)", err);
    if (!ctx) return kExitBadInput;
  }
  html::Page page;
  page.title = a.in.files.size() == 1 ? "substratec report: " + a.in.files.front()
                                       : fmt::format("substratec report: {} files", a.in.files.size());
  int status = kExitOk;
  for (const auto& file : a.in.files) {
    Diagnostics diags(file);
    auto loaded = import::loadMaterialSources(file, a.in.material, true, options.read, diags);
    err << diags.formatAll();
    if (!loaded) {
      status = kExitBadInput;
      html::MaterialPage unread;  // its diagnostics alone
      unread.file = file;
      unread.diagnostics = diags.all();
      page.materials.push_back(std::move(unread));
      continue;
    }
    for (const auto& s : *loaded) {
      page.materials.push_back(htmlMaterial(s, diags.all(), options, err, status));
      if (ctx && page.materials.back().result)
        if (int failed = measuredSteps(a, s, options, *ctx, outputs, page.materials.back(), err); failed != kExitOk)
          return failed;
    }
  }
  if (int usage = outputs.check(err); usage != kExitOk) return usage;  // includes and images are inputs too
  if (int failed = outputs.commit({{a.html, html::formatPage(page)}}, err); failed != kExitOk) return failed;
  out << a.html << "\n";
  return status;
}

/// `report`: every material's tree, features, budget and layout; with
/// --stop-after only the passes' dumps; with --html the page instead.
int runReport(const ReportArgs& a, std::ostream& out, std::ostream& err) {
  const CompileOptions options = toCompileOptions(a.compile);
  CommandOutputs outputs(out);  // writes only standard output, or the --html page
  outputs.namedFile(a.html);
  for (const auto& file : a.in.files) outputs.input(file);
  if (int status = outputs.check(err); status != kExitOk) return status;
  if (!a.html.empty() && options.stopAfter.empty()) return runHtmlReport(a, options, outputs, out, err);
  int status = kExitOk;
  const std::vector<import::MaterialSource> sources = loadEvery(a, options.read, err, status);
  if (int usage = outputs.check(err); usage != kExitOk) return usage;
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  bool first = true;
  for (const auto& source : sources) {
    const std::string& file = source.displayName;
    Diagnostics diags(file);
    auto result = compileText(file, source.text, options, diags);
    err << diags.formatAll();
    if (!result) {
      status = std::max(status, compileFailure(source, err));
      continue;
    }
    err << result->debugLog;  // --print-after(-all)
    if (a.compile.timePasses)
      for (const auto& t : result->timings) err << fmt::format("{}: pass {:<14} {:8.3f} ms\n", file, t.pass, t.milliseconds);
    if (!options.stopAfter.empty()) continue;
    std::optional<std::vector<EntryReport>> entries;
    if (a.spirv && !(entries = spirvCounts(*result, err))) return kExitInternal;
    reportMaterial(a, *result, entries.value_or(std::vector<EntryReport>{}), first, all, out);
    first = false;
  }
  if (a.json && options.stopAfter.empty()) printJson(all, a.in.files.size() == 1 && all.size() == 1, out);
  return status;
}

// ----- compile -----------------------------------------------------------------

struct CompileArgs {
  MaterialInputs in;
  std::string outDir;
  CompileFlags compile;
  BuildFlags build;
  bool skipValidation = false;
  std::string precision = "float";
};

void addCompileOptions(CLI::App* c, CompileArgs& a) {
  addMaterialInputs(c, a.in);
  addOutput(c, a.outDir, "Output directory");
  addTargetOption(c, a.build.target);
  addDiffuseOption(c, a.build.diffuse);
  addBudgetOptions(c, a.compile);
  c->add_flag("--skip-validation", a.skipValidation,
              "Write the outputs without compiling them with glslang (debugging the generator)");
  addMaxInputSize(c, a.compile);
  addPrecisionOption(c, a.precision);
  addJobsOption(c, a.build.jobs);
  addPlatformOptions(c, a.build,
                     "Simplify for this platform (built in: " + PlatformTable::builtin().names() +
                         "; more with --platforms; docs/scenes.md)");
  c->add_option("--cache", a.build.cache,
                "Content-hash cache directory: an unchanged material (bytes, options, compiler) is not recompiled");
  c->add_option("--depfile", a.build.depfile, "Write a Make-syntax dependency file (like glslc -MD -MF)");
  addPassOptions(c, a.compile);
}

/// --platform, --platforms of `compile`: the platform the materials are
/// simplified for, into `o`; the platforms file read is an input.
int choosePlatform(const BuildFlags& b, BatchOptions& o, std::vector<std::string>& inputs, std::ostream& err) {
  if (b.platform.empty() && b.platforms.empty()) return kExitOk;
  std::string messages;
  auto table = loadPlatformTable(b.platforms, o.compile.read, messages);
  err << messages;
  if (!table) return kExitBadInput;
  if (!b.platforms.empty()) inputs.push_back(b.platforms);
  if (b.platform.empty()) return kExitOk;
  const Platform* p = table->find(b.platform);
  if (!p)
    return printError(err, kExitUsage,
                      fmt::format("unknown platform {} (known: {})", quoteForDiagnostic(b.platform), table->names()));
  o.compile.platform = *p;
  return kExitOk;
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

/// What the built materials write (and their cache entries), their messages
/// printed; a material that failed, or whose name another one has (their
/// outputs would overwrite each other), makes `status` bad. `emit` is false
/// with --stop-after: the builds hold only their messages (and dumps).
void gatherBuilds(std::vector<MaterialBuild>& built, bool emit, std::vector<OutputFile>& files,
                  std::vector<OutputPath>& cacheEntries, std::ostream& err, int& status) {
  std::map<std::string, std::string> names;  // material name -> file
  for (MaterialBuild& b : built) {
    err << b.messages;
    if (b.internalError) status = kExitInternal;
    if (!b.ok) {
      if (status == kExitOk) status = kExitBadInput;
      continue;
    }
    if (!emit) continue;
    if (auto [at, fresh] = names.emplace(b.summary.name, b.path); !fresh) {
      err << fmt::format("{}: /name: error: material {} has the name of {}: their outputs would overwrite each other\n",
                         b.path, quoteForDiagnostic(b.summary.name), at->second);
      if (status == kExitOk) status = kExitBadInput;
    }
    for (OutputFile& f : b.files) files.push_back(std::move(f));
    if (b.cacheEntry) cacheEntries.push_back(std::move(*b.cacheEntry));
  }
}

/// Every file compiled (in parallel with -j, from --cache when unchanged) into
/// one output directory; all of them are written, or none. Every material of
/// a file that holds several, without --material (everyMaterialOf). With
/// --stop-after, the passes' dumps only.
int runCompile(const CompileArgs& a, std::ostream& out, std::ostream& err) {
  BatchOptions o = toBatchOptions(a.compile, a.build, a.in.material);
  o.generate.emit.precision = precisionOf(a.precision);
  o.validate = !a.skipValidation;
  std::vector<std::string> inputs = a.in.files;
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  outputs.namedFile(a.build.depfile);
  outputs.directory(a.build.cache);
  for (const auto& f : a.in.files) outputs.input(f);
  outputs.input(a.build.platforms);
  if (int status = outputs.check(err); status != kExitOk) return status;
  if (int status = choosePlatform(a.build, o, inputs, err); status != kExitOk) return status;
  int status = kExitOk;
  const std::vector<std::string> units =
      a.in.material.empty() ? everyMaterialOf(a.in.files, o, err, &status) : a.in.files;
  std::vector<MaterialBuild> built = buildMaterials(units, o);
  std::vector<OutputFile> files;
  std::vector<OutputPath> cacheEntries;
  const bool emit = a.compile.stopAfter.empty();
  gatherBuilds(built, emit, files, cacheEntries, err, status);
  if (status != kExitOk || !emit) return status;
  return writeOutputs(outputs, a.outDir, files, a.build.depfile, inputs, cacheEntries, out, err);
}

// ----- preview -----------------------------------------------------------------

/// --env: a procedural environment by name, or a Radiance file (lat-long).
void addEnvironmentOption(CLI::App* c, std::string& environment) {
  std::string names;
  for (const std::string& n : preview::environmentNames()) names += n + ",";
  c->add_option("--env", environment,
                "Environment: a procedural one, or a Radiance image in the lat-long layout (docs/render.md)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            const auto known = preview::environmentNames();
            if (std::find(known.begin(), known.end(), v) != known.end() || preview::isEnvironmentFile(v)) return "";
            std::string list;
            for (const std::string& n : known) list += n + ", ";
            return "expected " + list + "or a .hdr file, got '" + v + "'";
          },
          "{" + names.substr(0, names.size() - 1) + "}|FILE.hdr"))
      ->capture_default_str();
}

/// An --env file is an input of the command, read and decoded (its cube maps
/// built and kept for the render) before anything is rendered: a file that
/// cannot be is an error at its path, exit 1.
int checkEnvironment(const std::string& environment, CommandOutputs& outputs, std::ostream& err) {
  if (!preview::isEnvironmentFile(environment)) return kExitOk;
  outputs.input(environment);
  if (int status = outputs.check(err); status != kExitOk) return status;
  try {
    (void)preview::environmentMaps(environment);
  } catch (const std::runtime_error& e) {
    err << environment << ": error: cannot use the environment: "
        << std::string_view(e.what()).substr(environment.size() + 2) << "\n";
    return kExitBadInput;
  }
  return kExitOk;
}

struct PreviewArgs {
  MaterialInput in;
  std::string output;
  CompileFlags compile;
  int size = 256;
  std::string environment = preview::kDefaultEnvironment;
  bool sweep = false;
  std::string target = "glsl";
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  double exposure = 0;
  std::string precision = "float";
  TextureFlags textures;
};

void addPreviewOptions(CLI::App* c, PreviewArgs& a) {
  addMaterialInput(c, a.in);
  addOutput(c, a.output, "PNG file to write");
  addBudgetOptions(c, a.compile);
  c->add_option("--size", a.size, "Image width and height in pixels")->transform(cli::inRange(16, 2048, "pixels"))
      ->capture_default_str();
  addEnvironmentOption(c, a.environment);
  c->add_flag("--sweep", a.sweep,
              "A contact sheet: the material at each simplification step, labelled with bytes and closures");
  c->add_option("--target", a.target, "Which generated language renders: glsl or hlsl")
      ->check(CLI::IsMember({"glsl", "hlsl"}))->capture_default_str();
  addDiffuseOption(c, a.diffuse);
  c->add_option("--exposure", a.exposure,
                "Exposure in stops on top of the calibrated one (0: a white Lambertian facing the camera is display "
                "white before the tone curve)")
      ->transform(cli::inRange(-16.0, 16.0, "stops"))->capture_default_str();
  addMaxInputSize(c, a.compile);
  addPrecisionOption(c, a.precision);
  addTextureOptions(c, a.textures);
}

/// What preview renders: the material, or (--sweep) each of its simplification steps.
int previewSteps(const PreviewArgs& a, const import::MaterialSource& s, const CompileOptions& o,
                 std::vector<sweep::Step>& steps, std::ostream& err) {
  if (a.sweep) {
    CompileResult full;
    if (int failed = simplificationSteps(s, o, steps, full, err); failed != kExitOk) return failed;
    const std::string dropped = dropUnpackableSteps(steps);
    if (!dropped.empty())
      err << fmt::format("note: {} is not rendered: the storage format packs at most {}\n", dropped,
                         packfmt::kMaxClosures);
    return kExitOk;
  }
  Diagnostics diags(s.displayName);
  auto r = compileText(s.displayName, s.text, o, diags);
  err << diags.formatAll();
  if (!r) return compileFailure(s, err);
  steps.push_back({std::move(*r), "", 0});
  return kExitOk;
}

/// The preview: the sphere, or (--sweep) a contact sheet of the steps'
/// spheres labelled with their bytes and closures; nullopt, with the
/// internal error printed, when a render fails.
std::optional<preview::Image> renderPreview(const PreviewArgs& a, gpu::Context& ctx,
                                            const std::vector<sweep::Step>& steps,
                                            const preview::BoundTextures& textures, std::ostream& err) {
  preview::RenderOptions ro;
  ro.textures = &textures;
  ro.size = a.size;
  ro.environment = a.environment;
  ro.target = a.target == "hlsl" ? Target::Hlsl : Target::Glsl;
  ro.diffuseModel = diffuseModelOf(a.diffuse);
  ro.precision = precisionOf(a.precision);
  ro.exposure = a.exposure;
  std::vector<preview::Image> tiles;
  std::vector<std::string> labels;
  for (const auto& e : steps) {
    preview::Image hdr;
    Diagnostics failure(e.result.material.name);
    if (!preview::renderSphere(ctx, e.result, ro, &hdr, failure)) {
      printInternalError(err, failure.errorMessages());
      return std::nullopt;
    }
    tiles.push_back(preview::tonemap(hdr, a.exposure, preview::calibrationGains(a.environment)));
    const int closures = static_cast<int>(e.result.after.closures.size());
    labels.push_back(fmt::format("{}: {} B, {} cl", e.label, e.result.after.bytes(), closures));
  }
  if (!a.sweep) return tiles.front();
  return preview::contactSheet(tiles, labels, std::min<int>(4, static_cast<int>(tiles.size())));
}

/// Renders the material (or, with --sweep, a labelled contact sheet of its
/// simplification steps) on lavapipe and writes an 8-bit sRGB PNG.
int runPreview(const PreviewArgs& a, std::ostream& out, std::ostream& err) {
  const CompileOptions o = toCompileOptions(a.compile);
  CommandOutputs outputs(out);
  outputs.namedFile(a.output);
  int status = kExitOk;
  auto sources = loadFile(a.in, false, o.read, outputs, err, status);
  if (!sources) return status;  // its includes are checked too, before rendering
  std::vector<sweep::Step> steps;
  if (int failed = previewSteps(a, sources->front(), o, steps, err); failed != kExitOk) return failed;
  preview::BoundTextures textures;
  if (int failed = bindRenderTextures(a.textures, sources->front(), steps.front().result.material, o.read, outputs,
                                      &textures, err);
      failed != kExitOk)
    return failed;
  if (int status = outputs.check(err); status != kExitOk) return status;  // an image is an input too
  if (int failed = checkEnvironment(a.environment, outputs, err); failed != kExitOk) return failed;
  auto ctx = openGpu(a.precision, "preview renders on Vulkan (Mesa lavapipe)", err);
  if (!ctx) return kExitBadInput;
  std::optional<preview::Image> image = renderPreview(a, *ctx, steps, textures, err);
  if (!image) return kExitInternal;
  std::string png;
  if (int failed = srgbPng(*image, "preview", &png, err); failed != kExitOk) return failed;
  if (int failed = outputs.commit({{a.output, png}}, err); failed != kExitOk) return failed;
  out << a.output << "\n";
  return kExitOk;
}

// ----- render ------------------------------------------------------------------

struct RenderArgs {
  std::string model;
  std::string material;  // --material FILE[:NAME]: every primitive with it
  std::string output;
  CompileFlags compile;
  std::string size = "512x512";
  std::string camera;  // "": the document's first camera, else one that frames the scene; N; "frame"
  bool forward = false;
  std::string target = "glsl";
  std::string environment = preview::kDefaultEnvironment;
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  double exposure = 0;
  bool timings = false;
  TextureFlags textures;
  std::string platform;  // --platform: a built-in platform's budget and features
};

void addRenderOptions(CLI::App* c, RenderArgs& a) {
  c->add_option("model", a.model, "glTF 2.0 scene (.gltf or .glb)")->required();
  c->add_option("--material", a.material,
                "Draw every primitive with this material instead of the document's own: FILE, or FILE:NAME for one "
                "material of a .gltf, .glb, .materials.json or .mtlx file")
      ->type_name("FILE[:NAME]");
  addOutput(c, a.output, "PNG file to write");
  addBudgetOptions(c, a.compile);
  c->add_option("--size", a.size, "Image size in pixels, WxH (16 to 4096 a side)")->capture_default_str();
  c->add_option("--camera", a.camera,
                "The document's camera N (0-based, in node order), or 'frame' for one that frames the scene "
                "(default: the document's first camera, else 'frame')");
  c->add_option("--platform", a.platform,
                "Simplify every material for this platform (built in: " + PlatformTable::builtin().names() +
                    "; docs/scenes.md)");
  c->add_flag("--forward", a.forward, "Draw opaque materials with their forward pass instead of the deferred path");
  c->add_option("--target", a.target, "Which generated language renders: glsl or hlsl")
      ->check(CLI::IsMember({"glsl", "hlsl"}))->capture_default_str();
  addEnvironmentOption(c, a.environment);
  addDiffuseOption(c, a.diffuse);
  c->add_option("--exposure", a.exposure, "Exposure in stops on top of the calibrated one")
      ->transform(cli::inRange(-16.0, 16.0, "stops"))->capture_default_str();
  c->add_flag("--timings", a.timings,
              "Print each pass's GPU time (timestamp queries) and wall time (submissions) after the output's path");
  addMaxInputSize(c, a.compile);
  addTextureOptions(c, a.textures);
}

/// "WxH" -> width and height; kExitUsage (with the message) otherwise.
int parseImageSize(const std::string& text, int* width, int* height, std::ostream& err) {
  const std::size_t x = text.find('x');
  try {
    std::size_t used = 0;
    if (x != std::string::npos && x > 0) {
      *width = std::stoi(text.substr(0, x), &used);
      const bool whole = used == x;
      *height = std::stoi(text.substr(x + 1), &used);
      if (whole && used == text.size() - x - 1 && *width >= 16 && *height >= 16 && *width <= 4096 && *height <= 4096)
        return kExitOk;
    }
  } catch (const std::exception&) {
  }
  return printError(err, kExitUsage, fmt::format("--size: expected WxH with 16 to 4096 pixels a side, got '{}'", text));
}

/// The materials of the render: --material's, or the document's (and glTF's default).
std::optional<render::SceneSources> renderSources(const RenderArgs& a, const mesh::Scene& scene, const ReadLimits& read,
                                                  CommandOutputs& outputs, std::ostream& err, int& status) {
  if (!a.material.empty()) {
    MaterialInput in{a.material, ""};
    const std::size_t colon = a.material.rfind(':');
    if (colon != std::string::npos && colon > 0 && import::sourceKindOf(a.material.substr(0, colon)) !=
                                                       import::SourceKind::Substrate) {
      in.file = a.material.substr(0, colon);
      in.material = a.material.substr(colon + 1);
    }
    auto sources = loadFile(in, false, read, outputs, err, status);
    if (!sources) return std::nullopt;
    return render::oneMaterialSources(std::move(sources->front()), scene);
  }
  Diagnostics diags(a.model);
  auto sources = render::gltfSceneSources(a.model, scene, read, diags);
  err << diags.formatAll();
  if (!sources) status = kExitBadInput;
  return sources;
}

/// The camera --camera asks for: kExitUsage for a camera the document does not have.
int renderCamera(const RenderArgs& a, const mesh::Scene& scene, int width, int height, mesh::Camera* out,
                 std::ostream& err) {
  if (a.camera == "frame" || (a.camera.empty() && scene.cameras.empty())) {
    *out = mesh::framingCamera(scene, static_cast<double>(width) / height);
    return kExitOk;
  }
  std::size_t n = 0;
  if (!a.camera.empty()) {
    std::size_t used = 0;
    try {
      n = std::stoul(a.camera, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != a.camera.size() || n >= scene.cameras.size())
      return printError(err, kExitUsage,
                        fmt::format("--camera {}: {} has {} camera(s); give 0 to {} or 'frame'", a.camera, a.model,
                                    scene.cameras.size(), scene.cameras.empty() ? 0 : scene.cameras.size() - 1));
  }
  *out = scene.cameras[n];
  return kExitOk;
}

/// Compiles each source and binds its textures; the materials' results in `results` (kept alive).
int compileRenderMaterials(const RenderArgs& a, const render::SceneSources& s, const CompileOptions& o,
                           CommandOutputs& outputs, std::vector<CompileResult>* results,
                           std::vector<preview::BoundTextures>* textures, std::ostream& err) {
  results->resize(s.sources.size());
  textures->resize(s.sources.size());
  for (std::size_t i = 0; i < s.sources.size(); ++i) {
    const import::MaterialSource& src = s.sources[i];
    Diagnostics diags(src.displayName);
    auto r = compileText(src.displayName, src.text, o, diags);
    err << diags.formatAll();
    if (!r) return compileFailure(src, err);
    if (int volume = rejectVolume(r->material, src.displayName, "render", err); volume != kExitOk) return volume;
    (*results)[i] = std::move(*r);
    // --texture NAME=PATH binds every material's input NAME; a NAME no material has is an error below.
    TextureFlags flags{{}, a.textures.searchPaths};
    for (const std::string& t : a.textures.textures)
      for (const Input& in : (*results)[i].material.inputs)
        if (in.name == t.substr(0, t.find('='))) flags.textures.push_back(t);
    if (int failed = bindRenderTextures(flags, src, (*results)[i].material, o.read, outputs, &(*textures)[i], err);
        failed != kExitOk)
      return failed;
  }
  for (const std::string& t : a.textures.textures) {
    const std::string name = t.substr(0, t.find('='));
    bool used = false;
    for (const CompileResult& r : *results)
      for (const Input& in : r.material.inputs) used = used || (in.name == name && in.type == VType::Texture);
    if (!used) return printError(err, kExitUsage, fmt::format("--texture {}: no material of the render has a texture input of that name", name));
  }
  return kExitOk;
}

/// Draws a glTF scene with the emitted shaders on lavapipe (docs/render.md) and writes an sRGB PNG.
int runRender(const RenderArgs& a, std::ostream& out, std::ostream& err) {
  CompileOptions o = toCompileOptions(a.compile);
  if (!a.platform.empty()) {
    const PlatformTable table = PlatformTable::builtin();  // find() points into it
    const Platform* p = table.find(a.platform);
    if (!p)
      return printError(err, kExitUsage, fmt::format("unknown platform {} (known: {})", quoteForDiagnostic(a.platform),
                                                     table.names()));
    o.platform = *p;
  }
  int width = 0, height = 0;
  if (int status = parseImageSize(a.size, &width, &height, err); status != kExitOk) return status;
  CommandOutputs outputs(out);
  outputs.namedFile(a.output);
  outputs.input(a.model);
  if (int status = outputs.check(err); status != kExitOk) return status;
  Diagnostics meshDiags(a.model);
  mesh::MeshLimits limits;
  limits.maxFileBytes = std::max<std::size_t>(limits.maxFileBytes, o.read.maxInputBytes);
  auto scene = mesh::loadGltfScene(a.model, limits, meshDiags);
  err << meshDiags.formatAll();
  if (!scene) return kExitBadInput;
  for (const std::string& f : scene->files) outputs.input(f);
  int status = kExitOk;
  auto sources = renderSources(a, *scene, o.read, outputs, err, status);
  if (!sources) return status;
  std::vector<CompileResult> results;
  std::vector<preview::BoundTextures> textures;
  if (int failed = compileRenderMaterials(a, *sources, o, outputs, &results, &textures, err); failed != kExitOk)
    return failed;
  mesh::Camera camera;
  if (int failed = renderCamera(a, *scene, width, height, &camera, err); failed != kExitOk) return failed;
  if (int failed = outputs.check(err); failed != kExitOk) return failed;
  if (int failed = checkEnvironment(a.environment, outputs, err); failed != kExitOk) return failed;
  auto ctx = openGpu("float", "render draws on Vulkan (Mesa lavapipe)", err);
  if (!ctx) return kExitBadInput;
  std::vector<render::SceneMaterial> materials;
  for (std::size_t i = 0; i < results.size(); ++i) materials.push_back({&results[i], &textures[i]});
  render::RenderOptions ro;
  ro.width = width;
  ro.height = height;
  ro.forward = a.forward;
  ro.target = a.target == "hlsl" ? Target::Hlsl : Target::Glsl;
  ro.environment = a.environment;
  ro.diffuseModel = diffuseModelOf(a.diffuse);
  render::RenderResult result;
  Diagnostics failure(a.model);
  if (!render::renderScene(*ctx, *scene, materials, sources->primitiveMaterial, camera, ro, &result, failure))
    return printInternalError(err, failure.errorMessages());
  const std::array<double, 3> toCamera{-camera.forward[0], -camera.forward[1], -camera.forward[2]};
  const preview::Image image =
      preview::tonemap(result.hdr, a.exposure, render::renderCalibrationGains(a.environment, toCamera));
  std::string png;
  if (int failed = srgbPng(image, "render", &png, err); failed != kExitOk) return failed;
  if (int failed = outputs.commit({{a.output, png}}, err); failed != kExitOk) return failed;
  out << a.output << "\n";
  if (a.timings) {
    const render::RenderStats& st = result.stats;
    out << fmt::format("{} draws, {} of {} pixels covered (tiles: {} simple, {} single, {} complex, {} special)\n",
                       st.draws, st.coveredPixels, std::size_t(width) * height, st.tiles[0], st.tiles[1], st.tiles[2],
                       st.tiles[3]);
    out << fmt::format("GPU ms (timestamps): opaque {:.3f}, classify {:.3f}, lighting {:.3f}, forward {:.3f}\n",
                       st.opaqueNs * 1e-6, st.classifyNs * 1e-6, st.lightingNs * 1e-6, st.forwardNs * 1e-6);
    out << fmt::format("wall ms (submissions): opaque {:.3f}, classify {:.3f}, lighting {:.3f}, forward {:.3f}\n",
                       st.opaqueWallNs * 1e-6, st.classifyWallNs * 1e-6, st.lightingWallNs * 1e-6,
                       st.forwardWallNs * 1e-6);
  }
  return kExitOk;
}

// ----- sweep -------------------------------------------------------------------

struct SweepArgs {
  MaterialInput in;
  CompileFlags compile;
  bool json = false;
  bool csv = false;
  std::string plot;
  double maxError = -1;
  int pixels = 1 << 20;
  int runs = 5;
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
  int truthSamples = sweep::Options{}.truthSamples;
  int truthEvalSamples = sweep::Options{}.truthEvalSamples;
  int threads = 0;
  std::string precision = "float";
};

void addSweepOptions(CLI::App* c, SweepArgs& a) {
  addMaterialInput(c, a.in);
  CLI::Option* json = c->add_flag("--json", a.json, "Print {\"material\": ..., \"rows\": [...]}");
  c->add_flag("--csv", a.csv, "Print the rows as CSV (not with --json: one format on stdout)")->excludes(json);
  c->add_option("--plot", a.plot, "Also write an SVG plot of error against cost");
  c->add_option("--max-error", a.maxError, "Choose the cheapest row with rel_mse <= E and print its budget")
      ->transform(cli::inRange(0.0, 1e30, "(relative MSE)"));
  c->add_option("--pixels", a.pixels, "Shading points per timed dispatch")
      ->transform(cli::inRange(64, 1 << 24, "shading points"))->capture_default_str();
  c->add_option("--runs", a.runs, "Timed dispatches after the warm-up (the median is reported)")
      ->transform(cli::inRange(1, 100, "runs"))->capture_default_str();
  addDiffuseOption(c, a.diffuse);
  addMaxInputSize(c, a.compile);
  c->add_option("--truth-samples", a.truthSamples,
                "Random walks per truth albedo (per NoV and channel group; 0: no truth columns)")
      ->transform(cli::inRange(0, 1 << 22, "walks"))->capture_default_str();
  c->add_option("--truth-eval-samples", a.truthEvalSamples,
                "Random walks per truth BRDF grid point (per channel group)")
      ->transform(cli::inRange(1, 1 << 22, "walks"))->capture_default_str();
  c->add_option("-j,--jobs", a.threads, "Threads of the truths (the results do not depend on them)")
      ->transform(cli::inRange(1, 256, "threads"))->default_str("the machine's threads");
  addPrecisionOption(c, a.precision);
}

/// The rows in the format asked for, the --plot written, and with
/// --max-error the cheapest row within it (on stderr when stdout is JSON or CSV).
int printSweep(const SweepArgs& a, const std::string& name, const std::vector<sweep::Row>& rows,
               const CommandOutputs& outputs, std::ostream& out, std::ostream& err) {
  if (!a.plot.empty())
    if (int status = outputs.commit({{a.plot, sweep::plotSvg(name, rows)}}, err); status != kExitOk) return status;
  if (a.json) out << sweep::formatJson(name, rows);
  else if (a.csv) out << sweep::formatCsv(rows);
  else out << sweep::formatTable(name, rows);
  if (a.maxError < 0) return kExitOk;
  auto best = sweep::cheapestWithin(rows, a.maxError);
  if (!best)
    return printError(err, kExitBadInput,
                      fmt::format("no step of '{}' is within rel_mse {} (the first row's is {:.3e})", name,
                                  a.maxError, rows.empty() ? 0.0 : rows.front().relMse));
  const sweep::Row& row = rows[*best];
  (a.json || a.csv ? err : out) << fmt::format("budget {} ({}: {} B, {} closures, rel_mse {:.3e})\n", row.budget,
                                               row.label, row.bytes, row.closures, row.relMse);
  return kExitOk;
}

/// A volume's sweep (sweep/volume_sweep.h): nothing simplifies it, so its
/// rows are step counts of its march, lavapipe ns per ray against the error,
/// and --plot draws them. --csv and --max-error choose among simplification
/// steps: a usage error here.
int volumeSweep(const SweepArgs& a, const import::MaterialSource& s, const CompileResult& r,
                const CommandOutputs& outputs, std::ostream& out, std::ostream& err) {
  if (a.csv || a.maxError >= 0)
    return printError(err, kExitUsage,
                      fmt::format("{}: '{}' is a volume: its sweep is step counts of its march (the table, --json or "
                                  "--plot); --csv and --max-error are for surfaces' simplification steps",
                                  s.displayName, r.material.name));
  auto ctx = openGpu(a.precision, "sweep times the generated code on Vulkan (Mesa lavapipe)", err);
  if (!ctx) return kExitBadInput;
  sweep::Options so;
  so.pixels = a.pixels;
  so.timedRuns = a.runs;
  std::vector<sweep::VolumeRow> rows;
  Diagnostics failure(r.material.name);
  if (!sweep::measureVolume(*ctx, r, so, &rows, failure)) return printInternalError(err, failure.errorMessages());
  if (!a.plot.empty())
    if (int status = outputs.commit({{a.plot, sweep::plotVolumeSvg(r.material.name, rows)}}, err); status != kExitOk)
      return status;
  out << (a.json ? sweep::formatVolumeJson(r.material.name, rows) : sweep::formatVolumeTable(r.material.name, rows));
  return kExitOk;
}

/// The material at its full budget and at each simplification step: cost
/// (bytes, closures, instructions, lavapipe time) against error (vs the
/// authored tree; the accuracy metric against the truths). --max-error
/// chooses the cheapest measured row within the error.
int runSweep(const SweepArgs& a, std::ostream& out, std::ostream& err) {
  const CompileOptions o = toCompileOptions(a.compile);
  CommandOutputs outputs(out);
  outputs.namedFile(a.plot);
  int status = kExitOk;
  auto sources = loadFile(a.in, false, o.read, outputs, err, status);
  if (!sources) return status;  // its includes are checked too, before measuring
  std::vector<sweep::Step> steps;
  CompileResult full;
  if (int failed = simplificationSteps(sources->front(), o, steps, full, err); failed != kExitOk) return failed;
  if (isVolumeMaterial(full.material)) return volumeSweep(a, sources->front(), full, outputs, out, err);
  auto ctx = openGpu(a.precision, "sweep times the generated code on Vulkan (Mesa lavapipe)", err);
  if (!ctx) return kExitBadInput;
  sweep::Options so;
  so.pixels = a.pixels;
  so.timedRuns = a.runs;
  so.diffuseModel = diffuseModelOf(a.diffuse);
  so.truthSamples = a.truthSamples;
  so.truthEvalSamples = a.truthEvalSamples;
  so.truthThreads = a.threads;
  so.precision = precisionOf(a.precision);
  std::vector<sweep::Row> rows;
  Diagnostics failure(full.material.name);
  if (!sweep::measure(*ctx, steps, full, so, &rows, failure)) return printInternalError(err, failure.errorMessages());
  return printSweep(a, full.material.name, rows, outputs, out, err);
}

// ----- accuracy ----------------------------------------------------------------

struct AccuracyArgs {
  MaterialInput in;
  CompileFlags compile;
  bool json = false;
  int samples = accuracy::Options{}.samples;
  int evalSamples = accuracy::Options{}.evalSamples;
  int threads = 0;
  std::string diffuse{diffuseModelName(kDefaultDiffuseModel)};
};

void addAccuracyOptions(CLI::App* c, AccuracyArgs& a) {
  addMaterialInput(c, a.in);
  addBudgetOptions(c, a.compile,
                   {"Bytes per pixel budget (overrides settings.bytes_per_pixel)",
                    "Closure budget (overrides settings.max_closures)"});
  c->add_flag("--json", a.json, "Print the comparison as JSON (docs/accuracy.md)");
  c->add_option("--samples", a.samples, "Random walks per truth albedo (per NoV and channel group)")
      ->transform(cli::inRange(1, 1 << 22, "walks"))->capture_default_str();
  c->add_option("--eval-samples", a.evalSamples, "Random walks per truth BRDF grid point (per channel group)")
      ->transform(cli::inRange(1, 1 << 22, "walks"))->capture_default_str();
  c->add_option("-j,--jobs", a.threads, "Threads (the results do not depend on them)")
      ->transform(cli::inRange(1, 256, "threads"))->default_str("the machine's threads");
  addDiffuseOption(c, a.diffuse);
  addMaxInputSize(c, a.compile);
}

/// `accuracy` of a volume (accuracy/fog_accuracy.h): its march against step
/// counts, and its froxel payload's error; no ray to compare (nothing emits or
/// scatters) is bad input, like a black truth.
int volumeAccuracy(const import::MaterialSource& s, const CompileResult& r, bool json, std::ostream& out,
                   std::ostream& err) {
  const accuracy::FogReport report = accuracy::fogAccuracy(r.material, r.after.bytes());
  out << (json ? accuracy::fogJson(report).dump(2) + "\n" : accuracy::formatFogTable(report));
  if (report.rays > 0) return kExitOk;
  return printError(err, kExitBadInput,
                    fmt::format("{}: no accuracy to report: no ray through the volume has any radiance (the medium "
                                "neither emits nor scatters)",
                                s.displayName));
}

/// `accuracy`: the material as compiled (its settings, --budget,
/// --full-simplification) against the Monte Carlo truth of the authored
/// material (compiled without simplification) and, when they differ, against
/// the truth of the compiled closures. A comparison with problems (a black
/// truth: nothing to compare) is printed and exits with bad input.
int runAccuracy(const AccuracyArgs& a, std::ostream& out, std::ostream& err) {
  const CompileOptions o = toCompileOptions(a.compile);
  CommandOutputs outputs(out);
  int status = kExitOk;
  auto sources = loadFile(a.in, false, o.read, outputs, err, status);
  if (!sources) return status;
  const import::MaterialSource& s = sources->front();
  const CompileOptions unsimplified = unsimplifiedOptions(o);
  Diagnostics diags(s.displayName), ignored(s.displayName);
  auto compiled = compileText(s.displayName, s.text, o, diags);
  err << diags.formatAll();
  if (!compiled) return compileFailure(s, err);
  auto authored = compileText(s.displayName, s.text, unsimplified, ignored);  // compiled: so does the authored tree
  if (!authored) return printInternalError(err, "the unsimplified material does not compile: " + ignored.errorMessages());
  if (isVolumeMaterial(authored->material)) return volumeAccuracy(s, *authored, a.json, out, err);
  if (authored->after.closures.empty())  // unlit nodes only: nothing reflects, so there is no BRDF to measure
    return printError(err, kExitBadInput,
                      fmt::format("{}: no accuracy to report: the material has no closure (unlit nodes only): it "
                                  "reflects nothing",
                                  s.displayName));
  accuracy::Options ao;
  ao.samples = a.samples;
  ao.evalSamples = a.evalSamples;
  ao.threads = a.threads;
  ao.diffuseModel = diffuseModelNumber(diffuseModelOf(a.diffuse));
  accuracy::Report report;
  report.material = compiled->material.name;
  report.bytes = compiled->after.bytes();
  report.closures = static_cast<int>(compiled->after.closures.size());
  report.options = ao;
  const accuracy::Analytic analytic = accuracy::analyticOf(*compiled, ao);
  report.vsAuthored = accuracy::compare(analytic, accuracy::truthOf(*authored, ao));
  const bool differs = !compiled->steps.empty() || compiled->after.bytes() != authored->after.bytes() ||
                       compiled->after.closures.size() != authored->after.closures.size();
  if (differs) report.vsCompiled = accuracy::compare(analytic, accuracy::truthOf(*compiled, ao));
  out << (a.json ? accuracy::formatJson(report) : accuracy::formatTable(report));
  if (report.vsAuthored.problems.empty()) return kExitOk;
  std::string problems;
  for (const auto& p : report.vsAuthored.problems) problems += (problems.empty() ? "" : "; ") + p;
  return printError(err, kExitBadInput, fmt::format("{}: no accuracy to report: {}", s.displayName, problems));
}

// ----- stability ---------------------------------------------------------------

struct StabilityArgs {
  MaterialInput in;
  CompileFlags compile;
  bool json = false;
  long evaluations = 100000;
  bool noGpu = false;
  bool gpuOnly = false;
  std::string precision = "float";
  bool stressTextures = false;
};

void addStabilityOptions(CLI::App* c, StabilityArgs& a) {
  addMaterialInput(c, a.in);
  c->add_flag("--json", a.json, "Print the counts and the worst cases as JSON");
  c->add_option("--evaluations", a.evaluations, "Shading points to evaluate at least (each path)")
      ->transform(cli::inRange(1L, 100000000L, "shading points"))->capture_default_str();
  c->add_flag("--no-gpu", a.noGpu, "CPU reference only");
  c->add_flag("--gpu-only", a.gpuOnly, "The generated shaders only (no CPU reference, no furnace)")->excludes("--no-gpu");
  addBudgetOptions(c, a.compile, {"Bytes per pixel budget", "Closures per pixel", "Collapse to one closure first"});
  addMaxInputSize(c, a.compile);
  addPrecisionOption(c, a.precision);
  c->add_flag("--stress-textures", a.stressTextures,
              "Bind every texture to the GPU tests' checker (normal maps tilt, half below the surface) instead of "
              "its neutral value (flat normal, mid-grey)");
}

/// One material of `stability`: its report, or the status it adds (`fatal`:
/// an internal error that ends the command).
struct StabilityOutcome {
  int status = kExitOk;
  bool fatal = false;
  std::optional<stability::Report> report;
};

StabilityOutcome stabilityOf(const import::MaterialSource& source, const CompileOptions& o,
                             const stability::Options& so, gpu::Context* ctx, std::ostream& err) {
  {  // The material as written: its diagnostics name its own lines.
    Diagnostics diags(source.displayName);
    auto written = compileText(source.displayName, source.text, o, diags);
    if (!written) {
      err << diags.formatAll();
      return {compileFailure(source, err), false, std::nullopt};
    }
    if (int volume = rejectVolume(written->material, source.displayName, "stability's grid", err); volume != kExitOk)
      return {volume, false, std::nullopt};
  }
  std::string forceable;
  std::vector<stability::ForcedKind> kinds;
  Diagnostics failure(source.displayName);
  if (!stability::forceableText(source.text, &forceable, &kinds, failure))
    return {printError(err, kExitBadInput, source.displayName + ": " + failure.errorMessages()), false, std::nullopt};
  const std::string forcingName = source.displayName + " (with forcing inputs)";
  Diagnostics diags(forcingName);
  auto r = compileText(forcingName, forceable, stability::forcingOptions(o, kinds), diags);
  if (!r) {
    printInternalError(err, "the material with forcing inputs does not compile");
    err << diags.formatAll();
    return {kExitInternal, true, std::nullopt};
  }
  stability::Report report;
  if (!stability::run(*r, kinds, so, ctx, &report, failure))
    return {printInternalError(err, failure.errorMessages()), true, std::nullopt};
  return {kExitOk, false, std::move(report)};
}

/// The material on the hard-case grid (compiler/tools/stability/stability.h): counts
/// of non-finite values on the CPU reference and on lavapipe, and the white
/// furnace. Exit 4 when anything is non-finite or the furnace exceeds 1.001.
int runStability(const StabilityArgs& a, std::ostream& out, std::ostream& err) {
  const CompileOptions o = toCompileOptions(a.compile);
  CommandOutputs outputs(out);  // writes only standard output
  int status = kExitOk;
  // Every material of a glTF or MaterialX file without --material (like `report`).
  auto sources = loadFile(a.in, true, o.read, outputs, err, status);
  if (!sources) return status;
  std::unique_ptr<gpu::Context> ctx;
  if (!a.noGpu) {
    ctx = openGpu(a.precision, "stability runs the generated code on Vulkan (Mesa lavapipe; --no-gpu skips it)", err);
    if (!ctx) return kExitBadInput;
  }
  stability::Options so;
  so.evaluations = a.evaluations;
  so.gpu = !a.noGpu;
  so.cpu = !a.gpuOnly;
  so.precision = precisionOf(a.precision);
  so.textures = a.stressTextures ? gpu::TextureSet::Checker : gpu::TextureSet::Neutral;
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  bool first = true;
  for (const import::MaterialSource& source : *sources) {
    StabilityOutcome outcome = stabilityOf(source, o, so, ctx.get(), err);
    if (outcome.fatal) return kExitInternal;
    status = std::max(status, outcome.status);
    if (!outcome.report) continue;
    const stability::Report& report = *outcome.report;
    if (a.json) all.push_back(stability::toJson(report));
    else out << (first ? "" : "\n") << stability::formatText(report);
    first = false;
    if (!stability::furnaceExercised(report))
      printError(err, kExitOk,
                 fmt::format("{}: the furnace was never exercised: none of its {} evaluations returned any light{}",
                             source.displayName, report.furnaceEvaluations,
                             a.stressTextures ? " (--stress-textures binds a checker that, read as a normal map, "
                                                "points below the surface)"
                                              : ""));
    if (!stability::passed(report)) status = std::max(status, static_cast<int>(kExitUnstable));
  }
  // One material: its object (as before); several: an array, in file order.
  if (a.json && !all.empty()) printJson(all, sources->size() == 1, out);
  return status;
}

// ----- import ------------------------------------------------------------------

struct ImportArgs {
  MaterialInputs in;
  std::string outDir;
  CompileFlags compile;
  bool force = false;
  bool expand = false;
};

void addImportOptions(CLI::App* c, ImportArgs& a) {
  addMaterialFiles(c, a.in.files, "The .gltf, .glb, .materials.json or .mtlx files, and directories to search for them");
  addOutput(c, a.outDir, "Output directory (one <material>.json per material)");
  addMaterialChoice(c, a.in.material, "Import only this material (by name or identifier)");
  c->add_flag("--force", a.force, "Replace files in the output directory that an import of the same source did not write");
  c->add_flag("--expand", a.expand,
              "Write each material's building block (gltf_pbr, standard_surface, open_pbr_surface, disney_principled) "
              "as the slabs, operators and value nodes it stands for");
  addMaxInputSize(c, a.compile);
}

/// Every material of the import inputs, named uniquely across the files
/// (case-insensitively: they become file names), with the input each comes
/// from in `sourceOf`; false when a file does not import.
bool importAll(const std::vector<import::ImportInput>& inputs, const ReadLimits& read, import::ImportForm form,
               std::ostream& err, std::vector<import::ImportedMaterial>& materials, std::vector<std::string>& sourceOf) {
  import::NameSet names(/*caseInsensitive=*/true);
  bool failed = false;
  for (const import::ImportInput& in : inputs) {
    Diagnostics diags(in.path);
    auto imported = import::importFile(in.path, read, diags, form);
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
      if (inputs.size() > 1) m.location = in.path + " " + m.location;
      materials.push_back(std::move(m));
      sourceOf.push_back(in.path);
    }
  }
  return !failed;
}

/// --material of `import`: only that material is kept.
int pickImported(const std::string& material, const std::vector<import::ImportInput>& inputs,
                 std::vector<import::ImportedMaterial>& materials, std::vector<std::string>& sourceOf,
                 std::ostream& err) {
  Diagnostics diags(inputs.size() == 1 ? inputs.front().path : "");
  const import::ImportedMaterial* m = import::pickMaterial(materials, material, diags);
  if (inputs.size() == 1) err << diags.formatAll();
  else for (const Diagnostic& d : diags.all()) printError(err, kExitBadInput, d.message);  // several files
  if (!m) return kExitBadInput;
  const std::size_t i = static_cast<std::size_t>(m - materials.data());
  materials = {materials[i]};
  sourceOf = {sourceOf[i]};
  return kExitOk;
}

/// Nothing is replaced that an import of the same source did not write
/// (without --force): kExitUsage, each such file named. An output that is one
/// of the files read is left to writeOutputs: that it is an input is the
/// truer message.
int refuseForeign(const ImportArgs& a, const std::vector<OutputFile>& files, const std::vector<std::string>& sourceOf,
                  const CommandOutputs& outputs, std::ostream& err) {
  if (a.force) return kExitOk;
  int status = kExitOk;
  const std::vector<InputFile> inputsRead = outputs.inputs();
  for (std::size_t i = 0; i < files.size(); ++i) {
    const std::string path = (std::filesystem::path(a.outDir) / files[i].name).string();
    if (!sameFileAsInput({path}, inputsRead).empty()) continue;
    const std::string source = std::filesystem::path(sourceOf[i]).filename().string();
    if (import::replaceCheck(path, files[i].contents, source) == import::Replace::Foreign)
      status = printError(err, kExitUsage,
                          fmt::format("{} exists and was not written by importing {} (it is not the same text, nor a "
                                      "material whose description begins \"Imported from {} \"): not replaced; "
                                      "--force replaces it",
                                      path, source, source));
  }
  return status;
}

/// `import`: every material of glTF / MaterialX files and of the importable
/// files under directories (or the --material one) as substrate-material/1
/// files in the output directory, all or none; each is compiled first, so what
/// is written is known to compile. A file in the way is replaced only when an
/// import of the same source wrote it (import::replaceCheck), or with --force.
int runImport(const ImportArgs& a, std::ostream& out, std::ostream& err) {
  const ReadLimits read = toCompileOptions(a.compile).read;
  std::string messages;
  auto inputs = import::collectImportInputs(a.in.files, messages);
  err << messages;
  if (!inputs) return kExitBadInput;
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  for (const import::ImportInput& in : *inputs) outputs.input(in.path);
  if (int status = outputs.check(err); status != kExitOk) return status;
  std::vector<import::ImportedMaterial> materials;
  std::vector<std::string> sourceOf;  // the input each material comes from
  if (!importAll(*inputs, read, a.expand ? import::ImportForm::Expanded : import::ImportForm::Blocks, err, materials,
                 sourceOf)) return kExitBadInput;
  if (!a.in.material.empty())
    if (int status = pickImported(a.in.material, *inputs, materials, sourceOf, err); status != kExitOk) return status;
  std::vector<OutputFile> files;
  std::vector<std::string> fileSource;  // the input each file comes from
  for (std::size_t i = 0; i < materials.size(); ++i) {
    import::rebaseImageFiles(materials[i], std::filesystem::path(sourceOf[i]).parent_path().string(), a.outDir);
    const import::ImportedMaterial& m = materials[i];
    const import::MaterialSource source{sourceOf[i] + "[" + m.name + "]", m.text, true, "", {}};
    Diagnostics compileDiags(source.displayName);
    if (!compileText(source.displayName, m.text, CompileOptions{}, compileDiags)) {
      err << compileDiags.formatAll();
      return compileFailure(source, err);
    }
    files.push_back({m.name + ".json", m.text});
    fileSource.push_back(sourceOf[i]);
    for (const auto& image : m.images) {  // embedded images, beside the materials that name them
      const std::string& file = image.first;
      auto same = std::find_if(files.begin(), files.end(), [&](const OutputFile& f) { return f.name == file; });
      if (same != files.end() && same->contents != image.second)
        return printError(err, kExitBadInput,
                          fmt::format("{} and {} both embed an image written as {}: import them into different "
                                      "directories",
                                      fileSource[same - files.begin()], sourceOf[i], file));
      if (same != files.end()) continue;
      files.push_back({file, image.second});
      fileSource.push_back(sourceOf[i]);
    }
  }
  if (int status = refuseForeign(a, files, fileSource, outputs, err); status != kExitOk) return status;
  return writeOutputs(outputs, a.outDir, files, "", {}, {}, out, err);
}

// ----- scene -------------------------------------------------------------------

struct SceneArgs {
  std::string manifest;
  std::string outDir;
  CompileFlags compile;
  BuildFlags build;
};

void addSceneOptions(CLI::App* c, SceneArgs& a) {
  c->add_option("manifest", a.manifest, "Scene manifest (substrate-scene/1 JSON)")->required();
  addOutput(c, a.outDir, "Output directory");
  addPlatformOptions(c, a.build,
                     "Platform to build for, overriding the manifest's (built in: " + PlatformTable::builtin().names() +
                         "; more with --platforms)");
  addJobsOption(c, a.build.jobs);
  addTargetOption(c, a.build.target);
  addDiffuseOption(c, a.build.diffuse);
  addBudgetOptions(c, a.compile,
                   {"Bytes per pixel budget of every material (the platform still caps it)",
                    "Closure budget of every material", ""});
  addMaxInputSize(c, a.compile);
  c->add_option("--cache", a.build.cache, "Content-hash cache directory for the materials");
  c->add_option("--depfile", a.build.depfile,
                "Write a Make-syntax dependency file: the outputs depend on the manifest, the platforms file and "
                "every material");
}

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

/// Every material of a scene for its platform, and the lighting the scene
/// needs (scene/scene.h), written atomically into the output directory.
int runScene(const SceneArgs& a, std::ostream& out, std::ostream& err) {
  SceneOptions o;
  o.manifest = a.manifest;
  if (!a.build.platform.empty()) o.platform = a.build.platform;
  o.platformsFile = a.build.platforms;
  o.batch = toBatchOptions(a.compile, a.build);
  CommandOutputs outputs(out);
  outputs.directory(a.outDir);
  outputs.namedFile(a.build.depfile);
  outputs.directory(a.build.cache);
  outputs.input(a.manifest);
  outputs.input(a.build.platforms);
  if (int status = outputs.check(err); status != kExitOk) return status;
  SceneBuild b = buildScene(o);
  err << b.messages;
  if (b.status != SceneStatus::Ok) return exitCode(b.status);
  // The scene's depfile has one target, scene.json: which lighting files a
  // scene has depends on its materials, so a build system cannot list them
  // beforehand; it depends on scene.json (written with them, atomically).
  return writeOutputs(outputs, a.outDir, b.files, a.build.depfile, b.inputs, b.cacheEntries, out, err, "scene.json");
}

// ----- The command table and the dispatcher ------------------------------------

/// A command: its CLI11 subcommand, and what runs when it was parsed.
struct Command {
  CLI::App* app;
  std::function<int(std::ostream& out, std::ostream& err)> run;
};

/// Adds the subcommand `name` with the options `addOptions` gives its Args,
/// run by `run`.
template <typename Args>
Command command(CLI::App& app, const char* name, const char* help, void (*addOptions)(CLI::App*, Args&),
                int (*run)(const Args&, std::ostream&, std::ostream&)) {
  auto args = std::make_shared<Args>();
  CLI::App* sub = app.add_subcommand(name, help);
  addOptions(sub, *args);
  return {sub, [args, run](std::ostream& out, std::ostream& err) { return run(*args, out, err); }};
}

std::string versionLine() { return "substratec 0.1.0 (" + toolchainVersions() + ")"; }

/// No command, or a word that is none of them: say so and list them (CLI11
/// alone says "A subcommand is required" or "arguments were not expected").
int checkCommandWord(const CLI::App& app, const std::vector<std::string>& args, std::ostream& err) {
  std::string commands;
  bool known = false;
  for (const CLI::App* c : app.get_subcommands({})) {
    commands += (commands.empty() ? "" : ", ") + c->get_name();
    known = known || (!args.empty() && c->check_name(args[0]));
  }
  if (!args.empty() && (known || args[0].empty() || args[0][0] == '-')) return kExitOk;
  const std::string what = args.empty() ? std::string("a command is required") : "unknown command " + quoteForDiagnostic(args[0]);
  return printUsageError(err, fmt::format("{} (the commands: {})", what, commands));
}

/// Parses `args` into `app`; the exit status when parsing is the end of it
/// (help, version, a usage error), else nullopt.
std::optional<int> parse(CLI::App& app, const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
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
    out << versionLine() << "\n";
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    return printUsageError(err, e.what());
  }
  return std::nullopt;
}

}  // namespace

int runCli(const std::vector<std::string>& commandLine, std::ostream& out, std::ostream& err) {
  const std::optional<std::vector<std::string>> expanded = expandArgumentFiles(commandLine, err);
  if (!expanded) return kExitUsage;
  const std::vector<std::string>& args = *expanded;
  CLI::App app{"substratec: compiles Substrate material graphs (substrate-material/1) into priced, simplified, "
               "flattened shaders",
               "substratec"};
  app.require_subcommand(1);
  app.set_version_flag("--version", versionLine());
  const std::vector<Command> commands = {
      command(app, "report", "Print the tree, features, byte budget and layout of materials", addReportOptions,
              runReport),
      command(app, "compile", "Generate flattened GLSL/HLSL, the packing layout and entry shaders", addCompileOptions,
              runCompile),
      command(app, "preview", "Render the material on a sphere (Vulkan, Mesa lavapipe) into a PNG", addPreviewOptions,
              runPreview),
      command(app, "render",
              "Draw a glTF scene with the emitted shaders in raster passes (Vulkan, Mesa lavapipe) into a PNG "
              "(docs/render.md)",
              addRenderOptions, runRender),
      command(app, "sweep", "Cost against error at the full budget and at each simplification step", addSweepOptions,
              runSweep),
      command(app, "accuracy",
              "The shipping model against the Monte Carlo truth: albedo, BRDF, reciprocity and furnace per NoV "
              "(docs/accuracy.md)",
              addAccuracyOptions, runAccuracy),
      command(app, "stability", "Hard cases: non-finite values on the CPU and on lavapipe, white furnace",
              addStabilityOptions, runStability),
      command(app, "import",
              "Import glTF 2.0 (.gltf, .glb, .materials.json) or MaterialX (.mtlx) materials as substrate-material/1 "
              "files (docs/import.md)",
              addImportOptions, runImport),
      command(app, "scene", "Compile a scene's materials for its platform and the lighting it needs (docs/scenes.md)",
              addSceneOptions, runScene),
  };
  if (int status = checkCommandWord(app, args, err); status != kExitOk) return status;
  if (std::optional<int> status = parse(app, args, out, err)) return *status;
  try {
    for (const Command& c : commands)
      if (c.app->parsed()) return c.run(out, err);
  } catch (const std::exception& e) {
    return printInternalError(err, e.what());
  }
  return kExitUsage;
}

}  // namespace substratec
