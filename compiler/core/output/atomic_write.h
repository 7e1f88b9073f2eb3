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

/// One file to write, in any directory: its path and its bytes.
struct OutputPath {
  std::string path;
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

/// `files` as paths in `dir` (appended to `paths`); "" or, for a name that is
/// not a plain file name, the error writeFilesAtomically gives.
std::string outputPathsIn(const std::string& dir, const std::vector<OutputFile>& files, std::vector<OutputPath>* paths);

/// The same across directories: every file of a command (its outputs, its
/// depfile, its --cache entries, a plot) is committed together, or none is.
/// A destination that is already a regular file holding exactly the bytes to
/// write is not written again: its modification time stays, so a build system
/// that re-stats outputs after a command (Ninja's `restat`, which CMake sets
/// on every custom command) does not rebuild what depends on an output the
/// command left unchanged. (writeFilesAtomically goes through this too.)
/// All temporaries are written (every directory created) before the first
/// rename, so a destination that cannot be written fails the whole set with
/// nothing changed anywhere. Returns "" on success, else an error message.
std::string writePathsAtomically(const std::vector<OutputPath>& files);

/// Before a command does its work: can each of `paths` be written? A
/// temporary is created beside each (with the directories it needs) and
/// removed again, so a command fails in a moment rather than after its work
/// (writePathsAtomically still checks again). "" or the first failure.
std::string checkWritable(const std::vector<std::string>& paths);
/// The same for a directory a command writes into (created if missing):
/// "cannot write into 'DIR': ...".
std::string checkWritableDirectory(const std::string& dir);

}  // namespace substratec
