// Helpers for pass tests: build a material from inline JSON up to (and
// including) a named pass of the registry (pipeline/pass_registry.h), so a
// test can dump the IR, run one pass, and compare dumps — the Tint style of
// "input dump -> pass -> output dump".
#pragma once
#include <string>
#include <string_view>

#include <gtest/gtest.h>

#include "diag/diagnostics.h"
#include "ir/material.h"
#include "pipeline/pass_registry.h"
#include "ir/dump.h"

namespace substratec::test {

/// Runs the pipeline's passes in order up to and including `last` (a
/// registry name: "build-tree", "cull", "features", "shared-bases", ...) on
/// `json` with the default options, diagnostics into `d`; the material.
inline Material runPassesUntil(const std::string& json, std::string_view last, Diagnostics& d) {
  CompileOptions options;
  CompileResult result;
  PassContext context(json, options, d, result);
  if (!findPass(last)) ADD_FAILURE() << "no pass named " << last << " (the passes: " << passNames() << ")";
  else runPasses(context, last);
  return std::move(result.material);
}

/// runPassesUntil, failing the test (and returning an empty material) on any diagnostic.
inline Material runUntil(const std::string& json, std::string_view last) {
  Diagnostics d("test.json");
  Material m = runPassesUntil(json, last, d);
  EXPECT_FALSE(d.hasErrors()) << d.formatAll();
  return m;
}

/// The material as the pass tests mostly want it: analysed, not yet priced.
inline Material buildMaterial(const std::string& json) { return runUntil(json, "shared-bases"); }

/// The diagnostics a document produces through cull (formatted, one per line).
inline std::string diagnosticsOf(const std::string& json) {
  Diagnostics d("test.json");
  runPassesUntil(json, "cull", d);
  return d.formatAll();
}

/// `json` compiled with the default options (a failure to compile fails the
/// test, with its diagnostics; the result is then empty).
inline CompileResult compiled(const std::string& json) {
  Diagnostics d("test.json");
  auto r = compileText("test.json", json, {}, d);
  EXPECT_TRUE(r.has_value()) << d.formatAll();
  return r ? *r : CompileResult{};
}

/// Wraps `nodes` (the body of the "nodes" object) and `inputs` into a document.
inline std::string material(const std::string& nodes, const std::string& inputs = "{}",
                            const std::string& output = "root") {
  return R"({"format": "substrate-material/1", "name": "m", "inputs": )" + inputs + R"(, "nodes": {)" + nodes +
         R"(}, "output": ")" + output + R"("})";
}

}  // namespace substratec::test
