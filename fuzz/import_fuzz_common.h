// What the importer fuzzers check on every input: it is imported or rejected
// with at least one diagnostic, never a crash or an uncaught exception; every
// material it returns has a usable, unique name and compiles (an imported
// material that does not compile is the importer's bug: exit 3 in the CLI).
#pragma once
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "import/import.h"
#include "passes/resolve.h"
#include "pipeline/pipeline.h"

namespace substratec::fuzz {

/// Most imported materials compiled per input (compiling is the slow part).
inline constexpr std::size_t kMaxCompiled = 4;

inline void checkImported(const std::optional<std::vector<import::ImportedMaterial>>& materials,
                          const Diagnostics& diags) {
  if (!materials) {
    if (!diags.hasErrors()) std::abort();  // rejected without saying why
    return;
  }
  if (materials->empty()) std::abort();
  std::set<std::string> names;
  for (std::size_t i = 0; i < materials->size(); ++i) {
    const import::ImportedMaterial& m = (*materials)[i];
    if (!isUsableIdentifier(m.name) || !names.insert(m.name).second) std::abort();
    if (i >= kMaxCompiled) continue;
    Diagnostics d(m.name);
    if (!compileText(m.name, m.text, CompileOptions{}, d)) std::abort();
  }
  if (diags.formatAll().size() > (std::size_t{1} << 22)) std::abort();
}

/// A directory that does not exist: relative includes, buffers and images
/// are then never found (the fuzzers read no files).
inline const char* kNoDirectory = "/nonexistent-substratec-fuzz/dir";

/// Inputs naming device or kernel files are skipped: an absolute include of
/// /dev/stdin would wait for input forever.
inline bool namesSystemFiles(const std::string& text) {
  for (const char* p : {"/dev", "/proc", "/sys"})
    if (text.find(p) != std::string::npos) return true;
  return false;
}

}  // namespace substratec::fuzz
