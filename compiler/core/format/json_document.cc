#include "format/json_document.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <memory>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "output/file_identity.h"

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

std::string kindOfJson(const Json& j) {
  switch (j.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return j.get<bool>() ? "true" : "false";
    case Json::value_t::string: return quoteForDiagnostic(j.get<std::string>());
    case Json::value_t::array: return fmt::format("an array of {}", j.size());
    case Json::value_t::object: return "an object";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return fmt::format("{:g}", j.get<double>());
    default: return "a value";
  }
}

namespace {

std::string inputSizeError(std::size_t limit) {
  return fmt::format("input is larger than the limit of {} bytes (the input-size limit; --max-input-size)", limit);
}

}  // namespace

std::optional<std::string> readSourceFile(const std::string& path, const ReadLimits& limits,
                                          Diagnostics& diags) {
  // O_NONBLOCK only for the open: a FIFO without a writer must not hang it.
  int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    diags.errorAt(0, 0, fmt::format("cannot open file: {}", std::strerror(errno)));
    return std::nullopt;
  }
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    diags.errorAt(0, 0, fmt::format("cannot read file: {}", std::strerror(errno)));
    return std::nullopt;
  }
  if (S_ISDIR(st.st_mode)) {
    diags.errorAt(0, 0, "cannot read file: it is a directory");
    return std::nullopt;
  }
  noteFileRead(path, static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino));
  // A regular file is judged by its size before anything is read: an 80 MB
  // file costs one fstat, not 16 MiB of reading.
  if (S_ISREG(st.st_mode) && static_cast<std::uintmax_t>(st.st_size) > limits.maxInputBytes) {
    diags.errorAt(1, 1, fmt::format("input of {} bytes is larger than the limit of {} bytes (the input-size limit; "
                                    "--max-input-size)",
                                    static_cast<std::uintmax_t>(st.st_size), limits.maxInputBytes));
    return std::nullopt;
  }
  int flags = ::fcntl(fd, F_GETFL);
  if (flags >= 0) ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK);
  // Read at most maxInputBytes + 1 (a file may grow after the fstat; pipes and
  // devices have no size), so an oversized input is never read whole.
  std::string text;
  if (S_ISREG(st.st_mode)) text.reserve(static_cast<std::size_t>(st.st_size));
  const std::size_t cap = limits.maxInputBytes + 1;
  std::vector<char> buf(1 << 16);
  while (text.size() < cap) {
    const std::size_t want = std::min(buf.size(), cap - text.size());
    const ssize_t got = ::read(fd, buf.data(), want);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) {
      diags.errorAt(0, 0, fmt::format("cannot read file: {}", std::strerror(errno)));
      return std::nullopt;
    }
    if (got == 0) break;
    text.append(buf.data(), static_cast<std::size_t>(got));
  }
  if (text.size() > limits.maxInputBytes) {
    diags.errorAt(1, 1, inputSizeError(limits.maxInputBytes));
    return std::nullopt;
  }
  return text;
}

