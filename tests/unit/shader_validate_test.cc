// Tests for in-process shader validation (compiler/core/validate/shader_validate.h):
// GLSL and HLSL through glslang -> SPIR-V 1.5 -> spirv-val -> spirv-opt, the
// failure modes (syntax error, wrong HLSL entry point, link error, missing
// include), #include through include dirs and relative to the including file,
// instruction counts, determinism and concurrent use.
#include "validate/shader_validate.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace substratec {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTrivialFrag = R"(#version 450
layout(location = 0) in vec3 vColor;
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vec4(vColor, 1.0);
}
)";

constexpr const char* kHlslPixel = R"(
struct Params { float4 tint; };
[[vk::push_constant]] ConstantBuffer<Params> params;
float4 main(float3 color : COLOR0) : SV_Target0 {
  return float4(color, 1.0) * params.tint;
}
)";

ShaderSource glsl(const std::string& name, const std::string& text, ShaderStage stage = ShaderStage::Fragment) {
  ShaderSource s;
  s.name = name;
  s.text = text;
  s.language = ShaderLanguage::Glsl;
  s.stage = stage;
  return s;
}

ShaderSource hlsl(const std::string& name, const std::string& text, const std::string& entry = "main") {
  ShaderSource s;
  s.name = name;
  s.text = text;
  s.language = ShaderLanguage::Hlsl;
  s.stage = ShaderStage::Fragment;
  s.entryPoint = entry;
  return s;
}

// A fresh directory under the system temp dir, removed with the object.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "substratec_shader_XXXXXX").string();
    char* made = mkdtemp(pattern.data());
    if (made) path_ = made;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  void write(const std::string& rel, const std::string& text) const {
    fs::path p = path_ / rel;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
  }

 private:
  fs::path path_;
};

TEST(ShaderValidate, TrivialGlslFragmentShaderValidates) {
  ShaderValidation v = compileAndValidate(glsl("trivial.frag", kTrivialFrag), {.optimize = true});
  ASSERT_TRUE(v.ok) << v.log;
  EXPECT_EQ(v.log, "");
  ASSERT_GE(v.spirv.size(), 5u);
  EXPECT_EQ(v.spirv[0], 0x07230203u);  // SPIR-V magic
  EXPECT_EQ(v.spirv[1], 0x00010500u);  // SPIR-V 1.5
  EXPECT_GT(v.instructionCount, 0u);
  EXPECT_GT(v.optimizedInstructionCount, 0u);
  EXPECT_EQ(v.instructionCount, spirvInstructionCount(v.spirv));
  EXPECT_EQ(v.optimizedInstructionCount, spirvInstructionCount(v.optimized));
}

TEST(ShaderValidate, SaysWhereItsTimeWentPhaseByPhase) {
  for (const ShaderSource& src : {glsl("trivial.frag", kTrivialFrag), hlsl("pixel.hlsl", kHlslPixel)}) {
    const ShaderValidation v = compileAndValidate(src);
    ASSERT_TRUE(v.ok) << v.log;
    EXPECT_GT(v.timings.parseMs, 0.0) << src.name;
    EXPECT_GT(v.timings.linkMs, 0.0) << src.name;
    EXPECT_GT(v.timings.spirvMs, 0.0) << src.name;
    EXPECT_GT(v.timings.validateMs, 0.0) << src.name;
  }
  // A shader that does not parse spends nothing in the later phases.
  const ShaderValidation bad = compileAndValidate(glsl("bad.frag", "#version 450\nvoid main() { oops }\n"));
  ASSERT_FALSE(bad.ok);
  EXPECT_GT(bad.timings.parseMs, 0.0);
  EXPECT_EQ(bad.timings.linkMs + bad.timings.spirvMs + bad.timings.validateMs, 0.0);
}

TEST(ShaderValidate, OptimizedCopyOnlyOnRequest) {
  ShaderValidation v = compileAndValidate(glsl("trivial.frag", kTrivialFrag));
  ASSERT_TRUE(v.ok) << v.log;
  EXPECT_GT(v.instructionCount, 0u);
  EXPECT_TRUE(v.optimized.empty());
  EXPECT_EQ(v.optimizedInstructionCount, 0u);
}

