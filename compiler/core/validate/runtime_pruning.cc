#include "validate/runtime_pruning.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <set>
#include <string_view>
#include <unordered_map>
#include <unordered_set>

namespace substratec {
namespace {

constexpr std::size_t kMaxIncludeDepth = 16;

// ---------------------------------------------------------------------------
// Tokens of the shading languages' common C-like surface.

enum class Tok { Ident, Number, Punct, Directive };

struct Token {
  Tok kind;
  std::string_view text;
  std::size_t begin = 0, end = 0;  // offsets in the text
};

bool identStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool identChar(char c) { return identStart(c) || (c >= '0' && c <= '9'); }
bool digit(char c) { return c >= '0' && c <= '9'; }

/// End of a preprocessor line starting at `i` (its continuations and comments included).
std::size_t directiveEnd(std::string_view s, std::size_t i) {
  while (i < s.size()) {
    if (s[i] == '\\' && i + 1 < s.size() && s[i + 1] == '\n') {
      i += 2;
    } else if (s[i] == '\n') {
      break;
    } else if (s.compare(i, 2, "/*") == 0) {
      const std::size_t e = s.find("*/", i + 2);
      i = e == std::string_view::npos ? s.size() : e + 2;
    } else if (s.compare(i, 2, "//") == 0) {
      while (i < s.size() && s[i] != '\n') ++i;
    } else {
      ++i;
    }
  }
  return i;
}

/// Comments dropped; each preprocessor line (continuations included) is one Directive token
/// unless `inDirective` (a directive's own text, tokenized after its '#').
std::vector<Token> tokenize(std::string_view s, bool inDirective = false) {
  std::vector<Token> out;
  bool lineStart = !inDirective;
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    const std::size_t b = i;
    if (c == '\n') {
      lineStart = !inDirective;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == '\\') {
      ++i;
    } else if (s.compare(i, 2, "//") == 0) {
      while (i < s.size() && s[i] != '\n') ++i;
    } else if (s.compare(i, 2, "/*") == 0) {
      const std::size_t e = s.find("*/", i + 2);
      i = e == std::string_view::npos ? s.size() : e + 2;
    } else if (c == '#' && lineStart) {
      i = directiveEnd(s, i);
      out.push_back({Tok::Directive, s.substr(b, i - b), b, i});
    } else if (identStart(c)) {
      while (i < s.size() && identChar(s[i])) ++i;
      out.push_back({Tok::Ident, s.substr(b, i - b), b, i});
      lineStart = false;
    } else if (digit(c) || (c == '.' && i + 1 < s.size() && digit(s[i + 1]))) {
      while (i < s.size() && (identChar(s[i]) || s[i] == '.' ||
                              ((s[i] == '+' || s[i] == '-') && (s[i - 1] == 'e' || s[i - 1] == 'E'))))
        ++i;
      out.push_back({Tok::Number, s.substr(b, i - b), b, i});
      lineStart = false;
    } else if (c == '"') {
      ++i;
      while (i < s.size() && s[i] != '"' && s[i] != '\n') ++i;
      if (i < s.size() && s[i] == '"') ++i;
      out.push_back({Tok::Punct, s.substr(b, i - b), b, i});
      lineStart = false;
    } else {
      ++i;
      out.push_back({Tok::Punct, s.substr(b, 1), b, i});
      lineStart = false;
    }
  }
  return out;
}

bool is(const Token& t, char c) { return t.kind == Tok::Punct && t.text.size() == 1 && t.text[0] == c; }

/// A preprocessor line: its keyword ("define", "include", ...) and the tokens after it.
struct Directive {
  std::string_view keyword;
  std::vector<Token> rest;
};

Directive parseDirective(const Token& d) {
  std::vector<Token> tokens = tokenize(d.text.substr(1), /*inDirective=*/true);
  Directive out;
  if (!tokens.empty() && tokens.front().kind == Tok::Ident) {
    out.keyword = tokens.front().text;
    out.rest.assign(tokens.begin() + 1, tokens.end());
  } else {
    out.rest = std::move(tokens);
  }
  return out;
}

/// The file an #include names ("x" or <x>), or empty.
std::string includeName(const Directive& d) {
  if (d.keyword != "include" || d.rest.empty()) return {};
  const std::string_view first = d.rest.front().text;
  if (first.size() >= 2 && first.front() == '"') return std::string(first.substr(1, first.size() - 2));
  if (!is(d.rest.front(), '<')) return {};
  std::string name;
  for (std::size_t i = 1; i < d.rest.size() && !is(d.rest[i], '>'); ++i) name += d.rest[i].text;
  return name;
}

/// Token pasting anywhere (two adjacent '#' in a directive) could spell a name no text does.
bool pastes(const Directive& d) {
  for (std::size_t i = 1; i < d.rest.size(); ++i)
    if (is(d.rest[i - 1], '#') && is(d.rest[i], '#') && d.rest[i - 1].end == d.rest[i].begin) return true;
  return false;
}

// ---------------------------------------------------------------------------
// Top-level items: a declaration ending in ';', or a function definition
// ending at its body's '}'.

struct Item {
  std::size_t first = 0, last = 0;  // token indices, inclusive
  bool function = false;            // `... ) {`  or HLSL `... ) : SEMANTIC {`
  bool hasDirective = false;        // a preprocessor line between its first and last token
  std::string_view name;            // function: the identifier before its first top-level '('
  bool prunable = false;            // a plain function definition (see the header)
};

/// Previous non-directive token index before `k` within [first, k), or npos.
std::size_t previousCode(const std::vector<Token>& t, std::size_t first, std::size_t k) {
  while (k > first) {
    --k;
    if (t[k].kind != Tok::Directive) return k;
  }
  return std::string_view::npos;
}

void nameFunction(const std::vector<Token>& t, Item& item) {
  int depth = 0;
  for (std::size_t k = item.first; k <= item.last; ++k) {
    if (t[k].kind == Tok::Directive) continue;
    if (is(t[k], '(') && depth == 0) {
      const std::size_t n = previousCode(t, item.first, k);
      if (n == std::string_view::npos || t[n].kind != Tok::Ident) return;
      item.name = t[n].text;
      const std::size_t type = previousCode(t, item.first, n);
      item.prunable = item.function && !item.hasDirective && type != std::string_view::npos &&
                      t[type].kind == Tok::Ident && item.name != "main";
      return;
    }
    if (is(t[k], '(') || is(t[k], '[') || is(t[k], '{')) ++depth;
    if (is(t[k], ')') || is(t[k], ']') || is(t[k], '}')) --depth;
  }
}

/// Whether the code before the '{' at `k` ends like a function signature.
bool signatureBefore(const std::vector<Token>& t, std::size_t first, std::size_t k) {
  const std::size_t p = previousCode(t, first, k);
  if (p == std::string_view::npos) return false;
  if (is(t[p], ')')) return true;
  if (t[p].kind != Tok::Ident) return false;
  const std::size_t colon = previousCode(t, first, p);
  if (colon == std::string_view::npos || !is(t[colon], ':')) return false;
  const std::size_t paren = previousCode(t, first, colon);
  return paren != std::string_view::npos && is(t[paren], ')');
}

std::vector<Item> topLevelItems(const std::vector<Token>& t) {
  std::vector<Item> items;
  bool open = false;
  Item item;
  int paren = 0, brace = 0;
  auto close = [&](std::size_t k) {
    item.last = k;
    nameFunction(t, item);
    items.push_back(item);
    open = false;
  };
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k].kind == Tok::Directive) {
      if (open) item.hasDirective = true;
      continue;
    }
    if (!open) {
      item = Item{};
      item.first = k;
      open = true;
      paren = brace = 0;
    }
    if (is(t[k], '(') || is(t[k], '[')) ++paren;
    if (is(t[k], ')') || is(t[k], ']')) --paren;
    if (is(t[k], '{')) {
      if (brace == 0 && paren == 0 && !item.function) item.function = signatureBefore(t, item.first, k);
      ++brace;
    }
    if (is(t[k], '}') && --brace <= 0 && item.function) close(k);
    else if (is(t[k], ';') && brace <= 0 && paren <= 0) close(k);
  }
  if (open) {
    item.function = false;  // unterminated: never pruned, never dropped
    close(t.size() - 1);
    items.back().hasDirective = true;
  }
  return items;
}

