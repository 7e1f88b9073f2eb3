#include "emit/scene_emitter.h"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "emit/material_emitter.h"

namespace substratec {

namespace {

constexpr LayoutClass kClasses[] = {LayoutClass::Simple, LayoutClass::Single, LayoutClass::Complex,
                                    LayoutClass::Special};

int rank(LayoutClass c) { return static_cast<int>(c); }

/// The lighting shader that lights tiles whose largest class is `c`: the
/// smallest class of the scene at or above it (the largest one if none is).
const SceneLightingClass& targetOf(const SceneShape& s, LayoutClass c) {
  for (const SceneLightingClass& k : s.classes)
    if (rank(k.cls) >= rank(c)) return k;
  return s.classes.back();
}

std::string featureNames(std::uint16_t mask) {
  std::string s;
  for (int b = 0; b < kFeatureCount; ++b)
    if (mask & (1u << b)) s += (s.empty() ? "" : ", ") + std::string(featureName(b));
  return s.empty() ? "none" : s;
}

/// The frame block, the G-buffer and, with `lighting`, the environment,
/// material buffer, tile lists (read) and the colour target; without it the
/// tile lists and arguments (written).
std::string resources(const Syntax& syn, bool lighting, bool materialBuffer) {
  const bool glsl = syn.target == Target::Glsl;
  std::string s;
  if (glsl) {
    s += fmt::format("layout(local_size_x = {0}, local_size_y = {0}) in;\n", kSceneTileSize);
    s += R"(layout(set = 0, binding = 0, std140) uniform SubstrateSceneFrame {
  vec4 cameraForward;   // xyz: unit view direction; w: tan(half the vertical field of view)
  vec4 cameraRight;     // xyz: unit
  vec4 cameraUp;        // xyz: unit
  vec4 lightDirection;  // xyz: unit vector toward the light
  vec4 lightRadiance;   // rgb
  vec4 envParams;       // x: mip count of envPrefiltered
  uvec4 viewport;       // x, y: size in pixels; z: capacity of each tile list
} frame;
layout(set = 0, binding = 6, r32ui) uniform readonly uimage2DArray gbuffer;  // words 0-2, top-layer word
#define SUBSTRATE_SCENE_GBUFFER(p, layer) imageLoad(gbuffer, ivec3(int((p).x), int((p).y), int(layer))).x
)";
    if (lighting) {
      s += R"(layout(set = 0, binding = 1) uniform samplerCube envPrefiltered;
layout(set = 0, binding = 2) uniform samplerCube envIrradiance;
// set 0, binding 5: the energy tables (a uniform buffer, declared by substrate_energy_lut.h).
layout(set = 0, binding = 7, std430) readonly buffer SubstrateTileLists { uint tiles[]; };
layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D sceneColor;
#define SUBSTRATE_ENV_PREFILTERED(dir, lod) textureLod(envPrefiltered, dir, lod).rgb
#define SUBSTRATE_ENV_IRRADIANCE(dir) textureLod(envIrradiance, dir, 0.0).rgb
#define SUBSTRATE_SCENE_STORE(p, value) imageStore(sceneColor, ivec2(int((p).x), int((p).y)), value)
)";
      if (materialBuffer)
        s += "layout(set = 0, binding = 4, r32ui) uniform readonly uimage2DArray materialBuffer;  // words 3..\n"
             "#define SUBSTRATE_SCENE_MATERIAL_BUFFER(p, slice) imageLoad(materialBuffer, ivec3(int((p).x), "
             "int((p).y), int(slice))).x\n";
    } else {
      s += "layout(set = 0, binding = 7, std430) writeonly buffer SubstrateTileLists { uint tiles[]; };\n";
      s += "layout(set = 0, binding = 9, std430) buffer SubstrateTileArguments { uint tileArgs[]; };\n";
    }
    return s;
  }
  s += R"(struct SubstrateSceneFrameData {
  float4 cameraForward;   // xyz: unit view direction; w: tan(half the vertical field of view)
  float4 cameraRight;     // xyz: unit
  float4 cameraUp;        // xyz: unit
  float4 lightDirection;  // xyz: unit vector toward the light
  float4 lightRadiance;   // rgb
  float4 envParams;       // x: mip count of envPrefiltered
  uint4 viewport;         // x, y: size in pixels; z: capacity of each tile list
};
[[vk::binding(0, 0)]] ConstantBuffer<SubstrateSceneFrameData> frame;
[[vk::binding(6, 0)]] RWTexture2DArray<uint> gbuffer;  // words 0-2, top-layer word (read only)
#define SUBSTRATE_SCENE_GBUFFER(p, layer) gbuffer[uint3((p).x, (p).y, layer)]
)";
  if (lighting) {
    s += R"([[vk::binding(1, 0)]] TextureCube<float4> envPrefiltered;
[[vk::binding(2, 0)]] TextureCube<float4> envIrradiance;
[[vk::binding(3, 0)]] SamplerState envSampler;
// set 0, binding 5: the energy tables (a uniform buffer, declared by substrate_energy_lut.h).
[[vk::binding(7, 0)]] StructuredBuffer<uint> tiles;
[[vk::binding(8, 0)]] RWTexture2D<float4> sceneColor;
#define SUBSTRATE_ENV_PREFILTERED(dir, lod) envPrefiltered.SampleLevel(envSampler, dir, lod).rgb
#define SUBSTRATE_ENV_IRRADIANCE(dir) envIrradiance.SampleLevel(envSampler, dir, 0.0).rgb
#define SUBSTRATE_SCENE_STORE(p, value) sceneColor[(p)] = (value)
)";
    if (materialBuffer)
      s += "[[vk::binding(4, 0)]] RWTexture2DArray<uint> materialBuffer;  // words 3.. (read only)\n"
           "#define SUBSTRATE_SCENE_MATERIAL_BUFFER(p, slice) materialBuffer[uint3((p).x, (p).y, slice)]\n";
  } else {
    s += "[[vk::binding(7, 0)]] RWStructuredBuffer<uint> tiles;\n";
    s += "[[vk::binding(9, 0)]] RWStructuredBuffer<uint> tileArgs;\n";
  }
  return s;
}

