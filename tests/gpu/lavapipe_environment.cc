// How the GPU tests run lavapipe, set once for the whole process and for every
// process it starts (the `preview`, `render` and `sweep` commands the CLI tests
// run), before any Vulkan instance exists: gallivm reads its settings once.
//
// - LP_NATIVE_VECTOR_WIDTH=128: lavapipe compiles each pipeline for 4 lanes
//   instead of the 8 it picks on AVX2. A cold run of the tests is mostly LLVM
//   compiling pipelines, and 4 lanes compile in about half the time
//   (Examples/MaterialOnGpu, two shards on 2 cores, cold cache: 292 s at 8
//   lanes, 158 s at 4). What runs is the same SPIR-V; the lanes are how
//   lavapipe spreads invocations over SIMD registers. The benchmarks
//   (bench/shader_cost.sh) and the CLI keep the driver's own width.
// - MESA_SHADER_CACHE_DIR: the tests' own cache, never ~/.cache. Mesa's cache key
//   does not hold the vector width (a cache filled at 4 lanes is read at 8), so
//   the directory names the width (tests/CMakeLists.txt).
#include <cstdlib>

namespace {

const bool kLavapipeForTests = [] {
  setenv("LP_NATIVE_VECTOR_WIDTH", SUBSTRATEC_GPU_VECTOR_WIDTH, 1);
  setenv("MESA_SHADER_CACHE_DIR", SUBSTRATEC_GPU_CACHE_DIR, 1);
  return true;
}();

}  // namespace