TEST(ShaderValidate, VertexAndComputeStagesValidate) {
  ShaderValidation vert = compileAndValidate(glsl("t.vert", R"(#version 450
layout(location = 0) in vec3 pos;
void main() { gl_Position = vec4(pos, 1.0); }
)",
                                                  ShaderStage::Vertex));
  EXPECT_TRUE(vert.ok) << vert.log;
  ShaderValidation comp = compileAndValidate(glsl("t.comp", R"(#version 450
layout(local_size_x = 8) in;
layout(std430, set = 0, binding = 0) buffer Data { float v[]; } data;
void main() { data.v[gl_GlobalInvocationID.x] *= 2.0; }
)",
                                                  ShaderStage::Compute));
  EXPECT_TRUE(comp.ok) << comp.log;
}

TEST(ShaderValidate, GlslSyntaxErrorNamesFileAndLine) {
  ShaderValidation v = compileAndValidate(glsl("m.forward.frag", R"(#version 450
layout(location = 0) out vec4 outColor;
void main() {
  outColor = vec4(1.0) +;
}
)"));
  EXPECT_FALSE(v.ok);
  EXPECT_TRUE(v.spirv.empty());
  EXPECT_NE(v.log.find("m.forward.frag:4"), std::string::npos) << v.log;
}

TEST(ShaderValidate, GlslWithoutVersionGets450) {
  ShaderValidation v = compileAndValidate(glsl("nov.frag", R"(
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(1.0); }
)"));
  EXPECT_TRUE(v.ok) << v.log;
}

TEST(ShaderValidate, HlslPixelShaderWithMainValidates) {
  ShaderValidation v = compileAndValidate(hlsl("m.forward.ps.hlsl", kHlslPixel), {.optimize = true});
  ASSERT_TRUE(v.ok) << v.log;
  EXPECT_GT(v.instructionCount, 0u);
  EXPECT_LE(v.optimizedInstructionCount, v.instructionCount);
}

TEST(ShaderValidate, HlslStructOfResourcesIsLegalized) {
  // A struct holding a texture and a sampler: glslang's raw output has an
  // OpTypeStruct with opaque members, which Vulkan forbids, until its
  // legalization passes scalarize it.
  ShaderValidation v = compileAndValidate(hlsl("tex.ps.hlsl", R"(
[[vk::binding(0, 0)]] Texture2D<float4> albedo;
[[vk::binding(1, 0)]] SamplerState linearSampler;
struct Mat { Texture2D<float4> t; SamplerState s; float k; };
float4 fetch(Mat m, float2 uv) { return m.t.Sample(m.s, uv) * m.k; }
float4 main(float2 uv : TEXCOORD0) : SV_Target0 {
  Mat m;
  m.t = albedo;
  m.s = linearSampler;
  m.k = 0.5;
  return fetch(m, uv);
}
)"));
  // Valid only because legalization ran: the raw module is rejected. The module kept is the
  // legalized one, and spirv-val accepts it on its own.
  ASSERT_TRUE(v.ok) << v.log;
  EXPECT_EQ(v.instructionCount, spirvInstructionCount(v.spirv));
  std::string log;
  EXPECT_TRUE(spirvValidates(v.spirv, &log)) << log;
}

TEST(ShaderValidate, EveryModuleKeptIsOneSpirvValAcceptsWhetherOrNotLegalizationRan) {
  // An HLSL module spirv-val accepts raw is kept without a second validation (it is the same
  // module); one it rejects is legalized and validated again. Either way what is kept validates.
  for (const ShaderSource& src : {hlsl("pixel.hlsl", kHlslPixel), glsl("trivial.frag", kTrivialFrag)}) {
    const ShaderValidation v = compileAndValidate(src);
    ASSERT_TRUE(v.ok) << v.log;
    std::string log;
    EXPECT_TRUE(spirvValidates(v.spirv, &log)) << src.name << ": " << log;
  }
  std::string log;
  EXPECT_FALSE(spirvValidates({0x07230203u, 0x00010500u, 0, 1, 0, 0x00ffffffu}, &log));  // a broken module
  EXPECT_NE(log, "");
}

TEST(ShaderValidate, HlslStorageBuffersUseTheStorageBufferClass) {
  // glslang 12's HLSL front end would emit Uniform + BufferBlock, which
  // SPIR-V 1.4+ (and spirv-val for Vulkan 1.2) rejects.
  ShaderSource s = hlsl("buffers.hlsl", R"(
[[vk::binding(0, 0)]] StructuredBuffer<float> input;
[[vk::binding(1, 0)]] RWStructuredBuffer<float> output;
[[vk::binding(2, 0)]] ByteAddressBuffer raw;
[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) { output[id.x] = input[id.x] * asfloat(raw.Load(id.x * 4)); }
)");
  s.stage = ShaderStage::Compute;
  ShaderValidation v = compileAndValidate(s);
  EXPECT_TRUE(v.ok) << v.log;
}

TEST(ShaderValidate, HlslNamedEntryPointValidates) {
  std::string text = kHlslPixel;
  text.replace(text.find("main("), 4, "PSMain");
  ShaderValidation v = compileAndValidate(hlsl("ps.hlsl", text, "PSMain"));
  EXPECT_TRUE(v.ok) << v.log;
}

TEST(ShaderValidate, HlslWrongEntryPointFails) {
  // The source defines `main`; asking for `PSMain` must fail (glslang alone
  // only warns at link time and emits a module that passes spirv-val).
  ShaderValidation v = compileAndValidate(hlsl("ps.hlsl", kHlslPixel, "PSMain"));
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.log.find("PSMain"), std::string::npos) << v.log;

  std::string text = kHlslPixel;
  text.replace(text.find("main("), 4, "PSMain");
  ShaderValidation w = compileAndValidate(hlsl("ps.hlsl", text, "main"));
  EXPECT_FALSE(w.ok);
}

TEST(ShaderValidate, HlslSyntaxErrorNamesFileAndLine) {
  ShaderValidation v = compileAndValidate(hlsl("bad.ps.hlsl", "float4 main() : SV_Target0 {\n  return float4(1, 1, 1, 1)\n}\n"));
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.log.find("bad.ps.hlsl:"), std::string::npos) << v.log;
}

