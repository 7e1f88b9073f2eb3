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
        if (s.kind == BsdfKind::Unlit) break;  // reflects nothing (and is never in a vertical)
        // A fibre is no slab: its truth is reference/hair_truth.h (accuracy
        // takes it from there); the walk has nothing of it.
        if (s.kind == BsdfKind::Hair) break;
        double c = s.coverage == kNoValue ? 1.0 : saturate(scalar(s.coverage));
        out.push_back({c, {node.slab}});
        break;
      }
      case TreeOp::Horizontal: {
        double w = saturate(scalar(node.a));
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
      case TreeOp::CoverageWeight: append(out, expand(node.left), saturate(scalar(node.a))); break;
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

namespace {

// The closure's shading frame as evaluateMaterial builds it (tree_walk.cc:
// substrate_tangent_to_world, substrate_orthogonal_tangent), in world space.
V pinToWorld(const V& v, const V& N, const V& Tg) {
  const double mx = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2])});
  if (!(mx >= 1.1754943508222875e-38) || std::isinf(mx)) return unitOr(N, V{0, 0, 1});
  const V vs = v / mx;
  return unitOr(Tg * vs[0] + cross(N, Tg) * vs[1] + N * vs[2], unitOr(N, V{0, 0, 1}));
}
V tangentOrthogonalTo(const V& N, const V& Tg) {
  V t0, b0;
  orthonormalBasis(N, t0, b0);
  if (!std::isfinite(dot(Tg, Tg))) return t0;
  return unitOr(Tg - N * dot(N, Tg), t0);
}

/// Reads the slabs of a material (values evaluated at one point) into walk layers.
class LayerReader {
 public:
  LayerReader(const CompileResult& r, const Geometry& g, const TextureFn& tex)
      : r_(r), m_(r.material), gN_(V{g.N[0], g.N[1], g.N[2]}), gT_(V{g.T[0], g.T[1], g.T[2]}) {
    const EvalPoint p = tangentSpacePoint(g, tex);  // the DAG as evaluateMaterial evaluates it
    if (m_.values.size() > 0) vals_ = evaluateDag(m_, p, static_cast<ValueId>(m_.values.size() - 1));
  }
  const std::vector<std::array<double, 4>>& values() const { return vals_; }
  double scalar(ValueId v) const { return vals_[v][0]; }
  V vec3(ValueId v) const {
    const auto& x = vals_[v];
    if (m_.values.node(v).type == VType::Float) return splat3(x[0]);
    return {x[0], x[1], x[2]};
  }
  V normal(int slab) const { return pinToWorld(vec3(m_.slabs[slab].pin(SlabPin::Normal)), gN_, gT_); }
  V tangent(int slab, const V& N) const {
    return tangentOrthogonalTo(N, pinToWorld(vec3(m_.slabs[slab].pin(SlabPin::Tangent)), gN_, gT_));
  }
  /// The metalness provenance of a slab while its pins are the helper's outputs.
  const MetalnessSource* metalness(int slab) const {
    const Slab& s = m_.slabs[slab];
    if (!s.metalness || s.metalness->diffuse != s.pin(SlabPin::DiffuseAlbedo) || s.metalness->f0 != s.pin(SlabPin::F0))
      return nullptr;
    return &*s.metalness;
  }

