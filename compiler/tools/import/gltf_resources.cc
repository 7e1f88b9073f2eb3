#include "import/gltf_resources.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>

namespace substratec::import {

namespace {

/// A resource's bytes as far as the check needs them: readable, and how many.
struct Readable {
  bool ok = false;
  std::uintmax_t bytes = 0;
  std::string why;  // when not ok
};

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// The decoded size of a data: URI, or why it is malformed.
Readable dataUri(const std::string& uri) {
  const std::size_t comma = uri.find(',');
  if (comma == std::string::npos) return {false, 0, "a data: URI without ','"};
  const std::string header = uri.substr(5, comma - 5), data = uri.substr(comma + 1);
  if (header.size() < 7 || header.compare(header.size() - 7, 7, ";base64") != 0)
    return {true, data.size(), ""};  // percent-encoded text: its length bounds the bytes
  std::size_t n = data.size();
  while (n > 0 && data[n - 1] == '=' && data.size() - n < 2) --n;
  for (std::size_t i = 0; i < n; ++i) {
    const char c = data[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/'))
      return {false, 0, fmt::format("a base64 data: URI with the character {} at {}", quoteForDiagnostic(std::string(1, c)), i)};
  }
  if (data.size() % 4 != 0) return {false, 0, "a base64 data: URI whose length is not a multiple of 4"};
  return {true, n * 3 / 4, ""};
}


Readable file(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) return {false, 0, std::strerror(errno)};
  if (S_ISDIR(st.st_mode)) return {false, 0, "it is a directory"};
  if (!S_ISREG(st.st_mode)) return {false, 0, "not a regular file"};
  if (::access(path.c_str(), R_OK) != 0) return {false, 0, std::strerror(errno)};
  return {true, static_cast<std::uintmax_t>(st.st_size), ""};
}

/// A non-negative integer `j[key]`, or 0.
std::uintmax_t countOf(const Json& j, const char* key) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number_integer()) return 0;
  if (it->is_number_unsigned()) return it->get<std::uintmax_t>();
  const long long v = it->get<long long>();
  return v > 0 ? static_cast<std::uintmax_t>(v) : 0;
}

const Json* arrayOf(const Json& doc, const char* key) {
  auto it = doc.find(key);
  return it != doc.end() && it->is_array() ? &*it : nullptr;
}

std::optional<std::size_t> indexIn(const Json& j, const char* key, const Json* array) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_number_integer() || !array) return std::nullopt;
  const auto i = it->get<long long>();
  if (i < 0 || static_cast<std::size_t>(i) >= array->size()) return std::nullopt;
  return static_cast<std::size_t>(i);
}

/// Images sampled by a material: every textureInfo (a key ending in
/// "Texture" holding an "index") anywhere in a material, through its texture's
/// source (or an extension's source). image -> a material that samples it.
std::map<std::size_t, std::string> sampledImages(const Json& doc) {
  std::map<std::size_t, std::string> out;
  const Json* materials = arrayOf(doc, "materials");
  const Json* textures = arrayOf(doc, "textures");
  const Json* images = arrayOf(doc, "images");
  if (!materials || !textures || !images) return out;
  for (std::size_t m = 0; m < materials->size(); ++m) {
    const Json& mat = (*materials)[m];
    const std::string who = mat.is_object() && mat.contains("name") && mat["name"].is_string()
                                ? quoteForDiagnostic(mat["name"].get<std::string>())
                                : fmt::format("materials[{}]", m);
    std::vector<const Json*> stack = {&mat};
    for (std::size_t steps = 0; !stack.empty() && steps < 100000; ++steps) {  // bounded by the document
      const Json* j = stack.back();
      stack.pop_back();
      if (!j->is_object()) {
        if (j->is_array())
          for (const auto& c : *j) stack.push_back(&c);
        continue;
      }
      for (auto it = j->begin(); it != j->end(); ++it) {
        const std::string& key = it.key();
        if (key.size() >= 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && it->is_object())
          if (auto t = indexIn(*it, "index", textures); t && (*textures)[*t].is_object()) {
            const Json& tex = (*textures)[*t];
            std::optional<std::size_t> source = indexIn(tex, "source", images);
            if (auto e = tex.find("extensions"); e != tex.end() && e->is_object())
              for (const auto& [name, ext] : e->items())
                if (ext.is_object())
                  if (auto s = indexIn(ext, "source", images)) source = s;
            if (source) out.emplace(*source, who);
          }
        if (it->is_structured()) stack.push_back(&*it);
      }
    }
  }
  return out;
}

}  // namespace

namespace {

/// checkGltfResources' state: the warnings given (one per missing file, at
/// most kMaxResourceWarnings listed) and what each buffer holds.
class ResourceCheck {
 public:
  ResourceCheck(const std::string& baseDir, Diagnostics& d) : baseDir_(baseDir), d_(d) {}
  /// buffers[i]: geometry, never needed by a material; what it holds, for the images.
  void buffer(const Json& b, std::size_t i, std::optional<std::size_t> glbBinBytes);
  /// images[i]: an error when a material samples it and it cannot be read.
  void image(const Json& img, std::size_t i, const Json* views, const Json* bufferArray,
             const std::map<std::size_t, std::string>& sampled);
  bool finish() {
    if (unreported_ > 0) d_.warning("", fmt::format("{} more resources cannot be read (not listed)", unreported_));
    return ok_;
  }

