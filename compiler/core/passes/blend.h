// Parameter blending: one function per operator, each turning an operator
// over two (or one) slabs into one equivalent slab. The results are value-DAG
// expressions (folded where constant), so the same blend runs at compile time
// and in the generated shader. Formulas and reasoning: docs/simplification.md.
#pragma once
#include "ir/material.h"

namespace substratec {

/// Which blending rules a collapse uses. ProjectRules (the default) are the
/// rules documented in docs/simplification.md. PlainLerp is the naive baseline
/// the accuracy measurement (docs/accuracy.md) compares them with: every
/// parameter lerped by one weight — the raw mix weight w for horizontal and
/// select, the top's coverage for vertical, C_b/(C_a+C_b) for add — normals
/// and tangents lerped then normalized, no energy, transmittance or albedo
/// matching; coverage, thickness, discrete choices and feature flags as in
/// the project rules.
enum class BlendRule { ProjectRules, PlainLerp };

/// Horizontal mix (w toward the foreground): every parameter is lerped by the
/// coverage-weighted m = Cf·w / (Cf·w + Cb·(1−w)); normals and tangents are
/// lerped then normalized; coverage is lerp(Cb, Cf, w); what cannot be blended
/// (specular profile, SSS type, glint uv) goes to the side with the larger weight.
Slab blendHorizontal(Material& m, const Slab& background, const Slab& foreground, ValueId mix,
                     BlendRule rule = BlendRule::ProjectRules);

/// Vertical layering: where the top is present (probability Ct/C) the pair is
/// one interface over the base seen through the top's medium (T = exp(−d/MFP)
/// along the normal, twice); where it is absent, the base as it is.
Slab blendVertical(Material& m, const Slab& top, const Slab& base, ValueId thickness,
                   BlendRule rule = BlendRule::ProjectRules);

/// Add: colours add (saturated), everything else is coverage-weighted;
/// coverage sat(Ca + Cb).
Slab blendAdd(Material& m, const Slab& a, const Slab& b, BlendRule rule = BlendRule::ProjectRules);

/// Coverage weight: the slab with its coverage scaled by w.
Slab blendCoverageWeight(Material& m, const Slab& a, ValueId weight);

/// Select (a when value <= threshold): a horizontal mix toward b by the
/// run-time condition step(threshold < value).
Slab blendSelect(Material& m, const Slab& a, const Slab& b, ValueId value, ValueId threshold,
                 BlendRule rule = BlendRule::ProjectRules);

/// The slab's single-interface form: haze folded into the roughness
/// (lerp(r, r2, w)) and fuzz into the diffuse albedo (lerp(d, fuzz colour,
/// kFuzzAlbedo·amount)). Vertical blending uses it under the top.
Slab foldToSingleInterface(Material& m, const Slab& s);

/// The slab's interface as the runtime reads it under layers
/// (substrate_closure_fresnel_ends at coverage 1: the layers above are a
/// dielectric of F0 0.04): F0 and F90 scaled by the ratio of the largest
/// channel's F0 relative to it, ((s - 0.2) / (1 - 0.2 s))^2 with s = sqrt(F0),
/// to that F0: never above 1, only in the dielectric range (back to 1 over F0
/// 0.1 .. 0.2; a coloured F0 reaching 0.2 in a channel is a conductor's). `scale` receives the ratio (0: index-matched, no interface
/// left; 1: unchanged).
Slab interfaceUnderLayers(Material& m, const Slab& s, ValueId& scale);

/// Fraction of the fuzz colour a fully fuzzy slab adds to its diffuse albedo
/// when fuzz is folded (the mean directional albedo of a Charlie sheen lobe
/// over roughness, rounded).
inline constexpr double kFuzzAlbedo = 0.25;

/// The slab's coverage as a value (1 when not set).
ValueId coverageOf(Material& m, const Slab& s);

}  // namespace substratec
