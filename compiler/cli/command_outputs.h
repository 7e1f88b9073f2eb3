// How every command writes files (docs/robustness.md, "Outputs"). A command
// gathers what it will write as it learns it — the files the user named
// (`-o FILE`, `--plot`, `--depfile`), the directories it writes into (`-o
// DIR`, `--cache`), and standard output when it is redirected to a file —
// and checks them twice: before its work (check: no output is an input, each
// destination can be written, so a command fails in a moment rather than
// after minutes of rendering) and when it commits (commit: every file it
// read by then, includes and cache entries too, then all its files written
// or none: output/atomic_write.h). An output that resolves to an input is
// refused whatever its spelling (device and inode, output/file_identity.h).
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

#include "output/atomic_write.h"
#include "output/file_identity.h"

namespace substratec {

class CommandOutputs {
 public:
  /// `out` is the command's standard output: when it is the process's own,
  /// redirected to a regular file, that file is an output too.
  explicit CommandOutputs(const std::ostream& out);

  /// A file the user named for an output: a directory there is bad usage.
  void namedFile(const std::string& path);
  /// A directory the command writes into (created if missing).
  void directory(const std::string& path);
  /// An input known by name before it is read (compared even if its read fails).
  void input(const std::string& path);

  /// Before the work: kExitUsage when an output is a directory where a file
  /// is wanted or is a file read so far (by identity), kExitBadInput when a
  /// destination cannot be written; kExitOk. Messages go to `err`.
  int check(std::ostream& err) const;

  /// The same refusal for `files` (what is committed: a named file not among
  /// them is not written) against every file read by now, then
  /// `files` written all or none: kExitOk, kExitUsage, or kExitBadInput when
  /// one cannot be written (and nothing was).
  int commit(const std::vector<OutputPath>& files, std::ostream& err) const;

  /// Every file the command has read so far.
  std::vector<InputFile> inputs() const { return reads_.files(); }
  /// A depfile's prerequisites: `named` (the inputs as given, in order), then
  /// every other file read but a cache entry (MaterialX includes), sorted so
  /// that -j does not change the bytes.
  std::vector<std::string> prerequisites(const std::vector<std::string>& named) const;

 private:
  /// kExitUsage (with the message) when a named file is a directory, or one
  /// of `outputs`, the directories and standard output is an input or
  /// another of them; else kExitOk.
  int refuseInputs(const std::vector<std::string>& outputs, std::ostream& err) const;

  ReadLog reads_;
  std::vector<std::string> namedFiles_, directories_;
  bool stdoutIsFile_ = false;
};

}  // namespace substratec
