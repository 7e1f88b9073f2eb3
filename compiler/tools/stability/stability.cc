#include "stability/stability.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "blocks/expand.h"
#include "pipeline/generate.h"
#include "emit/kernel_emitter.h"
#include "gpu/sample_run.h"
#include "reference/hair.h"
#include "reference/reference.h"

namespace substratec::stability {

namespace {

using json = nlohmann::ordered_json;
using V3 = std::array<double, 3>;

constexpr std::size_t kMaxCases = 16;
constexpr std::size_t kFurnaceConfigurations = 128;  // white-furnace configurations (4,096-point integrals each, 3 views)
constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);

/// The forced values of each kind (docs/stability.md), smallest first.
const std::vector<std::pair<std::string, std::vector<double>>>& kindTable() {
  static const std::vector<std::pair<std::string, std::vector<double>>> table = {
      {"roughness", {0, 1e-4, 0.02, 0.5, 1}}, {"anisotropy", {-1, 0, 1}},     {"f0", {0, 1}},
      {"f90", {0, 1}},                        {"albedo", {0, 1}},             {"coverage", {0, 1e-7, 1}},
      {"mfp", {0, 1e-9, 1e6}},                {"thickness", {0, 1e-9, 10}},
      {"ior", {1, 1.0001, 3}},                {"cuticle_angle", {-20, 0, 20}},  // a hair's
  };
  return table;
}

/// p * (1 - f) + v * f, as value nodes.
json forcedPin(const json& own, const ForcedKind& k) {
  return json{{"kind", "add"},
              {"a", json{{"kind", "multiply"}, {"a", own}, {"b", json{{"kind", "one_minus"}, {"x", "$" + k.flagInput}}}}},
              {"b", json{{"kind", "multiply"}, {"a", "$" + k.valueInput}, {"b", "$" + k.flagInput}}}};
}

struct Rewriter {
  std::vector<ForcedKind> kinds;  // every kind of the table, with input names
  std::set<std::string> used;     // kinds that forced at least one pin

  ForcedKind& kind(const std::string& name) {
    for (ForcedKind& k : kinds)
      if (k.name == name) return k;
    throw std::logic_error("unknown kind " + name);
  }
  /// Forces `pin` of `node`; when absent, from `fallback` (its default) unless null.
  void force(json& node, const char* pin, const std::string& kindName, const json& fallback) {
    json own;
    if (node.contains(pin)) own = node[pin];
    else if (!fallback.is_null()) own = fallback;
    else return;
    node[pin] = forcedPin(own, kind(kindName));
    ++kind(kindName).pins;
    used.insert(kindName);
  }
  void visit(json& node) {
    if (!node.is_object()) return;
    for (auto& [key, value] : node.items())  // inline Substrate nodes first: their pins are theirs
      if (value.is_object() && value.contains("kind")) visit(value);
    if (!node.contains("kind") || !node["kind"].is_string()) return;
    const std::string kind = node["kind"];
    if (kind == "slab") {
      force(node, "roughness", "roughness", 0.5);
      force(node, "second_roughness", "roughness", nullptr);
      force(node, "fuzz_roughness", "roughness", nullptr);
      force(node, "anisotropy", "anisotropy", nullptr);
      force(node, "f0", "f0", 0.04);
      force(node, "f90", "f90", nullptr);
      force(node, "diffuse_albedo", "albedo", 0.18);
      force(node, "sss_mfp", "mfp", nullptr);
    } else if (kind == "hair") {  // absorption 0 (white) and huge (black), every lobe width
      force(node, "base_color", "albedo", 0.0);
      force(node, "roughness", "roughness", 0.5);
      force(node, "azimuthal_roughness", "roughness", 0.5);
      force(node, "ior", "ior", 1.55);
      force(node, "cuticle_angle", "cuticle_angle", 2.0);
      force(node, "scatter", "coverage", 0.0);
    } else if (kind == "eye") {  // a smooth and a rough cornea, black and white, all sclera and all iris
      force(node, "roughness", "roughness", 0.5);
      force(node, "diffuse_albedo", "albedo", 0.18);
      force(node, "iris_mask", "coverage", 0.0);
      force(node, "iris_distance", "coverage", 0.0);
      force(node, "sss_mfp", "mfp", nullptr);  // a scattering sclera's: zero to huge
    } else if (kind == "single_layer_water") {  // its surface's roughness, all foam or none, clear to opaque water
      force(node, "roughness", "roughness", 0.5);
      force(node, "base_color", "albedo", 0.0);
      force(node, "top_material_opacity", "coverage", 0.0);
      force(node, "water_albedo", "albedo", 0.0);
      force(node, "water_extinction", "mfp", 0.0);  // 0, 1e-9 and 1e6 per metre
    } else if (kind == "unlit") {
      force(node, "transmittance", "albedo", 1.0);  // 0 (opaque) and 1 (clear)
    } else if (kind == "vertical") {
      force(node, "thickness", "thickness", 0.0001);
    } else if (kind == "coverage_weight") {
      force(node, "weight", "coverage", nullptr);
    } else if (kind == "horizontal") {
      force(node, "mix", "coverage", nullptr);
    }
  }
};

std::string uniqueName(const json& inputs, const std::string& base) {
  std::string name = base;
  for (int i = 1; inputs.contains(name); ++i) name = fmt::format("{}_{}", base, i);
  return name;
}

// ---------------------------------------------------------------- the grid

/// A shading point of the grid, and how to name it.
struct Point {
  reference::Geometry g;
  V3 light{0, 0, 1};
  std::string label;
};

V3 normalized(V3 v) {
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / l, v[1] / l, v[2] / l};
}
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

