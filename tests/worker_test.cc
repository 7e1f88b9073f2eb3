// The persistent worker (cli/worker.h) at the protocol level: Bazel's JSON
// WorkRequest / WorkResponse lines, in process through runWorker and once
// through the built binary as Bazel starts it; and `@FILE` argument files.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>

#include "cli/argument_files.h"
#include "cli/worker.h"
#include "cli_util.h"

namespace worker_test {

using namespace substratec;
using namespace substratec::clitest;
using json = nlohmann::json;

const fs::path kExamples = fs::path(SUBSTRATEC_SOURCE_DIR) / "examples";
const std::string kBad = (fs::path(SUBSTRATEC_SOURCE_DIR) / "tests/bad/003_truncated_object.json").string();

std::string example(const char* name) { return (kExamples / name).string(); }

std::string requestLine(const std::vector<std::string>& arguments, int requestId) {
  return json{{"arguments", arguments}, {"requestId", requestId}}.dump() + "\n";
}

/// Runs a worker over `input`; its responses, one JSON object per line (every
/// line of its standard output must be one).
std::vector<json> serveAll(const std::vector<std::string>& prefix, const std::string& input,
                           const WorkerOptions& options = {}) {
  std::istringstream in(input);
  std::ostringstream out;
  EXPECT_EQ(runWorker(prefix, in, out, options), 0);
  std::vector<json> responses;
  std::istringstream lines(out.str());
  for (std::string line; std::getline(lines, line);) {
    json r = json::parse(line, nullptr, false);
    EXPECT_TRUE(r.is_object()) << "not a WorkResponse: " << line;
    if (r.is_object()) responses.push_back(r);
  }
  return responses;
}

TEST(Worker, AnswersEachRequestWithWhatTheSameCommandLinePrintsAndWritesTheSameFiles) {
  const fs::path oneShot = freshDir("worker", "one_shot");
  const fs::path worker = freshDir("worker", "singleplex");
  std::string input;
  std::vector<CliResult> expected;
  for (const char* name : {"car_paint.json", "row12_simple.json"}) {
    expected.push_back(cli({"compile", example(name), "-o", oneShot.string()}));
    input += requestLine({example(name), "-o", worker.string()}, 0);
  }
  const std::vector<json> responses = serveAll({"compile"}, input);
  ASSERT_EQ(responses.size(), 2u);
  for (std::size_t i = 0; i < responses.size(); ++i) {
    EXPECT_EQ(responses[i]["exitCode"], 0);
    EXPECT_EQ(responses[i]["requestId"], 0);
    std::string printed = expected[i].out + expected[i].err;
    const std::string dir = oneShot.string();
    for (std::size_t at = printed.find(dir); at != std::string::npos; at = printed.find(dir, at))
      printed.replace(at, dir.size(), worker.string());  // the same lines, naming the worker's directory
    EXPECT_EQ(responses[i]["output"], printed);
  }
  const auto files = filesOf(oneShot);
  EXPECT_EQ(files.size(), 14u);  // two materials, seven files each
  EXPECT_EQ(filesOf(worker), files);
}

TEST(Worker, MultiplexRequestsRunTogetherAndAreEachAnsweredOnceUnderTheirId) {
  const fs::path out = freshDir("worker", "multiplex");
  const std::vector<std::string> materials = {"car_paint.json", "row12_simple.json", "silk_in_plastic.json",
                                              "gold_sss_mix.json", "row24_fuzz.json"};
  std::string input;
  for (std::size_t i = 0; i < materials.size(); ++i)
    input += requestLine({example(materials[i].c_str()), "-o", out.string()}, static_cast<int>(i + 1));
  input += requestLine({kBad, "-o", out.string()}, 99);
  const std::vector<json> responses = serveAll({"compile"}, input, {.threads = 3});
  ASSERT_EQ(responses.size(), materials.size() + 1);
  std::set<int> ids;
  for (const json& r : responses) {
    const int id = r["requestId"];
    EXPECT_TRUE(ids.insert(id).second) << "request " << id << " answered twice";
    if (id == 99) {
      EXPECT_EQ(r["exitCode"], kExitBadInput);
      EXPECT_NE(r["output"].get<std::string>().find("003_truncated_object.json:"), std::string::npos) << r["output"];
    } else {
      EXPECT_EQ(r["exitCode"], 0) << r["output"];
    }
  }
  EXPECT_EQ(ids, (std::set<int>{1, 2, 3, 4, 5, 99}));
  EXPECT_EQ(filesOf(out).size(), 7 * materials.size());
}

TEST(Worker, AMalformedRequestIsAnsweredWithWhyAndTheWorkerReadsOn) {
  const fs::path out = freshDir("worker", "malformed");
  const std::string input = "not json\n"
                            "[1, 2]\n"
                            "{\"arguments\": \"compile\"}\n"
                            "{\"arguments\": [\"report\", 7]}\n"
                            "{\"requestId\": -1}\n"
                            "{\"requestId\": 5, \"sandboxDir\": \"sandbox/5\"}\n"
                            "\n" +  // a blank line is no request
                            requestLine({"compile", example("row12_simple.json"), "-o", out.string()}, 0) +
                            "{\"request_id\": 0, \"arguments\": [\"frobnicate\"]}";  // protobuf's field name, no newline
  const std::vector<json> responses = serveAll({}, input);
  ASSERT_EQ(responses.size(), 8u);
  const std::vector<std::string> why = {"1: not a WorkRequest", "2: not a WorkRequest",
                                        "3: arguments must be an array of strings", "4: arguments/1 is not a string",
                                        "5: requestId must be an integer", "6: sandboxDir is not supported"};
  for (std::size_t i = 0; i < why.size(); ++i) {
    EXPECT_EQ(responses[i]["exitCode"], kExitUsage);
    const std::string output = responses[i]["output"];
    EXPECT_EQ(output.rfind("substratec: error: work request " + why[i], 0), 0u) << output;
  }
  EXPECT_EQ(responses[5]["requestId"], 5);  // the id of a request it could read is kept
  EXPECT_EQ(responses[6]["exitCode"], 0) << responses[6]["output"];
  EXPECT_EQ(responses[7]["exitCode"], kExitUsage);
  EXPECT_NE(responses[7]["output"].get<std::string>().find("unknown command \"frobnicate\""), std::string::npos);
}

TEST(Worker, RequestsBackToBackWithoutNewlinesAreReadAsBazel4WritesThem) {
  // Bazel 4.2 (Debian's bazel-bootstrap) writes each JSON request with no newline after it.
  std::string input = requestLine({"--version"}, 0) + requestLine({"--version"}, 0);
  input.erase(std::remove(input.begin(), input.end(), '\n'), input.end());
  input += "{\"arguments\": [\"a}b\\\"{\"]}  {\"arguments\": [\"--version\"]}";  // braces and a quote inside a string
  const std::vector<json> responses = serveAll({}, input);
  ASSERT_EQ(responses.size(), 4u);
  EXPECT_EQ(responses[0]["exitCode"], 0);
  EXPECT_EQ(responses[1]["output"], responses[0]["output"]);
  EXPECT_EQ(responses[2]["exitCode"], kExitUsage);  // "a}b\"{" is an unknown command, not a broken request
  EXPECT_NE(responses[2]["output"].get<std::string>().find("unknown command"), std::string::npos);
  EXPECT_EQ(responses[3]["output"], responses[0]["output"]);
}

TEST(Worker, ALineLongerThanTheLimitIsRefusedAndTheNextOneServed) {
  const std::string input = "{\"arguments\": [\"" + std::string(200, 'x') + "\"]}\n" + requestLine({"--version"}, 0);
  const std::vector<json> responses = serveAll({}, input, {.maxRequestBytes = 100});
  ASSERT_EQ(responses.size(), 2u);
  EXPECT_EQ(responses[0]["exitCode"], kExitUsage);
  EXPECT_NE(responses[0]["output"].get<std::string>().find("work request 1: longer than 100 bytes"), std::string::npos);
  EXPECT_EQ(responses[1]["exitCode"], 0);
  EXPECT_EQ(responses[1]["output"].get<std::string>().rfind("substratec ", 0), 0u);
}

TEST(Worker, ACancellationGetsNoAnswerOfItsOwnAndEndOfInputEndsTheWorker) {
  const std::string input = requestLine({"--version"}, 7) + "{\"requestId\": 7, \"cancel\": true}\n";
  const std::vector<json> responses = serveAll({}, input);
  ASSERT_EQ(responses.size(), 1u);  // the request itself, run to its end
  EXPECT_EQ(responses[0]["requestId"], 7);
  EXPECT_EQ(responses[0]["exitCode"], 0);
  EXPECT_TRUE(serveAll({"compile"}, "").empty());
}

TEST(WorkerProcess, StartedAsBazelStartsItTheBinaryWritesOnlyResponsesOnItsStandardOutput) {
  const fs::path dir = freshDir("worker", "process");
  fs::create_directories(dir);
  const fs::path requests = dir / "requests.jsonl";
  std::ofstream(requests) << requestLine({example("car_paint.json"), "-o", (dir / "out").string()}, 0)
                          << "oops\n"
                          << requestLine({example("row12_simple.json"), "-o", (dir / "out").string()}, 0);
  const CliResult run = binary("compile --persistent_worker < " + requests.string());
  EXPECT_EQ(run.status, 0);
  const std::string& out = run.out;
  std::istringstream lines(out);
  std::vector<int> codes;
  for (std::string line; std::getline(lines, line);) {
    const json r = json::parse(line, nullptr, false);
    ASSERT_TRUE(r.is_object()) << "not a WorkResponse on standard output: " << line;
    codes.push_back(r["exitCode"]);
  }
  EXPECT_EQ(codes, (std::vector<int>{0, kExitUsage, 0}));
  EXPECT_EQ(filesOf(dir / "out").size(), 14u);
  EXPECT_EQ(run.err, "");
}

TEST(ArgumentFiles, AnAtFileStandsForTheArgumentsItHoldsOnePerLine) {
  const fs::path dir = freshDir("worker", "argfile");
  fs::create_directories(dir);
  // Bazel's "multiline" format, and its "shell" one (a directory with a space and a quote).
  const fs::path plain = dir / "plain.params";
  std::ofstream(plain) << example("row12_simple.json") << "\n-o\n" << (dir / "a").string() << "\n";
  const fs::path quoted = dir / "shell.params";
  std::ofstream(quoted) << example("row12_simple.json") << "\n-o\n'" << (dir / "b c'\\''d").string() << "'\n";
  EXPECT_EQ(cli({"compile", "@" + plain.string()}).status, 0);
  EXPECT_EQ(cli({"compile", "@" + quoted.string()}).status, 0);
  EXPECT_EQ(filesOf(dir / "b c'd"), filesOf(dir / "a"));
  EXPECT_EQ(filesOf(dir / "a").size(), 7u);

  const CliResult missing = cli({"compile", "@" + (dir / "none.params").string()});
  EXPECT_EQ(missing.status, kExitUsage);
  EXPECT_NE(missing.err.find("substratec: error: cannot read the argument file"), std::string::npos) << missing.err;
  const CliResult lone = cli({"compile", "@", "-o", (dir / "a").string()});  // a lone "@" is a file name
  EXPECT_EQ(lone.status, kExitBadInput);
  EXPECT_EQ(lone.err.find("argument file"), std::string::npos) << lone.err;
}

TEST(ArgumentFiles, AShellQuotedLineIsUnquotedAndAnyOtherIsTakenAsItIs) {
  EXPECT_EQ(argumentFromLine("'a b'"), "a b");
  EXPECT_EQ(argumentFromLine("'it'\\''s'"), "it's");
  EXPECT_EQ(argumentFromLine("''"), "");
  EXPECT_EQ(argumentFromLine("'a'b'"), "'a'b'");  // not one shell word: as it is
  EXPECT_EQ(argumentFromLine("don't"), "don't");
  EXPECT_EQ(argumentFromLine("'"), "'");
  EXPECT_EQ(argumentFromLine("--target=glsl"), "--target=glsl");
}

}  // namespace worker_test
