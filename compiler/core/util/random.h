// The one small random generator of the compiler and its tests: splitmix64
// (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
// generators"). Deterministic, no global state; the reference integrators and
// the random test cases rely on its exact sequence.
#pragma once
#include <cstdint>

namespace substratec {

/// Advances the state `s` and returns its next 64 random bits.
inline std::uint64_t splitmix64(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// The top 53 bits of `bits` as a double uniform in [0, 1).
inline double unitInterval(std::uint64_t bits) { return static_cast<double>(bits >> 11) * 0x1.0p-53; }

/// A splitmix64 stream from the state `s`.
struct SplitMix64 {
  std::uint64_t s = 0;
  std::uint64_t next() { return splitmix64(s); }
  double uniform() { return unitInterval(next()); }  // [0, 1), 53 bits
};

}  // namespace substratec