// ---------------------------------------------------------------------------
// The files an entry compiles.

struct File {
  std::string name;
  std::string_view text;
  bool runtime = false;
  std::vector<Token> tokens;
  std::vector<Item> items;
};

struct Analysis {
  bool usable = true;
  std::vector<File> files;  // files[0] is the entry
  std::unordered_map<std::string, std::size_t> byName;
  std::unordered_set<std::string_view> runtimeIdents;  // R: every identifier a runtime file spells
};

/// Visits the entry and, through #include lines (enabled or not), every file it may include.
void collectFiles(const ShaderSource& entry, const std::vector<RuntimeFile>& runtime, Analysis& a) {
  std::unordered_map<std::string_view, std::string_view> runtimeText;
  for (const RuntimeFile& f : runtime) runtimeText.emplace(f.name, f.text);
  a.files.push_back({entry.name, entry.text, false, tokenize(entry.text), {}});
  std::vector<std::pair<std::size_t, std::size_t>> stack{{0, 0}};  // file, depth
  while (!stack.empty() && a.usable) {
    const auto [index, depth] = stack.back();
    stack.pop_back();
    std::vector<std::string> includes;
    for (const Token& t : a.files[index].tokens) {
      if (t.kind != Tok::Directive) continue;
      const Directive d = parseDirective(t);
      if (pastes(d)) a.usable = false;
      if (std::string name = includeName(d); !name.empty()) includes.push_back(std::move(name));
      else if (d.keyword == "include") a.usable = false;
    }
    for (const std::string& name : includes) {
      if (a.byName.count(name)) continue;
      const auto memory = entry.memoryFiles.find(name);
      if (memory == entry.memoryFiles.end() || depth + 1 > kMaxIncludeDepth) {
        a.usable = false;
        return;
      }
      const bool isRuntime = runtimeText.count(name) && runtimeText.at(name) == memory->second;
      a.byName[name] = a.files.size();
      a.files.push_back({name, memory->second, isRuntime, tokenize(memory->second), {}});
      stack.push_back({a.files.size() - 1, depth + 1});
    }
  }
  for (File& f : a.files) {
    f.items = topLevelItems(f.tokens);
    if (!f.runtime) continue;
    for (const Token& t : f.tokens) {
      if (t.kind == Tok::Ident) a.runtimeIdents.insert(t.text);
      if (t.kind != Tok::Directive) continue;
      for (const Token& d : tokenize(t.text.substr(1), true))
        if (d.kind == Tok::Ident) a.runtimeIdents.insert(d.text);
    }
  }
}

