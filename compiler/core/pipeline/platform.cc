#include "pipeline/platform.h"

#include <algorithm>

#include <fmt/format.h>

namespace substratec {

namespace {

std::string knownFeatureNames() {
  std::string s;
  for (int b = 0; b < kFeatureCount; ++b)
    if (kPlatformFeatures & (1u << b)) s += (s.empty() ? "" : ", ") + std::string(featureName(b));
  return s;
}

}  // namespace

PlatformTable PlatformTable::builtin() {
  PlatformTable t;
  // Budgets after the course's byte table (docs/storage.md): mobile holds a
  // single-closure material with F90 + haze (20 B); console the two-closure
  // coats (40-48 B); pc-high every example (worked_example_72 is 72 B).
  t.platforms_.push_back({"mobile", 20, 1,
                          kFeatF90 | kFeatAnisotropy | kFeatHaze | kFeatEmissive,
                          "one closure, 20 bytes; no SSS, fuzz, glint or specular profile"});
  t.platforms_.push_back({"console", 48, 4, kPlatformFeatures & ~kFeatGlint,
                          "four closures, 48 bytes; no glint (136 bits a closure)"});
  t.platforms_.push_back({"pc-high", 80, 8, kPlatformFeatures, "eight closures, 80 bytes, every feature"});
  return t;
}

const Platform* PlatformTable::find(const std::string& name) const {
  for (const Platform& p : platforms_)
    if (p.name == name) return &p;
  return nullptr;
}

std::string PlatformTable::names() const {
  std::string s;
  for (const Platform& p : platforms_) s += (s.empty() ? "" : ", ") + p.name;
  return s;
}

std::optional<std::uint16_t> parseFeatureList(const Json& list, const std::string& pointer, Diagnostics& diags) {
  if (!list.is_array()) {
    diags.error(pointer, fmt::format("expected an array of feature names ({}), got {}", knownFeatureNames(),
                                     kindOfJson(list)));
    return std::nullopt;
  }
  std::uint16_t mask = 0;
  bool ok = true;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string p = fmt::format("{}/{}", pointer, i);
    const Json& e = list[i];
    int bit = -1;
    if (e.is_string())
      for (int b = 0; b < kFeatureCount; ++b)
        if ((kPlatformFeatures & (1u << b)) && featureName(b) == e.get_ref<const std::string&>()) bit = b;
    if (bit < 0) {
      diags.error(p, fmt::format("expected a feature name ({}), got {}", knownFeatureNames(), kindOfJson(e)));
      ok = false;
    } else if (mask & (1u << bit)) {
      diags.error(p, fmt::format("feature {} is listed twice", quoteForDiagnostic(e.get<std::string>())));
      ok = false;
    } else {
      mask |= static_cast<std::uint16_t>(1u << bit);
    }
  }
  if (!ok) return std::nullopt;
  return mask;
}

std::optional<PlatformTable> loadPlatformTable(const std::string& platformsFile, const ReadLimits& limits,
                                               std::string& messages) {
  PlatformTable t = PlatformTable::builtin();
  if (platformsFile.empty()) return t;
  Diagnostics d(platformsFile);
  const bool ok = t.applyFile(platformsFile, limits, d);
  messages += d.formatAll();
  if (!ok) return std::nullopt;
  return t;
}

bool PlatformTable::applyFile(const std::string& path, const ReadLimits& limits, Diagnostics& diags) {
  auto text = readSourceFile(path, limits, diags);
  return text && applyText(*text, limits, diags);
}

