// A small SPIR-V reflector for the GPU harness: lists the descriptor bindings an
// entry point uses (set, binding, name, descriptor kind, image dimension) and a
// compute entry point's LocalSize, straight from the module's words. It knows
// exactly the descriptor kinds the harness can bind; anything else is an error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "diag/diagnostics.h"

namespace substratec::gpu {

/// The Vulkan descriptor type a binding needs.
enum class DescriptorKind {
  UniformBuffer,         // storage class Uniform, struct decorated Block
  StorageBuffer,         // storage class StorageBuffer (Block), or Uniform with BufferBlock
  CombinedImageSampler,  // OpTypeSampledImage
  SampledImage,          // OpTypeImage Sampled=1 (separate texture, HLSL Texture2D)
  StorageImage,          // OpTypeImage Sampled=2
  Sampler,               // OpTypeSampler (HLSL SamplerState)
};

/// An image's SPIR-V Dim (None for buffers and samplers).
enum class ImageDim { None, Dim1D, Dim2D, Dim3D, Cube, Rect, Buffer, SubpassData };

/// One descriptor binding of the entry point.
struct DescriptorBinding {
  uint32_t set = 0;
  uint32_t binding = 0;
  std::string name;  // the variable's OpName (may be empty)
  DescriptorKind kind = DescriptorKind::UniformBuffer;
  ImageDim dim = ImageDim::None;
  bool arrayed = false;       // image type's Arrayed operand
  uint32_t count = 1;         // descriptor array size (0: runtime-sized array)
  uint32_t imageFormat = 0;   // SPIR-V ImageFormat of a StorageImage (0 = Unknown, 1 = Rgba32f, 33 = R32ui)
};

/// What the harness needs to know about a module.
struct ShaderReflection {
  std::string entryPoint;                   // name of the (first) entry point
  uint32_t executionModel = 0;              // SPIR-V ExecutionModel (5 = GLCompute)
  uint32_t localSize[3] = {0, 0, 0};        // OpExecutionMode LocalSize (compute only)
  std::vector<DescriptorBinding> bindings;  // sorted by (set, binding)
};

/// Reflects the first OpEntryPoint of `words`. For SPIR-V >= 1.4 only variables in its interface
/// are listed (earlier versions list interface-less globals, so every decorated variable is).
/// False, with an error reported, on a malformed module or a descriptor the harness cannot describe.
bool reflectSpirv(const std::vector<uint32_t>& words, ShaderReflection* out, Diagnostics& diags);

/// "UniformBuffer", "StorageImage", ...
const char* descriptorKindName(DescriptorKind kind);

}  // namespace substratec::gpu
