// substratec: a thin main over runCli (see cli/cli.h), or over runWorker
// (cli/worker.h) when a build system starts it with --persistent_worker.
#include <malloc.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "cli/worker.h"

int main(int argc, char** argv) {
  // A substratec process is short-lived and compiles its shaders on several
  // threads; glslang allocates and frees megabytes per shader. glibc's
  // default returns freed memory to the kernel at once and faults it back in
  // for the next shader (about a fifth of `compile`'s time, docs/performance.md);
  // keeping it costs nothing in a process that exits next (and a worker reuses it).
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_TOP_PAD, 64 << 20);
  std::ios::sync_with_stdio(false);
  std::vector<std::string> args(argv + 1, argv + argc);
  // Bazel starts a worker as `substratec ARGS... --persistent_worker` and sends
  // the rest of each command line as requests; ARGS go before each of them.
  if (auto flag = std::find(args.begin(), args.end(), substratec::kPersistentWorkerFlag); flag != args.end()) {
    args.erase(flag);
    return substratec::runWorker(args, std::cin, std::cout);
  }
  return substratec::runCli(args, std::cout, std::cerr);
}
