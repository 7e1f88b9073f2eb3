// Tests for the Vulkan compute harness (compiler/tools/gpu/harness.h) and its SPIR-V
// reflection (compiler/tools/gpu/spirv_reflect.h), on lavapipe with the validation
// layer on. Shaders are compiled by substratec's own in-process compiler. A
// missing Vulkan device, lavapipe or validation layer is a failure, never a skip.
#include "gpu/harness.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "gpu/spirv_reflect.h"
#include "validate/shader_validate.h"

namespace substratec::gpu {
namespace {

/// Compiles a compute shader with compileAndValidate; an empty module (and a test failure) on error.
std::vector<uint32_t> compile(ShaderLanguage language, const std::string& text) {
  ShaderSource src;
  src.name = language == ShaderLanguage::Glsl ? "test.comp" : "test.comp.hlsl";
  src.text = text;
  src.language = language;
  src.stage = ShaderStage::Compute;
  src.entryPoint = "main";
  ShaderValidation v = compileAndValidate(src);
  EXPECT_TRUE(v.ok) << v.log;
  return v.ok ? v.spirv : std::vector<uint32_t>{};
}

template <class T>
std::vector<std::byte> bytesOf(const std::vector<T>& values) {
  std::vector<std::byte> bytes(values.size() * sizeof(T));
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return bytes;
}

template <class T>
std::vector<T> valuesOf(const std::vector<std::byte>& bytes) {
  std::vector<T> values(bytes.size() / sizeof(T));
  std::memcpy(values.data(), bytes.data(), values.size() * sizeof(T));
  return values;
}

BufferResource outputBuffer(size_t bytes) { return BufferResource{std::vector<std::byte>(bytes), true}; }

/// One Context for the suite (instance + device cost tens of ms); every test checks it exists.
class GpuHarness : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    Context::Options options;
    options.shaderCacheDir = SUBSTRATEC_GPU_CACHE_DIR;
    context_ = Context::create(options, createError_);
  }
  static void TearDownTestSuite() { context_.reset(); }
  void SetUp() override { ASSERT_NE(context_, nullptr) << createError_.errorMessages(); }
  /// No test leaves validation messages behind (the one provoking them takes them).
  void TearDown() override {
    if (!context_) return;
    for (const std::string& m : context_->takeMessages()) ADD_FAILURE() << "unexpected validation message: " << m;
  }

  /// Builds the pipeline and runs one dispatch; false (with a test failure) if either fails.
  static bool run(const std::vector<uint32_t>& spirv, Resources& resources, uint32_t x, uint32_t y = 1, uint32_t z = 1) {
    Diagnostics diags("test");
    auto pipeline = context_->createPipeline(spirv, diags);
    EXPECT_NE(pipeline, nullptr) << diags.errorMessages();
    if (!pipeline) return false;
    const bool ok = context_->dispatch(*pipeline, resources, x, y, z, diags);
    EXPECT_TRUE(ok) << diags.errorMessages();
    return ok;
  }

  static std::unique_ptr<Context> context_;
  static Diagnostics createError_;
};
std::unique_ptr<Context> GpuHarness::context_;
Diagnostics GpuHarness::createError_("GPU harness");

constexpr const char* kGlslDouble = R"(#version 450
layout(local_size_x = 16) in;
layout(set = 0, binding = 0) readonly buffer Input { float values[]; } src;
layout(set = 0, binding = 1) writeonly buffer Output { float values[]; } dst;
void main() {
  uint i = gl_GlobalInvocationID.x;
  dst.values[i] = 2.0 * src.values[i];
}
)";

std::vector<float> ramp(size_t n) {
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i) v[i] = 0.37f * static_cast<float>(i) - 5.0f;
  return v;
}

TEST_F(GpuHarness, RunsOnLavapipe) {
  EXPECT_NE(context_->deviceName().find("llvmpipe"), std::string::npos) << context_->deviceName();
  EXPECT_NE(context_->driverInfo().find("Mesa"), std::string::npos) << context_->driverInfo();
}

