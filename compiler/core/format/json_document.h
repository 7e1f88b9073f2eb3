// Reading a material file: size limit, a nesting pre-scan, and a strict JSON
// parse (duplicate keys, byte-order marks and non-finite numbers rejected)
// into an order-preserving DOM. Syntax errors are reported as file:line:col;
// the parse also records where each value starts, so that later diagnostics,
// which name a JSON pointer, are printed at their value's line:col too.
#pragma once
#include <cstddef>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "diag/diagnostics.h"

namespace substratec {

using Json = nlohmann::ordered_json;

/// The reader's limits (docs/robustness.md); each has its own diagnostic.
struct ReadLimits {
  std::size_t maxInputBytes = 16u << 20;  // 16 MiB (--max-input-size)
  std::size_t maxNesting = 128;           // JSON arrays/objects
  std::size_t maxStringBytes = 1u << 16;  // any single string value, in bytes
  std::size_t maxKeyBytes = 256;          // any object key (ids are at most 128 bytes)
};

/// Reads `path` without reading past `limits.maxInputBytes`: a regular file
/// larger than the limit is rejected from its size alone (nothing is read);
/// pipes and devices are read in chunks up to the limit. A FIFO without a
/// writer does not block. Returns nullopt (with a diagnostic) if the file is
/// missing, a directory, unreadable or too large.
std::optional<std::string> readSourceFile(const std::string& path, const ReadLimits& limits,
                                          Diagnostics& diags);

/// Parses JSON text. All syntax problems are reported with line:col; values
/// that parse but are unacceptable (duplicate keys, NaN/Inf, huge strings)
/// are reported with their line:col and JSON pointer. Returns nullopt on any
/// error. On success, `diags` gets the document's SourceLocator: every later
/// pointer diagnostic is located at its value's first byte (a missing member
/// at its object's). Texts of 2 GiB or more are parsed without locations.
std::optional<Json> parseJsonDocument(const std::string& text, const ReadLimits& limits,
                                      Diagnostics& diags);

/// A JSON value as diagnostics describe it: null, true, a quoted string (escaped),
/// "an array of N", "an object", a number.
std::string kindOfJson(const Json& j);

/// 1-based line and column (in bytes; a tab is one byte) of a byte offset in
/// text. Lines end at '\n' (so a CRLF file counts lines as an LF one).
void lineColumnOf(const std::string& text, std::size_t offset, int& line, int& column);

}  // namespace substratec
