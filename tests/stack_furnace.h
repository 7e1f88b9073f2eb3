// Stacks of slabs under a white furnace (issue 16, "Stacked transparent layers
// create energy"): shared by the CPU property test (tests/unit/furnace_test.cc)
// and its lavapipe twin (tests/gpu/stability_test.cc).
//
// A stack of `depth` slabs s0 (top) .. s{depth-1} (bottom) whose every
// parameter is an input, so that one compiled material (one kernel) serves
// every random case of its shape: per slab diffuse_albedo, f0, roughness,
// sss_mfp and (through a coverage_weight) coverage; per vertical its
// thickness. Three shapes (stackMaterial).
//
// A case draws the inputs from a seeded generator, biased toward the hard
// values (albedo 1, F0 0 and 1, mirror roughness, an MFP or a thickness of 0,
// full and no coverage). Its furnace is the largest channel of the sum over
// closures of the view throughput times the importance-sampled integral of
// the closure under a white environment (reference::envIntegrated, glints
// off), as `substratec stability` measures it.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "reference/bsdf.h"
#include "reference/reference.h"
#include "util/random.h"

namespace substratec::stackfurnace {

/// The lighting's angular term for one interface above a closure
/// (substrate_coat_transmission): the layers above read as a dielectric
/// of IOR 1.5, F0 0.04, they let through 1 - F(mu) of it, (1 - F(mu)) / 0.96
/// of what T_N holds, with F on the Fresnel curve every interface follows
/// (reference::fresnelWeight: exact Fresnel within 1e-3,
/// ReferenceFresnel.TheCurveIsExactFresnelOfIor1_5).
inline double interfaceTerm(double mu) { return 1 - reference::fresnelWeight(mu); }

constexpr double kTolerance = 1.001;                 // docs/stability.md: the furnace bound
constexpr double kNoV[] = {1.0, 0.5, 0.1, 1e-3};     // the furnace's cosines (stability: 1, 0.5, 0.1) and grazing
constexpr int kSamples = 4096;                       // per strategy, as the stability furnace

enum class Shape { NestedBases, CoveredNestedBases, NestedTops };
constexpr Shape kShapes[] = {Shape::NestedBases, Shape::CoveredNestedBases, Shape::NestedTops};

inline const char* shapeName(Shape s) {
  switch (s) {
    case Shape::NestedBases: return "nested bases";
    case Shape::CoveredNestedBases: return "covered nested bases";
    default: return "nested tops";
  }
}

/// Whether the slabs of `shape` are under a coverage_weight (input cov{k}).
inline bool covered(Shape s) { return s != Shape::NestedBases; }

/// The material text of a stack of `depth` (>= 2) slabs of shape `shape`:
///   nested bases          vertical(s0, vertical(s1, ... s{depth-1})): every top a slab;
///   covered nested bases  the same with every slab k under a coverage_weight
///                         of weight cov{k} (every top an operator);
///   nested tops           vertical(vertical(c0, c1), c2)...: the slabs
///                         under coverage weights, every top but the
///                         innermost one a vertical holding the layers above.
/// Inputs, in declaration order per slab k: alb{k}, f0{k}, rgh{k}, mfp{k}
/// and (covered shapes) cov{k}; then per vertical j (1 .. depth-1): thk{j}.
inline std::string stackMaterial(int depth, Shape shape) {
  std::string inputs, nodes;
  auto input = [&](const std::string& name, double def, double lo, double hi) {
    inputs += fmt::format(R"({}"{}": {{"type": "float", "default": {}, "min": {}, "max": {}}})",
                          inputs.empty() ? "" : ", ", name, def, lo, hi);
  };
  auto slab = [&](int k) { return std::string(covered(shape) ? "c" : "s") + std::to_string(k); };
  for (int k = 0; k < depth; ++k) {
    input(fmt::format("alb{}", k), 1, 0, 1);
    input(fmt::format("f0{}", k), 0, 0, 1);
    input(fmt::format("rgh{}", k), 0.01, 0, 1);
    input(fmt::format("mfp{}", k), 1e6, 0, 1e6);
    nodes += fmt::format(
        R"("s{0}": {{"kind": "slab", "diffuse_albedo": "$alb{0}", "f0": "$f0{0}", "roughness": "$rgh{0}", )"
        R"("sss_mfp": "$mfp{0}"}}, )",
        k);
    if (covered(shape)) {
      input(fmt::format("cov{}", k), 1, 0, 1);
      nodes += fmt::format(R"("c{0}": {{"kind": "coverage_weight", "a": "s{0}", "weight": "$cov{0}"}}, )", k);
    }
  }
  for (int j = 1; j < depth; ++j) input(fmt::format("thk{}", j), 0, 0, 1);
  // Vertical j (1 .. depth-1) holds slab j-1 over the rest (nested bases) or
  // the slabs above j over slab j (nested tops); the outermost is "root".
  const bool tops = shape == Shape::NestedTops;
  auto name = [&](int j) { return j == (tops ? depth - 1 : 1) ? std::string("root") : fmt::format("v{}", j); };
  for (int j = 1; j < depth; ++j) {
    std::string top, base;
    if (tops) {
      top = j == 1 ? slab(0) : name(j - 1);
      base = slab(j);
    } else {
      top = slab(j - 1);
      base = j == depth - 1 ? slab(j) : name(j + 1);
    }
    nodes += fmt::format(R"({}"{}": {{"kind": "vertical", "top": "{}", "base": "{}", "thickness": "$thk{}"}})",
                         j == 1 ? "" : ", ", name(j), top, base, j);
  }
  return fmt::format(R"({{"format": "substrate-material/1", "name": "stack{}", "inputs": {{{}}}, "nodes": {{{}}}, )"
                     R"("output": "root"}})",
                     depth, inputs, nodes);
}

/// splitmix64: a small, fixed generator (the cases must not depend on the
/// standard library's distributions).
struct Rng {
  std::uint64_t s;
  std::uint64_t next() { return splitmix64(s); }  // util/random.h
  double uniform() { return unitInterval(next()); }
  /// One of `hard` (each with probability pHard / hard.size()) or uniform in [lo, hi].
  double pick(std::initializer_list<double> hard, double pHard, double lo, double hi) {
    const double u = uniform();
    if (u < pHard) return *(hard.begin() + std::min<std::size_t>(hard.size() - 1, static_cast<std::size_t>(u / pHard * hard.size())));
    return lo + (hi - lo) * uniform();
  }
  /// log-uniform in [lo, hi].
  double logUniform(double lo, double hi) { return lo * std::pow(hi / lo, uniform()); }
};

/// One random case's input values (in stackMaterial's declaration order) and
/// a description of it.
struct Case {
  reference::InputValues inputs;
  std::string text;
};

inline Case randomCase(int depth, Shape shape, Rng& rng) {
  Case c;
  auto push = [&](double v) { c.inputs.values.push_back({v, v, v, v}); };
  // A third of the cases are clear stacks: every layer above the bottom
  // transparent (an MFP of 1e6 or a thickness of 0) and fully present, white
  // or clear, with a weak interface; the bottom white. Independent draws
  // rarely line these up, and they are where interfaces add up.
  const bool clear = rng.uniform() < 1.0 / 3;
  if (clear) c.text += "clear stack: ";
  for (int k = 0; k < depth; ++k) {
    const bool bottom = k == depth - 1;
    double alb = rng.pick({1.0, 0.0}, 0.6, 0, 1);
    double f0 = rng.pick({0.0, 0.04, 1.0}, 0.6, 0, 1);
    const double rgh = rng.pick({0.0, 1e-4, 0.02, 1.0}, 0.5, 0, 1);
    double mfp = rng.uniform() < 0.3 ? rng.pick({0.0, 1e6}, 1, 0, 0) : rng.logUniform(1e-5, 1e6);
    double cov = rng.pick({1.0, 0.0}, 0.6, 0, 1);
    if (clear) {
      alb = bottom ? 1.0 : rng.pick({1.0, 0.0}, 1, 0, 0);
      f0 = rng.pick({0.0, 0.04}, 1, 0, 0);
      mfp = bottom ? 0.0 : 1e6;
      cov = 1;
    }
    for (double v : {alb, f0, rgh, mfp}) push(v);
    c.text += fmt::format("s{}(albedo {:.3g}, F0 {:.3g}, r {:.3g}, mfp {:.3g}", k, alb, f0, rgh, mfp);
    if (covered(shape)) {
      push(cov);
      c.text += fmt::format(", cov {:.3g}", cov);
    }
    c.text += ") ";
  }
  for (int j = 1; j < depth; ++j) {
    double thk = rng.uniform() < 0.4 ? rng.pick({0.0, 1e-9}, 1, 0, 0) : rng.logUniform(1e-6, 1);
    if (clear && rng.uniform() < 0.5) thk = 0;
    push(thk);
    c.text += fmt::format("thk{} {:.3g} ", j, thk);
  }
  return c;
}

/// The issue's own stack: white slabs (albedo 1, F0 0, roughness 1e-4),
/// fully present, every one but the bottom transparent (sss_mfp 1e6 and a
/// thickness of 0), the bottom opaque (sss_mfp 0 at the surface thickness).
inline Case whiteStack(int depth, Shape shape) {
  Case c;
  c.text = "white stack";
  for (int k = 0; k < depth; ++k) {
    for (double v : {1.0, 0.0, 1e-4, k == depth - 1 ? 0.0 : 1e6}) c.inputs.values.push_back({v, v, v, v});
    if (covered(shape)) c.inputs.values.push_back({1, 1, 1, 1});
  }
  for (int j = 1; j < depth; ++j) c.inputs.values.push_back({0, 0, 0, 0});
  return c;
}

/// The view at cosine mu in the XZ plane (normal +Z, tangent +X).
inline reference::V3<double> viewAt(double mu) { return {std::sqrt(std::max(0.0, 1 - mu * mu)), 0, mu}; }

/// The white furnace of `closures` seen from `V` (largest channel).
inline double furnace(std::vector<reference::Closure<double>> closures, const reference::V3<double>& V,
                      std::uint32_t seed) {
  std::array<double, 3> sum{0, 0, 0};
  for (auto& c : closures) {
    c.features &= ~reference::kFeatureGlint;
    c.glintValue = 1;
    const double NoV = c.N[0] * V[0] + c.N[1] * V[1] + c.N[2] * V[2];
    const auto t = reference::viewThroughput<double>(c, NoV, V);
    const auto e = reference::envIntegrated(
        c, V, [](const reference::V3<double>&) { return reference::V3<double>{1, 1, 1}; },
        reference::kDiffuseLambert, kSamples, seed);
    for (int k = 0; k < 3; ++k) sum[k] += t[k] * e[k];
  }
  return std::max({sum[0], sum[1], sum[2]});
}

}  // namespace substratec::stackfurnace
