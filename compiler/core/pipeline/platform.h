// Platforms: named profiles that materials are simplified for — a byte budget
// per pixel, closures per pixel, and the opt-in features the platform's
// lighting evaluates. A built-in table (mobile, console, pc-high;
// docs/scenes.md) that a project extends or overrides with a
// `substrate-platforms/1` file (schema/substrate-platforms.schema.json).
//
// A platform caps a material: the budget and the closure count used are the
// smaller of the material's (or --budget / --max-closures) and the platform's,
// and every feature the platform does not allow is disabled before the
// material is fitted to the budget (passes/simplify.h).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "ir/material.h"

namespace substratec {

/// The features a platform allows or not, by their scene names (featureName):
/// f90, anisotropy, sss, haze, fuzz, glint, specular_profile, emissive.
inline constexpr std::uint16_t kPlatformFeatures = kFeatF90 | kFeatAnisotropy | kFeatSss | kFeatHaze | kFeatFuzz |
                                                   kFeatGlint | kFeatSpecularProfile | kFeatEmissive;

struct Platform {
  std::string name;
  int bytesPerPixel = 80;
  int maxClosures = 8;
  std::uint16_t allowedFeatures = kPlatformFeatures;
  std::string description;

  std::uint16_t disallowedFeatures() const { return kPlatformFeatures & ~allowedFeatures; }
};

/// The platforms known to a run: the built-in table, then a --platforms file.
class PlatformTable {
 public:
  /// mobile, console, pc-high (docs/scenes.md, "Platforms").
  static PlatformTable builtin();

  const Platform* find(const std::string& name) const;
  const std::vector<Platform>& all() const { return platforms_; }
  /// "mobile, console, pc-high" (for diagnostics).
  std::string names() const;

  /// Reads a substrate-platforms/1 file and applies it: an entry with a known
  /// name overrides the keys it gives, a new name adds a platform ("extends"
  /// copies another first). Every problem is reported (JSON pointers, or
  /// line:col for syntax); on any error the table is left unchanged.
  bool applyFile(const std::string& path, const ReadLimits& limits, Diagnostics& diags);
  /// The same, from text already read.
  bool applyText(const std::string& text, const ReadLimits& limits, Diagnostics& diags);

 private:
  std::vector<Platform> platforms_;
};

/// The built-in table extended by `platformsFile` ("" for none). nullopt when
/// the file has errors; its diagnostics are appended to `messages`.
std::optional<PlatformTable> loadPlatformTable(const std::string& platformsFile, const ReadLimits& limits,
                                               std::string& messages);

/// Parses a list of feature names (a JSON array of strings) at `pointer`
/// into feature bits; unknown names are errors listing the known ones.
std::optional<std::uint16_t> parseFeatureList(const Json& list, const std::string& pointer, Diagnostics& diags);

}  // namespace substratec
