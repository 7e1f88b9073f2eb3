// The command line as a new user meets it (cli/cli_options.h): --help of every
// command states the default of every option that has one, the unit of every
// number and the values of every choice; a number out of range is told its
// bounds as written, a word where a number goes is "not a number", and a
// command that does not exist is named, with the list of those that do.
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli/cli.h"
#include "cli_util.h"

using substratec::clitest::cli;
using substratec::clitest::CliResult;

namespace cli_usage_test {

const std::string kRow12 = std::string(SUBSTRATEC_SOURCE_DIR) + "/examples/row12_simple.json";
const std::vector<std::string> kCommands = {"report", "compile", "preview", "sweep", "accuracy", "stability", "import", "scene"};

/// The option lines of `command --help`: each option with the line CLI11
/// may wrap its description onto.
std::vector<std::string> optionLines(const std::string& command) {
  CliResult r = cli({command, "--help"});
  EXPECT_EQ(r.status, 0);
  std::vector<std::string> lines;
  std::istringstream in(r.out);
  bool options = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "Options:") options = true;
    else if (options && line.rfind("  -", 0) == 0) lines.push_back(line);
  }
  return lines;
}

// Every option that takes a number or a choice shows its default ("=256",
// "=chan2024", or what decides it: "=the file's settings.bytes_per_pixel"),
// unless it is required or has none (--max-error); numbers state their range.
TEST(CliUsage, EveryNumberAndChoiceOfEveryCommandShowsItsDefaultAndRange) {
  const std::regex typed(R"(^\s+(-\w,)?--[\w-]+ (INT|UINT|FLOAT|TEXT:\{|LONG))");

  std::size_t checked = 0;
  for (const std::string& command : kCommands) {
    for (const std::string& line : optionLines(command)) {
      SCOPED_TRACE(command + ": " + line);
      if (!std::regex_search(line, typed) || line.find("REQUIRED") != std::string::npos) continue;
      if (line.find("--max-error") != std::string::npos) continue;  // no default: the column is chosen only when asked
      ++checked;
      // The option's part of the line (its description follows after two spaces).
      const std::string head = line.substr(0, line.find("  ", line.find_first_not_of(' ')));
      EXPECT_NE(head.find('='), std::string::npos) << "no default shown";
      if (head.find("TEXT:{") == std::string::npos) EXPECT_NE(head.find(":in ["), std::string::npos) << "no range";
    }
  }
  EXPECT_GE(checked, 35u);
  std::printf("[ help     ] %zu numeric and choice options of %zu commands state their defaults\n", checked,
              kCommands.size());
}

TEST(CliUsage, HelpStatesUnitsChoicesAndDefaults) {
  const std::string compile = cli({"compile", "--help"}).out;
  for (const char* expected : {"--budget INT:in [8, 1024] bytes=the file's settings.bytes_per_pixel",
                               "--diffuse TEXT:{lambert,chan2018,chan2024,eon}=chan2024",
                               "--target TEXT:{glsl,hlsl,all}=all", "--max-input-size UINT:in [1, 2147483648] bytes=16777216",
                               "-j,--jobs INT:in [1, 256] threads=the machine's threads", "--precision TEXT:{float,half}=float"})
    EXPECT_NE(compile.find(expected), std::string::npos) << expected << "\n" << compile;
  const std::string preview = cli({"preview", "--help"}).out;
  for (const char* expected : {"--size INT:in [16, 2048] pixels=256", "--exposure FLOAT:in [-16, 16] stops=0",
                               "--env TEXT:{studio,sky,white}|FILE.hdr=studio"})
    EXPECT_NE(preview.find(expected), std::string::npos) << expected << "\n" << preview;
}

TEST(CliUsage, ANumberOutOfRangeIsToldItsBoundsAsWritten) {
  CliResult r = cli({"sweep", "--max-error", "1e40", kRow12});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--max-error: \"1e40\" is out of range [0, 1e+30]"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("000000"), std::string::npos) << r.err;
  r = cli({"report", "--budget", "4", kRow12});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--budget: \"4\" is out of range [8, 1024]"), std::string::npos) << r.err;
  r = cli({"report", "--max-input-size", "-1", kRow12});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("\"-1\" is out of range [1, 2147483648]"), std::string::npos) << r.err;
  r = cli({"report", "--budget", "99999999999999999999", kRow12});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("is out of range [8, 1024]"), std::string::npos) << r.err;
}

TEST(CliUsage, AWordWhereANumberGoesIsNotANumber) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"report", "--budget", "abc", kRow12}, {"preview", "--exposure", "bright", kRow12, "-o", "x.png"},
        {"sweep", "--max-error", "", kRow12}, {"stability", "--evaluations", "1k", kRow12}}) {
    SCOPED_TRACE(args[1] + " " + args[2]);
    CliResult r = cli(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find("is not a number"), std::string::npos) << r.err;
  }
  CliResult r = cli({"report", "--budget", "12.5", kRow12});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--budget: \"12.5\" is not a whole number in [8, 1024]"), std::string::npos) << r.err;
  // Decimal, as checked: 016 is sixteen bytes (CLI11 alone reads it as octal 14).
  r = cli({"report", "--json", "--budget", "016", kRow12});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["budget"]["bytes_per_pixel"], 16);
}

TEST(CliUsage, AnUnknownCommandIsNamedAndTheCommandsListed) {
  for (const std::vector<std::string>& args : {std::vector<std::string>{"frobnicate", kRow12}, {"reprot"}, {}}) {
    CliResult r = cli(args);
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.err.find(args.empty() ? "a command is required" : "unknown command \"" + args[0] + "\""),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("(the commands: report, compile, preview, render, sweep, accuracy, stability, import, scene)"), std::string::npos)
        << r.err;
  }
  EXPECT_EQ(cli({"--version"}).status, 0);  // an option first is not a command
}

}  // namespace cli_usage_test