std::vector<Point> shadingPoints() {
  const std::vector<std::pair<V3, const char*>> normals = {
      {{0, 0, 1}, "+Z (pole)"},
      {{0, 0, -1}, "-Z (pole)"},
      {{1, 0, 0}, "+X (seam)"},
      {{-1, 0, 0}, "-X (seam)"},
      {{0, 1, 0}, "+Y (seam)"},
      {{0, -1, 0}, "-Y (seam)"},
      {normalized({1, 1, 0}), "(1,1,0) (seam diagonal)"},
      {normalized({1, 0, -1}), "(1,0,-1) (lower hemisphere)"},
      {normalized({0.5, 0.5, -1e-7}), "(0.5,0.5,-1e-7) (across the fold)"},
      {normalized({0.3, 0.5, 0.81}), "(0.3,0.5,0.81)"},
  };
  const double cosines[] = {-1e-4, 0, 1e-4, 0.5, 1};
  std::vector<Point> out;
  for (const auto& [N, nName] : normals) {
    // An orthonormal frame around N (any: the grid names its own tangents).
    const V3 helper = std::abs(N[2]) < 0.9 ? V3{0, 0, 1} : V3{1, 0, 0};
    const V3 t = normalized(cross(helper, N));
    const V3 b = cross(N, t);
    const std::vector<std::pair<V3, const char*>> tangents = {{t, "orthogonal"}, {N, "parallel to N"}, {{0, 0, 0}, "zero"}};
    for (const auto& [T, tName] : tangents)
      for (double cv : cosines)
        for (double cl : cosines)
          for (int opposite = 0; opposite < 2; ++opposite) {
            Point p;
            p.g.N = N;
            p.g.T = T;
            const double sv = std::sqrt(std::max(0.0, 1 - cv * cv)), sl = std::sqrt(std::max(0.0, 1 - cl * cl));
            const double side = opposite ? -1 : 1;
            for (int k = 0; k < 3; ++k) {
              p.g.V[k] = cv * N[k] + sv * t[k];
              p.light[k] = cl * N[k] + side * sl * t[k];
            }
            (void)b;
            p.g.position = N;
            p.g.uv0 = {0.53, 0.47};
            p.g.uv1 = {0.21, 0.79};
            p.g.uvDerivatives = {1e-3, 0, 0, 1e-3};
            p.g.dither = 0.5;
            p.label = fmt::format("N={} T={} NoV={:g} NoL={:g} light {} azimuth", nName, tName, cv, cl,
                                  opposite ? "opposite" : "same");
            out.push_back(p);
          }
  }
  return out;
}

