// Diagnostics: compiler-style, one line each, located either by line:column
// (syntax) or by JSON pointer (everything after parsing).
#pragma once
#include <cstddef>
#include <string>
#include <vector>

namespace substratec {

enum class Severity { Error, Warning, Note };

struct Diagnostic {
  Severity severity = Severity::Error;
  std::string file;     // as given on the command line (never made absolute)
  int line = 0;         // 1-based; 0 when located by pointer
  int column = 0;       // 1-based, in bytes
  std::string pointer;  // RFC 6901 JSON pointer ("" is the document root)
  bool hasPointer = false;
  std::string message;

  /// `file:LINE:COL: error: msg` or `file: /pointer: error: msg`, or
  /// `file: error: msg` when it is about the file as a whole (line 0: it
  /// cannot be opened or read).
  std::string format() const;
};

/// Collects diagnostics up to a limit (so one run reports many errors but a
/// hostile file cannot make it print millions of lines).
class Diagnostics {
 public:
  explicit Diagnostics(std::string file, std::size_t errorLimit = 50)
      : file_(std::move(file)), limit_(errorLimit) {}

  void errorAt(int line, int column, std::string message);
  /// An error located in another file than this one's (an included file).
  void errorIn(std::string file, int line, int column, std::string message);
  void error(std::string pointer, std::string message);
  void warning(std::string pointer, std::string message);
  void warningAt(int line, int column, std::string message);
  /// An error located nowhere in a document: a tool or a Vulkan call failed ("GPU harness:
  /// vkCreateDevice failed: ..."). Prints like any unlocated diagnostic (`file: error: msg`).
  void fail(std::string message);

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
  void push(Diagnostic d);
  std::string file_;
  std::size_t limit_;
  std::size_t errorCount_ = 0;
  std::size_t dropped_ = 0;
  std::vector<Diagnostic> list_;
};

/// Escapes one reference token for a JSON pointer ("~" -> "~0", "/" -> "~1").
std::string pointerToken(const std::string& key);
/// Quotes a string for a diagnostic, escaping control and non-ASCII bytes so
/// that a hostile file cannot put terminal escapes or invalid UTF-8 in output.
std::string quoteForDiagnostic(const std::string& s, std::size_t maxLen = 64);

}  // namespace substratec
