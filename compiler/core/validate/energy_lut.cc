// The runtime's directional-albedo tables as host data: the very header the
// shaders compile (runtime_shaders/substrate_energy_lut_data.h), so what a host
// uploads to the tables' uniform buffer is what the shaders were validated with.
#include "validate/runtime_files.h"

#define SUBSTRATE_CONST static const
#define SUBSTRATE_ARRAY_BEGIN(T, N) {
#define SUBSTRATE_ARRAY_END }
#include "substrate_energy_lut_data.h"

namespace substratec {

std::span<const float> energyLutTables() {
  static_assert(sizeof(SUBSTRATE_LUT_TABLES) / sizeof(float) == SUBSTRATE_LUT_FLOATS);
  return {SUBSTRATE_LUT_TABLES, SUBSTRATE_LUT_FLOATS};
}

}  // namespace substratec