TEST_F(GpuHarness, ReflectionListsBindingsNamesKindsAndLocalSize) {
  const auto glsl = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 8, local_size_y = 4, local_size_z = 2) in;
layout(set = 0, binding = 0) uniform Params { vec4 scale; } params;
layout(set = 0, binding = 1) uniform sampler2D albedo;
layout(set = 2, binding = 0) uniform samplerCube environment;
layout(set = 2, binding = 3) buffer Result { vec4 values[]; } result;
layout(set = 2, binding = 4, r32ui) uniform writeonly uimage2DArray ids;
void main() {
  vec4 c = textureLod(albedo, vec2(0.5), 0.0) + textureLod(environment, vec3(1.0, 0.0, 0.0), 0.0);
  result.values[gl_LocalInvocationIndex] = c * params.scale;
  imageStore(ids, ivec3(0), uvec4(1u));
}
)");
  ShaderReflection r;
  Diagnostics diags("test");
  ASSERT_TRUE(reflectSpirv(glsl, &r, diags)) << diags.errorMessages();
  EXPECT_EQ(r.entryPoint, "main");
  EXPECT_EQ(r.localSize[0], 8u);
  EXPECT_EQ(r.localSize[1], 4u);
  EXPECT_EQ(r.localSize[2], 2u);
  ASSERT_EQ(r.bindings.size(), 5u);
  auto expect = [&](size_t i, uint32_t set, uint32_t binding, const char* name, DescriptorKind kind, ImageDim dim) {
    SCOPED_TRACE(i);
    EXPECT_EQ(r.bindings[i].set, set);
    EXPECT_EQ(r.bindings[i].binding, binding);
    EXPECT_EQ(r.bindings[i].name, name);
    EXPECT_EQ(r.bindings[i].kind, kind) << descriptorKindName(r.bindings[i].kind);
    EXPECT_EQ(r.bindings[i].dim, dim);
    EXPECT_EQ(r.bindings[i].count, 1u);
  };
  expect(0, 0, 0, "params", DescriptorKind::UniformBuffer, ImageDim::None);
  expect(1, 0, 1, "albedo", DescriptorKind::CombinedImageSampler, ImageDim::Dim2D);
  expect(2, 2, 0, "environment", DescriptorKind::CombinedImageSampler, ImageDim::Cube);
  expect(3, 2, 3, "result", DescriptorKind::StorageBuffer, ImageDim::None);
  expect(4, 2, 4, "ids", DescriptorKind::StorageImage, ImageDim::Dim2D);
  EXPECT_TRUE(r.bindings[4].arrayed);
  EXPECT_EQ(r.bindings[4].imageFormat, 33u);  // R32ui

  const auto hlsl = compile(ShaderLanguage::Hlsl, R"(
cbuffer Params : register(b0) { float4 scale; };
[[vk::binding(1, 0)]] Texture2D<float4> albedo;
[[vk::binding(2, 0)]] SamplerState linearClamp;
[[vk::binding(3, 0)]] RWStructuredBuffer<float4> result;
[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  result[id.x] = albedo.SampleLevel(linearClamp, float2(0.5, 0.5), 0) * scale;
}
)");
  ASSERT_TRUE(reflectSpirv(hlsl, &r, diags)) << diags.errorMessages();
  EXPECT_EQ(r.localSize[0], 64u);
  ASSERT_EQ(r.bindings.size(), 4u);
  expect(0, 0, 0, "", DescriptorKind::UniformBuffer, ImageDim::None);  // a cbuffer's variable has no name
  expect(1, 0, 1, "albedo", DescriptorKind::SampledImage, ImageDim::Dim2D);
  expect(2, 0, 2, "linearClamp", DescriptorKind::Sampler, ImageDim::None);
  expect(3, 0, 3, "result", DescriptorKind::StorageBuffer, ImageDim::None);
}

