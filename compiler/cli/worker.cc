#include "cli/worker.h"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <istream>
#include <limits>
#include <mutex>
#include <ostream>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "cli/messages.h"
#include "util/parallel.h"

namespace substratec {
namespace {

using json = nlohmann::json;

/// A field by its JSON name or, when that differs, its protobuf name (proto3's JSON
/// mapping accepts both: Bazel writes `requestId`, a hand-written request may say
/// `request_id`).
const json* field(const json& object, const char* jsonName, const char* protoName = nullptr) {
  if (auto it = object.find(jsonName); it != object.end()) return &*it;
  if (!protoName) return nullptr;
  if (auto it = object.find(protoName); it != object.end()) return &*it;
  return nullptr;
}

/// Reads one request's text, at most `limit` bytes of it (`tooLong` when it
/// was longer: the rest is skipped). A request starts at the next character
/// that is not white space and ends where the JSON object (or array) it starts
/// with closes, or at the end of its line, or of the input. Bazel 4 writes its
/// JSON requests back to back, later versions one per line: both read the same.
/// False at the end of input, nothing read.
bool readRequest(std::istream& in, std::string& text, std::size_t limit, bool& tooLong) {
  text.clear();
  tooLong = false;
  std::streambuf* buf = in.rdbuf();
  constexpr int kEof = std::char_traits<char>::eof();
  int c = buf->sbumpc();
  while (c == ' ' || c == '\t' || c == '\r' || c == '\n') c = buf->sbumpc();
  if (c == kEof) return false;
  const bool structured = c == '{' || c == '[';
  int depth = 0;
  bool inString = false, escaped = false;
  for (; c != kEof && c != '\n'; c = buf->sbumpc()) {
    if (text.size() < limit)
      text.push_back(static_cast<char>(c));
    else
      tooLong = true;
    if (!structured) continue;
    if (inString) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        inString = false;
    } else if (c == '"') {
      inString = true;
    } else if (c == '{' || c == '[') {
      ++depth;
    } else if ((c == '}' || c == ']') && --depth == 0) {
      break;
    }
  }
  return true;
}

/// The protocol's answer for one request, written whole under the lock.
class Responder {
 public:
  explicit Responder(std::ostream& out) : out_(out) {}
  void respond(int exitCode, const std::string& output, int requestId) {
    const std::string line = workResponseLine(exitCode, output, requestId) + "\n";
    std::lock_guard<std::mutex> lock(mutex_);
    out_ << line;
    out_.flush();
  }

 private:
  std::ostream& out_;
  std::mutex mutex_;
};

/// Runs one request's command line through runCli and answers it.
void serve(const std::vector<std::string>& prefix, const WorkRequest& request, Responder& responder) {
  std::vector<std::string> args = prefix;
  args.insert(args.end(), request.arguments.begin(), request.arguments.end());
  std::ostringstream output;  // standard output and standard error, in the order printed
  int status = kExitInternal;
  try {
    status = runCli(args, output, output);
  } catch (const std::exception& e) {
    cli::printInternalError(output, e.what());
  }
  responder.respond(status, output.str(), request.requestId);
}

/// Multiplex requests, run on up to `threads` threads as they arrive.
class RequestPool {
 public:
  explicit RequestPool(std::size_t threads) : threads_(threads) {}
  ~RequestPool() { drain(); }

  void submit(std::function<void()> job) {
    std::unique_lock<std::mutex> lock(mutex_);
    queue_.push_back(std::move(job));
    if (workers_.size() < threads_ && queue_.size() > idle_) workers_.emplace_back([this] { work(); });
    wake_.notify_one();
  }

  /// Waits until every submitted request has been answered.
  void drain() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closing_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
    workers_.clear();
  }

 private:
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      ++idle_;
      wake_.wait(lock, [this] { return closing_ || !queue_.empty(); });
      --idle_;
      if (queue_.empty()) return;  // closing, nothing left
      std::function<void()> job = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      job();
      lock.lock();
    }
  }

  std::size_t threads_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> queue_;
  std::vector<std::thread> workers_;
  std::size_t idle_ = 0;
  bool closing_ = false;
};

}  // namespace

std::optional<WorkRequest> parseWorkRequest(const std::string& text, std::string* error, int* requestId) {
  *requestId = 0;
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded() || !j.is_object()) {
    *error = "not a WorkRequest (a JSON object)";
    return std::nullopt;
  }
  WorkRequest r;
  if (const json* id = field(j, "requestId", "request_id")) {
    if (!id->is_number_integer() || id->get<long long>() < 0 || id->get<long long>() > 2147483647) {
      *error = "requestId must be an integer from 0 to 2147483647";
      return std::nullopt;
    }
    r.requestId = id->get<int>();
    *requestId = r.requestId;
  }
  if (const json* args = field(j, "arguments")) {
    if (!args->is_array()) {
      *error = "arguments must be an array of strings";
      return std::nullopt;
    }
    for (std::size_t i = 0; i < args->size(); ++i) {
      if (!(*args)[i].is_string()) {
        *error = fmt::format("arguments/{} is not a string", i);
        return std::nullopt;
      }
      r.arguments.push_back((*args)[i].get<std::string>());
    }
  }
  if (const json* cancel = field(j, "cancel")) r.cancel = cancel->is_boolean() && cancel->get<bool>();
  const json* sandbox = field(j, "sandboxDir", "sandbox_dir");
  if (sandbox && !(sandbox->is_string() && sandbox->get<std::string>().empty())) {
    *error = "sandboxDir is not supported (substratec does not declare supports-multiplex-sandboxing)";
    return std::nullopt;
  }
  return r;
}

std::string workResponseLine(int exitCode, const std::string& output, int requestId) {
  json j = json::object();
  j["exitCode"] = exitCode;
  j["output"] = output;
  j["requestId"] = requestId;
  // Invalid UTF-8 in the output (a file name, say) is replaced rather than thrown on.
  return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

int runWorker(const std::vector<std::string>& prefix, std::istream& in, std::ostream& out,
              const WorkerOptions& options) {
  Responder responder(out);
  // Multiplex requests may all arrive at once: as many threads as asked (0: the machine's).
  RequestPool pool(workerCount(std::numeric_limits<std::size_t>::max(), options.threads));
  std::string text;
  bool tooLong = false;
  for (std::size_t number = 1; readRequest(in, text, options.maxRequestBytes, tooLong); ++number) {
    std::string error;
    int requestId = 0;
    std::optional<WorkRequest> request;
    if (tooLong)
      error = fmt::format("longer than {} bytes", options.maxRequestBytes);
    else
      request = parseWorkRequest(text, &error, &requestId);
    if (!request) {
      std::ostringstream message;
      cli::printError(message, kExitUsage, fmt::format("work request {}: {}", number, error));
      responder.respond(kExitUsage, message.str(), requestId);
      continue;
    }
    if (request->cancel) continue;  // requests always run to the end: nothing to cancel, no response due
    if (request->requestId == 0)
      serve(prefix, *request, responder);
    else
      pool.submit([&prefix, &responder, r = std::move(*request)] { serve(prefix, r, responder); });
  }
  pool.drain();
  return kExitOk;
}

}  // namespace substratec
