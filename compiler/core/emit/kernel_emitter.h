// Compute kernels that run a generated material over a buffer of shading
// samples (tests against the CPU reference) or over the pixels of a sphere
// (`substratec preview`). They include the material file and the runtime
// exactly as the forward and base-pass entries do, and differ from them only
// in where the shading point comes from and where the result goes. One
// emitter, both languages: the body is written in the runtime's common dialect
// (runtime_shaders/README.md); only resources and the entry signature go
// through the Syntax table.
//
// Bindings, set 0 (set 1 is the material's: its inputs block and textures):
//   1, 2  envPrefiltered, envIrradiance (cube maps; preview only; HLSL
//         samples them with the sampler at 3)
//   5     the runtime's energy tables (substrate_energy_lut.h)
//   0     preview parameters (SubstratePreview below; preview only)
//   6     samples: kSampleVec4s float4 per sample (sample kernels only)
//   (Throughput reads nothing but the material's resources and the tables)
//   7     results: floats, see below
//   8     per-sample inputs (sample kernels with perSampleInputs only): one float4
//         per non-texture material input (material order) per sample; the
//         material is then emitted with EmitOptions::inputsPerInvocation
#pragma once
#include <string>

#include "emit/material_emitter.h"

namespace substratec {

enum class KernelMode {
  Forward,   // evaluate, then light the closures inline (the forward pass)
  Deferred,  // evaluate, pack into the uint stream, unpack generically, then light (base pass + deferred lighting)
  Preview,   // a sphere, the key light and a split-sum environment, one RGBA float4 per pixel
  Throughput,  // cost: each invocation hashes its own shading point, evaluates, lights it (one light and a
               // constant split-sum environment) and writes one float4 (results[i]): no input buffer to read;
               // a volume's: one hashed ray marched in EmitOptions::volumeSteps steps (kVolumeCostExtent)
};

/// Sample layout (float4 index within a sample; `kSampleVec4s` per sample).
namespace kernel {
inline constexpr int kLocalSize = 64;  // threads per group: pad the sample count to a multiple of it
inline constexpr int kSampleVec4s = 11;
inline constexpr int kSamplePosition = 0;      // xyz: world position; w: the dither in [0, 1)
inline constexpr int kSampleNormal = 1;        // xyz: vertex normal (normalized by the kernel)
inline constexpr int kSampleTangent = 2;       // xyz: vertex tangent (made orthogonal by the kernel)
inline constexpr int kSampleView = 3;          // xyz: unit direction to the eye
inline constexpr int kSampleLight = 4;         // xyz: unit direction to the light
inline constexpr int kSampleUv = 5;            // xy: uv0, zw: uv1
inline constexpr int kSampleColor = 6;         // vertex colour
inline constexpr int kSampleUvDerivatives = 7; // d(uv0)/dx in xy, d(uv0)/dy in zw
inline constexpr int kSampleRadiance = 8;      // rgb: the light's radiance
inline constexpr int kSamplePrefiltered = 9;   // rgb: prefiltered environment radiance for every closure (split sum)
inline constexpr int kSampleIrradiance = 10;   // rgb: environment irradiance for every closure

/// Result layout (floats per sample: kResultHeaderFloats + kClosureFloats * closure count).
inline constexpr int kResultHeaderFloats = 20;
inline constexpr int kResultCount = 0;           // closure count (the unpacker's, in Deferred)
inline constexpr int kResultCoverage = 1;
inline constexpr int kResultLayoutClass = 2;     // Deferred: the class the base pass packed (word 0 bits 0-1); else 0
inline constexpr int kResultTransmittance = 4;   // rgb
inline constexpr int kResultDirect = 8;          // rgb: sum over closures of substrate_light_closure
inline constexpr int kResultEnvironment = 12;    // rgb: sum of view throughput * substrate_env_split_sum
inline constexpr int kResultEmissive = 16;       // rgb: sum of view throughput * emissive (Forward only; 0 in Deferred),
                                                 // and a single-layer water's body (substrate_water_seen) behind
                                                 // which lies the sample's prefiltered radiance kWaterSampleDepth
                                                 // metres below the surface
inline constexpr double kWaterSampleDepth = 0.5;
/// Each closure's SubstrateClosure fields, in this order (floats):
inline constexpr int kClosureFloats = 69;
inline constexpr int kClosureDiffuseAlbedo = 0, kClosureF0 = 3, kClosureF90 = 6, kClosureRoughness = 9,
                     kClosureAnisotropy = 10, kClosureN = 11, kClosureT = 14, kClosureSssMfp = 17,
                     kClosureSssPhase = 20, kClosureSssType = 21, kClosureSecondRoughness = 22,
                     kClosureSecondRoughnessWeight = 23, kClosureFuzzAmount = 24, kClosureFuzzColor = 25,
                     kClosureFuzzRoughness = 28, kClosureGlintValue = 29, kClosureGlintUv = 30,
                     kClosureGlintUvDerivatives = 32, kClosureSpecularProfile = 36, kClosureEmissive = 37,
                     kClosureWeight = 40, kClosureTopTransmittance = 41, kClosureCoverageAbove = 44,
                     kClosureFeatures = 45, kClosureIsTop = 46, kClosureExtraInterfaces = 47,
                     kClosureCoatFloor = 48, kClosureCoatInterface = 49,
                     kClosureCoatStretch = 50, kClosureCoatTangent = 52, kClosureCoatShare = 55,
                     kClosureHair = 56, kClosureIrisN = 60, kClosureIrisPlaneN = 63, kClosureIris = 66,
                     kClosureCoversLayers = 68;

/// Preview parameters (set 0, binding 0, std140 / cbuffer, float4 each):
///   camera: xyz eye position, w tan(vertical half field of view)
///   viewport: x width, y height (pixels), z mip count of envPrefiltered, w exposure (unused by the kernel)
///   lightDirection[kPreviewLights] (xyz, unit, toward the light), lightRadiance[kPreviewLights] (rgb)
/// The sphere has radius 1 at the origin, +Y up, the camera looks at the origin.
/// One light, `render`'s (issue 20, part 4: preview lights as render does;
/// it had a fill and a rim light too).
inline constexpr int kPreviewLights = 1;
inline constexpr int kPreviewParamVec4s = 2 + 2 * kPreviewLights;
/// The preview's specular profiles (specularProfileInputs order): profile k is
/// the texture p_<input> at set 1, binding kPreviewProfileBinding + k (HLSL's
/// sampler ps_<input> at 16 more), above the material's own textures.
inline constexpr int kPreviewProfileBinding = 40;
/// A volume's preview (isVolumeMaterial): the cube [-extent, extent]^3 around
/// the origin, marched in kVolumePreviewSteps steps, each lit by the key light
/// through kVolumePreviewShadowSteps steps toward it (same resources as the sphere's).
inline constexpr double kVolumePreviewExtent = 1.2;
inline constexpr int kVolumePreviewSteps = 48;
inline constexpr int kVolumePreviewShadowSteps = 8;
/// A volume's cost kernel (KernelMode::Throughput, EmitOptions::volumeSteps
/// steps, clamped to [1, kMaxVolumeSteps]): rays through the cube
/// [-extent, extent]^3, the one `accuracy` measures the march in.
inline constexpr double kVolumeCostExtent = 2.0;
inline constexpr int kMaxVolumeSteps = 4096;
}  // namespace kernel

/// The kernel source; it includes "<name>.material.{glsl,hlsl}" and the runtime.
/// emit.inputsPerInvocation (Forward and Deferred only): inputs from binding 8,
/// see above; emit.precision: the runtime's (every mode lights closures).
std::string emitKernel(const Material& m, const StorageLayout& layout, const Syntax& syn, KernelMode mode,
                       const EmitOptions& emit = {});

/// `<name>.<mode>.comp` / `<name>.<mode>.cs.hlsl` (mode: forward_samples, deferred_samples, preview, throughput).
/// A volume (isVolumeMaterial) has Preview and Throughput kernels only.
std::string kernelFileName(const Material& m, const Syntax& syn, KernelMode mode);

}  // namespace substratec