 private:
  void warn(const std::string& pointer, const std::string& file, const std::string& message) {
    if (!file.empty() && !warnedFiles_.insert(file).second) return;
    if (++warnings_ > kMaxResourceWarnings) {
      ++unreported_;
      return;
    }
    d_.warning(pointer, message);
  }
  std::pair<std::string, Readable> resolve(const std::string& uri) const {
    if (uri.rfind("data:", 0) == 0) return {"", dataUri(uri)};
    auto path = uriPath(uri);
    if (!path) return {"", {false, 0, "not a relative file path (only files next to the document are read)"}};
    const std::string full = (std::filesystem::path(baseDir_) / *path).string();
    return {full, file(full)};
  }

  const std::string& baseDir_;
  Diagnostics& d_;
  bool ok_ = true;
  int warnings_ = 0, unreported_ = 0;
  std::set<std::string> warnedFiles_;  // one warning per missing file
  std::vector<Readable> buffers_;
};

void ResourceCheck::buffer(const Json& b, std::size_t i, std::optional<std::size_t> glbBinBytes) {
  const std::string ptr = fmt::format("/buffers/{}", i);
  const std::uintmax_t need = b.is_object() ? countOf(b, "byteLength") : 0;
  Readable r;
  std::string file;
  if (b.is_object() && b.contains("uri") && b["uri"].is_string()) {
    std::tie(file, r) = resolve(b["uri"].get<std::string>());
    if (!r.ok)
      warn(ptr + "/uri", file, fmt::format("buffers[{}] {} cannot be read ({}); materials do not need geometry",
                                           i, quoteForDiagnostic(file.empty() ? b["uri"].get<std::string>() : file, 200),
                                           r.why));
  } else if (i == 0 && glbBinBytes) {
    r = {true, *glbBinBytes, ""};
  } else {
    r = {false, 0, "no uri and no .glb binary chunk"};
    warn(ptr, "", fmt::format("buffers[{}] has no uri and the document has no .glb binary chunk; materials do not "
                              "need geometry", i));
  }
  if (r.ok && r.bytes < need) {
    warn(ptr + "/byteLength", file, fmt::format("buffers[{}] holds {} bytes, fewer than its byteLength {}; "
                                                "materials do not need geometry", i, r.bytes, need));
    r.ok = false;
    r.why = fmt::format("its buffer holds {} of {} bytes", r.bytes, need);
  }
  buffers_.push_back(r);
}

void ResourceCheck::image(const Json& img, std::size_t i, const Json* views, const Json* bufferArray,
                          const std::map<std::size_t, std::string>& sampled) {
  if (!img.is_object()) return;  // the material reader reports it when a texture uses it
  std::string ptr = fmt::format("/images/{}", i), file, what;
  Readable r;
  if (img.contains("uri") && img["uri"].is_string()) {
    std::tie(file, r) = resolve(img["uri"].get<std::string>());
    ptr += "/uri";
    what = quoteForDiagnostic(file.empty() ? img["uri"].get<std::string>() : file, 200);
  } else if (auto v = indexIn(img, "bufferView", views); v) {
    ptr += "/bufferView";
    what = fmt::format("in bufferViews[{}]", *v);
    const Json& view = (*views)[*v];
    auto b = view.is_object() ? indexIn(view, "buffer", bufferArray) : std::nullopt;
    if (!b) r = {false, 0, "its bufferView names no buffer of the document"};
    else if (!buffers_[*b].ok) r = {false, 0, fmt::format("buffers[{}] cannot be read", *b)};
    else {
      const std::uintmax_t offset = countOf(view, "byteOffset"), length = countOf(view, "byteLength");
      r = offset <= buffers_[*b].bytes && length <= buffers_[*b].bytes - offset
              ? Readable{true, length, ""}
              : Readable{false, 0, fmt::format("bytes {}..{} are past the end of buffers[{}] ({} bytes)", offset,
                                               offset + length, *b, buffers_[*b].bytes)};
    }
  } else {
    r = {false, 0, "neither a uri nor a bufferView of the document"};
    what = "(no source)";
  }
  if (r.ok) return;
  if (auto s = sampled.find(i); s != sampled.end()) {
    d_.error(ptr, fmt::format("images[{}] {} cannot be read ({}): material {} samples it", i, what, r.why, s->second));
    ok_ = false;
  } else {
    warn(ptr, file, fmt::format("images[{}] {} cannot be read ({}); no material samples it", i, what, r.why));
  }
}

}  // namespace

