// The runtime's directional-albedo tables as host data (validate/runtime_files.h,
// runtime_shaders/substrate_energy_lut_data.h): what a host uploads to the uniform
// buffer substrate_energy_lut.h reads. Layout: 3 tables x 32 x 32, row-major,
// index = roughness cell * 32 + NoV cell; E then B then E_fuzz.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>

#include "validate/runtime_files.h"

namespace substratec {
namespace {

constexpr int kCells = kEnergyLutSize * kEnergyLutSize;

float E(int noV, int r) { return energyLutTables()[r * kEnergyLutSize + noV]; }
float B(int noV, int r) { return energyLutTables()[kCells + r * kEnergyLutSize + noV]; }
float Fuzz(int noV, int r) { return energyLutTables()[2 * kCells + r * kEnergyLutSize + noV]; }

TEST(EnergyLut, ThreeTablesOf32By32FitAUniformBuffer) {
  EXPECT_EQ(energyLutTables().size(), 3u * kCells + 960u);  // E, B, E_fuzz, then the anisotropic E_max, B_max
  EXPECT_LE(energyLutTables().size_bytes(), 16384u);  // Vulkan's minimum maxUniformBufferRange
  EXPECT_EQ(energyLutTables().size() % 4, 0u);        // whole float4 elements
}

TEST(EnergyLut, EntriesAreInRange) {
  for (int r = 0; r < kEnergyLutSize; ++r)
    for (int i = 0; i < kEnergyLutSize; ++i) {
      SCOPED_TRACE(testing::Message() << "NoV cell " << i << ", roughness cell " << r);
      EXPECT_GE(E(i, r), 0.0f);
      // E is stored as the sum of the upper bounds of E - B and B (the tables
      // are conservative envelopes, scripts/gen_energy_lut.py), so it may
      // exceed 1 by their slack: 0.08 at most, at grazing views.
      EXPECT_LE(E(i, r), 1.1f);
      EXPECT_GE(B(i, r), 0.0f);
      EXPECT_LE(B(i, r), E(i, r));
      EXPECT_GE(Fuzz(i, r), 0.0f);
      EXPECT_TRUE(std::isfinite(Fuzz(i, r)));
    }
}

TEST(EnergyLut, KnownValues) {
  // A smooth lobe seen head-on loses nothing; a rough one loses two thirds
  // (brute-force quadrature gives E(0.984, 0.984) = 0.32579). The entries are
  // upper bounds: raised by at most a few 1e-3 where the lookup's
  // extrapolation to NoV = 1 and r = 1 needed it.
  EXPECT_GE(E(31, 0), 1.0f);
  EXPECT_LE(E(31, 0), 1.001f);
  EXPECT_GE(E(31, 31), 0.32579f - 1e-5f);
  EXPECT_LE(E(31, 31), 0.32579f + 2e-3f);
  // Row order: E falls with roughness at normal incidence (within the envelope's slack).
  for (int r = 1; r < kEnergyLutSize; ++r) EXPECT_LT(E(31, r), E(31, r - 1) + 1e-3f) << r;
}

TEST(EnergyLut, TheAnisotropicWordsSurviveAFloatBuffer) {
  // The anisotropic table's words are bits (three 10-bit counts of 1/960 each)
  // that a host uploads, and a shader may fetch, as floats: none may be a
  // denormal (which some paths flush to zero), an infinity or a NaN (which
  // some canonicalize). The generator sets bit 30 where the counts alone would
  // make a denormal; the lookup masks it off.
  const auto words = energyLutTables().subspan(3u * kCells);
  ASSERT_EQ(words.size(), 960u);
  int checked = 0, lifted = 0;
  for (std::size_t k = 0; k < words.size(); ++k) {
    const float f = words[k];
    const auto bits = std::bit_cast<std::uint32_t>(f);
    EXPECT_EQ(std::fpclassify(f), FP_NORMAL) << "word " << k << " = 0x" << std::hex << bits;
    EXPECT_EQ(bits >> 31, 0u) << "word " << k;
    lifted += (bits >> 30) & 1u;
    ++checked;
  }
  EXPECT_EQ(checked, 960);
  EXPECT_GT(lifted, 0);  // the table has small B values: the rule is exercised
}

}  // namespace
}  // namespace substratec
