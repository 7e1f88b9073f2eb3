// The runtime's directional-albedo tables as host data: the very header the
// shaders compile (runtime_shaders/substrate_energy_lut_data.h), so what a host
// uploads to the tables' uniform buffer is what the shaders were validated with.
#include "validate/runtime_files.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <iterator>

// The anisotropic table is 32-bit words of three 10-bit values each (uint in the shaders).
using uint = std::uint32_t;
#define SUBSTRATE_CONST static const
#define SUBSTRATE_ARRAY_BEGIN(T, N) {
#define SUBSTRATE_ARRAY_END }
#include "substrate_energy_lut_data.h"

namespace substratec {

std::span<const float> energyLutTables() {
  constexpr std::size_t kBase = sizeof(SUBSTRATE_LUT_TABLES) / sizeof(float);
  constexpr std::size_t kAniso = sizeof(SUBSTRATE_LUT_ANISO_TABLE) / sizeof(float);
  static_assert(kBase + kAniso == SUBSTRATE_LUT_FLOATS);
  // The two arrays in order, as one buffer (the shaders' uniform buffer).
  static const std::array<float, SUBSTRATE_LUT_FLOATS> all = [] {
    std::array<float, SUBSTRATE_LUT_FLOATS> a{};
    std::copy(std::begin(SUBSTRATE_LUT_TABLES), std::end(SUBSTRATE_LUT_TABLES), a.begin());
    // The words' bits, as the shaders read them back (asuint).
    std::transform(std::begin(SUBSTRATE_LUT_ANISO_TABLE), std::end(SUBSTRATE_LUT_ANISO_TABLE), a.begin() + kBase,
                   [](uint w) { return std::bit_cast<float>(w); });
    return a;
  }();
  return {all.data(), all.size()};
}

}  // namespace substratec
