// `substratec sweep`: what each byte and each instruction buys. The authored
// material (no simplification at all), the material at its own budget, and
// after each simplification step down to one closure; for each row its cost
// (bytes, closures, SPIR-V instructions of the forward shader after the
// performance passes, lavapipe ns per shading point) and its error against
// the authored tree (relative MSE, max and 99th-percentile absolute error of
// linear radiance; CIEDE2000 of the packed colours: the GPU parity of the
// steps), and the accuracy metric (accuracy/accuracy.h, docs/accuracy.md)
// against the Monte Carlo truth of the authored material and against the truth
// of the row's own closures.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "emit/material_emitter.h"
#include "gpu/harness.h"
#include "pipeline/pipeline.h"
#include "accuracy/accuracy.h"

namespace substratec::sweep {

/// One material of the sweep: compiled at a budget, and what to call it.
struct Step {
  CompileResult result;
  std::string label;  // "authored", "full budget", "step 3", "full simplification"
  int budget = 0;     // the byte budget it was compiled with (authored: the bytes it needs)
};

/// The first row's label when the material's own settings simplify it.
inline constexpr const char* kAuthoredLabel = "authored";

/// The authored material (pipeline's unsimplifiedOptions: every closure, any
/// size; first, and only when the material's own settings simplify it), the
/// material at its own budget ("full budget"), after each simplification step
/// that changes its size (compiled with that step's bytes and closures as the
/// budget: simplification is deterministic, deepest first, so it stops
/// there), and fully simplified. Also the authored material in `*full`, the
/// reference of the errors. False with the diagnostics of the (last) compile
/// that failed in `diags`.
bool simplificationSteps(const std::string& path, const std::string& text, const CompileOptions& base,
                         std::vector<Step>* steps, CompileResult* full, Diagnostics& diags);

struct Row {
  std::string label;
  int budget = 0, bytes = 0, closures = 0;
  /// False for an authored tree the storage format cannot hold (more than
  /// packfmt::kMaxClosures closures): no code, so no instructions and no time
  /// (null in JSON, "—" in the table, not plotted, never chosen by --max-error).
  bool gpuMeasured = true;
  std::size_t spirvInstructions = 0;  // forward shader (GLSL), after SPIRV-Tools' performance passes
  double gpuNsPerPixel = 0;           // median of the timed dispatches, lighting one point (1 light + environment)
  double relMse = 0;                  // mean((x − y)² / (y² + 0.01)) over the probe set, y the unsimplified tree
  double maxAbs = 0, p99Abs = 0;      // of |x − y|
  double deltaE2000Mean = 0, deltaE2000Max = 0;  // packed vs exact colours (diffuse albedo, F0, F90, fuzz colour)
  /// The accuracy metric (docs/accuracy.md) of the row's analytic model
  /// against the truth of the authored material (what the artist made) and
  /// against the truth of the row's own closures (what the approximation
  /// makes of them); empty when Options::truthSamples is 0.
  std::optional<accuracy::Comparison> vsAuthoredTruth, vsOwnTruth;
  /// Options::precision Half only: the half-precision forward kernel's lit
  /// radiance (direct + environment + emissive) against the float32 one's on
  /// lavapipe over the same probes (sweep/precision.h).
  std::optional<double> relMseVsFloat32, maxAbsVsFloat32;
};

struct Options {
  int pixels = 1 << 20;  // shading points per timed dispatch
  int timedRuns = 5;     // after one untimed warm-up; the median is reported
  DiffuseModel diffuseModel = kDefaultDiffuseModel;
  /// Walks of the truths (accuracy::Options::samples and evalSamples); 0
  /// samples: no truth columns. Smaller than `accuracy`'s defaults: a sweep
  /// walks one truth per distinct row.
  int truthSamples = 8192, truthEvalSamples = 512;
  int truthThreads = 0;  // 0: the machine's; the figures do not depend on it
  Precision precision = Precision::Float;  // of the timed kernels and the counted forward shader
};

/// Median lavapipe time per invocation of `r`'s throughput kernel with `emit`
/// (a surface's: one shading point; a volume's: one ray, EmitOptions::volumeSteps)
/// over options.pixels invocations (whole groups), options.timedRuns runs after
/// one warm-up.
bool nsPerInvocation(gpu::Context& gpu, const CompileResult& r, const EmitOptions& emit, const Options& options,
                     double* ns, Diagnostics& diags);

/// Measures every step. `gpu` runs the timing kernels. False, with errors reported, on a failure.
bool measure(gpu::Context& gpu, const std::vector<Step>& steps, const CompileResult& full, const Options& options,
             std::vector<Row>* rows, Diagnostics& diags);

/// The cheapest measured row (fewest bytes, then fewest ns per pixel) whose
/// rel_mse is at most `maxError`, if any.
std::optional<std::size_t> cheapestWithin(const std::vector<Row>& rows, double maxError);

/// Outputs: a text table, `{"material": ..., "rows": [...]}`, CSV, and an SVG
/// plot of error (rel_mse, log scale) against cost (ns per pixel), one
/// labelled point per row.
std::string formatTable(const std::string& material, const std::vector<Row>& rows);
/// The table's columns after row, budget, bytes and closures (float
/// precision's), and a row's cells for them, as formatTable prints them:
/// what another page of the rows (the HTML report) shows.
std::vector<std::string> cellColumns();
std::vector<std::string> cells(const Row& r);
std::string formatJson(const std::string& material, const std::vector<Row>& rows);
std::string formatCsv(const std::vector<Row>& rows);
std::string plotSvg(const std::string& material, const std::vector<Row>& rows);

/// A plot of error (log scale) against cost: `title` (": error against cost"
/// is added), the axes' names and one labelled point per measured setting.
/// The surface sweep's plotSvg and the volume sweep's plotVolumeSvg draw one.
struct PlotPoint {
  std::string label;
  double cost = 0;   // x: linear
  double error = 0;  // y: log10, floored at 1e-8
};
struct Plot {
  std::string title, costAxis, errorAxis;
  std::vector<PlotPoint> points;
};
std::string plotSvg(const Plot& plot);

/// The plot's canvas (its viewBox is 0 0 kPlotWidth kPlotHeight) and the
/// estimate of a text's extent every label is placed from: kPlotGlyphWidth
/// font sizes per code point (wider than sans-serif's average glyph), a font
/// size above the baseline and a quarter of one below. Every text of plotSvg
/// lies inside the canvas by this estimate.
inline constexpr double kPlotWidth = 640, kPlotHeight = 400, kPlotGlyphWidth = 0.62;
double plotTextWidth(std::string_view text, double fontSize);

/// mean((x − y)² / (y² + 0.01)): the sweep's rel_mse of x against the reference y.
double relMse(const std::vector<double>& x, const std::vector<double>& y);

/// CIEDE2000 between two CIELAB colours (Sharma, Wu & Dalal 2005).
double deltaE2000Lab(const std::array<double, 3>& lab1, const std::array<double, 3>& lab2);
/// The same between two linear-sRGB colours (through XYZ, D65, and CIELAB).
double deltaE2000(const std::array<double, 3>& linearA, const std::array<double, 3>& linearB);

}  // namespace substratec::sweep
