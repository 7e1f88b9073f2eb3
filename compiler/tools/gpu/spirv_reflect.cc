// SPIR-V descriptor reflection for the GPU harness (see spirv_reflect.h).
#include "gpu/spirv_reflect.h"

#include <algorithm>
#include <map>
#include <set>

#include "gpu/spirv_words.h"

namespace substratec::gpu {
namespace {

using namespace spirv;

/// Decodes a nul-terminated literal string starting at words[begin] (at most `end`).
std::string stringOperand(const std::vector<uint32_t>& words, size_t begin, size_t end) {
  return literalString(words.data() + begin, end - begin);
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

/// What reflection reads from a module's instructions, by result id.
struct Module {
  struct Variable {
    uint32_t id, pointerType, storage;
  };
  uint32_t version = 0;
  std::map<uint32_t, std::string> names;
  std::map<uint32_t, Decorations> decorations;
  std::map<uint32_t, std::vector<uint32_t>> types;  // result id -> the type instruction's words (opcode first)
  std::map<uint32_t, uint32_t> constants;           // result id -> first value word
  std::vector<Variable> variables;
  std::set<uint32_t> interface;                     // the first entry point's interface ids

  const std::vector<uint32_t>* typeOf(uint32_t id) const {
    auto it = types.find(id);
    return it == types.end() ? nullptr : &it->second;
  }
  Decorations decorationsOf(uint32_t id) const {
    auto it = decorations.find(id);
    return it == decorations.end() ? Decorations{} : it->second;
  }
};

/// Reads the instructions reflection needs into `m`, and the first entry point (name, execution model,
/// LocalSize) into `out`; false, reporting it, on a malformed module or one without an entry point.
bool scanModule(const std::vector<uint32_t>& words, Module& m, ShaderReflection* out, Diagnostics& diags) {
  if (words.size() < 5 || words[0] != kSpirvMagic) {
    diags.fail("not a SPIR-V module (missing header or wrong magic number)");
    return false;
  }
  m.version = words[1];
  bool haveEntry = false;
  uint32_t entryId = 0;
  for (size_t at = 5; at < words.size();) {
    const uint32_t count = words[at] >> 16, op = words[at] & 0xffffu;
    if (count == 0 || at + count > words.size()) {
      diags.fail("malformed SPIR-V: bad instruction word count at word " + std::to_string(at));
      return false;
    }
    const size_t end = at + count;
    const uint32_t* w = &words[at];
    if (op == kOpName && count >= 3) {
      m.names[w[1]] = stringOperand(words, at + 2, end);
    } else if (op == kOpEntryPoint && count >= 4 && !haveEntry) {
      haveEntry = true;
      out->executionModel = w[1];
      entryId = w[2];
      out->entryPoint = stringOperand(words, at + 3, end);
      for (size_t i = at + 3 + literalStringWords(words, at + 3, end); i < end; ++i) m.interface.insert(words[i]);
    } else if (op == kOpExecutionMode && count >= 6 && haveEntry && w[1] == entryId && w[2] == kExecutionModeLocalSize) {
      std::copy(w + 3, w + 6, out->localSize);
    } else if (op == kOpDecorate && count >= 3) {
      Decorations& d = m.decorations[w[1]];
      if (w[2] == kDecorationBlock) d.block = true;
      if (w[2] == kDecorationBufferBlock) d.bufferBlock = true;
      if (w[2] == kDecorationDescriptorSet && count >= 4) d.hasSet = true, d.set = w[3];
      if (w[2] == kDecorationBinding && count >= 4) d.hasBinding = true, d.binding = w[3];
    } else if ((op >= kOpTypeImage && op <= kOpTypeStruct) || op == kOpTypePointer) {
      if (count >= 2) {
        std::vector<uint32_t>& t = m.types[w[1]] = std::vector<uint32_t>(w, w + count);
        t[0] = op;
      }
    } else if (op == kOpConstant && count >= 4) {
      m.constants[w[2]] = w[3];
    } else if (op == kOpVariable && count >= 4) {
      m.variables.push_back({w[2], w[1], w[3]});
    }
    at = end;
  }
  if (!haveEntry) diags.fail("SPIR-V module has no OpEntryPoint");
  return haveEntry;
}

/// The kind, image properties and array size of descriptor variable `v` (set, binding and name already
/// in `b`); false, reporting it, for a type the harness cannot bind.
bool describeVariable(const Module& m, const Module::Variable& v, DescriptorBinding& b, Diagnostics& diags) {
  const std::string where = "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" +
                            b.name + "')";
  const std::vector<uint32_t>* ptr = m.typeOf(v.pointerType);
  if (!ptr || (*ptr)[0] != kOpTypePointer || ptr->size() < 4) {
    diags.fail("malformed SPIR-V: variable at " + where + " does not have a pointer type");
    return false;
  }
  const std::vector<uint32_t>* t = m.typeOf((*ptr)[3]);
  if (t && ((*t)[0] == kOpTypeArray || (*t)[0] == kOpTypeRuntimeArray) && t->size() >= 3) {
    const auto size = t->size() >= 4 ? m.constants.find((*t)[3]) : m.constants.end();
    b.count = (*t)[0] == kOpTypeRuntimeArray ? 0 : (size != m.constants.end() ? size->second : 0);
    t = m.typeOf((*t)[2]);
  }
  if (!t) {
    diags.fail("unsupported descriptor type at " + where + " (pointee is not a type the reflector knows)");
    return false;
  }
  const uint32_t op = (*t)[0];
  if (op == kOpTypeSampledImage && t->size() >= 3) {
    b.kind = DescriptorKind::CombinedImageSampler;
    t = m.typeOf((*t)[2]);
    if (!t || (*t)[0] != kOpTypeImage) {
      diags.fail("malformed SPIR-V: OpTypeSampledImage at " + where + " does not name an OpTypeImage");
      return false;
    }
  }
  if ((*t)[0] == kOpTypeImage && t->size() >= 9) {
    b.dim = static_cast<ImageDim>(std::min<uint32_t>((*t)[3], 6) + 1);
    b.arrayed = (*t)[5] != 0;
    b.imageFormat = (*t)[8];
    if (op == kOpTypeImage) b.kind = (*t)[7] == 2 ? DescriptorKind::StorageImage : DescriptorKind::SampledImage;
    if (b.dim == ImageDim::Buffer || b.dim == ImageDim::SubpassData || (op == kOpTypeImage && (*t)[7] == 0)) {
      diags.fail("unsupported image descriptor at " + where + " (texel buffer, subpass input or unknown Sampled)");
      return false;
    }
  } else if (op == kOpTypeSampler) {
    b.kind = DescriptorKind::Sampler;
  } else if (op == kOpTypeStruct) {
    const Decorations sd = m.decorationsOf((*t)[1]);
    if (v.storage == kStorageStorageBuffer || (v.storage == kStorageUniform && sd.bufferBlock)) {
      b.kind = DescriptorKind::StorageBuffer;
    } else if (v.storage == kStorageUniform && sd.block) {
      b.kind = DescriptorKind::UniformBuffer;
    } else {
      diags.fail("unsupported buffer descriptor at " + where + " (storage class " + std::to_string(v.storage) +
                 " without Block/BufferBlock)");
      return false;
    }
  } else if (op != kOpTypeSampledImage) {
    diags.fail("unsupported descriptor type at " + where + " (SPIR-V type opcode " + std::to_string(op) + ")");
    return false;
  }
  if (v.storage != kStorageUniformConstant && v.storage != kStorageUniform && v.storage != kStorageStorageBuffer) {
    diags.fail("unsupported storage class " + std::to_string(v.storage) + " for descriptor at " + where);
    return false;
  }
  return true;
}

/// Sorts `bindings` by (set, binding) and merges aliased variables of one kind into one descriptor;
/// false, reporting it, when two variables of different kinds share a binding.
bool sortAndMerge(std::vector<DescriptorBinding>& bindings, Diagnostics& diags) {
  std::sort(bindings.begin(), bindings.end(), [](const DescriptorBinding& a, const DescriptorBinding& b) {
    return a.set != b.set ? a.set < b.set : a.binding < b.binding;
  });
  for (size_t i = 1; i < bindings.size(); ++i) {
    const DescriptorBinding& a = bindings[i - 1];
    const DescriptorBinding& b = bindings[i];
    if (a.set == b.set && a.binding == b.binding && a.kind != b.kind) {
      diags.fail("set " + std::to_string(a.set) + " binding " + std::to_string(a.binding) + " is used as both " +
                 descriptorKindName(a.kind) + " ('" + a.name + "') and " + descriptorKindName(b.kind) + " ('" +
                 b.name + "')");
      return false;
    }
  }
  bindings.erase(std::unique(bindings.begin(), bindings.end(),
                             [](const DescriptorBinding& a, const DescriptorBinding& b) {
                               return a.set == b.set && a.binding == b.binding;
                             }),
                 bindings.end());
  return true;
}

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

bool reflectSpirv(const std::vector<uint32_t>& words, ShaderReflection* out, Diagnostics& diags) {
  *out = ShaderReflection{};
  Module m;
  if (!scanModule(words, m, out, diags)) return false;
  for (const Module::Variable& v : m.variables) {
    const Decorations d = m.decorationsOf(v.id);
    if (!d.hasSet || !d.hasBinding) continue;
    if (m.version >= 0x00010400 && !m.interface.count(v.id)) continue;
    DescriptorBinding b;
    b.set = d.set;
    b.binding = d.binding;
    auto name = m.names.find(v.id);
    if (name != m.names.end()) b.name = name->second;
    if (!describeVariable(m, v, b, diags)) return false;
    out->bindings.push_back(std::move(b));
  }
  return sortAndMerge(out->bindings, diags);
}

}  // namespace substratec::gpu
