// A small Vulkan harness for lavapipe (Mesa's software Vulkan driver): tests
// and `substratec preview` run generated compute shaders on it, `substratec
// render` draws meshes with generated fragment shaders through raster passes,
// and both read the results back. Vulkan is loaded at run time (vulkan_loader.h), the
// Khronos validation layer is always on, and any warning or error it reports
// fails the dispatch: lavapipe runs shaders with broken interfaces and still
// returns plausible numbers, so the layer is the only witness.
//
// Usage: Context::create -> createPipeline(spirv) -> dispatch(pipeline, resources, ...)
// as often as needed. A Context and its pipelines are used from one thread at a
// time; pipelines must not outlive their Context.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "diag/diagnostics.h"
#include "gpu/spirv_reflect.h"

namespace substratec::gpu {

enum class Filter { Nearest, Linear };           // for magnification, minification and between mips
enum class Address { Repeat, ClampToEdge, MirroredRepeat };
enum class StorageFormat { R32Uint, R32G32B32A32Sfloat };

/// A uniform or storage buffer (the descriptor type comes from reflection). Not output: `data` is
/// uploaded. Output: `data` only gives the size; before each dispatch the buffer is filled with
/// quiet-NaN words (0x7fc00000), and afterwards it is read back into `data`. Output with `initialized`:
/// `data` is uploaded and read back (a buffer the shader updates, e.g. with atomics).
struct BufferResource {
  std::vector<std::byte> data;
  bool output = false;
  bool initialized = false;
};

/// An RGBA32F sampled texture, for CombinedImageSampler and SampledImage bindings. A Cube binding
/// needs layers == 6 (faces +X,-X,+Y,-Y,+Z,-Z) and width == height; an arrayed 2D binding any layers.
struct ImageResource {
  uint32_t width = 0, height = 0;
  uint32_t layers = 1;
  std::vector<std::vector<float>> mips;  // mips[level]: 4 floats per texel, layer-major then row-major
  Filter filter = Filter::Nearest;       // ignored for a SampledImage binding (no sampler there)
  Address address = Address::Repeat;     // u and w (and v unless addressV says otherwise)
  std::optional<Address> addressV;
};

/// A separate sampler (HLSL SamplerState) for a Sampler binding.
struct SamplerResource {
  Filter filter = Filter::Nearest;
  Address address = Address::Repeat;  // u and w (and v unless addressV says otherwise)
  std::optional<Address> addressV;
};

/// A storage image: cleared to NaN (float) or 0xFFFFFFFF (uint) before each dispatch, or, with
/// `upload`, filled from `data`; read back into `data` afterwards (layer-major, row-major, 4 or 16
/// bytes a texel).
struct StorageImageResource {
  uint32_t width = 0, height = 0, layers = 1;
  StorageFormat format = StorageFormat::R32G32B32A32Sfloat;
  std::vector<std::byte> data;
  bool upload = false;
};

using Resource = std::variant<BufferResource, ImageResource, SamplerResource, StorageImageResource>;
/// (set, binding) -> resource. Every binding the shader uses needs exactly one entry, and every entry
/// must be used.
using Resources = std::map<std::pair<uint32_t, uint32_t>, Resource>;

class Context;

// ----- Raster passes (raster.cc) -----------------------------------------------------------------

/// A colour attachment's format: packed words (the G-buffer) or linear HDR colour.
enum class AttachmentFormat { R32Uint, Rgba32Float };
/// Depth test of a raster pipeline (depth is D32_SFLOAT, 0 near, 1 far).
enum class DepthTest { Off, Less, LessOrEqual, Equal };
/// Colour blending of attachment 0 (the others are written as they are):
/// None; DualSource: dst = src0.rgb + dst.rgb * src1.rgb (a translucent forward
/// pass: colour out 0, background throughput out 1), alpha kept.
enum class Blend { None, DualSource };

/// The fixed-function state of a raster pipeline.
struct RasterState {
  std::vector<uint32_t> vertexComponents;  // floats at vertex input locations 0, 1, ... (1 to 4 each)
  std::vector<AttachmentFormat> colors;    // the render pass's colour attachments, in location order
  DepthTest depthTest = DepthTest::Less;
  bool depthWrite = true;
  /// Bit i: colour attachment i is written (a fragment stage that has no output for an
  /// attachment must leave its bit clear, or the attachment's value is undefined); 0: depth only.
  uint32_t colorWriteMask = ~0u;
  Blend blend = Blend::None;
};

/// Vertex data: RasterState::vertexComponents floats per vertex location 0, 1,
/// ... interleaved in `vertices` (stride = their sum), drawn as indexed triangles.
struct Geometry {
  std::vector<float> vertices;
  std::vector<uint32_t> indices;  // a multiple of 3, each < the vertex count
};

/// A colour attachment of a pass: cleared to `clear` (bits: uint words or float
/// bits), or loaded from `initial` when it is not empty (4 or 16 bytes a texel);
/// read back into `data` after the pass.
struct ColorAttachment {
  AttachmentFormat format = AttachmentFormat::Rgba32Float;
  std::array<uint32_t, 4> clear{};
  std::vector<std::byte> initial;
  std::vector<std::byte> data;
};

class RasterPipeline;

/// One indexed draw: its pipeline, geometry and resources (every binding of the
/// pipeline's two stages, except those the pass shares).
struct Draw {
  const RasterPipeline* pipeline = nullptr;
  const Geometry* geometry = nullptr;
  Resources resources;
};

/// A render pass: its attachments, the storage images every draw shares (a
/// G-buffer's material buffer: bound at the same set and binding in each draw
/// that uses it, cleared or uploaded as StorageImageResource says, read back),
/// and the draws in order.
struct RasterPass {
  uint32_t width = 0, height = 0;
  std::vector<ColorAttachment> colors;
  float depthClear = 1.0f;
  std::vector<float> depthInitial;  // non-empty: the depth attachment is loaded from it
  std::vector<float> depth;         // read back after the pass
  Resources shared;                 // StorageImageResources only
};

/// A graphics pipeline: a vertex and a fragment stage (or a vertex stage
/// alone, for depth-only draws) and its state.
class RasterPipeline {
 public:
  ~RasterPipeline();
  RasterPipeline(const RasterPipeline&) = delete;
  RasterPipeline& operator=(const RasterPipeline&) = delete;

