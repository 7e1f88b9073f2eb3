// The runtime shader library (runtime_shaders/) compiles and validates as a
// whole, in both languages, in every configuration a material can select:
// each diffuse model, every SUBSTRATE_USE_* switch off and on, and the energy
// tables from their uniform buffer or inlined (SUBSTRATE_LUT_INLINE). The
// shader is a deferred lighting pass: unpack a pixel's closures from its words
// (substrate_unpack.h), light them (substrate_lighting.h) and add the split-sum
// environment, so every public entry of the library is reached. Each also in
// half precision (SUBSTRATE_PRECISION_HALF: float16 colours, weights and
// throughputs; HLSL with glslang's 16-bit types).
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <string_view>

#include "diag/diagnostics.h"
#include "emit/material_emitter.h"
#include "emit/syntax.h"
#include "pipeline/pipeline.h"
#include "test_util.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec {
namespace {

constexpr const char* kGlslLighting = R"(#version 450
#include "substrate_prelude.glsl"
#include "substrate_closure.h"
#include "substrate_common.h"
#include "substrate_pack.h"
#include "substrate_unpack.h"
#include "substrate_energy_lut.h"
#include "substrate_bsdf.h"
#include "substrate_lighting.h"
layout(set = 0, binding = 0) uniform samplerCube envPrefiltered;
layout(set = 0, binding = 1) uniform samplerCube envIrradiance;
layout(set = 0, binding = 2, std430) readonly buffer Words { uint w[]; } words;
layout(location = 0) in vec3 inV;
layout(location = 1) in vec3 inL;
layout(location = 0) out vec4 outColor;
void main() {
  uint stream[SUBSTRATE_MAX_WORDS];
  for (int i = 0; i < SUBSTRATE_MAX_WORDS; ++i) stream[i] = words.w[i];
  SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES];
  uint count = substrate_unpack_material(stream, words.w[SUBSTRATE_MAX_WORDS], closures);
  vec3 V = normalize(inV);
  vec3 color = substrate_light_closures(closures, count, V, normalize(inL), vec3(1.0));
  for (uint k = 0u; k < count; ++k) {
    vec3 R = substrate_reflection_dir(closures[k], V);
    color += substrate_closure_view_throughput(closures[k], dot(closures[k].N, V), V) *
             substrate_env_split_sum(closures[k], V, textureLod(envPrefiltered, R, substrate_env_mip(closures[k].roughness, 8.0)).rgb,
                                     textureLod(envIrradiance, closures[k].N, 0.0).rgb);
  }
  float coverage;
  vec3 transmittance;
  substrate_translucency(closures[0], dot(closures[0].N, V), V, coverage, transmittance);
  outColor = vec4(color * transmittance, coverage);
}
)";

constexpr const char* kHlslLighting = R"(#include "substrate_prelude.hlsl"
#include "substrate_closure.h"
#include "substrate_common.h"
#include "substrate_pack.h"
#include "substrate_unpack.h"
#include "substrate_energy_lut.h"
#include "substrate_bsdf.h"
#include "substrate_lighting.h"
[[vk::binding(0, 0)]] TextureCube<float4> envPrefiltered;
[[vk::binding(1, 0)]] TextureCube<float4> envIrradiance;
[[vk::binding(3, 0)]] SamplerState envSampler;
[[vk::binding(2, 0)]] StructuredBuffer<uint> words;
float4 main([[vk::location(0)]] float3 inV : TEXCOORD0, [[vk::location(1)]] float3 inL : TEXCOORD1) : SV_Target0 {
  uint stream[SUBSTRATE_MAX_WORDS];
  for (int i = 0; i < SUBSTRATE_MAX_WORDS; ++i) stream[i] = words[i];
  SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES];
  uint count = substrate_unpack_material(stream, words[SUBSTRATE_MAX_WORDS], closures);
  float3 V = normalize(inV);
  float3 color = substrate_light_closures(closures, count, V, normalize(inL), float3(1.0, 1.0, 1.0));
  for (uint k = 0u; k < count; ++k) {
    float3 R = substrate_reflection_dir(closures[k], V);
    color += substrate_closure_view_throughput(closures[k], dot(closures[k].N, V), V) *
             substrate_env_split_sum(closures[k], V,
                                     envPrefiltered.SampleLevel(envSampler, R, substrate_env_mip(closures[k].roughness, 8.0)).rgb,
                                     envIrradiance.SampleLevel(envSampler, closures[k].N, 0.0).rgb);
  }
  float coverage;
  float3 transmittance;
  substrate_translucency(closures[0], dot(closures[0].N, V), V, coverage, transmittance);
  return float4(color * transmittance, coverage);
}
)";

