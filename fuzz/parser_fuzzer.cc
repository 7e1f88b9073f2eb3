// libFuzzer target: the front end. Arbitrary bytes through the strict JSON
// reader (pre-scan, SAX DOM builder) and, when they parse, through resolve.
// Every input must end either in a document or in at least one diagnostic;
// anything else (a crash, a sanitizer report, an uncaught exception, a
// failure without a diagnostic, a pointer diagnostic of a parsed document
// without a line:col) is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "passes/resolve.h"

using namespace substratec;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Diagnostics diags("fuzz.json");
  auto doc = parseJsonDocument(text, ReadLimits{}, diags);
  if (!doc) {
    if (!diags.hasErrors()) std::abort();  // rejected without saying why
  } else {
    auto resolved = resolveDocument(*doc, diags);
    if (!resolved && !diags.hasErrors()) std::abort();
    // Every pointer into a parsed document is located in it (diagnostics.h).
    for (const Diagnostic& d : diags.all())
      if (d.hasPointer && (d.line < 1 || d.column < 1 || static_cast<std::size_t>(d.column) > size + 1)) std::abort();
  }
  // Diagnostics stay bounded whatever the input (50 errors, quoted excerpts).
  const std::string all = diags.formatAll();
  if (all.size() > (std::size_t{1} << 22)) std::abort();
  return 0;
}