/// Configuration `c`: a choice per kind (0 = own, i = values[i - 1]) and an input set.
struct Configuration {
  std::vector<int> choice;
  int inputSet = 0;  // 0 defaults, 1 minima, 2 maxima
};

struct Grid {
  std::vector<ForcedKind> kinds;
  int inputSets = 1;
  long count = 1;

  Configuration at(long index) const {
    Configuration c;
    c.inputSet = static_cast<int>(index % inputSets);
    index /= inputSets;
    for (const ForcedKind& k : kinds) {
      const long n = static_cast<long>(k.values.size()) + 1;
      c.choice.push_back(static_cast<int>(index % n));
      index /= n;
    }
    return c;
  }
  std::string describe(const Configuration& c) const {
    std::string s;
    for (std::size_t i = 0; i < kinds.size(); ++i)
      s += c.choice[i] == 0 ? fmt::format("{}=own ", kinds[i].name)
                            : fmt::format("{}={:g} ", kinds[i].name, kinds[i].values[c.choice[i] - 1]);
    static const char* sets[] = {"defaults", "minima", "maxima"};
    return s + "inputs=" + sets[c.inputSet];
  }
};

bool isForcingInput(const std::vector<ForcedKind>& kinds, const std::string& name) {
  for (const ForcedKind& k : kinds)
    if (k.flagInput == name || k.valueInput == name) return true;
  return false;
}

bool hasRange(const Material& m, const std::vector<ForcedKind>& kinds) {
  for (const Input& in : m.inputs)
    if (in.type != VType::Texture && !isForcingInput(kinds, in.name) && (in.min || in.max)) return true;
  return false;
}

/// The inputs of a configuration (one per Material::inputs entry). `white`: colour inputs at 1.
reference::InputValues inputsOf(const Material& m, const Grid& grid, const Configuration& c, bool white = false) {
  reference::InputValues v;
  for (const Input& in : m.inputs) {
    std::array<double, 4> x = in.defaultValue;
    bool forcing = false;
    for (std::size_t k = 0; k < grid.kinds.size(); ++k) {
      const ForcedKind& kind = grid.kinds[k];
      if (in.name == kind.flagInput) x = {c.choice[k] ? 1.0 : 0.0, 0, 0, 0}, forcing = true;
      if (in.name == kind.valueInput) x = {c.choice[k] ? kind.values[c.choice[k] - 1] : 0.0, 0, 0, 0}, forcing = true;
    }
    if (!forcing && in.type != VType::Texture) {
      if (c.inputSet == 1 && in.min) x = *in.min;
      if (c.inputSet == 2 && in.max) x = *in.max;
      if (white && in.isColor) x = {1, 1, 1, 1};
    }
    v.values.push_back(x);
  }
  return v;
}