  /// Every pin of the slab into its layer (the frame's angle is the caller's).
  WalkLayer layer(int slab) const {
    const Slab& s = m_.slabs[slab];
    WalkLayer L;
    L.f0 = vec3(s.pin(SlabPin::F0));
    L.f90 = vec3(s.pin(SlabPin::F90));
    L.diffuseAlbedo = vec3(s.pin(SlabPin::DiffuseAlbedo));
    L.mfp = vec3(s.pin(SlabPin::SssMfp)) * scalar(s.pin(SlabPin::SssMfpScale));
    L.roughness = scalar(s.pin(SlabPin::Roughness));
    L.phaseAnisotropy = scalar(s.pin(SlabPin::SssPhaseAnisotropy));
    const int node = r_.tree.slabNode[slab];
    const int v = node >= 0 ? r_.tree.layerVertical[node] : -1;
    L.thickness = v >= 0 ? scalar(m_.nodes[v].a) : m_.settings.surfaceThickness;
    // MFP 0 is opaque matter (docs/format.md), but a layer of no thickness is
    // no matter (the runtime's transmittance exp(-0 / 0) is 1).
    L.opaqueBase = L.mfp[0] <= 0 && L.mfp[1] <= 0 && L.mfp[2] <= 0 && L.thickness > 0;
    // A black opaque slab is a conductor only where its F0 is none of a
    // dielectric's: a black plastic or fabric (F0 0.04, 0.005) is a dielectric
    // interface over matter that absorbs what enters, as the runtime reads it
    // (substrate_closure_dielectric_part), not Gulbrandsen's conductor of n < 1.
    L.conductor = L.opaqueBase && max3(L.diffuseAlbedo) <= 0 && max3(L.f0) > kPlausibleDielectricF0;
    L.anisotropy = std::clamp(scalar(s.pin(SlabPin::Anisotropy)), -1.0, 1.0);
    L.secondRoughness = scalar(s.pin(SlabPin::SecondRoughness));
    L.secondRoughnessWeight = saturate(scalar(s.pin(SlabPin::SecondRoughnessWeight)));
    L.fuzzAmount = saturate(scalar(s.pin(SlabPin::FuzzAmount)));
    L.fuzzColor = vec3(s.pin(SlabPin::FuzzColor));
    L.fuzzRoughness = scalar(s.pin(SlabPin::FuzzRoughness));
    L.specularTint = splat3(1.0);  // SUBSTRATE_SPECULAR_PROFILE_SAMPLE's default tint (the LUT: excluded)
    return L;
  }

 private:
  const CompileResult& r_;
  const Material& m_;
  V gN_, gT_;
  std::vector<std::array<double, 4>> vals_;
};

/// The term of the stack `slabs` in the frame of its top slab: lower layers'
/// tangents as angles about the top's normal.
WalkTerm termOf(const LayerReader& reader, const SlabTerm& t) {
  WalkTerm w;
  w.weight = t.weight;
  if (t.slabs.empty()) return w;
  w.N = reader.normal(t.slabs[0]);
  w.T = reader.tangent(t.slabs[0], w.N);
  const V B = cross(w.N, w.T);
  for (int s : t.slabs) {
    WalkLayer L = reader.layer(s);
    const V Tk = reader.tangent(s, reader.normal(s));
    L.tangentAngle = std::atan2(dot(Tk, B), dot(Tk, w.T));
    w.stack.push_back(L);
  }
  return w;
}

/// Splits every term containing a slab with metalness provenance into the
/// conductor (weight m) and the dielectric (weight 1 - m) the helper mixes.
std::vector<WalkTerm> splitMetalness(const LayerReader& reader, const std::vector<int>& slabs, WalkTerm term) {
  std::vector<WalkTerm> done{std::move(term)};
  for (std::size_t k = 0; k < slabs.size(); ++k) {
    const MetalnessSource* ms = reader.metalness(slabs[k]);
    if (!ms) continue;
    const double m = saturate(reader.scalar(ms->metallic));
    V base = reader.vec3(ms->baseColor);
    for (double& c : base) c = saturate(c);
    const double spec = saturate(reader.scalar(ms->specular));
    std::vector<WalkTerm> next;
    for (const WalkTerm& t : done) {
      if (k >= t.stack.size()) {  // the stack already ended above (a conductor)
        next.push_back(t);
        continue;
      }
      WalkTerm metal = t, dielectric = t;
      metal.weight *= m;
      WalkLayer& c = metal.stack[k];
      c.conductor = c.opaqueBase = true;
      c.f0 = base;  // f90: the slab's
      c.diffuseAlbedo = splat3(0.0);
      metal.stack.resize(k + 1);  // a conductor hides everything below
      dielectric.weight *= 1 - m;
      WalkLayer& d = dielectric.stack[k];
      d.conductor = false;
      d.f0 = splat3(0.08 * spec);
      d.diffuseAlbedo = base;
      if (metal.weight > 0) next.push_back(std::move(metal));
      if (dielectric.weight > 0) next.push_back(std::move(dielectric));
    }
    done = std::move(next);
  }
  return done;
}

}  // namespace

