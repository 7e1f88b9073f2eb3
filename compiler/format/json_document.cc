#include "format/json_document.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>

namespace substratec {

void lineColumnOf(const std::string& text, std::size_t offset, int& line, int& column) {
  line = 1;
  column = 1;
  if (offset > text.size()) offset = text.size();
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
}

std::optional<std::string> readSourceFile(const std::string& path, const ReadLimits& limits,
                                          Diagnostics& diags) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) {
    diags.errorAt(0, 0, "cannot open file");
    return std::nullopt;
  }
  std::string text;
  // Read at most maxInputBytes + 1 so an oversized file is rejected without
  // being read whole (an 80 MB file costs one chunk, not 80 MB).
  const std::size_t cap = limits.maxInputBytes + 1;
  std::vector<char> buf(1 << 16);
  while (text.size() < cap) {
    std::size_t want = std::min(buf.size(), cap - text.size());
    std::size_t got = std::fread(buf.data(), 1, want, f);
    if (got == 0) break;
    text.append(buf.data(), got);
  }
  bool readError = std::ferror(f) != 0;
  std::fclose(f);
  if (readError) {
    diags.errorAt(0, 0, "cannot read file");
    return std::nullopt;
  }
  if (text.size() > limits.maxInputBytes) {
    diags.errorAt(1, 1, fmt::format("input is larger than the limit of {} bytes (--max-input-size)",
                                    limits.maxInputBytes));
    return std::nullopt;
  }
  return text;
}

namespace {

/// Linear pre-scan: rejects byte-order marks and nesting deeper than the limit
/// before the parser sees the text, so depth can never exhaust any stack.
bool preScan(const std::string& text, const ReadLimits& limits, Diagnostics& diags) {
  if (text.size() >= 3 && static_cast<unsigned char>(text[0]) == 0xEF &&
      static_cast<unsigned char>(text[1]) == 0xBB && static_cast<unsigned char>(text[2]) == 0xBF) {
    diags.errorAt(1, 1, "file starts with a UTF-8 byte-order mark; save it as UTF-8 without BOM");
    return false;
  }
  if (text.size() >= 2 && ((static_cast<unsigned char>(text[0]) == 0xFF &&
                            static_cast<unsigned char>(text[1]) == 0xFE) ||
                           (static_cast<unsigned char>(text[0]) == 0xFE &&
                            static_cast<unsigned char>(text[1]) == 0xFF))) {
    diags.errorAt(1, 1, "file is UTF-16 (byte-order mark found); material files must be UTF-8");
    return false;
  }
  std::size_t depth = 0;
  bool inString = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    char c = text[i];
    if (inString) {
      if (c == '\\') ++i;
      else if (c == '"') inString = false;
      continue;
    }
    if (c == '"') {
      inString = true;
    } else if (c == '[' || c == '{') {
      if (++depth > limits.maxNesting) {
        int line, col;
        lineColumnOf(text, i, line, col);
        diags.errorAt(line, col, fmt::format("nesting is deeper than the limit of {} levels",
                                             limits.maxNesting));
        return false;
      }
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    }
  }
  return true;
}

/// SAX handler building an ordered DOM while enforcing what plain JSON allows
/// but a material file must not contain.
class StrictDomBuilder {
 public:
  StrictDomBuilder(const std::string& text, const ReadLimits& limits, Diagnostics& diags)
      : text_(text), limits_(limits), diags_(diags) {}

  Json result;
  bool failed = false;

