// The members of a uniform block as a SPIR-V module lays them out: names and
// byte offsets, straight from OpMemberName and OpMemberDecorate Offset. Hosts
// fill a material's inputs block from this, because GLSL's std140 and HLSL's
// cbuffer packing place the same members differently (a float3 after a float,
// for instance), and the module is the authority on what its code reads.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "ir/material.h"

namespace substratec::gpu {

struct BlockMember {
  std::string name;     // OpMemberName (empty when the module has no names)
  uint32_t offset = 0;  // bytes from the start of the block
};

/// The members, in declaration order, of the block variable decorated with
/// DescriptorSet `set` and Binding `binding`; empty if there is none.
std::vector<BlockMember> blockMembers(const std::vector<uint32_t>& spirv, uint32_t set, uint32_t binding);

/// The bytes of material `m`'s inputs block (set 1, binding 0 of the generated
/// code) laid out as `members` says: each member named after an input (GLSL
/// `i_<input>`, HLSL `<material>_i_<input>`) gets `values[input]` (or the
/// input's default when `values` is empty), as 32-bit floats; the size is
/// rounded up to 16 bytes.
std::vector<std::byte> inputBlockBytes(const Material& m, const std::vector<BlockMember>& members,
                                       const std::vector<std::array<double, 4>>& values);

/// The index of the input a resource or member of the generated code is named
/// after (`t_<input>`, `s_<input>`, `i_<input>`, `<material>_i_<input>`), or -1.
int inputOfResource(const Material& m, const std::string& name);

}  // namespace substratec::gpu
