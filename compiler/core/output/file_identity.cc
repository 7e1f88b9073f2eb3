#include "output/file_identity.h"

#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <mutex>

#include <fmt/format.h>

namespace substratec {

namespace fs = std::filesystem;

namespace {

std::mutex gLogMutex;
ReadLog* gActive = nullptr;  // guarded by gLogMutex

/// Where a path would be written: the identity of the file itself when it
/// exists, else of its nearest existing ancestor and the rest of the path
/// below it. Two outputs with the same place are the same file.
struct Place {
  FileId id;
  std::string rest;  // "" when the file exists
  auto operator<=>(const Place&) const = default;
};

Place placeOf(const std::string& path, int depth = 0) {
  if (auto id = fileIdOf(path)) return {*id, ""};
  const fs::path p(path);
  fs::path rest = p.filename();
  fs::path dir = p.parent_path();
  std::optional<FileId> at;
  for (;; dir = dir.parent_path()) {  // bounded by the number of components of the path
    at = fileIdOf(dir.empty() ? "." : dir.string());
    if (at || dir.empty() || dir == dir.parent_path()) break;
    rest = dir.filename() / rest;
  }
  if (!at) return {FileId{}, p.lexically_normal().string()};  // nothing of it exists
  // What is below `dir` will be created as plain directories, so "." and
  // ".." there mean what they say; a ".." above them climbs out of `dir`,
  // perhaps onto a file that exists (`out/../input.json`, `out` missing).
  const fs::path normal = rest.lexically_normal();
  if (normal != rest && depth < 4) return placeOf(((dir.empty() ? fs::path(".") : dir) / normal).string(), depth + 1);
  return {*at, normal.string()};
}

}  // namespace

std::optional<FileId> fileIdOf(const std::string& path) {
  struct stat st;
  if (path.empty() || ::stat(path.c_str(), &st) != 0) return std::nullopt;
  return FileId{static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino)};
}

ReadLog::ReadLog() {
  std::lock_guard<std::mutex> lock(gLogMutex);
  previous_ = gActive;
  gActive = this;
}

ReadLog::~ReadLog() {
  std::lock_guard<std::mutex> lock(gLogMutex);
  if (gActive == this) gActive = previous_;
}

std::vector<InputFile> ReadLog::files() const {
  std::lock_guard<std::mutex> lock(gLogMutex);
  return files_;
}

void ReadLog::add(const std::string& path) {
  if (auto id = fileIdOf(path)) {
    std::lock_guard<std::mutex> lock(gLogMutex);
    record(path, *id, false);
  }
}

void ReadLog::record(const std::string& path, FileId id, bool cacheEntry) {  // gLogMutex held
  for (const InputFile& f : files_)
    if (f.id == id) return;
  files_.push_back({path, id, cacheEntry});
}

void noteFileRead(const std::string& path, std::uint64_t device, std::uint64_t inode, bool cacheEntry) {
  std::lock_guard<std::mutex> lock(gLogMutex);
  if (gActive) gActive->record(path, FileId{device, inode}, cacheEntry);
}

std::string sameFileAsInput(const std::vector<std::string>& outputs, const std::vector<InputFile>& inputs) {
  std::map<Place, const std::string*> seen;
  for (const std::string& out : outputs) {
    const Place place = placeOf(out);
    if (place.rest.empty())
      for (const InputFile& in : inputs)
        if (in.id == place.id)
          return in.path == out
                     ? fmt::format("output '{}' is an input; refusing to overwrite it", out)
                     : fmt::format("output '{}' is the input '{}' (the same file); refusing to overwrite it", out,
                                   in.path);
    if (auto [at, fresh] = seen.emplace(place, &out); !fresh)
      return fmt::format("outputs '{}' and '{}' are the same file; one would overwrite the other", *at->second, out);
  }
  return "";
}

}  // namespace substratec
