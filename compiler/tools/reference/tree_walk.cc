// Mirrors the generated <name>_evaluate (compiler/core/emit/material_emitter.cc,
// docs/codegen.md "The material function") with the runtime's tree operators
// (runtime_shaders/substrate_tree.h) and tree-walk helpers (the end of
// runtime_shaders/substrate_values.h):
//   1. values: the value DAG in double (ir/value_eval.h), directions in tangent
//      space (normal (0,0,1), tangent (1,0,0), view = ts_view), textures through
//      the caller's TextureFn; rounded to T;
//   2. tree: each slab's coverage C and transmittance T along the normal, then
//      the operators bottom-up; the root's C/T are the material's;
//   3. closures: per closure (r.after.closures order) the walk to the root
//      (weights, layers above, roughness widening) and the pins its features use.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "emit/material_emitter.h"
#include "ir/value_eval.h"
#include "reference/bsdf.h"
#include "reference/common.h"
#include "reference/energy_lut.h"
#include "reference/reference.h"

namespace substratec::reference {
using namespace detail;

namespace {

template <class T> constexpr T kTreeEpsilon = T(SUBSTRATE_TREE_EPSILON);  // runtime_shaders/substrate_constants.h
template <class T> constexpr T kFltMin = T(1.175494351e-38);           // SUBSTRATE_VALUES_FLT_MIN
template <class T> constexpr T kValuesFltMax = T(3.402823466e+38);     // SUBSTRATE_VALUES_FLT_MAX

// --- substrate_tree.h

// substrate_op_horizontal: C = (1-w)Cb + w Cf, T = ((1-w)Cb Tb + w Cf Tf) / max(1e-6, C).
template <class T>
void opHorizontal(T cb, const V3<T>& tb, T cf, const V3<T>& tf, T w, T& c, V3<T>& t) {
  c = (T(1) - w) * cb + w * cf;
  t = ((T(1) - w) * cb * tb + w * cf * tf) / std::max(kTreeEpsilon<T>, c);
}

// substrate_op_vertical: C = Ct + Cb(1-Ct), T = Tt Ct(1-Cb) + Tb Cb(1-Ct) + Tt Tb Ct Cb.
template <class T>
void opVertical(T ct, const V3<T>& tt, T cb, const V3<T>& tb, T& c, V3<T>& t) {
  c = ct + cb * (T(1) - ct);
  t = tt * (ct * (T(1) - cb)) + tb * (cb * (T(1) - ct)) + tt * tb * (ct * cb);
}

// substrate_op_add: C = sat(Ca + Cb), T = (Ca Ta + Cb Tb) / max(1e-6, Ca + Cb).
template <class T>
void opAdd(T ca, const V3<T>& ta, T cb, const V3<T>& tb, T& c, V3<T>& t) {
  c = saturate(ca + cb);
  t = (ca * ta + cb * tb) / std::max(kTreeEpsilon<T>, ca + cb);
}

// substrate_layer_above: the layers above as one (coverage, transmittance) pair
// whose normal-incidence throughput 1 - C + C T is the product of the layers'.
template <class T>
void layerAbove(T& c, V3<T>& t, T cLayer, const V3<T>& tLayer) {
  V3<T> through = (splat3(T(1) - c) + c * t) * (splat3(T(1) - cLayer) + cLayer * tLayer);
  T cNew = T(1) - (T(1) - c) * (T(1) - cLayer);
  t = saturate((through - splat3(T(1) - cNew)) / std::max(kTreeEpsilon<T>, cNew));
  c = cNew;
}

// substrate_extra_interfaces: SUBSTRATE_EXTRA_INTERFACE^n, the angular part of
// n more interfaces above folded into a transmittance along the normal.
template <class T>
T extraInterfaces(int n) {
  return std::pow(T(SUBSTRATE_EXTRA_INTERFACE), T(n));
}

// --- substrate_values.h, tree-walk helpers

// substrate_value_pow: y == 0 -> 1; max(x, 0) == 0 -> 0; else min(pow, FLT_MAX).
template <class T>
T valuePow(T x, T y) {
  if (y == T(0)) return T(1);
  T b = std::max(x, T(0));
  if (b == T(0)) return T(0);
  return std::min(std::pow(b, y), kValuesFltMax<T>);
}

// substrate_roughness_to_variance: r^1.1 / (1 - r), r clamped to [0, 0.999].
template <class T>
T roughnessToVariance(T r) {
  T rc = clampT(r, T(0), T(0.999));
  return valuePow(rc, T(1.1)) / (T(1) - rc);
}

// substrate_variance_to_roughness: exactly the shader's two Newton steps in
// x = logit(r) from x0 = ln v (ln v >= 0) or ln v / 1.1, v clamped to
// [1e-30, variance(0.999)]; v <= 0 (or NaN) gives 0. Not an exact inverse: the
// reference computes what the shader computes.
template <class T>
T varianceToRoughness(T v) {
  if (!(v > T(0))) return T(0);
  T L = std::log(clampT(v, T(1e-30), roughnessToVariance(T(0.999))));
  T x = L >= T(0) ? L : L / T(1.1);
  for (int i = 0; i < 2; ++i) {
    T r = T(1) / (T(1) + std::exp(-x));
    T h = T(1.1) * std::log(r) - std::log(T(1) - r) - L;
    x = x - h / (T(1.1) - T(0.1) * r);
  }
  return clampT(T(1) / (T(1) + std::exp(-x)), T(0), T(0.999));
}

// substrate_values_normalize_or: fallback for a non-finite v or max|v_i| < FLT_MIN.
template <class T>
V3<T> normalizeOr(const V3<T>& v, const V3<T>& fallback) {
  if (!finite3(v)) return fallback;
  T m = max3(vabs(v));
  if (!(m >= kFltMin<T>)) return fallback;
  return normalize(v / m);
}

// substrate_tangent_to_world: normalize(T v.x + (N x T) v.y + N v.z), v scaled by
// its largest |component| first; a zero, denormal or infinite v gives N.
template <class T>
V3<T> tangentToWorld(const V3<T>& v, const V3<T>& N, const V3<T>& Tg) {
  T m = max3(vabs(v));
  if (!(m >= kFltMin<T>) || std::isinf(m)) return N;
  V3<T> vs = v / m;
  V3<T> B = cross(N, Tg);
  return normalizeOr(Tg * vs[0] + B * vs[1] + N * vs[2], N);
}

// substrate_orthogonal_tangent: T made orthogonal to the normalized N (two
// Gram-Schmidt steps); Duff's b1 with s = N.z >= 0 ? 1 : -1 (here -0 counts as
// positive, unlike substrate_orthonormal_basis) when T is zero, non-finite or
// within 1e-3 of parallel (|t|^2 <= 1e-6 |T|^2).
template <class T>
V3<T> orthogonalTangent(const V3<T>& N, const V3<T>& Tg) {
  V3<T> n = normalizeOr(N, V3<T>{T(0), T(0), T(1)});
  T s = n[2] >= T(0) ? T(1) : T(-1);
  T a = T(-1) / (s + n[2]);
  T b = n[0] * n[1] * a;
  V3<T> t0{T(1) + s * n[0] * n[0] * a, s * b, -s * n[0]};
  if (!finite3(Tg)) return t0;
  T m = max3(vabs(Tg));
  if (!(m >= kFltMin<T>)) return t0;
  V3<T> ts = Tg / m;
  V3<T> t = ts - n * dot(n, ts);
  if (!(dot(t, t) > T(1e-6) * dot(ts, ts))) return t0;
  t = t - n * dot(n, t);
  return normalize(t);
}

// Feature bits of the IR (ir/material.h) the emitter tests.
bool has(std::uint16_t f, Feature bit) { return (f & bit) != 0; }

template <class T>
class Walk {
 public:
  Walk(const CompileResult& r, const std::vector<std::array<double, 4>>& values, const Geometry& g)
      : m_(r.material), t_(r.tree), L_(r.after), vals_(values),
        conductorCurve_(usesConductorCurve(r.material, r.after)), lowIorCurve_(usesLowIorCurve(r.material, r.after)),
        gN_(cast<T>(g.N)), gT_(cast<T>(g.T)),
        gV_(cast<T>(g.V)), uvDerivatives_(cast<T>(g.uvDerivatives)) {}