TEST_F(GpuHarness, GlslShaderDoublesAStorageBufferExactly) {
  const std::vector<float> input = ramp(64);
  Resources res{{{0, 0}, BufferResource{bytesOf(input)}}, {{0, 1}, outputBuffer(64 * sizeof(float))}};
  ASSERT_TRUE(run(compile(ShaderLanguage::Glsl, kGlslDouble), res, 4));
  const auto out = valuesOf<float>(std::get<BufferResource>(res.at({0, 1})).data);
  ASSERT_EQ(out.size(), 64u);
  for (size_t i = 0; i < 64; ++i) EXPECT_EQ(out[i], 2.0f * input[i]) << i;
}

TEST_F(GpuHarness, HlslShaderDoublesARWStructuredBufferExactly) {
  const auto spirv = compile(ShaderLanguage::Hlsl, R"(
[[vk::binding(0, 0)]] StructuredBuffer<float> src;
[[vk::binding(1, 0)]] RWStructuredBuffer<float> dst;
[numthreads(16, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) { dst[id.x] = 2.0 * src[id.x]; }
)");
  const std::vector<float> input = ramp(48);
  Resources res{{{0, 0}, BufferResource{bytesOf(input)}}, {{0, 1}, outputBuffer(48 * sizeof(float))}};
  ASSERT_TRUE(run(spirv, res, 3));
  const auto out = valuesOf<float>(std::get<BufferResource>(res.at({0, 1})).data);
  for (size_t i = 0; i < 48; ++i) EXPECT_EQ(out[i], 2.0f * input[i]) << i;
}

/// A 4x4 RGBA32F texture whose texel (x, y) is (x, y, 10x + y, 1 + x*y).
ImageResource texture4x4() {
  ImageResource img;
  img.width = img.height = 4;
  img.mips.emplace_back();
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      img.mips[0].insert(img.mips[0].end(), {float(x), float(y), float(10 * x + y), float(1 + x * y)});
  return img;
}

TEST_F(GpuHarness, UniformBufferAndCombinedImageSamplerReadTexelCentresExactly) {
  // Texel centres shifted by one whole texture (params.offset = 1): Repeat wraps them back.
  const auto spirv = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 4, local_size_y = 4) in;
layout(set = 0, binding = 0) uniform Params { vec2 offset; float scale; } params;
layout(set = 0, binding = 1) uniform sampler2D tex;
layout(set = 2, binding = 0) buffer Output { vec4 texels[]; } result;  // set 1 stays empty
void main() {
  vec2 uv = (vec2(gl_GlobalInvocationID.xy) + 0.5) / 4.0 + params.offset;
  result.texels[gl_GlobalInvocationID.y * 4u + gl_GlobalInvocationID.x] = params.scale * textureLod(tex, uv, 0.0);
}
)");
  Resources res{{{0, 0}, BufferResource{bytesOf(std::vector<float>{1.0f, 1.0f, 2.0f, 0.0f})}},
                {{0, 1}, texture4x4()},
                {{2, 0}, outputBuffer(16 * 4 * sizeof(float))}};
  ASSERT_TRUE(run(spirv, res, 1));
  const auto out = valuesOf<float>(std::get<BufferResource>(res.at({2, 0})).data);
  const auto& texels = std::get<ImageResource>(res.at({0, 1})).mips[0];
  for (size_t i = 0; i < texels.size(); ++i) EXPECT_EQ(out[i], 2.0f * texels[i]) << "float " << i;
}

