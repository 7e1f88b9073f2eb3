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
/// light L and view g.V (world space). The tree of r.material (pass the result of
/// a compilation that did not simplify: a budget and closure count large enough)
/// expands into a weighted sum of stacks (groundTruthTerms), each walked by
/// layeredEval with seed + i * 0x9E3779B9 for term i (term 0: the seed, so a
/// one-term material is layeredEval of its stack) in the term's own shading
/// frame (WalkTerm::N, T: its top slab's evaluated normal and tangent pins in
/// world space, as evaluateMaterial builds them); a view or light below a
/// term's shading horizon gives that term 0 (both below the geometric horizon:
/// 0 for all). Inputs at their defaults; `tex` samples textures (unset:
/// value_eval's constant sample).
///
/// READINGS (what the truth takes each slab to be):
///  * Metalness provenance (Slab::metalness, set when diffuse_albedo and f0 are
///    the outputs of one metalness_to_diffuse_f0 node): the slab is the mix the
///    helper describes, every term containing it splits into metallic m x a
///    conductor (WalkLayer::conductor, f0 = base colour, f90 = the slab's; it
///    ends the stack) and (1 - m) x a dielectric (f0 = 0.08 specular, diffuse
///    albedo = base colour, the rest of the slab unchanged).
///  * Without it: an opaque slab (MFP 0, thickness > 0) of diffuse albedo 0 in
///    every channel and an F0 above kPlausibleDielectricF0 in some channel is a
///    conductor; any other slab is a dielectric whose IOR its F0 gives (a
///    black one of F0 0.04 is a dielectric over matter that absorbs all that
///    enters: black plastic, not a conductor of n < 1). A dielectric F0 above kPlausibleDielectricF0 (IOR > ~1.93)
///    is walked as is and listed by groundTruthExcluded ("implausible
///    dielectric f0").
///  * Every feature pin goes into the layer (f90, anisotropy, tangent angle of
///    lower layers about the top's normal, haze, fuzz); the walk (random_walk.h)
///    says how it models them. specularTint is 1 (the runtime's default
///    SUBSTRATE_SPECULAR_PROFILE_SAMPLE); a specular-profile LUT is excluded.
///    Glints are walked as the plain lobe and excluded (the mean of the glint
///    factor over uv was not verified to be 1). Lower layers whose normal
///    differs from the top's are walked in the top's frame and excluded.
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
/// partly), by stable name, in tree order of first use, read at the inputs'
/// defaults (Geometry{}): "glint" (walked as the plain lobe), "specular
/// profile" (its LUT; tint 1 walked), "sss type" (the runtime's wrap /
/// diffusion approximation of a bottom medium: the truth walks the medium),
/// "implausible dielectric f0" (above), "lower-layer normals" (walked in the
/// top's frame), "translucency" (thin-surface or non-opaque blend modes: the
/// truth is reflection only). Emission is not part of the BSDF and is not
/// listed. Empty when the truth walks everything the material uses.
std::vector<std::string> groundTruthExcluded(const CompileResult& r);

/// The white furnace of r: the same compiled material (tree, features, layout
/// unchanged; pins replaced by new constant DAG values) with every albedo at 1
/// and absorption off, read at the inputs' defaults: diffuse albedo 1, fuzz
/// colour 1; a metalness slab's base colour 1 with its pins recomputed by the
/// helper (so evaluateMaterial's f0 = 0.08 s (1 - m) + m and the truth's split
/// see the same white); conductors (opaque, diffuse 0) F0 = F90 = 1; a coat's
/// medium (MFP > 0, on top of a vertical) clear (MFP kClearMfp); an opaque slab
/// a white Lambertian; a bottom medium keeps its MFP with albedo 1 (non-
/// absorbing: its walk needs a large maxDepth). Its truth is 1 up to what the
/// walk loses; the analytic model's is what it keeps of the light.
CompileResult furnaceMaterial(const CompileResult& r);

}  // namespace substratec::reference