// ---------------------------------------------------------------------------
// Reachability.

void addIdents(const std::vector<Token>& tokens, std::size_t first, std::size_t last,
               std::unordered_set<std::string_view>& into) {
  for (std::size_t k = first; k <= last && k < tokens.size(); ++k) {
    if (tokens[k].kind == Tok::Ident) into.insert(tokens[k].text);
    if (tokens[k].kind == Tok::Directive)
      for (const Token& d : tokenize(tokens[k].text.substr(1), true))
        if (d.kind == Tok::Ident) into.insert(d.text);
  }
}

struct Definition {
  std::size_t file, item;
};

/// Marks, per runtime file, the prunable items nothing reaches; returns how many there are in all.
std::size_t markUnreached(const ShaderSource& entry, Analysis& a, std::vector<std::vector<bool>>& removed,
                          std::size_t& definitions) {
  std::unordered_set<std::string_view> reached;
  std::unordered_map<std::string_view, std::vector<Definition>> byName;
  std::vector<std::string> defineTexts;
  for (const auto& [name, value] : entry.defines) defineTexts.push_back(name + " " + value);
  for (const std::string& d : defineTexts) addIdents(tokenize(d, true), 0, SIZE_MAX, reached);
  removed.assign(a.files.size(), {});
  definitions = 0;
  for (std::size_t f = 0; f < a.files.size(); ++f) {
    const File& file = a.files[f];
    removed[f].assign(file.items.size(), false);
    if (!file.runtime) {
      if (!file.tokens.empty()) addIdents(file.tokens, 0, file.tokens.size() - 1, reached);
      continue;
    }
    std::vector<bool> inItem(file.tokens.size(), false);
    for (std::size_t i = 0; i < file.items.size(); ++i) {
      const Item& item = file.items[i];
      for (std::size_t k = item.first; k <= item.last; ++k) inItem[k] = true;
      if (item.prunable) {
        byName[item.name].push_back({f, i});
        removed[f][i] = true;
        ++definitions;
      } else {
        addIdents(file.tokens, item.first, item.last, reached);
      }
    }
    for (std::size_t k = 0; k < file.tokens.size(); ++k)
      if (!inItem[k]) addIdents(file.tokens, k, k, reached);
  }
  std::vector<std::string_view> work(reached.begin(), reached.end());
  while (!work.empty()) {
    const std::string_view name = work.back();
    work.pop_back();
    auto it = byName.find(name);
    if (it == byName.end()) continue;
    for (const Definition& d : it->second) {
      removed[d.file][d.item] = false;
      std::unordered_set<std::string_view> body;
      const Item& item = a.files[d.file].items[d.item];
      addIdents(a.files[d.file].tokens, item.first, item.last, body);
      for (std::string_view n : body)
        if (reached.insert(n).second) work.push_back(n);
    }
    byName.erase(it);
  }
  std::size_t count = 0;
  for (const auto& r : removed) count += static_cast<std::size_t>(std::count(r.begin(), r.end(), true));
  return count;
}

