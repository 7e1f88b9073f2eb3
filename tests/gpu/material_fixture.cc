#include "material_fixture.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <random>

#include "emit/material_emitter.h"
#include "gpu/block_layout.h"
#include "validate/runtime_files.h"

namespace substratec::gputest {

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






template <class T>
void add(std::array<T, 3>& acc, const std::array<T, 3>& v) {
  for (int c = 0; c < 3; ++c) acc[c] += v[c];
}
template <class T>
std::array<T, 3> mul(const std::array<T, 3>& a, const std::array<T, 3>& b) {
  return {a[0] * b[0], a[1] * b[1], a[2] * b[2]};
}
template <class T>
std::array<T, 3> toT(const std::array<double, 3>& v) {
  return {static_cast<T>(v[0]), static_cast<T>(v[1]), static_cast<T>(v[2])};
}

template <class T>
void lightInto(Shaded<T>& out, const std::vector<reference::Closure<T>>& closures, const Sample& s, int diffuseModel) {
  const auto V = toT<T>(s.geometry.V), L = toT<T>(s.light), radiance = toT<T>(s.radiance);
  const auto pre = toT<T>(s.prefiltered), irr = toT<T>(s.irradiance);
  for (const auto& c : closures) {
    add(out.direct, reference::lightClosure<T>(c, V, L, radiance, diffuseModel));
    T NoV = c.N[0] * V[0] + c.N[1] * V[1] + c.N[2] * V[2];
    auto viewT = reference::viewThroughput<T>(c, NoV, V);
    add(out.environment, mul(viewT, reference::envSplitSum<T>(c, V, pre, irr, diffuseModel)));
    add(out.emissive, mul(viewT, c.emissive));
  }
}

template <class T, std::size_t N>
std::array<T, N> arrayOf(const std::array<double, N>& a) {
  std::array<T, N> out;
  for (std::size_t i = 0; i < N; ++i) out[i] = static_cast<T>(a[i]);
  return out;
}

template <class T>
reference::Closure<T> convertClosure(const reference::Closure<double>& c) {
  // Every field is copied by name: a new one left out would keep its default here.
  static_assert(sizeof(reference::Closure<double>) == 544,
                "Closure gained or lost a field: copy it below, then update the size");
  reference::Closure<T> o;
  o.diffuseAlbedo = arrayOf<T>(c.diffuseAlbedo);
  o.f0 = arrayOf<T>(c.f0);
  o.f90 = arrayOf<T>(c.f90);
  o.roughness = static_cast<T>(c.roughness);
  o.anisotropy = static_cast<T>(c.anisotropy);
  o.N = arrayOf<T>(c.N);
  o.T_ = arrayOf<T>(c.T_);
  o.sssMfp = arrayOf<T>(c.sssMfp);
  o.sssPhaseAnisotropy = static_cast<T>(c.sssPhaseAnisotropy);
  o.sssType = c.sssType;
  o.secondRoughness = static_cast<T>(c.secondRoughness);
  o.secondRoughnessWeight = static_cast<T>(c.secondRoughnessWeight);
  o.fuzzAmount = static_cast<T>(c.fuzzAmount);
  o.fuzzColor = arrayOf<T>(c.fuzzColor);
  o.fuzzRoughness = static_cast<T>(c.fuzzRoughness);
  o.glintValue = static_cast<T>(c.glintValue);
  o.glintUv = arrayOf<T>(c.glintUv);
  o.glintUvDerivatives = arrayOf<T>(c.glintUvDerivatives);
  o.specularProfile = c.specularProfile;
  o.hair = arrayOf<T>(c.hair);
  o.irisN = arrayOf<T>(c.irisN);
  o.irisPlaneN = arrayOf<T>(c.irisPlaneN);
  o.iris = arrayOf<T>(c.iris);
  o.emissive = arrayOf<T>(c.emissive);
  o.weight = static_cast<T>(c.weight);
  o.topTransmittance = arrayOf<T>(c.topTransmittance);
  o.coverageAbove = static_cast<T>(c.coverageAbove);
  o.extraInterfaces = c.extraInterfaces;
  o.coatFloor = static_cast<T>(c.coatFloor);
  o.coatInterface = static_cast<T>(c.coatInterface);
  o.coatStretch = arrayOf<T>(c.coatStretch);
  o.coatTangent = arrayOf<T>(c.coatTangent);
  o.coatShare = static_cast<T>(c.coatShare);
  o.features = c.features;
  o.isTop = c.isTop;
  o.coversLayers = c.coversLayers;
  o.metalnessMix = c.metalnessMix;
  o.conductorCurve = c.conductorCurve;
  o.lowIorCurve = c.lowIorCurve;
  return o;
}

}  // namespace

