// The runtime shader library (runtime_shaders/), embedded at build time.
#pragma once
#include <span>
#include <string_view>
#include <vector>

namespace substratec {

struct RuntimeFile {
  std::string_view name;
  std::string_view text;
};

const std::vector<RuntimeFile>& runtimeFiles();

/// The runtime's directional-albedo tables (substrate_energy_lut_data.h): 3 x 32 x 32
/// floats, E then B then E_fuzz, each row-major (index = roughness cell * 32 + NoV cell),
/// then the anisotropic E_max and B_max, 960 words of two halves each (their bits
/// as floats): 4032 words. A host binds them as the uniform buffer
/// substrate_energy_lut.h reads (1008 float4, 16,128 bytes; shaders without
/// anisotropy read the first 768).
std::span<const float> energyLutTables();

inline constexpr int kEnergyLutSize = 32;  // cells per axis

}  // namespace substratec
