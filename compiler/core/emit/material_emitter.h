// Code generation: the flattened material function. One language-neutral
// emitter writing the runtime's dialect; the target's Syntax table supplies
// only the resource declarations and input access (emit/syntax.h).
//
// Output (docs/codegen.md): resources (the inputs' uniform block / constant
// buffer and the textures), then `<name>_evaluate(g, closures, coverage,
// transmittance[, emission])`: the value DAG as locals, each slab's coverage and
// transmittance, the operators bottom-up by distance from leaves, and each
// slab's walk up to the root producing its closure — all unrolled for this
// static topology (no loops, no recursion). Then `<name>_pack`, the packing
// of the closures into the uint stream of docs/storage.md with static bit
// offsets.
#pragma once
#include <string>

#include "emit/syntax.h"
#include "ir/material.h"
#include "ir/tree_info.h"
#include "storage/layout.h"

namespace substratec {

/// Precision of the runtime's lighting (docs/stability.md, "Half precision"):
/// Half compiles the "medium" quantities of runtime_shaders/ (colours,
/// albedos, Fresnel, energy weights, throughputs) as float16. The material
/// function and the base pass are float32 in both.
enum class Precision { Float, Half };

struct EmitOptions {
  DiffuseModel diffuseModel = kDefaultDiffuseModel;  // SUBSTRATE_DIFFUSE_MODEL (ir/enums.h)
  Precision precision = Precision::Float;  // of the entries and kernels that light closures
  std::string sourceName;        // file name (no directory) for the header comment
  /// Declare the inputs as private globals instead of the uniform block: a
  /// kernel that reads one input set per shading point (KernelMode's
  /// per-sample inputs, `substratec stability`) assigns them before calling
  /// `<name>_evaluate`. Same names as the block, so the body is unchanged.
  bool inputsPerInvocation = false;
  /// The pack function stores a pixel where one plain closure is left in the
  /// SIMPLE layout (storage/layout.h, runtimeSimpleClosures). Off only to
  /// compare with the static layout (tests).
  bool dynamicSimplification = true;
  /// A volume's throughput kernel (the cost `sweep` times): the steps of its march.
  int volumeSteps = 64;
};

/// `<name>.material.glsl` / `.hlsl`.
std::string emitMaterial(const Material& m, const TreeInfo& t, const StorageLayout& layout, const Syntax& syn,
                         const EmitOptions& options);

/// `#define SUBSTRATE_USE_<FEATURE> 0|1` for each runtime switch
/// (runtime_shaders/substrate_closure.h), 1 for the kFeat* bits of `features`.
std::string useDefines(std::uint16_t features);
/// `#define SUBSTRATE_USE_EXTRA_INTERFACES 0|1`: 1 when a closure of `layout`
/// lies under more than one interface (ClosureLayout::extraInterfaces > 0),
/// so the lighting compiles the interface term's power only for stacks; and
/// `#define SUBSTRATE_USE_LAYERS 0|1`: 1 when a closure lies under a layer
/// (not ClosureLayout::isTop), so the lighting compiles the layers' part.
std::string extraInterfacesDefine(const StorageLayout& layout);
/// SUBSTRATE_USE_CONDUCTOR_CURVE of the material `m` laid out as `layout`
/// (issue 19, step 23): some closure may be what the ground truth walks as a
/// conductor (its F0 not a constant of at most 0.1 in every channel, no
/// medium, no constant diffuse above 0 unless a metalness mix; a closure
/// without a slab counts as one), whose Fresnel follows a curve per channel
/// (substrate_fresnel_curve). The CPU reference reads it too (Closure::conductorCurve).
bool usesConductorCurve(const Material& m, const StorageLayout& layout);
/// SUBSTRATE_USE_LOW_IOR_CURVE of `m` laid out as `layout` (issue 19, step 24):
/// no closure lies under layers (under them, and on top of them, the
/// dielectric curve is chi) and some closure's F0 may fall below 0.04 in its
/// largest channel (a closure without a slab counts as one): its dielectric
/// curve is that of its own IOR (substrate_fresnel_curve). The CPU reference reads it
/// too (Closure::lowIorCurve).
bool usesLowIorCurve(const Material& m, const StorageLayout& layout);

/// The pixel's top-layer roughness as the top-layer word stores it (docs/storage.md)
/// and the lighting reads it for the layers above a closure
/// (SubstrateClosure.coatFloor): the top closures' roughness, weighted by
/// their weights, saturated (one top closure: its roughness). `arr` names the
/// closures' array.
std::string topRoughnessExpr(const StorageLayout& layout, const std::string& arr);

/// Shared by the entry, kernel and scene emitters.
/// A material blended over the background through its transmittance (dual-source).
bool translucentBlend(const Material& m);

/// The texture inputs the closures of `layout` use as specular profiles, in
/// profile-index order (first use among the closures): a closure's
/// `specularProfile` is its input's position here + 1.
std::vector<int> specularProfileInputs(const Material& m, const StorageLayout& layout);
/// A closure of `layout` is emissive.
bool anyEmissive(const Material& m, const StorageLayout& layout);
/// The base pass writes its emissive output (location 4): a closure is
/// emissive or an unlit node emits (unlitEmission).
bool basePassEmissive(const Material& m, const StorageLayout& layout);
/// What the background is multiplied by behind a translucent material (float3,
/// from `coverage` and `transmittance`).
std::string backgroundThroughput(const Material& m);
/// Lights closure `c` (an expression) seen from `view` into `color`: the light
/// `L` of radiance frame.lightRadiance and the split-sum environment
/// (SUBSTRATE_ENV_PREFILTERED / _IRRADIANCE, mip count frame.envParams.x).
std::string lightClosureCode(const std::string& c, const std::string& view, const std::string& indent);

/// Declares `closures`, `coverage` and `transmittance` (and `emission` when
/// unlitEmission) and evaluates the material into them at the
/// SubstrateGeometry `g` (an entry's or kernel's body).
std::string evaluateCall(const Material& m);

/// The material's tree holds an unlit node that emits (its emissive is not
/// the constant 0): `<name>_evaluate` then also returns `emission`, what the
/// unlit nodes emit toward the viewer, weighted by the operators above them
/// (light-independent: the forward pass adds it to the colour, the base pass
/// to its emissive output).
bool unlitEmission(const Material& m);

/// The size of the closures' array in declarations and signatures:
/// `<NAME>_CLOSURE_COUNT`, or 1 for a material with no closure (only unlit
/// nodes): its one slot is neutral with weight 0 (nothing lights it), and
/// holds the normal and roughness the top-layer word stores.
std::string closureArraySize(const Material& m);

/// Names used across emitted files.
std::string materialUpper(const Material& m);  // NAME in macros

/// "float" / "half" (the CLI's --precision).
const char* precisionName(Precision p);
/// What an entry or kernel that lights closures writes before the prelude:
/// `#define SUBSTRATE_PRECISION_HALF 1` for Half, nothing for Float.
std::string precisionDefine(Precision p);

}  // namespace substratec
