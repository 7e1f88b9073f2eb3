// The ground truth of a compiled material: its Substrate tree expanded into a
// weighted sum of layer stacks (groundTruthTerms), each walked by the
// position-free random walk of random_walk.h.
#include "reference/ground_truth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "ir/value_eval.h"
#include "reference/common.h"

namespace substratec::reference {
using namespace detail;

namespace {

using V = V3<double>;
double clampUnit(double x) { return std::clamp(x, 0.0, 1.0); }
V normalizedOr(const V& v, const V& fallback) {
  double l2 = dot(v, v);
  if (!(l2 > 0) || !std::isfinite(l2)) return fallback;
  return v / std::sqrt(l2);
}

}  // namespace

namespace {

struct SlabTerm {
  double weight;
  std::vector<int> slabs;  // top to bottom
};

class TreeExpansion {
 public:
  TreeExpansion(const Material& m, const std::vector<std::array<double, 4>>& vals) : m_(m), vals_(vals) {}

  double scalar(ValueId v) const { return vals_[v][0]; }
  V vec3(ValueId v) const {
    const auto& x = vals_[v];
    if (m_.values.node(v).type == VType::Float) return splat3(x[0]);
    return {x[0], x[1], x[2]};
  }

  std::vector<SlabTerm> expand(int n) const {
    const TreeNode& node = m_.nodes[n];
    std::vector<SlabTerm> out;
    switch (node.op) {
      case TreeOp::Slab: {
        const Slab& s = m_.slabs[node.slab];
        double c = s.coverage == kNoValue ? 1.0 : clampUnit(scalar(s.coverage));
        out.push_back({c, {node.slab}});
        break;
      }
      case TreeOp::Horizontal: {
        double w = clampUnit(scalar(node.a));
        append(out, expand(node.left), 1 - w);
        append(out, expand(node.right), w);
        break;
      }
      case TreeOp::Select: {
        double step = scalar(node.b) >= scalar(node.a) ? 1.0 : 0.0;  // foreground when value > threshold
        append(out, expand(node.left), step);
        append(out, expand(node.right), 1 - step);
        break;
      }
      case TreeOp::Add:
        append(out, expand(node.left), 1);
        append(out, expand(node.right), 1);
        break;
      case TreeOp::CoverageWeight: append(out, expand(node.left), clampUnit(scalar(node.a))); break;
      case TreeOp::Vertical: {
        std::vector<SlabTerm> top = expand(node.left), base = expand(node.right);
        double ct = 0, cb = 0;
        for (const SlabTerm& t : top) ct += t.weight;
        for (const SlabTerm& b : base) cb += b.weight;
        for (const SlabTerm& t : top)
          for (const SlabTerm& b : base) {
            SlabTerm x{t.weight * b.weight, t.slabs};
            x.slabs.insert(x.slabs.end(), b.slabs.begin(), b.slabs.end());
            push(out, std::move(x));
          }
        append(out, base, std::max(0.0, 1 - ct));
        append(out, top, std::max(0.0, 1 - cb));
        break;
      }
    }
    return out;
  }

 private:
  static void push(std::vector<SlabTerm>& out, SlabTerm t) {
    if (t.weight > 0) out.push_back(std::move(t));
  }
  static void append(std::vector<SlabTerm>& out, const std::vector<SlabTerm>& in, double w) {
    for (const SlabTerm& t : in) push(out, SlabTerm{t.weight * w, t.slabs});
  }