template <class T>
bool finite3(const std::array<T, 3>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// The first non-finite quantity of a closure, or "".
template <class T>
std::string badField(const reference::Closure<T>& c) {
  if (!finite3(c.diffuseAlbedo)) return "diffuse_albedo";
  if (!finite3(c.f0)) return "f0";
  if (!finite3(c.f90)) return "f90";
  if (!std::isfinite(c.roughness)) return "roughness";
  if (!std::isfinite(c.anisotropy)) return "anisotropy";
  if (!finite3(c.N)) return "N";
  if (!finite3(c.T_)) return "T";
  if (!finite3(c.sssMfp)) return "sss_mfp";
  if (!std::isfinite(c.sssPhaseAnisotropy)) return "sss_phase_anisotropy";
  if (!std::isfinite(c.secondRoughness) || !std::isfinite(c.secondRoughnessWeight)) return "haze";
  if (!std::isfinite(c.fuzzAmount) || !finite3(c.fuzzColor) || !std::isfinite(c.fuzzRoughness)) return "fuzz";
  if (!std::isfinite(c.glintValue)) return "glint_value";
  if (!finite3(c.emissive)) return "emissive";
  if (!std::isfinite(c.weight)) return "weight";
  if (!finite3(c.topTransmittance)) return "top_transmittance";
  if (!std::isfinite(c.coverageAbove)) return "coverage_above";
  return "";
}

template <class T>
std::array<T, 3> toT(const V3& v) {
  return {static_cast<T>(v[0]), static_cast<T>(v[1]), static_cast<T>(v[2])};
}

/// One CPU evaluation in T: "" if everything is finite, else what is not (and its value).
template <class T>
std::string evaluate(const CompileResult& r, const Point& p, const reference::InputValues& in,
                     const reference::TextureFn& textures, double* value) {
  const auto m = reference::evaluateMaterial<T>(r, p.g, in, textures);
  if (!std::isfinite(m.coverage)) return *value = m.coverage, "coverage";
  if (!finite3(m.transmittance)) return *value = m.transmittance[0], "transmittance";
  if (!finite3(m.emission)) return *value = m.emission[0], "emission";
  const auto V = toT<T>(p.g.V), L = toT<T>(p.light), one = toT<T>({1, 1, 1}), pi = toT<T>({std::numbers::pi, std::numbers::pi, std::numbers::pi});
  if (m.water) {  // a water's body: a white background behind 0, 1 m and 1e30 m of it
    for (T depth : {T(0), T(1), T(1e30)}) {
      const auto seen = reference::waterSeen<T>(m.closures[0], *m.water, {T(1), T(1), T(1), depth}, T(0), V, L, one);
      if (!finite3(seen)) return *value = seen[0], fmt::format("water body at {:g} m", double(depth));
    }
  }
  for (std::size_t k = 0; k < m.closures.size(); ++k) {
    const auto& c = m.closures[k];
    if (std::string f = badField(c); !f.empty()) return *value = NAN, fmt::format("closure {} {}", k, f);
    const T NoV = c.N[0] * V[0] + c.N[1] * V[1] + c.N[2] * V[2];
    const auto direct = reference::lightClosure<T>(c, V, L, one, kDiffuseModel);
    if (!finite3(direct)) return *value = direct[0], fmt::format("closure {} direct light", k);
    const auto viewT = reference::viewThroughput<T>(c, NoV, V);
    if (!finite3(viewT)) return *value = viewT[0], fmt::format("closure {} view throughput", k);
    const auto env = reference::envSplitSum<T>(c, V, one, pi, kDiffuseModel);
    if (!finite3(env)) return *value = env[0], fmt::format("closure {} split-sum environment", k);
    T coverage = T(1);
    std::array<T, 3> transmittance{};
    reference::translucency<T>(c, NoV, V, coverage, transmittance);
    if (!std::isfinite(coverage) || !finite3(transmittance))
      return *value = coverage, fmt::format("closure {} translucency", k);
  }
  return "";
}

/// Which result float of a sample kernel is `at` (kernel_emitter.h's layout).
std::string resultName(int at) {
  using namespace kernel;
  if (at < kResultHeaderFloats) {
    if (at == kResultCoverage) return "coverage";
    if (at >= kResultTransmittance && at < kResultTransmittance + 4) return "transmittance";
    if (at >= kResultDirect && at < kResultDirect + 4) return "direct light";
    if (at >= kResultEnvironment && at < kResultEnvironment + 4) return "split-sum environment";
    if (at >= kResultEmissive && at < kResultEmissive + 4) return "emissive";
    return fmt::format("header float {}", at);
  }
  const int k = (at - kResultHeaderFloats) / kClosureFloats, f = (at - kResultHeaderFloats) % kClosureFloats;
  return fmt::format("closure {} float {}", k, f);
}

bool runGpu(const CompileResult& r, const Grid& grid, const std::vector<Point>& points,
            const std::vector<std::pair<long, int>>& work, gpu::TextureSet textures, gpu::Context& ctx, Report* report,
            Diagnostics& diags) {
  EmitOptions emit;
  emit.inputsPerInvocation = true;
  emit.precision = report->precision;
  if (!gpu::canRun(ctx, emit.precision, diags)) return false;
  int inputCount = 0;
  for (const Input& in : r.material.inputs) inputCount += in.type != VType::Texture;
  const int stride = gpu::resultStride(r);
  constexpr std::size_t kChunk = 16384;
  for (KernelMode mode : {KernelMode::Forward, KernelMode::Deferred}) {
    const char* where = mode == KernelMode::Forward ? "gpu forward" : "gpu deferred";
    std::vector<uint32_t> spirv;
    auto pipeline = gpu::kernelPipeline(ctx, r, Target::Glsl, mode, emit, "stability", &spirv, diags);
    if (!pipeline) return false;
    for (std::size_t start = 0; start < work.size(); start += kChunk) {
      const std::size_t n = std::min(kChunk, work.size() - start);
      const std::size_t padded = (n + kernel::kLocalSize - 1) / kernel::kLocalSize * kernel::kLocalSize;
      std::vector<gpu::Sample> samples(padded);
      std::vector<float> inputs(padded * std::max(inputCount, 1) * 4, 0.0f);
      for (std::size_t j = 0; j < padded; ++j) {
        const auto [config, point] = work[start + std::min(j, n - 1)];
        const Point& p = points[point];
        samples[j].geometry = p.g;
        samples[j].light = p.light;
        samples[j].radiance = {1, 1, 1};
        samples[j].prefiltered = {1, 1, 1};
        samples[j].irradiance = {std::numbers::pi, std::numbers::pi, std::numbers::pi};
        const reference::InputValues in = inputsOf(r.material, grid, grid.at(config));
        int slot = 0;
        for (std::size_t i = 0; i < r.material.inputs.size(); ++i) {
          if (r.material.inputs[i].type == VType::Texture) continue;
          for (int c = 0; c < 4; ++c)
            inputs[(j * inputCount + slot) * 4 + c] = static_cast<float>(in.values[i][c]);
          ++slot;
        }
      }
      gpu::Resources res = gpu::kernelResources(r.material, pipeline->reflection(), spirv, {},
                                                gpu::sampleBuffer(samples), padded * stride, textures);
      {  // bound even without inputs: the kernel declares it (a material of literals only)
        gpu::BufferResource buf;
        buf.data.resize(inputs.size() * sizeof(float));
        std::memcpy(buf.data.data(), inputs.data(), buf.data.size());
        res[{0, 8}] = buf;
      }
      if (!ctx.dispatch(*pipeline, res, static_cast<uint32_t>(padded / kernel::kLocalSize), 1, 1, diags)) return false;
      const std::vector<float> out = gpu::floatsOf(res, 0, 7);
      for (std::size_t j = 0; j < n; ++j) {
        ++report->gpuEvaluations;
        for (int f = 0; f < stride; ++f) {
          const float x = out[j * stride + f];
          if (std::isfinite(x)) continue;
          ++report->gpuNonfinite;
          if (report->worst.size() < kMaxCases) {
            const auto [config, point] = work[start + j];
            report->worst.push_back(
                {where, resultName(f), grid.describe(grid.at(config)), points[point].label, static_cast<double>(x)});
          }
          break;
        }
      }
    }
  }
  return true;
}

/// The furnace: directional albedo (sum over closures of the view throughput
/// times the importance-sampled integral under a white environment) of
/// configurations with white inputs and albedo forced to 1, at NoV 1, 0.5, 0.1.
/// Counts the evaluations and those that returned any light (the lit ones: a
/// normal turned away from the view returns none, and tests nothing).
void furnace(const CompileResult& r, const Grid& grid, int samples, const reference::TextureFn& textures,
             Report* report) {
  // The configurations with albedo 1 (when the material has the kind), at most kFurnaceConfigurations spread over the grid.
  std::vector<long> chosen;
  int albedo = -1;
  for (std::size_t k = 0; k < grid.kinds.size(); ++k)
    if (grid.kinds[k].name == "albedo") albedo = static_cast<int>(k);
  std::vector<long> all;
  for (long c = 0; c < grid.count; ++c) {
    const Configuration cfg = grid.at(c);
    if (cfg.inputSet != 0) continue;
    if (albedo >= 0 && (cfg.choice[albedo] == 0 || grid.kinds[albedo].values[cfg.choice[albedo] - 1] != 1)) continue;
    all.push_back(c);
  }
  // A scattered sample (a multiplicative hash of the rank), not a stride: a
  // stride through the mixed-radix index would alias with the kinds' radices.
  const std::size_t want = std::min<std::size_t>(kFurnaceConfigurations, all.size());
  std::set<std::size_t> taken;
  for (std::uint64_t i = 0; taken.size() < want; ++i) {
    const std::size_t j = static_cast<std::size_t>((i * 0x9E3779B97F4A7C15ull) >> 11) % all.size();
    if (taken.insert(j).second) chosen.push_back(all[j]);
  }
  std::uint32_t seed = 11;
  for (long c : chosen) {
    const Configuration cfg = grid.at(c);
    const reference::InputValues in = inputsOf(r.material, grid, cfg, /*white=*/true);
    for (double mu : {1.0, 0.5, 0.1}) {
      reference::Geometry g;
      g.V = {std::sqrt(1 - mu * mu), 0, mu};
      const auto m = reference::evaluateMaterial<double>(r, g, in, textures);
      double albedoSum[3] = {0, 0, 0};
      for (auto cl : m.closures) {
        // Glints conserve energy over a pixel's footprint, not at a point: a
        // sparkle returns many times the light in its few directions.
        cl.features &= ~reference::kFeatureGlint;
        cl.glintValue = 1;
        const double NoV = cl.N[0] * g.V[0] + cl.N[1] * g.V[1] + cl.N[2] * g.V[2];
        const V3 t = reference::viewThroughput<double>(cl, NoV, V3{g.V[0], g.V[1], g.V[2]});
        // A fibre scatters all around: its albedo is over the sphere, by quadrature.
        const V3 e = (cl.features & reference::kFeatureHair)
                         ? reference::hairAlbedoIntegrated(cl, V3{g.V[0], g.V[1], g.V[2]})
                         : reference::envIntegrated(
                               cl, g.V, [](const V3&) { return V3{1, 1, 1}; }, kDiffuseModel, samples, seed++);
        for (int k = 0; k < 3; ++k) albedoSum[k] += t[k] * e[k];
      }
      const double a = std::max({albedoSum[0], albedoSum[1], albedoSum[2]});
      ++report->furnaceEvaluations;
      if (a > 0) ++report->furnaceLit;
      if (a > report->furnaceMax || report->furnaceWorst.where.empty()) {
        report->furnaceMax = std::max(report->furnaceMax, a);
        report->furnaceWorst = {"furnace", "directional albedo (largest channel)", grid.describe(cfg),
                                fmt::format("N=+Z NoV={:g}", mu), a};
      }
    }
  }
}

}  // namespace