TEST_F(GpuHarness, HlslTexture2DAndSamplerStatePairReadTexels) {
  const auto spirv = compile(ShaderLanguage::Hlsl, R"(
[[vk::binding(0, 0)]] Texture2D<float4> tex;
[[vk::binding(1, 0)]] SamplerState smp;
[[vk::binding(2, 0)]] RWStructuredBuffer<float4> result;
[numthreads(4, 4, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  result[id.y * 4 + id.x] = tex.SampleLevel(smp, (float2(id.xy) + 0.5) / 4.0, 0);
}
)");
  Resources res{{{0, 0}, texture4x4()},
                {{0, 1}, SamplerResource{Filter::Nearest, Address::ClampToEdge, std::nullopt}},
                {{0, 2}, outputBuffer(16 * 4 * sizeof(float))}};
  ASSERT_TRUE(run(spirv, res, 1));
  EXPECT_EQ(valuesOf<float>(std::get<BufferResource>(res.at({0, 2})).data), std::get<ImageResource>(res.at({0, 0})).mips[0]);
}

TEST_F(GpuHarness, CubeMapLookupAlongEachAxisReturnsThatFace) {
  const auto spirv = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 6) in;
layout(set = 0, binding = 0) uniform samplerCube environment;
layout(set = 0, binding = 1) buffer Output { vec4 colors[6]; } result;
const vec3 kAxes[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));
void main() {
  uint i = gl_LocalInvocationIndex;
  result.colors[i] = textureLod(environment, kAxes[i], 0.0);
}
)");
  ImageResource cube;  // 2x2 faces, face f filled with (f, 10f, 100f, 1)
  cube.width = cube.height = 2;
  cube.layers = 6;
  cube.mips.emplace_back();
  for (int face = 0; face < 6; ++face)
    for (int texel = 0; texel < 4; ++texel)
      cube.mips[0].insert(cube.mips[0].end(), {float(face), 10.0f * face, 100.0f * face, 1.0f});
  Resources res{{{0, 0}, cube}, {{0, 1}, outputBuffer(6 * 4 * sizeof(float))}};
  ASSERT_TRUE(run(spirv, res, 1));
  const auto out = valuesOf<float>(std::get<BufferResource>(res.at({0, 1})).data);
  for (int face = 0; face < 6; ++face) {  // +X, -X, +Y, -Y, +Z, -Z are layers 0..5
    EXPECT_EQ(out[4 * face + 0], float(face)) << "axis " << face;
    EXPECT_EQ(out[4 * face + 1], 10.0f * face) << "axis " << face;
  }
}

TEST_F(GpuHarness, UnwrittenOutputsReadBackAsTheirFillPattern) {
  // Only element 0 of the buffer and texel (0, 0) of the image are written.
  const auto spirv = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) buffer Output { float values[]; } result;
layout(set = 0, binding = 1, r32ui) uniform writeonly uimage2D ids;
void main() {
  result.values[0] = 42.0;
  imageStore(ids, ivec2(0, 0), uvec4(7u));
}
)");
  StorageImageResource ids;
  ids.width = 3;
  ids.height = 2;
  ids.format = StorageFormat::R32Uint;
  Resources res{{{0, 0}, outputBuffer(4 * sizeof(float))}, {{0, 1}, ids}};
  ASSERT_TRUE(run(spirv, res, 1));
  const auto words = valuesOf<uint32_t>(std::get<BufferResource>(res.at({0, 0})).data);
  EXPECT_EQ(words, (std::vector<uint32_t>{std::bit_cast<uint32_t>(42.0f), 0x7fc00000u, 0x7fc00000u, 0x7fc00000u}));
  EXPECT_EQ(valuesOf<uint32_t>(std::get<StorageImageResource>(res.at({0, 1})).data),
            (std::vector<uint32_t>{7u, 0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu}));
}

