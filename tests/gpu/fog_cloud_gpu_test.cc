// The volumetric fog cloud on lavapipe, against its CPU mirror in double
// (reference/fog_cloud.h):
//  - the froxel pass `substratec compile` emits for a volume
//    (<name>.volume.comp, <name>.volume.cs.hlsl), for both examples, GLSL and
//    HLSL: every froxel's payload unpacks to the double evaluation of the
//    material's pins at the froxel's centre, sanitized (fogCloudMake), within
//    the payload's quantization, and nearly every payload is the double's pack
//    bit for bit; every froxel is written, nothing past the grid is;
//  - the hard cases: a material whose four pins are its inputs, given zero,
//    tiny, huge, out-of-range, infinite and NaN values through the uniform
//    block: the material function's sample (before packing: what a
//    ray-marcher gets) is finite, in range and the mirror's sanitized value
//    exactly, and the froxel pass writes the mirror's payload bit for bit;
//  - substrate_fog_cloud_step, marched along rays in float on the GPU (through
//    homogeneous media, raw samples included, and through froxels unpacked
//    with substrate_fog_cloud_unpack), against marchFogCloud in double.
//
// Tolerances:
//  - albedo and ambient occlusion (unorm8): |gpu - ref| <= 1/255 + 1e-6 (half
//    a step of rounding, and as much again for a value float and double round
//    to different sides of a step's middle);
//  - extinction and emissive (RGB9E5): |gpu - ref| <= 2^-8 of the largest
//    channel (of either) + 2^-24 (half a step is 2^-9 of it; the rest allows
//    that flip, or the shared exponent's bump on one side only);
//  - payloads bit-identical to the double's pack: at least 99% (a flip needs
//    float's error to reach a step's middle; it does where cancellation
//    magnifies it, the puff's 1 - d / r at its rim: about 1 froxel in 10^3);
//  - the march: |gpu - ref| <= 1e-4 |ref| + 1e-30, per channel of radiance and
//    throughput (float's exp and N steps of rounding stay near 1e-5; the
//    absolute term is for throughputs float flushes to 0 below 1e-38).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <tuple>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "emit/entry_emitter.h"
#include "emit/syntax.h"
#include "ir/value_eval.h"
#include "material_fixture.h"
#include "pipeline/generate.h"
#include "reference/fog_cloud.h"
#include "validate/runtime_files.h"
#include "validate/shader_validate.h"