namespace {

/// A byte JSON never has outside a string: a control byte other than the
/// whitespace ones, DEL, or any byte of a multi-byte UTF-8 sequence.
bool binaryByte(unsigned char c) { return c >= 0x7F || (c < 0x20 && c != '\t' && c != '\n' && c != '\r'); }

/// What a file that is not JSON text seems to be, from its first bytes.
std::string notJsonReason(const std::string& text, std::size_t offset) {
  auto startsWith = [&](std::string_view magic) { return text.compare(0, magic.size(), magic) == 0; };
  if (startsWith("\x89PNG")) return "not JSON (a PNG image)";
  if (startsWith("glTF")) return "not JSON (a binary glTF container; give it the .glb extension)";
  if (startsWith("\x1f\x8b")) return "not JSON (gzip-compressed data)";
  if (startsWith("PK\x03\x04")) return "not JSON (a zip archive)";
  if (startsWith("\x7f" "ELF")) return "not JSON (an executable)";
  if (text.size() >= 2 && text[0] != 0 && text[1] == 0)
    return "not JSON (UTF-16 without a byte-order mark?); material files must be UTF-8";
  const auto c = static_cast<unsigned char>(text[offset]);
  if (c == 0) return "not JSON (a NUL byte outside a string; is this a binary file?)";
  if (c < 0x80) return fmt::format("not JSON (control byte 0x{:02X} outside a string; is this a binary file?)", c);
  return fmt::format("not JSON (byte 0x{:02X} outside a string; only strings hold non-ASCII text)", c);
}

/// Linear pre-scan: rejects byte-order marks, bytes no JSON text has outside
/// a string (binary files: "not JSON", at the first such byte, rather than
/// whatever the parser or the nesting limit would make of them) and nesting
/// deeper than the limit before the parser sees the text, so depth can never
/// exhaust any stack.
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
    } else if (binaryByte(static_cast<unsigned char>(c))) {
      int line, col;
      lineColumnOf(text, i, line, col);
      diags.errorAt(line, col, notJsonReason(text, i));
      return false;
    } else if (c == '[' || c == '{') {
      if (++depth > limits.maxNesting) {
        int line, col;
        lineColumnOf(text, i, line, col);
        diags.errorAt(line, col, fmt::format("nesting is deeper than the limit of {} levels (the nesting-depth limit)",
                                             limits.maxNesting));
        return false;
      }
    } else if (c == ']' || c == '}') {
      if (depth > 0) --depth;
    }
  }
  return true;
}

// Objects with up to this many keys find a key by scanning their members
// (the builder's duplicate check and the locator's lookup alike); larger ones
// keep a hash index from key to member ordinal, so n keys cost O(n).
constexpr std::size_t kLinearKeys = 16;
using KeyIndex = std::unordered_map<std::string, std::uint32_t>;

/// Where every value of a parsed document starts, as a tree parallel to the
/// DOM: per value 16 bytes, per member or element 4 more, plus each member's
/// key. A JSON pointer is located by walking its tokens down the tree; the
/// DOM is not needed (the locator outlives it).
class JsonLocations final : public SourceLocator {
 public:
  bool locate(std::string_view pointer, int& line, int& column) const override {
    if (nodes_.empty()) return false;
    std::uint32_t at = 0;
    std::string token;
    while (!pointer.empty() && pointer[0] == '/') {
      const std::size_t end = pointer.find('/', 1);
      unescapeToken(pointer.substr(1, end == std::string_view::npos ? std::string_view::npos : end - 1), token);
      pointer = end == std::string_view::npos ? std::string_view() : pointer.substr(end);
      const std::optional<std::uint32_t> child = childOf(at, token);
      if (!child) break;  // a missing member or element: its container
      at = *child;
    }
    lineColumn(nodes_[at].offset, line, column);
    return true;
  }

