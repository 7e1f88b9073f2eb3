#include "diag/diagnostics.h"

#include <fmt/format.h>

namespace substratec {

namespace {
const char* severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}
/// The file as diagnostics name it: text without a file name is stdin's.
std::string_view displayName(const std::string& file) {
  return file.empty() ? std::string_view("<stdin>") : std::string_view(file);
}
}  // namespace

std::string Diagnostic::format() const {
  const std::string where = line > 0 ? fmt::format("{}:{}:{}", displayName(file), line, column)
                                     : std::string(displayName(file));
  if (!hasPointer) return fmt::format("{}: {}: {}", where, severityName(severity), message);
  return fmt::format("{}: {}: {} [{}]", where, severityName(severity), message, pointer.empty() ? "/" : pointer);
}

void Diagnostics::push(Diagnostic d) {
  if (d.severity == Severity::Error) {
    if (errorCount_ >= limit_) {
      ++dropped_;
      return;
    }
    ++errorCount_;
  }
  list_.push_back(std::move(d));
}

void Diagnostics::located(Severity severity, std::string file, int line, int column, std::string message,
                          std::optional<std::string> pointer) {
  Diagnostic d;
  d.severity = severity;
  d.file = std::move(file);
  d.line = line;
  d.column = column;
  d.hasPointer = pointer.has_value();
  if (pointer) d.pointer = std::move(*pointer);
  d.message = std::move(message);
  push(std::move(d));
}

void Diagnostics::mapPointers(std::string generated, std::string source, std::string what) {
  mapped_.push_back({std::move(generated), std::move(source), std::move(what)});
}

void Diagnostics::pointed(Severity severity, std::string pointer, std::string message) {
  for (const MappedPointers& m : mapped_)
    if (pointer == m.generated || pointer.starts_with(m.generated + "/")) {
      message += fmt::format(" ({}, at {})", m.what, pointer);
      pointer = m.source;
      break;
    }
  int line = 0, column = 0;
  if (locator_ && !locator_->locate(pointer, line, column)) line = column = 0;
  located(severity, file_, line, column, std::move(message), std::move(pointer));
}

void Diagnostics::errorAt(int line, int column, std::string message) {
  located(Severity::Error, file_, line, column, std::move(message));
}

void Diagnostics::errorAt(int line, int column, std::string message, std::string pointer) {
  located(Severity::Error, file_, line, column, std::move(message), std::move(pointer));
}

void Diagnostics::errorIn(std::string file, int line, int column, std::string message) {
  located(Severity::Error, std::move(file), line, column, std::move(message));
}

void Diagnostics::warningAt(int line, int column, std::string message) {
  located(Severity::Warning, file_, line, column, std::move(message));
}

void Diagnostics::error(std::string pointer, std::string message) {
  pointed(Severity::Error, std::move(pointer), std::move(message));
}

void Diagnostics::warning(std::string pointer, std::string message) {
  pointed(Severity::Warning, std::move(pointer), std::move(message));
}

void Diagnostics::note(std::string pointer, std::string message) {
  pointed(Severity::Note, std::move(pointer), std::move(message));
}

void Diagnostics::fail(std::string message) {
  Diagnostic d;
  d.file = file_;
  d.message = std::move(message);
  push(std::move(d));
}

std::string Diagnostics::errorMessages() const {
  std::string out;
  for (const auto& d : list_) {
    if (d.severity != Severity::Error) continue;
    if (!out.empty()) out += '\n';
    out += d.message;
  }
  return out;
}

std::string Diagnostics::formatAll() const {
  std::string out;
  for (const auto& d : list_) {
    out += d.format();
    out += '\n';
  }
  if (dropped_ > 0) {
    out += fmt::format("{}: error: too many errors ({} more not shown)\n", displayName(file_), dropped_);
  }
  return out;
}

std::string pointerToken(const std::string& key) {
  std::string out;
  out.reserve(key.size());
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string quoteForDiagnostic(const std::string& s, std::size_t maxLen) {
  std::string out = "\"";
  std::size_t n = 0;
  for (unsigned char c : s) {
    if (n++ >= maxLen) {
      out += "...";
      break;
    }
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c >= 0x7f) {
      out += fmt::format("\\x{:02x}", c);
    } else {
      out += static_cast<char>(c);
    }
  }
  out += '"';
  return out;
}

}  // namespace substratec