  MaterialResult<T> run() {
    const std::size_t n = m_.nodes.size();
    C_.assign(n, T(1));
    Tr_.assign(n, splat3(T(1)));
    TI_.assign(n, splat3(T(1)));
    FT_.assign(n, splat3(T(1)));
    slabs();
    operators();
    MaterialResult<T> out;
    if (m_.root >= 0) {
      out.coverage = C_[m_.root];
      out.transmittance = Tr_[m_.root];
    } else {
      out.coverage = T(0);
      out.transmittance = splat3(T(1));
    }
    assignProfiles();
    for (const ClosureLayout& cl : L_.closures) out.closures.push_back(closure(cl));
    out.emission = emission();
    if (isWaterMaterial(m_)) out.water = water(m_.slabs[m_.nodes[m_.root].slab]);
    // What the layers' top lets through at grazing angles (the emitter's emitCoatFloor).
    setCoatFloor(out.closures, topRoughness(out.closures));
    setCoversLayers(out.closures);  // the emitter's emitCoversLayers
    setCoatInterface(out.closures);  // the emitter's emitCoatInterface
    return out;
  }

 private:
  // A value of the DAG rounded to T; a Float broadcasts (as the pins' own
  // broadcast, and as GLSL's vec3 * float).
  T scalar(ValueId v) const { return static_cast<T>(vals_[v][0]); }
  V3<T> vec3(ValueId v) const {
    const auto& x = vals_[v];
    if (m_.values.node(v).type == VType::Float) return splat3(static_cast<T>(x[0]));
    return {static_cast<T>(x[0]), static_cast<T>(x[1]), static_cast<T>(x[2])};
  }
  V2<T> vec2(ValueId v) const { return {static_cast<T>(vals_[v][0]), static_cast<T>(vals_[v][1])}; }

