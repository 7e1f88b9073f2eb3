// Helpers of the in-process CLI tests of scenes and build pipelines: run
// `substratec` through runCli, read a file, a fresh scratch directory.
#pragma once
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli.h"

namespace substratec::clitest {

namespace fs = std::filesystem;

struct CliResult {
  int status;
  std::string out, err;
};

inline CliResult cli(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  int status = runCli(args, out, err);
  return {status, out.str(), err.str()};
}

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// SUBSTRATEC_WORK_DIR/<group>/<name>, removed first.
inline fs::path freshDir(const std::string& group, const std::string& name) {
  fs::path d = fs::path(SUBSTRATEC_WORK_DIR) / group / name;
  fs::remove_all(d);
  return d;
}

/// Every regular file of `dir` by name, with its bytes.
inline std::map<std::string, std::string> filesOf(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files[e.path().filename().string()] = slurp(e.path());
  return files;
}

}  // namespace substratec::clitest