constexpr const char* kUseSwitches[] = {"SUBSTRATE_USE_F90",   "SUBSTRATE_USE_ANISOTROPY", "SUBSTRATE_USE_HAZE",
                                        "SUBSTRATE_USE_FUZZ",  "SUBSTRATE_USE_SSS",        "SUBSTRATE_USE_GLINT",
                                        "SUBSTRATE_USE_SPECULAR_PROFILE", "SUBSTRATE_USE_EMISSIVE",
                                        "SUBSTRATE_USE_EXTRA_INTERFACES", "SUBSTRATE_USE_WRAP_UNDER_LAYERS",
                                        "SUBSTRATE_USE_FUZZ_UNDER_LAYERS", "SUBSTRATE_USE_CONDUCTOR_CURVE"};

struct Config {
  ShaderLanguage language;
  int diffuseModel;
  bool features;
  bool inlineLut;
  bool half = false;
};

std::string describe(const Config& c) {
  return std::string(c.language == ShaderLanguage::Glsl ? "GLSL" : "HLSL") + ", diffuse model " +
         std::to_string(c.diffuseModel) + ", features " + (c.features ? "on" : "off") + ", tables " +
         (c.inlineLut ? "inline" : "in a uniform buffer") + (c.half ? ", half precision" : "");
}

ShaderValidation compileLighting(const Config& c) {
  ShaderSource src;
  src.language = c.language;
  src.name = c.language == ShaderLanguage::Glsl ? "lighting.frag" : "lighting.ps.hlsl";
  src.text = c.language == ShaderLanguage::Glsl ? kGlslLighting : kHlslLighting;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  src.defines.push_back({"SUBSTRATE_DIFFUSE_MODEL", std::to_string(c.diffuseModel)});
  for (const char* use : kUseSwitches) src.defines.push_back({use, c.features ? "1" : "0"});
  if (c.inlineLut) src.defines.push_back({"SUBSTRATE_LUT_INLINE", "1"});
  if (c.half) src.defines.push_back({"SUBSTRATE_PRECISION_HALF", "1"});
  src.hlsl16BitTypes = c.half;
  return compileAndValidate(src);
}

TEST(RuntimeShaders, EveryConfigurationCompilesAndValidates) {
  for (ShaderLanguage language : {ShaderLanguage::Glsl, ShaderLanguage::Hlsl})
    for (int model = 0; model < 4; ++model)
      for (bool features : {false, true})
        for (bool half : {false, true}) {
          Config c{language, model, features, false, half};
          SCOPED_TRACE(describe(c));
          ShaderValidation v = compileLighting(c);
          EXPECT_TRUE(v.ok) << v.log;
        }
}

TEST(RuntimeShaders, InlineTablesCompileAndValidate) {
  for (ShaderLanguage language : {ShaderLanguage::Glsl, ShaderLanguage::Hlsl}) {
    Config c{language, 2, true, true};
    SCOPED_TRACE(describe(c));
    ShaderValidation v = compileLighting(c);
    EXPECT_TRUE(v.ok) << v.log;
  }
}

/// Counts the instructions with opcode `op`.
std::size_t countOpcode(const std::vector<uint32_t>& w, uint32_t op) {
  std::size_t n = 0;
  for (std::size_t i = 5; i < w.size() && (w[i] >> 16) != 0; i += w[i] >> 16) n += (w[i] & 0xffffu) == op;
  return n;
}

/// Whether the module declares a 16-bit float type (OpTypeFloat 16).
bool hasFloat16Type(const std::vector<uint32_t>& w) {
  constexpr uint32_t kOpTypeFloat = 22;
  for (std::size_t i = 5; i < w.size() && (w[i] >> 16) != 0; i += w[i] >> 16)
    if ((w[i] & 0xffffu) == kOpTypeFloat && w[i + 2] == 16) return true;
  return false;
}

TEST(RuntimeShaders, HalfPrecisionComputesInFloat16AndFloatDoesNot) {
  // SUBSTRATE_PRECISION_HALF turns the medium types into float16 in both
  // languages (HLSL: only with 16-bit types; without them `half` is 32-bit and
  // the module has no Float16); the float build declares no 16-bit float.
  constexpr uint32_t kOpCapability = 17, kOpFConvert = 115;
  for (ShaderLanguage language : {ShaderLanguage::Glsl, ShaderLanguage::Hlsl}) {
    Config half{language, 2, true, false, true}, full{language, 2, true, false, false};
    SCOPED_TRACE(describe(half));
    ShaderValidation h = compileLighting(half), f = compileLighting(full);
    ASSERT_TRUE(h.ok && f.ok) << h.log << f.log;
    EXPECT_TRUE(hasFloat16Type(h.spirv));
    EXPECT_GT(countOpcode(h.spirv, kOpFConvert), countOpcode(f.spirv, kOpFConvert));
    EXPECT_EQ(countOpcode(h.spirv, kOpCapability), countOpcode(f.spirv, kOpCapability) + 1) << "Float16";
    EXPECT_FALSE(hasFloat16Type(f.spirv));
  }
}

