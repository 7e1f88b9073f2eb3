// Helpers for pass tests: build a material from inline JSON up to (and
// including) a named stage, so a test can dump the IR, run one pass, and
// compare dumps — the Tint style of "input dump -> pass -> output dump".
#pragma once
#include <string>

#include <gtest/gtest.h>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "ir/material.h"
#include "passes/build_tree.h"
#include "passes/build_values.h"
#include "passes/cull.h"
#include "passes/features.h"
#include "passes/resolve.h"
#include "passes/shared_bases.h"
#include "ir/dump.h"

namespace substratec::test {

enum class Stage { Tree, Cull, Features, Bases };

/// Runs parse, resolve, build-values, build-tree and then the passes up to
/// and including `last`. Fails the test (and returns an empty material) on
/// any diagnostic.
inline Material buildMaterial(const std::string& json, Stage last = Stage::Bases) {
  Material m;
  Diagnostics d("test.json");
  auto doc = parseJsonDocument(json, ReadLimits{}, d);
  std::optional<ResolvedDoc> r;
  if (doc) r = resolveDocument(*doc, d);
  if (r) {
    ValueTable t = buildValueDag(*r, m);
    if (buildSubstrateTree(*r, t, m, d)) {
      if (last >= Stage::Cull) cullStaticMatter(m, d);
      if (last >= Stage::Features) analyzeFeatures(m);
      if (last >= Stage::Bases) shareLocalBases(m);
    }
  }
  EXPECT_FALSE(d.hasErrors()) << d.formatAll();
  return m;
}

/// The diagnostics a document produces (formatted, one per line).
inline std::string diagnosticsOf(const std::string& json) {
  Material m;
  Diagnostics d("test.json");
  auto doc = parseJsonDocument(json, ReadLimits{}, d);
  std::optional<ResolvedDoc> r;
  if (doc) r = resolveDocument(*doc, d);
  if (r) {
    ValueTable t = buildValueDag(*r, m);
    if (buildSubstrateTree(*r, t, m, d)) cullStaticMatter(m, d);
  }
  return d.formatAll();
}

/// Wraps `nodes` (the body of the "nodes" object) and `inputs` into a document.
inline std::string material(const std::string& nodes, const std::string& inputs = "{}",
                            const std::string& output = "root") {
  return R"({"format": "substrate-material/1", "name": "m", "inputs": )" + inputs + R"(, "nodes": {)" + nodes +
         R"(}, "output": ")" + output + R"("})";
}

}  // namespace substratec::test