namespace substratec::gputest {
namespace fog_cloud_gpu_test {

namespace fs = std::filesystem;
using reference::FogCloudSample;
using D3 = std::array<double, 3>;
using Words = std::array<uint32_t, 3>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kNaNFill = 0x7fc00000u;  // what the harness fills an output buffer with
constexpr uint32_t kGroup = kVolumeLocalSize;

constexpr double kUnormTolerance = 1.0 / 255 + 1e-6;
constexpr double kIdenticalShare = 0.99;
constexpr double kMarchRelative = 1e-4, kMarchAbsolute = 1e-30;

double maxOf(const D3& v) { return std::max(v[0], std::max(v[1], v[2])); }
/// The value the GPU sees of a double the test uploads as a float.
double asFloat(double x) { return static_cast<float>(x); }
D3 asFloat(const D3& v) { return {asFloat(v[0]), asFloat(v[1]), asFloat(v[2])}; }
uint32_t floatBits(double x) { return std::bit_cast<uint32_t>(static_cast<float>(x)); }

double rgb9e5Tolerance(const D3& gpu, const D3& ref) {
  return std::ldexp(std::max(maxOf(gpu), maxOf(ref)), -8) + std::ldexp(1.0, -24);
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

CompileResult compileVolume(const std::string& name, const std::string& text) {
  Diagnostics diags(name);
  auto r = compileText(name, text, CompileOptions{}, diags);
  EXPECT_TRUE(r.has_value()) << diags.formatAll();
  if (!r) return CompileResult{};
  EXPECT_TRUE(isVolumeMaterial(r->material)) << name;
  return std::move(*r);
}

CompileResult compileExample(const std::string& stem) {
  return compileVolume(stem + ".json", readFile(fs::path(SUBSTRATEC_SOURCE_DIR) / "examples" / (stem + ".json")));
}

// ---------------------------------------------------------------------------
// The froxel grid and the double's view of a froxel

/// A froxel grid as the pass's SubstrateVolumeGrid block holds it (origin and
/// cell size already rounded to float: the double uses what the GPU reads).
struct Grid {
  D3 origin, cell;
  std::array<uint32_t, 3> n;

  uint32_t count() const { return n[0] * n[1] * n[2]; }
  std::array<uint32_t, 3> cellOf(uint32_t i) const { return {i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1])}; }
  /// Froxel i as the pass describes it to the material (emitVolumeEntry).
  EvalPoint point(uint32_t i, const std::vector<std::array<double, 4>>& inputs) const {
    const auto c = cellOf(i);
    EvalPoint p;
    for (int k = 0; k < 3; ++k) p.position[k] = origin[k] + (c[k] + 0.5) * cell[k];
    p.uv0 = {(c[0] + 0.5) / n[0], (c[1] + 0.5) / n[1]};
    p.uv1 = {(c[2] + 0.5) / n[2], 0};
    p.sampler = gpu::sampleTexture;  // the textures kernelResources binds
    for (const auto& v : inputs) p.inputs.push_back({asFloat(v[0]), asFloat(v[1]), asFloat(v[2]), asFloat(v[3])});
    return p;
  }
  /// The block's 48 bytes: float4 origin, float4 cellSize, uint4 counts.
  std::vector<std::byte> block() const {
    std::array<uint32_t, 12> w{floatBits(origin[0]), floatBits(origin[1]), floatBits(origin[2]), 0,
                               floatBits(cell[0]),   floatBits(cell[1]),   floatBits(cell[2]),   0,
                               n[0],                 n[1],                 n[2],                 0};
    std::vector<std::byte> bytes(sizeof w);
    std::memcpy(bytes.data(), w.data(), sizeof w);
    return bytes;
  }
};

/// `n` froxels spanning [lo, hi] on each axis.
Grid gridOver(double lo, double hi, std::array<uint32_t, 3> n) {
  Grid g{{}, {}, n};
  for (int k = 0; k < 3; ++k) {
    g.origin[k] = asFloat(lo);
    g.cell[k] = asFloat((hi - lo) / n[k]);
  }
  return g;
}

/// The double's sample at `p`: the fog cloud's four pins evaluated, then
/// fogCloudMake (substrate_fog_cloud_make, which the material function calls).
FogCloudSample doubleSample(const Material& m, const EvalPoint& p) {
  const Slab& fog = m.slabs[m.nodes[m.root].slab];
  auto pin = [&](SlabPin which) -> D3 {
    const ValueId v = fog.pin(which);
    const auto x = evaluateValue(m, v, p);
    if (m.values.node(v).type == VType::Float) return {x[0], x[0], x[0]};
    return {x[0], x[1], x[2]};
  };
  return reference::fogCloudMake(pin(SlabPin::Albedo), pin(SlabPin::Extinction), pin(SlabPin::Emissive),
                                 pin(SlabPin::AmbientOcclusion)[0]);
}

/// Why the payload the GPU wrote (unpacked) is not the double's sample `ref`:
/// a value non-finite or out of its range, or outside its tolerance; "" when it is.
std::string mismatch(const FogCloudSample& gpu, const FogCloudSample& ref) {
  std::string why;
  auto check = [&](const char* field, int c, double g, double r, double tolerance, double hi) {
    if (!std::isfinite(g) || g < 0 || g > hi)
      why += fmt::format(" {}[{}] = {} is outside [0, {}];", field, c, g, hi);
    else if (!(std::abs(g - r) <= tolerance))
      why += fmt::format(" {}[{}] = {}, the double's {} (|d| {:.3g} > {:.3g});", field, c, g, r, std::abs(g - r),
                         tolerance);
  };
  const double maxE = reference::kFogMaxExtinction;
  for (int c = 0; c < 3; ++c) {
    check("albedo", c, gpu.albedo[c], ref.albedo[c], kUnormTolerance, 1);
    check("extinction", c, gpu.extinction[c], ref.extinction[c], rgb9e5Tolerance(gpu.extinction, ref.extinction),
          maxE);
    check("emissive", c, gpu.emissive[c], ref.emissive[c], rgb9e5Tolerance(gpu.emissive, ref.emissive), maxE);
  }
  check("ambient_occlusion", 0, gpu.ambientOcclusion, ref.ambientOcclusion, kUnormTolerance, 1);
  return why;
}

std::string describe(const FogCloudSample& s) {
  return fmt::format("albedo ({}, {}, {}) extinction ({}, {}, {}) emissive ({}, {}, {}) ao {}", s.albedo[0],
                     s.albedo[1], s.albedo[2], s.extinction[0], s.extinction[1], s.extinction[2], s.emissive[0],
                     s.emissive[1], s.emissive[2], s.ambientOcclusion);
}

/// Why an RGB9E5 word is not one substrate_rgb9e5_encode writes, or "": its
/// largest mantissa is at least 256 unless the exponent is 0 (a mantissa that
/// rounded to 512 bumps the exponent rather than spill into the next field).
std::string nonCanonical(uint32_t w, const char* field) {
  const uint32_t e = w >> 27, hi = std::max({w & 0x1ffu, (w >> 9) & 0x1ffu, (w >> 18) & 0x1ffu});
  if (e == 0 || hi >= 256) return "";
  return fmt::format(" {} word {:#010x} is not normalized (exponent {}, largest mantissa {});", field, w, e, hi);
}

/// Payloads compared with the double, over a test.
struct Tally {
  long compared = 0, identical = 0, failed = 0;
  std::string first;