std::vector<WalkTerm> groundTruthTerms(const CompileResult& r, const Geometry& g, const TextureFn& tex) {
  const Material& m = r.material;
  if (m.root < 0) return {};
  const LayerReader reader(r, g, tex);
  TreeExpansion tree(m, reader.values());
  std::vector<WalkTerm> out;
  for (const SlabTerm& t : tree.expand(m.root))
    for (WalkTerm& w : splitMetalness(reader, t.slabs, termOf(reader, t))) out.push_back(std::move(w));
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

/// A direction in the local frame of a term (its top slab's N, T; B = N x T).
V localIn(const WalkTerm& t, const V& w) {
  const V B = cross(t.N, t.T);
  return unitOr(V{dot(w, t.T), dot(w, B), dot(w, t.N)}, V{0, 0, 1});
}

/// Sums weight * walk(term) over the terms (term i walked with seed + i *
/// 0x9E3779B9); independent terms: the standard errors add in quadrature.
template <class F>
Estimate sumTerms(const std::vector<WalkTerm>& terms, const WalkOptions& options, F&& walk) {
  Estimate sum;
  V var{0, 0, 0};
  for (std::size_t i = 0; i < terms.size(); ++i) {
    WalkOptions o = options;
    o.seed = options.seed + static_cast<std::uint32_t>(i) * 0x9E3779B9u;
    const Estimate e = walk(terms[i], o);
    const double w = terms[i].weight;
    sum.value = sum.value + e.value * w;
    var = var + e.standardError * e.standardError * (w * w);
    sum.samples += e.samples;
  }
  for (int c = 0; c < 3; ++c) sum.standardError[c] = std::sqrt(var[c]);
  return sum;
}

V worldOf(const std::array<double, 3>& a) { return V{a[0], a[1], a[2]}; }

}  // namespace

Estimate groundTruthEstimate(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                             const WalkOptions& options) {
  const V view = unitOr(worldOf(g.V), V{0, 0, 1}), light = unitOr(L, V{0, 0, 1});
  if (!(dot(view, worldOf(g.N)) > 0) || !(dot(light, worldOf(g.N)) > 0)) return Estimate{};
  return sumTerms(groundTruthTerms(r, g, tex), options, [&](const WalkTerm& t, const WalkOptions& o) {
    const V wo = localIn(t, view), wi = localIn(t, light);
    if (!(wo[2] > 0) || !(wi[2] > 0)) return Estimate{};  // below the term's shading horizon
    return layeredEvalEstimate(t.stack, wo, wi, o);
  });
}

V3<double> groundTruth(const CompileResult& r, const Geometry& g, const V3<double>& L, const TextureFn& tex,
                       const WalkOptions& options) {
  return groundTruthEstimate(r, g, L, tex, options).value;
}

Estimate groundTruthAlbedo(const CompileResult& r, const Geometry& g, const TextureFn& tex, const WalkOptions& options) {
  const V view = unitOr(worldOf(g.V), V{0, 0, 1});
  if (!(dot(view, worldOf(g.N)) > 0)) return Estimate{};
  return sumTerms(groundTruthTerms(r, g, tex), options, [&](const WalkTerm& t, const WalkOptions& o) {
    const V wo = localIn(t, view);
    if (!(wo[2] > 0)) return Estimate{};
    return layeredAlbedoEstimate(t.stack, wo, o);
  });
}

}  // namespace substratec::reference

