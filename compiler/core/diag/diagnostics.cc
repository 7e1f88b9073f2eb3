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
}  // namespace

std::string Diagnostic::format() const {
  if (hasPointer) {
    return fmt::format("{}: {}: {}: {}", file, pointer.empty() ? "/" : pointer,
                       severityName(severity), message);
  }
  // Not located in the text (the file cannot be opened or read): the path alone.
  if (line <= 0) return fmt::format("{}: {}: {}", file, severityName(severity), message);
  return fmt::format("{}:{}:{}: {}: {}", file, line, column, severityName(severity), message);
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

void Diagnostics::errorAt(int line, int column, std::string message) {
  Diagnostic d;
  d.file = file_;
  d.line = line;
  d.column = column;
  d.message = std::move(message);
  push(std::move(d));
}

void Diagnostics::errorIn(std::string file, int line, int column, std::string message) {
  Diagnostic d;
  d.file = std::move(file);
  d.line = line;
  d.column = column;
  d.message = std::move(message);
  push(std::move(d));
}

void Diagnostics::error(std::string pointer, std::string message) {
  Diagnostic d;
  d.file = file_;
  d.pointer = std::move(pointer);
  d.hasPointer = true;
  d.message = std::move(message);
  push(std::move(d));
}

void Diagnostics::warningAt(int line, int column, std::string message) {
  Diagnostic d;
  d.severity = Severity::Warning;
  d.file = file_;
  d.line = line;
  d.column = column;
  d.message = std::move(message);
  push(std::move(d));
}

void Diagnostics::warning(std::string pointer, std::string message) {
  Diagnostic d;
  d.severity = Severity::Warning;
  d.file = file_;
  d.pointer = std::move(pointer);
  d.hasPointer = true;
  d.message = std::move(message);
  push(std::move(d));
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
    out += fmt::format("{}: error: too many errors ({} more not shown)\n", file_, dropped_);
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
