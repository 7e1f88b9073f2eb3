// Generated-shader cost (issue 6, docs/performance.md "Generated-shader cost"):
// what the code substratec generates costs to run, on lavapipe, against a
// hand-written floor. Not a test; bench/shader_cost.sh builds and runs it.
//
//   1. floor:     the Throughput kernel of a simple one-slab material
//                 (examples/row12_simple.json) against a hand-written minimal
//                 GGX + Lambert kernel (bench/shaders/minimal_ggx_lambert.comp,
//                 read and compiled at run time with the project's glslang path,
//                 compileAndValidate) doing the same job: ns per pixel, ratios,
//                 SPIR-V instructions. The hand-written file is compiled five
//                 ways: its environment BRDF from Karis' analytic fit ("floor
//                 (Karis)") or from the runtime's tables ("floor (tables)"), the
//                 Karis one with constant parameters, with the runtime's model
//                 (energy compensation, Chan 2024), and its prologue alone.
//   2. closures:  synthetic materials (horizontal mixes of N distinct slabs,
//                 written here in substrate-material/1) with 1, 2, 3, 4, 6, 8
//                 closures: optimized forward-shader instructions and ns per
//                 pixel, with least-squares lines (value = a + b N) and R².
//   3. examples:  every examples/*.json at budgets {own, 80, 48, 20, full
//                 simplification}: bytes, closures, forward instructions, ns/pixel.
//   4. diffuse:   one material under each diffuse model: instructions, ns/pixel.
//   5. half:      every example at its own budget in float32 and in half
//                 precision (`--precision half`, EmitOptions::precision): ns/pixel
//                 of both (the two kernels of an example timed in the same
//                 interleaved rounds), optimized forward-shader instructions, and
//                 rel_mse, max |Δ| and max |Δ|/|f| of the half kernel's output
//                 against float32's (docs/stability.md, "Half precision").
//
// Timing: the material's Throughput kernel (compiler/core/emit/kernel_emitter.h:
// each invocation hashes its own shading point, evaluates the material, lights
// it with one light and a constant split-sum environment, writes one float4),
// compiled as `substratec sweep` compiles it (compileKernel: glslang, SPIR-V as
// validated, no SPIRV-Tools optimization; lavapipe optimizes it itself), one
// dispatch of `--pixels` invocations timed with GPU timestamps
// (gpu::Context::dispatch). The kernels compared with each other (one table
// row group) are dispatched in interleaved rounds: one untimed warm-up round,
// then `--runs` timed rounds, each dispatching every kernel of the group once
// (alternately in order and in reverse order);
// the median per kernel is reported, and ratios are of those medians. Kernels
// whose generated code is byte-identical (two budgets that give the same
// material) are compiled and timed once.
//
// Forward-shader instructions: the GLSL forward entry (`<name>.forward.frag`)
// after SPIRV-Tools' performance passes, as `substratec report --spirv` counts it.
//
// Usage: shader_cost [--pixels N] [--runs N] [--parts 12345] [--dump DIR] [--extra DIR] [--callgrind]
//   --dump DIR   writes the timed kernels' sources and the synthetic materials to DIR.
//   --extra DIR  also times every DIR/*.comp in part 1's group (row12_simple's
//                resources; includes found in DIR first, then in the embedded
//                runtime), e.g. a variant of the runtime or of a generated kernel.
//   --callgrind  parts 1, 2, 4 and 5, no timing: one instrumented dispatch per kernel
//                for callgrind (x86 instructions executed per pixel, deterministic);
//                SHADER_COST_CALLGRIND=1 bench/shader_cost.sh runs and sums it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define SHADER_COST_HAVE_CALLGRIND 1
#else
#define SHADER_COST_HAVE_CALLGRIND 0
#endif

#include "pipeline/generate.h"
#include "emit/kernel_emitter.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "pipeline/pipeline.h"
#include "sweep/sweep.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace fs = std::filesystem;
using namespace substratec;