  /// 1-based line and byte column of an offset (binary search of the line starts).
  void lineColumn(std::size_t offset, int& line, int& column) const {
    const auto next = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), offset);
    line = static_cast<int>(next - lineStarts_.begin());
    column = static_cast<int>(offset - *(next - 1)) + 1;
  }

 private:
  friend class LocationRecorder;
  static constexpr std::uint32_t kNoKey = UINT32_MAX;
  struct Node {
    std::uint32_t offset = 0;         // the value's first byte
    std::uint32_t key = kNoKey;       // members: index into keyStarts_
    std::uint32_t firstChild = 0;     // containers: index into children_
    std::uint32_t childCount : 31 = 0;
    std::uint32_t isArray : 1 = 0;
  };

  /// RFC 6901: "~1" is '/', "~0" is '~'.
  static void unescapeToken(std::string_view raw, std::string& out) {
    out.clear();
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] == '~' && i + 1 < raw.size() && (raw[i + 1] == '0' || raw[i + 1] == '1')) {
        out += raw[++i] == '1' ? '/' : '~';
      } else {
        out += raw[i];
      }
    }
  }

  std::string_view keyOf(const Node& n) const {
    if (n.key == kNoKey) return {};
    return std::string_view(keys_).substr(keyStarts_[n.key], keyStarts_[n.key + 1] - keyStarts_[n.key]);
  }

  /// The node of container `at`'s member or element named by `token`.
  std::optional<std::uint32_t> childOf(std::uint32_t at, const std::string& token) const {
    const Node& n = nodes_[at];
    std::optional<std::uint32_t> ordinal;
    if (n.isArray) {
      // An index: decimal digits, no leading zero (RFC 6901).
      if (token.empty() || token.size() > 9 || (token[0] == '0' && token.size() > 1)) return std::nullopt;
      std::uint32_t i = 0;
      for (char c : token) {
        if (c < '0' || c > '9') return std::nullopt;
        i = i * 10 + static_cast<std::uint32_t>(c - '0');
      }
      ordinal = i;
    } else if (auto big = largeObjects_.find(at); big != largeObjects_.end()) {
      if (auto it = big->second.find(token); it != big->second.end()) ordinal = it->second;
    } else {
      for (std::uint32_t i = 0; i < n.childCount && !ordinal; ++i)
        if (keyOf(nodes_[children_[n.firstChild + i]]) == token) ordinal = i;
    }
    if (!ordinal || *ordinal >= n.childCount) return std::nullopt;
    return children_[n.firstChild + *ordinal];
  }

  std::vector<Node> nodes_;                   // [0] is the document
  std::vector<std::uint32_t> children_;       // each container's children, contiguous
  std::string keys_;                          // every member's key, concatenated
  std::vector<std::uint32_t> keyStarts_;      // where key i starts in keys_ (and a final end)
  std::vector<std::uint32_t> lineStarts_{0};  // the offset of each line's first byte
  std::unordered_map<std::uint32_t, KeyIndex> largeObjects_;  // objects of over kLinearKeys members
};

/// Records where each value starts while the SAX parser reads. Every callback
/// is for one token; the recorder finds it by skipping whitespace, ',' and
/// ':' from the end of the previous one and steps over it (a second look at
/// the bytes, without building anything). A JSON string cannot hold a raw
/// newline, so every line break is in the whitespace skipped, and the line
/// table is built by the same skip. Cost: linear in the text, no pointer
/// strings (deep nesting costs nothing more per value).
class LocationRecorder {
 public:
  explicit LocationRecorder(const std::string& text)
      : text_(text), on_(text.size() < (std::size_t{1} << 31)), out_(std::make_shared<JsonLocations>()) {}

  bool enabled() const { return on_; }