  /// Checks froxel `what`'s words against the double's sample `ref`.
  void check(const Words& words, const FogCloudSample& ref, const std::string& what) {
    ++compared;
    if (words == reference::fogCloudPack(ref)) ++identical;
    const FogCloudSample gpu = reference::fogCloudUnpack(words);
    const std::string why =
        mismatch(gpu, ref) + nonCanonical(words[1], "extinction") + nonCanonical(words[2], "emissive");
    if (why.empty()) return;
    if (failed++ == 0) first = fmt::format("{}:{}\n  gpu    {}\n  double {}", what, why, describe(gpu), describe(ref));
  }
};

// ---------------------------------------------------------------------------
// Running the froxel pass

/// A compute kernel of a volume in one language: its SPIR-V and pipeline.
struct VolumeKernel {
  std::vector<uint32_t> spirv;
  std::unique_ptr<gpu::ComputePipeline> pipeline;
};

/// The test's own kernel that writes the material function's sample, before
/// any packing (what a ray-marcher gets at each step): 10 floats (albedo,
/// extinction, emissive, ambient occlusion) from invocation 0 at one point.
std::string sampleKernel(const Material& m, const Syntax& syn) {
  std::string s = std::string(syn.header) + "#define SUBSTRATE_TEXTURE_LOD0 1\n";
  s += fmt::format("#include \"{}\"\n#include \"{}{}\"\n\n", syn.prelude, m.name, syn.materialExtension);
  s += syn.storageBuffer(0, 1, Access::Write, "SubstrateFogSamples", "float", "samples");
  s += "\n" + syn.computeMain(kVolumeLocalSize, 1);
  s += fmt::format("  if ({}.x != 0u) return;\n", syn.computeId(ComputeId::Dispatch));
  s += "  SubstrateGeometry g;\n  g.position = SUBSTRATE_SPLAT3(0.0);\n";
  s += "  g.N = float3(0.0, 0.0, 1.0);\n  g.T = float3(1.0, 0.0, 0.0);\n  g.V = float3(0.0, 0.0, 1.0);\n";
  s += "  g.uv0 = SUBSTRATE_SPLAT2(0.5);\n  g.uv1 = SUBSTRATE_SPLAT2(0.5);\n";
  s += "  g.vertexColor = SUBSTRATE_SPLAT4(1.0);\n  g.uvDerivatives = SUBSTRATE_SPLAT4(0.0);\n  g.dither = 0.5;\n";
  s += fmt::format("  SubstrateFogCloudSample f = {}_sample(g);\n", m.name);
  s += "  for (uint c = 0u; c < 3u; ++c) {\n    samples[c] = f.albedo[c];\n    samples[3u + c] = f.extinction[c];\n"
       "    samples[6u + c] = f.emissive[c];\n  }\n  samples[9] = f.ambientOcclusion;\n}\n";
  return s;
}

enum class Kernel { FroxelPass, Sample };

/// The froxel pass of `r` in `target` (from the files `substratec compile`
/// writes) or the sample kernel (against the same material file), compiled.
ShaderValidation compileVolumeKernel(const CompileResult& r, Target target, Kernel kind) {
  GenerateOptions o;
  o.glsl = target == Target::Glsl;
  o.hlsl = target == Target::Hlsl;
  const Generated g = generateFiles(r, o);
  const Syntax& syn = syntaxFor(target);
  if (kind == Kernel::FroxelPass) return compileGeneratedEntry(g, volumeFileName(r.material, syn));
  ShaderSource src;
  src.name = r.material.name + ".sample_test" + std::string(syn.computeExtension);
  src.text = sampleKernel(r.material, syn);
  src.language = target == Target::Glsl ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
  src.stage = ShaderStage::Compute;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  for (const OutputFile& f : g.files) src.memoryFiles.emplace(f.name, f.contents);
  ShaderValidation v = compileAndValidate(src);
  if (!v.ok) v.log = src.text + "\n" + v.log;
  return v;
}

/// compileVolumeKernel's kernel with its pipeline, built once per process (a
/// pipeline is most of a GPU test's time on lavapipe). Null, with a test
/// failure, if either fails.
const VolumeKernel* volumeKernel(gpu::Context& ctx, const CompileResult& r, Target target, Kernel kind) {
  static std::map<std::tuple<std::string, Target, Kernel>, VolumeKernel> cache;
  VolumeKernel& k = cache[{r.material.name, target, kind}];
  if (k.pipeline) return &k;
  ShaderValidation v = compileVolumeKernel(r, target, kind);
  EXPECT_TRUE(v.ok) << v.log;
  if (!v.ok) return nullptr;
  Diagnostics diags("test");
  k.pipeline = ctx.createPipeline(v.spirv, diags);
  EXPECT_NE(k.pipeline, nullptr) << diags.errorMessages();
  if (!k.pipeline) return nullptr;
  const auto& local = k.pipeline->reflection().localSize;
  EXPECT_EQ(local[0] * local[1] * local[2], kGroup) << "one froxel an invocation, 64 a group";
  k.spirv = std::move(v.spirv);
  return &k;
}

/// Runs `kernel` of material `m` once per `groups` groups with `inputs`
/// (empty: defaults) and `grid` bound: every word of its output (set 0,
/// binding 1) of `outputWords` words; empty, with a test failure, when the dispatch fails.
std::vector<uint32_t> runKernel(gpu::Context& ctx, const VolumeKernel& kernel, const Material& m, const Grid& grid,
                                const std::vector<std::array<double, 4>>& inputs, std::array<uint32_t, 2> groups,
                                std::size_t outputWords) {
  // The material's inputs block and textures as the sample kernels get them; the grid and the output.
  gpu::Resources res = gpu::kernelResources(m, kernel.pipeline->reflection(), kernel.spirv, inputs, {}, 0);
  for (const gpu::DescriptorBinding& b : kernel.pipeline->reflection().bindings)
    if (b.set == 0 && b.binding == 0) res[{0, 0}] = gpu::BufferResource{grid.block(), false};
  gpu::BufferResource out;
  out.data.resize(outputWords * sizeof(uint32_t));
  out.output = true;
  res[{0, 1}] = out;
  Diagnostics diags("test");
  const bool ok = ctx.dispatch(*kernel.pipeline, res, groups[0], groups[1], 1, diags);
  EXPECT_TRUE(ok) << diags.errorMessages();
  if (!ok) return {};
  const auto& data = std::get<gpu::BufferResource>(res.at({0, 1})).data;
  std::vector<uint32_t> words(data.size() / sizeof(uint32_t));
  std::memcpy(words.data(), data.data(), data.size());
  return words;
}

/// The froxel pass over `grid` with `inputs`, dispatched as the pass expects
/// (a row of groups a z slice): the froxel buffer (3 words a froxel, x
/// fastest), a group's worth of froxels longer than the grid (to see strays).
std::vector<uint32_t> runFroxels(gpu::Context& ctx, const VolumeKernel& pass, const Material& m, const Grid& grid,
                                 const std::vector<std::array<double, 4>>& inputs) {
  const uint32_t slice = (grid.n[0] * grid.n[1] + kGroup - 1) / kGroup;
  return runKernel(ctx, pass, m, grid, inputs, {slice, grid.n[2]}, (std::size_t{grid.count()} + kGroup) * 3);
}

/// Words of froxels [0, count) that are still the NaN fill (never written:
/// no payload of these tests has a word equal to it), and words past them that
/// are not (written outside the grid).
std::string unwrittenOrStray(const std::vector<uint32_t>& words, uint32_t count) {
  long unwritten = 0, stray = 0;
  for (std::size_t w = 0; w < words.size(); ++w) {
    if (w < std::size_t{count} * 3 && words[w] == kNaNFill) ++unwritten;
    if (w >= std::size_t{count} * 3 && words[w] != kNaNFill) ++stray;
  }
  if (unwritten == 0 && stray == 0) return "";
  return fmt::format("{} words of the grid's {} froxels never written, {} words past the grid written", unwritten,
                     count, stray);
}

Words froxelWords(const std::vector<uint32_t>& words, uint32_t i) {
  return {words[3 * i], words[3 * i + 1], words[3 * i + 2]};
}

const char* targetName(Target t) { return t == Target::Glsl ? "GLSL" : "HLSL"; }

class FogCloudOnGpu : public ::testing::Test {
 protected:
  void SetUp() override {
    Diagnostics diags("test");
    ctx_ = sharedContext(diags);
    ASSERT_NE(ctx_, nullptr) << "lavapipe is required (GPU tests never skip): " << diags.errorMessages();
  }