namespace substratec::reference {
using namespace detail;

namespace {

/// The excluded features of one slab (its own feature bits and pins).
void slabExclusions(const Slab& s, const WalkLayer& L, bool provenance, std::vector<std::string>& out) {
  auto add = [&](const char* name) {
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  };
  if (s.features & kFeatGlint) add("glint");
  if (s.specularProfileInput >= 0) add("specular profile");
  if (s.sssType != SssType::None && !L.opaqueBase) add("sss type");
  const bool implausible = std::max({L.f0[0], L.f0[1], L.f0[2]}) > kPlausibleDielectricF0;
  if (!provenance && !L.conductor && implausible) add("implausible dielectric f0");
}

}  // namespace

std::vector<std::string> groundTruthExcluded(const CompileResult& r) {
  std::vector<std::string> out;
  const Material& m = r.material;
  if (m.root < 0) return out;
  const Geometry g;
  const LayerReader reader(r, g, {});
  for (int s : slabsInTreeOrder(m)) slabExclusions(m.slabs[s], reader.layer(s), reader.metalness(s) != nullptr, out);
  TreeExpansion tree(m, reader.values());
  for (const SlabTerm& t : tree.expand(m.root))
    for (std::size_t k = 1; k < t.slabs.size(); ++k)
      if (dot(reader.normal(t.slabs[k]), reader.normal(t.slabs[0])) < 1 - 1e-9 &&
          std::find(out.begin(), out.end(), "lower-layer normals") == out.end())
        out.push_back("lower-layer normals");
  if (m.settings.thinSurface || m.settings.blendMode != BlendMode::Opaque) out.push_back("translucency");
  return out;
}

namespace {

/// One slab of the furnace: albedos at 1, conductors white (F0 and F90: a
/// conductor's F90 below 1 absorbs at grazing angles), coats clear.
void whitenSlab(const CompileResult& r, const LayerReader& reader, int index, Material& m) {
  ValueDag& dag = m.values;
  Slab& s = m.slabs[index];
  if (s.kind == BsdfKind::Hair) {  // a white fibre: no absorption (base colour 1)
    s.pin(SlabPin::BaseColor) = dag.splat(VType::Vec3, 1.0);
    return;
  }
  if (s.kind == BsdfKind::Unlit) return;  // reflects nothing
  const WalkLayer L = reader.layer(index);
  const ValueId one3 = dag.splat(VType::Vec3, 1.0);
  s.pin(SlabPin::FuzzColor) = one3;
  if (s.metalness && reader.metalness(index)) {
    // The helper recomputed on a white base colour: the analytic pins and the truth's split agree.
    MetalnessSource& ms = *s.metalness;
    ms.baseColor = one3;
    ValueId args[3] = {one3, ms.metallic, ms.specular};
    ms.diffuse = dag.makeN(Op::MetalnessToDiffuseF0, VType::Vec3, args, 3, 0);
    ms.f0 = dag.makeN(Op::MetalnessToDiffuseF0, VType::Vec3, args, 3, 1);
    s.pin(SlabPin::DiffuseAlbedo) = ms.diffuse;
    s.pin(SlabPin::F0) = ms.f0;
    s.pin(SlabPin::F90) = one3;  // its conductor part is white; its dielectric part gives the rest to the diffuse
  } else if (L.conductor) {
    s.pin(SlabPin::F0) = one3;
    s.pin(SlabPin::F90) = one3;
  } else {
    s.pin(SlabPin::DiffuseAlbedo) = one3;
  }
  const int node = r.tree.slabNode[index];
  const bool coat = node >= 0 && r.tree.layerVertical[node] >= 0;
  if (coat && !L.opaqueBase) {  // a coat's medium: clear (a white opaque coat stays a white Lambertian)
    s.pin(SlabPin::SssMfp) = dag.splat(VType::Vec3, kClearMfp);
    s.pin(SlabPin::SssMfpScale) = dag.scalar(1.0);
  }
}

}  // namespace

CompileResult furnaceMaterial(const CompileResult& r) {
  CompileResult out = r;
  if (out.material.root < 0) return out;
  const LayerReader reader(r, Geometry{}, {});
  for (int s = 0; s < static_cast<int>(out.material.slabs.size()); ++s) whitenSlab(r, reader, s, out.material);
  return out;
}

}  // namespace substratec::reference
