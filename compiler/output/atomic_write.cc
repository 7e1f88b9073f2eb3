#include "output/atomic_write.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <fmt/format.h>

namespace substratec {

namespace fs = std::filesystem;

namespace {

/// A plain file name: no directory part, not "." or "..", no NUL.
bool isPlainFileName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && name.find('/') == std::string::npos &&
         name.find('\0') == std::string::npos;
}

/// Creates a new file `dir/.name.tmp<pid>.<n>` (mode 0666 & ~umask, like
/// any output) and writes `contents` into it. Never follows or reuses an
/// existing name (O_CREAT | O_EXCL). Returns "" and the path, or an error.
std::string writeTemporary(const fs::path& dir, const OutputFile& f, fs::path* tempPath) {
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    fs::path tmp = dir / fmt::format(".{}.tmp{}.{}", f.name, static_cast<long>(::getpid()), attempt);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) *tempPath = tmp;
    else if (errno != EEXIST || attempt >= 100)
      return fmt::format("cannot write '{}': {}", (dir / f.name).string(), std::strerror(errno));
  }
  std::size_t done = 0;
  while (done < f.contents.size()) {
    ssize_t n = ::write(fd, f.contents.data() + done, f.contents.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::string why = std::strerror(n < 0 ? errno : EIO);
      ::close(fd);
      return fmt::format("cannot write '{}': {}", (dir / f.name).string(), why);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return fmt::format("cannot write '{}': {}", (dir / f.name).string(), std::strerror(errno));
  return "";
}

}  // namespace

std::string writeFilesAtomically(const std::string& dirName, const std::vector<OutputFile>& files) {
  const fs::path dir = dirName.empty() ? fs::path(".") : fs::path(dirName);
  for (const auto& f : files)
    if (!isPlainFileName(f.name)) return fmt::format("refusing to write the output name '{}'", f.name);

  // The directories this run creates, deepest last, so a failure removes them again.
  std::error_code ec;
  std::vector<fs::path> created;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    created.insert(created.begin(), p);
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  if (ec) return fmt::format("cannot create output directory '{}': {}", dir.string(), ec.message());

  std::vector<fs::path> temps(files.size()), backups(files.size());
  std::vector<bool> existed(files.size(), false);
  std::size_t renamed = 0;
  // On failure: put back what was replaced, remove what was added, remove the
  // temporaries and the directories this run created. The folder is as it was.
  auto rollback = [&](std::string message) {
    std::error_code ignored;
    for (std::size_t i = renamed; i-- > 0;) {
      const fs::path dest = dir / files[i].name;
      if (!backups[i].empty()) fs::rename(backups[i], dest, ignored);
      else if (!existed[i]) fs::remove(dest, ignored);
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      if (!temps[i].empty()) fs::remove(temps[i], ignored);
      if (!backups[i].empty()) fs::remove(backups[i], ignored);
    }
    for (auto it = created.rbegin(); it != created.rend(); ++it) fs::remove(*it, ignored);  // only if empty
    return message;
  };

  // Phase 1: every file to a new temporary beside its destination (same file system).
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::string error = writeTemporary(dir, files[i], &temps[i]);
    if (!error.empty()) return rollback(error);
  }
  // Phase 2: keep a hard link to every file about to be replaced (so a failure
  // half way can put it back), then rename each temporary into place (atomic
  // per file on POSIX).
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path dest = dir / files[i].name;
    struct stat st;
    if (::lstat(dest.c_str(), &st) != 0) continue;  // nothing to replace
    existed[i] = true;
    for (int attempt = 0; attempt < 100; ++attempt) {
      fs::path backup = dir / fmt::format(".{}.old{}.{}", files[i].name, static_cast<long>(::getpid()), attempt);
      if (::link(dest.c_str(), backup.c_str()) == 0) {
        backups[i] = backup;
        break;
      }
      if (errno != EEXIST) break;  // no hard links here: the rename stays atomic, only the rollback is lost
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path dest = dir / files[i].name;
    fs::rename(temps[i], dest, ec);
    if (ec) return rollback(fmt::format("cannot rename into '{}': {}", dest.string(), ec.message()));
    temps[i].clear();
    ++renamed;
  }
  std::error_code ignored;
  for (const auto& b : backups)
    if (!b.empty()) fs::remove(b, ignored);
  return "";
}

}  // namespace substratec