TEST_F(GpuHarness, ResourceMismatchesFailNamingTheBinding) {
  Diagnostics diags("test");
  auto pipeline = context_->createPipeline(compile(ShaderLanguage::Glsl, kGlslDouble), diags);
  ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
  Resources missing{{{0, 0}, BufferResource{bytesOf(ramp(16))}}};
  EXPECT_FALSE(context_->dispatch(*pipeline, missing, 1, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find("no resource for set 0 binding 1 ('dst', StorageBuffer)"), std::string::npos)
      << diags.errorMessages();

  Resources wrongKind{{{0, 0}, BufferResource{bytesOf(ramp(16))}}, {{0, 1}, SamplerResource{}}};
  EXPECT_FALSE(context_->dispatch(*pipeline, wrongKind, 1, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find(
                "set 0 binding 1 ('dst', StorageBuffer) needs a BufferResource, got a SamplerResource"),
            std::string::npos)
      << diags.errorMessages();

  Resources extra{{{0, 0}, BufferResource{bytesOf(ramp(16))}}, {{0, 1}, outputBuffer(64)}, {{3, 7}, outputBuffer(4)}};
  EXPECT_FALSE(context_->dispatch(*pipeline, extra, 1, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find("set 3 binding 7 is not used"), std::string::npos)
      << diags.errorMessages();
}

TEST_F(GpuHarness, InterfaceViolationIsReportedByTheValidationLayerAndFailsTheDispatch) {
  // The shader declares an rgba32f float image; the resource is an R32_UINT image (harness-legal, since
  // only the descriptor kind is checked; lavapipe would happily run it).
  const auto spirv = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 1) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D color;
void main() { imageStore(color, ivec2(0, 0), vec4(1.0)); }
)");
  StorageImageResource wrong;
  wrong.width = wrong.height = 1;
  wrong.format = StorageFormat::R32Uint;
  Resources res{{{0, 0}, wrong}};
  Diagnostics diags("test");
  auto pipeline = context_->createPipeline(spirv, diags);
  ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
  EXPECT_FALSE(context_->dispatch(*pipeline, res, 1, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find("the validation layer reported"), std::string::npos)
      << diags.errorMessages();
  EXPECT_NE(diags.errorMessages().find("VUID-vkCmdDispatch-format-"), std::string::npos)
      << diags.errorMessages();  // "-07753" in layer 1.3.239
  const auto messages = context_->takeMessages();
  ASSERT_FALSE(messages.empty());
  EXPECT_EQ(messages[0].rfind("ERROR [validation]", 0), 0u) << messages[0];

  // The same pipeline with the right format runs clean afterwards.
  res = Resources{{{0, 0}, StorageImageResource{1, 1, 1, StorageFormat::R32G32B32A32Sfloat, {}}}};
  EXPECT_TRUE(context_->dispatch(*pipeline, res, 1, 1, 1, diags)) << diags.errorMessages();
  EXPECT_EQ(valuesOf<float>(std::get<StorageImageResource>(res.at({0, 0})).data), std::vector<float>(4, 1.0f));
}

TEST_F(GpuHarness, SameDispatchTwiceGivesIdenticalBytes) {
  // Transcendentals and linear filtering between mips: anything nondeterministic would show.
  const auto spirv = compile(ShaderLanguage::Glsl, R"(#version 450
layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0) uniform sampler2D tex;
layout(set = 0, binding = 1) buffer Output { vec4 values[]; } result;
void main() {
  vec2 p = vec2(gl_GlobalInvocationID.xy) / 16.0;
  vec4 t = textureLod(tex, p * 1.37 + 0.11, p.x * 1.5);
  result.values[gl_GlobalInvocationID.y * 16u + gl_GlobalInvocationID.x] = sin(t * 3.1) * exp(-p.y) + pow(t, vec4(2.2));
}
)");
  ImageResource img;
  img.width = img.height = 4;
  img.filter = Filter::Linear;
  for (uint32_t size = 4; size >= 1; size /= 2) {
    img.mips.emplace_back();
    for (uint32_t i = 0; i < size * size * 4; ++i) img.mips.back().push_back(std::fmod(0.731f * float(i + size), 1.0f));
  }
  Diagnostics diags("test");
  auto pipeline = context_->createPipeline(spirv, diags);
  ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
  std::vector<std::byte> first;
  for (int round = 0; round < 2; ++round) {
    Resources res{{{0, 0}, img}, {{0, 1}, outputBuffer(256 * 4 * sizeof(float))}};
    ASSERT_TRUE(context_->dispatch(*pipeline, res, 2, 2, 1, diags)) << diags.errorMessages();
    const auto& bytes = std::get<BufferResource>(res.at({0, 1})).data;
    for (float f : valuesOf<float>(bytes)) ASSERT_FALSE(std::isnan(f));
    if (round == 0) first = bytes;
    else EXPECT_TRUE(bytes == first);
  }
}

constexpr const char* kXorshiftLoop = R"(#version 450
layout(local_size_x = 1) in;
layout(set = 0, binding = 0) uniform Params { uint iterations; } params;
layout(set = 0, binding = 1) buffer Output { uint state[]; } result;
void main() {
  uint x = gl_WorkGroupID.x + 1u;
  for (uint i = 0u; i < params.iterations; ++i) { x ^= x << 13; x ^= x >> 17; x ^= x << 5; }
  result.state[gl_WorkGroupID.x] = x;
}
)";

