#include "cli/command_outputs.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "cli/cli.h"
#include "cli/messages.h"

namespace substratec {

namespace {

/// How standard output is named among the outputs when it is a file.
constexpr const char* kStdout = "/dev/stdout";

}  // namespace

CommandOutputs::CommandOutputs(const std::ostream& out) {
  struct stat st;
  stdoutIsFile_ = &out == &std::cout && ::fstat(STDOUT_FILENO, &st) == 0 && S_ISREG(st.st_mode);
}

void CommandOutputs::namedFile(const std::string& path) {
  if (!path.empty()) namedFiles_.push_back(path);
}

void CommandOutputs::directory(const std::string& path) {
  if (!path.empty()) directories_.push_back(path);
}

void CommandOutputs::input(const std::string& path) { reads_.add(path); }

int CommandOutputs::refuseInputs(const std::vector<std::string>& outputs, std::ostream& err) const {
  std::error_code ec;
  for (const std::string& f : namedFiles_)
    if (std::filesystem::is_directory(f, ec)) {
      return cli::printError(err, kExitUsage, fmt::format("output '{}' is a directory; expected the name of a file", f));
    }
  std::vector<std::string> all = directories_;
  all.insert(all.end(), outputs.begin(), outputs.end());
  if (stdoutIsFile_) all.push_back(kStdout);
  std::string error = sameFileAsInput(all, reads_.files());
  if (error.empty()) return kExitOk;
  const std::string named = fmt::format("output '{}'", kStdout);
  if (error.rfind(named, 0) == 0)  // `>> input`: say it as the user wrote it
    error = "standard output" + error.substr(named.size(), error.find(';') - named.size()) +
            "; refusing to write to it";
  return cli::printError(err, kExitUsage, error);
}

std::vector<std::string> CommandOutputs::prerequisites(const std::vector<std::string>& named) const {
  std::vector<std::string> more;
  for (const InputFile& f : reads_.files())
    if (!f.cacheEntry && std::find(named.begin(), named.end(), f.path) == named.end() &&
        std::find(more.begin(), more.end(), f.path) == more.end())
      more.push_back(f.path);
  std::sort(more.begin(), more.end());
  std::vector<std::string> all = named;
  all.insert(all.end(), more.begin(), more.end());
  return all;
}

int CommandOutputs::check(std::ostream& err) const {
  if (int status = refuseInputs(namedFiles_, err); status != kExitOk) return status;
  std::string error = checkWritable(namedFiles_);
  for (std::size_t i = 0; error.empty() && i < directories_.size(); ++i) error = checkWritableDirectory(directories_[i]);
  if (error.empty()) return kExitOk;
  return cli::printError(err, kExitBadInput, error);
}

int CommandOutputs::commit(const std::vector<OutputPath>& files, std::ostream& err) const {
  std::vector<std::string> paths;
  for (const OutputPath& f : files) paths.push_back(f.path);
  if (int status = refuseInputs(paths, err); status != kExitOk) return status;
  if (std::string error = writePathsAtomically(files); !error.empty()) return cli::printError(err, kExitBadInput, error);
  return kExitOk;
}

}  // namespace substratec
