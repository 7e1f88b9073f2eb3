// The ground truth of a compiled material (the Monte Carlo truth the analytic
// model is judged by): the Substrate tree as a weighted sum of layer stacks,
// each walked by layeredEval / layeredAlbedo (random_walk.h has the walk's model).
#pragma once
#include <string>
#include <vector>

#include "pipeline/pipeline.h"
#include "reference/random_walk.h"
#include "reference/reference.h"

namespace substratec::reference {

/// The ground truth of a compiled material at one shading point: f * cos for
/// light L and view g.V (world space, around the geometric normal g.N; the
/// material's normals are not used). The tree of r.material (pass the result of
/// a compilation that did not simplify: a budget and closure count large enough)
/// expands into a weighted sum of stacks (groundTruthTerms), each walked by
/// layeredEval with seed + i * 0x9E3779B9 for term i (term 0: the seed, so a
/// one-term material is layeredEval of its stack). Inputs at their
/// defaults; `tex` samples textures (unset: value_eval's constant sample).
V3<double> groundTruth(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                       const WalkOptions& options);

/// One term of groundTruth: weight * layeredEval(stack).
struct WalkTerm {
  double weight = 1;
  std::vector<WalkLayer> stack;
  V3<double> N{0, 0, 1}, T{1, 0, 0};  // the term's shading frame (world): its top slab's normal and tangent
};

/// Dielectric F0 above this (IOR above ~1.9) is outside the plausible range of
/// dielectrics: walked as is (the IOR its F0 gives) and listed by
/// groundTruthExcluded as "implausible dielectric f0".
inline constexpr double kPlausibleDielectricF0 = 0.1;
/// The MFP of a furnace coat: clear (no extinction over any thickness).
inline constexpr double kClearMfp = 1e30;

/// The tree as a weighted sum of stacks, combined linearly with the tree walk's
/// weights (tree_walk.cc): a slab is [slab] with its own coverage (1 unless
/// simplification made one); horizontal: background (1 - mix), foreground mix
/// (mix saturated); select: background step, foreground 1 - step, step =
/// threshold >= value; add: both, weight 1 each; coverage weight: times the
/// weight (saturated); vertical: every top term over every base term (weights
/// multiplied, stacks concatenated), plus the base terms alone times
/// 1 - (coverage of the top), plus the top terms alone times 1 - (coverage of the
/// base). A layer's thickness is that of TreeInfo::layerVertical's vertical
/// (else settings.surfaceThickness); its MFP is sss_mfp * sss_mfp_scale; it is
/// opaque when every channel of the MFP is <= 0 and its thickness is > 0 (no
/// thickness is no matter: the runtime's exp(-0 / 0) is 1). Terms of weight 0
/// are dropped.
std::vector<WalkTerm> groundTruthTerms(const CompileResult& r, const Geometry& g, const TextureFn& tex);

/// The closure without the features the walk does not model (anisotropy, haze,
/// fuzz, glints, specular profiles: their feature bits cleared, their values
/// neutral): the part of the analytic model the ground truth can judge.
Closure<double> layeringOnly(Closure<double> c);

/// groundTruth with its standard error.
Estimate groundTruthEstimate(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                             const WalkOptions& options);

/// The directional albedo of the material's truth for view g.V: the sum over
/// groundTruthTerms of weight * layeredAlbedoEstimate, with its standard error.
Estimate groundTruthAlbedo(const CompileResult& r, const Geometry& g, const TextureFn& tex, const WalkOptions& options);

/// The features of r's material the truth does not model (or models only
/// partly), by name ("glint", "lower-layer normals", ...): every comparison
/// lists them. Empty when the truth walks everything the material uses.
std::vector<std::string> groundTruthExcluded(const CompileResult& r);

/// The white furnace of r: the same tree with every albedo at 1 (diffuse
/// albedo, fuzz colour, metalness base colour; conductors F0 = F90 = 1) and
/// absorption off. Its truth is 1 (energy conservation); the analytic model's
/// is what it keeps of the light.
CompileResult furnaceMaterial(const CompileResult& r);

}  // namespace substratec::reference