/// What kXorshiftLoop leaves for workgroup 0 after `iterations` steps.
uint32_t xorshift(uint32_t iterations) {
  uint32_t x = 1;
  for (uint32_t i = 0; i < iterations; ++i) x ^= x << 13, x ^= x >> 17, x ^= x << 5;
  return x;
}

// A fact about the driver, not the harness: llvmpipe (gallivm's loop limiter) silently ends any loop
// after 65535 iterations. Shaders meant for lavapipe must keep their loops below that.
TEST_F(GpuHarness, LavapipeEndsLoopsAfter65535Iterations) {
  Diagnostics diags("test");
  auto pipeline = context_->createPipeline(compile(ShaderLanguage::Glsl, kXorshiftLoop), diags);
  ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
  for (uint32_t iterations : {1000u, 65535u, 65536u, 100000u}) {
    Resources res{{{0, 0}, BufferResource{bytesOf(std::vector<uint32_t>{iterations})}}, {{0, 1}, outputBuffer(4)}};
    ASSERT_TRUE(context_->dispatch(*pipeline, res, 1, 1, 1, diags)) << diags.errorMessages();
    EXPECT_EQ(valuesOf<uint32_t>(std::get<BufferResource>(res.at({0, 1})).data)[0],
              xorshift(std::min(iterations, 65535u)))
        << iterations << " iterations";
  }
}

TEST(GpuHarnessTimeout, AFenceTimeoutFailsTheDispatchInsteadOfHanging) {
  // ~4 s of work on this machine (10000 workgroups of 60000 loop steps) against a 100 ms timeout. The
  // Context is then unusable (its objects leak; the work finishes in the background).
  Context::Options options;
  options.shaderCacheDir = SUBSTRATEC_GPU_CACHE_DIR;
  options.fenceTimeoutNs = 100'000'000;
  Diagnostics diags("test");
  auto context = Context::create(options, diags);
  ASSERT_NE(context, nullptr) << diags.errorMessages();
  auto pipeline = context->createPipeline(compile(ShaderLanguage::Glsl, kXorshiftLoop), diags);
  ASSERT_NE(pipeline, nullptr) << diags.errorMessages();
  const uint32_t groups = 10000;
  Resources res{{{0, 0}, BufferResource{bytesOf(std::vector<uint32_t>{60000u})}}, {{0, 1}, outputBuffer(4 * groups)}};
  EXPECT_FALSE(context->dispatch(*pipeline, res, groups, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find("vkWaitForFences timed out after 100 ms"), std::string::npos)
      << diags.errorMessages();
  EXPECT_FALSE(context->dispatch(*pipeline, res, 1, 1, 1, diags));
  EXPECT_NE(diags.errorMessages().find("unusable"), std::string::npos)
      << diags.errorMessages();
  EXPECT_TRUE(context->takeMessages().empty());
}

}  // namespace
}  // namespace substratec::gpu
