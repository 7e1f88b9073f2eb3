#include "validate/toolchain.h"

#include <fmt/format.h>
#include <glslang/Public/ShaderLang.h>
#include <spirv-tools/libspirv.h>

namespace substratec {

std::string toolchainVersions() {
  glslang::Version v = glslang::GetVersion();
  return fmt::format("glslang {}.{}.{}, SPIRV-Tools {}", v.major, v.minor, v.patch, spvSoftwareVersionString());
}

}  // namespace substratec