CompileOptions forcingOptions(const CompileOptions& base, const std::vector<ForcedKind>& kinds) {
  CompileOptions o = base;
  constexpr std::size_t kNodesPerPin = 4;  // forcedPin: add, two multiplies, one_minus
  for (const ForcedKind& k : kinds) {
    o.resolve.maxInputs += 2;
    o.resolve.maxNodes += kNodesPerPin * static_cast<std::size_t>(k.pins);
  }
  return o;
}

bool forceableText(const std::string& text, std::string* rewritten, std::vector<ForcedKind>* kinds,
                   Diagnostics& diags) {
  json doc = json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) {
    diags.fail("the material is not a JSON object");
    return false;
  }
  // The forced pins are the slabs' and operators' a building block stands
  // for: its expansion's (blocks/expand.h), rewritten as a hand-written one.
  if (blocks::hasBuildingBlocks(doc)) {
    std::vector<blocks::ExpandedBlock> expanded;
    auto flat = blocks::expandBuildingBlocks(doc, diags, ResolveLimits{}, expanded);
    if (!flat) return false;
    doc = std::move(*flat);
  }
  if (!doc.contains("inputs") || !doc["inputs"].is_object()) doc["inputs"] = json::object();
  Rewriter rw;
  for (const auto& [name, values] : kindTable()) {
    ForcedKind k;
    k.name = name;
    k.values = values;
    k.flagInput = uniqueName(doc["inputs"], "stability_force_" + name);
    k.valueInput = uniqueName(doc["inputs"], "stability_" + name);
    rw.kinds.push_back(k);
  }
  if (doc.contains("nodes") && doc["nodes"].is_object())
    for (auto& [id, node] : doc["nodes"].items()) rw.visit(node);
  kinds->clear();
  for (const ForcedKind& k : rw.kinds) {
    if (!rw.used.count(k.name)) continue;
    doc["inputs"][k.flagInput] = json{{"type", "float"}, {"default", 0}, {"min", 0}, {"max", 1}};
    doc["inputs"][k.valueInput] =
        json{{"type", "float"}, {"default", k.values.front()}, {"min", k.values.front()}, {"max", k.values.back()}};
    kinds->push_back(k);
  }
  *rewritten = doc.dump(1);
  return true;
}

