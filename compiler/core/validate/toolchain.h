// The shader toolchain substratec validates its output with (glslang and
// SPIRV-Tools, linked in-process). Issue 4's validation lives beside this.
#pragma once
#include <string>

namespace substratec {

/// "glslang X.Y.Z, SPIRV-Tools vYYYY.N" — the versions actually linked.
std::string toolchainVersions();

}  // namespace substratec
