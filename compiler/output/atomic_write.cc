#include "output/atomic_write.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <fmt/format.h>

namespace substratec {

namespace fs = std::filesystem;

std::string writeFilesAtomically(const std::string& dir, const std::vector<OutputFile>& files) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return fmt::format("cannot create output directory '{}': {}", dir, ec.message());
  std::vector<fs::path> temps;
  auto cleanup = [&] {
    for (const auto& t : temps) fs::remove(t, ec);
  };
  // Phase 1: every file to a temporary beside its destination (same file system).
  for (const auto& f : files) {
    fs::path tmp = fs::path(dir) / fmt::format(".{}.tmp{}", f.name, static_cast<long>(::getpid()));
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      cleanup();
      return fmt::format("cannot write '{}'", (fs::path(dir) / f.name).string());
    }
    temps.push_back(tmp);
    out << f.contents;
    out.flush();
    if (!out) {
      cleanup();
      return fmt::format("cannot write '{}'", (fs::path(dir) / f.name).string());
    }
  }
  // Phase 2: rename into place (atomic per file on POSIX).
  for (std::size_t i = 0; i < files.size(); ++i) {
    fs::rename(temps[i], fs::path(dir) / files[i].name, ec);
    if (ec) {
      cleanup();
      return fmt::format("cannot rename into '{}': {}", (fs::path(dir) / files[i].name).string(), ec.message());
    }
  }
  return "";
}

}  // namespace substratec