bool run(const CompileResult& r, const std::vector<ForcedKind>& kinds, const Options& o, gpu::Context* gpu,
         Report* report, Diagnostics& diags) {
  Grid grid;
  grid.kinds = kinds;
  grid.inputSets = hasRange(r.material, kinds) ? 3 : 1;
  grid.count = grid.inputSets;
  for (const ForcedKind& k : kinds) grid.count *= static_cast<long>(k.values.size()) + 1;
  const std::vector<Point> points = shadingPoints();
  report->material = r.material.name;
  report->precision = o.precision;
  report->textures = o.textures;
  const reference::TextureFn textures = gpu::textureFunction(r.material, o.textures);
  for (const ForcedKind& k : kinds) report->forced.push_back(k.name);
  report->configurations = grid.count;
  report->shadingPoints = static_cast<long>(points.size());

  // The work list: perConfiguration points per configuration, rotating through the points.
  const long per = std::max(1L, (o.evaluations + grid.count - 1) / grid.count);
  std::vector<std::pair<long, int>> work;
  work.reserve(static_cast<std::size_t>(grid.count * per));
  long next = 0;
  for (long c = 0; c < grid.count; ++c)
    for (long k = 0; k < per; ++k) work.emplace_back(c, static_cast<int>(next++ % static_cast<long>(points.size())));

  report->cpu = o.cpu;
  if (o.cpu) {
    for (const auto& [config, point] : work) {
      const Configuration cfg = grid.at(config);
      const reference::InputValues in = inputsOf(r.material, grid, cfg);
      ++report->evaluations;
      double value = 0;
      std::string bad = evaluate<double>(r, points[point], in, textures, &value);
      const char* where = "cpu double";
      if (bad.empty()) {
        bad = evaluate<float>(r, points[point], in, textures, &value);
        where = "cpu float";
      }
      if (bad.empty()) continue;
      ++report->nonfinite;
      if (report->worst.size() < kMaxCases)
        report->worst.push_back({where, bad, grid.describe(cfg), points[point].label, value});
    }
  }
  if (o.gpu && !runGpu(r, grid, points, work, o.textures, *gpu, report, diags)) return false;
  // The furnace measures reflection: a material with no closure (unlit
  // nodes only) reflects nothing, by definition, so it has no furnace.
  report->furnaceApplicable = !r.after.closures.empty();
  if (o.cpu && report->furnaceApplicable) furnace(r, grid, o.furnaceSamples, textures, report);
  report->furnaceJudged = o.cpu && report->furnaceApplicable;
  // `add` sums two pieces of matter: more light than arrives, by construction.
  for (const TreeNode& n : r.material.nodes)
    if (n.op == TreeOp::Add) report->furnaceJudged = false;
  return true;
}

