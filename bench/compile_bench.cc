// In-process compile time of every bundled example (issue 2: <= 0.5 ms per
// material for compileText: parse + every pass, pricing included).
//
//   Compile/<stem>             compileText() on one example
//   Compile/parse_only/<stem>  parseJsonDocument() alone, largest example only
//   CompileAll                 every example once per iteration
//
// Examples are globbed from <source>/examples/*.json at startup (sorted), so
// a new example gets a benchmark without touching this file. Each file is read
// once, outside the timed loop, and compiled once untimed to check that it is
// valid: a benchmark of a material that fails to compile would time the error
// path and mean nothing.
//
// Counter `us_per_material` is wall-clock microseconds per compiled material
// (for CompileAll: per material, not per iteration).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "pipeline/generate.h"
#include "pipeline/pipeline.h"
#include "report/html_report.h"

namespace fs = std::filesystem;
using namespace substratec;

namespace {

struct Example {
  std::string stem;
  std::string path;  // for diagnostics
  std::string text;
};

std::vector<Example>& examples() {
  static std::vector<Example> list;
  return list;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Wall-clock timer for the whole measured loop, to report a plain
/// microseconds-per-material counter (the library's own Time column is per
/// iteration, which for CompileAll is per 16 materials).
class LoopClock {
 public:
  LoopClock() : t0_(std::chrono::steady_clock::now()) {}
  void report(benchmark::State& state, double materialsPerIteration) const {
    double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0_).count();
    double n = static_cast<double>(state.iterations()) * materialsPerIteration;
    if (n > 0) state.counters["us_per_material"] = benchmark::Counter(us / n);
  }

 private:
  std::chrono::steady_clock::time_point t0_;
};

void BM_Compile(benchmark::State& state, const Example* ex) {
  const CompileOptions options;
  LoopClock clock;
  for (auto _ : state) {
    Diagnostics diags(ex->path);
    auto result = compileText(ex->path, ex->text, options, diags);
    benchmark::DoNotOptimize(result);
    benchmark::ClobberMemory();
  }
  clock.report(state, 1);
}

// Issue 3: simplifying to one closure is part of the per-material budget.
void BM_CompileFullySimplified(benchmark::State& state, const Example* ex) {
  CompileOptions options;
  options.fullSimplification = true;
  LoopClock clock;
  for (auto _ : state) {
    Diagnostics diags(ex->path);
    auto result = compileText(ex->path, ex->text, options, diags);
    benchmark::DoNotOptimize(result);
    benchmark::ClobberMemory();
  }
  clock.report(state, 1);
}

// Issue 4: code generation (both targets, no validation) after the compile.
void BM_Generate(benchmark::State& state, const Example* ex) {
  Diagnostics diags(ex->path);
  auto result = compileText(ex->path, ex->text, CompileOptions{}, diags);
  LoopClock clock;
  for (auto _ : state) {
    Generated g = generateFiles(*result, GenerateOptions{});
    benchmark::DoNotOptimize(g);
  }
  clock.report(state, 1);
}

// Issue 4: generation plus in-process validation of every entry shader, both
// targets (glslang, spirv-val), as `substratec compile` does it: the entries
// compile in parallel, so the wall time (judged) is below the process CPU time
// (also printed). With optimize, also SPIRV-Tools' performance passes, as
// `substratec report --spirv` does. The first call of a process pays glslang's
// one-time initialization; Google Benchmark's warm-up iterations absorb it, so
// this is the steady-state cost per material.
void BM_GenerateAndValidate(benchmark::State& state, const Example* ex, bool optimize) {
  Diagnostics diags(ex->path);
  auto result = compileText(ex->path, ex->text, CompileOptions{}, diags);
  LoopClock clock;
  for (auto _ : state) {
    Generated g = generateFiles(*result, GenerateOptions{});
    validateGenerated(g, {.optimize = optimize});
    if (!g.valid) state.SkipWithError("generated code does not validate");
    benchmark::DoNotOptimize(g);
  }
  clock.report(state, 1);
}

// Issue 21: where a validated material's time goes. Every entry of both
// targets compiled one after another on this thread (compileGeneratedEntry,
// as validateGenerated compiles each), with ShaderValidation::timings summed
// per material: glslang's front end (parse_ms), its linker (link_ms), SPIR-V
// generation (spirv_ms) and spirv-val (val_ms). CPU time per material is the
// benchmark's time (one thread).
void BM_ValidatePhases(benchmark::State& state, const Example* ex) {
  Diagnostics diags(ex->path);
  auto result = compileText(ex->path, ex->text, CompileOptions{}, diags);
  ShaderValidation::Timings sum;
  for (auto _ : state) {
    Generated g = generateFiles(*result, GenerateOptions{});
    for (const OutputFile& f : g.files) {
      if (!f.name.ends_with(".frag") && !f.name.ends_with(".ps.hlsl")) continue;
      ShaderValidation v = compileGeneratedEntry(g, f.name);
      if (!v.ok) state.SkipWithError("generated code does not validate");
      sum.parseMs += v.timings.parseMs;
      sum.linkMs += v.timings.linkMs;
      sum.spirvMs += v.timings.spirvMs;
      sum.validateMs += v.timings.validateMs;
    }
  }
  const double n = static_cast<double>(state.iterations());
  if (n == 0) return;
  state.counters["parse_ms"] = sum.parseMs / n;
  state.counters["link_ms"] = sum.linkMs / n;
  state.counters["spirv_ms"] = sum.spirvMs / n;
  state.counters["val_ms"] = sum.validateMs / n;
}

void BM_ParseOnly(benchmark::State& state, const Example* ex) {
  const ReadLimits limits;
  LoopClock clock;
  for (auto _ : state) {
    Diagnostics diags(ex->path);
    auto doc = parseJsonDocument(ex->text, limits, diags);
    benchmark::DoNotOptimize(doc);
    benchmark::ClobberMemory();
  }
  clock.report(state, 1);
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(ex->text.size()));
}

