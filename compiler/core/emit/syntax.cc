#include "emit/syntax.h"

#include <cctype>
#include <cmath>

#include <fmt/format.h>

namespace substratec {

std::string dialectType(VType t) {
  switch (t) {
    case VType::Vec2: return "float2";
    case VType::Vec3: return "float3";
    case VType::Vec4: return "float4";
    default: return "float";
  }
}

std::string dialectLiteral(double v) {
  if (!std::isfinite(v)) v = v > 0 ? 3.0e38 : (v < 0 ? -3.0e38 : 0.0);
  if (v == 0) return "0.0";
  std::string s = fmt::format("{:.9g}", v);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  if (s.find_first_of("eE") != std::string::npos && s.find('.') == std::string::npos) {
    auto e = s.find_first_of("eE");
    s.insert(e, ".0");
  }
  if (v < 0) s = "(" + s + ")";
  return s;
}

namespace {

bool isGlsl(const Syntax& s) { return s.target == Target::Glsl; }

/// HLSL's register attribute of (set, binding).
std::string vkBinding(int set, int binding) { return fmt::format("[[vk::binding({}, {})]] ", binding, set); }

/// inNormal / outColor: GLSL's stage variables are globals with a prefix.
std::string prefixed(std::string_view prefix, std::string_view name) {
  std::string s(name);
  if (!s.empty()) s[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
  return std::string(prefix) + s;
}

std::string trailing(const std::string& comment) { return comment.empty() ? "" : "  // " + comment; }

}  // namespace

std::string Syntax::uniformBlock(int set, int binding, std::string_view block, std::string_view instance,
                                 std::string_view members) const {
  if (isGlsl(*this))
    return fmt::format("layout(set = {}, binding = {}, std140) uniform {} {{\n{}}} {};\n", set, binding, block, members,
                       instance);
  return fmt::format("struct {} {{\n{}}};\n{}ConstantBuffer<{}> {};\n", block, members, vkBinding(set, binding), block,
                     instance);
}

std::string Syntax::storageBuffer(int set, int binding, Access access, std::string_view block, std::string_view element,
                                  std::string_view name) const {
  if (isGlsl(*this)) {
    const char* q = access == Access::Read ? "readonly " : access == Access::Write ? "writeonly " : "";
    return fmt::format("layout(set = {}, binding = {}, std430) {}buffer {} {{ {} {}[]; }};\n", set, binding, q, block,
                       element, name);
  }
  return fmt::format("{}{}StructuredBuffer<{}> {};\n", vkBinding(set, binding), access == Access::Read ? "" : "RW",
                     element, name);
}

std::string Syntax::texture(int set, int binding, bool cube, std::string_view name) const {
  if (isGlsl(*this))
    return fmt::format("layout(set = {}, binding = {}) uniform {} {};\n", set, binding, cube ? "samplerCube" : "sampler2D",
                       name);
  return fmt::format("{}{}<float4> {};\n", vkBinding(set, binding), cube ? "TextureCube" : "Texture2D", name);
}

std::string Syntax::sampler(int set, int binding, std::string_view name) const {
  return isGlsl(*this) ? "" : fmt::format("{}SamplerState {};\n", vkBinding(set, binding), name);
}

std::string Syntax::storageImage(int set, int binding, Access access, ImageKind kind, std::string_view name) const {
  const bool words = kind == ImageKind::UintArray;
  if (isGlsl(*this)) {
    const char* q = access == Access::Read ? "readonly " : access == Access::Write ? "writeonly " : "";
    return fmt::format("layout(set = {}, binding = {}, {}) uniform {}{} {};\n", set, binding, words ? "r32ui" : "rgba32f",
                       q, words ? "uimage2DArray" : "image2D", name);
  }
  return fmt::format("{}{} {};\n", vkBinding(set, binding), words ? "RWTexture2DArray<uint>" : "RWTexture2D<float4>",
                     name);
}

std::string Syntax::materialInputs(std::string_view material, const std::vector<std::pair<VType, std::string>>& inputs,
                                   bool perInvocation) const {
  std::string s;
  if (isGlsl(*this)) {
    for (const auto& in : inputs) s += fmt::format("  {} i_{};\n", dialectType(in.first), in.second);
    if (perInvocation) return fmt::format("struct {0}_Inputs {{\n{1}}};\n{0}_Inputs {0}_inputs;\n", material, s);
    return fmt::format("layout(set = 1, binding = 0, std140) uniform {0}_Inputs {{\n{1}}} {0}_inputs;\n", material, s);
  }
  for (const auto& in : inputs)
    s += fmt::format("{}{} {}_i_{};\n", perInvocation ? "static " : "  ", dialectType(in.first), material, in.second);
  if (perInvocation) return s;
  return fmt::format("{}cbuffer {}_Inputs {{\n{}}};\n", vkBinding(1, 0), material, s);
}

std::string Syntax::inputAccess(std::string_view material, std::string_view input) const {
  if (isGlsl(*this)) return fmt::format("{}_inputs.i_{}", material, input);
  return fmt::format("{}_i_{}", material, input);
}

std::string Syntax::fragmentInterface(const std::vector<StageVar>& inputs, const std::vector<StageVar>& outputs) const {
  std::string s;
  if (isGlsl(*this)) {
    for (const StageVar& v : inputs)
      s += fmt::format("layout(location = {}) in {} {};{}\n", v.location, v.type, input(v.name), trailing(v.comment));
    for (const StageVar& v : outputs)
      s += fmt::format("layout(location = {}{}) out {} {};{}\n", v.location,
                       v.index ? fmt::format(", index = {}", v.index) : "", v.type, output(v.name), trailing(v.comment));
    return s;
  }
  s += "struct PSInput {\n  float4 position : SV_Position;\n";
  for (const StageVar& v : inputs)
    s += fmt::format("  [[vk::location({})]] {} {} : {};{}\n", v.location, v.type, v.name, v.semantic, trailing(v.comment));
  s += "};\n\nstruct PSOutput {\n";
  // A dual-source output wants [[vk::location(0), vk::index(1)]] (DXC);
  // glslang's HLSL front end does not know vk::index: the next target instead.
  for (const StageVar& v : outputs)
    s += fmt::format("  [[vk::location({0})]] {1} {2} : SV_Target{0};{3}\n", v.location + v.index, v.type, v.name,
                     trailing(v.comment));
  return s + "};\n";
}

std::string Syntax::fragmentMain() const {
  return isGlsl(*this) ? "void main() {\n" : "PSOutput main(PSInput i) {\n  PSOutput o;\n";
}

std::string Syntax::earlyFragmentTests() const {
  return isGlsl(*this) ? "layout(early_fragment_tests) in;\n" : "[earlydepthstencil]\n";
}

std::string Syntax::fragmentEnd() const { return isGlsl(*this) ? "}\n" : "  return o;\n}\n"; }

std::string Syntax::input(std::string_view n) const {
  return isGlsl(*this) ? prefixed("in", n) : fmt::format("i.{}", n);
}

std::string Syntax::output(std::string_view n) const {
  return isGlsl(*this) ? prefixed("out", n) : fmt::format("o.{}", n);
}

std::string Syntax::fragCoord() const { return isGlsl(*this) ? "gl_FragCoord" : "i.position"; }

std::string Syntax::texelFetch(std::string_view texture, std::string_view pixel) const {
  if (isGlsl(*this)) return fmt::format("texelFetch({}, ivec2({}), 0)", texture, pixel);
  return fmt::format("{}.Load(int3(int2({}), 0))", texture, pixel);
}

std::string Syntax::computeMain(int x, int y) const {
  if (isGlsl(*this)) return fmt::format("layout(local_size_x = {}, local_size_y = {}) in;\nvoid main() {{\n", x, y);
  return fmt::format(
      "[numthreads({}, {}, 1)]\n"
      "void main(uint3 dispatchId : SV_DispatchThreadID, uint3 groupId : SV_GroupID, uint3 localId : SV_GroupThreadID) "
      "{{\n",
      x, y);
}

std::string Syntax::computeId(ComputeId id) const {
  if (isGlsl(*this))
    return id == ComputeId::Dispatch ? "gl_GlobalInvocationID" : id == ComputeId::Group ? "gl_WorkGroupID"
                                                                                        : "gl_LocalInvocationID";
  return id == ComputeId::Dispatch ? "dispatchId" : id == ComputeId::Group ? "groupId" : "localId";
}

const Syntax& syntaxFor(Target t) {
  static const Syntax glsl{Target::Glsl, "glsl", ".material.glsl", "substrate_prelude.glsl",
                           "#version 450\n#extension GL_GOOGLE_include_directive : require\n", ".frag", ".comp"};
  static const Syntax hlsl{Target::Hlsl, "hlsl", ".material.hlsl", "substrate_prelude.hlsl", "", ".ps.hlsl", ".cs.hlsl"};
  return t == Target::Glsl ? glsl : hlsl;
}

std::string environmentResources(const Syntax& syn) {
  return syn.texture(0, 1, true, "envPrefiltered") + syn.texture(0, 2, true, "envIrradiance") +
         syn.sampler(0, 3, "envSampler") +
         "// set 0, binding 5: the energy tables (a uniform buffer, declared by substrate_energy_lut.h).\n"
         "#define SUBSTRATE_ENV_PREFILTERED(dir, lod) SUBSTRATE_TEXTURE_SAMPLE_LEVEL(envPrefiltered, envSampler, dir, "
         "lod).rgb\n"
         "#define SUBSTRATE_ENV_IRRADIANCE(dir) SUBSTRATE_TEXTURE_SAMPLE_LEVEL(envIrradiance, envSampler, dir, 0.0).rgb\n";
}

}  // namespace substratec
