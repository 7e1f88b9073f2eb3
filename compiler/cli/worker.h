// `substratec [ARGS...] --persistent_worker`: a warm compiler for build
// systems, speaking Bazel's persistent-worker protocol in its JSON form (which
// Bazel and Buck2 speak): WorkRequest objects on standard input (one per line,
// or back to back as Bazel 4 writes them), one WorkResponse per line on
// standard output (docs/scenes.md, "Persistent worker").
//
// A request runs the command line ARGS + its `arguments` through runCli, in
// this process: glslang's built-in symbol tables, the embedded runtime and the
// energy tables are set up once for every request, so a material costs what it
// costs in a batch. The response carries runCli's exit status and everything it
// printed (standard output and standard error, in order) as `output`.
//
// Requests with a non-zero `requestId` (a multiplex worker) run concurrently,
// up to the machine's threads, and are answered as they finish; `requestId` 0
// (a singleplex worker) runs at once, before the next request is read. A request
// that is not a WorkRequest is answered with exit status 2 and what is wrong,
// and the worker reads on. End of input ends the worker (status 0) once every request
// has been answered.
#pragma once
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace substratec {

/// The flag that makes `substratec` a worker (Bazel appends it to the
/// worker's start-up arguments).
inline constexpr const char* kPersistentWorkerFlag = "--persistent_worker";

/// Longest request read (64 MiB); a longer one is answered as too long.
inline constexpr std::size_t kMaxWorkRequestBytes = std::size_t{64} << 20;

/// A parsed WorkRequest (the fields substratec uses).
struct WorkRequest {
  std::vector<std::string> arguments;
  int requestId = 0;
  bool cancel = false;  // a cancellation: substratec finishes requests instead (no response of its own)
};

/// Parses one request's text. On a malformed one: nullopt, `error` says why,
/// and `requestId` is its id when it had a readable one (else 0).
std::optional<WorkRequest> parseWorkRequest(const std::string& text, std::string* error, int* requestId);

/// One WorkResponse line (JSON, without the newline).
std::string workResponseLine(int exitCode, const std::string& output, int requestId);

struct WorkerOptions {
  std::size_t threads = 0;                          // multiplex requests run at once (0: the machine's threads)
  std::size_t maxRequestBytes = kMaxWorkRequestBytes;  // a longer request is answered as too long
};

/// Serves requests from `in` until its end, answering on `out`; `prefix` is
/// put before every request's arguments. Returns 0.
int runWorker(const std::vector<std::string>& prefix, std::istream& in, std::ostream& out,
              const WorkerOptions& options = {});

}  // namespace substratec