  /// mfpOf: mfp * sss_mfp_scale, without the product when the scale is the constant 1.
  V3<T> mfpOf(const Slab& s) const {
    ValueId scale = s.pin(SlabPin::SssMfpScale);
    if (m_.values.isConstEqual(scale, 1.0)) return vec3(s.pin(SlabPin::SssMfp));
    return vec3(s.pin(SlabPin::SssMfp)) * scalar(scale);
  }

  // emitTree, slabs: C = coverage (1 without one); T = substrate_transmittance(mfp,
  // d) with d the thickness of TreeInfo::layerVertical's vertical, else the
  // surface thickness; the constant (0, 0, 0) when the MFP is the constant 0 and
  // d is a positive constant (no medium: opaque).
  void slabs() {
    for (int n : t_.preorder) {
      const TreeNode& node = m_.nodes[n];
      if (node.op != TreeOp::Slab) continue;
      const Slab& s = m_.slabs[node.slab];
      C_[n] = s.coverage == kNoValue ? T(1) : scalar(s.coverage);
      if (s.kind == BsdfKind::Unlit) {  // no interface: TI = T (an unlit is never in a vertical)
        Tr_[n] = TI_[n] = vec3(s.pin(SlabPin::Transmittance));
        continue;
      }
      const int v = t_.layerVertical[n];
      const ValueId mfp = s.pin(SlabPin::SssMfp);
      const double d = m_.settings.surfaceThickness;
      const bool opaque =
          m_.values.isConstEqual(mfp, 0.0) &&
          (v < 0 ? d > 0 : m_.values.isConst(m_.nodes[v].a) && m_.values.node(m_.nodes[v].a).c[0] > 0);
      if (opaque)
        Tr_[n] = splat3(T(0));
      else
        Tr_[n] = transmittance(mfpOf(s), v >= 0 ? scalar(m_.nodes[v].a) : static_cast<T>(d));
      TI_[n] = Tr_[n] * (splat3(T(1)) - vec3(s.pin(SlabPin::F0)));
      if (s.features & kFeatFuzz) FT_[n] = splat3(fuzzThrough(s));
    }
  }

