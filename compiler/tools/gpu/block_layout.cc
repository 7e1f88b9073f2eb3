#include "gpu/block_layout.h"

#include <algorithm>
#include <cstring>
#include <map>

#include "gpu/spirv_words.h"

namespace substratec::gpu {

std::vector<BlockMember> blockMembers(const std::vector<uint32_t>& w, uint32_t set, uint32_t binding) {
  using namespace spirv;
  std::map<uint32_t, uint32_t> setOf, bindingOf, pointee, varType;
  std::map<uint32_t, std::map<uint32_t, BlockMember>> members;  // struct id -> member index -> member
  for (std::size_t i = 5; i < w.size();) {
    const uint32_t op = w[i] & 0xffffu, n = w[i] >> 16;
    if (n == 0 || i + n > w.size()) break;
    const uint32_t* a = &w[i + 1];
    if (op == kOpDecorate && n >= 4 && a[1] == kDecorationDescriptorSet) setOf[a[0]] = a[2];
    if (op == kOpDecorate && n >= 4 && a[1] == kDecorationBinding) bindingOf[a[0]] = a[2];
    if (op == kOpMemberName && n >= 3) members[a[0]][a[1]].name = literalString(a + 2, n - 3);
    if (op == kOpMemberDecorate && n >= 5 && a[2] == kDecorationOffset) members[a[0]][a[1]].offset = a[3];
    if (op == kOpTypePointer && n >= 4) pointee[a[0]] = a[2];
    if (op == kOpVariable && n >= 4) varType[a[1]] = a[0];
    i += n;
  }
  std::vector<BlockMember> out;
  for (const auto& [var, s] : setOf) {
    auto b = bindingOf.find(var);
    auto t = varType.find(var);
    if (s != set || b == bindingOf.end() || b->second != binding || t == varType.end()) continue;
    auto p = pointee.find(t->second);
    if (p == pointee.end()) continue;
    for (const auto& [index, m] : members[p->second]) out.push_back(m);
    break;
  }
  return out;
}

int inputOfResource(const Material& m, const std::string& name) {
  std::string bare = name;
  const std::string hlslMember = m.name + "_i_";
  if (bare.rfind(hlslMember, 0) == 0) bare = bare.substr(hlslMember.size());
  else if (bare.rfind("i_", 0) == 0 || bare.rfind("t_", 0) == 0 || bare.rfind("s_", 0) == 0) bare = bare.substr(2);
  else return -1;
  for (std::size_t i = 0; i < m.inputs.size(); ++i)
    if (m.inputs[i].name == bare) return static_cast<int>(i);
  return -1;
}

std::vector<std::byte> inputBlockBytes(const Material& m, const std::vector<BlockMember>& members,
                                       const std::vector<std::array<double, 4>>& values) {
  uint32_t size = 16;
  std::vector<std::pair<uint32_t, float>> writes;
  for (const BlockMember& member : members) {
    const int index = inputOfResource(m, member.name);
    if (index < 0) continue;
    const Input& in = m.inputs[index];
    const std::array<double, 4>& v = values.empty() ? in.defaultValue : values[index];
    const int components = componentCount(in.type);
    size = std::max(size, member.offset + 4u * static_cast<uint32_t>(components));
    for (int c = 0; c < components; ++c) writes.push_back({member.offset + 4u * c, static_cast<float>(v[c])});
  }
  std::vector<std::byte> bytes((size + 15) / 16 * 16, std::byte{0});
  for (const auto& [offset, f] : writes) std::memcpy(bytes.data() + offset, &f, sizeof f);
  return bytes;
}

}  // namespace substratec::gpu
