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
  std::string s = syn.uniformBlock(0, 0, "SubstrateSceneFrame", "frame",
                                   "  float4 cameraForward;   // xyz: unit view direction; w: tan(half the vertical field of view)\n"
                                   "  float4 cameraRight;     // xyz: unit\n"
                                   "  float4 cameraUp;        // xyz: unit\n"
                                   "  float4 lightDirection;  // xyz: unit vector toward the light\n"
                                   "  float4 lightRadiance;   // rgb\n"
                                   "  float4 envParams;       // x: mip count of envPrefiltered\n"
                                   "  uint4 viewport;         // x, y: size in pixels; z: capacity of each tile list\n");
  s += "// G-buffer: words 0-2 and the top-layer word in layers 0-3.\n";
  s += syn.storageImage(0, 6, Access::Read, ImageKind::UintArray, "gbuffer");
  if (!lighting)
    return s + syn.storageBuffer(0, 7, Access::Write, "SubstrateTileLists", "uint", "tiles") +
           syn.storageBuffer(0, 9, Access::ReadWrite, "SubstrateTileArguments", "uint", "tileArgs");
  s += environmentResources(syn);
  s += syn.storageBuffer(0, 7, Access::Read, "SubstrateTileLists", "uint", "tiles");
  s += syn.storageImage(0, 8, Access::Write, ImageKind::Float4, "sceneColor");
  if (materialBuffer) {
    s += "// Material buffer: words 3.. in layers 0..\n";
    s += syn.storageImage(0, 4, Access::Read, ImageKind::UintArray, "materialBuffer");
  }
  return s;
}