namespace {

struct Args {
  int pixels = 1 << 20;
  int runs = 5;
  std::string parts = "12345";
  std::string dump;
  std::string extra;  // a directory of extra kernels (*.comp) timed with part 1
  bool callgrind = false;
  std::string source = SUBSTRATEC_SOURCE_DIR;
};

[[noreturn]] void die(const std::string& message) {
  std::fprintf(stderr, "shader_cost: %s\n", message.c_str());
  std::exit(2);
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) die("cannot read " + p.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CompileResult compileOrDie(const std::string& name, const std::string& text, const CompileOptions& o) {
  Diagnostics diags(name);
  auto r = compileText(name, text, o, diags);
  if (!r) die("cannot compile " + name + ":\n" + diags.formatAll());
  return std::move(*r);
}

std::optional<CompileResult> tryCompile(const std::string& name, const std::string& text, const CompileOptions& o,
                                        std::string* why) {
  Diagnostics diags(name);
  auto r = compileText(name, text, o, diags);
  if (!r) *why = diags.formatAll();
  return r;
}

// ---------------------------------------------------------------------------
// Kernels and their timing.

/// One compute kernel to time, with its resources (built once, reused by every dispatch).
struct Kernel {
  std::string label;
  std::string source;                // the kernel's text (for --dump)
  std::string materialText;          // the material file it includes ("" for the floor)
  std::vector<uint32_t> spirv;       // as validated (what lavapipe runs)
  std::size_t instructions = 0;      // of `spirv`
  std::size_t optimizedInstructions = 0;  // after SPIRV-Tools' performance passes
  std::unique_ptr<gpu::ComputePipeline> pipeline;
  gpu::Resources resources;
  std::vector<double> nsPerPixel;    // one per timed round
  double median() const {
    std::vector<double> v = nsPerPixel;
    std::sort(v.begin(), v.end());
    if (v.empty()) return 0;
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
};

int paddedPixels(int pixels) {
  return (pixels + kernel::kLocalSize - 1) / kernel::kLocalSize * kernel::kLocalSize;
}

/// Validated SPIR-V of `src` (optimized copy counted), or death with the log.
ShaderValidation compileSource(const ShaderSource& src) {
  ShaderValidation v = compileAndValidate(src, {.optimize = true});
  if (!v.ok) die("kernel " + src.name + " does not validate:\n" + numberLines(src.text) + "\n" + v.log);
  return v;
}

/// The material's Throughput kernel, compiled as compileKernel (pipeline/generate.h)
/// compiles it — the same material file, kernel text and embedded runtime — and
/// also optimized, for its instruction count.
std::unique_ptr<Kernel> generatedKernel(const CompileResult& r, const EmitOptions& emit, const std::string& label) {
  const Syntax& syn = syntaxFor(Target::Glsl);
  GenerateOptions go;
  go.hlsl = false;
  go.emit = emit;
  const Generated g = generateFiles(r, go);
  const std::string materialName = r.material.name + std::string(syn.materialExtension);
  auto k = std::make_unique<Kernel>();
  k->label = label;
  for (const OutputFile& f : g.files)
    if (f.name == materialName) k->materialText = f.contents;
  if (k->materialText.empty()) die("no material file for " + r.material.name);
  ShaderSource src;
  src.name = kernelFileName(r.material, syn, KernelMode::Throughput);
  src.text = emitKernel(r.material, r.after, syn, KernelMode::Throughput, emit);
  src.language = ShaderLanguage::Glsl;
  src.stage = ShaderStage::Compute;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  src.memoryFiles[materialName] = k->materialText;
  ShaderValidation v = compileSource(src);
  k->source = src.text;
  k->spirv = std::move(v.spirv);
  k->instructions = v.instructionCount;
  k->optimizedInstructions = v.optimizedInstructionCount;
  return k;
}

/// The optimized forward shader's instruction count (GLSL), as `report --spirv` counts it.
std::size_t forwardInstructions(const CompileResult& r, const EmitOptions& emit) {
  GenerateOptions go;
  go.hlsl = false;
  go.emit = emit;
  Generated g = generateFiles(r, go);
  validateGenerated(g, {.optimize = true});
  if (!g.valid) die("generated code does not validate:\n" + g.failure);
  for (const EntryReport& e : g.entries)
    if (e.file.ends_with(".forward.frag")) return e.optimizedInstructions;
  die("no forward shader for " + r.material.name);
}

/// Builds the kernel's pipeline and resources (`m` supplies the inputs block).
void prepare(gpu::Context& ctx, Kernel& k, const Material& m, int pixels) {
  Diagnostics diags("bench");
  k.pipeline = ctx.createPipeline(k.spirv, diags);
  if (!k.pipeline) die("pipeline for " + k.label + ": " + diags.errorMessages());
  k.resources = gpu::kernelResources(m, k.pipeline->reflection(), k.spirv, {}, {},
                                     static_cast<std::size_t>(paddedPixels(pixels)) * 4);
}

/// One untimed warm-up round, then `runs` timed rounds; each round dispatches
/// every kernel of the group once, in order, then in reverse order the next
/// round (so that no kernel always runs first or last).
void timeGroup(gpu::Context& ctx, const std::vector<Kernel*>& group, int pixels, int runs) {
  const int n = paddedPixels(pixels);
  for (int round = 0; round <= runs; ++round)
    for (std::size_t j = 0; j < group.size(); ++j) {
      Kernel* k = group[round % 2 ? group.size() - 1 - j : j];
      Diagnostics diags("bench");
      double t = 0;
      if (!ctx.dispatch(*k->pipeline, k->resources, static_cast<uint32_t>(n / kernel::kLocalSize), 1, 1, diags, &t))
        die("dispatch of " + k->label + ": " + diags.errorMessages());
      if (round > 0) k->nsPerPixel.push_back(t / n);
    }
}

/// --callgrind (under `valgrind --tool=callgrind --instr-atstart=no`, see
/// bench/shader_cost.sh): per kernel, one warm-up dispatch, then one dispatch
/// with instrumentation on, its counts dumped to a file named after the kernel.
/// The JIT-compiled shader shows up without symbols ("???" object); the script
/// sums it. Without valgrind's headers at build time this only dispatches.
void countInstructions(gpu::Context& ctx, const std::vector<Kernel*>& group, int pixels) {
  const int n = paddedPixels(pixels);
  for (Kernel* k : group) {
    Diagnostics diags("bench");
    for (int run = 0; run < 2; ++run) {
#if SHADER_COST_HAVE_CALLGRIND
      if (run == 1) {
        CALLGRIND_ZERO_STATS;
        CALLGRIND_START_INSTRUMENTATION;
      }
#endif
      if (!ctx.dispatch(*k->pipeline, k->resources, static_cast<uint32_t>(n / kernel::kLocalSize), 1, 1, diags))
        die("dispatch of " + k->label + ": " + diags.errorMessages());
#if SHADER_COST_HAVE_CALLGRIND
      if (run == 1) {
        CALLGRIND_STOP_INSTRUMENTATION;
        CALLGRIND_DUMP_STATS_AT(k->label.c_str());
      }
#endif
    }
    fmt::print("counted: {}\n", k->label);
  }
#if !SHADER_COST_HAVE_CALLGRIND
  fmt::print("(built without <valgrind/callgrind.h>: nothing counted)\n");
#endif
}

void dumpKernel(const Args& a, const Kernel& k, const std::string& file) {
  if (a.dump.empty()) return;
  fs::create_directories(a.dump);
  std::ofstream(fs::path(a.dump) / file) << k.source;
  if (!k.materialText.empty()) std::ofstream(fs::path(a.dump) / (file + ".material.glsl")) << k.materialText;
}

std::string stemOf(const std::string& path) { return fs::path(path).stem().string(); }

struct Fit {
  double a = 0, b = 0, r2 = 0;
};

/// Least squares y = a + b x, and its coefficient of determination.
Fit linearFit(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  Fit f;
  f.b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  f.a = (sy - f.b * sx) / n;
  const double mean = sy / n;
  double ssRes = 0, ssTot = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double e = y[i] - (f.a + f.b * x[i]);
    ssRes += e * e;
    ssTot += (y[i] - mean) * (y[i] - mean);
  }
  f.r2 = ssTot > 0 ? 1 - ssRes / ssTot : 1;
  return f;
}

std::string spread(const Kernel& k) {
  const auto [lo, hi] = std::minmax_element(k.nsPerPixel.begin(), k.nsPerPixel.end());
  return fmt::format("{:.1f}–{:.1f}", *lo, *hi);
}

// ---------------------------------------------------------------------------
// 1. The floor.

void partFloor(gpu::Context& ctx, const Args& a) {
  const std::string examplePath = a.source + "/examples/row12_simple.json";
  const CompileResult simple = compileOrDie("row12_simple.json", readAll(examplePath), {});
  const std::string floorPath = a.source + "/bench/shaders/minimal_ggx_lambert.comp";
  const std::string floorText = readAll(floorPath);

  enum class Floor { PrologueOnly, KarisConstants, Karis, Tables, RuntimeModel };
  auto floorKernel = [&](Floor f) {
    const bool uniformParams = f != Floor::KarisConstants && f != Floor::PrologueOnly;
    const bool envLut = f == Floor::Tables || f == Floor::RuntimeModel;
    ShaderSource src;
    src.name = "minimal_ggx_lambert.comp";
    src.text = floorText;
    src.language = ShaderLanguage::Glsl;
    src.stage = ShaderStage::Compute;
    src.defines = {{"MINIMAL_PARAMS_UNIFORM", uniformParams ? "1" : "0"},
                   {"MINIMAL_ENV_LUT", envLut ? "1" : "0"},
                   {"MINIMAL_SHADING", f == Floor::PrologueOnly ? "0" : "1"},
                   {"MINIMAL_RUNTIME_MODEL", f == Floor::RuntimeModel ? "1" : "0"}};
    ShaderValidation v = compileSource(src);
    auto k = std::make_unique<Kernel>();
    switch (f) {
      case Floor::PrologueOnly: k->label = "prologue only: the shading point written out, no material, no lighting"; break;
      case Floor::KarisConstants: k->label = "floor (Karis), parameters as compile-time constants"; break;
      case Floor::Karis: k->label = "**floor (Karis)**: hand-written GGX + Lambert, env. BRDF from Karis' fit"; break;
      case Floor::Tables: k->label = "**floor (tables)**: the same, env. BRDF from the runtime's tables"; break;
      case Floor::RuntimeModel:
        k->label = "floor (tables) + the runtime's model: energy compensation, Chan 2024 diffuse";
        break;
    }
    k->source = src.text;
    k->spirv = std::move(v.spirv);
    k->instructions = v.instructionCount;
    k->optimizedInstructions = v.optimizedInstructionCount;
    return k;
  };
  auto prologue = floorKernel(Floor::PrologueOnly);
  auto floorConst = floorKernel(Floor::KarisConstants);
  auto floorKaris = floorKernel(Floor::Karis);
  auto floorLut = floorKernel(Floor::Tables);
  auto floorModel = floorKernel(Floor::RuntimeModel);
  EmitOptions lambert;
  lambert.diffuseModel = DiffuseModel::Lambert;
  auto generated = generatedKernel(simple, {}, "generated `row12_simple` (default diffuse: Chan 2024)");
  auto generatedLambert = generatedKernel(simple, lambert, "generated `row12_simple`, `--diffuse lambert`");
  std::vector<Kernel*> group = {prologue.get(),   floorConst.get(), floorKaris.get(),       floorLut.get(),
                                floorModel.get(), generated.get(),  generatedLambert.get()};
  // --extra DIR: every DIR/*.comp, its includes found in DIR first, then in the embedded runtime.
  std::vector<std::unique_ptr<Kernel>> extras;
  if (!a.extra.empty()) {
    std::map<std::string, std::string> texts;
    std::vector<std::string> comps;
    for (const auto& e : fs::directory_iterator(a.extra)) {
      if (!e.is_regular_file()) continue;
      texts[e.path().filename().string()] = readAll(e.path());
      if (e.path().extension() == ".comp") comps.push_back(e.path().filename().string());
    }
    std::sort(comps.begin(), comps.end());
    for (const std::string& c : comps) {
      ShaderSource src;
      src.name = c;
      src.text = texts[c];
      src.stage = ShaderStage::Compute;
      for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
      for (const auto& [name, text] : texts) src.memoryFiles[name] = text;
      ShaderValidation v = compileSource(src);
      auto k = std::make_unique<Kernel>();
      k->label = "extra: " + c;
      k->spirv = std::move(v.spirv);
      k->instructions = v.instructionCount;
      k->optimizedInstructions = v.optimizedInstructionCount;
      group.push_back(k.get());
      extras.push_back(std::move(k));
    }
  }
  for (Kernel* k : group) prepare(ctx, *k, simple.material, a.pixels);
  if (a.callgrind) {
    countInstructions(ctx, group, a.pixels);
    return;
  }
  dumpKernel(a, *floorKaris, "minimal_ggx_lambert.comp");
  dumpKernel(a, *generated, "row12_simple.throughput.comp");
  timeGroup(ctx, group, a.pixels, a.runs);

  // Same job: how far the floors' radiance is from the generated kernels'.
  auto rgb = [](const Kernel& k) { return gpu::floatsOf(k.resources, 0, 7); };
  auto relDiff = [](const std::vector<float>& x, const std::vector<float>& y) {
    double num = 0, den = 0;
    for (std::size_t i = 0; i < x.size(); i += 4)
      for (int c = 0; c < 3; ++c) {
        num += std::abs(double(x[i + c]) - y[i + c]);
        den += std::abs(double(y[i + c]));
      }
    return num / den;
  };

  const double karisNs = floorKaris->median(), lutNs = floorLut->median();
  fmt::print("## 1. The floor: a simple material against a hand-written GGX + Lambert kernel\n\n");
  fmt::print("{} pixels per dispatch, {} interleaved timed rounds after 1 warm-up round; median (min–max) ns per "
             "pixel; ratios of medians.\n\n",
             paddedPixels(a.pixels), a.runs);
  fmt::print("| kernel | ns/pixel | min–max | ÷ floor (Karis) | ÷ floor (tables) | SPIR-V instr. (as compiled / "
             "optimized) |\n");
  fmt::print("|---|---:|---:|---:|---:|---:|\n");
  for (Kernel* k : group)
    fmt::print("| {} | {:.2f} | {} | {:.3f} | {:.3f} | {} / {} |\n", k->label, k->median(), spread(*k),
               k->median() / karisNs, k->median() / lutNs, k->instructions, k->optimizedInstructions);
  const std::vector<float> fk = rgb(*floorKaris), fl = rgb(*floorLut), gd = rgb(*generated),
                           gl = rgb(*generatedLambert);
  fmt::print("\nSame job (mean |Δrgb| / mean |rgb| over all pixels): floor (Karis) vs generated Lambert {:.3f}, "
             "floor (tables) vs generated Lambert {:.3f}, floor (Karis) vs floor (tables) {:.3f}, generated Lambert vs "
             "Chan 2024 {:.3f}.\n",
             relDiff(fk, gl), relDiff(fl, gl), relDiff(fk, fl), relDiff(gl, gd));
  auto verdict = [](double r) { return r <= 1.1 ? "met" : "NOT met"; };
  fmt::print("\nTarget ≤ 1.1 × floor: generated (Chan 2024) {:.3f} × floor (Karis): {}; {:.3f} × floor (tables): {}. "
             "Generated Lambert: {:.3f} × floor (Karis): {}; {:.3f} × floor (tables): {}.\n\n",
             generated->median() / karisNs, verdict(generated->median() / karisNs), generated->median() / lutNs,
             verdict(generated->median() / lutNs), generatedLambert->median() / karisNs,
             verdict(generatedLambert->median() / karisNs), generatedLambert->median() / lutNs,
             verdict(generatedLambert->median() / lutNs));
}

// ---------------------------------------------------------------------------
// 2. Cost against closures.

/// N distinct slabs (albedo, F0, roughness from inputs) mixed by a chain of
/// horizontals whose weights are inputs too: N closures, nothing folded,
/// nothing simplified (budget 1024 bytes, 8 closures).
std::string syntheticMaterial(int n) {
  std::string inputs, nodes;
  for (int k = 0; k < n; ++k) {
    const double t = n > 1 ? double(k) / (n - 1) : 0.0;
    inputs += fmt::format(
        "    \"albedo_{0}\": {{\"type\": \"color\", \"default\": [{1:.3f}, {2:.3f}, {3:.3f}], \"min\": 0, \"max\": 1}},\n"
        "    \"f0_{0}\": {{\"type\": \"color\", \"default\": [{4:.3f}, {4:.3f}, {4:.3f}], \"min\": 0, \"max\": 1}},\n"
        "    \"roughness_{0}\": {{\"type\": \"float\", \"default\": {5:.3f}, \"min\": 0, \"max\": 1}},\n",
        k, 0.2 + 0.6 * t, 0.5 - 0.3 * t, 0.3 + 0.2 * t, 0.02 + 0.06 * t, 0.2 + 0.6 * t);
    nodes += fmt::format(
        "    \"slab_{0}\": {{\"kind\": \"slab\", \"diffuse_albedo\": \"$albedo_{0}\", \"f0\": \"$f0_{0}\", "
        "\"roughness\": \"$roughness_{0}\"}},\n",
        k);
    if (k > 0) {
      inputs += fmt::format("    \"mix_{0}\": {{\"type\": \"float\", \"default\": {1:.3f}, \"min\": 0, \"max\": 1}},\n",
                            k, 1.0 / (k + 1));
      nodes += fmt::format(
          "    \"mix_{0}_node\": {{\"kind\": \"horizontal\", \"background\": \"{1}\", \"foreground\": \"slab_{0}\", "
          "\"mix\": \"$mix_{0}\"}},\n",
          k, k == 1 ? std::string("slab_0") : fmt::format("mix_{}_node", k - 1));
    }
  }
  inputs.resize(inputs.size() - 2);  // the last ",\n"
  nodes.resize(nodes.size() - 2);
  const std::string output = n == 1 ? "slab_0" : fmt::format("mix_{}_node", n - 1);
  return fmt::format(
      "{{\n  \"format\": \"substrate-material/1\",\n  \"name\": \"synthetic_{0}\",\n"
      "  \"description\": \"bench/shader_cost.cc: {0} distinct slabs in a chain of horizontal mixes.\",\n"
      "  \"settings\": {{\"bytes_per_pixel\": 1024, \"max_closures\": 8}},\n"
      "  \"inputs\": {{\n{1}\n  }},\n  \"nodes\": {{\n{2}\n  }},\n  \"output\": \"{3}\"\n}}\n",
      n, inputs, nodes, output);
}

void partClosures(gpu::Context& ctx, const Args& a) {
  const std::vector<int> counts = {1, 2, 3, 4, 6, 8};
  std::vector<CompileResult> results;
  std::vector<std::unique_ptr<Kernel>> kernels;
  std::vector<std::size_t> forward;
  for (int n : counts) {
    const std::string text = syntheticMaterial(n);
    if (!a.dump.empty()) {
      fs::create_directories(a.dump);
      std::ofstream(fs::path(a.dump) / fmt::format("synthetic_{}.json", n)) << text;
    }
    results.push_back(compileOrDie(fmt::format("synthetic_{}.json", n), text, {}));
    const CompileResult& r = results.back();
    if (static_cast<int>(r.after.closures.size()) != n)
      die(fmt::format("synthetic_{} has {} closures, not {}", n, r.after.closures.size(), n));
    forward.push_back(forwardInstructions(r, {}));
    kernels.push_back(generatedKernel(r, {}, fmt::format("synthetic_{}", n)));
    prepare(ctx, *kernels.back(), r.material, a.pixels);
    dumpKernel(a, *kernels.back(), fmt::format("synthetic_{}.throughput.comp", n));
  }
  std::vector<Kernel*> group;
  for (auto& k : kernels) group.push_back(k.get());
  if (a.callgrind) {
    countInstructions(ctx, group, a.pixels);
    return;
  }
  timeGroup(ctx, group, a.pixels, a.runs);

  fmt::print("## 2. Cost against the number of closures\n\n");
  fmt::print("Synthetic materials: N distinct slabs (albedo, F0, roughness from inputs) in a chain of N − 1 "
             "horizontal mixes (weights from inputs), budget 1024 bytes and 8 closures (nothing simplified); "
             "default diffuse (Chan 2024). Timed in interleaved rounds.\n\n");
  fmt::print("| closures | bytes | forward instr. (optimized) | throughput kernel instr. (optimized) | ns/pixel (median) | "
             "min–max | ns/pixel per closure |\n");
  fmt::print("|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<double> x, ns, instr;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    const Kernel& k = *kernels[i];
    fmt::print("| {} | {} | {} | {} | {:.2f} | {} | {:.2f} |\n", counts[i], results[i].after.bytes(), forward[i],
               k.optimizedInstructions, k.median(), spread(k), k.median() / counts[i]);
    x.push_back(counts[i]);
    ns.push_back(k.median());
    instr.push_back(static_cast<double>(forward[i]));
  }
  auto fits = [&](std::size_t from, const char* what) {
    const std::vector<double> xs(x.begin() + from, x.end()), ys(ns.begin() + from, ns.end()),
        is(instr.begin() + from, instr.end());
    const Fit fn = linearFit(xs, ys), fi = linearFit(xs, is);
    fmt::print("Least squares over {} ({} points):\n\n", what, xs.size());
    fmt::print("- ns/pixel = {:.2f} + {:.2f} · closures, R² = {:.4f}; residuals (measured − fit):", fn.a, fn.b, fn.r2);
    for (std::size_t i = 0; i < xs.size(); ++i) fmt::print(" {}: {:+.2f}", xs[i], ys[i] - (fn.a + fn.b * xs[i]));
    fmt::print("\n- forward instructions = {:.1f} + {:.1f} · closures, R² = {:.4f}\n\n", fi.a, fi.b, fi.r2);
  };
  fmt::print("\n");
  fits(0, "1–8 closures");
  fits(1, "2–8 closures (the forward shader lights one closure without a loop, several in one loop)");
}

/// examples/*.json, sorted, without the volumes (a volumetric fog cloud has no
/// surface, so no throughput kernel or forward shader: `accuracy` measures it).
std::vector<std::string> surfaceExamples(const std::string& source) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(source + "/examples")) {
    if (e.path().extension() != ".json") continue;
    if (isVolumeMaterial(compileOrDie(e.path().filename().string(), readAll(e.path().string()), {}).material)) continue;
    files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// ---------------------------------------------------------------------------
// 3. Every example at every budget.

void partExamples(gpu::Context& ctx, const Args& a) {
  const std::vector<std::string> files = surfaceExamples(a.source);

  struct Budget {
    std::string label;
    std::optional<int> bytes;
    bool full = false;
  };
  const std::vector<Budget> budgets = {{"own", {}, false}, {"80", 80, false}, {"48", 48, false},
                                       {"20", 20, false},  {"full", {}, true}};

  fmt::print("## 3. Every example at five budgets\n\n");
  fmt::print("Budgets: `own` (the file's settings), `--budget 80`, `--budget 48`, `--budget 20` (the file's "
             "max_closures kept), `--full-simplification`. A budget that gives byte-identical generated code as an "
             "earlier one of the same example is timed once (its cells repeat the figures). Each example's distinct "
             "variants are timed in interleaved rounds. Default diffuse (Chan 2024).\n\n");
  fmt::print("Each cell: bytes per pixel · closures · optimized forward-shader instructions · ns/pixel (median). "
             "`ref.`: row12_simple's throughput kernel, timed in the same rounds as the example's variants (the "
             "machine's speed during that example: divide by it to compare examples timed at different moments).\n\n");
  fmt::print("| example |");
  for (const Budget& b : budgets) fmt::print(" {} |", b.label);
  fmt::print(" ref. |\n|---|");
  for (std::size_t i = 0; i <= budgets.size(); ++i) fmt::print("---:|");
  fmt::print("\n");
  const CompileResult reference =
      compileOrDie("row12_simple.json", readAll(a.source + "/examples/row12_simple.json"), {});
  for (const std::string& path : files) {
    const std::string text = readAll(path);
    const std::string name = fs::path(path).filename().string();
    struct Variant {
      std::string budget;
      std::optional<CompileResult> result;
      std::string failure;
      int kernelIndex = -1;
      std::size_t forward = 0;
    };
    std::vector<Variant> variants;
    std::vector<std::unique_ptr<Kernel>> kernels;
    std::vector<std::size_t> kernelForward;
    std::map<std::string, int> byMaterialText;
    for (const Budget& b : budgets) {
      CompileOptions o;
      o.budgetOverride = b.bytes;
      o.fullSimplification = b.full;
      Variant v;
      v.budget = b.label;
      v.result = tryCompile(name, text, o, &v.failure);
      if (v.result) {
        auto k = generatedKernel(*v.result, {}, fmt::format("{} @ {}", stemOf(path), b.label));
        auto it = byMaterialText.find(k->materialText);
        if (it != byMaterialText.end()) {
          v.kernelIndex = it->second;
          v.forward = kernelForward[it->second];
        } else {
          v.forward = forwardInstructions(*v.result, {});
          prepare(ctx, *k, v.result->material, a.pixels);
          dumpKernel(a, *k, fmt::format("{}.{}.throughput.comp", stemOf(path), b.label));
          v.kernelIndex = static_cast<int>(kernels.size());
          byMaterialText[k->materialText] = v.kernelIndex;
          kernels.push_back(std::move(k));
          kernelForward.push_back(v.forward);
        }
      }
      variants.push_back(std::move(v));
    }
    auto ref = generatedKernel(reference, {}, "row12_simple (reference)");
    prepare(ctx, *ref, reference.material, a.pixels);
    std::vector<Kernel*> group = {ref.get()};
    for (auto& k : kernels) group.push_back(k.get());
    timeGroup(ctx, group, a.pixels, a.runs);
    fmt::print("| {} |", stemOf(path));
    for (const Variant& v : variants) {
      if (!v.result) {
        fmt::print(" — (does not compile: {}) |", v.failure.substr(0, v.failure.find('\n')));
        continue;
      }
      fmt::print(" {} B · {} · {} · {:.1f} |", v.result->after.bytes(), v.result->after.closures.size(), v.forward,
                 kernels[v.kernelIndex]->median());
    }
    fmt::print(" {:.1f} |\n", ref->median());
    std::fflush(stdout);
    // Free the 16 MB result buffers before the next example.
    kernels.clear();
  }
  fmt::print("\n");
}

// ---------------------------------------------------------------------------
// 4. Diffuse models.

void partDiffuse(gpu::Context& ctx, const Args& a) {
  const CompileResult r = compileOrDie("row12_simple.json", readAll(a.source + "/examples/row12_simple.json"), {});
  const char* names[4] = {"Lambert", "Chan 2018", "Chan 2024 (default)", "EON"};
  std::vector<std::unique_ptr<Kernel>> kernels;
  std::vector<std::size_t> forward;
  for (int model = 0; model < 4; ++model) {
    EmitOptions e;
    e.diffuseModel = static_cast<DiffuseModel>(model);
    forward.push_back(forwardInstructions(r, e));
    kernels.push_back(generatedKernel(r, e, fmt::format("row12_simple, diffuse {}", names[model])));
    prepare(ctx, *kernels.back(), r.material, a.pixels);
  }
  std::vector<Kernel*> group;
  for (auto& k : kernels) group.push_back(k.get());
  if (a.callgrind) {
    countInstructions(ctx, group, a.pixels);
    return;
  }
  timeGroup(ctx, group, a.pixels, a.runs);
  fmt::print("## 4. Diffuse models (row12_simple)\n\n");
  fmt::print("| diffuse model | `--diffuse` | forward instr. (optimized) | ns/pixel (median) | min–max | vs Lambert |\n");
  fmt::print("|---|---|---:|---:|---:|---:|\n");
  for (int model = 0; model < 4; ++model)
    fmt::print("| {} | `{}` | {} | {:.2f} | {} | {:.3f} |\n", names[model], diffuseModelName(static_cast<DiffuseModel>(model)), forward[model],
               kernels[model]->median(), spread(*kernels[model]), kernels[model]->median() / kernels[0]->median());
  fmt::print("\n");
}

// ---------------------------------------------------------------------------
// 5. Half precision.

void partHalf(gpu::Context& ctx, const Args& a) {
  if (!ctx.shaderFloat16()) die("part 5 needs shaderFloat16 (" + ctx.deviceName() + " has none)");
  const std::vector<std::string> files = surfaceExamples(a.source);
  EmitOptions full, half;
  half.precision = Precision::Half;
  if (!a.callgrind) {
    fmt::print("## 5. Half precision (`--precision half`)\n\n");
    fmt::print("Every example at its own budget: the throughput kernel in float32 and in half, the two of an example "
               "timed in the same interleaved rounds ({} pixels, {} timed rounds; median, min–max ns per pixel); "
               "optimized forward-shader instructions; the half kernel's output (rgb per pixel) against float32's: "
               "rel_mse = mean((h − f)² / (f² + 0.01)), max |h − f|, and max |h − f| / |f| where |f| ≥ 0.01.\n\n",
               paddedPixels(a.pixels), a.runs);
    fmt::print("| example | float32 ns/pixel | half ns/pixel | half ÷ float32 | forward instr. float32 / half | "
               "rel_mse | max abs | max rel |\n|---|---:|---:|---:|---:|---:|---:|---:|\n");
  }
  for (const std::string& path : files) {
    const CompileResult r = compileOrDie(stemOf(path) + ".json", readAll(path), {});
    auto f = generatedKernel(r, full, stemOf(path) + " float32");
    auto h = generatedKernel(r, half, stemOf(path) + " half");
    prepare(ctx, *f, r.material, a.pixels);
    prepare(ctx, *h, r.material, a.pixels);
    dumpKernel(a, *h, stemOf(path) + ".half.throughput.comp");
    std::vector<Kernel*> group = {f.get(), h.get()};
    if (a.callgrind) {
      countInstructions(ctx, group, a.pixels);
      continue;
    }
    timeGroup(ctx, group, a.pixels, a.runs);
    // rgb of every pixel (each result is a float4: colour, coverage).
    auto rgb = [](const Kernel& k) {
      const std::vector<float> out = gpu::floatsOf(k.resources, 0, 7);
      std::vector<double> v;
      for (std::size_t i = 0; i < out.size(); ++i)
        if (i % 4 != 3) v.push_back(out[i]);
      return v;
    };
    const std::vector<double> x = rgb(*h), y = rgb(*f);
    double maxAbs = 0, maxRel = 0;
    for (std::size_t i = 0; i < y.size(); ++i) {
      maxAbs = std::max(maxAbs, std::abs(x[i] - y[i]));
      if (std::abs(y[i]) >= 0.01) maxRel = std::max(maxRel, std::abs(x[i] - y[i]) / std::abs(y[i]));
    }
    fmt::print("| {} | {:.2f} ({}) | {:.2f} ({}) | {:.3f} | {} / {} | {:.2e} | {:.2e} | {:.2e} |\n", stemOf(path),
               f->median(), spread(*f), h->median(), spread(*h), h->median() / f->median(), forwardInstructions(r, full),
               forwardInstructions(r, half), sweep::relMse(x, y), maxAbs, maxRel);
    std::fflush(stdout);
  }
  if (!a.callgrind) fmt::print("\n");
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) die("missing value after " + arg);
      return argv[++i];
    };
    if (arg == "--pixels") a.pixels = std::max(kernel::kLocalSize, std::atoi(value().c_str()));
    else if (arg == "--runs") a.runs = std::max(1, std::atoi(value().c_str()));
    else if (arg == "--parts") a.parts = value();
    else if (arg == "--dump") a.dump = value();
    else if (arg == "--extra") a.extra = value();
    else if (arg == "--callgrind") a.callgrind = true;
    else if (arg == "--source") a.source = value();
    else if (arg == "-h" || arg == "--help") {
      std::printf("usage: shader_cost [--pixels N] [--runs N] [--parts 12345] [--dump DIR] [--extra DIR] [--callgrind] [--source DIR]\n");
      return 0;
    } else die("unknown argument " + arg);
  }
  if (a.callgrind) a.parts.erase(std::remove(a.parts.begin(), a.parts.end(), '3'), a.parts.end());
  Diagnostics diags("bench");
  auto ctx = gpu::Context::create({}, diags);
  if (!ctx) die("no lavapipe: " + diags.errorMessages());
  const auto t0 = std::chrono::steady_clock::now();
  fmt::print("# shader_cost: {} pixels per dispatch, {} timed runs (median), device {} ({})\n\n",
             paddedPixels(a.pixels), a.runs, ctx->deviceName(), ctx->driverInfo());
  std::fflush(stdout);
  auto part = [&](char c, void (*f)(gpu::Context&, const Args&)) {
    if (a.parts.find(c) == std::string::npos) return;
    std::ifstream loadavg("/proc/loadavg");
    std::string l1, l5, l15;
    loadavg >> l1 >> l5 >> l15;
    if (!a.callgrind) fmt::print("(load average before table {}: {} {} {})\n\n", c, l1, l5, l15);
    f(*ctx, a);
    std::fflush(stdout);
  };
  part('1', partFloor);
  part('2', partClosures);
  part('3', partExamples);
  part('4', partDiffuse);
  part('5', partHalf);
  fmt::print("(total {:.0f} s)\n",
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return 0;
}