bool furnaceExercised(const Report& r) { return !r.cpu || !r.furnaceApplicable || r.furnaceLit > 0; }

bool passed(const Report& r) {
  return r.nonfinite == 0 && r.gpuNonfinite == 0 && !(r.furnaceJudged && r.furnaceMax > kFurnaceLimit) &&
         furnaceExercised(r);
}

std::string formatText(const Report& r) {
  std::string s = fmt::format("----- STABILITY - {} -----\n", r.material);
  s += fmt::format("forced parameters: {}\n", r.forced.empty() ? std::string("none") : fmt::format("{}", fmt::join(r.forced, ", ")));
  s += fmt::format("configurations:    {} x {} shading points\n", r.configurations, r.shadingPoints);
  s += fmt::format("textures:          {}\n", r.textures == gpu::TextureSet::Neutral
                                                  ? "neutral (flat normal maps, mid-grey colours; --stress-textures: "
                                                    "the checker)"
                                                  : "checker (--stress-textures: normal maps tilt, half of them "
                                                    "below the surface)");
  if (r.cpu)
    s += fmt::format("cpu evaluations:   {} (double and float), non-finite: {}\n", r.evaluations, r.nonfinite);
  else
    s += "cpu evaluations:   not run (--gpu-only)\n";
  s += fmt::format("gpu evaluations:   {} (forward and deferred, {} precision), non-finite: {}\n", r.gpuEvaluations,
                   precisionName(r.precision), r.gpuNonfinite);
  if (r.cpu && !r.furnaceApplicable)
    s += "furnace:           not applicable (no closure: an unlit material reflects nothing)\n";
  else if (r.cpu)
    s += fmt::format("furnace max:       {:.5f}  ({}; {}){}\n", r.furnaceMax, r.furnaceWorst.configuration,
                     r.furnaceWorst.geometry, r.furnaceJudged ? "" : "  [not judged: `add` sums matter]");
  else
    s += "furnace max:       not run (--gpu-only)\n";
  if (r.cpu && r.furnaceApplicable)
    s += fmt::format("furnace lit:       {} of {} evaluations{}\n", r.furnaceLit, r.furnaceEvaluations,
                     r.furnaceLit == 0 ? "  [never exercised: no evaluation returned any light]" : "");
  for (const Case& c : r.worst)
    s += fmt::format("non-finite: {} {} = {} at {}; {}\n", c.where, c.quantity, c.value, c.configuration, c.geometry);
  return s;
}

