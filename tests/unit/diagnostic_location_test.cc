// Diagnostics located at line:col: the reader's table maps a JSON pointer to
// where its value starts (format/json_document.cc), and Diagnostics prints
// `file:line:col: error: message [/pointer]` (diag/diagnostics.cc).
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "diag/diagnostics.h"
#include "format/json_document.h"

namespace substratec::diagloc {

/// "line:col" of `pointer` in `json` (parsed with `limits`), or "unparsed".
std::string where(const std::string& json, const std::string& pointer, const ReadLimits& limits = {}) {
  Diagnostics d("t.json");
  if (!parseJsonDocument(json, limits, d) || !d.locator()) return "unparsed: " + d.formatAll();
  int line = 0, column = 0;
  if (!d.locator()->locate(pointer, line, column)) return "not located";
  return std::to_string(line) + ":" + std::to_string(column);
}

/// Checks that `pointer`'s value starts with `expected` in the text, by
/// finding line:col in `json` independently of the table (counted cases).
int gChecked = 0;
void expectValueAt(const std::string& json, const std::string& pointer, const std::string& expected) {
  SCOPED_TRACE(pointer);
  Diagnostics d("t.json");
  ASSERT_TRUE(parseJsonDocument(json, ReadLimits{}, d)) << d.formatAll();
  int line = 0, column = 0;
  ASSERT_TRUE(d.locator()->locate(pointer, line, column));
  std::size_t at = 0;
  for (int l = 1; l < line; ++l) at = json.find('\n', at) + 1;
  EXPECT_EQ(json.compare(at + static_cast<std::size_t>(column) - 1, expected.size(), expected), 0)
      << line << ":" << column << " holds " << json.substr(at + static_cast<std::size_t>(column) - 1, 20);
  ++gChecked;
}

TEST(DiagnosticLocation, NestedObjectsAndArrays) {
  const std::string json =
      "{\n"
      "  \"a\": {\"b\": [10, [20, {\"c\": true}], \"s\"]},\n"
      "  \"n\": null,\n"
      "\t\"t\": [ ]\n"
      "}\n";
  expectValueAt(json, "", "{\n");
  expectValueAt(json, "/a", "{\"b\"");
  expectValueAt(json, "/a/b", "[10");
  expectValueAt(json, "/a/b/0", "10,");
  expectValueAt(json, "/a/b/1", "[20");
  expectValueAt(json, "/a/b/1/0", "20,");
  expectValueAt(json, "/a/b/1/1", "{\"c\"");
  expectValueAt(json, "/a/b/1/1/c", "true}");
  expectValueAt(json, "/a/b/2", "\"s\"]");
  expectValueAt(json, "/n", "null");
  expectValueAt(json, "/t", "[ ]");  // after a tab: a tab is one column
  EXPECT_EQ(where(json, "/t"), "4:7");
  EXPECT_EQ(where(json, "/a/b/1/1/c"), "2:30");
  std::printf("[ located  ] %d pointers checked against the text\n", gChecked);
}

TEST(DiagnosticLocation, MissingMembersLocateTheirContainer) {
  const std::string json = "{\n  \"a\": {\n    \"b\": [1, 2]\n  }\n}";
  EXPECT_EQ(where(json, "/a"), "2:8");
  EXPECT_EQ(where(json, "/a/missing"), "2:8");          // a missing member: its object
  EXPECT_EQ(where(json, "/a/missing/deeper/0"), "2:8");
  EXPECT_EQ(where(json, "/a/b/2"), "3:10");             // past the end: the array
  EXPECT_EQ(where(json, "/a/b/01"), "3:10");            // not an index (leading zero)
  EXPECT_EQ(where(json, "/a/b/-"), "3:10");
  EXPECT_EQ(where(json, "/a/b/1/x"), "3:14");           // below a scalar: the scalar
  EXPECT_EQ(where(json, "/zzz"), "1:1");
}

TEST(DiagnosticLocation, EscapedKeys) {
  // RFC 6901 escapes in the pointer (~0 '~', ~1 '/'), JSON escapes in the key.
  const std::string json = "{\"a/b\": 1, \"m~n\": 2, \"q\\\"\\u00e9\": 3, \"~1\": 4, \"\": 5}";
  EXPECT_EQ(where(json, "/a~1b"), "1:9");
  EXPECT_EQ(where(json, "/m~0n"), "1:19");
  EXPECT_EQ(where(json, "/q\"\xc3\xa9"), "1:35");
  EXPECT_EQ(where(json, "/~01"), "1:44");
  EXPECT_EQ(where(json, "/"), "1:51");   // the member named ""
  EXPECT_EQ(where(json, "/a/b"), "1:1");  // "a" is not a member
  EXPECT_EQ(pointerToken("a/b~c"), "a~1b~0c");
}

TEST(DiagnosticLocation, LinesAndCrlf) {
  const std::string lf = "{\n\"x\":\n\n  [1,\n   2]}";
  std::string crlf;
  for (char c : lf) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_EQ(where(lf, "/x/1"), "5:4");
  EXPECT_EQ(where(crlf, "/x/1"), "5:4");  // '\r' ends no line and, before '\n', shifts no column
  EXPECT_EQ(where(crlf, "/x"), "4:3");
  // The same numbers as the syntax errors' lineColumnOf.
  int line = 0, column = 0;
  lineColumnOf(crlf, crlf.find('2'), line, column);
  EXPECT_EQ(std::to_string(line) + ":" + std::to_string(column), "5:4");
}

TEST(DiagnosticLocation, LargeObjectsUseTheirKeyIndex) {
  std::string json = "{";
  for (int i = 0; i < 200; ++i) json += (i ? ",\n\"k" : "\n\"k") + std::to_string(i) + "\": " + std::to_string(i);
  json += "\n}";
  for (int i : {0, 15, 16, 17, 199}) EXPECT_EQ(where(json, "/k" + std::to_string(i)), std::to_string(i + 2) + ":" + std::to_string(5 + std::to_string(i).size() + 1)) << i;
  EXPECT_EQ(where(json, "/k200"), "1:1");
}

TEST(DiagnosticLocation, DiagnosticsPrintLineColumnAndPointer) {
  Diagnostics d("m.json");
  ASSERT_TRUE(parseJsonDocument("{\n  \"nodes\": {\"a\": 1}\n}", ReadLimits{}, d));
  d.error("/nodes/a", "bad value");
  d.warning("/nodes/b", "no such node");
  d.error("", "about the document");
  d.errorAt(0, 0, "cannot read");
  EXPECT_EQ(d.formatAll(),
            "m.json:2:18: error: bad value [/nodes/a]\n"
            "m.json:2:12: warning: no such node [/nodes/b]\n"
            "m.json:1:1: error: about the document [/]\n"
            "m.json: error: cannot read\n");
  Diagnostics none("m.json");  // no document parsed: the pointer alone
  none.error("/nodes/a", "bad value");
  EXPECT_EQ(none.formatAll(), "m.json: error: bad value [/nodes/a]\n");
  Diagnostics unnamed("");  // text without a file name
  ASSERT_TRUE(parseJsonDocument("\n [1]", ReadLimits{}, unnamed));
  unnamed.error("/0", "x");
  EXPECT_EQ(unnamed.formatAll(), "<stdin>:2:3: error: x [/0]\n");
}

TEST(DiagnosticLocation, ParseTimeErrorsAtTheirToken) {
  Diagnostics d("m.json");
  EXPECT_FALSE(parseJsonDocument("{\"a\": {\"b\": 1,\n   \"b\": 2}}", ReadLimits{}, d));
  EXPECT_EQ(d.formatAll(), "m.json:2:4: error: duplicate key \"b\" [/a/b]\n");  // the second one
  ReadLimits small;
  small.maxStringBytes = 3;
  Diagnostics s("m.json");
  EXPECT_FALSE(parseJsonDocument("[\"ok\",\n  \"long\"]", small, s));
  EXPECT_EQ(s.formatAll(),
            "m.json:2:3: error: string of 4 bytes is longer than the limit of 3 bytes (the string-length limit) [/1]\n");
}

// Deep nesting is as cheap per value as flat text: no pointer strings are
// built while parsing, and locating walks one level per token.
TEST(DiagnosticLocation, DeepNestingStaysLinear) {
  ReadLimits deep;
  deep.maxNesting = 600;
  const int depth = 512, leaves = 100000;
  std::string json, ptr;
  for (int i = 0; i < depth; ++i) {
    json += i % 2 ? "[" : "{\"k\":";
    ptr += i % 2 ? "/0" : "/k";
  }
  std::string leafArray = "[";
  for (int i = 0; i < leaves; ++i) leafArray += i ? ",7" : "7";
  leafArray += "]";
  json += leafArray;
  for (int i = depth - 1; i >= 0; --i) json += i % 2 ? "]" : "}";
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(where(json, ptr + "/" + std::to_string(leaves - 1), deep),
            "1:" + std::to_string(json.find(leafArray) + 2 * leaves));
  const double deepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_EQ(where(leafArray, "/" + std::to_string(leaves - 1)), "1:" + std::to_string(2 * leaves));
  const double flatMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count();
  std::printf("[ deep     ] %d levels over %d values: %.1f ms (flat: %.1f ms)\n", depth, leaves, deepMs, flatMs);
  EXPECT_LT(deepMs, 10 * flatMs + 50);
  // Many refused values at depth: each diagnostic's pointer is O(depth), and
  // the error limit bounds how many are built.
  ReadLimits tiny = deep;
  tiny.maxStringBytes = 0;
  std::string strings = json.substr(0, json.find(leafArray)) + "[";
  for (int i = 0; i < leaves; ++i) strings += i ? ",\"x\"" : "\"x\"";
  strings += "]" + json.substr(json.find(leafArray) + leafArray.size());
  Diagnostics d("t.json");
  const auto t2 = std::chrono::steady_clock::now();
  EXPECT_FALSE(parseJsonDocument(strings, tiny, d));
  const double errMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t2).count();
  EXPECT_EQ(d.errorCount(), 50u);
  EXPECT_NE(d.formatAll().find("too many errors"), std::string::npos);
  EXPECT_LT(errMs, 20 * flatMs + 100);
}