namespace {

/// The top level of a platforms file: only its known keys, and the format tag.
void checkPlatformsFileKeys(const Json& doc, Diagnostics& diags) {
  for (auto it = doc.begin(); it != doc.end(); ++it) {
    const std::string& key = it.key();
    if (key == "$schema" || key == "description") {
      if (!it->is_string()) diags.error("/" + pointerToken(key), "expected a string");
    } else if (key != "format" && key != "platforms") {
      diags.error("/" + pointerToken(key),
                  fmt::format("unknown key {} (expected one of: format, platforms, description)", quoteForDiagnostic(key)));
    }
  }
  auto fmtIt = doc.find("format");
  if (fmtIt == doc.end())
    diags.error("", "missing required key \"format\" (expected \"substrate-platforms/1\")");
  else if (!fmtIt->is_string() || fmtIt->get<std::string>() != "substrate-platforms/1")
    diags.error("/format", fmt::format("expected \"substrate-platforms/1\", got {}", kindOfJson(*fmtIt)));
}

/// The keys of one platform object at `ptr`, over `def` (its base, if any).
void readPlatformKeys(const Json& p, const std::string& ptr, Platform& def, Diagnostics& diags) {
  for (auto k = p.begin(); k != p.end(); ++k) {
    const std::string kp = ptr + "/" + pointerToken(k.key());
    const Json& v = *k;
    auto integer = [&](int lo, int hi, int& out) {
      if (!v.is_number_integer() || v.get<long long>() < lo || v.get<long long>() > hi)
        diags.error(kp, fmt::format("expected an integer in [{},{}], got {}", lo, hi, kindOfJson(v)));
      else
        out = static_cast<int>(v.get<long long>());
    };
    if (k.key() == "bytes_per_pixel") {
      integer(8, 1024, def.bytesPerPixel);
    } else if (k.key() == "max_closures") {
      integer(1, 8, def.maxClosures);
    } else if (k.key() == "features") {
      if (auto mask = parseFeatureList(v, kp, diags)) def.allowedFeatures = *mask;
    } else if (k.key() == "description") {
      if (!v.is_string()) diags.error(kp, "expected a string");
      else def.description = v.get<std::string>();
    } else if (k.key() != "extends") {
      diags.error(kp, fmt::format("unknown key {} (expected one of: extends, bytes_per_pixel, max_closures, "
                                  "features, description)",
                                  quoteForDiagnostic(k.key())));
    }
  }
}

/// One entry of "platforms": a new platform, or a change to one of `result`
/// (built in or defined before), which it replaces or joins.
void readPlatformEntry(const std::string& name, const Json& p, std::vector<Platform>& result, Diagnostics& diags) {
  const std::string ptr = "/platforms/" + pointerToken(name);
  if (name.empty() || name.size() > 64 || name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") != std::string::npos) {
    diags.error(ptr, fmt::format("platform name {} must be 1-64 characters of a-z, 0-9, '-' and '_'",
                                 quoteForDiagnostic(name)));
    return;
  }
  if (!p.is_object()) {
    diags.error(ptr, fmt::format("expected a platform object like {{\"bytes_per_pixel\": 20, \"max_closures\": 1}}, "
                                 "got {}", kindOfJson(p)));
    return;
  }
  auto existing = std::find_if(result.begin(), result.end(), [&](const Platform& q) { return q.name == name; });
  Platform def;
  bool haveBase = existing != result.end();
  if (haveBase) def = *existing;
  if (auto e = p.find("extends"); e != p.end()) {
    const Platform* base = nullptr;
    if (e->is_string())
      for (const Platform& q : result)
        if (q.name == e->get_ref<const std::string&>()) base = &q;
    if (!base) {
      std::string known;
      for (const Platform& q : result) known += (known.empty() ? "" : ", ") + q.name;
      diags.error(ptr + "/extends", fmt::format("expected the name of a platform defined before ({}), got {}", known,
                                                kindOfJson(*e)));
      return;
    }
    def = *base;
    haveBase = true;
  }
  def.name = name;
  readPlatformKeys(p, ptr, def, diags);
  if (!haveBase)
    for (const char* required : {"bytes_per_pixel", "max_closures"})
      if (!p.contains(required))
        diags.error(ptr, fmt::format("a new platform needs \"{}\" (or \"extends\": a platform to start from)",
                                     required));
  if (existing != result.end()) *existing = def;
  else result.push_back(def);
}

}  // namespace

bool PlatformTable::applyText(const std::string& text, const ReadLimits& limits, Diagnostics& diags) {
  auto doc = parseJsonDocument(text, limits, diags);
  if (!doc) return false;
  if (!doc->is_object()) {
    diags.error("", fmt::format("expected the platforms object at the top level, got {}", kindOfJson(*doc)));
    return false;
  }
  const std::size_t errorsBefore = diags.errorCount();
  checkPlatformsFileKeys(*doc, diags);

  std::vector<Platform> result = platforms_;
  auto listIt = doc->find("platforms");
  if (listIt == doc->end()) {
    diags.error("", "missing required key \"platforms\" (an object of platforms keyed by name)");
  } else if (!listIt->is_object()) {
    diags.error("/platforms", fmt::format("expected an object of platforms keyed by name, got {}", kindOfJson(*listIt)));
  } else {
    for (auto p = listIt->begin(); p != listIt->end(); ++p) readPlatformEntry(p.key(), *p, result, diags);
  }
  if (diags.errorCount() != errorsBefore) return false;
  platforms_ = std::move(result);
  return true;
}

}  // namespace substratec