std::vector<reference::InputValues> makeInputSets(const Material& m, int count, uint32_t seed) {
  Rng rng(seed);
  std::vector<reference::InputValues> sets(count);
  for (int k = 0; k < count; ++k) {
    for (const Input& in : m.inputs) {
      std::array<double, 4> v = in.defaultValue;
      if (k > 0 && in.type != VType::Texture) {
        for (int c = 0; c < componentCount(in.type); ++c) {
          double lo = in.min ? (*in.min)[c] : -INFINITY, hi = in.max ? (*in.max)[c] : INFINITY;
          double x;
          if (std::isfinite(lo) && std::isfinite(hi)) x = rng.uniform(lo, hi);
          else if (in.isColor) x = rng.uniform(0, 1);
          else x = in.defaultValue[c] * rng.uniform(0.5, 1.5) + rng.uniform(-0.05, 0.05);
          v[c] = std::clamp(x, lo, hi);
        }
      }
      sets[k].values.push_back(v);
    }
  }
  return sets;
}

template <class T>
Shaded<T> shade(const CompileResult& r, const Sample& s, const reference::InputValues& in, int diffuseModel) {
  Shaded<T> out;
  out.material = reference::evaluateMaterial<T>(r, s.geometry, in, sampleTexture);
  lightInto(out, out.material.closures, s, diffuseModel);
  add(out.emissive, out.material.emission);  // the unlit nodes' (the forward kernel's `emission`)
  if (out.material.water) {  // a water's body, the sample's prefiltered radiance kWaterSampleDepth behind it
    const auto pre = toT<T>(s.prefiltered);
    add(out.emissive, reference::waterSeen<T>(out.material.closures[0], *out.material.water,
                                              {pre[0], pre[1], pre[2], T(kernel::kWaterSampleDepth)}, T(0),
                                              toT<T>(s.geometry.V), toT<T>(s.light), toT<T>(s.radiance)));
  }
  return out;
}
template Shaded<float> shade<float>(const CompileResult&, const Sample&, const reference::InputValues&, int);
template Shaded<double> shade<double>(const CompileResult&, const Sample&, const reference::InputValues&, int);

