// The substratec command line, as a library function so tests can drive it
// without spawning processes. main() is a thin wrapper.
#pragma once
#include <iosfwd>
#include <string>
#include <vector>

namespace substratec {

/// Exit codes: 0 success, 1 bad input, 2 bad usage, 3 internal compiler error.
/// kExitUnstable: `stability` found non-finite values or energy gain.
enum ExitCode { kExitOk = 0, kExitBadInput = 1, kExitUsage = 2, kExitInternal = 3, kExitUnstable = 4 };

int runCli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace substratec
