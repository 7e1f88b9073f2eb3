// Running a compiled material on lavapipe next to the CPU reference
// (gpu/sample_run.h runs the kernels): input sets, the reference's view of a
// sample, the kernels' closure dumps, and the comparison rule of the GPU tests.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "emit/kernel_emitter.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace substratec::gputest {

using gpu::floatsOf;
using gpu::kTextureSize;
using gpu::makeSamples;
using gpu::resultStride;
using gpu::Sample;
using gpu::sampleBuffer;
using gpu::sampleTexture;
using gpu::textureTexels;

/// Input values: set 0 is every default; the others draw each input inside
/// its declared range (colours in [0, 1], others around the default).
std::vector<reference::InputValues> makeInputSets(const Material& m, int count, uint32_t seed);

/// The resources of one sample-kernel dispatch with input set `inputs`.
inline gpu::Resources kernelResources(const Material& m, const gpu::ShaderReflection& reflection,
                                      const std::vector<uint32_t>& spirv, const reference::InputValues& inputs,
                                      const std::vector<std::byte>& samples, std::size_t resultFloats) {
  return gpu::kernelResources(m, reflection, spirv, inputs.values, samples, resultFloats);
}

/// The reference's view of one sample, in precision T: closures and the
/// lit sums the sample kernels write (kernel_emitter.h's result layout).
template <class T>
struct Shaded {
  reference::MaterialResult<T> material;
  std::array<T, 3> direct{}, environment{}, emissive{};
};
template <class T>
Shaded<T> shade(const CompileResult& r, const Sample& s, const reference::InputValues& in, int diffuseModel);

/// How much the direct light of `shaded` (the double reference of `s`) moves
/// when the lighting's inputs move by float rounding: the glint lobe hashes its
/// uv cell and H's slope bin (floor()s), so a closure with glints is
/// discontinuous at float resolution, which |ref32 − ref64| cannot see. Per
/// channel, the largest change over nudges of V, L (1e-6 rad) and the glint uv
/// (2^-22 relative); zero for a material without glints.
std::array<double, 3> glintSpread(const Shaded<double>& shaded, const Sample& s, int diffuseModel);

/// The reference's lighting of closures read back from the GPU (the deferred
/// path: what the unpacker produced), in precision T.
template <class T>
Shaded<T> lightClosures(const std::vector<reference::Closure<double>>& closures, const Sample& s, int diffuseModel);

/// Closure `k` of sample `i` as the kernel of `r` wrote it, with the kernel's
/// switches the results do not hold: SUBSTRATE_USE_METALNESS_MIX
/// (Material::metalnessMix) and SUBSTRATE_USE_CONDUCTOR_CURVE (usesConductorCurve).
reference::Closure<double> closureFromResults(const std::vector<float>& results, int stride, int i, int k,
                                              const CompileResult& r);

/// The GPU tests' comparison rule: |gpu − ref64| ≤ k·|ref32 − ref64| + abs + rel·|ref64|.
struct Tolerance {
  double k = 8, abs = 2e-4, rel = 2e-3;
  bool ok(double gpu, double ref64, double ref32) const {
    double d = gpu - ref64;
    if (d < 0) d = -d;
    double c = ref32 - ref64;
    if (c < 0) c = -c;
    double r = ref64 < 0 ? -ref64 : ref64;
    return d <= k * c + abs + rel * r;
  }
};

/// The process's lavapipe context (created once; null, with its creation's error reported).
gpu::Context* sharedContext(Diagnostics& diags);

}  // namespace substratec::gputest
