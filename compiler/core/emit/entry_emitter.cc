#include "emit/entry_emitter.h"

#include <fmt/format.h>

namespace substratec {

namespace {

bool translucent(const Material& m) {
  return m.settings.blendMode == BlendMode::TranslucentGrey || m.settings.blendMode == BlendMode::TranslucentColored ||
         m.settings.blendMode == BlendMode::ColoredTransmittanceOnly;
}

bool usesEmissive(const Material& m, const StorageLayout& L) {
  for (const auto& c : L.closures)
    if (m.slabs[c.slab].features & kFeatEmissive) return true;
  return false;
}

/// Shared prologue: includes. The material file includes the runtime it needs;
/// the base pass includes substrate_pack.h before it, which compiles the
/// material's pack function in (the forward pass does not pack).
std::string includes(const Material& m, const Syntax& syn, bool lighting, Precision precision = Precision::Float) {
  std::string s;
  if (syn.target == Target::Glsl) s += "#version 450\n#extension GL_GOOGLE_include_directive : require\n";
  // The forward pass lights the closures <name>_evaluate returns: their normals are unit.
  if (lighting) s += "#define SUBSTRATE_UNIT_CLOSURE_NORMALS 1  // lit as evaluated: unit normals\n";
  s += precisionDefine(precision);
  s += fmt::format("#include \"{}\"\n", syn.prelude);
  if (!lighting) s += "#include \"substrate_pack.h\"\n";
  s += fmt::format("#include \"{}{}\"\n", m.name, syn.materialExtension);
  if (lighting) s += "#include \"substrate_energy_lut.h\"\n#include \"substrate_bsdf.h\"\n#include \"substrate_lighting.h\"\n";
  return s;
}

/// Fills SubstrateGeometry `g` from the interpolants (both entry kinds).
std::string geometryCode(const Syntax& syn) {
  if (syn.target == Target::Glsl)
    return R"(  SubstrateGeometry g;
  g.N = normalize(inNormal);
  g.T = substrate_orthogonal_tangent(g.N, inTangent.xyz);
  g.V = normalize(frame.cameraPosition.xyz - inPosition);
  g.position = inPosition;
  g.uv0 = inUv0;
  g.uv1 = inUv1;
  g.vertexColor = inColor;
  g.uvDerivatives = vec4(dFdx(inUv0), dFdy(inUv0));
  // Interleaved gradient noise (Jimenez 2014): the per-pixel dither.
  g.dither = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
)";
  return R"(  SubstrateGeometry g;
  g.N = normalize(i.normal);
  g.T = substrate_orthogonal_tangent(g.N, i.tangent.xyz);
  g.V = normalize(frame.cameraPosition.xyz - i.worldPosition);
  g.position = i.worldPosition;
  g.uv0 = i.uv0;
  g.uv1 = i.uv1;
  g.vertexColor = i.color;
  g.uvDerivatives = float4(ddx(i.uv0), ddy(i.uv0));
  // Interleaved gradient noise (Jimenez 2014): the per-pixel dither.
  g.dither = frac(52.9829189 * frac(dot(i.position.xy, float2(0.06711056, 0.00583715))));
)";
}

std::string frameResources(const Syntax& syn, bool environment) {
  if (syn.target == Target::Glsl) {
    std::string s = R"(layout(set = 0, binding = 0, std140) uniform SubstrateFrame {
  vec4 cameraPosition;  // xyz: world position of the eye
  vec4 lightDirection;  // xyz: unit vector toward the light
  vec4 lightRadiance;   // rgb
  vec4 envParams;       // x: mip count of the prefiltered environment
} frame;
)";
    if (environment)
      s += "layout(set = 0, binding = 1) uniform samplerCube envPrefiltered;\n"
           "layout(set = 0, binding = 2) uniform samplerCube envIrradiance;\n"
           "// set 0, binding 5: the energy tables (a uniform buffer, declared by substrate_energy_lut.h).\n";
    s += R"(
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv0;
layout(location = 4) in vec2 inUv1;
layout(location = 5) in vec4 inColor;
)";
    return s;
  }
  std::string s = R"(struct SubstrateFrameData {
  float4 cameraPosition;  // xyz: world position of the eye
  float4 lightDirection;  // xyz: unit vector toward the light
  float4 lightRadiance;   // rgb
  float4 envParams;       // x: mip count of the prefiltered environment
};
[[vk::binding(0, 0)]] ConstantBuffer<SubstrateFrameData> frame;
)";
  if (environment)
    s += "[[vk::binding(1, 0)]] TextureCube<float4> envPrefiltered;\n"
         "[[vk::binding(2, 0)]] TextureCube<float4> envIrradiance;\n"
         "[[vk::binding(3, 0)]] SamplerState envSampler;\n"
         "// set 0, binding 5: the energy tables (a uniform buffer, declared by substrate_energy_lut.h).\n";
  s += R"(
