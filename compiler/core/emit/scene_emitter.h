// The deferred lighting of a scene (docs/scenes.md): compute shaders made for
// what the scene's materials store after simplification, and no more.
//
//  - a tile-classification shader: one 8x8 tile per workgroup reads each
//    pixel's layout class (word 0, bits 0-1), takes the tile's largest, maps
//    it to the cheapest lighting shader the scene has that handles it, and
//    appends the tile to that class's list (indirect-dispatch arguments and
//    tile lists in two buffers);
//  - one lighting shader per tile class the scene's pixels can have (SIMPLE,
//    SINGLE, COMPLEX, SPECIAL): one workgroup per listed tile, each pixel's
//    words read from the G-buffer and the material buffer, unpacked and lit
//    (one directional light and the split-sum environment). Each is compiled
//    with only the features, closures and words of the materials whose pixels
//    it may light (those of its class or a lower one): a SIMPLE shader reads
//    three fields at fixed offsets and lights one closure without a loop; a
//    scene without anisotropy, fuzz, ... compiles none of their code.
//
// Both languages from one emitter: the bodies are the runtime's common
// dialect; resources and entry signatures go through the Syntax table.
//
// Bindings (set 0), shared by the two kinds:
//   0  SubstrateSceneFrame (std140 / cbuffer), float4 each: cameraForward (xyz
//      unit, w tan of half the vertical field of view), cameraRight, cameraUp,
//      lightDirection (xyz, toward the light), lightRadiance (rgb), envParams
//      (x: mip count of envPrefiltered), then uint4 viewport (x width, y height
//      in pixels, z tiles per class list: the capacity of each list)
//   1, 2  envPrefiltered, envIrradiance (cube maps; HLSL samples with 3)
//   4  materialBuffer: words 3.. of each pixel (r32ui 2D array, layer = word - 3;
//      what the base passes write; bound only when the scene needs more than 3 words)
//   5  the runtime's energy tables (substrate_energy_lut.h)
//   6  gbuffer: r32ui 2D array, layers 0-2 the render-target words, 3 the top-layer word
//   7  tile lists: uint per tile (x | y << 16), class c's list at c * viewport.z
//   8  sceneColor: rgba32f storage image (lighting writes every pixel of its tiles)
//   9  tile arguments: uint4 per class (x: tiles listed, y = z = 1: indirect
//      dispatch arguments); the host sets them to (0, 1, 1, 0) before classifying
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "emit/syntax.h"
#include "ir/enums.h"
#include "storage/layout.h"

namespace substratec {

/// What the lighting needs of one compiled material (batch/batch.h keeps it).
struct SceneMaterialShape {
  std::string name;
  LayoutClass layoutClass = LayoutClass::Simple;
  bool runtimeSimple = false;       // its base pass may also store pixels SIMPLE (dynamic simplification)
  std::uint16_t storedFeatures = 0; // kFeat* bits its closures store
  int closures = 1;
  int words = 2;
  bool metalnessMix = false;        // its shaders read conductor-like F0 as a metalness mix (Material::metalnessMix)
  bool conductorCurve = false;      // its shaders follow a conductor's own Fresnel curve (usesConductorCurve)
  bool lowIorCurve = false;         // and a low-IOR dielectric's (usesLowIorCurve)
};

/// One lighting shader: the pixels of tiles of `cls`, which may hold any class up to it.
struct SceneLightingClass {
  LayoutClass cls = LayoutClass::Simple;
  std::uint16_t features = 0;  // stored features of the materials it may light
  int maxClosures = 1;
  int maxWords = 2;
  std::vector<std::string> materials;  // those materials (names, scene order)
  bool metalnessMix = false;           // some of them is a metalness mix (SUBSTRATE_USE_METALNESS_MIX)
  bool conductorCurve = false;         // some of them follows a conductor's curve (SUBSTRATE_USE_CONDUCTOR_CURVE)
  bool lowIorCurve = false;            // some of them a low-IOR dielectric's (SUBSTRATE_USE_LOW_IOR_CURVE)
  bool noClosure = false;              // some of them has no closure (unlit only: SUBSTRATE_USE_NO_CLOSURE)
};

struct SceneShape {
  std::string name;
  std::vector<SceneLightingClass> classes;  // the classes the scene's pixels can have, ascending
  std::uint16_t storedFeatures = 0;         // union over the materials
  int maxWords = 2;
  int maxClosures = 1;
  DiffuseModel diffuseModel = kDefaultDiffuseModel;
};

inline constexpr int kSceneTileSize = 8;

/// The lighting shaders a scene of these materials needs (volumes have none:
/// they store no pixel; a scene needs one surface, scene.cc checks).
SceneShape sceneShape(const std::string& name, const std::vector<SceneMaterialShape>& materials, DiffuseModel diffuseModel);

/// Material-buffer slices to allocate: words beyond the three render targets.
inline int materialBufferSlices(const SceneShape& s) { return s.maxWords > 3 ? s.maxWords - 3 : 0; }

std::string emitSceneLighting(const SceneShape& scene, const SceneLightingClass& cls, const Syntax& syn);
std::string emitTileClassification(const SceneShape& scene, const Syntax& syn);

/// `<scene>.lighting_<class>.comp` / `.cs.hlsl`, `<scene>.classify_tiles.comp` / `.cs.hlsl`.
std::string sceneLightingFileName(const SceneShape& scene, LayoutClass cls, const Syntax& syn);
std::string tileClassificationFileName(const SceneShape& scene, const Syntax& syn);
/// "simple", "single", "complex", "special".
std::string tileClassName(LayoutClass cls);

}  // namespace substratec
