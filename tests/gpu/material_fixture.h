// Running a compiled material on lavapipe next to the CPU reference: the
// sample set, the material's resources (inputs block, procedural textures,
// energy tables), the kernels' result layout (emit/kernel_emitter.h) and the
// comparison rule of the GPU tests.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "emit/kernel_emitter.h"
#include "gpu/harness.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace substratec::gputest {

/// One shading point and its lighting, as the sample kernels read it.
struct Sample {
  reference::Geometry geometry;
  std::array<double, 3> light{0, 0, 1};     // unit, toward the light
  std::array<double, 3> radiance{1, 1, 1};  // of the light
  std::array<double, 3> prefiltered{0, 0, 0};
  std::array<double, 3> irradiance{0, 0, 0};
};

inline constexpr int kTextureSize = 16;

/// `count` samples (a multiple of kernel::kLocalSize) from a fixed seed: normals
/// and tangents all around, views from head-on to 1e-4 from grazing (and a few
/// just behind the surface), lights above and below the horizon, uvs inside
/// texels of kTextureSize-texel textures (never on a texel edge), dithers in [0, 1).
std::vector<Sample> makeSamples(int count, uint32_t seed);

/// The kernel's sample buffer for `samples`.
std::vector<std::byte> sampleBuffer(const std::vector<Sample>& samples);

/// Input values: set 0 is every default; the others draw each input inside
/// its declared range (colours in [0, 1], others around the default).
std::vector<reference::InputValues> makeInputSets(const Material& m, int count, uint32_t seed);

/// The procedural kTextureSize² RGBA texture bound to texture input `input`
/// (smooth gradients and a checker, values in [0, 1]), and its nearest/repeat lookup.
std::vector<float> textureTexels(int input);
std::array<double, 4> sampleTexture(int input, double u, double v);

/// The resources of one kernel dispatch: the inputs block filled from the
/// module's own member offsets (GLSL std140 and HLSL cbuffer packing differ),
/// the textures and samplers by name, the energy tables, the samples, and an
/// output buffer of `resultFloats` floats.
gpu::Resources kernelResources(const Material& m, const gpu::ShaderReflection& reflection,
                               const std::vector<uint32_t>& spirv, const reference::InputValues& inputs,
                               const std::vector<std::byte>& samples, std::size_t resultFloats);

/// Floats per sample in a sample kernel's results.
int resultStride(const CompileResult& r);

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

/// Closure `k` of sample `i` as the kernel wrote it.
reference::Closure<double> closureFromResults(const std::vector<float>& results, int stride, int i, int k);

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

/// Reads a float result buffer back from a BufferResource.
std::vector<float> floatsOf(const gpu::Resources& resources, uint32_t set, uint32_t binding);

/// The process's lavapipe context (created once; null with `error` set).
gpu::Context* sharedContext(std::string* error);

}  // namespace substratec::gputest