  /// A scalar value: returns where it starts.
  std::size_t value() {
    if (!on_) return 0;
    return addNode(nextToken());
  }
  /// '{' or '[': returns where it starts.
  std::size_t beginContainer(bool isArray) {
    if (!on_) return 0;
    const std::size_t at = addNode(nextToken());
    out_->nodes_.back().isArray = isArray;
    open_.push_back({static_cast<std::uint32_t>(out_->nodes_.size() - 1), static_cast<std::uint32_t>(pending_.size())});
    return at;
  }
  /// '}' or ']': the container's children become contiguous; `index`, a large
  /// object's key index, is kept for lookups.
  void endContainer(std::unique_ptr<KeyIndex> index) {
    if (!on_) return;
    nextToken();
    const Open o = open_.back();
    open_.pop_back();
    JsonLocations::Node& n = out_->nodes_[o.node];
    n.firstChild = static_cast<std::uint32_t>(out_->children_.size());
    n.childCount = static_cast<std::uint32_t>(pending_.size() - o.firstPending) & 0x7FFFFFFFu;
    out_->children_.insert(out_->children_.end(), pending_.begin() + o.firstPending, pending_.end());
    pending_.resize(o.firstPending);
    if (index) out_->largeObjects_.emplace(o.node, std::move(*index));
  }
  /// A member's key (as parsed): returns where it starts.
  std::size_t key(const std::string& k) {
    if (!on_) return 0;
    const std::size_t at = nextToken();
    pendingKey_ = static_cast<std::uint32_t>(out_->keyStarts_.size());
    out_->keyStarts_.push_back(static_cast<std::uint32_t>(out_->keys_.size()));
    out_->keys_ += k;
    return at;
  }
  /// Line and column of an offset already passed (0, 0 when not recording).
  void lineColumn(std::size_t offset, int& line, int& column) const {
    line = column = 0;
    if (on_) out_->lineColumn(offset, line, column);
  }
  /// The table, once the parse succeeded (nullptr when not recording).
  std::shared_ptr<const SourceLocator> finish() {
    if (!on_ || out_->nodes_.empty()) return nullptr;
    out_->keyStarts_.push_back(static_cast<std::uint32_t>(out_->keys_.size()));
    return std::move(out_);
  }

 private:
  struct Open {
    std::uint32_t node;          // the container's node
    std::uint32_t firstPending;  // where its children start in pending_
  };

  std::size_t addNode(std::size_t at) {
    const auto index = static_cast<std::uint32_t>(out_->nodes_.size());
    JsonLocations::Node& n = out_->nodes_.emplace_back();
    n.offset = static_cast<std::uint32_t>(at);
    n.key = pendingKey_;
    pendingKey_ = JsonLocations::kNoKey;
    if (!open_.empty()) pending_.push_back(index);
    return at;
  }

  /// The start of the token the parser has just read; moves past it.
  std::size_t nextToken() {
    const std::size_t n = text_.size();
    std::size_t i = cursor_;
    for (; i < n; ++i) {
      const char c = text_[i];
      if (c == '\n') out_->lineStarts_.push_back(static_cast<std::uint32_t>(i + 1));
      else if (c != ' ' && c != '\t' && c != '\r' && c != ',' && c != ':') break;
    }
    const std::size_t start = i;
    if (i >= n) return cursor_ = n, n;
    switch (text_[i]) {
      case '"':
        for (++i; i < n && text_[i] != '"'; ++i)
          if (text_[i] == '\\') ++i;
        ++i;
        break;
      case 't': case 'n': i += 4; break;
      case 'f': i += 5; break;
      case '{': case '}': case '[': case ']': ++i; break;
      default:  // a number
        while (i < n && (std::isdigit(static_cast<unsigned char>(text_[i])) || text_[i] == '-' || text_[i] == '+' ||
                         text_[i] == '.' || text_[i] == 'e' || text_[i] == 'E'))
          ++i;
    }
    cursor_ = std::min(i, n);
    return start;
  }

  const std::string& text_;
  const bool on_;
  std::shared_ptr<JsonLocations> out_;
  std::size_t cursor_ = 0;                 // just past the last token
  std::vector<Open> open_;                 // the open containers, innermost last
  std::vector<std::uint32_t> pending_;     // the open containers' children so far
  std::uint32_t pendingKey_ = JsonLocations::kNoKey;
};

/// SAX handler building an ordered DOM while enforcing what plain JSON allows
/// but a material file must not contain. JSON pointers are built only when a
/// diagnostic needs one (from the stack of open containers).
class StrictDomBuilder {
 public:
  StrictDomBuilder(const std::string& text, const ReadLimits& limits, Diagnostics& diags)
      : text_(text), limits_(limits), diags_(diags), locations_(text) {}

  Json result;
  bool failed = false;

