// What the command line says in its own name, not about a place in an input
// (those are diagnostics, diag/diagnostics.h, and name their file): every
// `substratec: error: …`, `substratec: internal compiler error: …` and
// `substratec: warning: …` line of cli/ is printed here, none built by hand.
#pragma once
#include <ostream>
#include <string_view>

#include "cli/cli.h"

namespace substratec::cli {

/// Prints `substratec: error: MESSAGE` and returns `status`.
inline int printError(std::ostream& err, int status, std::string_view message) {
  err << "substratec: error: " << message << "\n";
  return status;
}

/// A usage error: the message, how to get help, and kExitUsage.
inline int printUsageError(std::ostream& err, std::string_view message) {
  printError(err, kExitUsage, message);
  err << "Run 'substratec --help' for usage.\n";
  return kExitUsage;
}

/// Prints `substratec: internal compiler error: MESSAGE` (a bug of the
/// compiler, not of the input) and returns kExitInternal.
inline int printInternalError(std::ostream& err, std::string_view message) {
  err << "substratec: internal compiler error: " << message << "\n";
  return kExitInternal;
}

}  // namespace substratec::cli