/// The byte `line:column` names in `text` (npos if there is none).
std::size_t offsetOf(const std::string& text, int line, int column) {
  std::size_t at = 0;
  for (int l = 1; l < line; ++l) {
    at = text.find('\n', at);
    if (at == std::string::npos) return at;
    ++at;
  }
  return at + static_cast<std::size_t>(column) - 1;
}

/// Locates every value of `doc` (parsed from `text`) by its pointer and checks
/// that the byte there starts a value of its type; returns how many it checked.
std::size_t checkEveryValue(const std::string& text, const Json& doc, const SourceLocator& at,
                            const std::string& pointer) {
  int line = 0, column = 0;
  EXPECT_TRUE(at.locate(pointer, line, column));
  const std::size_t o = offsetOf(text, line, column);
  const char c = o < text.size() ? text[o] : '\0';
  const char want = doc.is_object() ? '{' : doc.is_array() ? '[' : doc.is_string() ? '"' : doc.is_null() ? 'n'
                    : doc.is_boolean() ? (doc.get<bool>() ? 't' : 'f') : '0';
  if (want == '0') EXPECT_TRUE(c == '-' || (c >= '0' && c <= '9')) << pointer << " at " << line << ":" << column;
  else EXPECT_EQ(c, want) << pointer << " at " << line << ":" << column;
  std::size_t n = 1;
  if (doc.is_object())
    for (auto it = doc.begin(); it != doc.end(); ++it)
      n += checkEveryValue(text, *it, at, pointer + "/" + pointerToken(it.key()));
  if (doc.is_array())
    for (std::size_t i = 0; i < doc.size(); ++i) n += checkEveryValue(text, doc[i], at, pointer + "/" + std::to_string(i));
  return n;
}

