// `@FILE` arguments (argument files, as gcc, glslc and javac read them): a
// build system that writes its long command lines to a file, like Bazel's
// param files, passes `@FILE` instead (docs/scenes.md, "Persistent worker").
#pragma once
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace substratec {

/// Arguments one argument file may hold (a million: far beyond any build's).
inline constexpr std::size_t kMaxFileArguments = std::size_t{1} << 20;

/// Replaces every argument `@FILE` (an `@` and at least one more character)
/// by the arguments FILE holds: one per line, without the newline (Bazel's
/// "multiline" format); a line that is one shell single-quoted word ('a b',
/// with '\'' for a quote: Bazel's "shell" format) is unquoted. Argument files
/// are not read recursively (an `@` in one is an argument like any other).
/// nullopt, with `substratec: error: …` on `err`, when a file cannot be read,
/// exceeds the input size limit (16 MiB) or holds more than kMaxFileArguments.
std::optional<std::vector<std::string>> expandArgumentFiles(const std::vector<std::string>& args, std::ostream& err);

/// One line of an argument file as the argument it stands for (see above).
std::string argumentFromLine(const std::string& line);

}  // namespace substratec
