// Which files a command reads and which it would write, compared by what they
// are (device and inode) rather than by how they are spelled: `preview p.json
// -o p.json`, `--depfile ./d.json` beside `d.json`, an output reached through
// a symbolic or a hard link, and a material named m.layout.json compiled into
// its own folder all name one file. Every command runs its outputs through
// sameFileAsInput before it writes anything (exit 2 when one is an input).
//
// The inputs are the files the command actually read: readSourceFile (every
// material, include, manifest and platforms file) and the --cache reader
// record each file they open in the active ReadLog, with the identity of the
// open file (fstat), so a file renamed or replaced after it was read is still
// the one compared.
#pragma once
#include <compare>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace substratec {

/// A file's identity: the device and inode a path resolves to.
struct FileId {
  std::uint64_t device = 0;
  std::uint64_t inode = 0;
  auto operator<=>(const FileId&) const = default;
};

/// The identity of what `path` names now (symbolic links followed); nullopt
/// when nothing is there.
std::optional<FileId> fileIdOf(const std::string& path);

/// One file a command read: as it was named, and what it was when read.
struct InputFile {
  std::string path;
  FileId id;
  bool cacheEntry = false;  // a --cache entry used (an input, but no depfile prerequisite)
};

/// Records every file read (readSourceFile, the --cache reader) while it is
/// alive, on any thread. One log is active at a time in a process: a log
/// created while another is active takes over until it ends, then the other
/// is active again.
class ReadLog {
 public:
  ReadLog();
  ~ReadLog();
  ReadLog(const ReadLog&) = delete;
  ReadLog& operator=(const ReadLog&) = delete;

  /// Every file read so far, in the order first read (each identity once).
  std::vector<InputFile> files() const;
  /// Adds a file read by other means (an input known by name, not yet read).
  void add(const std::string& path);

 private:
  friend void noteFileRead(const std::string& path, std::uint64_t device, std::uint64_t inode, bool cacheEntry);
  void record(const std::string& path, FileId id, bool cacheEntry);
  ReadLog* previous_ = nullptr;
  std::vector<InputFile> files_;
};

/// Called by the readers with the fstat of the file they opened: recorded in
/// the active ReadLog, if any.
void noteFileRead(const std::string& path, std::uint64_t device, std::uint64_t inode, bool cacheEntry = false);

/// What a command is about to write: each path (existing or not; a file that
/// does not exist yet is compared through its nearest existing directory and
/// the rest of its path) checked against every input and every other output.
/// "" when all are distinct; else an error message naming the output and the
/// input (or the two outputs) that are the same file.
std::string sameFileAsInput(const std::vector<std::string>& outputs, const std::vector<InputFile>& inputs);

}  // namespace substratec
