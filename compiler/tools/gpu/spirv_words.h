// The SPIR-V words the harness' two module readers share (spirv_reflect.cc: descriptor bindings;
// block_layout.cc: a block's member offsets): opcodes, decorations and enumerants from the SPIR-V
// 1.6 specification, and literal-string decoding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace substratec::gpu::spirv {

enum : uint32_t {
  kOpName = 5,
  kOpMemberName = 6,
  kOpEntryPoint = 15,
  kOpExecutionMode = 16,
  kOpTypeImage = 25,
  kOpTypeSampler = 26,
  kOpTypeSampledImage = 27,
  kOpTypeArray = 28,
  kOpTypeRuntimeArray = 29,
  kOpTypeStruct = 30,
  kOpTypePointer = 32,
  kOpConstant = 43,
  kOpVariable = 59,
  kOpDecorate = 71,
  kOpMemberDecorate = 72,
  kDecorationBlock = 2,
  kDecorationBufferBlock = 3,
  kDecorationBinding = 33,
  kDecorationDescriptorSet = 34,
  kDecorationOffset = 35,
  kExecutionModeLocalSize = 17,
  kStorageUniformConstant = 0,
  kStorageUniform = 2,
  kStorageStorageBuffer = 12,
  kSpirvMagic = 0x07230203,
};

/// A literal string operand: nul-terminated, packed little-endian into at most `words` words at `w`.
inline std::string literalString(const uint32_t* w, std::size_t words) {
  std::string s;
  for (std::size_t i = 0; i < words; ++i)
    for (int b = 0; b < 4; ++b) {
      const char c = static_cast<char>((w[i] >> (8 * b)) & 0xffu);
      if (c == '\0') return s;
      s += c;
    }
  return s;
}

}  // namespace substratec::gpu::spirv