  bool null() { return put(Json(nullptr)); }
  bool boolean(bool v) { return put(Json(v)); }
  bool number_integer(Json::number_integer_t v) { return put(Json(v)); }
  bool number_unsigned(Json::number_unsigned_t v) { return put(Json(v)); }
  bool number_float(Json::number_float_t v, const std::string& lexeme) {
    if (!std::isfinite(v)) {
      diags_.error(pointerForNext(), fmt::format("number {} is out of range (it overflows a double)",
                                                 quoteForDiagnostic(lexeme, 32)));
      failed = true;
      return put(Json(0.0));
    }
    return put(Json(v));
  }
  bool string(std::string& v) {
    if (v.size() > limits_.maxStringBytes) {
      diags_.error(pointerForNext(), fmt::format("string of {} bytes is longer than the limit of {}",
                                                 v.size(), limits_.maxStringBytes));
      failed = true;
      return put(Json(std::string()));
    }
    return put(Json(std::move(v)));
  }
  bool binary(Json::binary_t&) { return false; }
  bool start_object(std::size_t) {
    std::string ptr = pointerForNext();
    Json* slot = slotForNext();
    *slot = Json::object();
    stack_.push_back(Frame{slot, {}, std::move(ptr), {}, false});
    return true;
  }
  bool key(std::string& k) {
    Frame& f = stack_.back();
    std::string ptr = f.pointer + "/" + pointerToken(k);
    if (k.size() > limits_.maxStringBytes) {
      diags_.error(f.pointer, fmt::format("key of {} bytes is longer than the limit of {}", k.size(),
                                          limits_.maxStringBytes));
      failed = true;
    }
    f.duplicate = !f.keys.insert(k).second;
    if (f.duplicate) {
      diags_.error(ptr, fmt::format("duplicate key {}", quoteForDiagnostic(k)));
      failed = true;
    }
    f.key = k;
    return true;
  }
  bool end_object() {
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) {
    std::string ptr = pointerForNext();
    Json* slot = slotForNext();
    *slot = Json::array();
    stack_.push_back(Frame{slot, {}, std::move(ptr), {}, false});
    return true;
  }
  bool end_array() {
    stack_.pop_back();
    return true;
  }
  bool parse_error(std::size_t position, const std::string& lastToken,
                   const nlohmann::detail::exception& ex) {
    // nlohmann reports the byte *after* the offending token; point at its start.
    std::size_t offset = position > 0 ? position - 1 : 0;
    if (!lastToken.empty() && offset + 1 >= lastToken.size()) offset = offset + 1 - lastToken.size();
    int line, col;
    lineColumnOf(text_, offset, line, col);
    diags_.errorAt(line, col, describe(ex.what(), lastToken));
    failed = true;
    return false;
  }

 private:
  struct Frame {
    Json* node;
    std::string key;
    std::string pointer;
    std::unordered_set<std::string> keys;  // objects: keys seen (ordered_json lookups are linear)
    bool duplicate = false;                 // the current key repeats an earlier one
  };

  static std::string describe(const std::string& what, const std::string& lastToken) {
    // nlohmann: "[json.exception.parse_error.101] parse error at line 1, column 2:
    // syntax error while parsing value - invalid literal; last read: 'x'"
    std::string msg = what;
    auto p = msg.find("syntax error while parsing");
    if (p != std::string::npos) msg = msg.substr(p);
    else if (auto q = msg.find("] "); q != std::string::npos) msg = msg.substr(q + 2);  // drop "[json.exception...]" 
    auto lr = msg.find("; last read:");
    if (lr != std::string::npos) msg = msg.substr(0, lr);
    if (lastToken.empty()) return "JSON " + msg;
    return fmt::format("JSON {} (near {})", msg, quoteForDiagnostic(lastToken, 24));
  }

  std::string pointerForNext() const {
    if (stack_.empty()) return "";
    const Frame& f = stack_.back();
    if (f.node->is_array()) return f.pointer + "/" + std::to_string(f.node->size());
    return f.pointer + "/" + pointerToken(f.key);
  }

  Json* slotForNext() {
    if (stack_.empty()) return &result;
    Frame& f = stack_.back();
    if (f.node->is_array()) {
      f.node->push_back(Json());
      return &f.node->back();
    }
    // Append directly to the ordered map's vector: its operator[] searches
    // linearly, which would make an object of n keys cost O(n^2). A duplicate
    // (already reported) goes to a scratch slot so the first value is kept.
    if (f.duplicate) {
      scratch_ = Json();
      return &scratch_;
    }
    auto& items = static_cast<std::vector<std::pair<const std::string, Json>>&>(f.node->get_ref<Json::object_t&>());
    items.emplace_back(f.key, Json());
    return &items.back().second;
  }
  bool put(Json v) {
    Json* slot = slotForNext();
    *slot = std::move(v);
    return true;
  }

  const std::string& text_;
  const ReadLimits& limits_;
  Diagnostics& diags_;
  std::vector<Frame> stack_;
  Json scratch_;
};

}  // namespace

std::optional<Json> parseJsonDocument(const std::string& text, const ReadLimits& limits,
                                      Diagnostics& diags) {
  if (!preScan(text, limits, diags)) return std::nullopt;
  bool onlySpace = true;
  for (char c : text) {
    if (c != ' ' && c != '\n' && c != '\r' && c != '\t') {
      onlySpace = false;
      break;
    }
  }
  if (onlySpace) {
    int line, col;
    lineColumnOf(text, text.size(), line, col);
    diags.errorAt(line, col, "file is empty; expected a JSON object");
    return std::nullopt;
  }
  StrictDomBuilder builder(text, limits, diags);
  bool ok = false;
  try {
    ok = Json::sax_parse(text, &builder, nlohmann::detail::input_format_t::json, true, false);
  } catch (const std::exception& e) {
    diags.errorAt(1, 1, fmt::format("JSON parse failed: {}", e.what()));
    return std::nullopt;
  }
  if (!ok || builder.failed) return std::nullopt;
  return std::move(builder.result);
}

}  // namespace substratec