  bool null() { return scalar(Json(nullptr)); }
  bool boolean(bool v) { return scalar(Json(v)); }
  bool number_integer(Json::number_integer_t v) { return scalar(Json(v)); }
  bool number_unsigned(Json::number_unsigned_t v) { return scalar(Json(v)); }
  bool number_float(Json::number_float_t v, const std::string& lexeme) {
    if (!std::isfinite(v)) {  // nlohmann rejects these itself; kept should it ever pass one
      reject(locations_.value(), [&] { return pointerForNext(); },
             fmt::format("number {} is out of range (it overflows a double)", quoteForDiagnostic(lexeme, 32)));
      return put(Json(0.0));
    }
    return scalar(Json(v));
  }
  bool string(std::string& v) {
    if (v.size() > limits_.maxStringBytes) {
      reject(locations_.value(), [&] { return pointerForNext(); },
             fmt::format("string of {} bytes is longer than the limit of {} bytes (the string-length limit)",
                         v.size(), limits_.maxStringBytes));
      return put(Json(std::string()));
    }
    return scalar(Json(std::move(v)));
  }
  bool binary(Json::binary_t&) { return false; }
  bool start_object(std::size_t) {
    locations_.beginContainer(false);
    Json* slot = slotForNext();
    *slot = Json::object();
    stack_.push_back(Frame{slot});
    return true;
  }
  bool key(std::string& k) {
    const std::size_t at = locations_.key(k);
    Frame& f = stack_.back();
    f.keyTooLong = k.size() > limits_.maxKeyBytes;
    if (f.keyTooLong) {
      reject(at, [&] { return pointerAt(stack_.size() - 1); },
             fmt::format("key {} of {} bytes is longer than the limit of {} bytes (the key-length limit; keys "
                         "are ids, pin and setting names)",
                         quoteForDiagnostic(k, 32), k.size(), limits_.maxKeyBytes));
    }
    f.duplicate = !insertKey(f, k);
    f.key = std::move(k);
    if (f.duplicate)
      reject(at, [&] { return pointerAt(stack_.size()); }, fmt::format("duplicate key {}", quoteForDiagnostic(f.key)));
    return true;
  }
  bool end_object() {
    locations_.endContainer(std::move(stack_.back().keys));
    stack_.pop_back();
    return true;
  }
  bool start_array(std::size_t) {
    locations_.beginContainer(true);
    Json* slot = slotForNext();
    *slot = Json::array();
    stack_.push_back(Frame{slot});
    return true;
  }
  bool end_array() {
    locations_.endContainer(nullptr);
    stack_.pop_back();
    return true;
  }
  bool parse_error(std::size_t position, const std::string& lastToken,
                   const nlohmann::detail::exception& ex) {
    // nlohmann reports the byte *after* the offending token; point at its start.
    // The token as nlohmann shows it spells each control byte as "<U+XXXX>":
    // count those as the one byte they stand for.
    std::size_t offset = position > 0 ? position - 1 : 0;
    const std::size_t tokenBytes = rawTokenBytes(lastToken);
    if (tokenBytes > 0 && offset + 1 >= tokenBytes) offset = offset + 1 - tokenBytes;
    int line, col;
    lineColumnOf(text_, offset, line, col);
    diags_.errorAt(line, col, describe(ex.what(), lastToken));
    failed = true;
    return false;
  }

  /// Where the document's values start (after a successful parse).
  std::shared_ptr<const SourceLocator> locations() { return locations_.finish(); }

 private:
  struct Frame {
    Json* node;
    std::string key{};                               // objects: the current key
    std::unique_ptr<KeyIndex> keys{};                // objects past kLinearKeys keys: key -> ordinal
    bool duplicate = false;                          // the current key repeats an earlier one
    bool keyTooLong = false;                         // the current key is over the limit
  };

