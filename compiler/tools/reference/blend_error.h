// Accuracy of parameter blending (docs/accuracy.md, "Parameter blending vs
// plain lerp"): compiles a material, simplifies it step by step with a given
// blending rule, and measures each simplified material against the full
// (unsimplified) one with the CPU reference over a fixed, deterministic probe
// set. Measurement only: nothing in the compiler depends on it.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "passes/blend.h"
#include "pipeline/pipeline.h"

namespace substratec::reference {

/// The probe set's radiance of a compiled material, one value per channel per
/// probe: 64 shading points (normals on a Fibonacci sphere, tangents
/// orthogonal to them, uv0/uv1 spread over [0,1]^2) x 4 views x 4 lights, all
/// above the horizon in the point's tangent frame. A probe's radiance is
/// sum over closures of lightClosure(L, radiance 1) + viewThroughput(NoV) x
/// (envSplitSum(prefiltered 0.5, irradiance 0.5 pi) + emissive), with the
/// runtime's default diffuse model. Inputs at their defaults; textures sampled
/// through blendProbeTexture. 64 x 4 x 4 x 3 = 3072 values.
std::vector<double> blendProbeRadiance(const CompileResult& r);

/// The smooth procedural texture of the probes, distinct per input: r, g in
/// [0.25, 0.75], b in [0.75, 0.95] (a plausible tangent-space normal map), a in [0.1, 0.9].
std::array<double, 4> blendProbeTexture(int inputIndex, double u, double v);

/// mean over i of (x_i - y_i)^2 / (y_i^2 + 0.01): x simplified, y full (sizes must match).
double relativeMse(const std::vector<double>& x, const std::vector<double>& y);

/// A simplification budget at which the blending rules are compared.
struct BlendBudget {
  int bytes = 0, closures = 0;  // budgetOverride / maxClosuresOverride
  bool full = false;            // the full simplification instead
};

/// The budgets of every step of `text`'s full simplification under `rule`:
/// step k's bytes and closures after it (deepest-first simplification is
/// deterministic, so compiling at that budget stops at step k), the last one
/// the full simplification itself. Budgets at which the simplification
/// reaches the same step as at the previous one are dropped. Empty for a
/// material that needs no simplification; nullopt (with diagnostics) when it
/// does not compile.
std::optional<std::vector<BlendBudget>> simplificationBudgets(const std::string& text, BlendRule rule,
                                                              Diagnostics& diags);

/// One material simplified to one budget with one rule, measured.
struct BlendStepError {
  int step = 0;          // steps applied (CompileResult::steps.size())
  std::string action;    // the last step: "collapse VERTICAL root", "disable glint", ...
  bool full = false;     // the full simplification (--full-simplification)
  int bytes = 0;         // packed bytes per pixel after simplification
  int closures = 0;      // closures after simplification
  double relMse = 0;     // against the unsimplified material
};

/// `text` simplified with `rule` to each budget, against the unsimplified
/// material (relativeMse of blendProbeRadiance). nullopt (with diagnostics)
/// when it does not compile at some budget.
std::optional<std::vector<BlendStepError>> measureBlendError(const std::string& text,
                                                             const std::vector<BlendBudget>& budgets, BlendRule rule,
                                                             Diagnostics& diags);

}  // namespace substratec::reference
