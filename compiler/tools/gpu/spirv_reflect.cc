// SPIR-V descriptor reflection for the GPU harness (see spirv_reflect.h).
#include "gpu/spirv_reflect.h"

#include <algorithm>
#include <map>
#include <set>

namespace substratec::gpu {
namespace {

// Opcodes, decorations and enumerants from the SPIR-V 1.6 specification.
enum : uint32_t {
  kOpName = 5,
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
  kDecorationBlock = 2,
  kDecorationBufferBlock = 3,
  kDecorationBinding = 33,
  kDecorationDescriptorSet = 34,
  kExecutionModeLocalSize = 17,
  kStorageUniformConstant = 0,
  kStorageUniform = 2,
  kStorageStorageBuffer = 12,
  kSpirvMagic = 0x07230203,
};

/// Decodes a nul-terminated literal string starting at words[begin] (at most `end`).
std::string literalString(const std::vector<uint32_t>& words, size_t begin, size_t end) {
  std::string s;
  for (size_t i = begin; i < end; ++i) {
    for (int b = 0; b < 4; ++b) {
      const char c = static_cast<char>((words[i] >> (8 * b)) & 0xffu);
      if (c == '\0') return s;
      s.push_back(c);
    }
  }
  return s;
}

/// Words of a literal string (including its terminating nul) starting at words[begin].
size_t literalStringWords(const std::vector<uint32_t>& words, size_t begin, size_t end) {
  for (size_t i = begin; i < end; ++i)
    if ((words[i] & 0xff000000u) == 0 || (words[i] & 0xff0000u) == 0 || (words[i] & 0xff00u) == 0 ||
        (words[i] & 0xffu) == 0)
      return i - begin + 1;
  return end - begin;
}

struct Decorations {
  bool block = false, bufferBlock = false;
  bool hasSet = false, hasBinding = false;
  uint32_t set = 0, binding = 0;
};

}  // namespace

const char* descriptorKindName(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::UniformBuffer: return "UniformBuffer";
    case DescriptorKind::StorageBuffer: return "StorageBuffer";
    case DescriptorKind::CombinedImageSampler: return "CombinedImageSampler";
    case DescriptorKind::SampledImage: return "SampledImage";
    case DescriptorKind::StorageImage: return "StorageImage";
    case DescriptorKind::Sampler: return "Sampler";
  }
  return "?";
}

