// Make-syntax dependency files (`--depfile FILE`, like `glslc -MD -MF` or
// `gcc -MD -MF`): one rule, every output a target of every input, so that a
// build system reruns the command when any input changes. Ninja (which wants
// the first target to be its edge's first output, and every target one of its
// outputs) and Make read it alike. Paths are written as given (never made
// absolute); spaces, '#' and '\' before them are escaped with '\', '$' as "$$".
#pragma once
#include <string>
#include <vector>

namespace substratec {

/// `out1 out2 ...: in1 in2 ...` with line continuations, ending in a newline.
std::string makeDepfile(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

/// Writes it atomically to `path` (a temporary renamed into place); "" or an error.
std::string writeDepfile(const std::string& path, const std::vector<std::string>& outputs,
                         const std::vector<std::string>& inputs);

}  // namespace substratec
