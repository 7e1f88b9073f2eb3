#include "gpu/sample_run.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <random>

#include "pipeline/generate.h"
#include "gpu/block_layout.h"
#include "validate/runtime_files.h"

namespace substratec::gpu {

namespace {

using namespace kernel;
using V3 = std::array<double, 3>;

/// Uniform in [0, 1) from a 32-bit Mersenne twister (the same numbers on every
/// platform, unlike the standard distributions).
class Rng {
 public:
  explicit Rng(uint32_t seed) : g_(seed) {}
  double uniform() { return static_cast<double>(g_() >> 8) * (1.0 / 16777216.0); }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int below(int n) { return static_cast<int>(uniform() * n); }

 private:
  std::mt19937 g_;
};

V3 normalize(V3 v) {
  double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / l, v[1] / l, v[2] / l};
}
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

V3 onSphere(Rng& rng) {
  double z = rng.uniform(-1, 1), phi = rng.uniform(0, 2 * M_PI), r = std::sqrt(std::max(0.0, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// A direction at cosine `c` from `n`, at a random azimuth.
V3 atCosine(Rng& rng, const V3& n, const V3& t, double c) {
  V3 b = cross(n, t);
  double s = std::sqrt(std::max(0.0, 1 - c * c)), phi = rng.uniform(0, 2 * M_PI);
  V3 d;
  for (int i = 0; i < 3; ++i) d[i] = c * n[i] + s * (std::cos(phi) * t[i] + std::sin(phi) * b[i]);
  return normalize(d);
}

/// A uv inside a texel (never near its edges, also after the small integer
/// scales materials apply), wrapped up to one period either side.
double texelCoordinate(Rng& rng, double within) {
  return (rng.below(kTextureSize) + within) / kTextureSize + (rng.below(3) - 1);
}

void put(std::vector<float>& out, std::size_t at, double x, double y, double z, double w) {
  out[at] = static_cast<float>(x);
  out[at + 1] = static_cast<float>(y);
  out[at + 2] = static_cast<float>(z);
  out[at + 3] = static_cast<float>(w);
}

uint32_t hash(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

}  // namespace

std::vector<Sample> makeSamples(int count, uint32_t seed) {
  Rng rng(seed);
  std::vector<Sample> out(count);
  for (Sample& s : out) {
    reference::Geometry& g = s.geometry;
    V3 n = onSphere(rng);
    V3 t = normalize(cross(n, onSphere(rng)));  // unit and orthogonal to n
    g.N = n;
    g.T = t;
    double pick = rng.uniform(), cv;
    if (pick < 0.70) cv = rng.uniform(0.05, 1.0);
    else if (pick < 0.85) cv = rng.uniform(1e-4, 0.05);
    else if (pick < 0.90) cv = 1e-4;
    else if (pick < 0.95) cv = -rng.uniform(0.0, 1e-3);  // just behind (a normal-mapped surface)
    else cv = 1.0;
    g.V = atCosine(rng, n, t, cv);
    double cl = rng.uniform() < 0.8 ? rng.uniform(1e-3, 1.0) : -rng.uniform(0.0, 1.0);
    s.light = atCosine(rng, n, t, cl);
    g.position = {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
    g.uv0 = {texelCoordinate(rng, 0.37), texelCoordinate(rng, 0.61)};
    g.uv1 = {texelCoordinate(rng, 0.43), texelCoordinate(rng, 0.29)};
    g.vertexColor = {rng.uniform(), rng.uniform(), rng.uniform(), rng.uniform()};
    g.uvDerivatives = {rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01), rng.uniform(-0.01, 0.01),
                       rng.uniform(-0.01, 0.01)};
    g.dither = rng.uniform();
    s.radiance = {rng.uniform(0.5, 3), rng.uniform(0.5, 3), rng.uniform(0.5, 3)};
    s.prefiltered = {rng.uniform(0, 2), rng.uniform(0, 2), rng.uniform(0, 2)};
    s.irradiance = {rng.uniform(0, 3), rng.uniform(0, 3), rng.uniform(0, 3)};
  }
  return out;
}

std::vector<std::byte> sampleBuffer(const std::vector<Sample>& samples) {
  std::vector<float> f(samples.size() * kSampleVec4s * 4, 0.0f);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    const reference::Geometry& g = s.geometry;
    auto at = [&](int k) { return (i * kSampleVec4s + k) * 4; };
    put(f, at(kSamplePosition), g.position[0], g.position[1], g.position[2], g.dither);
    put(f, at(kSampleNormal), g.N[0], g.N[1], g.N[2], 0);
    put(f, at(kSampleTangent), g.T[0], g.T[1], g.T[2], 0);
    put(f, at(kSampleView), g.V[0], g.V[1], g.V[2], 0);
    put(f, at(kSampleLight), s.light[0], s.light[1], s.light[2], 0);
    put(f, at(kSampleUv), g.uv0[0], g.uv0[1], g.uv1[0], g.uv1[1]);
    put(f, at(kSampleColor), g.vertexColor[0], g.vertexColor[1], g.vertexColor[2], g.vertexColor[3]);
    put(f, at(kSampleUvDerivatives), g.uvDerivatives[0], g.uvDerivatives[1], g.uvDerivatives[2], g.uvDerivatives[3]);
    put(f, at(kSampleRadiance), s.radiance[0], s.radiance[1], s.radiance[2], 0);
    put(f, at(kSamplePrefiltered), s.prefiltered[0], s.prefiltered[1], s.prefiltered[2], 0);
    put(f, at(kSampleIrradiance), s.irradiance[0], s.irradiance[1], s.irradiance[2], 0);
  }
  std::vector<std::byte> bytes(f.size() * sizeof(float));
  std::memcpy(bytes.data(), f.data(), bytes.size());
  return bytes;
}

std::vector<float> textureTexels(int input) {
  std::vector<float> t(kTextureSize * kTextureSize * 4);
  for (int y = 0; y < kTextureSize; ++y)
    for (int x = 0; x < kTextureSize; ++x) {
      const double u = (x + 0.5) / kTextureSize, v = (y + 0.5) / kTextureSize;
      const double checker = ((x / 4 + y / 4) % 2) ? 0.8 : 0.2;
      const double noise = (hash(static_cast<uint32_t>(input * 4096 + y * kTextureSize + x)) >> 8) / 16777216.0;
      float* p = &t[(y * kTextureSize + x) * 4];
      p[0] = static_cast<float>(u);
      p[1] = static_cast<float>(v);
      p[2] = static_cast<float>(checker);
      p[3] = static_cast<float>(0.25 + 0.5 * noise);
    }
  return t;
}

std::array<double, 4> sampleTexture(int input, double u, double v) {
  static std::mutex mutex;
  static std::map<int, std::vector<float>> cache;
  const std::vector<float>* texels;
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(input);
    if (it == cache.end()) it = cache.emplace(input, textureTexels(input)).first;
    texels = &it->second;
  }
  // Nearest, repeat: texel floor(frac(u) * size), as Vulkan addresses it.
  auto texel = [](double c) {
    int i = static_cast<int>(std::floor((c - std::floor(c)) * kTextureSize));
    return std::clamp(i, 0, kTextureSize - 1);
  };
  const float* p = &(*texels)[(texel(v) * kTextureSize + texel(u)) * 4];
  return {p[0], p[1], p[2], p[3]};
}

std::string_view textureSetName(TextureSet set) { return set == TextureSet::Neutral ? "neutral" : "checker"; }

std::vector<TextureRole> textureRoles(const Material& m) {
  // Marks on the DAG (bit 0: reaches a normal, bit 1: reaches a tangent),
  // pushed from the uses to the arguments: ids are topologically sorted
  // (arguments have smaller ids), so one sweep from the top is enough.
  constexpr std::uint8_t kNormal = 1, kTangent = 2;
  const ValueDag& dag = m.values;
  std::vector<std::uint8_t> mark(dag.size(), 0);
  auto seed = [&](ValueId v, std::uint8_t bit) {
    if (v != kNoValue && v < mark.size()) mark[v] |= bit;
  };
  for (const Slab& slab : m.slabs) {
    seed(slab.pin(SlabPin::Normal), kNormal);
    seed(slab.pin(SlabPin::Tangent), kTangent);
  }
  for (ValueId id = 0; id < dag.size(); ++id) {  // the helpers' own normals
    const ValueNode& n = dag.node(id);
    if (n.op == Op::ThinFilm) seed(n.args[0], kNormal);
    if (n.op == Op::RotationToTangent || n.op == Op::ViewDependentCoverage) seed(n.args[1], kNormal);
  }
  std::vector<TextureRole> roles(m.inputs.size(), TextureRole::Colour);
  std::vector<std::uint8_t> inputMark(m.inputs.size(), 0);
  for (ValueId id = static_cast<ValueId>(dag.size()); id-- > 0;) {
    if (!mark[id]) continue;
    const ValueNode& n = dag.node(id);
    if (n.op == Op::Sample && n.attr < inputMark.size()) inputMark[n.attr] |= mark[id];
    for (int a = 0; a < n.argCount; ++a) seed(n.args[a], mark[id]);
  }
  for (std::size_t i = 0; i < roles.size(); ++i)
    if (m.inputs[i].type == VType::Texture)
      roles[i] = (inputMark[i] & kNormal) ? TextureRole::Normal
                 : (inputMark[i] & kTangent) ? TextureRole::Tangent
                                             : TextureRole::Colour;
  return roles;
}

std::array<double, 4> neutralTexel(TextureRole role) {
  switch (role) {
    case TextureRole::Normal: return {0.5, 0.5, 1, 1};
    case TextureRole::Tangent: return {1, 0.5, 0.5, 1};
    case TextureRole::Colour: break;
  }
  return {0.5, 0.5, 0.5, 1};
}

reference::TextureFn textureFunction(const Material& m, TextureSet set) {
  if (set == TextureSet::Checker) return sampleTexture;
  std::vector<std::array<double, 4>> texels;
  for (TextureRole role : textureRoles(m)) texels.push_back(neutralTexel(role));
  return [texels](int input, double, double) {
    return input >= 0 && static_cast<std::size_t>(input) < texels.size() ? texels[input] : neutralTexel(TextureRole::Colour);
  };
}

Resources kernelResources(const Material& m, const ShaderReflection& reflection,
                               const std::vector<uint32_t>& spirv, const std::vector<std::array<double, 4>>& inputValues,
                               const std::vector<std::byte>& samples, std::size_t resultFloats, TextureSet textures) {
  const std::vector<TextureRole> roles =
      textures == TextureSet::Neutral ? textureRoles(m) : std::vector<TextureRole>{};
  Resources res;
  for (const DescriptorBinding& b : reflection.bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    if (b.set == 0 && b.binding == 5) {  // the energy tables
      auto lut = energyLutTables();
      BufferResource buf;
      buf.data.resize(lut.size_bytes());
      std::memcpy(buf.data.data(), lut.data(), lut.size_bytes());
      res[key] = buf;
    } else if (b.set == 0 && b.binding == 6) {
      res[key] = BufferResource{samples, false};
    } else if (b.set == 0 && b.binding == 7) {
      BufferResource out;
      out.data.resize(resultFloats * sizeof(float));
      out.output = true;
      res[key] = out;
    } else if (b.set == 1 && b.binding == 0) {  // the material's inputs
      res[key] = BufferResource{inputBlockBytes(m, blockMembers(spirv, 1, 0), inputValues), false};
    } else if (b.set == 1 && (b.kind == DescriptorKind::CombinedImageSampler ||
                              b.kind == DescriptorKind::SampledImage)) {
      const int index = inputOfResource(m, b.name);
      ImageResource img;
      img.width = img.height = kTextureSize;
      if (textures == TextureSet::Neutral) {
        const auto texel = neutralTexel(index >= 0 && static_cast<std::size_t>(index) < roles.size()
                                            ? roles[index]
                                            : TextureRole::Colour);
        std::vector<float> flat(kTextureSize * kTextureSize * 4);
        for (std::size_t i = 0; i < flat.size(); ++i) flat[i] = static_cast<float>(texel[i % 4]);
        img.mips = {flat};
      } else {
        img.mips = {textureTexels(index)};
      }
      res[key] = img;
    } else if (b.set == 1 && b.kind == DescriptorKind::Sampler) {
      res[key] = SamplerResource{};
    }
    // Anything else stays unbound: the harness names it.
  }
  return res;
}

int resultStride(const CompileResult& r) {
  return kResultHeaderFloats + kClosureFloats * static_cast<int>(r.after.closures.size());
}

std::vector<float> floatsOf(const Resources& resources, uint32_t set, uint32_t binding) {
  const auto& buf = std::get<BufferResource>(resources.at({set, binding}));
  std::vector<float> f(buf.data.size() / sizeof(float));
  std::memcpy(f.data(), buf.data.data(), f.size() * sizeof(float));
  return f;
}

bool canRun(const Context& ctx, Precision precision, Diagnostics& diags) {
  if (precision == Precision::Float || ctx.shaderFloat16()) return true;
  diags.fail("half precision needs a Vulkan device with shaderFloat16 (" + ctx.deviceName() + " has none)");
  return false;
}

std::unique_ptr<ComputePipeline> kernelPipeline(Context& ctx, const CompileResult& r, Target target, KernelMode mode,
                                                const EmitOptions& emit, const char* what, std::vector<uint32_t>* spirv,
                                                Diagnostics& diags) {
  ShaderValidation v = compileKernel(r, target, mode, emit);
  if (!v.ok) {
    diags.fail(std::string("internal compiler error: the ") + what + " kernel does not validate\n" + v.log);
    return nullptr;
  }
  *spirv = std::move(v.spirv);
  return ctx.createPipeline(*spirv, diags);
}

bool runSampleKernel(Context& ctx, const CompileResult& r, Target target, KernelMode mode, const EmitOptions& emit,
                     const std::vector<Sample>& samples, const std::vector<std::array<double, 4>>& inputValues,
                     std::vector<float>* results, Diagnostics& diags) {
  if (!canRun(ctx, emit.precision, diags)) return false;
  std::vector<uint32_t> spirv;
  auto pipeline = kernelPipeline(ctx, r, target, mode, emit, "sample", &spirv, diags);
  if (!pipeline) return false;
  Resources res = kernelResources(r.material, pipeline->reflection(), spirv, inputValues, sampleBuffer(samples),
                                  samples.size() * static_cast<std::size_t>(resultStride(r)));
  if (!ctx.dispatch(*pipeline, res, static_cast<uint32_t>(samples.size() / kLocalSize), 1, 1, diags)) return false;
  *results = floatsOf(res, 0, 7);
  return true;
}

}  // namespace substratec::gpu
