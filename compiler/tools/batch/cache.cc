#include "batch/cache.h"

#include <elf.h>
#include <link.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#define XXH_INLINE_ALL
#include <xxhash.h>

#include <fmt/format.h>

#include "output/file_identity.h"
#include "validate/toolchain.h"

namespace substratec {

namespace {

constexpr std::string_view kMagic = "substratec-cache/1";
constexpr std::size_t kMaxEntryBytes = 64u << 20;

/// The GNU build-id note of the main program, as hex ("" if it has none).
std::string buildId() {
  std::string id;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* out) {
        for (int i = 0; i < info->dlpi_phnum; ++i) {
          const ElfW(Phdr)& ph = info->dlpi_phdr[i];
          if (ph.p_type != PT_NOTE) continue;
          const char* p = reinterpret_cast<const char*>(info->dlpi_addr + ph.p_vaddr);
          const char* end = p + ph.p_memsz;
          while (p + sizeof(ElfW(Nhdr)) <= end) {
            const auto* n = reinterpret_cast<const ElfW(Nhdr)*>(p);
            const char* name = p + sizeof(ElfW(Nhdr));
            const char* desc = name + ((n->n_namesz + 3) & ~3u);
            if (desc + n->n_descsz > end) break;
            if (n->n_type == NT_GNU_BUILD_ID && n->n_namesz == 4 && std::string_view(name, 3) == "GNU") {
              auto* s = static_cast<std::string*>(out);
              for (unsigned k = 0; k < n->n_descsz; ++k)
                *s += fmt::format("{:02x}", static_cast<unsigned char>(desc[k]));
              return 1;
            }
            p = desc + ((n->n_descsz + 3) & ~3u);
          }
        }
        return 1;  // the first object is the main program: stop there
      },
      &id);
  return id;
}

std::string readAll(const std::filesystem::path& p, std::size_t limit) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return {};
  std::string s;
  char buf[1 << 16];
  while (in && s.size() <= limit) {
    in.read(buf, sizeof buf);
    s.append(buf, static_cast<std::size_t>(in.gcount()));
  }
  return s.size() > limit ? std::string() : s;
}

}  // namespace

std::string hash128(std::string_view bytes) {
  const XXH128_hash_t h = XXH3_128bits(bytes.data(), bytes.size());
  return fmt::format("{:016x}{:016x}", h.high64, h.low64);
}

const std::string& compilerIdentity() {
  static const std::string id = [] {
    std::string build = buildId();
    if (build.empty()) build = "exe-" + hash128(readAll("/proc/self/exe", std::size_t{1} << 31));
    return "substratec 0.1.0 (" + toolchainVersions() + ") build " + build;
  }();
  return id;
}

std::string cacheKeyText(const std::string& path, const std::string& input, const BatchOptions& o) {
  // Every option that can change an output or a diagnostic. A new option of
  // CompileOptions, GenerateOptions or EmitOptions that does must be added here.
  const CompileOptions& c = o.compile;
  const EmitOptions& e = o.generate.emit;
  std::string platform = "none";
  if (c.platform)
    platform = fmt::format("{} {} {} {}", c.platform->name, c.platform->bytesPerPixel, c.platform->maxClosures,
                           c.platform->allowedFeatures);
  return fmt::format(
      "{}\ncompiler {}\nread {} {} {} {}\nresolve {} {} {}\ntree {}\nbudget {}\nclosures {}\nfull {}\nblend {}\n"
      "platform {}\ntargets {}{}\ndiffuse {}\nprecision {}\nper-invocation {}\ndynamic {}\nvalidate {}\npath {}\ninput {} {}\n",
      kMagic, compilerIdentity(), c.read.maxInputBytes, c.read.maxNesting, c.read.maxStringBytes, c.read.maxKeyBytes,
      c.resolve.maxNodes, c.resolve.maxInputs, c.resolve.maxIdentifierBytes, c.tree.maxTreeNodes,
      c.budgetOverride ? std::to_string(*c.budgetOverride) : "-",
      c.maxClosuresOverride ? std::to_string(*c.maxClosuresOverride) : "-", c.fullSimplification,
      static_cast<int>(c.blendRule), platform, o.generate.glsl ? "glsl" : "", o.generate.hlsl ? " hlsl" : "",
      diffuseModelNumber(e.diffuseModel), static_cast<int>(e.precision), e.inputsPerInvocation, e.dynamicSimplification, o.validate, path, input.size(), hash128(input));
}

std::string MaterialCache::entryPath(const std::string& keyText) const {
  const std::string key = hash128(keyText);
  return (std::filesystem::path(dir_) / key.substr(0, 2) / (key + ".entry")).string();
}

std::optional<CachedMaterial> MaterialCache::load(const std::string& keyText) const {
  const std::string path = entryPath(keyText);
  const std::string text = readAll(path, kMaxEntryBytes);
  // "<magic> <checksum of the rest>\n<json>"
  const std::size_t eol = text.find('\n');
  if (eol == std::string::npos || text.compare(0, kMagic.size(), kMagic) != 0 || eol != kMagic.size() + 1 + 32 ||
      text[kMagic.size()] != ' ')
    return std::nullopt;
  const std::string_view body = std::string_view(text).substr(eol + 1);
  if (text.compare(kMagic.size() + 1, 32, hash128(body)) != 0) return std::nullopt;
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(body, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return std::nullopt;
  try {
    if (j.at("key").get<std::string>() != keyText) return std::nullopt;  // another key in this slot
    CachedMaterial m;
    auto summary = summaryFromJson(j.at("summary"));
    if (!summary) return std::nullopt;
    m.summary = std::move(*summary);
    m.messages = j.at("messages").get<std::string>();
    for (const auto& f : j.at("files")) {
      OutputFile out{f.at("name").get<std::string>(), f.at("contents").get<std::string>()};
      if (out.name.empty() || out.name.find('/') != std::string::npos || out.name == "." || out.name == "..")
        return std::nullopt;
      m.files.push_back(std::move(out));
    }
    if (m.files.empty()) return std::nullopt;
    // An entry used is an input of the command, like any file it reads
    // (output/file_identity.h); one ignored is rewritten, as the cache's own.
    if (auto id = fileIdOf(path)) noteFileRead(path, id->device, id->inode, /*cacheEntry=*/true);
    return m;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;
  }
}

std::optional<OutputPath> MaterialCache::entryFile(const std::string& keyText, const CachedMaterial& entry,
                                                   std::string* error) const {
  nlohmann::ordered_json j;
  j["key"] = keyText;
  j["summary"] = summaryJson(entry.summary);
  j["messages"] = entry.messages;
  nlohmann::ordered_json files = nlohmann::ordered_json::array();
  for (const OutputFile& f : entry.files) files.push_back({{"name", f.name}, {"contents", f.contents}});
  j["files"] = files;
  std::string body;
  try {
    body = j.dump();
  } catch (const nlohmann::json::exception& e) {  // not UTF-8: kept out of the cache rather than altered
    *error = std::string("cannot cache ") + entry.summary.name + ": " + e.what();
    return std::nullopt;
  }
  return OutputPath{entryPath(keyText), fmt::format("{} {}\n{}", kMagic, hash128(body), body)};
}

std::string MaterialCache::store(const std::string& keyText, const CachedMaterial& entry) const {
  std::string error;
  auto file = entryFile(keyText, entry, &error);
  if (!file) return error;
  return writePathsAtomically({*file});
}

}  // namespace substratec