  const Material& m_;
  const std::vector<std::array<double, 4>>& vals_;
};

}  // namespace

std::vector<WalkTerm> groundTruthTerms(const CompileResult& r, const Geometry& g, const TextureFn& tex) {
  const Material& m = r.material;
  if (m.root < 0) return {};
  // The value DAG as evaluateMaterial evaluates it (tangent space; inputs at their defaults).
  const EvalPoint p = tangentSpacePoint(g, tex);
  std::vector<std::array<double, 4>> vals;
  if (m.values.size() > 0) vals = evaluateDag(m, p, static_cast<ValueId>(m.values.size() - 1));
  TreeExpansion tree(m, vals);

  auto layerOf = [&](int slab) {
    const Slab& s = m.slabs[slab];
    WalkLayer L;
    L.f0 = tree.vec3(s.pin(SlabPin::F0));
    L.f90 = tree.vec3(s.pin(SlabPin::F90));
    L.diffuseAlbedo = tree.vec3(s.pin(SlabPin::DiffuseAlbedo));
    L.mfp = tree.vec3(s.pin(SlabPin::SssMfp)) * tree.scalar(s.pin(SlabPin::SssMfpScale));
    L.roughness = tree.scalar(s.pin(SlabPin::Roughness));
    L.phaseAnisotropy = tree.scalar(s.pin(SlabPin::SssPhaseAnisotropy));
    const int node = r.tree.slabNode[slab];
    const int v = node >= 0 ? r.tree.layerVertical[node] : -1;
    L.thickness = v >= 0 ? tree.scalar(m.nodes[v].a) : m.settings.surfaceThickness;
    // MFP 0 is opaque matter (docs/format.md), but a layer of no thickness is
    // no matter (the runtime's transmittance exp(-0 / 0) is 1).
    L.opaqueBase = L.mfp[0] <= 0 && L.mfp[1] <= 0 && L.mfp[2] <= 0 && L.thickness > 0;
    return L;
  };

  std::vector<WalkTerm> out;
  for (const SlabTerm& t : tree.expand(m.root)) {
    WalkTerm w;
    w.weight = t.weight;
    for (int s : t.slabs) w.stack.push_back(layerOf(s));
    out.push_back(std::move(w));
  }
  return out;
}

Closure<double> layeringOnly(Closure<double> c) {
  c.features &= ~(kFeatureAnisotropy | kFeatureHaze | kFeatureFuzz | kFeatureGlint | kFeatureSpecularProfile);
  c.anisotropy = 0;
  c.secondRoughnessWeight = 0;
  c.fuzzAmount = 0;
  c.glintValue = 1;
  c.specularProfile = 0;
  return c;
}

namespace {

/// The view and light in the local frame of the geometric normal and tangent
/// (N, the tangent made orthogonal to it, B = N x T).
struct LocalFrame {
  V N, T, B;
  explicit LocalFrame(const Geometry& g) {
    N = normalizedOr(g.N, V{0, 0, 1});
    V t0, b0;
    orthonormalBasis(N, t0, b0);
    T = normalizedOr(g.T - N * dot(N, g.T), t0);
    B = cross(N, T);
  }
  V local(const V& w) const { return normalizedOr(V{dot(w, T), dot(w, B), dot(w, N)}, V{0, 0, 1}); }
};

/// Sums weight * estimate over the terms (term i walked with seed + i * 0x9E3779B9);
/// independent terms: the standard errors add in quadrature.
template <class F>
Estimate sumTerms(const std::vector<WalkTerm>& terms, const WalkOptions& options, F&& walk) {
  Estimate sum;
  V var{0, 0, 0};
  for (std::size_t i = 0; i < terms.size(); ++i) {
    WalkOptions o = options;
    o.seed = options.seed + static_cast<std::uint32_t>(i) * 0x9E3779B9u;
    const Estimate e = walk(terms[i].stack, o);
    const double w = terms[i].weight;
    sum.value = sum.value + e.value * w;
    var = var + e.standardError * e.standardError * (w * w);
    sum.samples += e.samples;
  }
  for (int c = 0; c < 3; ++c) sum.standardError[c] = std::sqrt(var[c]);
  return sum;
}

}  // namespace

Estimate groundTruthEstimate(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                             const WalkOptions& options) {
  const LocalFrame f(g);
  const V wo = f.local(g.V), wi = f.local(L);
  if (!(wo[2] > 0) || !(wi[2] > 0)) return Estimate{};
  return sumTerms(groundTruthTerms(r, g, tex), options, [&](const std::vector<WalkLayer>& stack, const WalkOptions& o) {
    return layeredEvalEstimate(stack, wo, wi, o);
  });
}

V3<double> groundTruth(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                       const WalkOptions& options) {
  return groundTruthEstimate(r, g, L, tex, options).value;
}

Estimate groundTruthAlbedo(const CompileResult& r, const Geometry& g, const TextureFn& tex, const WalkOptions& options) {
  const LocalFrame f(g);
  const V wo = f.local(g.V);
  if (!(wo[2] > 0)) return Estimate{};
  return sumTerms(groundTruthTerms(r, g, tex), options, [&](const std::vector<WalkLayer>& stack, const WalkOptions& o) {
    return layeredAlbedoEstimate(stack, wo, o);
  });
}

}  // namespace substratec::reference