struct PSInput {
  float4 position : SV_Position;
  [[vk::location(0)]] float3 worldPosition : POSITION0;
  [[vk::location(1)]] float3 normal : NORMAL0;
  [[vk::location(2)]] float4 tangent : TANGENT0;
  [[vk::location(3)]] float2 uv0 : TEXCOORD0;
  [[vk::location(4)]] float2 uv1 : TEXCOORD1;
  [[vk::location(5)]] float4 color : COLOR0;
};
)";
  return s;
}

}  // namespace

std::string forwardFileName(const Material& m, const Syntax& syn) {
  return m.name + (syn.target == Target::Glsl ? ".forward.frag" : ".forward.ps.hlsl");
}
std::string basePassFileName(const Material& m, const Syntax& syn) {
  return m.name + (syn.target == Target::Glsl ? ".basepass.frag" : ".basepass.ps.hlsl");
}

std::string emitForwardEntry(const Material& m, const StorageLayout& L, const Syntax& syn, Precision precision) {
  const bool glsl = syn.target == Target::Glsl;
  const std::string upper = materialUpper(m);
  const std::string v3 = syn.type(VType::Vec3);
  const int n = static_cast<int>(L.closures.size());
  const bool dual = translucent(m);
  std::string s = fmt::format("// Generated by substratec: the forward pass of '{}' ({} closure(s), lit inline, no packing).\n",
                              m.name, n);
  s += includes(m, syn, true, precision) + "\n" + frameResources(syn, true);
  if (glsl) {
    s += dual ? "layout(location = 0, index = 0) out vec4 outColor;\n"
                "layout(location = 0, index = 1) out vec4 outTransmittance;  // dual-source: background multiplier\n"
              : "layout(location = 0) out vec4 outColor;\n";
    s += "\nvoid main() {\n";
  } else {
    s += "\nstruct PSOutput {\n  [[vk::location(0)]] float4 color : SV_Target0;\n";
    // Dual-source blending wants [[vk::location(0), vk::index(1)]] (DXC); glslang's HLSL
    // front end does not know vk::index, so the transmittance goes to target 1.
    if (dual) s += "  [[vk::location(1)]] float4 transmittance : SV_Target1;  // the background multiplier\n";
    s += "};\n\nPSOutput main(PSInput i) {\n";
  }
  s += geometryCode(syn);
  s += fmt::format("  SubstrateClosure closures[{}_CLOSURE_COUNT];\n  float coverage;\n  {} transmittance;\n", upper, v3);
  s += fmt::format("  {}_evaluate(g, closures, coverage, transmittance);\n", m.name);
  s += fmt::format("  {} L = frame.lightDirection.xyz;\n  {} color = SUBSTRATE_SPLAT3(0.0);\n", v3, v3);
  // One closure: lit inline (no loop). Several: one loop over them, so the
  // lighting code exists once in the shader instead of once per closure.
  const bool loop = n > 1;
  const std::string cl = loop ? "closures[k]" : "closures[0]";
  // A closure whose weight is 0 at this pixel is skipped (dynamic culling);
  // a lone closure of static weight 1 needs no test.
  const bool test = loop || L.closures[0].storesWeight;
  if (loop) {
    s += fmt::format("  for (uint k = 0u; k < uint({}_CLOSURE_COUNT); ++k) {{\n", upper);
    s += "    if (!substrate_closure_visible(closures[k])) continue;  // weight 0 here: nothing to light\n";
  } else {
    s += fmt::format("  // closure 0 ('{}')\n", m.slabs[L.closures[0].slab].id);
    if (test) s += "  if (substrate_closure_visible(closures[0])) {  // weight 0 here: nothing to light\n";
  }
  const std::string in = test ? "    " : "  ";
  s += fmt::format("{}color += substrate_light_closure({}, g.V, L, frame.lightRadiance.rgb);\n", in, cl);
  std::string pre = glsl ? fmt::format("textureLod(envPrefiltered, substrate_reflection_dir({0}, g.V), "
                                       "substrate_env_mip(substrate_env_roughness({0}), frame.envParams.x)).rgb", cl)
                         : fmt::format("envPrefiltered.SampleLevel(envSampler, substrate_reflection_dir({0}, g.V), "
                                       "substrate_env_mip(substrate_env_roughness({0}), frame.envParams.x)).rgb", cl);
  std::string irr = glsl ? fmt::format("textureLod(envIrradiance, {}.N, 0.0).rgb", cl)
                         : fmt::format("envIrradiance.SampleLevel(envSampler, {}.N, 0.0).rgb", cl);
  s += fmt::format("{0}color += substrate_closure_view_throughput({1}, dot({1}.N, g.V)) * "
                   "substrate_env_split_sum({1}, g.V, {2}, {3});\n", in, cl, pre, irr);
  if (usesEmissive(m, L))
    s += fmt::format("{0}color += substrate_closure_view_throughput({1}, dot({1}.N, g.V)) * {1}.emissive;\n", in, cl);
  if (test) s += "  }\n";
  std::string color = "color", alpha = "coverage";
  if (m.settings.blendMode == BlendMode::AlphaHoldout) color = "SUBSTRATE_SPLAT3(0.0)";
  if (m.settings.blendMode == BlendMode::Masked)
    s += glsl ? "  if (coverage < 0.5) discard;\n" : "  clip(coverage - 0.5);\n";
  if (m.settings.blendMode == BlendMode::ColoredTransmittanceOnly) color = "SUBSTRATE_SPLAT3(0.0)";
  std::string through = fmt::format("SUBSTRATE_SPLAT3(1.0 - coverage) + coverage * transmittance");
  if (m.settings.blendMode == BlendMode::TranslucentGrey)
    through = "SUBSTRATE_SPLAT3(1.0 - coverage + coverage * dot(transmittance, SUBSTRATE_SPLAT3(1.0 / 3.0)))";
  if (glsl) {
    s += fmt::format("  outColor = vec4({}, {});\n", color, alpha);
    if (dual) s += fmt::format("  outTransmittance = vec4({}, 1.0);\n", through);
    s += "}\n";
  } else {
    s += fmt::format("  PSOutput o;\n  o.color = float4({}, {});\n", color, alpha);
    if (dual) s += fmt::format("  o.transmittance = float4({}, 1.0);\n", through);
    s += "  return o;\n}\n";
  }
  return s;
}