  // emitTree, operators bottom-up (by distance from leaves, then pre-order).
  void operators() {
    for (int n : t_.bottomUpOperators) {
      const TreeNode& node = m_.nodes[n];
      const int l = node.left, r = node.right;
      switch (node.op) {
        case TreeOp::Horizontal:
          opHorizontal(C_[l], Tr_[l], C_[r], Tr_[r], scalar(node.a), C_[n], Tr_[n]);
          break;
        case TreeOp::Select:  // foreground when value > threshold: 1 - step(value, threshold)
          opHorizontal(C_[l], Tr_[l], C_[r], Tr_[r], T(1) - step(node), C_[n], Tr_[n]);
          break;
        case TreeOp::Vertical: opVertical(C_[l], Tr_[l], C_[r], Tr_[r], C_[n], Tr_[n]); break;
        case TreeOp::Add: opAdd(C_[l], Tr_[l], C_[r], Tr_[r], C_[n], Tr_[n]); break;
        case TreeOp::CoverageWeight:
          C_[n] = scalar(node.a) * C_[l];
          Tr_[n] = Tr_[l];
          break;
        case TreeOp::Slab: break;
      }
      // The emitter's TI_: the same operator on what the children let through
      // with their interfaces (used when the node is an operator on top of a vertical).
      T c;
      switch (node.op) {
        case TreeOp::Horizontal: opHorizontal(C_[l], TI_[l], C_[r], TI_[r], scalar(node.a), c, TI_[n]); break;
        case TreeOp::Select: opHorizontal(C_[l], TI_[l], C_[r], TI_[r], T(1) - step(node), c, TI_[n]); break;
        case TreeOp::Vertical: opVertical(C_[l], TI_[l], C_[r], TI_[r], c, TI_[n]); break;
        case TreeOp::Add: opAdd(C_[l], TI_[l], C_[r], TI_[r], c, TI_[n]); break;
        case TreeOp::CoverageWeight: TI_[n] = TI_[l]; break;
        case TreeOp::Slab: break;
      }
      // The emitter's FT_: the same operator on what the children's fuzz lets
      // through (1 without fuzz; used when the node is in a vertical's top).
      switch (node.op) {
        case TreeOp::Horizontal: opHorizontal(C_[l], FT_[l], C_[r], FT_[r], scalar(node.a), c, FT_[n]); break;
        case TreeOp::Select: opHorizontal(C_[l], FT_[l], C_[r], FT_[r], T(1) - step(node), c, FT_[n]); break;
        case TreeOp::Vertical: opVertical(C_[l], FT_[l], C_[r], FT_[r], c, FT_[n]); break;
        case TreeOp::Add: opAdd(C_[l], FT_[l], C_[r], FT_[r], c, FT_[n]); break;
        case TreeOp::CoverageWeight: FT_[n] = FT_[l]; break;
        case TreeOp::Slab: break;
      }
    }
  }

  /// GLSL step(edge = value, x = threshold): threshold >= value ? 1 : 0.
  T step(const TreeNode& node) const { return scalar(node.b) >= scalar(node.a) ? T(1) : T(0); }

  // collectNeeded: specular profile indices in order of first use over the closures.
  void assignProfiles() {
    for (const ClosureLayout& cl : L_.closures) {
      const Slab& s = m_.slabs[cl.slab];
      if (s.specularProfileInput >= 0 && !profileIndex_.count(s.specularProfileInput)) {
        const int k = static_cast<int>(profileIndex_.size());
        profileIndex_[s.specularProfileInput] = k;
      }
    }
  }