bool reflectSpirv(const std::vector<uint32_t>& words, ShaderReflection* out, std::string* error) {
  *out = ShaderReflection{};
  if (words.size() < 5 || words[0] != kSpirvMagic) {
    *error = "not a SPIR-V module (missing header or wrong magic number)";
    return false;
  }
  const uint32_t version = words[1];
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, Decorations> decorations;
  std::map<uint32_t, std::vector<uint32_t>> types;  // result id -> the type instruction's words (opcode first)
  std::map<uint32_t, uint32_t> constants;           // result id -> first value word
  struct Variable { uint32_t id, pointerType, storage; };
  std::vector<Variable> variables;
  bool haveEntry = false;
  uint32_t entryId = 0;
  std::set<uint32_t> interface;

  for (size_t at = 5; at < words.size();) {
    const uint32_t count = words[at] >> 16, op = words[at] & 0xffffu;
    if (count == 0 || at + count > words.size()) {
      *error = "malformed SPIR-V: bad instruction word count at word " + std::to_string(at);
      return false;
    }
    const size_t end = at + count;
    const uint32_t* w = &words[at];
    if (op == kOpName && count >= 3) {
      names[w[1]] = literalString(words, at + 2, end);
    } else if (op == kOpEntryPoint && count >= 4 && !haveEntry) {
      haveEntry = true;
      out->executionModel = w[1];
      entryId = w[2];
      out->entryPoint = literalString(words, at + 3, end);
      for (size_t i = at + 3 + literalStringWords(words, at + 3, end); i < end; ++i) interface.insert(words[i]);
    } else if (op == kOpExecutionMode && count >= 6 && haveEntry && w[1] == entryId && w[2] == kExecutionModeLocalSize) {
      std::copy(w + 3, w + 6, out->localSize);
    } else if (op == kOpDecorate && count >= 3) {
      Decorations& d = decorations[w[1]];
      if (w[2] == kDecorationBlock) d.block = true;
      if (w[2] == kDecorationBufferBlock) d.bufferBlock = true;
      if (w[2] == kDecorationDescriptorSet && count >= 4) d.hasSet = true, d.set = w[3];
      if (w[2] == kDecorationBinding && count >= 4) d.hasBinding = true, d.binding = w[3];
    } else if ((op >= kOpTypeImage && op <= kOpTypeStruct) || op == kOpTypePointer) {
      if (count >= 2) {
        std::vector<uint32_t>& t = types[w[1]] = std::vector<uint32_t>(w, w + count);
        t[0] = op;
      }
    } else if (op == kOpConstant && count >= 4) {
      constants[w[2]] = w[3];
    } else if (op == kOpVariable && count >= 4) {
      variables.push_back({w[2], w[1], w[3]});
    }
    at = end;
  }
  if (!haveEntry) {
    *error = "SPIR-V module has no OpEntryPoint";
    return false;
  }

  auto typeOf = [&](uint32_t id) -> const std::vector<uint32_t>* {
    auto it = types.find(id);
    return it == types.end() ? nullptr : &it->second;
  };
  for (const Variable& v : variables) {
    const Decorations& d = decorations[v.id];
    if (!d.hasSet || !d.hasBinding) continue;
    if (version >= 0x00010400 && !interface.count(v.id)) continue;
    DescriptorBinding b;
    b.set = d.set;
    b.binding = d.binding;
    b.name = names.count(v.id) ? names[v.id] : std::string();
    const std::string where = "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" +
                              b.name + "')";
    const std::vector<uint32_t>* ptr = typeOf(v.pointerType);
    if (!ptr || (*ptr)[0] != kOpTypePointer || ptr->size() < 4) {
      *error = "malformed SPIR-V: variable at " + where + " does not have a pointer type";
      return false;
    }
    const std::vector<uint32_t>* t = typeOf((*ptr)[3]);
    if (t && ((*t)[0] == kOpTypeArray || (*t)[0] == kOpTypeRuntimeArray) && t->size() >= 3) {
      b.count = (*t)[0] == kOpTypeRuntimeArray ? 0 : (t->size() >= 4 && constants.count((*t)[3]) ? constants[(*t)[3]] : 0);
      t = typeOf((*t)[2]);
    }
    if (!t) {
      *error = "unsupported descriptor type at " + where + " (pointee is not a type the reflector knows)";
      return false;
    }
    const uint32_t op = (*t)[0];
    if (op == kOpTypeSampledImage && t->size() >= 3) {
      b.kind = DescriptorKind::CombinedImageSampler;
      t = typeOf((*t)[2]);
      if (!t || (*t)[0] != kOpTypeImage) {
        *error = "malformed SPIR-V: OpTypeSampledImage at " + where + " does not name an OpTypeImage";
        return false;
      }
    }
    if ((*t)[0] == kOpTypeImage && t->size() >= 9) {
      b.dim = static_cast<ImageDim>(std::min<uint32_t>((*t)[3], 6) + 1);
      b.arrayed = (*t)[5] != 0;
      b.imageFormat = (*t)[8];
      if (op == kOpTypeImage) b.kind = (*t)[7] == 2 ? DescriptorKind::StorageImage : DescriptorKind::SampledImage;
      if (b.dim == ImageDim::Buffer || b.dim == ImageDim::SubpassData || (op == kOpTypeImage && (*t)[7] == 0)) {
        *error = "unsupported image descriptor at " + where + " (texel buffer, subpass input or unknown Sampled)";
        return false;
      }
    } else if (op == kOpTypeSampler) {
      b.kind = DescriptorKind::Sampler;
    } else if (op == kOpTypeStruct) {
      const Decorations& sd = decorations[(*t)[1]];
      if (v.storage == kStorageStorageBuffer || (v.storage == kStorageUniform && sd.bufferBlock)) {
        b.kind = DescriptorKind::StorageBuffer;
      } else if (v.storage == kStorageUniform && sd.block) {
        b.kind = DescriptorKind::UniformBuffer;
      } else {
        *error = "unsupported buffer descriptor at " + where + " (storage class " + std::to_string(v.storage) +
                 " without Block/BufferBlock)";
        return false;
      }
    } else if (op != kOpTypeSampledImage) {
      *error = "unsupported descriptor type at " + where + " (SPIR-V type opcode " + std::to_string(op) + ")";
      return false;
    }
    if (v.storage != kStorageUniformConstant && v.storage != kStorageUniform && v.storage != kStorageStorageBuffer) {
      *error = "unsupported storage class " + std::to_string(v.storage) + " for descriptor at " + where;
      return false;
    }
    out->bindings.push_back(std::move(b));
  }
  std::sort(out->bindings.begin(), out->bindings.end(), [](const DescriptorBinding& a, const DescriptorBinding& b) {
    return a.set != b.set ? a.set < b.set : a.binding < b.binding;
  });
  for (size_t i = 1; i < out->bindings.size(); ++i) {
    const DescriptorBinding& a = out->bindings[i - 1];
    const DescriptorBinding& b = out->bindings[i];
    if (a.set == b.set && a.binding == b.binding && a.kind != b.kind) {
      *error = "set " + std::to_string(a.set) + " binding " + std::to_string(a.binding) + " is used as both " +
               descriptorKindName(a.kind) + " ('" + a.name + "') and " + descriptorKindName(b.kind) + " ('" +
               b.name + "')";
      return false;
    }
  }
  // Aliased variables of the same kind describe one descriptor.
  out->bindings.erase(std::unique(out->bindings.begin(), out->bindings.end(),
                                  [](const DescriptorBinding& a, const DescriptorBinding& b) {
                                    return a.set == b.set && a.binding == b.binding;
                                  }),
                      out->bindings.end());
  return true;
}

}  // namespace substratec::gpu
