// Pass 6 — feature analysis: marks, per slab, the opt-in features it uses.
// A feature is used only when its gate pin is not a constant equal to the
// neutral default: f90 != 1, anisotropy != 0, sss_mfp != 0 (and scale != 0,
// sss_type != none), second_roughness_weight != 0 (haze), fuzz_amount != 0,
// glint_value != 1, a specular_profile given, emissive != 0.
// A medium (MFP) on a slab with a layer below it only attenuates what is
// below: it is recorded as `medium`, not `sss` (it costs no storage).
// Also derives sss_type when not given (diffusion; simple_volume on thin surfaces).
// Must run after culling (culled slabs must not count) and before pricing.
#pragma once
#include "ir/material.h"

namespace substratec {

void analyzeFeatures(Material& m);

}  // namespace substratec