void BM_CompileAll(benchmark::State& state) {
  const CompileOptions options;
  const auto& list = examples();
  LoopClock clock;
  for (auto _ : state) {
    for (const Example& ex : list) {
      Diagnostics diags(ex.path);
      auto result = compileText(ex.path, ex.text, options, diags);
      benchmark::DoNotOptimize(result);
    }
    benchmark::ClobberMemory();
  }
  clock.report(state, static_cast<double>(list.size()));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(list.size()));
}

/// `report --html` over every example (issue 24): each compiled, again
/// unsimplified where its budget simplified it, and one page of them all
/// formatted; the time per material against CompileAll's is the page's cost.
void BM_HtmlReportAll(benchmark::State& state) {
  const CompileOptions options;
  const auto& list = examples();
  LoopClock clock;
  std::size_t bytes = 0;
  for (auto _ : state) {
    html::Page page;
    page.title = "all examples";
    for (const Example& ex : list) page.materials.push_back(html::compiledMaterial(ex.path, ex.text, options));
    const std::string html = html::formatPage(page);
    bytes = html.size();
    benchmark::DoNotOptimize(html);
  }
  clock.report(state, static_cast<double>(list.size()));
  state.counters["page_bytes"] = static_cast<double>(bytes);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(list.size()));
}

/// Loads and validates every example; returns false (after printing why) if
/// there is none or any of them does not compile.
bool loadExamples(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".json") files.push_back(entry.path());
  if (ec || files.empty()) {
    std::fprintf(stderr, "compile_bench: no examples/*.json under %s\n", dir.string().c_str());
    return false;
  }
  std::sort(files.begin(), files.end());
  bool ok = true;
  for (const auto& f : files) {
    Example ex{f.stem().string(), f.string(), readAll(f)};
    Diagnostics diags(ex.path);
    auto result = compileText(ex.path, ex.text, CompileOptions{}, diags);
    if (!result || diags.hasErrors()) {
      std::fprintf(stderr, "compile_bench: %s does not compile:\n%s", ex.path.c_str(),
                   diags.formatAll().c_str());
      ok = false;
    }
    examples().push_back(std::move(ex));
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  // Optional leading non-flag argument: the examples directory.
  fs::path dir = fs::path(SUBSTRATEC_SOURCE_DIR) / "examples";
  if (argc > 1 && argv[1][0] != '-') {
    dir = argv[1];
    for (int i = 1; i + 1 < argc; ++i) argv[i] = argv[i + 1];
    --argc;
  }
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!loadExamples(dir)) return 1;

  const auto& list = examples();
  for (const Example& ex : list)
    benchmark::RegisterBenchmark(("Compile/" + ex.stem).c_str(), BM_Compile, &ex)
        ->Unit(benchmark::kMicrosecond);
  const Example* largest = &*std::max_element(
      list.begin(), list.end(), [](const Example& a, const Example& b) { return a.text.size() < b.text.size(); });
  benchmark::RegisterBenchmark(("Compile/parse_only/" + largest->stem).c_str(), BM_ParseOnly, largest)
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("CompileAll", BM_CompileAll)->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("HtmlReportAll", BM_HtmlReportAll)->Unit(benchmark::kMicrosecond);
  // The deepest tree: the most operators to collapse.
  const Example* deepest = nullptr;
  std::size_t mostOps = 0;
  for (const Example& ex : list) {
    Diagnostics diags(ex.path);
    auto r = compileText(ex.path, ex.text, CompileOptions{}, diags);
    if (!r) continue;
    std::size_t ops = r->tree.preorder.size() - r->tree.slabOrder.size();
    if (!deepest || ops > mostOps) {
      deepest = &ex;
      mostOps = ops;
    }
  }
  if (deepest)
    benchmark::RegisterBenchmark(("CompileFullySimplified/" + deepest->stem).c_str(), BM_CompileFullySimplified, deepest)
        ->Unit(benchmark::kMicrosecond);
  for (const Example& ex : list)
    benchmark::RegisterBenchmark(("Generate/" + ex.stem).c_str(), BM_Generate, &ex)->Unit(benchmark::kMicrosecond);
  for (const Example& ex : list)
    benchmark::RegisterBenchmark(("GenerateAndValidate/" + ex.stem).c_str(), BM_GenerateAndValidate, &ex, false)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MeasureProcessCPUTime();
  for (const Example& ex : list)
    benchmark::RegisterBenchmark(("ValidatePhases/" + ex.stem).c_str(), BM_ValidatePhases, &ex)
        ->Unit(benchmark::kMillisecond);
  for (const Example& ex : list)
    benchmark::RegisterBenchmark(("GenerateValidateOptimize/" + ex.stem).c_str(), BM_GenerateAndValidate, &ex, true)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MeasureProcessCPUTime();

  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