// Every value of every example, bad input, warning case and import-corpus
// document, and of mutations of the examples (whitespace, CRLF, tabs,
// escapes): located where a value of its type starts.
TEST(DiagnosticLocation, EveryValueOfEveryDocumentIsLocated) {
  namespace fs = std::filesystem;
  const fs::path root = SUBSTRATEC_SOURCE_DIR;
  std::vector<std::string> texts;
  for (const char* dir : {"examples", "tests/bad", "tests/warnings", "tests/import/corpus/gltf", "examples/scenes",
                          "examples/platforms"})
    for (const auto& e : fs::directory_iterator(root / dir))
      if (e.is_regular_file() && e.path().extension() == ".json") {
        std::ifstream in(e.path(), std::ios::binary);
        std::ostringstream s;
        s << in.rdbuf();
        texts.push_back(s.str());
      }
  std::mt19937 rng(17);
  const std::size_t files = texts.size();
  for (std::size_t i = 0; i < files && i < 40; ++i) {  // reformatted twins: same values, other places
    std::string t;
    for (char c : texts[i]) {
      if (c == '\n') t += rng() % 2 ? "\r\n" : "\n\t \n";
      else if ((c == ',' || c == ':') && rng() % 3 == 0) t += std::string(1, c) + "\n\t";
      else t += c;
    }
    texts.push_back(std::move(t));
  }
  std::size_t parsed = 0, values = 0;
  for (const std::string& text : texts) {
    Diagnostics d("t.json");
    auto doc = parseJsonDocument(text, ReadLimits{}, d);
    if (!doc) continue;
    ++parsed;
    values += checkEveryValue(text, *doc, *d.locator(), "");
  }
  std::printf("[ located  ] %zu values of %zu documents (of %zu texts), each at a byte of its type\n", values,
              parsed, texts.size());
  EXPECT_GE(parsed, 100u);
}

}  // namespace substratec::diagloc
