#include "cli/argument_files.h"

#include <fmt/format.h>

#include "cli/messages.h"
#include "diag/diagnostics.h"
#include "format/json_document.h"

namespace substratec {

namespace {

/// `'…'` with `'\''` for each quote inside, as a POSIX shell reads one word; nullopt if `line` is not that.
std::optional<std::string> shellSingleQuoted(const std::string& line) {
  if (line.size() < 2 || line.front() != '\'' || line.back() != '\'') return std::nullopt;
  std::string word;
  std::size_t i = 1;
  while (i < line.size()) {
    const std::size_t close = line.find('\'', i);
    word.append(line, i, close - i);
    if (close == line.size() - 1) return word;
    if (line.compare(close, 4, "'\\''") != 0) return std::nullopt;  // a quote outside '\''
    word += '\'';
    i = close + 4;
  }
  return std::nullopt;
}

}  // namespace

std::string argumentFromLine(const std::string& line) {
  if (std::optional<std::string> word = shellSingleQuoted(line)) return *word;
  return line;
}

std::optional<std::vector<std::string>> expandArgumentFiles(const std::vector<std::string>& args, std::ostream& err) {
  std::vector<std::string> expanded;
  for (const std::string& arg : args) {
    if (arg.size() < 2 || arg.front() != '@') {
      expanded.push_back(arg);
      continue;
    }
    const std::string path = arg.substr(1);
    Diagnostics diags(path);
    std::optional<std::string> text = readSourceFile(path, ReadLimits{}, diags);
    if (!text) {
      cli::printError(err, kExitUsage, fmt::format("cannot read the argument file {}: {}", quoteForDiagnostic(path),
                                                   diags.errorMessages()));
      return std::nullopt;
    }
    std::size_t count = 0;
    for (std::size_t start = 0; start < text->size();) {
      std::size_t end = text->find('\n', start);
      if (end == std::string::npos) end = text->size();
      std::string line = text->substr(start, end - start);
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (++count > kMaxFileArguments) {
        cli::printError(err, kExitUsage, fmt::format("the argument file {} holds more than {} arguments",
                                                     quoteForDiagnostic(path), kMaxFileArguments));
        return std::nullopt;
      }
      expanded.push_back(argumentFromLine(line));
      start = end + 1;
    }
  }
  return expanded;
}

}  // namespace substratec