/// The entry point's first lines: `group` (the workgroup id) and `local` (the
/// invocation in the tile) as uint2.
std::string entry(const Syntax& syn) {
  if (syn.target == Target::Glsl)
    return "void main() {\n  uint2 group = gl_WorkGroupID.xy;\n  uint2 local = gl_LocalInvocationID.xy;\n";
  return fmt::format("[numthreads({0}, {0}, 1)]\nvoid main(uint3 groupId : SV_GroupID, uint3 localId : SV_GroupThreadID) "
                     "{{\n  uint2 group = groupId.xy;\n  uint2 local = localId.xy;\n",
                     kSceneTileSize);
}

/// Lights closure `c` (an expression) into `color`.
std::string lightClosure(const std::string& c, const std::string& indent) {
  return fmt::format(
      "{0}color += substrate_light_closure({1}, V, L, frame.lightRadiance.rgb);\n"
      "{0}color += substrate_closure_view_throughput({1}, dot({1}.N, V)) *\n"
      "{0}         substrate_env_split_sum({1}, V,\n"
      "{0}                                 SUBSTRATE_ENV_PREFILTERED(substrate_reflection_dir({1}, V),\n"
      "{0}                                                           substrate_env_mip(substrate_env_roughness({1}), "
      "frame.envParams.x)),\n"
      "{0}                                 SUBSTRATE_ENV_IRRADIANCE({1}.N));\n",
      indent, c);
}

