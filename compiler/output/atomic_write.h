// Writing outputs so that a build system never sees a half-written file:
// every file is written to a temporary name in the destination folder and
// renamed into place only when all of them were written.
#pragma once
#include <string>
#include <vector>

namespace substratec {

struct OutputFile {
  std::string name;      // file name inside the output directory
  std::string contents;
};

/// Writes all files into `dir` (created if missing) or none of them: on any
/// failure the temporaries are removed and the directory is as it was.
/// Returns "" on success, else an error message.
std::string writeFilesAtomically(const std::string& dir, const std::vector<OutputFile>& files);

}  // namespace substratec
