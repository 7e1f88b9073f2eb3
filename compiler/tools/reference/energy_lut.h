// Mirrors runtime_shaders/substrate_energy_lut.h: bilinear lookups into the
// directional-albedo tables (E, B, E_fuzz; 32 x 32 each; and E_max of anisotropic lobes, validate/runtime_files.h's
// energyLutTables(), the floats the host uploads), with the shader's edge
// extrapolation and output clamps.
#pragma once
#include <array>

#include "reference/reference.h"

namespace substratec::reference {

/// substrate_lut_coords: the four indices (x0y0, x1y0, x0y1, x1y1) into a table
/// and the weights, for x = NoV and y = roughness (both saturated).
template <class T>
void lutCoords(T x, T y, std::array<int, 4>& idx, V2<T>& f);

/// substrate_energy_albedo: E(NoV, r), clamped to [1e-3, 1].
template <class T>
T energyAlbedo(T NoV, T roughness);

/// substrate_energy_dfg: (E - B, B), each clamped to [0, 1] (the tables are
/// upper bounds of E - B and of B separately, so E is not clamped first).
template <class T>
V2<T> energyDfg(T NoV, T roughness);

/// substrate_energy_aniso: (E_max, B_max)(NoV, r, |A|) of an anisotropic lobe,
/// the largest albedo and B over the view's azimuth (the fourth table),
/// with `iso` (the isotropic E, B) at |A| = 0; E clamped to [1e-3, 1], B to [0, 1].
template <class T>
V2<T> energyAniso(T NoV, T roughness, T absAnisotropy, const V2<T>& iso);

/// substrate_fuzz_albedo: E_fuzz(NoV, r), >= 0.
template <class T>
T fuzzAlbedo(T NoV, T fuzzRoughness);

/// substrate_fuzz_mean_albedo: a lower bound of the cosine-weighted mean of min(E_fuzz, 1) over
/// the hemisphere, a quartic in the fuzz roughness.
template <class T>
T fuzzMeanAlbedo(T fuzzRoughness);

/// substrate_fuzz_albedo_deviation: an upper bound of the standard deviation of
/// min(E_fuzz, 1) over the cosine-weighted hemisphere, min(0.06 + 0.4 r, 0.134).
template <class T>
T fuzzAlbedoDeviation(T fuzzRoughness);

}  // namespace substratec::reference