std::string materialList(const std::vector<std::string>& names) {
  std::string s;
  for (const std::string& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

std::string tileClassName(LayoutClass cls) {
  std::string s(layoutClassName(cls));
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return s;
}

SceneShape sceneShape(const std::string& name, const std::vector<SceneMaterialShape>& materials, DiffuseModel diffuseModel) {
  SceneShape s;
  s.name = name;
  s.diffuseModel = diffuseModel;
  for (LayoutClass c : kClasses) {
    bool present = false;
    for (const SceneMaterialShape& m : materials)
      present = present || m.layoutClass == c || (c == LayoutClass::Simple && m.runtimeSimple);
    if (!present) continue;
    SceneLightingClass k;
    k.cls = c;
    for (const SceneMaterialShape& m : materials) {
      // Pixels of class c or below: the material's static layout, or its
      // dynamically simplified pixels (SIMPLE: no feature, one closure, two words).
      const bool full = rank(m.layoutClass) <= rank(c);
      if (!full && !m.runtimeSimple) continue;
      k.materials.push_back(m.name);
      if (!full) continue;
      k.features |= m.storedFeatures;
      k.maxClosures = std::max(k.maxClosures, m.closures);
      k.maxWords = std::max(k.maxWords, m.words);
    }
    s.classes.push_back(k);
  }
  for (const SceneMaterialShape& m : materials) {
    s.storedFeatures |= m.storedFeatures;
    s.maxWords = std::max(s.maxWords, m.words);
    s.maxClosures = std::max(s.maxClosures, m.closures);
  }
  return s;
}

std::string sceneLightingFileName(const SceneShape& scene, LayoutClass cls, const Syntax& syn) {
  return fmt::format("{}.lighting_{}{}", scene.name, tileClassName(cls), syn.target == Target::Glsl ? ".comp" : ".cs.hlsl");
}

std::string tileClassificationFileName(const SceneShape& scene, const Syntax& syn) {
  return fmt::format("{}.classify_tiles{}", scene.name, syn.target == Target::Glsl ? ".comp" : ".cs.hlsl");
}

std::string emitSceneLighting(const SceneShape& scene, const SceneLightingClass& k, const Syntax& syn) {
  const bool glsl = syn.target == Target::Glsl;
  const bool simple = k.cls == LayoutClass::Simple;
  const bool one = k.maxClosures == 1;  // every pixel has a single-closure header
  std::string s;
  if (glsl) s += "#version 450\n#extension GL_GOOGLE_include_directive : require\n";
  s += fmt::format(
      "// Generated by substratec: the deferred lighting of scene '{}' for {} tiles ({} pixels and below).\n"
      "// Materials it may light: {}.\n"
      "// Stored features: {}; at most {} closure(s) and {} word(s) a pixel. Bindings: compiler/core/emit/scene_emitter.h.\n",
      scene.name, layoutClassName(k.cls), layoutClassName(k.cls), materialList(k.materials), featureNames(k.features),
      k.maxClosures, k.maxWords);
  s += useDefines(k.features & ~kFeatEmissive);  // the base pass adds emissive
  // Extra interfaces are in closure headers only: a lone closure is on top.
  s += fmt::format("#define SUBSTRATE_USE_EXTRA_INTERFACES {}\n", k.maxClosures > 1 ? 1 : 0);
  s += fmt::format("#define SUBSTRATE_DIFFUSE_MODEL {}\n", diffuseModelNumber(scene.diffuseModel));
  s += fmt::format("#define SUBSTRATE_MAX_CLOSURES {}\n", k.maxClosures);
  s += fmt::format("#define SUBSTRATE_MAX_WORDS {}\n", k.maxWords);
  s += fmt::format("#define SUBSTRATE_SCENE_TILE_CLASS {}u  // this shader's tile list\n", rank(k.cls));
  s += fmt::format("#include \"{}\"\n", syn.prelude);
  s += "#include \"substrate_closure.h\"\n#include \"substrate_common.h\"\n#include \"substrate_pack.h\"\n"
       "#include \"substrate_unpack.h\"\n#include \"substrate_energy_lut.h\"\n#include \"substrate_bsdf.h\"\n"
       "#include \"substrate_lighting.h\"\n\n";
  s += resources(syn, true, k.maxWords > 3);
  s += R"(
// The direction to the eye at the centre of pixel p (a pinhole camera).
float3 substrate_scene_view(uint2 p) {
  float2 ndc = ((float2(p) + SUBSTRATE_SPLAT2(0.5)) / float2(frame.viewport.xy)) * 2.0 - SUBSTRATE_SPLAT2(1.0);
  float aspect = float(frame.viewport.x) / float(frame.viewport.y);
  float3 dir = normalize(frame.cameraForward.xyz + (ndc.x * aspect * frame.cameraForward.w) * frame.cameraRight.xyz -
                         (ndc.y * frame.cameraForward.w) * frame.cameraUp.xyz);
  return -dir;
}

)";
  s += entry(syn);
  s += fmt::format(R"(  uint tile = tiles[SUBSTRATE_SCENE_TILE_CLASS * frame.viewport.z + group.x];
  uint2 pixel = uint2(tile & 0xffffu, tile >> 16u) * {}u + local;
  if (pixel.x >= frame.viewport.x || pixel.y >= frame.viewport.y) {{
    return;
  }}
  uint words[SUBSTRATE_MAX_WORDS];
)",
                   kSceneTileSize);
  for (int w = 0; w < k.maxWords; ++w)
    s += w < 3 ? fmt::format("  words[{0}] = SUBSTRATE_SCENE_GBUFFER(pixel, {0}u);\n", w)
               : fmt::format("  words[{}] = SUBSTRATE_SCENE_MATERIAL_BUFFER(pixel, {}u);\n", w, w - 3);
  s += "  uint topLayer = SUBSTRATE_SCENE_GBUFFER(pixel, 3u);\n";
  s += "  float3 V = substrate_scene_view(pixel);\n  float3 L = frame.lightDirection.xyz;\n";
  s += "  float3 color = SUBSTRATE_SPLAT3(0.0);\n";
  if (simple) {
    s += "  // SIMPLE pixels only: three fields at fixed offsets, one closure of weight 1, no feature.\n";
    s += "  SubstrateClosure c;\n  substrate_unpack_simple(words, topLayer, c);\n";
    s += lightClosure("c", "  ");
  } else if (one) {
    s += "  // One closure a pixel (single-closure headers): no loop.\n";
    s += "  SubstrateClosure c;\n  substrate_unpack_single_closure(words, topLayer, c);\n";
    s += "  if (substrate_closure_visible(c)) {  // dynamic culling: weight 0 here\n";
    s += lightClosure("c", "    ");
    s += "  }\n";
  } else {
    s += "  SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES];\n";
    s += "  uint count = substrate_unpack_material(words, topLayer, closures);\n";
    s += "  for (uint k = 0u; k < uint(SUBSTRATE_MAX_CLOSURES); ++k) {\n";
    s += "    if (k >= count || !substrate_closure_visible(closures[k])) continue;  // dynamic culling: weight 0 here\n";
    s += lightClosure("closures[k]", "    ");
    s += "  }\n";
  }
  s += "  SUBSTRATE_SCENE_STORE(pixel, float4(color, 1.0));\n}\n";
  return s;
}

