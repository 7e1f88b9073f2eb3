// `substratec stability`: the material on a grid of hard cases, on the CPU
// reference (double and float) and in the generated shaders on lavapipe
// (forward and packed paths), counting non-finite values; and the largest
// directional albedo of any forced configuration under a white furnace.
//
// THE GRID
//   Forced parameters. The material is rewritten (forceableText) so that every
//   slab parameter it has can be forced at run time from two shared inputs per
//   kind, a flag f in {0, 1} and a value v: the pin p becomes
//   p * (1 - f) + v * f, exact for either flag (x * 0 = 0, x * 1 = x for finite
//   x). Kinds and their forced values (docs/stability.md):
//     roughness {0, 1e-4, 0.02, 0.5, 1} (roughness, second_roughness,
//       fuzz_roughness), anisotropy {-1, 0, 1} (where the slab has it),
//     f0 {0, 1}, f90 {0, 1} (where the slab has it), albedo {0, 1}
//       (diffuse_albedo), coverage {0, 1e-7, 1} (coverage_weight.weight,
//       horizontal.mix), mfp {0, 1e-9, 1e6} (where the slab has sss_mfp),
//     thickness {0, 1e-9, 10} (vertical.thickness).
//   Each kind also has "own" (flag 0). Configurations: the cross product of
//   every kind's choices with the material's own inputs at their defaults, at
//   their minima and at their maxima.
//   Shading points: normals at the octahedral poles and seams (±X, ±Y, ±Z,
//   diagonals, just off the fold) and a generic one; tangents orthogonal,
//   parallel to the normal and zero (degenerate frames); NoV and NoL in
//   {-1e-4, 0, 1e-4, 0.5, 1}, the light in the view's azimuth or the opposite
//   one (so V = L and V = -L both occur).
//   Each configuration is evaluated at `perConfiguration` shading points
//   (rotating through the list: every configuration meets a different slice,
//   and over the configurations every point meets every value), where
//   perConfiguration = max(1, evaluations / configurations).
//
// WHAT AN EVALUATION CHECKS
//   CPU (double and float): every closure field, coverage and transmittance,
//   the direct light, the view throughput, the split-sum environment and
//   translucency. GPU: the forward kernel (closures lit inline) and the
//   deferred kernel (packed, unpacked, lit) write the closures and the sums:
//   every float must be finite. With Options::precision Half the GPU kernels
//   light in half precision (EmitOptions::precision; the CPU reference has one
//   precision for both).
//
// THE FURNACE
//   Up to 128 configurations with albedo 1 and white colour inputs (a
//   scattered sample of the grid), at NoV 1, 0.5, 0.1: the sum over closures of
//   the view throughput times reference::envIntegrated under a white
//   environment (4,096 points: noise well under 1e-3), glints off (they
//   conserve energy over a footprint, not at a point). Judged (<= 1.001) unless
//   the tree has an `add`, which sums matter. Its denominator is the number of
//   evaluations that returned any light (`furnace lit`): none is a failure (a
//   furnace that saw only black tested nothing).
//
// TEXTURES
//   By default every texture input is bound at rest (gpu::TextureSet::Neutral):
//   normal maps flat, direction maps along the tangent, colours mid-grey, so
//   the shading normals face the viewer wherever the geometric one does. With
//   Options::textures Checker (`--stress-textures`) the GPU tests' checker,
//   whose texels decoded as a normal map tilt and point below the surface.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "emit/material_emitter.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "pipeline/pipeline.h"

namespace substratec::stability {

/// A forceable parameter kind and its forced values.
struct ForcedKind {
  std::string name;            // "roughness", "anisotropy", ...
  std::vector<double> values;  // forced values (the grid adds "own")
  std::string flagInput, valueInput;  // the inputs forceableText added
  long pins = 0;                      // pins it forced (each became four value nodes)
};

/// The material rewritten so that its slab parameters can be forced (see
/// above), and the kinds it has. False, reporting it, if the text is not a
/// JSON object (the caller compiled it first: its diagnostics come from there).
bool forceableText(const std::string& text, std::string* rewritten, std::vector<ForcedKind>* kinds,
                   Diagnostics& diags);

/// The options forceableText's output compiles with: `base`, with the input-
/// and node-count limits raised by exactly what the rewrite added (two inputs
/// per kind, four value nodes per forced pin), so that a material within the
/// limits stays within them once rewritten (1023 inputs + 16 used to fail with
/// "more than 1024 inputs"): the harness's own inputs are not the user's.
CompileOptions forcingOptions(const CompileOptions& base, const std::vector<ForcedKind>& kinds);

struct Options {
  long evaluations = 100000;  // at least this many (CPU; the GPU runs the same points in each path)
  bool gpu = true;
  bool cpu = true;  // the CPU reference's grid and the furnace (neither depends on `precision`)
  int furnaceSamples = 4096;  // importance samples per furnace integral (noise well under 1e-3)
  Precision precision = Precision::Float;  // of the GPU kernels' lighting
  gpu::TextureSet textures = gpu::TextureSet::Neutral;  // Checker: --stress-textures
};

inline constexpr double kFurnaceLimit = 1.001;  // the largest directional albedo a judged furnace allows

/// One non-finite (or, for the furnace, the largest) case: where it was found.
struct Case {
  std::string where;          // "cpu double", "cpu float", "gpu forward", "gpu deferred", "furnace"
  std::string quantity;       // "closure 0 f0", "direct", ...
  std::string configuration;  // "roughness=0 f0=1 inputs=defaults ..."
  std::string geometry;       // "N=(0,0,1) T=parallel NoV=1e-4 NoL=0 same azimuth"
  double value = 0;
};

struct Report {
  std::string material;
  Precision precision = Precision::Float;  // of the GPU kernels
  gpu::TextureSet textures = gpu::TextureSet::Neutral;
  std::vector<std::string> forced;  // the kinds
  long configurations = 0, shadingPoints = 0;
  long evaluations = 0, nonfinite = 0;        // CPU: points evaluated (each in double and in float), bad ones
  long gpuEvaluations = 0, gpuNonfinite = 0;  // GPU: points evaluated over both paths, bad ones
  double furnaceMax = 0;                      // largest directional albedo, white inputs, white furnace (glints off)
  long furnaceEvaluations = 0, furnaceLit = 0;  // furnace evaluations, and those that returned any light
  bool cpu = true;                            // Options::cpu: the CPU grid and the furnace ran
  bool furnaceApplicable = true;              // false for a material with no closure (unlit only): it reflects nothing
  bool furnaceJudged = true;                  // false when the tree has an `add` (it sums matter: > 1 by design)
                                              // or without the CPU part
  Case furnaceWorst;
  std::vector<Case> worst;                    // the first non-finite cases (at most 16)
};

/// Runs the grid on `r` (compiled from forceableText's output; `kinds` from it).
/// `gpu` may be null when options.gpu is false. False, with errors reported,
/// when a kernel does not compile or a dispatch fails.
bool run(const CompileResult& r, const std::vector<ForcedKind>& kinds, const Options& options, gpu::Context* gpu,
         Report* report, Diagnostics& diags);

/// False when the CPU part ran and no furnace evaluation returned any light.
bool furnaceExercised(const Report& report);
/// Every check met: nothing non-finite, the furnace exercised and (when
/// judged) at most kFurnaceLimit. `stability` exits 4 otherwise.
bool passed(const Report& report);

std::string formatText(const Report& report);
nlohmann::ordered_json toJson(const Report& report);
std::string formatJson(const Report& report);  // toJson, indented

}  // namespace substratec::stability