bool checkGltfResources(const Json& doc, const std::string& baseDir, std::optional<std::size_t> glbBinBytes,
                        Diagnostics& diags) {
  if (!doc.is_object()) return true;
  ResourceCheck check(baseDir, diags);
  // Buffers: geometry, never needed by a material; what each holds, for the images.
  const Json* buffers = arrayOf(doc, "buffers");
  if (buffers)
    for (std::size_t i = 0; i < buffers->size(); ++i) check.buffer((*buffers)[i], i, glbBinBytes);
  // Images: needed when a material samples them.
  const Json* images = arrayOf(doc, "images");
  const Json* views = arrayOf(doc, "bufferViews");
  if (images) {
    const std::map<std::size_t, std::string> sampled = sampledImages(doc);
    for (std::size_t i = 0; i < images->size(); ++i) check.image((*images)[i], i, views, buffers, sampled);
  }
  return check.finish();
}

/// A relative URI as a path (percent-decoded), or nullopt when it is not one.
std::optional<std::string> uriPath(const std::string& uri) {
  if (uri.find("://") != std::string::npos) return std::nullopt;
  std::string out;
  for (std::size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hexDigit(uri[i + 1]) >= 0 && hexDigit(uri[i + 2]) >= 0) {
      out += static_cast<char>(hexDigit(uri[i + 1]) * 16 + hexDigit(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  if (out.find('\0') != std::string::npos) return std::nullopt;
  return out;
}

std::optional<std::string> decodeDataUri(const std::string& uri, std::string* why) {
  const std::size_t comma = uri.find(',');
  if (uri.rfind("data:", 0) != 0 || comma == std::string::npos) {
    *why = "not a data: URI";
    return std::nullopt;
  }
  const Readable r = dataUri(uri);  // validates the alphabet and the length
  if (!r.ok) {
    *why = r.why;
    return std::nullopt;
  }
  const std::string header = uri.substr(5, comma - 5);
  if (header.size() < 7 || header.compare(header.size() - 7, 7, ";base64") != 0) {
    *why = "a data: URI that is not base64";
    return std::nullopt;
  }
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    return c == '+' ? 62 : c == '/' ? 63 : -1;  // '=' padding
  };
  std::string out;
  out.reserve(r.bytes);
  std::uint32_t bits = 0;
  int count = 0;
  for (std::size_t i = comma + 1; i < uri.size(); ++i) {
    const int v = value(uri[i]);
    if (v < 0) break;
    bits = (bits << 6) | static_cast<std::uint32_t>(v);
    if ((count += 6) >= 8) {
      count -= 8;
      out.push_back(static_cast<char>((bits >> count) & 0xFF));
    }
  }
  return out;
}

std::optional<EmbeddedImage> embeddedImage(const Json& doc, int index, const std::string* glbBin, std::string* why) {
  why->clear();
  const Json* images = arrayOf(doc, "images");
  if (!images || index < 0 || index >= static_cast<int>(images->size()) || !(*images)[index].is_object()) return std::nullopt;
  const Json& img = (*images)[index];
  std::string mime = img.contains("mimeType") && img["mimeType"].is_string() ? img["mimeType"].get<std::string>() : "";
  std::optional<std::string> bytes;
  if (img.contains("uri") && img["uri"].is_string()) {
    const std::string& uri = img["uri"].get_ref<const std::string&>();
    if (uri.rfind("data:", 0) != 0) return std::nullopt;  // a file
    if (mime.empty()) mime = uri.substr(5, uri.find_first_of(";,") - 5);
    bytes = decodeDataUri(uri, why);
  } else if (auto v = indexIn(img, "bufferView", arrayOf(doc, "bufferViews")); v) {
    const Json& view = doc["bufferViews"][*v];
    const auto b = indexIn(view, "buffer", arrayOf(doc, "buffers"));
    const std::uintmax_t offset = countOf(view, "byteOffset"), length = countOf(view, "byteLength");
    std::optional<std::string> buffer;
    if (b && doc["buffers"][*b].is_object() && doc["buffers"][*b].contains("uri")) {
      const Json& uri = doc["buffers"][*b]["uri"];
      if (uri.is_string() && uri.get<std::string>().rfind("data:", 0) == 0) buffer = decodeDataUri(uri.get<std::string>(), why);
      else *why = "an image in a buffer file is not read (only a .glb's binary chunk and data: URIs)";
    } else if (b && *b == 0 && glbBin) {
      buffer = *glbBin;
    } else {
      *why = "its bufferView's buffer has no bytes here";
    }
    if (buffer && (offset > buffer->size() || length > buffer->size() - offset)) {
      *why = fmt::format("its bufferView ({} bytes at {}) runs past its buffer's {} bytes", length, offset, buffer->size());
      buffer.reset();
    }
    if (buffer) bytes = buffer->substr(static_cast<std::size_t>(offset), static_cast<std::size_t>(length));
  } else {
    return std::nullopt;
  }
  if (!bytes) {
    if (why->empty()) *why = "its bytes cannot be read";
    return std::nullopt;
  }
  const std::string extension = mime == "image/png" ? "png" : mime == "image/jpeg" ? "jpg" : "img";
  return EmbeddedImage{std::move(*bytes), extension};
}

}  // namespace substratec::import