/// `text` with the removed items' characters blanked out, newlines kept.
std::string blankOut(const File& file, const std::vector<bool>& removed) {
  std::string out(file.text);
  for (std::size_t i = 0; i < file.items.size(); ++i) {
    if (!removed[i]) continue;
    for (std::size_t c = file.tokens[file.items[i].first].begin; c < file.tokens[file.items[i].last].end; ++c)
      if (out[c] != '\n') out[c] = ' ';
  }
  return out;
}

// ---------------------------------------------------------------------------
// The runtime configuration.

/// The names a non-function declaration declares, or nothing when it cannot
/// tell (a block or struct without an instance name, whose members may be
/// global): `layout(...)` and `[[...]]` prefixes skipped, then the identifier
/// before each top-level '(', '[', '=', ':', ',' or ';' that starts a declarator.
std::vector<std::string_view> declaredNames(const std::vector<Token>& t, const Item& item) {
  std::vector<std::string_view> names;
  std::size_t k = item.first;
  auto skipGroup = [&](char open, char close) {
    int depth = 0;
    for (; k <= item.last; ++k) {
      if (is(t[k], open)) ++depth;
      if (is(t[k], close) && --depth == 0) break;
    }
    ++k;
  };
  while (k <= item.last) {
    if (t[k].text == "layout" && k + 1 <= item.last && is(t[k + 1], '(')) {
      ++k;
      skipGroup('(', ')');
    } else if (is(t[k], '[') && k + 1 <= item.last && is(t[k + 1], '[')) {
      skipGroup('[', ']');
    } else {
      break;
    }
  }
  bool inDeclarator = true;  // false after '=', ':' or '(' until the next top-level ','
  int depth = 0;
  bool block = false, instance = false;
  for (; k <= item.last; ++k) {
    if (t[k].kind == Tok::Directive) continue;
    const bool opens = is(t[k], '(') || is(t[k], '[') || is(t[k], '{');
    if (depth == 0 && opens && is(t[k], '{')) block = true;
    if (depth == 0 && (opens || is(t[k], '=') || is(t[k], ':') || is(t[k], ',') || is(t[k], ';'))) {
      const std::size_t p = previousCode(t, item.first, k);
      if (inDeclarator && p != std::string_view::npos && t[p].kind == Tok::Ident) {
        names.push_back(t[p].text);
        if (block && !is(t[k], '{')) instance = true;
      }
      inDeclarator = is(t[k], ',') || is(t[k], '{');
    }
    if (opens) ++depth;
    if (is(t[k], ')') || is(t[k], ']') || is(t[k], '}')) --depth;
    if (depth == 0 && is(t[k], '}')) inDeclarator = true;
  }
  if (block && !instance) names.clear();
  return names;
}