std::string emitTileClassification(const SceneShape& scene, const Syntax& syn) {
  const bool glsl = syn.target == Target::Glsl;
  std::string s;
  if (glsl) s += "#version 450\n#extension GL_GOOGLE_include_directive : require\n";
  std::string classes;
  for (const SceneLightingClass& k : scene.classes) classes += (classes.empty() ? "" : ", ") + tileClassName(k.cls);
  s += fmt::format(
      "// Generated by substratec: tile classification of scene '{}'. Each {}x{} tile goes to the list of the\n"
      "// cheapest lighting shader of the scene that handles its most complex pixel ({}).\n"
      "// Bindings: compiler/core/emit/scene_emitter.h.\n",
      scene.name, kSceneTileSize, kSceneTileSize, classes);
  s += fmt::format("#include \"{}\"\n#include \"substrate_closure.h\"\n#include \"substrate_pack.h\"\n\n", syn.prelude);
  s += resources(syn, false, false);
  s += "\n// The lighting shader (SUBSTRATE_LAYOUT_*) of a tile whose most complex pixel is of class c.\n";
  s += "uint substrate_scene_tile_target(uint c) {\n";
  for (LayoutClass c : {LayoutClass::Simple, LayoutClass::Single, LayoutClass::Complex})
    s += fmt::format("  if (c <= {}u) {{\n    return {}u;\n  }}\n", rank(c), rank(targetOf(scene, c).cls));
  s += fmt::format("  return {}u;\n}}\n\n", rank(targetOf(scene, LayoutClass::Special).cls));
  s += glsl ? "shared uint substrateTileClass;\n\n" : "groupshared uint substrateTileClass;\n\n";
  s += entry(syn);
  const std::string barrier = glsl ? "  memoryBarrierShared();\n  barrier();\n" : "  GroupMemoryBarrierWithGroupSync();\n";
  s += fmt::format("  uint index = local.y * {}u + local.x;\n", kSceneTileSize);
  s += fmt::format("  if (index == 0u) {{\n    substrateTileClass = {}u;\n  }}\n", rank(scene.classes.front().cls));
  s += barrier;
  s += fmt::format("  uint2 pixel = group * {}u + local;\n", kSceneTileSize);
  s += "  if (pixel.x < frame.viewport.x && pixel.y < frame.viewport.y) {\n";
  s += "    uint c = substrate_scene_tile_target(substrate_layout_class(SUBSTRATE_SCENE_GBUFFER(pixel, 0u)));\n";
  s += glsl ? "    atomicMax(substrateTileClass, c);\n" : "    InterlockedMax(substrateTileClass, c);\n";
  s += "  }\n";
  s += barrier;
  s += "  if (index == 0u) {\n    uint c = substrateTileClass;\n";
  s += glsl ? "    uint slot = atomicAdd(tileArgs[c * 4u], 1u);\n"
            : "    uint slot;\n    InterlockedAdd(tileArgs[c * 4u], 1u, slot);\n";
  s += "    tiles[c * frame.viewport.z + slot] = group.x | (group.y << 16u);\n  }\n}\n";
  return s;
}

}  // namespace substratec