TEST(ShaderValidate, GlslIncludeFromIncludeDirAndRelative) {
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  // lib/common.glsl is found through the include dir; it includes detail.glsl
  // relative to itself (lib/ is not an include dir).
  dir.write("lib/common.glsl", "#include \"detail.glsl\"\nvec4 shade(vec3 c) { return vec4(scale(c), 1.0); }\n");
  dir.write("lib/detail.glsl", "vec3 scale(vec3 c) { return c * SCALE; }\n");
  ShaderSource s = glsl("m.forward.frag", R"(#version 450
#include "lib/common.glsl"
layout(location = 0) in vec3 vColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = shade(vColor); }
)");
  s.includeDirs = {dir.path().string()};
  s.defines = {{"SCALE", "0.5"}};
  ShaderValidation v = compileAndValidate(s);
  EXPECT_TRUE(v.ok) << v.log;

  // The explicit extension line the generated entry shaders may carry is fine too.
  ShaderSource withExt = s;
  withExt.text.insert(withExt.text.find('\n') + 1, "#extension GL_GOOGLE_include_directive : require\n");
  ShaderValidation e = compileAndValidate(withExt);
  EXPECT_TRUE(e.ok) << e.log;

  // Without the include dir the header is not found.
  ShaderSource noDirs = s;
  noDirs.includeDirs.clear();
  ShaderValidation n = compileAndValidate(noDirs);
  EXPECT_FALSE(n.ok);
  EXPECT_NE(n.log.find("lib/common.glsl"), std::string::npos) << n.log;
}

TEST(ShaderValidate, ErrorInIncludedFileNamesThatFile) {
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  dir.write("broken.glsl", "vec3 f(vec3 c) {\n  return c *;\n}\n");
  ShaderSource s = glsl("m.forward.frag", R"(#version 450
#include "broken.glsl"
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(f(vec3(1.0)), 1.0); }
)");
  s.includeDirs = {dir.path().string()};
  ShaderValidation v = compileAndValidate(s);
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.log.find("broken.glsl:2"), std::string::npos) << v.log;
}

TEST(ShaderValidate, HlslIncludeFromIncludeDir) {
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  dir.write("common.hlsli", "float3 scale(float3 c) { return c * 0.5; }\n");
  ShaderSource s = hlsl("m.forward.ps.hlsl", R"(#include "common.hlsli"
float4 main(float3 color : COLOR0) : SV_Target0 { return float4(scale(color), 1.0); }
)");
  s.includeDirs = {dir.path().string()};
  ShaderValidation v = compileAndValidate(s);
  EXPECT_TRUE(v.ok) << v.log;
}

TEST(ShaderValidate, MemoryFilesAreFoundBeforeDirectories) {
  TempDir dir;
  dir.write("common.glsl", "#error the directory copy must not be read\n");
  const std::string common = "#include \"detail.glsl\"\nvec4 shade(vec3 c) { return vec4(scale(c), 1.0); }\n";
  const std::string detail = "vec3 scale(vec3 c) { return c * 0.5; }\n";
  ShaderSource s = glsl("m.frag", R"(#version 450
#include "common.glsl"
layout(location = 0) in vec3 vColor;
layout(location = 0) out vec4 outColor;
void main() { outColor = shade(vColor); }
)");
  s.includeDirs = {dir.path().string()};
  s.memoryFiles = {{"common.glsl", common}, {"detail.glsl", detail}};
  ShaderValidation v = compileAndValidate(s);
  EXPECT_TRUE(v.ok) << v.log;
  // An error inside a memory file names it.
  const std::string broken = "vec4 shade(vec3 c) { return c; }\n";
  s.memoryFiles = {{"common.glsl", broken}};
  ShaderValidation bad = compileAndValidate(s);
  EXPECT_FALSE(bad.ok);
  EXPECT_NE(bad.log.find("common.glsl:1"), std::string::npos) << bad.log;
}