  gpu::Context* ctx_ = nullptr;
};

// ---------------------------------------------------------------------------
// 1. The froxel pass of the examples

/// The pass of `r` in `target` over `grid` for each input set, every froxel
/// checked against the double at its centre.
void checkFroxelPass(gpu::Context& ctx, const CompileResult& r, Target target, const Grid& grid, Tally& tally) {
  const VolumeKernel* pass = volumeKernel(ctx, r, target, Kernel::FroxelPass);
  ASSERT_NE(pass, nullptr);
  const Material& m = r.material;
  const auto inputSets = makeInputSets(m, 3, 0xf06u);
  for (std::size_t set = 0; set < inputSets.size(); ++set) {
    const auto& inputs = inputSets[set].values;
    const std::vector<uint32_t> words = runFroxels(ctx, *pass, m, grid, inputs);
    ASSERT_FALSE(words.empty());
    EXPECT_EQ(unwrittenOrStray(words, grid.count()), "") << m.name << " " << targetName(target) << " set " << set;
    for (uint32_t i = 0; i < grid.count(); ++i) {
      const auto c = grid.cellOf(i);
      tally.check(froxelWords(words, i), doubleSample(m, grid.point(i, inputs)),
                  fmt::format("{} {} input set {} froxel {} ({}, {}, {})", m.name, targetName(target), set, i, c[0],
                              c[1], c[2]));
    }
  }
}

TEST_F(FogCloudOnGpu, FroxelPassGivesTheDoubleSampleAtEveryFroxelCentreInGlslAndHlsl) {
  // 9 x 7 x 5 froxels over [-1.2, 1.2]^3: the puff's unit sphere and the air around it.
  const Grid grid = gridOver(-1.2, 1.2, {9, 7, 5});
  Tally tally;
  long outside = 0;  // puff froxels whose centre is outside the sphere (extinction 0)
  for (const char* stem : {"fog_cloud_puff", "fog_neon_haze"}) {
    SCOPED_TRACE(stem);
    const CompileResult r = compileExample(stem);
    ASSERT_TRUE(isVolumeMaterial(r.material));
    for (Target target : {Target::Glsl, Target::Hlsl}) checkFroxelPass(*ctx_, r, target, grid, tally);
    if (std::string(stem) == "fog_cloud_puff")
      for (uint32_t i = 0; i < grid.count(); ++i)
        outside += maxOf(doubleSample(r.material, grid.point(i, {})).extinction) == 0;
  }
  std::printf("[ fog      ] froxel pass: %ld froxels compared (2 examples x GLSL, HLSL x 3 input sets x %u), %ld "
              "bit-identical to the double's pack, %ld outside the tolerances\n",
              tally.compared, grid.count(), tally.identical, tally.failed);
  RecordProperty("froxels_compared", static_cast<int>(tally.compared));
  EXPECT_GT(outside, 0) << "the grid must reach outside the puff";
  EXPECT_LT(outside, static_cast<long>(grid.count())) << "and inside it";
  ASSERT_GT(tally.compared, 0) << "no froxel compared";
  EXPECT_EQ(tally.failed, 0) << tally.failed << " of " << tally.compared << " froxels; first: " << tally.first;
  EXPECT_GE(tally.identical, kIdenticalShare * static_cast<double>(tally.compared))
      << "payloads bit-identical to the double's pack: " << tally.identical << " of " << tally.compared;
}

// ---------------------------------------------------------------------------
// 2. The hard cases

/// A fog cloud whose every pin is an input, with no range: the uniform block
/// carries whatever the test writes, NaN and infinities included.
constexpr const char* kHardMaterial = R"({
  "format": "substrate-material/1",
  "name": "fog_hard_pins",
  "inputs": {
    "albedo": { "type": "vec3", "default": [0.5, 0.5, 0.5] },
    "extinction": { "type": "vec3", "default": [1, 1, 1] },
    "emissive": { "type": "vec3", "default": [0, 0, 0] },
    "occlusion": { "type": "float", "default": 1 }
  },
  "nodes": {
    "fog": {
      "kind": "volumetric_fog_cloud",
      "albedo": "$albedo",
      "extinction": "$extinction",
      "emissive": "$emissive",
      "ambient_occlusion": "$occlusion"
    }
  },
  "output": "fog"
})";

