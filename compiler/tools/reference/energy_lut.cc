// Mirrors runtime_shaders/substrate_energy_lut.h: the tables are the same
// 3072 floats (validate/runtime_files.h, energyLutTables(): E, then B, then
// E_fuzz, each row-major with index = roughness cell * 32 + NoV cell), read
// through the shader's substrate_lut_coords / substrate_lut_blend and clamps.
#include "reference/energy_lut.h"

#include <cmath>

#include "reference/common.h"
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

template <class T>
T fuzzAlbedo(T NoV, T fuzzRoughness) {
  std::array<int, 4> i;
  V2<T> f;
  lutCoords(NoV, fuzzRoughness, i, f);
  return std::max(blend(kFuzz, i, f), T(0));
}

#define SUBSTRATEC_INSTANTIATE(T)                                                  \
  template void lutCoords<T>(T, T, std::array<int, 4>&, V2<T>&);                   \
  template T energyAlbedo<T>(T, T);                                                \
  template V2<T> energyDfg<T>(T, T);                                               \
  template T fuzzAlbedo<T>(T, T);
SUBSTRATEC_INSTANTIATE(float)
SUBSTRATEC_INSTANTIATE(double)
#undef SUBSTRATEC_INSTANTIATE

}  // namespace substratec::reference
