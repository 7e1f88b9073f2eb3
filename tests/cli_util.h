// Helpers of the CLI tests: run `substratec` through runCli or as the built
// binary in a child process, read a file, a fresh scratch directory.
#pragma once
#include <sys/wait.h>

#include <cstdio>
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

/// Runs the built binary with `args` (a shell command line's tail: redirections
/// of standard input may follow the arguments) in a child process: its standard
/// output captured, its standard error through a file, its exit status
/// (128 + the signal when a signal ended it).
inline CliResult binary(const std::string& args) {
  fs::create_directories(SUBSTRATEC_WORK_DIR);
  const std::string errFile = std::string(SUBSTRATEC_WORK_DIR) + "/stderr.txt";
  const std::string cmd = std::string(SUBSTRATEC_BINARY) + " " + args + " 2>" + errFile;
  CliResult r{-1, "", ""};
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) r.out.append(buf, n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  r.err = slurp(errFile);
  return r;
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