  // emitClosures.
  Closure<T> closure(const ClosureLayout& cl) const {
    const Slab& s = m_.slabs[cl.slab];
    const int node = t_.slabNode[cl.slab];
    std::vector<int> tops;
    const T weight = weightAndTops(s, node, tops);
    T ca = T(0), va = T(0);
    V3<T> ta = splat3(T(1));
    if (!cl.isTop) layersAbove(cl, tops, ca, va, ta);

    Closure<T> c;  // substrate_closure_init
    if (s.kind == BsdfKind::Hair) return hairClosure(s);  // always the whole material: weight 1, on top
    if (s.kind == BsdfKind::Eye) return eyeClosure(s);    // so is an eye
    c.diffuseAlbedo = vec3(s.pin(SlabPin::DiffuseAlbedo));
    // A slab layered on top scatters back only what it does not let through
    // (substrate_layer_scattering; the emitter skips it for a known-opaque
    // slab, T = 0, and for the constant albedo 0: the same values).
    if (t_.layerVertical[node] >= 0) c.diffuseAlbedo = layerScattering(c.diffuseAlbedo, Tr_[node]);
    c.f0 = vec3(s.pin(SlabPin::F0));
    T rough = scalar(s.pin(SlabPin::Roughness));
    // Under a layer the roughness always goes through the variance round trip
    // (the emitter writes it even when no slab above widens it, va = 0).
    if (!cl.isTop) rough = varianceToRoughness(roughnessToVariance(rough) + va);
    c.roughness = rough;
    c.N = tangentToWorld(vec3(s.pin(SlabPin::Normal)), gN_, gT_);
    std::uint32_t bits = featurePins(s, c);
    if (cl.storesWeight) bits |= kFeatureWeight;
    if (cl.storesCoverageAbove) bits |= kFeatureCoverageAbove;
    c.weight = weight;
    if (!cl.isTop) {
      c.topTransmittance = ta;
      c.coverageAbove = ca;
      c.extraInterfaces = static_cast<std::uint32_t>(cl.extraInterfaces);
      c.isTop = false;
    }
    c.features = bits;
    c.metalnessMix = m_.metalnessMix;  // the material's SUBSTRATE_USE_METALNESS_MIX
    c.conductorCurve = conductorCurve_;  // and its SUBSTRATE_USE_CONDUCTOR_CURVE
    c.lowIorCurve = lowIorCurve_;        // and SUBSTRATE_USE_LOW_IOR_CURVE
    return c;
  }

  /// The walk up to the root: the weight is C (when the slab has a coverage)
  /// times each mix/coverage/select factor, multiplied in walk order; `tops`
  /// gets the top layer of each vertical the slab is under (root last).
  T weightAndTops(const Slab& s, int node, std::vector<int>& tops) const {
    T weight = s.coverage == kNoValue ? T(1) : C_[node];
    for (int x = node, p = t_.parent[node]; p >= 0; x = p, p = t_.parent[p]) {
      const TreeNode& op = m_.nodes[p];
      switch (op.op) {
        case TreeOp::Horizontal: weight = weight * (op.right == x ? scalar(op.a) : T(1) - scalar(op.a)); break;
        case TreeOp::CoverageWeight: weight = weight * scalar(op.a); break;
        case TreeOp::Select: weight = weight * (op.right == x ? T(1) - step(op) : step(op)); break;
        case TreeOp::Vertical:
          if (op.right != x) break;
          tops.push_back(op.left);
          // What the layer's fuzz lets through where it covers (the emitter's walkUp).
          if (fuzzyLayer(t_, op.left))
            weight = weight * (t_.unitCoverage[op.left] ? FT_[op.left][0]
                                                        : T(1) - C_[op.left] * (T(1) - FT_[op.left][0]));
          break;
        default: break;
      }
    }
    return weight;
  }

  /// The emitter's emitEmission: each emitting unlit's emissive times its
  /// path weight.
  V3<T> emission() const {
    V3<T> e = splat3(T(0));
    if (m_.root < 0) return e;
    for (int n : t_.preorder) {
      const TreeNode& node = m_.nodes[n];
      if (node.op != TreeOp::Slab) continue;
      const Slab& s = m_.slabs[node.slab];
      if (s.kind != BsdfKind::Unlit || !has(s.features, kFeatEmissive)) continue;
      std::vector<int> tops;
      e = e + vec3(s.pin(SlabPin::Emissive)) * weightAndTops(s, n, tops);
    }
    return e;
  }

  /// The emitter's FT_ of a slab with fuzz: substrate_fuzz_transmission of its
  /// fuzz seen along the view at its own normal.
  T fuzzThrough(const Slab& s) const {
    const V3<T> N = tangentToWorld(vec3(s.pin(SlabPin::Normal)), gN_, gT_);
    const T e = std::min(fuzzAlbedo(saturate(dot(N, gV_)), scalar(s.pin(SlabPin::FuzzRoughness))), T(1));
    return T(1) - saturate(scalar(s.pin(SlabPin::FuzzAmount))) * e;
  }

