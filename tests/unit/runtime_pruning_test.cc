// Not parsing what no one calls (compiler/core/validate/runtime_pruning.h):
// what is removed and what stays, the runtime configuration two entries share
// or not, the SPIR-V of every entry of every example, imported and control
// material with the runtime pruned (the same words as whole), and how
// compileAndValidateShared keeps validation as strict as a whole compile.
#include "validate/runtime_pruning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/generate.h"
#include "pipeline/pipeline.h"
#include "util/parallel.h"

namespace substratec {
namespace {

namespace fs = std::filesystem;

std::size_t lineCount(const std::string& s) { return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n')); }

/// A fragment entry including the memory runtime file "rt.h" (and, when given, a material file).
struct Fixture {
  std::vector<RuntimeFile> runtime;
  std::string runtimeText;
  std::string materialText;
  ShaderSource entry;

  Fixture(std::string rt, std::string body, std::string material = "") : runtimeText(std::move(rt)), materialText(std::move(material)) {
    entry.name = "entry.frag";
    entry.text = "#version 450\n#extension GL_GOOGLE_include_directive : require\n";
    if (!materialText.empty()) entry.text += "#include \"mat.glsl\"\n";
    entry.text += "#include \"rt.h\"\nlayout(location = 0) out vec4 outColor;\nvoid main() {\n" + body + "\n}\n";
    runtime.push_back({"rt.h", runtimeText});
    entry.memoryFiles["rt.h"] = runtimeText;
    if (!materialText.empty()) entry.memoryFiles["mat.glsl"] = materialText;
  }
  std::string pruned(const RuntimePruning& p) const {
    auto it = p.prunedFiles.find("rt.h");
    return it == p.prunedFiles.end() ? runtimeText : it->second;
  }
};

TEST(RuntimePruning, AFunctionNothingReachesIsBlankedOutAndWhatIsReachedStays) {
  Fixture f("float twice(float x) { return 2.0 * x; }\n"
            "float used(float x) {\n  return twice(x);\n}\n"
            "float unused(float x) {\n  return x * 3.0;\n}\n",
            "outColor = vec4(used(1.0));");
  const RuntimePruning p = pruneRuntime(f.entry, f.runtime);
  ASSERT_TRUE(p.usable);
  EXPECT_EQ(p.definitions, 3u);
  EXPECT_EQ(p.removed, 1u);
  const std::string text = f.pruned(p);
  EXPECT_NE(text.find("float used(float x)"), std::string::npos);
  EXPECT_NE(text.find("float twice(float x)"), std::string::npos);  // reached through used()
  EXPECT_EQ(text.find("unused"), std::string::npos);
  EXPECT_EQ(lineCount(text), lineCount(f.runtimeText));  // line numbers hold
  EXPECT_TRUE(compileAndValidate(withPrunedRuntime(f.entry, p)).ok);
}

TEST(RuntimePruning, EveryOverloadOfAReachedNameStays) {
  Fixture f("float pick(float x) { return x; }\nvec2 pick(vec2 x) { return x; }\nfloat other() { return 1.0; }\n",
            "outColor = vec4(pick(1.0));");
  const RuntimePruning p = pruneRuntime(f.entry, f.runtime);
  EXPECT_EQ(p.removed, 1u);
  EXPECT_NE(f.pruned(p).find("vec2 pick(vec2 x)"), std::string::npos);
}

TEST(RuntimePruning, NamesInPreprocessorLinesAndDeclarationsAreRoots) {
  Fixture f("#define CALL_HELPER(x) helper(x)\n"
            "float helper(float x) { return x; }\n"
            "float fromPrototype(float x);\n"
            "float fromPrototype(float x) { return x; }\n"
            "const float kValue = fromConstant(1.0);\n"
            "float fromConstant(float x) { return x; }\n",
            "outColor = vec4(CALL_HELPER(1.0));");
  const RuntimePruning p = pruneRuntime(f.entry, f.runtime);
  ASSERT_TRUE(p.usable);
  EXPECT_EQ(p.removed, 0u);
}

TEST(RuntimePruning, ADefinitionWithAPreprocessorLineInsideIsNeverRemoved) {
  Fixture f("float guarded(float x) {\n#if 1\n  return x;\n#endif\n}\nfloat plain() { return 0.0; }\n",
            "outColor = vec4(1.0);");
  const RuntimePruning p = pruneRuntime(f.entry, f.runtime);
  EXPECT_EQ(p.definitions, 1u);
  EXPECT_EQ(p.removed, 1u);
  EXPECT_NE(f.pruned(p).find("guarded"), std::string::npos);
}

TEST(RuntimePruning, TokenPastingOrAnUnresolvedIncludeTurnsItOff) {
  Fixture pasting("#define NAME(a) sub_##a\nfloat sub_x() { return 1.0; }\n", "outColor = vec4(NAME(x)());");
  EXPECT_FALSE(pruneRuntime(pasting.entry, pasting.runtime).usable);
  EXPECT_TRUE(compileAndValidateShared(pasting.entry, pasting.runtime).ok);  // compiled whole
  Fixture missing("float f() { return 1.0; }\n", "outColor = vec4(1.0);");
  missing.entry.text = "#include \"elsewhere.h\"\n" + missing.entry.text;
  EXPECT_FALSE(pruneRuntime(missing.entry, missing.runtime).usable);
}

// What the runtime's definitions see: two materials that differ only in their
// own names, inputs and closure counts share a configuration; a feature macro,
// the language or a preamble define separates them.
TEST(RuntimePruning, TheConfigurationIsWhatTheRuntimeSeesNotTheMaterialsOwnNames) {
  const std::string rt = "float feature() {\n#if SUBSTRATE_USE_X\n  return 1.0;\n#else\n  return 0.0;\n#endif\n}\n"
                         "float unused() { return 2.0; }\nfloat readsSpare() { return spare; }\n";
  auto material = [](const std::string& name, int count, int useX) {
    return "#ifndef MATERIAL_" + name + "\n#define MATERIAL_" + name + " 1\n#define SUBSTRATE_USE_X " +
           std::to_string(useX) + "\n#define " + name + "_COUNT " + std::to_string(count) + "\n" +
           "layout(set = 1, binding = 0, std140) uniform " + name + "_Inputs { vec4 i_" + name + "; } " + name +
           "_inputs;\nfloat " + name + "_evaluate(float v[" + name + "_COUNT]) { return v[0] + " + name +
           "_inputs.i_" + name + ".x; }\n#endif\n";
  };
  const std::string body = "float v[1];\nv[0] = 1.0;\noutColor = vec4(feature());";
  Fixture a(rt, body, material("alpha", 1, 1));
  Fixture b(rt, body, material("beta", 3, 1));
  Fixture c(rt, body, material("gamma", 1, 0));
  const RuntimePruning pa = pruneRuntime(a.entry, a.runtime), pb = pruneRuntime(b.entry, b.runtime),
                       pc = pruneRuntime(c.entry, c.runtime);
  ASSERT_TRUE(pa.usable && pb.usable && pc.usable);
  EXPECT_EQ(pa.configuration, pb.configuration);
  EXPECT_NE(pa.configuration, pc.configuration);
  Fixture d(rt, body, material("alpha", 1, 1));
  d.entry.defines.push_back({"SUBSTRATE_EXTRA", "1"});
  EXPECT_NE(pa.configuration, pruneRuntime(d.entry, d.runtime).configuration);
  Fixture e(rt, body, material("alpha", 1, 1));
  e.entry.hlsl16BitTypes = true;
  EXPECT_NE(pa.configuration, pruneRuntime(e.entry, e.runtime).configuration);
  // What a material declares is in the configuration when the runtime spells its name, not otherwise.
  Fixture f(rt, body, material("alpha", 1, 1) + "const float spare = 1.0;\n");
  EXPECT_NE(pa.configuration, pruneRuntime(f.entry, f.runtime).configuration);
  Fixture g(rt, body, material("alpha", 1, 1) + "const float spare_twin = 1.0;\nfloat unused_twin() { return 0.0; }\n");
  EXPECT_EQ(pa.configuration, pruneRuntime(g.entry, g.runtime).configuration);
  Fixture h(rt, body, material("alpha", 1, 1) + "#define unused unused_renamed\n");
  EXPECT_NE(pa.configuration, pruneRuntime(h.entry, h.runtime).configuration);
}

// compileAndValidateShared is as strict as a whole compile: a runtime whose
// uncalled function does not compile fails every entry, every time, with the
// whole text's diagnostics.
TEST(RuntimePruning, SharedCompilesFailOnAnErrorInAFunctionNoEntryCalls) {
  Fixture f("float used() { return 1.0; }\nfloat broken() { return undeclared_name; }\n",
            "outColor = vec4(used());");
  f.entry.defines.push_back({"SUBSTRATE_TEST_BROKEN_RUNTIME", "1"});
  EXPECT_EQ(pruneRuntime(f.entry, f.runtime).removed, 1u);
  EXPECT_TRUE(compileAndValidate(withPrunedRuntime(f.entry, pruneRuntime(f.entry, f.runtime))).ok);
  for (int i = 0; i < 2; ++i) {
    const ShaderValidation v = compileAndValidateShared(f.entry, f.runtime);
    EXPECT_FALSE(v.ok);
    EXPECT_NE(v.log.find("undeclared_name"), std::string::npos) << v.log;
  }
}

TEST(RuntimePruning, TheSecondEntryOfAConfigurationIsCompiledPrunedAndAFailureThereIsCompiledAgainWhole) {
  const std::string rt = "float used() { return 1.0; }\nfloat spare() { return 2.0; }\n";
  Fixture first(rt, "outColor = vec4(used());");
  first.entry.defines.push_back({"SUBSTRATE_TEST_SHARED_RUNTIME", "1"});
  const SharedCompileCounts before = sharedCompileCounts();
  ASSERT_TRUE(compileAndValidateShared(first.entry, first.runtime).ok);
  const SharedCompileCounts afterFirst = sharedCompileCounts();
  EXPECT_EQ(afterFirst.whole, before.whole + 1);
  EXPECT_EQ(afterFirst.pruned, before.pruned);

  Fixture second(rt, "outColor = vec4(used() + 1.0);");  // the same configuration: the entry's main is not in it
  second.entry.defines = first.entry.defines;
  ASSERT_TRUE(compileAndValidateShared(second.entry, second.runtime).ok);
  EXPECT_EQ(sharedCompileCounts().pruned, afterFirst.pruned + 1);

  Fixture bad(rt, "outColor = vec4(used() + missing_in_entry);");
  bad.entry.defines = first.entry.defines;
  const ShaderValidation whole = compileAndValidate(bad.entry);
  const SharedCompileCounts beforeBad = sharedCompileCounts();
  const ShaderValidation shared = compileAndValidateShared(bad.entry, bad.runtime);
  EXPECT_FALSE(shared.ok);
  EXPECT_EQ(shared.log, whole.log);
  EXPECT_EQ(sharedCompileCounts().retried, beforeBad.retried + 1);
}

/// The materials the repository holds as files: every example and bench
/// control, and every 6th of the importer's golden imports of the MaterialX
/// and glTF corpora (all 542 would take a minute of CPU).
std::vector<fs::path> repositoryMaterials() {
  const fs::path root = SUBSTRATEC_SOURCE_DIR;
  std::vector<fs::path> paths, imported;
  for (const char* dir : {"examples", "bench/materials"})
    for (const auto& e : fs::directory_iterator(root / dir))
      if (e.path().extension() == ".json") paths.push_back(e.path());
  for (const auto& e : fs::recursive_directory_iterator(root / "tests/import/golden"))
    if (e.path().extension() == ".json") imported.push_back(e.path());
  std::sort(imported.begin(), imported.end());
  for (std::size_t i = 0; i < imported.size(); i += 6) paths.push_back(imported[i]);
  std::sort(paths.begin(), paths.end());
  return paths;
}

// The property that makes pruning exact for what is written: glslang drops
// uncalled functions, so the module is the same word for word.
TEST(RuntimePruning, EveryEntryOfEveryRepositoryMaterialCompilesToTheSameSpirvPruned) {
  const std::vector<fs::path> paths = repositoryMaterials();
  std::mutex mutex;
  std::size_t materials = 0, entries = 0, definitions = 0, removed = 0;
  std::vector<std::string> failures;
  parallelFor(paths.size(), 0, [&](std::size_t i) {
    Diagnostics diagnostics(paths[i].string());
    const std::optional<CompileResult> r = compileFile(paths[i].string(), CompileOptions{}, diagnostics);
    if (!r) return;  // an imported material with its own errors is import_tests' business
    const Generated g = generateFiles(*r, GenerateOptions{});
    for (const ShaderSource& src : entrySources(g)) {
      const RuntimePruning p = pruneRuntime(src, runtimeFiles());
      const ShaderValidation whole = compileAndValidate(src);
      const ShaderValidation pruned = compileAndValidate(withPrunedRuntime(src, p));
      std::lock_guard<std::mutex> lock(mutex);
      ++entries;
      definitions += p.definitions;
      removed += p.removed;
      if (!p.usable || !whole.ok || !pruned.ok || whole.spirv != pruned.spirv)
        failures.push_back(paths[i].filename().string() + ": " + src.name + (p.usable ? "" : " (not prunable)") +
                           (whole.ok ? "" : " (whole fails)") + (pruned.ok ? "" : " (pruned fails: " + pruned.log + ")"));
    }
    std::lock_guard<std::mutex> lock(mutex);
    ++materials;
  });
  EXPECT_TRUE(failures.empty()) << failures.size() << " entries differ, first: " << failures.front();
  ASSERT_GE(materials, 100u);
  ASSERT_EQ(entries, 4 * materials);
  EXPECT_GT(removed, definitions / 4);  // it does remove something
  std::printf("[ pruning  ] %zu materials, %zu entries: %zu of %zu runtime definitions removed (%.0f %%)\n", materials,
              entries, removed, definitions, 100.0 * static_cast<double>(removed) / static_cast<double>(definitions));
}

}  // namespace
}  // namespace substratec
