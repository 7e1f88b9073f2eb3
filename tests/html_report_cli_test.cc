// `substratec report --html` and `scene -o DIR`'s report.html (issue 24,
// docs/report.md "HTML"): what the command writes and refuses. The page's
// structure per example is a golden (golden_tests); how it renders is checked
// in a real browser (tests/html/check_html_report.py).
#include <algorithm>
#include <fstream>

#include <gtest/gtest.h>

#include "cli_util.h"

namespace html_report_cli_test {
using namespace substratec::clitest;

const fs::path kSource = SUBSTRATEC_SOURCE_DIR;

std::string example(const std::string& name) { return (kSource / "examples" / name).string(); }

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + 1)) ++n;
  return n;
}

TEST(HtmlReport, WritesOnePageOfEveryMaterialAndPrintsItsPath) {
  const fs::path dir = freshDir("html_report", "two");
  fs::create_directories(dir);
  const std::string page = (dir / "r.html").string();
  CliResult r = cli({"report", example("row12_simple.json"), example("worked_example_72.json"), "--budget", "16",
                     "--html", page});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, page + "\n");
  const std::string html = slurp(page);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_EQ(count(html, "<section class=\"material\""), 2u);
  // The worked example at 16 B simplifies: its authored tree beside the simplified one.
  EXPECT_EQ(count(html, "data-view=\"authored\""), 2u);
  EXPECT_EQ(count(html, "data-view=\"simplified\""), 1u);
  EXPECT_NE(html.find("data-node=\"fabric_a\""), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http://example"), std::string::npos);
  EXPECT_EQ(fs::directory_iterator(dir)->path().filename(), "r.html");  // no temporary left behind
}

TEST(HtmlReport, AMaterialThatDoesNotCompileIsOnThePageWithItsErrorsAndTheExitSaysSo) {
  const fs::path dir = freshDir("html_report", "bad");
  fs::create_directories(dir);
  std::ofstream(dir / "bad.json") << R"({"format": "substrate-material/1", "name": "bad",
  "nodes": {"root": {"kind": "slab", "roughness": 3}}, "output": "root"})";
  const std::string page = (dir / "r.html").string();
  CliResult r = cli({"report", (dir / "bad.json").string(), example("row12_simple.json"), "--html", page});
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("/nodes/root/roughness"), std::string::npos) << r.err;
  const std::string html = slurp(page);
  EXPECT_NE(html.find("did not compile"), std::string::npos);
  // The error links to the line of its pointer in the listed source.
  EXPECT_NE(html.find("<a href=\"#m0-src-L2\">"), std::string::npos) << html.substr(0, 4000);
  EXPECT_NE(html.find("<span id=\"m0-src-L2\""), std::string::npos);
  EXPECT_NE(html.find("<code class=\"pointer\">/nodes/root/roughness</code>"), std::string::npos);
  EXPECT_EQ(count(html, "<section class=\"material\""), 2u);
}

TEST(HtmlReport, PreviewsAndSweepNeedHtmlAndHtmlExcludesJson) {
  for (const char* flag : {"--previews", "--sweep"}) {
    CliResult r = cli({"report", example("row12_simple.json"), flag});
    EXPECT_EQ(r.status, 2) << flag << ": " << r.err;
    EXPECT_NE(r.err.find("--html"), std::string::npos) << r.err;
  }
  CliResult r = cli({"report", example("row12_simple.json"), "--json", "--html", "x.html"});
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST(HtmlReport, SceneWritesReportHtmlWithItsMaterialsSortedAgainstThePlatformBudget) {
  const fs::path dir = freshDir("html_report", "scene");
  fs::create_directories(dir);
  CliResult r = cli({"scene", (kSource / "examples/scenes/all_examples.json").string(), "-o", (dir / "out").string(),
                     "--platform", "mobile"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("report.html"), std::string::npos);
  const std::string html = slurp(dir / "out/report.html");
  EXPECT_NE(html.find("<section class=\"scene\""), std::string::npos);
  EXPECT_NE(html.find("Platform mobile:"), std::string::npos) << html.substr(0, 3000);
  // One bar per material, largest first.
  std::vector<int> bytes;
  for (std::size_t i = html.find("class=\"scene-bar\""); i != std::string::npos; i = html.find("class=\"scene-bar\"", i + 1)) {
    const std::size_t b = html.find(" B</text>", i);
    const std::size_t gt = html.rfind('>', b);
    bytes.push_back(std::stoi(html.substr(gt + 1, b - gt - 1)));
  }
  EXPECT_EQ(bytes.size(), count(html, "<section class=\"material\""));
  EXPECT_GE(bytes.size(), 10u);
  EXPECT_TRUE(std::is_sorted(bytes.rbegin(), bytes.rend()));
}

}  // namespace html_report_cli_test
