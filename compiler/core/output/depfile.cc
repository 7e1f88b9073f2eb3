#include "output/depfile.h"

#include <filesystem>
#include <set>

#include "output/atomic_write.h"

namespace substratec {

namespace {

/// One path as a Make word: '$' doubled; spaces, tabs and '#' escaped with a
/// backslash, and the backslashes right before them doubled (GNU Make's rule).
std::string makeWord(const std::string& path) {
  std::string out;
  std::size_t backslashes = 0;
  for (char c : path) {
    if (c == '\\') {
      ++backslashes;
      out += c;
      continue;
    }
    if (c == ' ' || c == '\t' || c == '#') {
      out.append(backslashes, '\\');
      out += '\\';
    }
    backslashes = 0;
    if (c == '$') out += '$';
    out += c;
  }
  return out;
}

}  // namespace

std::string makeDepfile(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  std::string s;
  for (std::size_t i = 0; i < outputs.size(); ++i) s += (i ? " \\\n  " : "") + makeWord(outputs[i]);
  s += ":";
  std::set<std::string> seen;
  for (const std::string& in : inputs)
    if (seen.insert(in).second) s += " \\\n  " + makeWord(in);
  return s + "\n";
}

std::string writeDepfile(const std::string& path, const std::vector<std::string>& outputs,
                         const std::vector<std::string>& inputs) {
  const std::filesystem::path p(path);
  const std::string dir = p.parent_path().empty() ? "." : p.parent_path().string();
  return writeFilesAtomically(dir, {{p.filename().string(), makeDepfile(outputs, inputs)}});
}

}  // namespace substratec
