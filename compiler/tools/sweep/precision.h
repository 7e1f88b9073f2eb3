// Half precision against float32 on lavapipe: one material's forward sample
// kernel (emit/kernel_emitter.h: closures evaluated and lit inline, one light
// and a split-sum environment) compiled with EmitOptions::precision Float and
// Half, run over the same samples and inputs, and how far the half-precision
// lit radiance is from the float32 one. `substratec sweep --precision half`,
// bench/shader_cost.cc (table 5) and tests/gpu/stability_test.cc use it
// (docs/stability.md, "Half precision").
#pragma once
#include <array>
#include <string>
#include <vector>

#include "emit/syntax.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "pipeline/pipeline.h"

namespace substratec::sweep {

/// The forward kernel's results in each precision (kernel_emitter.h's result
/// layout: gpu::resultStride(r) floats per sample).
struct BothPrecisions {
  std::vector<float> float32, half;
};

/// Runs the forward kernel of `r` for `target` in both precisions over
/// `samples` (a multiple of kernel::kLocalSize) with `inputValues` (empty:
/// defaults). False, with errors reported (a kernel that does not validate, a failed
/// dispatch, or a device without shaderFloat16).
bool runBothPrecisions(gpu::Context& ctx, const CompileResult& r, Target target, const std::vector<gpu::Sample>& samples,
                       const std::vector<std::array<double, 4>>& inputValues, BothPrecisions* out, Diagnostics& diags);

/// Per sample and channel, the radiance the forward pass writes: direct +
/// environment + emissive (kResultDirect, kResultEnvironment, kResultEmissive).
std::vector<double> litRadiance(const std::vector<float>& results, int stride);

struct PrecisionError {
  double relMse = 0;  // sweep's rel_mse (relMse) of half's lit radiance against float32's
  double maxAbs = 0;  // the largest |half − float32| of it
};
PrecisionError precisionError(const BothPrecisions& results, int stride);

}  // namespace substratec::sweep
