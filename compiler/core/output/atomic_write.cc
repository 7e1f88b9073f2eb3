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
std::string writeTemporary(const fs::path& dest, const std::string& contents, fs::path* tempPath) {
  const fs::path dir = dest.parent_path().empty() ? fs::path(".") : dest.parent_path();
  const std::string name = dest.filename().string();
  int fd = -1;
  for (int attempt = 0; fd < 0; ++attempt) {
    fs::path tmp = dir / fmt::format(".{}.tmp{}.{}", name, static_cast<long>(::getpid()), attempt);
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) *tempPath = tmp;
    else if (errno != EEXIST || attempt >= 100)
      return fmt::format("cannot write '{}': {}", dest.string(), std::strerror(errno));
  }
  std::size_t done = 0;
  while (done < contents.size()) {
    ssize_t n = ::write(fd, contents.data() + done, contents.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      std::string why = std::strerror(n < 0 ? errno : EIO);
      ::close(fd);
      return fmt::format("cannot write '{}': {}", dest.string(), why);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return fmt::format("cannot write '{}': {}", dest.string(), std::strerror(errno));
  return "";
}

/// The directory a destination goes into ("." for a bare name).
fs::path dirOf(const fs::path& dest) { return dest.parent_path().empty() ? fs::path(".") : dest.parent_path(); }

/// Creates the directory `dest` goes into, and the directories above it that
/// are missing, appending each one created to `created` (shallowest first).
/// "" or an error naming `dest`.
std::string makeDirectory(const fs::path& dest, std::vector<fs::path>& created) {
  const fs::path dir = dirOf(dest);
  std::error_code ec;
  std::vector<fs::path> missing;
  for (fs::path p = dir; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {  // bounded by the path's depth
    missing.insert(missing.begin(), p);
    if (p == p.parent_path()) break;
  }
  for (const fs::path& p : missing) {
    const bool made = fs::create_directory(p, ec);
    if (ec) return fmt::format("cannot write '{}': cannot create the directory '{}': {}", dest.string(), p.string(), ec.message());
    if (made) created.push_back(p);
  }
  if (!fs::is_directory(dir, ec))
    return fmt::format("cannot write '{}': '{}' is not a directory", dest.string(), dir.string());
  return "";
}

}  // namespace

std::string outputPathsIn(const std::string& dirName, const std::vector<OutputFile>& files,
                          std::vector<OutputPath>* paths) {
  const fs::path dir = dirName.empty() ? fs::path(".") : fs::path(dirName);
  for (const auto& f : files)
    if (!isPlainFileName(f.name)) return fmt::format("refusing to write the output name '{}'", f.name);
  for (const auto& f : files) paths->push_back({(dir / f.name).string(), f.contents});
  return "";
}

std::string writeFilesAtomically(const std::string& dirName, const std::vector<OutputFile>& files) {
  std::vector<OutputPath> paths;
  if (std::string error = outputPathsIn(dirName, files, &paths); !error.empty()) return error;
  if (paths.empty()) {  // nothing to write: the directory alone
    std::vector<fs::path> created;
    return makeDirectory((dirName.empty() ? fs::path(".") : fs::path(dirName)) / "-", created);
  }
  return writePathsAtomically(paths);
}

namespace {

/// Whether `path` is a regular file (not a link to one) holding exactly `contents`.
bool holdsExactly(const fs::path& path, const std::string& contents) {
  struct stat st;
  if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_size != static_cast<off_t>(contents.size()))
    return false;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) return false;
  std::string existing(contents.size(), '\0');
  std::size_t got = 0;
  while (got < existing.size()) {
    const ssize_t n = ::read(fd, existing.data() + got, existing.size() - got);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return got == contents.size() && existing == contents;
}

}  // namespace

