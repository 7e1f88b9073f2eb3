#include "sweep/precision.h"

#include <algorithm>
#include <cmath>

#include "emit/kernel_emitter.h"
#include "sweep/sweep.h"

namespace substratec::sweep {

bool runBothPrecisions(gpu::Context& ctx, const CompileResult& r, Target target, const std::vector<gpu::Sample>& samples,
                       const std::vector<std::array<double, 4>>& inputValues, BothPrecisions* out, Diagnostics& diags) {
  EmitOptions emit;
  emit.precision = Precision::Float;
  if (!gpu::runSampleKernel(ctx, r, target, KernelMode::Forward, emit, samples, inputValues, &out->float32, diags))
    return false;
  emit.precision = Precision::Half;
  return gpu::runSampleKernel(ctx, r, target, KernelMode::Forward, emit, samples, inputValues, &out->half, diags);
}

std::vector<double> litRadiance(const std::vector<float>& results, int stride) {
  using namespace kernel;
  std::vector<double> rgb;
  const std::size_t count = results.size() / static_cast<std::size_t>(stride);
  rgb.reserve(count * 3);
  for (std::size_t i = 0; i < count; ++i) {
    const float* s = &results[i * static_cast<std::size_t>(stride)];
    for (int c = 0; c < 3; ++c)
      rgb.push_back(static_cast<double>(s[kResultDirect + c]) + s[kResultEnvironment + c] + s[kResultEmissive + c]);
  }
  return rgb;
}

PrecisionError precisionError(const BothPrecisions& results, int stride) {
  const std::vector<double> f = litRadiance(results.float32, stride), h = litRadiance(results.half, stride);
  PrecisionError e;
  e.relMse = relMse(h, f);
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double d = std::abs(h[i] - f[i]);
    e.maxAbs = std::isnan(d) || std::isnan(e.maxAbs) ? NAN : std::max(e.maxAbs, d);  // a NaN shows
  }
  return e;
}

}  // namespace substratec::sweep