std::array<double, 3> glintSpread(const Shaded<double>& shaded, const Sample& s, int diffuseModel) {
  std::array<double, 3> spread{0, 0, 0};
  bool glint = false;
  for (const auto& c : shaded.material.closures)
    glint = glint || ((c.features & reference::kFeatureGlint) && c.glintValue < 1);
  if (!glint) return spread;
  const V3 n = s.geometry.N;
  const V3 side = normalize(cross(n, std::abs(n[0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0}));
  const V3 up = cross(n, side);
  auto nudge = [](const V3& d, const V3& axis, double e) {
    return normalize(V3{d[0] + e * axis[0], d[1] + e * axis[1], d[2] + e * axis[2]});
  };
  for (int k = 0; k < 8; ++k) {
    Sample p = s;
    const double e = (k % 2 ? 1e-6 : -1e-6);
    if (k < 4) p.geometry.V = nudge(s.geometry.V, k < 2 ? side : up, e);
    else p.light = nudge(s.light, k < 6 ? side : up, e);
    std::vector<reference::Closure<double>> closures = shaded.material.closures;
    for (auto& c : closures)
      for (double& u : c.glintUv) u *= 1 + (k % 2 ? 1 : -1) * 0x1p-22;
    Shaded<double> moved;
    lightInto(moved, closures, p, diffuseModel);
    for (int c = 0; c < 3; ++c) spread[c] = std::max(spread[c], std::abs(moved.direct[c] - shaded.direct[c]));
  }
  return spread;
}

template <class T>
Shaded<T> lightClosures(const std::vector<reference::Closure<double>>& closures, const Sample& s, int diffuseModel) {
  Shaded<T> out;
  for (const auto& c : closures) out.material.closures.push_back(convertClosure<T>(c));
  lightInto(out, out.material.closures, s, diffuseModel);
  return out;
}
template Shaded<float> lightClosures<float>(const std::vector<reference::Closure<double>>&, const Sample&, int);
template Shaded<double> lightClosures<double>(const std::vector<reference::Closure<double>>&, const Sample&, int);

reference::Closure<double> closureFromResults(const std::vector<float>& results, int stride, int i, int k,
                                              const CompileResult& r) {
  const float* p = &results[static_cast<std::size_t>(i) * stride + kResultHeaderFloats + kClosureFloats * k];
  auto v3 = [&](int at) { return std::array<double, 3>{p[at], p[at + 1], p[at + 2]}; };
  reference::Closure<double> c;
  c.diffuseAlbedo = v3(kClosureDiffuseAlbedo);
  c.f0 = v3(kClosureF0);
  c.f90 = v3(kClosureF90);
  c.roughness = p[kClosureRoughness];
  c.anisotropy = p[kClosureAnisotropy];
  c.N = v3(kClosureN);
  c.T_ = v3(kClosureT);
  c.sssMfp = v3(kClosureSssMfp);
  c.sssPhaseAnisotropy = p[kClosureSssPhase];
  c.sssType = static_cast<uint32_t>(p[kClosureSssType]);
  c.secondRoughness = p[kClosureSecondRoughness];
  c.secondRoughnessWeight = p[kClosureSecondRoughnessWeight];
  c.fuzzAmount = p[kClosureFuzzAmount];
  c.fuzzColor = v3(kClosureFuzzColor);
  c.fuzzRoughness = p[kClosureFuzzRoughness];
  c.glintValue = p[kClosureGlintValue];
  c.glintUv = {p[kClosureGlintUv], p[kClosureGlintUv + 1]};
  c.glintUvDerivatives = {p[kClosureGlintUvDerivatives], p[kClosureGlintUvDerivatives + 1],
                          p[kClosureGlintUvDerivatives + 2], p[kClosureGlintUvDerivatives + 3]};
  c.specularProfile = static_cast<uint32_t>(p[kClosureSpecularProfile]);
  c.emissive = v3(kClosureEmissive);
  c.weight = p[kClosureWeight];
  c.topTransmittance = v3(kClosureTopTransmittance);
  c.coverageAbove = p[kClosureCoverageAbove];
  c.features = static_cast<uint32_t>(p[kClosureFeatures]);
  c.isTop = p[kClosureIsTop] != 0.0f;
  c.extraInterfaces = static_cast<uint32_t>(p[kClosureExtraInterfaces]);
  c.coatFloor = p[kClosureCoatFloor];
  c.coatInterface = p[kClosureCoatInterface];
  c.coatStretch = {p[kClosureCoatStretch], p[kClosureCoatStretch + 1]};
  c.coatTangent = v3(kClosureCoatTangent);
  c.coatShare = p[kClosureCoatShare];
  c.coversLayers = p[kClosureCoversLayers] != 0.0f;
  if (c.features & reference::kFeatureHair)  // else the kernel has no hair field (SUBSTRATE_USE_HAIR 0)
    c.hair = {p[kClosureHair], p[kClosureHair + 1], p[kClosureHair + 2], p[kClosureHair + 3]};
  if (c.features & reference::kFeatureEye) {  // else the kernel has no iris fields (SUBSTRATE_USE_EYE 0)
    c.irisN = v3(kClosureIrisN);
    c.irisPlaneN = v3(kClosureIrisPlaneN);
    c.iris = {p[kClosureIris], p[kClosureIris + 1]};
  }
  c.metalnessMix = r.material.metalnessMix;  // the kernel's SUBSTRATE_USE_METALNESS_MIX (not in the results)
  c.conductorCurve = usesConductorCurve(r.material, r.after);  // and its SUBSTRATE_USE_CONDUCTOR_CURVE
  c.lowIorCurve = usesLowIorCurve(r.material, r.after);        // and SUBSTRATE_USE_LOW_IOR_CURVE
  return c;
}

gpu::Context* sharedContext(Diagnostics& diags) {
  static std::once_flag once;
  static std::unique_ptr<gpu::Context> context;
  static Diagnostics failure("GPU harness");
  std::call_once(once, [] {
    gpu::Context::Options o;
#ifdef SUBSTRATEC_GPU_CACHE_DIR
    o.shaderCacheDir = SUBSTRATEC_GPU_CACHE_DIR;
#endif
    context = gpu::Context::create(o, failure);
  });
  if (!context) diags.fail(failure.errorMessages());
  return context.get();
}

}  // namespace substratec::gputest