TEST(RuntimeShaders, TablesInAUniformBufferAreNotConstants) {
  // Inline, the 3,072 table entries (4,032 with anisotropy) become constants of every module; from the
  // uniform buffer, the module has a few dozen.
  constexpr uint32_t kOpConstant = 43;
  ShaderValidation buffer = compileLighting({ShaderLanguage::Glsl, 2, true, false});
  ShaderValidation inlined = compileLighting({ShaderLanguage::Glsl, 2, true, true});
  ASSERT_TRUE(buffer.ok && inlined.ok) << buffer.log << inlined.log;
  EXPECT_LT(countOpcode(buffer.spirv, kOpConstant), 500u);
  EXPECT_GT(countOpcode(inlined.spirv, kOpConstant), 2000u);
}

/// The value of `#define NAME ` in the generated GLSL of a material of `nodes`
/// and `inputs` ("none" without it).
std::string materialDefine(const std::string& name, const std::string& nodes, const std::string& inputs) {
  Diagnostics d("m.json");
  auto r = compileText("m.json", test::material(nodes, inputs), {}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  if (!r) return std::string();
  const std::string glsl = emitMaterial(r->material, r->tree, r->after, syntaxFor(Target::Glsl), {});
  const std::string key = "#define " + name + " ";
  const std::size_t at = glsl.find(key);
  return at == std::string::npos ? std::string("none") : glsl.substr(at + key.size(), 1);
}

std::string slabNode(const std::string& albedo, const std::string& f0) {
  return R"("root": {"kind": "slab", "roughness": 0.4, "diffuse_albedo": )" + albedo + R"(, "f0": )" + f0 + "}";
}

TEST(RuntimeShaders, AMaterialPaysForTheConductorCurveOnlyWhereASlabMayBeAConductor) {
  // Issue 19, step 23: a conductor's Fresnel follows a curve per channel
  // (substrate_fresnel_curve), three coefficients per light where a
  // dielectric's chi is one. The material compiles it (SUBSTRATE_USE_CONDUCTOR_CURVE
  // 1) only when some slab may be what the truth walks as a conductor: its F0
  // not a constant of a dielectric (every channel at most 0.1), no medium, and
  // no constant diffuse above 0 (a high-IOR dielectric over a diffuse there).
  const auto define = [](const std::string& nodes, const std::string& inputs) {
    return materialDefine("SUBSTRATE_USE_CONDUCTOR_CURVE", nodes, inputs);
  };
  const std::string input = R"({"x": {"type": "float", "default": 0.04, "min": 0, "max": 1}})";
  EXPECT_EQ(define(slabNode("0.5", "0.04"), "{}"), "0");
  EXPECT_EQ(define(slabNode("0", "[0.1, 0.05, 0.02]"), "{}"), "0");
  EXPECT_EQ(define(slabNode("0", "0.12"), "{}"), "1");
  EXPECT_EQ(define(slabNode("0", "[0.9, 0.6, 0.3]"), "{}"), "1");
  EXPECT_EQ(define(slabNode("0.5", "0.9"), "{}"), "0");
  EXPECT_EQ(define(R"("root": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.9, "sss_mfp": 0.01})", "{}"), "0");
  EXPECT_EQ(define(slabNode("0", R"("$x")"), input), "1");
  EXPECT_EQ(define(slabNode(R"("$x")", "0.9"), input), "1");
}

TEST(RuntimeShaders, AMaterialPaysForTheLowIorCurveOnlyWhereADielectricMayHaveALowF0) {
  // Issue 19, step 24: a dielectric of F0 below 0.04 follows the curve of its
  // own IOR (substrate_fresnel_curve), whose coefficients are computed per
  // evaluation where chi's are constants. The material compiles it
  // (SUBSTRATE_USE_LOW_IOR_CURVE 1) only when it has no layers (under them,
  // and on top of them, the curve is chi) and some slab's F0 may fall below
  // 0.04 in its largest channel.
  const auto define = [](const std::string& nodes, const std::string& inputs) {
    return materialDefine("SUBSTRATE_USE_LOW_IOR_CURVE", nodes, inputs);
  };
  const std::string input = R"({"x": {"type": "float", "default": 0.04, "min": 0, "max": 1}})";
  EXPECT_EQ(define(slabNode("0.5", "0.04"), "{}"), "0");
  EXPECT_EQ(define(slabNode("0", "[0.1, 0.05, 0.02]"), "{}"), "0");
  EXPECT_EQ(define(slabNode("0.5", "0.9"), "{}"), "0");
  EXPECT_EQ(define(slabNode("0.5", "0.005"), "{}"), "1");
  EXPECT_EQ(define(slabNode("0.5", "[0.03, 0.02, 0.01]"), "{}"), "1");
  EXPECT_EQ(define(slabNode("0.5", "0"), "{}"), "1");
  EXPECT_EQ(define(slabNode("0.5", R"("$x")"), input), "1");
  const std::string coat = R"("coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.02, "roughness": 0.1, "sss_mfp": 10},
    "base": {"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.02, "roughness": 0.5},
    "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0.1})";
  EXPECT_EQ(define(coat, "{}"), "0");
}

}  // namespace
}  // namespace substratec
