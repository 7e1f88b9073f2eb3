// Running a compiled material's sample kernels (emit/kernel_emitter.h) on
// lavapipe: the sample set, the material's resources (inputs block,
// procedural textures, energy tables) and the result buffer. Used by the GPU
// tests (against the CPU reference) and by `substratec sweep`.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "emit/kernel_emitter.h"
#include "gpu/harness.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"

namespace substratec::gpu {

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

/// The procedural kTextureSize² RGBA texture bound to texture input `input`
/// (smooth gradients and a checker, values in [0, 1]), and its nearest/repeat lookup.
/// The stress set: decoded as a tangent-space normal map (2·rgb − 1) half of
/// its texels point below the surface (b = 0.2 gives z = −0.6).
std::vector<float> textureTexels(int input);
std::array<double, 4> sampleTexture(int input, double u, double v);

/// Which texels the harness binds to a material's texture inputs.
enum class TextureSet : std::uint8_t {
  Checker,  // textureTexels: gradients and a checker (the GPU tests, `stability --stress-textures`)
  Neutral,  // each texture at rest, by its role (neutralTexel): what `stability` runs by default
};
std::string_view textureSetName(TextureSet set);  // "checker", "neutral"

/// What a texture input feeds, found on the value DAG: a texture that reaches
/// a slab's `normal` pin (or the normal of a helper: thin_film,
/// rotation_to_tangent, view_dependent_coverage) is a normal map; one that
/// reaches only `tangent` pins is a direction map; anything else is a colour
/// (colours, scalars packed in channels, masks, specular profiles).
enum class TextureRole : std::uint8_t { Colour, Normal, Tangent };
/// One role per Material::inputs entry (Colour for inputs that are not textures).
std::vector<TextureRole> textureRoles(const Material& m);

/// A texture at rest: a normal map's flat texel (0.5, 0.5, 1, 1), which
/// decodes to the geometric normal; a direction map's (1, 0.5, 0.5, 1), which
/// decodes to the geometric tangent (read as glTF's anisotropy texture: the
/// tangent direction at half strength); a colour's mid-grey (0.5, 0.5, 0.5)
/// with alpha 1 (fully present).
std::array<double, 4> neutralTexel(TextureRole role);

/// The CPU reference's texture lookup of `set` for material `m` (sampleTexture
/// for Checker; each input's neutralTexel for Neutral).
reference::TextureFn textureFunction(const Material& m, TextureSet set);

/// The resources of one sample-kernel dispatch: the inputs block filled from
/// the module's own member offsets (GLSL std140 and HLSL cbuffer packing
/// differ) with `inputValues` (empty: defaults), the textures (of `textures`)
/// and samplers by name, the energy tables, the samples, and an output buffer
/// of `resultFloats` floats.
Resources kernelResources(const Material& m, const ShaderReflection& reflection, const std::vector<uint32_t>& spirv,
                          const std::vector<std::array<double, 4>>& inputValues, const std::vector<std::byte>& samples,
                          std::size_t resultFloats, TextureSet textures = TextureSet::Checker);

/// Floats per sample in a sample kernel's results.
int resultStride(const CompileResult& r);

/// Reads a float result buffer back from a BufferResource.
std::vector<float> floatsOf(const Resources& resources, uint32_t set, uint32_t binding);

/// False, reporting why, when kernels of `precision` cannot run on `ctx`: Half
/// needs shaderFloat16.
bool canRun(const Context& ctx, Precision precision, Diagnostics& diags);

/// Compiles the material's `mode` kernel for `target` with `emit` (compileKernel)
/// into `*spirv` and builds its pipeline. Null, reporting "internal compiler
/// error: the <what> kernel does not validate" and the log (a compiler bug) or
/// the pipeline's failure.
std::unique_ptr<ComputePipeline> kernelPipeline(Context& ctx, const CompileResult& r, Target target, KernelMode mode,
                                                const EmitOptions& emit, const char* what, std::vector<uint32_t>* spirv,
                                                Diagnostics& diags);

/// Compiles the material's `mode` sample kernel (Forward or Deferred) for
/// `target` with `emit` (kernelPipeline) and runs it once over `samples` (a
/// multiple of kernel::kLocalSize) with `inputValues` (empty: defaults):
/// `*results` holds resultStride(r) floats per sample. False, with errors
/// reported, when the kernel does not validate or the dispatch fails.
bool runSampleKernel(Context& ctx, const CompileResult& r, Target target, KernelMode mode, const EmitOptions& emit,
                     const std::vector<Sample>& samples, const std::vector<std::array<double, 4>>& inputValues,
                     std::vector<float>* results, Diagnostics& diags);

}  // namespace substratec::gpu
