// `substratec render`: meshes drawn on lavapipe with what `compile` and
// `scene` emit, run as an engine runs them (docs/render.md):
//
//   deferred (the default)
//     1. G-buffer pass (one render pass): a depth pre-pass of every opaque
//        primitive with the runtime's vertex stage alone, then each
//        material's `<name>.basepass` with depth test EQUAL and early
//        fragment tests, writing words 0-2, the top-layer word and emissive
//        into five colour attachments and words 3.. into the material buffer;
//     2. the scene's tile classification, then each tile class's lighting
//        shader over its tiles (emit/scene_emitter.h), both as `scene` emits
//        them for the materials drawn;
//     3. composite: lit colour + emissive where something was drawn, the
//        environment where nothing was;
//     4. forward pass over that: masked materials (the base pass keeps no
//        coverage) with `<name>.forward`, then translucent ones back to
//        front, blended dual-source (colour + background x throughput).
//        A single-layer water is drawn between the two, with its forward
//        entry, over what lies behind it: the frame so far as its set 0,
//        binding 6 (rgb the colour, a the distance from the eye).
//   --forward
//     1. every opaque and masked primitive with its `<name>.forward`, depth
//        test LESS; 3. and 4. as above for the waters and translucent ones.
//
// One directional light (preview's key light) and the split-sum environment,
// as the generated lighting expects. GLSL or HLSL: the same passes, the
// language's shaders.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "emit/syntax.h"
#include "gpu/harness.h"
#include "mesh/gltf_mesh.h"
#include "pipeline/pipeline.h"
#include "preview/environment.h"
#include "preview/image.h"
#include "preview/textures.h"

namespace substratec::render {

/// One material of a render: its compile result and its bound textures (null: every texture input
/// gets its neutral texel).
struct SceneMaterial {
  const CompileResult* result = nullptr;
  const preview::BoundTextures* textures = nullptr;
};

struct RenderOptions {
  int width = 512, height = 512;
  bool forward = false;  // draw every opaque material with its forward pass instead of the deferred path
  Target target = Target::Glsl;
  std::string environment = preview::kDefaultEnvironment;
  DiffuseModel diffuseModel = kDefaultDiffuseModel;
};

/// What the passes cost and what they drew. Two clocks: timestamp queries
/// around each pass's GPU work (uploads and read-backs excluded), and the
/// host's wall time of each submission (uploads, the work, read-backs; no
/// shader or pipeline compilation). The timestamps of render's 512 x 512
/// lighting dispatch read 0.07 ms, which cannot be (not understood yet,
/// docs/performance.md "render"): read the wall times for classify and lighting.
struct RenderStats {
  double opaqueNs = 0;       // deferred: pre-pass + base pass; forward: the opaque forward pass
  double classifyNs = 0;     // deferred: tile classification
  double lightingNs = 0;     // deferred: every tile class's lighting
  double forwardNs = 0;      // the forward pass after lighting (masked, translucent), when it has draws
  double opaqueWallNs = 0, classifyWallNs = 0, lightingWallNs = 0, forwardWallNs = 0;  // the same, host wall time
  int draws = 0;             // primitives drawn (a pre-pass draw not counted)
  std::array<std::size_t, 4> tiles{};  // deferred: tiles per class (simple, single, complex, special)
  std::size_t coveredPixels = 0;       // pixels some primitive covers
};

/// A render: linear HDR colour (alpha 1), the depth attachment (1 where nothing was drawn), what it cost.
struct RenderResult {
  preview::Image hdr;
  std::vector<float> depth;
  RenderStats stats;
};

/// Draws `scene` from `camera`: primitive i with materials[primitiveMaterial[i]]. False, with errors
/// reported, when a shader does not validate (a compiler bug: "internal compiler error") or a pass fails.
bool renderScene(gpu::Context& ctx, const mesh::Scene& scene, const std::vector<SceneMaterial>& materials,
                 const std::vector<int>& primitiveMaterial, const mesh::Camera& camera, const RenderOptions& o,
                 RenderResult* out, Diagnostics& diags);

/// The tone map's gains for a render under `environment` (preview::calibrationGains' convention for the
/// render's one light): π / E_c for the irradiance a surface facing `towardCamera` receives.
std::array<double, 3> renderCalibrationGains(const std::string& environment, const std::array<double, 3>& towardCamera);

}  // namespace substratec::render