// 0.5 is an ordinary value, and a tie of unorm8's rounding (127.5);
// 511.75 / 256 rounds to mantissa 512 at its exponent, which RGB9E5 bumps.
const std::vector<double> kHardAlbedo = {0, 0.5, 1, 2, kNaN};
const std::vector<double> kHardExtinction = {0, 1e-30, 1, 511.75 / 256, 65408, 1e30, kInf, kNaN, -1};
const std::vector<double> kHardEmissive = {0, 1e30, kInf, kNaN};
const std::vector<double> kHardOcclusion = {0, 0.5, 1, kNaN};

/// A colour of `values`: red values[i], green and blue `rotation` and twice
/// that further on (a grey when the rotation is 0, so each value is seen
/// alone and next to the others, whose shared exponent it then shares).
std::array<double, 4> rotated(const std::vector<double>& values, std::size_t i, std::size_t rotation) {
  const std::size_t n = values.size();
  return {values[i % n], values[(i + rotation) % n], values[(i + 2 * rotation) % n], 0};
}

/// Every combination of the four pins' hard values: 5 x 9 x 4 x 4 = 720
/// sets, each as Material::inputs orders them (found by name).
std::vector<std::vector<std::array<double, 4>>> hardInputSets(const Material& m) {
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < m.inputs.size(); ++i) index[m.inputs[i].name] = i;
  std::vector<std::vector<std::array<double, 4>>> sets;
  for (std::size_t a = 0; a < kHardAlbedo.size(); ++a)
    for (std::size_t e = 0; e < kHardExtinction.size(); ++e)
      for (std::size_t s = 0; s < kHardEmissive.size(); ++s)
        for (std::size_t o = 0; o < kHardOcclusion.size(); ++o) {
          std::vector<std::array<double, 4>> set(m.inputs.size());
          set.at(index.at("albedo")) = rotated(kHardAlbedo, a, o);
          set.at(index.at("extinction")) = rotated(kHardExtinction, e, s);
          set.at(index.at("emissive")) = rotated(kHardEmissive, s, a);
          set.at(index.at("occlusion")) = {kHardOcclusion[o], 0, 0, 0};
          sets.push_back(set);
        }
  return sets;
}

std::string describeInputs(const Material& m, const std::vector<std::array<double, 4>>& in) {
  std::string s;
  for (std::size_t i = 0; i < m.inputs.size(); ++i)
    s += componentCount(m.inputs[i].type) == 1
             ? fmt::format(" {} {}", m.inputs[i].name, in[i][0])
             : fmt::format(" {} ({}, {}, {})", m.inputs[i].name, in[i][0], in[i][1], in[i][2]);
  return s;
}

/// The material function's samples (the sample kernel's 10 floats) compared
/// with the mirror's sanitized sample: the sanitizing is clamps of floats the
/// double holds exactly, so they must be equal.
struct SampleTally {
  long values = 0, nonFinite = 0, outOfRange = 0, different = 0;
  std::string first;

  void check(const std::vector<uint32_t>& words, const FogCloudSample& ref, const std::string& what) {
    const std::array<double, 10> want = {ref.albedo[0],     ref.albedo[1],     ref.albedo[2],  ref.extinction[0],
                                         ref.extinction[1], ref.extinction[2], ref.emissive[0], ref.emissive[1],
                                         ref.emissive[2],   ref.ambientOcclusion};
    for (int k = 0; k < 10; ++k) {
      const double g = std::bit_cast<float>(words.at(k)), hi = k < 3 || k == 9 ? 1 : reference::kFogMaxExtinction;
      ++values;
      const bool finite = std::isfinite(g), inRange = g >= 0 && g <= hi, equal = g == asFloat(want[k]);
      nonFinite += !finite;
      outOfRange += finite && !inRange;
      different += !equal;
      if ((!finite || !inRange || !equal) && first.empty())
        first = fmt::format("{}: value {} (albedo 0-2, extinction 3-5, emissive 6-8, ao 9) = {}, the mirror's {}", what,
                            k, g, want[k]);
    }
  }
};

