// The runtime shader library (runtime_shaders/), embedded at build time.
#pragma once
#include <string_view>
#include <vector>

namespace substratec {

struct RuntimeFile {
  std::string_view name;
  std::string_view text;
};

const std::vector<RuntimeFile>& runtimeFiles();

}  // namespace substratec
