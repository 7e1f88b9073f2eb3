// Diagnostics: compiler-style, one line each, in the form editors and CI
// annotators jump to:
//
//   file:LINE:COL: error: message [/json/pointer]
//
// Syntax errors are located by the reader; errors found after parsing carry a
// JSON pointer, located through the parsed document's SourceLocator (the
// reader attaches one to the Diagnostics, so the passes name pointers only).
// LINE and COL are 1-based; COL counts bytes (a tab is one, a multi-byte UTF-8
// character as many as its bytes). docs/diagnostics.md describes the form.
#pragma once
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace substratec {

enum class Severity { Error, Warning, Note };

struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;     // as given on the command line (never made absolute); "" prints as <stdin>
  int line = 0;         // 1-based; 0 when not located in the text
  int column = 0;       // 1-based, in bytes
  std::string pointer;  // RFC 6901 JSON pointer ("" is the document root)
  bool hasPointer = false;
  std::string message;

  /// `file:LINE:COL: error: msg`, with ` [/pointer]` appended when it has a
  /// pointer; `file: error: msg [/pointer]` when the pointer could not be
  /// located (no document was parsed); `file: error: msg` when it is about the
  /// file as a whole (it cannot be opened or read).
  std::string format() const;
};

/// Where a JSON pointer's value starts in the text it was parsed from
/// (format/json_document.h builds one during the parse).
class SourceLocator {
 public:
  virtual ~SourceLocator() = default;
  /// The 1-based line and column (bytes) of the value `pointer` names, or of
  /// the deepest value on its path that exists (a missing member locates its
  /// object). False only if nothing can be located.
  virtual bool locate(std::string_view pointer, int& line, int& column) const = 0;
};

/// Collects diagnostics up to a limit (so one run reports many errors but a
/// hostile file cannot make it print millions of lines).
class Diagnostics {
 public:
  explicit Diagnostics(std::string file, std::size_t errorLimit = 50)
      : file_(std::move(file)), limit_(errorLimit) {}

  /// An error at line:column (0, 0: about the file as a whole); `pointer`, if
  /// given, is printed after the message.
  void errorAt(int line, int column, std::string message);
  void errorAt(int line, int column, std::string message, std::string pointer);
  /// An error located in another file than this one's (an included file).
  void errorIn(std::string file, int line, int column, std::string message);
  /// An error or warning about the value at `pointer`, located through the
  /// locator when there is one.
  void error(std::string pointer, std::string message);
  void warning(std::string pointer, std::string message);
  void note(std::string pointer, std::string message);  // information, never a failure
  void warningAt(int line, int column, std::string message);
  /// An error located nowhere in a document: a tool or a Vulkan call failed ("GPU harness:
  /// vkCreateDevice failed: ..."). Prints like any unlocated diagnostic (`file: error: msg`).
  void fail(std::string message);

  /// Pointers into what a rewrite generated (a building block's expansion):
  /// a later diagnostic at `generated` or under it is reported at `source`,
  /// its message saying `what` it was about and the pointer it had.
  void mapPointers(std::string generated, std::string source, std::string what);

  /// The document later pointers are located in (the reader sets it after a
  /// successful parse; nullptr: pointers stay unlocated).
  void setLocator(std::shared_ptr<const SourceLocator> locator) { locator_ = std::move(locator); }
  const std::shared_ptr<const SourceLocator>& locator() const { return locator_; }

  bool hasErrors() const { return errorCount_ > 0; }
  std::size_t errorCount() const { return errorCount_; }
  bool limitReached() const { return errorCount_ >= limit_; }
  const std::vector<Diagnostic>& all() const { return list_; }
  const std::string& file() const { return file_; }

  /// All diagnostics, one per line, plus a "too many errors" line if cut.
  std::string formatAll() const;
  /// The errors' messages alone (no file, no severity), joined by newlines: for a caller that puts
  /// a tool's failure into its own sentence ("substratec: error: preview renders on Vulkan ...: <it>").
  std::string errorMessages() const;

 private:
  void located(Severity severity, std::string file, int line, int column, std::string message,
               std::optional<std::string> pointer = std::nullopt);
  void pointed(Severity severity, std::string pointer, std::string message);
  void push(Diagnostic d);
  std::string file_;
  std::size_t limit_;
  std::size_t errorCount_ = 0;
  std::size_t dropped_ = 0;
  std::vector<Diagnostic> list_;
  std::shared_ptr<const SourceLocator> locator_;
  struct MappedPointers {
    std::string generated, source, what;
  };
  std::vector<MappedPointers> mapped_;
};

/// Escapes one reference token for a JSON pointer ("~" -> "~0", "/" -> "~1").
std::string pointerToken(const std::string& key);
/// Quotes a string for a diagnostic, escaping control and non-ASCII bytes so
/// that a hostile file cannot put terminal escapes or invalid UTF-8 in output.
std::string quoteForDiagnostic(const std::string& s, std::size_t maxLen = 64);

}  // namespace substratec
