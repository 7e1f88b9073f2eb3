// A G-buffer for a scene's lighting shaders (emit/scene_emitter.h) on
// lavapipe: pixels packed by the CPU mirror of docs/storage.md from the CPU
// reference's closures (the SIMPLE layout where dynamic simplification would
// store one, storage/pack.h runtimeSimpleClosure), and the resources of the
// tile-classification and lighting dispatches. The GPU tests check the
// scene's shaders with it; bench/scene_lighting times them.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "emit/scene_emitter.h"
#include "gpu/harness.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"
#include "storage/pack.h"

namespace substratec::gpu {

/// The camera, light and (constant) environment of SubstrateSceneFrame.
struct SceneFrame {
  uint32_t width = 0, height = 0;
  std::array<double, 3> forward{0, 0, -1}, right{1, 0, 0}, up{0, 1, 0};
  double tanHalfFov = 0.4;
  std::array<double, 3> light{0.3, 0.5, 0.8124038404635961};  // unit
  std::array<double, 3> radiance{2.0, 1.8, 1.6};
  std::array<double, 3> prefiltered{0.6, 0.5, 0.4};  // every direction and mip
  std::array<double, 3> irradiance{1.2, 1.0, 0.8};
  double envMips = 1;  // mip levels of the prefiltered environment (envParams.x; 1: the constant one above)

  uint32_t tilesX() const { return (width + kSceneTileSize - 1) / kSceneTileSize; }
  uint32_t tilesY() const { return (height + kSceneTileSize - 1) / kSceneTileSize; }
  uint32_t tiles() const { return tilesX() * tilesY(); }
  /// The direction to the eye at the centre of pixel (x, y), as the lighting computes it.
  std::array<double, 3> view(uint32_t x, uint32_t y) const;
};

/// One packed pixel and what it holds.
struct GbufferPixel {
  std::vector<uint32_t> words;
  uint32_t topLayer = 0;
  LayoutClass cls = LayoutClass::Simple;
  std::vector<reference::Closure<double>> closures;  // read back by the CPU unpacker (world space)
};

/// A reference closure as the packer's values (storage/pack.h).
ClosureValues closureValues(const reference::Closure<double>& c);

/// The closures the reference evaluates for `r` at `g` with `inputs`, packed
/// as the base pass packs them (with dynamic simplification) and read back.
GbufferPixel packPixel(const CompileResult& r, const reference::Geometry& g, const reference::InputValues& inputs);

/// A shading point of pixel (x, y) facing the eye: V from the frame, N tilted
/// from V by the pixel, uv given, a per-pixel dither.
reference::Geometry pixelGeometry(const SceneFrame& f, uint32_t x, uint32_t y, std::array<double, 2> uv);

class Gbuffer {
 public:
  Gbuffer(uint32_t width, uint32_t height, int slices);
  void set(uint32_t x, uint32_t y, const GbufferPixel& p);
  /// The G-buffer image (layers 0-2 words, 3 the top-layer word) and the material buffer (words 3..).
  StorageImageResource gbufferImage() const;
  StorageImageResource materialBufferImage() const;

 private:
  uint32_t width_, height_;
  int slices_;
  std::vector<uint32_t> layers_, material_;
};

/// The tile lists classification wrote: tile ids (ty * tilesX + tx) per class.
struct TileLists {
  std::array<std::vector<uint32_t>, 4> tiles;
  std::vector<uint32_t> raw;  // the list buffer as written (what the lighting reads)
};

/// SubstrateSceneFrame (emit/scene_emitter.h) for `f`; viewport.z = f.tiles().
BufferResource sceneFrameBlock(const SceneFrame& f);

/// Runs a classification pipeline over `gbuffer`; false, with errors reported, on failure.
bool classifyTiles(Context& ctx, const ComputePipeline& classify, const SceneFrame& f, const Gbuffer& gbuffer,
                   TileLists* out, Diagnostics& diags);
/// The same over a G-buffer image (4 layers of r32ui: words 0-2, the top-layer word); with `ns`, the
/// dispatch's timestamps (Context::dispatch).
bool classifyTiles(Context& ctx, const ComputePipeline& classify, const SceneFrame& f,
                   const StorageImageResource& gbufferImage, TileLists* out, Diagnostics& diags, double* ns = nullptr);

/// The resources of one lighting dispatch (its reflection says which it uses);
/// the colour target (binding 8) is an RGBA32F output of the frame's size.
Resources lightingResources(const ComputePipeline& lighting, const SceneFrame& f, const Gbuffer& gbuffer,
                            const TileLists& lists);

}  // namespace substratec::gpu
