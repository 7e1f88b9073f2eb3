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

/// Writes all files into `dir` (created if missing) or none of them. Each is
/// written to a new temporary beside its destination (O_EXCL, never through
/// an existing name), then all are renamed into place; a file being replaced
/// is kept as a hard link until every rename succeeded. On any failure the
/// replaced files are put back, the temporaries and any directory this call
/// created are removed: the directory is as it was. `name`s must be plain
/// file names. Returns "" on success, else an error message.
std::string writeFilesAtomically(const std::string& dir, const std::vector<OutputFile>& files);

}  // namespace substratec