TEST_F(FogCloudOnGpu, HardPinValuesGiveOnlyFiniteSanitizedSamplesAndPayloads) {
  const CompileResult r = compileVolume("fog_hard_pins.json", kHardMaterial);
  const Material& m = r.material;
  ASSERT_EQ(m.inputs.size(), 4u);
  const Grid grid = gridOver(-1, 1, {1, 1, 1});  // the pins are uniform: one froxel a set
  const auto sets = hardInputSets(m);
  Tally payloads;
  SampleTally samples;
  for (Target target : {Target::Glsl, Target::Hlsl}) {
    const VolumeKernel* pass = volumeKernel(*ctx_, r, target, Kernel::FroxelPass);
    const VolumeKernel* sample = volumeKernel(*ctx_, r, target, Kernel::Sample);
    ASSERT_TRUE(pass && sample);
    for (const auto& inputs : sets) {
      const FogCloudSample ref = doubleSample(m, grid.point(0, inputs));
      const std::string what = fmt::format("{} inputs{}", targetName(target), describeInputs(m, inputs));
      const std::vector<uint32_t> words = runFroxels(*ctx_, *pass, m, grid, inputs);
      ASSERT_FALSE(words.empty());
      ASSERT_EQ(unwrittenOrStray(words, 1), "") << what;
      payloads.check(froxelWords(words, 0), ref, what);
      const std::vector<uint32_t> floats = runKernel(*ctx_, *sample, m, grid, inputs, {1, 1}, 10);
      ASSERT_FALSE(floats.empty());
      samples.check(floats, ref, what);
    }
  }
  std::printf("[ fog      ] hard cases: GLSL, HLSL x %zu input sets: %ld payloads (%ld bit-identical to the mirror's "
              "pack, %ld outside the tolerances); %ld sample values (%ld non-finite, %ld out of range, %ld not the "
              "mirror's)\n",
              sets.size(), payloads.compared, payloads.identical, payloads.failed, samples.values, samples.nonFinite,
              samples.outOfRange, samples.different);
  RecordProperty("hard_cases", static_cast<int>(payloads.compared));
  ASSERT_GT(payloads.compared, 0) << "no hard case run";
  ASSERT_GT(samples.values, 0);
  EXPECT_EQ(samples.nonFinite, 0) << samples.first;
  EXPECT_EQ(samples.outOfRange, 0) << samples.first;
  EXPECT_EQ(samples.different, 0) << samples.first;
  // A payload's values are finite and in range by construction (unorm8, RGB9E5 up to 65408): what can go wrong is
  // the value. No arithmetic precedes the sanitizing, so the words are the mirror's, bit for bit.
  EXPECT_EQ(payloads.failed, 0) << payloads.failed << " of " << payloads.compared << " payloads; first: "
                                << payloads.first;
  EXPECT_EQ(payloads.identical, payloads.compared) << "payloads that are not the mirror's pack bit for bit";
}

// ---------------------------------------------------------------------------
// 3. The march

// One ray a case (kCaseFloats floats): the sample (albedo 0-2, extinction 3-5,
// emissive 6-8, ambient occlusion 9: raw, the step sanitizes it), the ray
// (origin 10-12, direction 13-15, length 16), the step count (17), the medium
// (18: 0 the sample, 1 the froxels), the lights (inScattered 20-22, ambient
// 23-25). Results: radiance 0-2, throughput 4-6 of 8 floats.
constexpr int kCaseFloats = 28, kResultFloats = 8;