std::string emitBasePassEntry(const Material& m, const StorageLayout& L, const Syntax& syn) {
  const bool glsl = syn.target == Target::Glsl;
  const std::string upper = materialUpper(m);
  const std::string v3 = syn.type(VType::Vec3);
  const int words = L.words();
  const int rts = std::min(words, 3);
  const bool emissive = usesEmissive(m, L);
  std::string s = fmt::format(
      "// Generated by substratec: the base pass of '{}' — {} packed words ({} to render targets, {} to the "
      "material buffer) and the top-layer word.\n",
      m.name, words, rts, words - rts);
  s += includes(m, syn, false) + "\n" + frameResources(syn, false);
  if (glsl) {
    for (int k = 0; k < rts; ++k) s += fmt::format("layout(location = {0}) out uint outWord{0};\n", k);
    s += "layout(location = 3) out uint outTopLayer;\n";
    if (emissive) s += "layout(location = 4) out vec4 outEmissive;\n";
    if (words > 3) s += "layout(set = 0, binding = 4, r32ui) uniform writeonly uimage2DArray materialBuffer;\n";
    s += "\nvoid main() {\n";
  } else {
    if (words > 3) s += "[[vk::binding(4, 0)]] RWTexture2DArray<uint> materialBuffer;\n";
    s += "\nstruct PSOutput {\n";
    for (int k = 0; k < rts; ++k) s += fmt::format("  [[vk::location({0})]] uint word{0} : SV_Target{0};\n", k);
    s += "  [[vk::location(3)]] uint topLayer : SV_Target3;\n";
    if (emissive) s += "  [[vk::location(4)]] float4 emissive : SV_Target4;\n";
    s += "};\n\nPSOutput main(PSInput i) {\n";
  }
  s += geometryCode(syn);
  s += fmt::format("  SubstrateClosure closures[{}_CLOSURE_COUNT];\n  float coverage;\n  {} transmittance;\n", upper, v3);
  s += fmt::format("  {}_evaluate(g, closures, coverage, transmittance);\n", m.name);
  s += fmt::format("  uint words[{}_WORD_COUNT];\n  uint topLayer;\n", upper);
  s += fmt::format("  {}_pack(closures, g.dither, words, topLayer);\n", m.name);
  if (glsl) {
    for (int k = 0; k < rts; ++k) s += fmt::format("  outWord{0} = words[{0}];\n", k);
    s += "  outTopLayer = topLayer;\n";
    for (int k = 3; k < words; ++k)
      s += fmt::format("  imageStore(materialBuffer, ivec3(ivec2(gl_FragCoord.xy), {}), uvec4(words[{}], 0u, 0u, 0u));\n",
                       k - 3, k);
  } else {
    s += "  PSOutput o;\n";
    for (int k = 0; k < rts; ++k) s += fmt::format("  o.word{0} = words[{0}];\n", k);
    s += "  o.topLayer = topLayer;\n";
    for (int k = 3; k < words; ++k)
      s += fmt::format("  materialBuffer[uint3(uint2(i.position.xy), {}u)] = words[{}];\n", k - 3, k);
  }
  if (emissive) {
    std::string sum = "SUBSTRATE_SPLAT3(0.0)";
    for (std::size_t c = 0; c < L.closures.size(); ++c)
      if (m.slabs[L.closures[c].slab].features & kFeatEmissive)
        sum += fmt::format(" + closures[{0}].weight * closures[{0}].emissive", c);  // the light-independent part
    s += glsl ? fmt::format("  outEmissive = vec4({}, 1.0);\n", sum) : fmt::format("  o.emissive = float4({}, 1.0);\n", sum);
  }
  s += glsl ? "}\n" : "  return o;\n}\n";
  return s;
}

}  // namespace substratec