  /// The layers above, from the root down (substrate_layer_above); a slab on
  /// top of a vertical transmits T (1 - F0) and widens the roughness below by
  /// C * variance(its roughness). An operator on top: its TI (its slabs'
  /// T (1 - F0) through the operators), no widening. The lighting applies
  /// 1 + cl.extraInterfaces interfaces (the first ones from the root down);
  /// every further one (TreeInfo::interfaces of the tops) times
  /// extraInterfaces.
  void layersAbove(const ClosureLayout& cl, const std::vector<int>& tops, T& ca, T& va, V3<T>& ta) const {
    int lit = 1 + cl.extraInterfaces;
    for (auto it = tops.rbegin(); it != tops.rend(); ++it) {
      const TreeNode& top = m_.nodes[*it];
      V3<T> tTop = TI_[*it];
      if (top.op == TreeOp::Slab) {
        tTop = Tr_[*it];
        const Slab& ts = m_.slabs[top.slab];
        va = va + C_[*it] * roughnessToVariance(scalar(ts.pin(SlabPin::Roughness)));
        tTop = tTop * (splat3(T(1)) - vec3(ts.pin(SlabPin::F0)));
      }
      const int extra = foldedInterfaces(t_.interfaces[*it], lit);
      if (extra > 0) tTop = tTop * extraInterfaces<T>(extra);
      layerAbove(ca, ta, C_[*it], tTop);
    }
  }

  /// emitHairClosure: a hair's pins into its closure.
  Closure<T> hairClosure(const Slab& s) const {
    Closure<T> c;
    c.diffuseAlbedo = vec3(s.pin(SlabPin::BaseColor));
    c.roughness = scalar(s.pin(SlabPin::Roughness));
    c.N = tangentToWorld(vec3(s.pin(SlabPin::Normal)), gN_, gT_);
    c.T_ = orthogonalTangent(c.N, tangentToWorld(vec3(s.pin(SlabPin::Tangent)), gN_, gT_));
    c.hair = {scalar(s.pin(SlabPin::AzimuthalRoughness)), scalar(s.pin(SlabPin::Ior)),
              scalar(s.pin(SlabPin::CuticleAngle)), scalar(s.pin(SlabPin::Scatter))};
    if (has(s.features, kFeatEmissive)) c.emissive = vec3(s.pin(SlabPin::Emissive));
    c.features = kFeatureHair;
    c.metalnessMix = m_.metalnessMix;
    c.conductorCurve = conductorCurve_;
    c.lowIorCurve = lowIorCurve_;
    return c;
  }

  /// The emitter's `water`: a water's body.
  Water<T> water(const Slab& s) const {
    Water<T> w;
    w.albedo = vec3(s.pin(SlabPin::WaterAlbedo));
    w.extinction = vec3(s.pin(SlabPin::WaterExtinction));
    w.phaseG = scalar(s.pin(SlabPin::WaterPhaseG));
    w.scaleBehind = vec3(s.pin(SlabPin::ColorScaleBehindWater));
    w.opacity = saturate(scalar(s.pin(SlabPin::TopMaterialOpacity)));
    w.f0 = T(0.08) * saturate(scalar(s.pin(SlabPin::Specular)));  // its surface is closure 0: build_tree's slab
    return w;
  }

  /// emitEyeClosure: an eye's pins into its closure (F0 0.04, the init's).
  Closure<T> eyeClosure(const Slab& s) const {
    Closure<T> c;
    c.diffuseAlbedo = vec3(s.pin(SlabPin::DiffuseAlbedo));
    c.roughness = scalar(s.pin(SlabPin::Roughness));
    c.N = tangentToWorld(vec3(s.pin(SlabPin::Normal)), gN_, gT_);
    c.irisN = tangentToWorld(vec3(s.pin(SlabPin::IrisNormal)), gN_, gT_);
    c.irisPlaneN = tangentToWorld(vec3(s.pin(SlabPin::IrisPlaneNormal)), gN_, gT_);
    c.iris = {scalar(s.pin(SlabPin::IrisMask)), scalar(s.pin(SlabPin::IrisDistance))};
    if (has(s.features, kFeatEmissive)) c.emissive = vec3(s.pin(SlabPin::Emissive));
    if (has(s.features, kFeatSss)) sssPins(s, c);  // the sclera's subsurface scattering
    c.features = kFeatureEye;
    c.metalnessMix = m_.metalnessMix;
    c.conductorCurve = conductorCurve_;
    c.lowIorCurve = lowIorCurve_;
    return c;
  }