  /// The two stages' bindings, merged (sorted by set and binding).
  const ShaderReflection& reflection() const { return reflection_; }
  const RasterState& state() const { return state_; }

 private:
  friend class Context;
  friend struct RasterRecorder;
  struct Impl;
  RasterPipeline(ShaderReflection reflection, RasterState state, std::unique_ptr<Impl> impl);
  ShaderReflection reflection_;
  RasterState state_;
  std::unique_ptr<Impl> impl_;
};

/// A compute pipeline: the module's reflection, descriptor set layouts (empty ones for unused set
/// numbers below the highest), pipeline layout and pipeline. Reusable for any number of dispatches.
class ComputePipeline {
 public:
  ~ComputePipeline();
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  const ShaderReflection& reflection() const { return reflection_; }

 private:
  friend class Context;
  struct Impl;
  ComputePipeline(ShaderReflection reflection, std::unique_ptr<Impl> impl);
  ShaderReflection reflection_;
  std::unique_ptr<Impl> impl_;
};

class Context {
 public:
  struct Options {
    std::string shaderCacheDir;  // non-empty: MESA_SHADER_CACHE_DIR (set, overwriting) before the instance
    uint64_t fenceTimeoutNs = std::chrono::nanoseconds(std::chrono::seconds(120)).count();
  };

  /// Loads libvulkan.so.1, creates an instance (Vulkan 1.2, VK_LAYER_KHRONOS_validation with
  /// synchronization validation, and a VK_EXT_debug_utils messenger recording warnings and errors;
  /// the messenger also watches vkCreateInstance itself) and a device on lavapipe with one
  /// compute queue (and shaderFloat16 when the device has it). Sets VK_DRIVER_FILES to lavapipe's ICD
  /// unless VK_DRIVER_FILES or VK_ICD_FILENAMES is set non-empty (setenv: call before starting threads).
  /// Null, with an error reported ("GPU harness: ..."), when anything is missing.
  static std::unique_ptr<Context> create(const Options& options, Diagnostics& diags);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  std::string deviceName() const;  // "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string driverInfo() const;  // "Mesa 22.3.6 (LLVM 15.0.6)"
  /// Whether the device has (and so the Context enabled) shaderFloat16: half-precision arithmetic in
  /// shaders (SPIR-V capability Float16, `--precision half`). Lavapipe has it.
  bool shaderFloat16() const;

  /// Reflects `spirv` (a GLCompute entry point is required) and builds its pipeline. Null, with an
  /// error reported, on a reflection or Vulkan failure, or when the validation layer reported anything.
  std::unique_ptr<ComputePipeline> createPipeline(const std::vector<uint32_t>& spirv, Diagnostics& diags);

  /// Binds `resources` (checked against the reflection: a missing, unused or incompatible resource
  /// is an error naming set, binding and variable), records and submits one dispatch of
  /// groupsX*groupsY*groupsZ workgroups, waits for it (at most Options::fenceTimeoutNs) and reads the
  /// outputs back into `resources`. False, with errors reported, on any failed Vulkan call (with its
  /// VkResult), a timeout, or any validation message recorded meanwhile (all of them listed). After a
  /// timeout the Context is unusable: its objects may still be in use and are leaked, never waited on.
  /// With `dispatchNs`, two timestamp queries around the dispatch give its execution time in ns
  /// (uploads, clears and read-backs excluded).
  bool dispatch(const ComputePipeline& pipeline, Resources& resources, uint32_t groupsX, uint32_t groupsY,
                uint32_t groupsZ, Diagnostics& diags, double* dispatchNs = nullptr);

  /// A graphics pipeline of `vertex` (a Vertex entry point) and `fragment` (a Fragment entry point, or
  /// empty for depth-only draws) for attachments and state `state`. Null, with an error
  /// reported, on a reflection or Vulkan failure, two stages that disagree on a binding, a feature the
  /// device lacks (fragment stores, dual-source blending), or any validation message.
  std::unique_ptr<RasterPipeline> createRasterPipeline(const std::vector<uint32_t>& vertex,
                                                       const std::vector<uint32_t>& fragment, const RasterState& state,
                                                       Diagnostics& diags);

  /// Records one render pass of `pass.width` x `pass.height` with `draws` in order (each draw's
  /// pipeline must match the pass's attachments), submits it, waits and reads the attachments and shared
  /// storage images back. Resources are checked as in dispatch. False, with errors reported, as dispatch.
  /// With `passNs`, two timestamp queries around the draws give their execution time in ns.
  bool render(RasterPass& pass, std::vector<Draw>& draws, Diagnostics& diags, double* passNs = nullptr);

  /// Every message recorded so far ("ERROR [validation] Validation Error: [ VUID-... ] ..."); clears the list.
  std::vector<std::string> takeMessages();

 private:
  friend class ComputePipeline;
  friend class RasterPipeline;
  friend struct RasterRecorder;
  struct Impl;
  explicit Context(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace substratec::gpu