struct SkeletonLine {
  std::vector<std::string_view> tokens;
  std::string_view defines;  // a #define or #undef of a name the runtime never spells: its name
};

class Skeleton {
 public:
  explicit Skeleton(const Analysis& a) : a_(a) {}

  /// Lines of `file`'s text; the entry's only up to its last #include: runtime
  /// text comes only through includes, and what follows it cannot change how
  /// runtime text before it compiles (declare before use; macros apply after
  /// their #define).
  bool add(std::size_t fileIndex, std::size_t depth) {
    if (depth > kMaxIncludeDepth) return false;
    const File& file = a_.files[fileIndex];
    std::size_t limit = file.tokens.size();
    if (fileIndex == 0) {
      limit = 0;
      for (std::size_t k = 0; k < file.tokens.size(); ++k)
        if (file.tokens[k].kind == Tok::Directive && !includeName(parseDirective(file.tokens[k])).empty()) limit = k + 1;
    }
    std::size_t item = 0;
    for (std::size_t k = 0; k < limit; ++k) {
      while (item < file.items.size() && file.items[item].last < k) ++item;
      const bool inside = item < file.items.size() && file.items[item].first <= k;
      if (inside) {
        const Item& it = file.items[item];
        if (k == it.first && !keepItem(file, it)) k = it.last;
        else if (!addToken(file.tokens[k], depth)) return false;
        continue;
      }
      if (!addToken(file.tokens[k], depth)) return false;
    }
    return true;
  }

  /// Drops the #defines of non-runtime names nothing left refers to, renames
  /// the rest of those names by first occurrence, and prints the lines.
  std::string text() {
    std::vector<bool> dropped(lines_.size(), false);
    for (bool changed = true; changed;) {
      changed = false;
      std::unordered_set<std::string_view> used;
      for (std::size_t i = 0; i < lines_.size(); ++i) {
        if (dropped[i]) continue;
        for (std::size_t k = 0; k < lines_[i].tokens.size(); ++k)
          if (lines_[i].defines.empty() || k != 2) used.insert(lines_[i].tokens[k]);
      }
      for (std::size_t i = 0; i < lines_.size(); ++i) {
        if (!dropped[i] && !lines_[i].defines.empty() && !used.count(lines_[i].defines)) {
          dropped[i] = true;
          changed = true;
        }
      }
    }
    std::unordered_map<std::string_view, std::size_t> renamed;
    std::string out;
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      if (dropped[i]) continue;
      for (std::string_view t : lines_[i].tokens) {
        if (macros_.count(t)) {
          auto [it, fresh] = renamed.emplace(t, renamed.size());
          out += fmt::format("${} ", it->second);
        } else {
          out.append(t);
          out += ' ';
        }
      }
      out += '\n';
    }
    return out;
  }

 private:
  /// Whether a top-level item of a non-runtime file can matter to runtime code:
  /// it does unless it only declares names the runtime never spells.
  bool keepItem(const File& file, const Item& item) const {
    if (item.hasDirective) return true;
    if (item.function) return item.name.empty() || a_.runtimeIdents.count(item.name);
    const std::vector<std::string_view> names = declaredNames(file.tokens, item);
    if (names.empty()) return true;
    return std::any_of(names.begin(), names.end(), [&](std::string_view n) { return a_.runtimeIdents.count(n); });
  }

  bool addToken(const Token& t, std::size_t depth) {
    if (t.kind != Tok::Directive) {
      if (lines_.empty() || !lines_.back().defines.empty() || lineIsDirective_) newLine(false);
      lines_.back().tokens.push_back(t.text);
      return true;
    }
    const Directive d = parseDirective(t);
    if (const std::string name = includeName(d); !name.empty()) {
      const std::size_t index = a_.byName.at(name);
      if (!a_.files[index].runtime) return add(index, depth + 1);
    }
    newLine(true);
    SkeletonLine& line = lines_.back();
    line.tokens.push_back("#");
    line.tokens.push_back(d.keyword);
    for (const Token& r : d.rest) line.tokens.push_back(r.text);
    if ((d.keyword == "define" || d.keyword == "undef") && !d.rest.empty() && d.rest.front().kind == Tok::Ident &&
        !a_.runtimeIdents.count(d.rest.front().text)) {
      line.defines = d.rest.front().text;
      macros_.insert(line.defines);
    }
    return true;
  }

  void newLine(bool directive) {
    lines_.emplace_back();
    lineIsDirective_ = directive;
  }

  const Analysis& a_;
  std::vector<SkeletonLine> lines_;
  bool lineIsDirective_ = false;
  std::unordered_set<std::string_view> macros_;
};

