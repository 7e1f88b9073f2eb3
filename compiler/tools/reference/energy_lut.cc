// Mirrors runtime_shaders/substrate_energy_lut.h: the tables are the same
// 4032 words (validate/runtime_files.h, energyLutTables(): E, then B, then
// E_fuzz, each row-major with index = roughness cell * 32 + NoV cell, then the
// anisotropic E_max and B_max, 15 x 16 words of four, three 10-bit values each), read
// through the shader's substrate_lut_coords / substrate_lut_blend and clamps.
#include "reference/energy_lut.h"

#include <bit>
#include <cmath>
#include <cstdint>

#include "reference/common.h"
#include "substrate_constants.h"  // runtime_shaders/
#include "validate/runtime_files.h"

namespace substratec::reference {
using namespace detail;

namespace {

constexpr int kE = 0, kB = 1, kFuzz = 2;  // SUBSTRATE_LUT_E / _B / _FUZZ

template <class T>
T fetch(int table, int index) {
  return static_cast<T>(energyLutTables()[static_cast<std::size_t>(table * 1024 + index)]);
}

// substrate_lut_blend: lerp(lerp(v00, v10, f.x), lerp(v01, v11, f.x), f.y).
template <class T>
T blend(int table, const std::array<int, 4>& i, const V2<T>& f) {
  return lerp(lerp(fetch<T>(table, i[0]), fetch<T>(table, i[1]), f[0]),
              lerp(fetch<T>(table, i[2]), fetch<T>(table, i[3]), f[0]), f[1]);
}

}  // namespace

// substrate_lut_coords: p = saturate(x, y) * 32 - 0.5, p0 = clamp(floor(p), 0, 30),
// f = p - p0 (in [-0.5, 1.5]: the outer half cells are extrapolated linearly).
template <class T>
void lutCoords(T x, T y, std::array<int, 4>& idx, V2<T>& f) {
  V2<T> p{saturate(x) * T(32) - T(0.5), saturate(y) * T(32) - T(0.5)};
  V2<T> p0{clampT(std::floor(p[0]), T(0), T(30)), clampT(std::floor(p[1]), T(0), T(30))};
  f = {p[0] - p0[0], p[1] - p0[1]};
  const int x0 = static_cast<int>(p0[0]), y0 = static_cast<int>(p0[1]);
  idx = {y0 * 32 + x0, y0 * 32 + x0 + 1, y0 * 32 + x0 + 32, y0 * 32 + x0 + 33};
}

template <class T>
T energyAlbedo(T NoV, T roughness) {
  std::array<int, 4> i;
  V2<T> f;
  lutCoords(NoV, roughness, i, f);
  return clampT(blend(kE, i, f), T(1e-3), T(1));
}

template <class T>
V2<T> energyDfg(T NoV, T roughness) {
  std::array<int, 4> i;
  V2<T> f;
  lutCoords(NoV, roughness, i, f);
  // The tables bound E - B and B from above separately: E is not clamped
  // before the difference (substrate_energy_dfg).
  T e = blend(kE, i, f);
  T b = clampT(blend(kB, i, f), T(0), T(1));
  return {clampT(e - b, T(0), T(1)), b};
}

// substrate_energy_aniso: p = (sqrt(sat(NoV)), sat(r)) * 15, p0 = min(floor(p), 14),
// k = p0.y * 15 + p0.x; hat weights over a = 3 sat(|A|) (1/3 at a = 1, 2/3 at
// a = 2, 1 at a = 3) plus `iso` at a = 0; rows k and k + 15, each (E, B) at
// |A| (the words' three 10-bit counts of 1/960 by those weights) lerped in NoV
// between its two nodes, lerped in r.
template <class T>
V2<T> energyAniso(T NoV, T roughness, T absAnisotropy, const V2<T>& iso) {
  const T px = std::sqrt(saturate(NoV)) * T(15), py = saturate(roughness) * T(15);
  const T x0 = std::min(std::floor(px), T(14)), y0 = std::min(std::floor(py), T(14));
  const T fx = px - x0, fy = py - y0;
  const int k = static_cast<int>(y0) * 15 + static_cast<int>(x0);
  const auto table = energyLutTables();
  const T a = saturate(absAnisotropy) * T(3);
  std::array<T, 3> w;
  for (int s = 0; s < 3; ++s) w[s] = std::max(T(1) - std::fabs(a - T(s + 1)), T(0)) * T(1.0 / 960.0);
  // The value of word c of `element` at |A|: its three slices by the weights.
  auto value = [&](int element, int c) {
    const auto word = std::bit_cast<std::uint32_t>(table[static_cast<std::size_t>(3 * 1024 + element * 4 + c)]);
    T v = 0;
    for (int s = 0; s < 3; ++s) v += static_cast<T>((word >> (10 * s)) & 1023u) * w[s];
    return v;
  };
  // substrate_energy_aniso_row: (E, B) lerped in NoV between (E_i, B_i) and (E_i+1, B_i+1).
  auto row = [&](int element) {
    return std::array<T, 2>{lerp(value(element, 0), value(element, 2), fx),
                            lerp(value(element, 1), value(element, 3), fx)};
  };
  const auto r0 = row(k), r1 = row(k + 15);
  const T wIso = std::max(T(1) - a, T(0));
  const T e = lerp(r0[0], r1[0], fy) + iso[0] * wIso;
  const T b = lerp(r0[1], r1[1], fy) + iso[1] * wIso;
  return {clampT(e, T(1e-3), T(1)), clampT(b, T(0), T(1))};
}

template <class T>
T fuzzAlbedo(T NoV, T fuzzRoughness) {
  std::array<int, 4> i;
  V2<T> f;
  lutCoords(NoV, fuzzRoughness, i, f);
  return std::max(blend(kFuzz, i, f), T(0));
}

// substrate_fuzz_mean_albedo: the quartic in r, SUBSTRATE_FUZZ_MEAN_*.
template <class T>
T fuzzMeanAlbedo(T fuzzRoughness) {
  const T r = saturate(fuzzRoughness);
  return std::max(
      (((T(SUBSTRATE_FUZZ_MEAN_4) * r + T(SUBSTRATE_FUZZ_MEAN_3)) * r + T(SUBSTRATE_FUZZ_MEAN_2)) * r +
       T(SUBSTRATE_FUZZ_MEAN_1)) * r + T(SUBSTRATE_FUZZ_MEAN_0),
      T(0));
}

// substrate_fuzz_albedo_deviation: min(0.06 + 0.4 r, 0.134), SUBSTRATE_FUZZ_DEVIATION_*.
template <class T>
T fuzzAlbedoDeviation(T fuzzRoughness) {
  return std::min(T(SUBSTRATE_FUZZ_DEVIATION_0) + T(SUBSTRATE_FUZZ_DEVIATION_SLOPE) * saturate(fuzzRoughness),
                  T(SUBSTRATE_FUZZ_DEVIATION_MAX));
}

#define SUBSTRATEC_INSTANTIATE(T)                                                  \
  template T fuzzMeanAlbedo<T>(T);                                                 \
  template T fuzzAlbedoDeviation<T>(T);                                            \
  template void lutCoords<T>(T, T, std::array<int, 4>&, V2<T>&);                   \
  template T energyAlbedo<T>(T, T);                                                \
  template V2<T> energyDfg<T>(T, T);                                               \
  template V2<T> energyAniso<T>(T, T, T, const V2<T>&);                          \
  template T fuzzAlbedo<T>(T, T);
SUBSTRATEC_INSTANTIATE(float)
SUBSTRATEC_INSTANTIATE(double)
#undef SUBSTRATEC_INSTANTIATE

}  // namespace substratec::reference