  /// A slab's or an eye's subsurface scattering into c (emitSssPins).
  void sssPins(const Slab& s, Closure<T>& c) const {
    c.sssMfp = mfpOf(s);
    c.sssPhaseAnisotropy = scalar(s.pin(SlabPin::SssPhaseAnisotropy));
    c.sssType = static_cast<std::uint32_t>(s.sssType);
  }

  /// The pins of the slab's features into c; returns their feature bits.
  std::uint32_t featurePins(const Slab& s, Closure<T>& c) const {
    std::uint32_t bits = 0;
    const std::uint16_t f = s.features;
    if (has(f, kFeatF90)) {
      bits |= kFeatureF90;
      c.f90 = vec3(s.pin(SlabPin::F90));
    }
    if (has(f, kFeatAnisotropy)) {
      bits |= kFeatureAnisotropy;
      c.anisotropy = scalar(s.pin(SlabPin::Anisotropy));
      c.T_ = orthogonalTangent(c.N, tangentToWorld(vec3(s.pin(SlabPin::Tangent)), gN_, gT_));
    }
    if (has(f, kFeatSss)) sssPins(s, c);
    if (has(f, kFeatHaze)) {
      bits |= kFeatureHaze;
      c.secondRoughness = scalar(s.pin(SlabPin::SecondRoughness));
      c.secondRoughnessWeight = scalar(s.pin(SlabPin::SecondRoughnessWeight));
    }
    if (has(f, kFeatFuzz)) {
      bits |= kFeatureFuzz;
      c.fuzzAmount = scalar(s.pin(SlabPin::FuzzAmount));
      c.fuzzColor = vec3(s.pin(SlabPin::FuzzColor));
      c.fuzzRoughness = scalar(s.pin(SlabPin::FuzzRoughness));
    }
    if (has(f, kFeatGlint)) {
      bits |= kFeatureGlint;
      c.glintValue = scalar(s.pin(SlabPin::GlintValue));
      c.glintUv = vec2(s.pin(SlabPin::GlintUv));
      c.glintUvDerivatives = uvDerivatives_;
    }
    if (has(f, kFeatSpecularProfile)) {
      bits |= kFeatureSpecularProfile;
      c.specularProfile = static_cast<std::uint32_t>(profileIndex_.at(s.specularProfileInput) + 1);
    }
    if (has(f, kFeatEmissive)) c.emissive = vec3(s.pin(SlabPin::Emissive));
    return bits;
  }

  const Material& m_;
  const TreeInfo& t_;
  const StorageLayout& L_;
  const std::vector<std::array<double, 4>>& vals_;
  bool conductorCurve_;  // the material's SUBSTRATE_USE_CONDUCTOR_CURVE
  bool lowIorCurve_;     // and SUBSTRATE_USE_LOW_IOR_CURVE
  V3<T> gN_, gT_, gV_;
  V4<T> uvDerivatives_;
  std::vector<T> C_;
  std::vector<V3<T>> Tr_;
  std::vector<V3<T>> TI_;  // what each node lets through with its interfaces (emitter's TI_)
  std::vector<V3<T>> FT_;  // what each node's fuzz lets through along the view (emitter's FT_; splat)
  std::map<int, int> profileIndex_;
};

}  // namespace

template <class T>
MaterialResult<T> evaluateMaterial(const CompileResult& r, const Geometry& g, const InputValues& in,
                                   const TextureFn& tex) {
  const Material& m = r.material;
  // The value DAG in double, at the generated code's tangent-space point.
  EvalPoint p = tangentSpacePoint(g, tex);
  p.inputs = in.values;
  std::vector<std::array<double, 4>> values;
  if (m.values.size() > 0) values = evaluateDag(m, p, static_cast<ValueId>(m.values.size() - 1));
  return Walk<T>(r, values, g).run();
}

template MaterialResult<float> evaluateMaterial<float>(const CompileResult&, const Geometry&, const InputValues&,
                                                       const TextureFn&);
template MaterialResult<double> evaluateMaterial<double>(const CompileResult&, const Geometry&, const InputValues&,
                                                         const TextureFn&);

}  // namespace substratec::reference