constexpr const char* kMarchKernel = R"(#version 450
#include "substrate_prelude.glsl"
#include "substrate_fog_cloud.h"

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;
layout(std430, set = 0, binding = 0) readonly buffer Cases { float cases[]; };
// The froxel medium: origin (float bits) 0-2, cell size 3-5, counts 6-8, then 3 words a froxel from word 12, x fastest.
layout(std430, set = 0, binding = 1) readonly buffer Froxels { uint froxels[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Results { float results[]; };

float3 at3(uint i) { return float3(cases[i], cases[i + 1u], cases[i + 2u]); }

SubstrateFogCloudSample froxelAt(float3 p) {
  float3 origin = asfloat(uint3(froxels[0], froxels[1], froxels[2]));
  float3 cell = asfloat(uint3(froxels[3], froxels[4], froxels[5]));
  int3 n = int3(froxels[6], froxels[7], froxels[8]);
  int3 c = clamp(int3(floor((p - origin) / cell)), int3(0), n - int3(1));
  uint i = 12u + 3u * uint(c.x + n.x * (c.y + n.y * c.z));
  return substrate_fog_cloud_unpack(froxels[i], froxels[i + 1u], froxels[i + 2u]);
}

void main() {
  uint k = gl_GlobalInvocationID.x;
  uint at = k * 28u;
  SubstrateFogCloudSample s;
  s.albedo = at3(at);
  s.extinction = at3(at + 3u);
  s.emissive = at3(at + 6u);
  s.ambientOcclusion = cases[at + 9u];
  float3 origin = at3(at + 10u);
  float3 direction = at3(at + 13u);
  int steps = clamp(int(cases[at + 17u]), 1, 1 << 20);
  bool froxel = cases[at + 18u] > 0.5;
  float3 inScattered = at3(at + 20u);
  float3 ambient = at3(at + 23u);
  float ds = cases[at + 16u] / float(steps);
  float3 radiance = float3(0.0);
  float3 throughput = float3(1.0);
  for (int i = 0; i < steps; ++i) {
    float3 p = origin + direction * ((float(i) + 0.5) * ds);
    substrate_fog_cloud_step(froxel ? froxelAt(p) : s, ds, inScattered, ambient, radiance, throughput);
  }
  for (uint c = 0u; c < 3u; ++c) {
    results[k * 8u + c] = radiance[c];
    results[k * 8u + 4u + c] = throughput[c];
  }
}
)";

struct MarchCase {
  FogCloudSample sample;  // raw (the step sanitizes)
  D3 origin{}, direction{1, 0, 0};
  double length = 1;
  int steps = 1;
  bool froxels = false;
  D3 inScattered{1, 0.9, 0.8}, ambient{0.3, 0.3, 0.4};
};

/// The froxel medium: `grid`'s payloads of the puff at its defaults, packed by
/// the double (so this test needs no froxel pass), behind the kernel's header.
struct FroxelMedium {
  Grid grid;
  std::vector<uint32_t> buffer;  // the kernel's Froxels

  FogCloudSample at(const D3& p) const {  // froxelAt, in double
    std::array<uint32_t, 3> c{};
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<uint32_t>(
          std::clamp(std::floor((p[k] - grid.origin[k]) / grid.cell[k]), 0.0, static_cast<double>(grid.n[k] - 1)));
    const std::size_t i = 12 + 3 * (c[0] + grid.n[0] * (c[1] + grid.n[1] * c[2]));
    return reference::fogCloudUnpack({buffer[i], buffer[i + 1], buffer[i + 2]});
  }
};

FroxelMedium puffMedium() {
  const CompileResult r = compileExample("fog_cloud_puff");
  FroxelMedium f{gridOver(-1.2, 1.2, {9, 7, 5}), {}};
  const Grid& g = f.grid;
  f.buffer = {floatBits(g.origin[0]), floatBits(g.origin[1]), floatBits(g.origin[2]), floatBits(g.cell[0]),
              floatBits(g.cell[1]),   floatBits(g.cell[2]),   g.n[0],                g.n[1],
              g.n[2],                 0,                      0,                     0};
  for (uint32_t i = 0; i < g.count(); ++i)
    for (uint32_t w : reference::fogCloudPack(doubleSample(r.material, g.point(i, {})))) f.buffer.push_back(w);
  return f;
}

/// Homogeneous media: a cloud, the neon haze, no extinction, the format's
/// largest, the thin-step threshold, mixed channels, raw NaN / infinite /
/// negative / out-of-range samples; each over lengths 0, 1, 2.5, N (ds = 1),
/// 1e12 (steps clamped to 1e9), -1 and NaN, under ordinary and non-finite lights.
std::vector<MarchCase> homogeneousCases(int steps) {
  const std::vector<FogCloudSample> samples = {
      {{0.96, 0.97, 0.99}, {3, 3, 3}, {0, 0, 0}, 0.8},
      {{0.2, 0.2, 0.2}, {0.05, 0.06, 0.08}, {0.08, 0.02, 0.12}, 1},
      {{0.5, 0.5, 0.5}, {0, 0, 0}, {1, 2, 3}, 1},
      {{0.9, 0.9, 0.9}, {65408, 65408, 65408}, {65408, 1, 0}, 1},
      {{0.7, 0.8, 0.9}, {0.0099, 0.01, 0.0101}, {0.5, 0.5, 0.5}, 0.5},
      {{0.3, 0.6, 0.9}, {0, 1, 65408}, {1, 0, 5}, 0.25},
      {{kNaN, 2, -1}, {kNaN, kInf, -5}, {kInf, kNaN, -1}, kNaN},
      {{1, 1, 1}, {1e30, 1e-30, 1e30}, {1e30, 1e30, 1e-30}, 5},
  };
  std::vector<MarchCase> cases;
  for (const FogCloudSample& s : samples)
    for (double length : {0.0, 1.0, 2.5, static_cast<double>(steps), 1e12, -1.0, kNaN})
      for (int light = 0; light < 2; ++light) {
        MarchCase c;
        c.sample = s;
        c.length = length;
        c.steps = steps;
        if (light == 1) {
          c.inScattered = {kInf, kNaN, 1e38};
          c.ambient = {1e38, kInf, 0};
        }
        cases.push_back(c);
      }
  return cases;
}

/// Rays through the froxel medium along each axis, one through each column of
/// froxel centres across the grid: with the grid's n cells on the way, a
/// step's midpoint is (2i + 1) n / 2N cells in, never a cell boundary (n odd).
std::vector<MarchCase> froxelCases(const Grid& g, int steps) {
  std::vector<MarchCase> cases;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (uint32_t a = 0; a < g.n[u]; ++a)
      for (uint32_t b = 0; b < g.n[v]; ++b) {
        MarchCase c;
        c.froxels = true;
        c.steps = steps;
        c.origin[axis] = g.origin[axis];
        c.origin[u] = asFloat(g.origin[u] + (a + 0.5) * g.cell[u]);
        c.origin[v] = asFloat(g.origin[v] + (b + 0.5) * g.cell[v]);
        c.direction = {0, 0, 0};
        c.direction[axis] = 1;
        c.length = asFloat(g.n[axis] * g.cell[axis]);
        cases.push_back(c);
      }
  }
  return cases;
}

std::vector<float> caseFloats(const std::vector<MarchCase>& cases) {
  std::vector<float> f((cases.size() + kGroup - 1) / kGroup * kGroup * kCaseFloats, 0.0f);
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const MarchCase& c = cases[k];
    float* p = &f[k * kCaseFloats];
    auto put = [&](int at, const D3& v) {
      for (int i = 0; i < 3; ++i) p[at + i] = static_cast<float>(v[i]);
    };
    put(0, c.sample.albedo);
    put(3, c.sample.extinction);
    put(6, c.sample.emissive);
    p[9] = static_cast<float>(c.sample.ambientOcclusion);
    put(10, c.origin);
    put(13, c.direction);
    p[16] = static_cast<float>(c.length);
    p[17] = static_cast<float>(c.steps);
    p[18] = c.froxels ? 1.0f : 0.0f;
    put(20, c.inScattered);
    put(23, c.ambient);
  }
  return f;
}