std::string writePathsAtomically(const std::vector<OutputPath>& all) {
  for (const auto& f : all)
    if (!isPlainFileName(fs::path(f.path).filename().string()))
      return fmt::format("refusing to write the output '{}'", f.path);
  // A destination that already holds these bytes is left as it is (its
  // modification time kept): see the header.
  std::vector<const OutputPath*> files;
  for (const auto& f : all)
    if (!holdsExactly(f.path, f.contents)) files.push_back(&f);

  std::vector<fs::path> created;  // the directories this call creates, shallowest first
  std::vector<fs::path> temps(files.size()), backups(files.size());
  std::vector<bool> existed(files.size(), false);
  std::size_t renamed = 0;
  // On failure: put back what was replaced, remove what was added, remove the
  // temporaries and the directories this call created. Everything is as it was.
  auto rollback = [&](std::string message) {
    std::error_code ignored;
    for (std::size_t i = renamed; i-- > 0;) {
      const fs::path dest = files[i]->path;
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

  // Phase 1: every directory, then every file to a new temporary beside its
  // destination (same file system). Any destination that cannot be written
  // fails here, before anything is renamed.
  for (const auto& f : files)
    if (std::string error = makeDirectory(f->path, created); !error.empty()) return rollback(error);
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::string error = writeTemporary(files[i]->path, files[i]->contents, &temps[i]);
    if (!error.empty()) return rollback(error);
  }
  // Phase 2: keep a hard link to every file about to be replaced (so a failure
  // half way can put it back), then rename each temporary into place (atomic
  // per file on POSIX).
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path dest = files[i]->path;
    struct stat st;
    if (::lstat(dest.c_str(), &st) != 0) continue;  // nothing to replace
    existed[i] = true;
    const std::string name = dest.filename().string();
    for (int attempt = 0; attempt < 100; ++attempt) {
      fs::path backup = dirOf(dest) / fmt::format(".{}.old{}.{}", name, static_cast<long>(::getpid()), attempt);
      if (::link(dest.c_str(), backup.c_str()) == 0) {
        backups[i] = backup;
        break;
      }
      if (errno != EEXIST) break;  // no hard links here: the rename stays atomic, only the rollback is lost
    }
  }
  std::error_code ec;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path dest = files[i]->path;
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

namespace {

/// Whether `p` could be written, without creating anything another process
/// could see half-made: where its directory exists, a temporary is written
/// beside it and removed (unique names: no race); where it does not, the
/// nearest existing ancestor must be a directory this process may create
/// entries in. A probe that created and then removed the missing directories
/// raced with concurrent commands writing into the same new folder (two
/// `compile`s of one CMake target's depfile folder: one removed the folder
/// between the other's mkdir of it and of its child). "" or the error.
std::string probe(const fs::path& p) {
  const fs::path dir = dirOf(p);
  std::error_code ec;
  fs::path existing = dir;
  while (!existing.empty() && !fs::exists(existing, ec)) {  // bounded by the path's depth
    if (existing == existing.parent_path()) break;
    existing = existing.parent_path();
  }
  if (existing.empty()) existing = ".";
  if (existing == dir) {
    if (!fs::is_directory(dir, ec))
      return fmt::format("cannot write '{}': '{}' is not a directory", p.string(), dir.string());
    fs::path temp;
    std::string error = writeTemporary(p, "", &temp);
    if (!temp.empty()) fs::remove(temp, ec);
    return error;
  }
  if (!fs::is_directory(existing, ec))
    return fmt::format("cannot write '{}': '{}' is not a directory", p.string(), existing.string());
  if (::access(existing.c_str(), W_OK | X_OK) != 0)
    return fmt::format("cannot write '{}': cannot create a directory in '{}': {}", p.string(), existing.string(),
                       std::strerror(errno));
  return "";
}

}  // namespace

std::string checkWritable(const std::vector<std::string>& paths) {
  for (const std::string& p : paths)
    if (std::string error = probe(p); !error.empty()) return error;
  return "";
}

std::string checkWritableDirectory(const std::string& dir) {
  const fs::path file = fs::path(dir.empty() ? "." : dir) / "probe";
  std::string error = probe(file);
  // Named as the directory: "probe" is no file of the user's.
  const std::string named = "'" + file.string() + "'";
  if (auto at = error.find(named); at != std::string::npos) error.replace(at, named.size(), "into '" + dir + "'");
  return error;
}

}  // namespace substratec
