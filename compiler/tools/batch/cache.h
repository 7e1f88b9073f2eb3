// The content-hash cache of compiled materials (`--cache DIR`, docs/scenes.md,
// "Build pipelines"). The key is a hash (XXH3, 128 bits) of a key text that
// names everything the outputs depend on: the compiler (its version, the
// toolchain it links and the build id of the running executable), every
// option that changes an output, the input's path as given (it is in the
// outputs and the diagnostics) and the hash of its bytes. An entry holds the
// material's output files, its summary and its diagnostics; it is written
// atomically (a temporary renamed into place). An entry is used only when it
// reads back whole: its checksum matches, it is of this format, it is valid
// JSON of the expected shape and its key text is exactly the one expected;
// anything else (truncated, edited, a collision) is ignored and rewritten.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "batch/batch.h"

namespace substratec {

/// "substratec 0.1.0 (glslang ..., SPIRV-Tools ...) build <id>": the build id
/// of the running executable (its GNU build-id note, else a hash of the file).
const std::string& compilerIdentity();

/// 32 lowercase hex digits of XXH3-128 of `bytes`.
std::string hash128(std::string_view bytes);

/// The key text of one material: what its outputs depend on.
std::string cacheKeyText(const std::string& path, const std::string& input, const BatchOptions& options);

struct CachedMaterial {
  std::vector<OutputFile> files;
  MaterialSummary summary;
  std::string messages;  // warnings, replayed on a hit
};

class MaterialCache {
 public:
  explicit MaterialCache(std::string dir) : dir_(std::move(dir)) {}

  /// The entry of `keyText`, if one reads back whole (see above).
  std::optional<CachedMaterial> load(const std::string& keyText) const;
  /// Writes the entry of `keyText` atomically; "" or an error message.
  std::string store(const std::string& keyText, const CachedMaterial& entry) const;
  /// The entry of `keyText` as a file to write with a command's outputs (so
  /// that a command writes everything or nothing); nullopt and `error` when
  /// it cannot be cached (not UTF-8).
  std::optional<OutputPath> entryFile(const std::string& keyText, const CachedMaterial& entry,
                                      std::string* error) const;

  /// Where the entry of `keyText` lives: DIR/<first two hex digits>/<key>.entry.
  std::string entryPath(const std::string& keyText) const;

 private:
  std::string dir_;
};

}  // namespace substratec