// Counts of compileAndValidateShared's outcomes, for benchmarks and tests.
std::atomic<std::size_t> g_whole{0}, g_pruned{0}, g_retried{0};

}  // namespace

RuntimePruning pruneRuntime(const ShaderSource& entry, const std::vector<RuntimeFile>& runtime) {
  RuntimePruning result;
  Analysis a;
  collectFiles(entry, runtime, a);
  if (!a.usable) return result;

  Skeleton skeleton(a);
  if (!skeleton.add(0, 0)) return result;
  result.configuration = fmt::format("{} stage {} half {} entry {}\n", entry.language == ShaderLanguage::Glsl ? "glsl" : "hlsl",
                                     static_cast<int>(entry.stage), entry.hlsl16BitTypes, entry.entryPoint);
  for (const auto& [name, value] : entry.defines) result.configuration += fmt::format("#define {} {}\n", name, value);
  result.configuration += skeleton.text();

  std::vector<std::vector<bool>> removed;
  result.removed = markUnreached(entry, a, removed, result.definitions);
  for (std::size_t f = 0; f < a.files.size(); ++f) {
    if (a.files[f].runtime && std::count(removed[f].begin(), removed[f].end(), true))
      result.prunedFiles.emplace(a.files[f].name, blankOut(a.files[f], removed[f]));
  }
  result.usable = true;
  return result;
}

ShaderSource withPrunedRuntime(const ShaderSource& entry, const RuntimePruning& pruning) {
  ShaderSource pruned = entry;
  for (const auto& [name, text] : pruning.prunedFiles) pruned.memoryFiles[name] = text;
  return pruned;
}

ShaderValidation compileAndValidateShared(const ShaderSource& entry, const std::vector<RuntimeFile>& runtime,
                                          const ValidateOptions& options) {
  // Configurations whose whole runtime some entry of this process compiled and validated.
  static std::mutex mutex;
  static std::set<std::string> compiledWhole;

  const RuntimePruning pruning = pruneRuntime(entry, runtime);
  bool known = false;
  if (pruning.usable && pruning.removed > 0) {
    std::lock_guard<std::mutex> lock(mutex);
    known = compiledWhole.count(pruning.configuration) > 0;
  }
  if (known) {
    ShaderValidation v = compileAndValidate(withPrunedRuntime(entry, pruning), options);
    if (v.ok) {
      ++g_pruned;
      return v;
    }
    ++g_retried;  // compiled again whole: the diagnostics are the whole text's
  }
  ShaderValidation v = compileAndValidate(entry, options);
  ++g_whole;
  if (v.ok && pruning.usable && pruning.removed > 0) {
    std::lock_guard<std::mutex> lock(mutex);
    compiledWhole.insert(pruning.configuration);
  }
  return v;
}

SharedCompileCounts sharedCompileCounts() { return {g_whole.load(), g_pruned.load(), g_retried.load()}; }

}  // namespace substratec
