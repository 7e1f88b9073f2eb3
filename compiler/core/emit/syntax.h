// One emitter, two languages. Every shader body is written once in the
// runtime's dialect (HLSL spellings: float3, lerp, saturate, frac,
// groupshared, InterlockedAdd, ...), which runtime_shaders/substrate_prelude.glsl
// maps to GLSL and substrate_prelude.hlsl completes for HLSL. A Syntax is the
// small per-target table of what truly differs (MaterialX's resource binding
// context): the version header, file extensions, resource declarations, the
// entry point's signature and how a body reads its inputs and writes its
// outputs.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "ir/value.h"

namespace substratec {

enum class Target { Glsl, Hlsl };

/// The dialect's type name of a value type (float, float2, float3, float4).
std::string dialectType(VType t);
/// A float literal that parses the same in both languages ("0.5", "1.0", "1e-05").
std::string dialectLiteral(double v);

/// How a shader uses a buffer or an image.
enum class Access { Read, Write, ReadWrite };
/// The storage images the shaders use: uint words in layers, or a colour target.
enum class ImageKind { UintArray, Float4 };
/// The compute built-ins a body reads (as uint3).
enum class ComputeId { Dispatch, Group, Local };

/// A fragment-stage input (interpolant) or output (render target).
struct StageVar {
  int location = 0;
  std::string_view type;  // dialect type
  std::string name;       // inNormal / i.normal; outColor / o.color
  std::string_view semantic = "";  // HLSL input semantic (outputs are SV_Target<location + index>)
  std::string comment = "";
  int index = 0;  // dual-source blending index (outputs)
};

struct Syntax {
  Target target;
  std::string_view name;               // "glsl" / "hlsl"
  std::string_view materialExtension;  // ".material.glsl" / ".material.hlsl"
  std::string_view prelude;            // runtime prelude file to include
  std::string_view header;             // the lines before anything else (GLSL's #version)
  std::string_view fragmentExtension;  // ".frag" / ".ps.hlsl"
  std::string_view computeExtension;   // ".comp" / ".cs.hlsl"

  // --- Resource declarations (descriptor set, binding).
  /// A uniform block / constant buffer `instance` of struct `block`; `members` in the dialect.
  std::string uniformBlock(int set, int binding, std::string_view block, std::string_view instance,
                           std::string_view members) const;
  /// A runtime-sized array `name` of `element` (GLSL: in a buffer block named `block`).
  std::string storageBuffer(int set, int binding, Access access, std::string_view block, std::string_view element,
                            std::string_view name) const;
  /// A sampled 2D or cube texture of float4 (GLSL: a combined image sampler).
  std::string texture(int set, int binding, bool cube, std::string_view name) const;
  /// A sampler (HLSL only: GLSL's textures carry theirs).
  std::string sampler(int set, int binding, std::string_view name) const;
  std::string storageImage(int set, int binding, Access access, ImageKind kind, std::string_view name) const;
  /// The material's non-texture inputs: a uniform block at set 1, binding 0,
  /// or (`perInvocation`) private globals a kernel sets for each point.
  std::string materialInputs(std::string_view material, const std::vector<std::pair<VType, std::string>>& inputs,
                             bool perInvocation) const;
  /// A material input inside its uniform block / constant buffer / globals.
  std::string inputAccess(std::string_view material, std::string_view input) const;

  // --- Entry points.
  /// The fragment stage's interpolants and render targets.
  std::string fragmentInterface(const std::vector<StageVar>& inputs, const std::vector<StageVar>& outputs) const;
  /// `main`'s signature and opening brace (HLSL: declares the output struct `o`).
  std::string fragmentMain() const;
  /// The fragment entry's early-fragment-tests request, placed right before
  /// fragmentMain(): depth and stencil are tested before the shader runs, so a
  /// fragment that is hidden never runs and never stores (a base pass that
  /// writes the material buffer needs it; docs/render.md).
  std::string earlyFragmentTests() const;
  /// `main`'s closing lines (HLSL: returns `o`).
  std::string fragmentEnd() const;
  std::string input(std::string_view name) const;   // an interpolant
  std::string output(std::string_view name) const;  // a render target
  std::string fragCoord() const;                    // the pixel's window position (float4)
  /// Texel `pixel` (an integer-valued float2) of mip 0 of 2D texture `texture` (float4).
  std::string texelFetch(std::string_view texture, std::string_view pixel) const;
  /// A compute `main` of x·y invocations a group, up to its opening brace.
  std::string computeMain(int x, int y) const;
  std::string computeId(ComputeId id) const;
};

const Syntax& syntaxFor(Target t);

/// The split-sum environment (set 0, bindings 1-3) and its two sampling macros
/// SUBSTRATE_ENV_PREFILTERED(dir, lod) and SUBSTRATE_ENV_IRRADIANCE(dir).
std::string environmentResources(const Syntax& syn);

}  // namespace substratec