namespace substratec {

namespace {

/// Header feature bits of a closure (SUBSTRATE_FEATURE_*, docs/storage.md).
unsigned featureBits(const ClosureLayout& c) {
  unsigned b = 0;
  if (c.storedFeatures & kFeatF90) b |= 1;
  if (c.storedFeatures & kFeatAnisotropy) b |= 2;
  if (c.storedFeatures & kFeatHaze) b |= 4;
  if (c.storedFeatures & kFeatFuzz) b |= 8;
  if (c.storedFeatures & kFeatGlint) b |= 16;
  if (c.storedFeatures & kFeatSpecularProfile) b |= 32;
  if (c.storesWeight) b |= 64;
  if (c.storesCoverageAbove) b |= 128;
  return b;
}

/// The statements that pack every field of `L`, at static bit offsets, from
/// `closures[closureIndex[i]]` for the layout's closure i. `topN` is the
/// top-layer normal already computed (for a tangent angle in its frame).
std::string packFields(const Material& m, const StorageLayout& L, const std::vector<int>& closureIndex,
                       const std::string& indent) {
  const bool multi = L.closures.size() > 1;
  std::string s;
  int offset = 0;
  auto put = [&](const std::string& code, int bits) {
    int w = offset / 32, sh = offset % 32;
    s += fmt::format("{}{{ uint q = {};\n{}  words[{}] |= q << {}u;", indent, code, indent, w, sh);
    if (sh + bits > 32) s += fmt::format("\n{}  words[{}] |= q >> {}u;", indent, w + 1, 32 - sh);
    s += " }\n";
    offset += bits;
  };
  // The SSS type tells the unpacker an SSS field follows: non-zero only when one is stored.
  auto sssCode = [&](const ClosureLayout& c) {
    return (c.storedFeatures & kFeatSss) ? static_cast<unsigned>(m.slabs[c.slab].sssType) : 0u;
  };
  auto closure = [&](int i) { return fmt::format("closures[{}]", closureIndex[i]); };
  const int cls = static_cast<int>(L.layoutClass);
  for (const LayoutField& f : L.fields) {
    const std::string c = f.closure >= 0 ? closure(f.closure) : "";
    const std::string field = f.name.substr(f.name.find('.') + 1);
    s += fmt::format("{}// {} ({} bits at {})\n", indent, f.name, f.bits, offset);
    if (f.name == "header") {
      const ClosureLayout& c0 = L.closures[0];
      put(multi ? fmt::format("substrate_material_header_multi({}u, {}u, {}u)", cls, L.closures.size(), L.basisCount)
                : fmt::format("substrate_material_header_single({}u, {}u, {}u)", cls, featureBits(c0), sssCode(c0)),
          f.bits);
    } else if (field == "header") {
      const ClosureLayout& cl = L.closures[f.closure];
      put(fmt::format("substrate_closure_header({}u, {}, {}u, {}u, {}u)", cl.basis, cl.isTop ? "true" : "false",
                      featureBits(cl), sssCode(cl), cl.extraInterfaces),
          f.bits);
    } else if (field == "diffuse_albedo" || field == "f0" || field == "f90" || field == "top_transmittance") {
      const char* member = field == "diffuse_albedo" ? "diffuseAlbedo" : field == "f0" ? "f0"
                           : field == "f90"          ? "f90"
                                                     : "topTransmittance";
      put(fmt::format("substrate_q_color20({}.{}, dither)", c, member), f.bits);
    } else if (field == "roughness" || field == "weight" || field == "coverage_above") {
      const char* member = field == "roughness" ? "roughness" : field == "weight" ? "weight" : "coverageAbove";
      put(fmt::format("substrate_q_unorm({}.{}, 8u, dither)", c, member), f.bits);
    } else if (field == "sss") {
      put(fmt::format("substrate_q_sss({0}.sssMfp, {0}.sssPhaseAnisotropy, dither)", c), f.bits);
    } else if (field == "haze") {
      put(fmt::format("substrate_q_haze({0}.secondRoughness, {0}.secondRoughnessWeight, dither)", c), f.bits);
    } else if (field == "fuzz") {
      put(fmt::format("substrate_q_fuzz({0}.fuzzAmount, {0}.fuzzColor, {0}.fuzzRoughness, dither)", c), f.bits);
    } else if (field == "anisotropy") {
      put(fmt::format("substrate_q_anisotropy({}.anisotropy, dither)", c), f.bits);
    } else if (field == "specular_profile") {
      put(fmt::format("substrate_q_specular_profile({}.specularProfile)", c), f.bits);
    } else if (field == "glint") {
      const int k = closureIndex[f.closure];
      s += fmt::format("{}uint4 glint{} = uint4(0u, 0u, 0u, 0u);\n", indent, k);
      put(fmt::format("substrate_q_glint({0}.glintValue, {0}.glintUv, {0}.glintUvDerivatives, dither, glint{1})", c, k), 8);
      for (const char* part : {"x", "y", "z", "w"}) put(fmt::format("glint{}.{}", k, part), 32);
    } else if (f.basis >= 0) {
      int first = 0;
      for (std::size_t i = 0; i < L.closures.size(); ++i)
        if (L.closures[i].basis == f.basis) {
          first = static_cast<int>(i);
          break;
        }
      const std::string n = closure(first) + ".N";
      if (field == "normal") {
        put(fmt::format("substrate_q_normal({}, dither)", n), f.bits);
      } else {  // tangent_angle, in the frame of the normal as the unpacker decodes it
        bool elided = !multi || (f.basis == 0 && L.basis0NormalElided);
        std::string stored = elided ? "substrate_top_layer_normal_as_stored(topN, dither)"
                                    : fmt::format("substrate_normal_as_stored({}, dither)", n);
        int aniso = first;
        for (std::size_t i = 0; i < L.closures.size(); ++i)
          if (L.closures[i].basis == f.basis && (L.closures[i].storedFeatures & kFeatAnisotropy)) {
            aniso = static_cast<int>(i);
            break;
          }
        put(fmt::format("substrate_tangent_angle_encode({}.T, {}, dither)", closure(aniso), stored), f.bits);
      }
    }
  }
  return s;
}

/// The run-time test that closure `k` is alone at this pixel with nothing it
/// stores in use (storage/layout.h, runtimeSimpleClosures).
std::string aloneAndPlain(const Material& m, const StorageLayout& L, int k) {
  std::vector<std::string> terms;
  const std::string c = fmt::format("closures[{}]", k);
  for (int j = 0; j < static_cast<int>(L.closures.size()); ++j)
    if (j != k) terms.push_back(fmt::format("!(closures[{}].weight > 0.0)", j));
  const ClosureLayout& cl = L.closures[k];
  if (cl.storesWeight) terms.push_back(c + ".weight >= 1.0");
  if (cl.storesCoverageAbove) terms.push_back(fmt::format("!({}.coverageAbove > 0.0)", c));
  const std::uint16_t f = cl.storedFeatures;
  if (f & kFeatF90) terms.push_back(fmt::format("min(min({0}.f90.x, {0}.f90.y), {0}.f90.z) >= 1.0", c));
  if (f & kFeatAnisotropy) terms.push_back(c + ".anisotropy == 0.0");
  if (f & kFeatSss) terms.push_back(fmt::format("!(substrate_max3({}.sssMfp) > 0.0)", c));
  if (f & kFeatHaze) terms.push_back(fmt::format("!({}.secondRoughnessWeight > 0.0)", c));
  if (f & kFeatFuzz) terms.push_back(fmt::format("!({}.fuzzAmount > 0.0)", c));
  if (f & kFeatGlint) terms.push_back(c + ".glintValue >= 1.0");
  (void)m;
  std::string s;
  for (const std::string& t : terms) s += (s.empty() ? "" : " && ") + t;
  return s.empty() ? "true" : s;
}

}  // namespace

std::string emitPackFunction(const Material& m, const StorageLayout& L, const Syntax& syn, bool dynamicSimplification) {
  const std::string upper = materialUpper(m);
  const std::string v3 = syn.type(VType::Vec3);
  std::string s;
  s += "// Packs the closures into the uint stream of docs/storage.md (static bit offsets, centred dither).\n";
  s += "// Compiled when substrate_pack.h is included before this file (the base pass does).\n";
  s += "#ifdef SUBSTRATE_PACK_H\n";
  s += fmt::format("void {0}_pack(SubstrateClosure closures[{1}_CLOSURE_COUNT], float dither, out uint words[{1}_WORD_COUNT], "
                   "out uint topLayer) {{\n",
                   m.name, upper);
  for (int w = 0; w < L.words(); ++w) s += fmt::format("  words[{}] = 0u;\n", w);
  // Dynamic simplification: a pixel where one closure is left, with nothing
  // it stores in use, is stored in the SIMPLE layout (docs/scenes.md).
  for (int k : dynamicSimplification ? runtimeSimpleClosures(m, L) : std::vector<int>{}) {
    s += fmt::format("  // Dynamic simplification: closure {} ('{}') alone and plain at this pixel -> the SIMPLE layout.\n",
                     k, m.slabs[L.closures[k].slab].id);
    s += fmt::format("  if ({}) {{\n", aloneAndPlain(m, L, k));
    s += fmt::format("    topLayer = substrate_q_top_layer(closures[{0}].N, saturate(closures[{0}].roughness), dither);\n", k);
    s += packFields(m, simpleLayoutOf(L, k), {k}, "    ");
    s += "    return;\n  }\n";
  }
  // Top-layer word: the top closures' normal and roughness, coverage-weighted.
  std::string nsum, rsum, wsum;
  for (std::size_t i = 0; i < L.closures.size(); ++i) {
    if (!L.closures[i].isTop) continue;
    const std::string c = fmt::format("closures[{}]", i);
    nsum += (nsum.empty() ? "" : " + ") + fmt::format("{0}.weight * {0}.N", c);
    rsum += (rsum.empty() ? "" : " + ") + fmt::format("{0}.weight * {0}.roughness", c);
    wsum += (wsum.empty() ? "" : " + ") + fmt::format("{}.weight", c);
  }
  s += fmt::format("  {} topN = substrate_safe_normalize({}, closures[0].N);\n", v3, nsum);
  s += fmt::format("  float topRoughness = saturate(({}) / max({}, 1e-6));\n", rsum, wsum);
  s += "  topLayer = substrate_q_top_layer(topN, topRoughness, dither);\n";
  std::vector<int> identity(L.closures.size());
  for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<int>(i);
  s += packFields(m, L, identity, "  ");
  s += "}\n#endif\n";
  return s;
}

}  // namespace substratec
