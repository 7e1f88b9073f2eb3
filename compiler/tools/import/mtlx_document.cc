#include "import/mtlx_document.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

namespace substratec::import {

namespace {

constexpr int kMaxIncludeDepth = 8;
constexpr std::size_t kMaxDocuments = 64;

bool isInclude(pugi::xml_node n) {
  const std::string name = n.name();
  return name == "xi:include" || (name.size() > 8 && name.substr(name.size() - 8) == ":include");
}

}  // namespace

bool MtlxDocument::load(const std::string& text, const std::string& fileName, const std::string& baseDir,
                        const ReadLimits& limits, Diagnostics& diags) {
  const std::string path = (std::filesystem::path(baseDir) / fileName).string();
  return loadOne(text, fileName, Reading{fileIdOf(path), path, diags.file()}, baseDir, 0, 0, 0, limits, diags);
}

bool MtlxDocument::loadOne(const std::string& text, const std::string& fileName, const Reading& reading,
                           const std::string& dir, int depth, int includeLine, int includeColumn,
                           const ReadLimits& limits, Diagnostics& diags) {
  auto loaded = std::make_unique<Loaded>();
  loaded->fileName = fileName;
  loaded->text = text;
  loaded->includeLine = includeLine;
  loaded->includeColumn = includeColumn;
  const pugi::xml_parse_result r = loaded->doc.load_buffer(loaded->text.data(), loaded->text.size(), pugi::parse_default);
  auto at = [&](std::size_t offset, const std::string& message) {
    int line = includeLine, column = includeColumn;
    if (depth == 0) lineColumnOf(loaded->text, offset, line, column);
    diags.errorAt(line, column, depth == 0 ? message : fmt::format("in included {}: {}", fileName, message));
  };
  if (!r) {
    at(static_cast<std::size_t>(std::max<std::ptrdiff_t>(r.offset, 0)), fmt::format("XML: {}", r.description()));
    return false;
  }
  const pugi::xml_node root = loaded->doc.child("materialx");
  if (!root) {
    at(0, "expected a <materialx> root element");
    return false;
  }
  Loaded* self = loaded.get();
  docs_.push_back(std::move(loaded));
  loading_.push_back(reading);
  bool ok = true;
  for (pugi::xml_node n : root.children()) {
    if (n.type() != pugi::node_element) continue;
    if (isInclude(n)) {
      if (!loadInclude(n, *self, reading, dir, depth, includeLine, includeColumn, limits, diags)) ok = false;
      continue;
    }
    const std::string name = n.attribute("name").as_string();
    top_.push_back(n);
    if (!name.empty() && !byName_.count(name)) byName_[name] = n;
  }
  loading_.pop_back();
  return ok;
}

/// One xi:include of the file being read (`self`, at `reading`): its file read
/// and loaded in turn, unless the href is missing, the include too deep or one
/// too many, a cycle, or the file unreadable (each an error at the include).
bool MtlxDocument::loadInclude(pugi::xml_node n, const Loaded& self, const Reading& reading, const std::string& dir,
                               int depth, int includeLine, int includeColumn, const ReadLimits& limits,
                               Diagnostics& diags) {
  const std::string href = n.attribute("href").as_string();
  int line = includeLine, column = includeColumn;
  if (depth == 0) lineColumnOf(self.text, static_cast<std::size_t>(n.offset_debug()), line, column);
  auto fail = [&](const std::string& m) {
    diags.errorAt(line, column, m);
    return false;
  };
  if (href.empty()) {
    return fail("xi:include without an href");
  }
  if (depth + 1 > kMaxIncludeDepth || docs_.size() >= kMaxDocuments) {
    return fail(fmt::format("xi:include '{}': more than {} levels or {} files of includes", href, kMaxIncludeDepth,
                            kMaxDocuments));
  }
  const std::filesystem::path path = std::filesystem::path(dir) / href;
  Reading next{fileIdOf(path.string()), path.string(),
               (std::filesystem::path(reading.display).parent_path() / href).string()};
  // A cycle: the file is one of those being read (the same file, however
  // its path is spelled; by path only where it has no identity).
  auto same = [&](const Reading& r) {
    return next.id && r.id ? *next.id == *r.id : path.lexically_normal() == std::filesystem::path(r.path).lexically_normal();
  };
  if (auto open = std::find_if(loading_.begin(), loading_.end(), same); open != loading_.end()) {
    std::string chain;
    for (auto it = open; it != loading_.end(); ++it) chain += it->display + " -> ";
    int holderLine = 0, holderColumn = 0;  // in the file that holds this include
    lineColumnOf(self.text, static_cast<std::size_t>(std::max<std::ptrdiff_t>(n.offset_debug(), 0)), holderLine,
                 holderColumn);
    diags.errorIn(reading.display, holderLine, holderColumn,
                  fmt::format("xi:include '{}' closes a cycle of includes ({}{})", href, chain, open->display));
    return false;
  }
  Diagnostics readDiags(href);
  auto included = readSourceFile(path.string(), limits, readDiags);
  if (!included) {
    return fail(fmt::format("xi:include '{}': {}", href,
                            readDiags.all().empty() ? std::string("cannot read it") : readDiags.all().front().message));
  }
  const std::string name = std::filesystem::path(href).filename().string();
  return loadOne(*included, name, next, path.parent_path().string(), depth + 1, line, column, limits, diags);
}

pugi::xml_node MtlxDocument::find(const std::string& name) const {
  auto it = byName_.find(name);
  return it == byName_.end() ? pugi::xml_node() : it->second;
}

const MtlxDocument::Loaded* MtlxDocument::owner(pugi::xml_node n) const {
  const pugi::xml_node root = n.root();
  for (const auto& d : docs_)
    if (d->doc == root) return d.get();
  return nullptr;
}

std::string MtlxDocument::filePrefix(pugi::xml_node n) const {
  std::string prefix;
  for (pugi::xml_node p = n; p; p = p.parent()) {
    if (p.type() != pugi::node_element) continue;
    if (auto a = p.attribute("fileprefix")) prefix = std::string(a.as_string()) + prefix;
  }
  return prefix;
}

void MtlxDocument::lineColumn(pugi::xml_node n, int& line, int& column) const {
  line = column = 0;
  const Loaded* d = owner(n);
  if (!d) return;
  if (d->includeLine > 0) {
    line = d->includeLine;
    column = d->includeColumn;
    return;
  }
  const std::ptrdiff_t off = n.offset_debug();
  if (off >= 0) lineColumnOf(d->text, static_cast<std::size_t>(off), line, column);
}

std::string MtlxDocument::describe(pugi::xml_node n) const {
  std::vector<std::string> parts;
  for (pugi::xml_node p = n; p && p.type() == pugi::node_element && std::string(p.name()) != "materialx";
       p = p.parent())
    parts.push_back(fmt::format("{} '{}'", p.name(), p.attribute("name").as_string()));
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) out += (i ? " in " : "") + parts[i];
  const Loaded* d = owner(n);
  if (d && d->includeLine > 0) {
    int line = 0, column = 0;
    const std::ptrdiff_t off = n.offset_debug();
    if (off >= 0) lineColumnOf(d->text, static_cast<std::size_t>(off), line, column);
    out += fmt::format(" (included {} line {})", d->fileName, line);
  }
  return out;
}

std::optional<std::vector<double>> parseMtlxNumbers(const std::string& s) {
  if (s == "true") return std::vector<double>{1};
  if (s == "false") return std::vector<double>{0};
  std::vector<double> out;
  const char* p = s.c_str();
  while (*p) {
    while (*p == ' ' || *p == '\t' || *p == ',' || *p == '\n' || *p == '\r') ++p;
    if (!*p) break;
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v)) return std::nullopt;
    out.push_back(v);
    p = end;
  }
  if (out.empty()) return std::nullopt;
  return out;
}

int mtlxComponents(const std::string& type) {
  if (type == "float" || type == "integer" || type == "boolean") return 1;
  if (type == "vector2") return 2;
  if (type == "color3" || type == "vector3") return 3;
  if (type == "color4" || type == "vector4") return 4;
  return 0;
}

}  // namespace substratec::import