json toJson(const Report& r) {
  auto caseJson = [](const Case& c) {
    json j;
    j["where"] = c.where;
    j["quantity"] = c.quantity;
    j["configuration"] = c.configuration;
    j["geometry"] = c.geometry;
    j["value"] = std::isfinite(c.value) ? json(c.value) : json(fmt::format("{}", c.value));
    return j;
  };
  json j;
  j["material"] = r.material;
  j["forced"] = r.forced;
  j["configurations"] = r.configurations;
  j["shading_points"] = r.shadingPoints;
  j["cpu"] = r.cpu;
  j["evaluations"] = r.evaluations;
  j["nonfinite"] = r.nonfinite;
  j["gpu_evaluations"] = r.gpuEvaluations;
  j["gpu_nonfinite"] = r.gpuNonfinite;
  j["gpu_precision"] = precisionName(r.precision);
  j["textures"] = gpu::textureSetName(r.textures);
  j["furnace_evaluations"] = r.furnaceEvaluations;
  j["furnace_lit"] = r.furnaceLit;
  j["furnace_exercised"] = furnaceExercised(r);
  j["furnace_max"] = r.furnaceMax;
  j["furnace_judged"] = r.furnaceJudged;
  j["furnace_applicable"] = r.furnaceApplicable;
  j["furnace_worst"] = caseJson(r.furnaceWorst);
  j["worst"] = json::array();
  for (const Case& c : r.worst) j["worst"].push_back(caseJson(c));
  return j;
}

std::string formatJson(const Report& r) { return toJson(r).dump(2) + "\n"; }

}  // namespace substratec::stability