  /// Records `k` in the frame's object; false if it was already there.
  bool insertKey(Frame& f, const std::string& k) {
    const auto& items = f.node->get_ref<const Json::object_t&>();
    if (!f.keys) {
      for (const auto& [name, value] : items)
        if (name == k) return false;
      if (items.size() < kLinearKeys) return true;
      f.keys = std::make_unique<KeyIndex>();
      for (const auto& [name, value] : items) f.keys->emplace(name, static_cast<std::uint32_t>(f.keys->size()));
    }
    return f.keys->emplace(k, static_cast<std::uint32_t>(items.size())).second;
  }

  /// The length in the file of a token nlohmann returned with control bytes
  /// spelled "<U+XXXX>" (8 characters for 1 byte).
  static std::size_t rawTokenBytes(const std::string& token) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < token.size(); ++n) {
      const bool escaped = i + 8 <= token.size() && token.compare(i, 3, "<U+") == 0 && token[i + 7] == '>' &&
                           std::isxdigit(static_cast<unsigned char>(token[i + 3])) &&
                           std::isxdigit(static_cast<unsigned char>(token[i + 4])) &&
                           std::isxdigit(static_cast<unsigned char>(token[i + 5])) &&
                           std::isxdigit(static_cast<unsigned char>(token[i + 6]));
      i += escaped ? 8 : 1;
    }
    return n;
  }

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

  /// The reference token of frame i's current child: an array index or the
  /// current key (an over-long key is shortened: pointers stay bounded).
  std::string tokenOf(std::size_t i, bool next) const {
    const Frame& f = stack_[i];
    if (f.node->is_array()) return std::to_string(next ? f.node->size() : f.node->size() - 1);
    if (f.keyTooLong) return pointerToken(f.key.substr(0, 32)) + "...";
    return pointerToken(f.key);
  }

  /// The pointer of the value open at depth `depth` (0: the document).
  std::string pointerAt(std::size_t depth) const {
    std::string p;
    for (std::size_t i = 0; i < depth && i < stack_.size(); ++i) p += "/" + tokenOf(i, false);
    return p;
  }

  /// The pointer of the value about to be added to the innermost container.
  std::string pointerForNext() const {
    if (stack_.empty()) return "";
    return pointerAt(stack_.size() - 1) + "/" + tokenOf(stack_.size() - 1, true);
  }

  Json* slotForNext() {
    if (stack_.empty()) return &result;
    Frame& f = stack_.back();
    if (f.node->is_array()) {
      f.node->push_back(Json());
      return &f.node->back();
    }
    // A duplicate (already reported) is parsed into a slot of its own so the
    // first value is kept. Each duplicate gets a new slot, never a reused
    // one: a duplicate nested inside a duplicate's value must not free the
    // container its parser frames still point into.
    if (f.duplicate) return &scratch_.emplace_back();
    // Append directly to the ordered map's vector: its operator[] searches
    // linearly, which would make an object of n keys cost O(n^2).
    auto& items = static_cast<std::vector<std::pair<const std::string, Json>>&>(f.node->get_ref<Json::object_t&>());
    items.emplace_back(f.key, Json());
    return &items.back().second;
  }
  bool put(Json v) {
    Json* slot = slotForNext();
    *slot = std::move(v);
    return true;
  }
  bool scalar(Json v) {
    locations_.value();
    return put(std::move(v));
  }
  /// A value that parses but is refused: located at `offset`, named by the
  /// pointer `pointerOf()` builds (O(depth): not built past the error limit).
  template <typename PointerOf>
  void reject(std::size_t offset, PointerOf pointerOf, std::string message) {
    int line, col;
    locations_.lineColumn(offset, line, col);
    diags_.errorAt(line, col, std::move(message), diags_.limitReached() ? std::string() : pointerOf());
    failed = true;
  }

  const std::string& text_;
  const ReadLimits& limits_;
  Diagnostics& diags_;
  LocationRecorder locations_;
  std::vector<Frame> stack_;
  std::deque<Json> scratch_;  // values of duplicate keys (stable addresses)
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
  diags.setLocator(builder.locations());
  return std::move(builder.result);
}

}  // namespace substratec