/// marchFogCloud of case `c`, every input as the kernel reads it (rounded to float).
reference::FogMarch doubleMarch(const MarchCase& c, const FroxelMedium& medium) {
  FogCloudSample s = c.sample;
  s.albedo = asFloat(s.albedo);
  s.extinction = asFloat(s.extinction);
  s.emissive = asFloat(s.emissive);
  s.ambientOcclusion = asFloat(s.ambientOcclusion);
  auto at = [&](const D3& p) { return c.froxels ? medium.at(p) : s; };
  return reference::marchFogCloud(at, asFloat(c.origin), asFloat(c.direction), asFloat(c.length), c.steps,
                                  asFloat(c.inScattered), asFloat(c.ambient));
}

template <class T>
std::vector<std::byte> bytesOf(const std::vector<T>& v) {
  std::vector<std::byte> b(v.size() * sizeof(T));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

/// The march kernel's results for `cases` (kResultFloats a case); empty, with a test failure, on an error.
std::vector<float> runMarch(gpu::Context& ctx, const std::vector<MarchCase>& cases, const FroxelMedium& medium) {
  ShaderSource src;
  src.name = "fog_march_test.comp";
  src.text = kMarchKernel;
  src.language = ShaderLanguage::Glsl;
  src.stage = ShaderStage::Compute;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  const ShaderValidation v = compileAndValidate(src);
  EXPECT_TRUE(v.ok) << v.log;
  if (!v.ok) return {};
  Diagnostics diags("test");
  const auto pipeline = ctx.createPipeline(v.spirv, diags);
  EXPECT_NE(pipeline, nullptr) << diags.errorMessages();
  if (!pipeline) return {};
  const std::vector<float> in = caseFloats(cases);
  const std::size_t padded = in.size() / kCaseFloats;
  gpu::Resources res;
  res[{0, 0}] = gpu::BufferResource{bytesOf(in), false};
  res[{0, 1}] = gpu::BufferResource{bytesOf(medium.buffer), false};
  gpu::BufferResource out;
  out.data.resize(padded * kResultFloats * sizeof(float));
  out.output = true;
  res[{0, 2}] = out;
  const bool ok = ctx.dispatch(*pipeline, res, static_cast<uint32_t>(padded / kGroup), 1, 1, diags);
  EXPECT_TRUE(ok) << diags.errorMessages();
  return ok ? gpu::floatsOf(res, 0, 2) : std::vector<float>{};
}

std::string describeCase(const MarchCase& c) {
  return fmt::format("{} N {} length {} origin ({}, {}, {}) direction ({}, {}, {}); {}; light ({}, {}, {}) ambient "
                     "({}, {}, {})",
                     c.froxels ? "froxels" : "homogeneous", c.steps, c.length, c.origin[0], c.origin[1], c.origin[2],
                     c.direction[0], c.direction[1], c.direction[2], c.froxels ? "puff" : describe(c.sample),
                     c.inScattered[0], c.inScattered[1], c.inScattered[2], c.ambient[0], c.ambient[1], c.ambient[2]);
}

TEST_F(FogCloudOnGpu, MarchStepInFloatFollowsTheDoubleMarch) {
  const FroxelMedium medium = puffMedium();
  std::vector<MarchCase> cases;
  for (int steps : {1, 4, 16, 64}) {
    for (const MarchCase& c : homogeneousCases(steps)) cases.push_back(c);
    for (const MarchCase& c : froxelCases(medium.grid, steps)) cases.push_back(c);
  }
  const std::vector<float> results = runMarch(*ctx_, cases, medium);
  ASSERT_FALSE(results.empty());
  long compared = 0, failed = 0, froxelRays = 0, opaque = 0;
  double worst = 0;  // the largest |gpu - ref| / (the allowed difference)
  std::string first;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const reference::FogMarch ref = doubleMarch(cases[k], medium);
    froxelRays += cases[k].froxels;
    opaque += maxOf(ref.throughput) == 0;
    for (int q = 0; q < 2; ++q)
      for (int c = 0; c < 3; ++c) {
        const double r = q == 0 ? ref.radiance[c] : ref.throughput[c];
        const double g = results[k * kResultFloats + 4 * q + c];
        const double allowed = kMarchRelative * std::abs(r) + kMarchAbsolute, d = std::abs(g - r);
        ++compared;
        worst = std::max(worst, d / allowed);
        if (std::isfinite(g) && d <= allowed) continue;
        if (failed++ == 0)
          first = fmt::format("case {}: {} {} = {}, the double's {}\n  {}", k, q == 0 ? "radiance" : "throughput", c,
                              g, r, describeCase(cases[k]));
      }
  }
  std::printf("[ fog      ] march: %zu rays (%ld through the froxels, %ld opaque), N in {1, 4, 16, 64}: %ld values "
              "compared, worst %.3f of the tolerance, %ld outside\n",
              cases.size(), froxelRays, opaque, compared, worst, failed);
  RecordProperty("march_rays", static_cast<int>(cases.size()));
  ASSERT_GT(compared, 0) << "no ray marched";
  EXPECT_GT(froxelRays, 0);
  EXPECT_EQ(failed, 0) << failed << " of " << compared << " values; first: " << first;
}

}  // namespace fog_cloud_gpu_test
}  // namespace substratec::gputest