/// The entry point's first lines: `group` (the workgroup id) and `local` (the
/// invocation in the tile) as uint2.
std::string entry(const Syntax& syn) {
  return syn.computeMain(kSceneTileSize, kSceneTileSize) +
         fmt::format("  uint2 group = {}.xy;\n  uint2 local = {}.xy;\n", syn.computeId(ComputeId::Group),
                     syn.computeId(ComputeId::Local));
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

SceneShape sceneShape(const std::string& name, const std::vector<SceneMaterialShape>& all, DiffuseModel diffuseModel) {
  std::vector<SceneMaterialShape> materials;  // the surfaces: a volume stores no pixel for the lighting to read
  for (const SceneMaterialShape& m : all)
    if (m.layoutClass != LayoutClass::Volume) materials.push_back(m);
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
      k.metalnessMix = k.metalnessMix || m.metalnessMix;
      k.conductorCurve = k.conductorCurve || m.conductorCurve;
      k.lowIorCurve = k.lowIorCurve || m.lowIorCurve;
      if (!full) continue;
      k.noClosure = k.noClosure || m.closures == 0;
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
  return fmt::format("{}.lighting_{}{}", scene.name, tileClassName(cls), syn.computeExtension);
}

std::string tileClassificationFileName(const SceneShape& scene, const Syntax& syn) {
  return fmt::format("{}.classify_tiles{}", scene.name, syn.computeExtension);
}

namespace {

/// The runtime's switches for one tile class's lighting: what the stream's
/// headers cannot rule out stays compiled.
std::string sceneUseDefines(const SceneLightingClass& k) {
  std::string s;
  s += useDefines(k.features & ~(kFeatEmissive | kFeatWater));  // the base pass adds emissive and a water's body
  // Extra interfaces are in closure headers only: a lone closure is on top.
  s += fmt::format("#define SUBSTRATE_USE_EXTRA_INTERFACES {}\n", k.maxClosures > 1 ? 1 : 0);
  s += fmt::format("#define SUBSTRATE_USE_LAYERS {}\n", k.maxClosures > 1 ? 1 : 0);  // so are layers
  // Nor what F0 the closures under layers have.
  s += fmt::format("#define SUBSTRATE_USE_COAT_CONDUCTOR {}\n", k.maxClosures > 1 ? 1 : 0);
  s += fmt::format("#define SUBSTRATE_USE_COAT_FLOOR {}\n", k.maxClosures > 1 ? 1 : 0);  // nor what is on top
  // A stretched top's floor only where some closure of the class is anisotropic.
  s += fmt::format("#define SUBSTRATE_USE_COAT_ANISO {}\n", k.maxClosures > 1 && (k.features & kFeatAnisotropy) ? 1 : 0);
  // Nor which closures under layers wrap or have a fuzz.
  s += fmt::format("#define SUBSTRATE_USE_WRAP_UNDER_LAYERS {}\n", k.maxClosures > 1 ? 1 : 0);
  s += fmt::format("#define SUBSTRATE_USE_FUZZ_UNDER_LAYERS {}\n", k.maxClosures > 1 ? 1 : 0);
  // Only an unlit material's pixels hold the no-closure header (host-cleared
  // pixels hold 0): a class that lights none compiles no test for it.
  s += fmt::format("#define SUBSTRATE_USE_NO_CLOSURE {}\n", k.noClosure ? 1 : 0);
  // The stream does not say which closures are metalness mixes, so a class
  // that lights some material with a metalness slab reads every conductor-like
  // F0 as one (the runtime's default); a class that lights none reads none,
  // as those materials' own shaders do. (It read them all: a thin film's or a
  // coat's coloured F0 over a diffuse was lit 7-25 % brighter deferred than
  // forward, RenderCorpus on open_pbr_pearl; docs/scenes.md.)
  s += fmt::format("#define SUBSTRATE_USE_METALNESS_MIX {}\n", k.metalnessMix ? 1 : 0);
  // Nor which closures are conductors: a class compiles their curve when one of
  // its materials does, so a material lit alone is lit deferred as forward.
  s += fmt::format("#define SUBSTRATE_USE_CONDUCTOR_CURVE {}\n", k.conductorCurve ? 1 : 0);
  // Nor which are dielectrics of low IOR with no layers: likewise.
  s += fmt::format("#define SUBSTRATE_USE_LOW_IOR_CURVE {}\n", k.lowIorCurve ? 1 : 0);
  return s;
}

}  // namespace

std::string emitSceneLighting(const SceneShape& scene, const SceneLightingClass& k, const Syntax& syn) {
  const bool simple = k.cls == LayoutClass::Simple;
  const bool one = k.maxClosures == 1;  // every pixel has a single-closure header
  std::string s(syn.header);
  s += fmt::format(
      "// Generated by substratec: the deferred lighting of scene '{}' for {} tiles ({} pixels and below).\n"
      "// Materials it may light: {}.\n"
      "// Stored features: {}; at most {} closure(s) and {} word(s) a pixel. Bindings: compiler/core/emit/scene_emitter.h.\n",
      scene.name, layoutClassName(k.cls), layoutClassName(k.cls), materialList(k.materials), featureNames(k.features),
      k.maxClosures, k.maxWords);
  s += sceneUseDefines(k);
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
    s += w < 3 ? fmt::format("  words[{0}] = SUBSTRATE_IMAGE_LOAD_LAYER(gbuffer, pixel, {0}u);\n", w)
               : fmt::format("  words[{}] = SUBSTRATE_IMAGE_LOAD_LAYER(materialBuffer, pixel, {}u);\n", w, w - 3);
  s += "  uint topLayer = SUBSTRATE_IMAGE_LOAD_LAYER(gbuffer, pixel, 3u);\n";
  s += "  float3 V = substrate_scene_view(pixel);\n  float3 L = frame.lightDirection.xyz;\n";
  s += "  float3 color = SUBSTRATE_SPLAT3(0.0);\n";
  if (simple) {
    s += "  // SIMPLE pixels only: three fields at fixed offsets, one closure of weight 1, no feature.\n";
    s += "  SubstrateClosure c;\n  substrate_unpack_simple(words, topLayer, c);\n";
    s += lightClosureCode("c", "V", "  ");
  } else if (one) {
    s += "  // One closure a pixel (single-closure headers): no loop.\n";
    s += "  SubstrateClosure c;\n  substrate_unpack_single_closure(words, topLayer, c);\n";
    s += "  if (substrate_closure_visible(c)) {  // dynamic culling: weight 0 here\n";
    s += lightClosureCode("c", "V", "    ");
    s += "  }\n";
  } else {
    s += "  SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES];\n";
    s += "  uint count = substrate_unpack_material(words, topLayer, closures);\n";
    s += "  for (uint k = 0u; k < uint(SUBSTRATE_MAX_CLOSURES); ++k) {\n";
    s += "    if (k >= count || !substrate_closure_visible(closures[k])) continue;  // dynamic culling: weight 0 here\n";
    s += lightClosureCode("closures[k]", "V", "    ");
    s += "  }\n";
  }
  s += "  SUBSTRATE_IMAGE_STORE(sceneColor, pixel, float4(color, 1.0));\n}\n";
  return s;
}

std::string emitTileClassification(const SceneShape& scene, const Syntax& syn) {
  std::string s(syn.header);
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
  s += "groupshared uint substrateTileClass;\n\n";
  s += entry(syn);
  const std::string barrier = "  GroupMemoryBarrierWithGroupSync();\n";
  s += fmt::format("  uint index = local.y * {}u + local.x;\n", kSceneTileSize);
  s += fmt::format("  if (index == 0u) {{\n    substrateTileClass = {}u;\n  }}\n", rank(scene.classes.front().cls));
  s += barrier;
  s += fmt::format("  uint2 pixel = group * {}u + local;\n", kSceneTileSize);
  s += "  if (pixel.x < frame.viewport.x && pixel.y < frame.viewport.y) {\n";
  s += "    uint c = substrate_scene_tile_target(substrate_layout_class(SUBSTRATE_IMAGE_LOAD_LAYER(gbuffer, pixel, 0u)));\n";
  s += "    InterlockedMax(substrateTileClass, c);\n";
  s += "  }\n";
  s += barrier;
  s += "  if (index == 0u) {\n    uint c = substrateTileClass;\n";
  s += "    uint slot;\n    InterlockedAdd(tileArgs[c * 4u], 1u, slot);\n";
  s += "    tiles[c * frame.viewport.z + slot] = group.x | (group.y << 16u);\n  }\n}\n";
  return s;
}

}  // namespace substratec