TEST(ShaderValidate, LinkErrorFails) {
  ShaderValidation v = compileAndValidate(glsl("link.frag", R"(#version 450
layout(location = 0) out vec4 outColor;
vec4 missingBody(float x);
void main() { outColor = missingBody(1.0); }
)"));
  EXPECT_FALSE(v.ok);
  EXPECT_NE(v.log.find("ERROR"), std::string::npos) << v.log;
}

TEST(ShaderValidate, OptimizationRemovesDeadCode) {
  ShaderValidation v = compileAndValidate(glsl("dead.frag", R"(#version 450
layout(location = 0) in vec3 vColor;
layout(location = 0) out vec4 outColor;
float unusedWork(vec3 c) {
  float acc = 0.0;
  for (int i = 0; i < 4; ++i) acc += dot(c, c) * float(i);
  return acc;
}
void main() {
  float dead = unusedWork(vColor) * 3.0;
  vec3 alsoDead = normalize(vColor) * dead;
  if (false) { outColor = vec4(alsoDead, dead); return; }
  outColor = vec4(vColor, 1.0);
}
)"),
                                          {.optimize = true});
  ASSERT_TRUE(v.ok) << v.log;
  EXPECT_LT(v.optimizedInstructionCount, v.instructionCount);
}

TEST(ShaderValidate, Deterministic) {
  ShaderValidation a = compileAndValidate(glsl("trivial.frag", kTrivialFrag), {.optimize = true});
  ShaderValidation b = compileAndValidate(glsl("trivial.frag", kTrivialFrag), {.optimize = true});
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_EQ(a.spirv, b.spirv);
  EXPECT_EQ(a.optimized, b.optimized);
  ShaderValidation c = compileAndValidate(hlsl("ps.hlsl", kHlslPixel));
  ShaderValidation d = compileAndValidate(hlsl("ps.hlsl", kHlslPixel));
  ASSERT_TRUE(c.ok && d.ok);
  EXPECT_EQ(c.spirv, d.spirv);
}

TEST(ShaderValidate, ConcurrentValidationSucceeds) {
  ShaderValidation reference = compileAndValidate(glsl("trivial.frag", kTrivialFrag));
  ASSERT_TRUE(reference.ok);
  constexpr int kThreads = 4;
  std::vector<ShaderValidation> glslResults(kThreads), hlslResults(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 5; ++i) {
        glslResults[t] = compileAndValidate(glsl("trivial.frag", kTrivialFrag));
        hlslResults[t] = compileAndValidate(hlsl("ps.hlsl", kHlslPixel));
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) {
    EXPECT_TRUE(glslResults[t].ok) << glslResults[t].log;
    EXPECT_TRUE(hlslResults[t].ok) << hlslResults[t].log;
    EXPECT_EQ(glslResults[t].spirv, reference.spirv);
  }
}

TEST(ShaderValidate, InstructionCountWalksWordCounts) {
  // Header + OpCapability Shader (2 words) + OpMemoryModel (3 words).
  std::vector<uint32_t> words = {0x07230203u, 0x00010500u, 0, 10, 0, (2u << 16) | 17u, 1, (3u << 16) | 14u, 0, 1};
  EXPECT_EQ(spirvInstructionCount(words), 2u);
  words.push_back(5u << 16);  // truncated instruction
  EXPECT_EQ(spirvInstructionCount(words), 0u);
  EXPECT_EQ(spirvInstructionCount({}), 0u);
}

TEST(ShaderValidate, NumberLines) {
  EXPECT_EQ(numberLines("a\nb\n"), "   1 | a\n   2 | b\n");
  EXPECT_EQ(numberLines("a\nb"), "   1 | a\n   2 | b\n");
  std::string many;
  for (int i = 0; i < 12; ++i) many += "x\n";
  std::string numbered = numberLines(many);
  EXPECT_NE(numbered.find("  12 | x\n"), std::string::npos) << numbered;
}

}  // namespace
}  // namespace substratec
