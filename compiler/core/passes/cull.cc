#include "passes/cull.h"

#include <fmt/format.h>

#include <set>
#include <string>

namespace substratec {

namespace {

class Culler {
 public:
  Culler(Material& m, Diagnostics& diags) : m_(m), diags_(diags) {}

  /// Returns the node that replaces `i`, or -1 if the subtree is empty.
  /// `layer`: the thickness of the layer that holds `i` (TreeInfo::layerVertical:
  /// the nearest vertical whose top layer holds it; kNoValue: the surface thickness).
  /// Kept lean: it recurses as deep as the tree (DeepTrees runs 512 levels on a
  /// 1 MiB stack, under ASan too), so the notes and their strings live in the
  /// helpers below, which are not inlined into this frame.
  int visit(int i, ValueId layer) {
    const TreeNode& node = m_.nodes[i];
    if (node.op == TreeOp::Slab) return i;
    const TreeOp op = node.op;
    const int left = node.left, right = node.right;
    const ValueId a = node.a;
    if (const int chosen = constantChoice(i); chosen != kNoChoice) return chosen < 0 ? -1 : visit(chosen, layer);
    // A vertical's top is a layer of the vertical's thickness; its base stays in `layer`.
    const int l = left >= 0 ? visit(left, op == TreeOp::Vertical ? a : layer) : -1;
    const int r = right >= 0 ? visit(right, layer) : -1;
    return rebuild(i, l, r, layer);
  }

 private:
  static constexpr int kNoChoice = -2;

  /// An operator whose constant weight or value decides it: the child that
  /// replaces it (-1: removed with its subtree), with the notes; else kNoChoice.
  [[gnu::noinline]] int constantChoice(int i) {
    const TreeNode n = m_.nodes[i];
    const ValueDag& dag = m_.values;
    switch (n.op) {
      case TreeOp::Horizontal:
        if (dag.isConstEqual(n.a, 0)) {
          drop(n.right, fmt::format("foreground of horizontal '{}': mix is constant 0", n.id));
          note(n.id, "horizontal with constant mix 0 replaced by its background");
          return n.left;
        }
        if (dag.isConstEqual(n.a, 1)) {
          drop(n.left, fmt::format("background of horizontal '{}': mix is constant 1", n.id));
          note(n.id, "horizontal with constant mix 1 replaced by its foreground");
          return n.right;
        }
        break;
      case TreeOp::CoverageWeight:
        if (dag.isConstEqual(n.a, 0)) {
          drop(n.left, fmt::format("under coverage_weight '{}': weight is constant 0", n.id));
          note(n.id, "coverage_weight with constant weight 0 removed with its subtree");
          return -1;
        }
        if (dag.isConstEqual(n.a, 1)) {
          note(n.id, "coverage_weight with constant weight 1 removed (no effect)");
          return n.left;
        }
        break;
      case TreeOp::Select:
        if (dag.isConst(n.a) && dag.isConst(n.b)) {
          bool pickA = dag.node(n.a).c[0] <= dag.node(n.b).c[0];
          drop(pickA ? n.right : n.left,
               fmt::format("side {} of select '{}': the constant value always picks {}", pickA ? "b" : "a", n.id,
                           pickA ? "a" : "b"));
          note(n.id, fmt::format("select with a constant value replaced by side {}", pickA ? "a" : "b"));
          return pickA ? n.left : n.right;
        }
        break;
      default: break;
    }
    return kNoChoice;
  }

  /// Operator `i` after its children became `l` and `r` (-1: empty): what
  /// replaces it — its opaque top for a vertical that hides its base, the
  /// other side for an operator left with one empty side, or `i` relinked.
  [[gnu::noinline]] int rebuild(int i, int l, int r, ValueId layer) {
    const TreeNode n = m_.nodes[i];  // copy: rewriteAsWeight changes the node
    ValueDag& dag = m_.values;
    if (n.op == TreeOp::Vertical && l >= 0 && r >= 0) {
      const bool hidden = opaque(l, n.a, false);
      if (hidden || opaque(l, n.a, true)) warnHidden(n, l, hidden);
      // Replaced by its top only where the top stays opaque in the layer that
      // then holds it (its slabs take that layer's thickness): otherwise the
      // rewrite would change what the top lets through.
      if (hidden && opaque(l, layer, false)) {
        drop(n.right, fmt::format("base of vertical '{}': hidden by its opaque top '{}'", n.id, m_.nodes[l].id));
        note(n.id, fmt::format("vertical '{}' replaced by its top: the top is opaque", n.id));
        return l;
      }
    }
    if (n.op == TreeOp::CoverageWeight) {
      if (l < 0) {
        note(n.id, fmt::format("coverage_weight '{}' removed: its subtree is empty", n.id));
        return -1;
      }
      m_.nodes[i].left = l;
      return i;
    }
    if (l >= 0 && r >= 0) {
      m_.nodes[i].left = l;
      m_.nodes[i].right = r;
      return i;
    }
    if (l < 0 && r < 0) {
      note(n.id, fmt::format("{} '{}' removed: both sides are empty", treeOpName(n.op), n.id));
      return -1;
    }
    int kept = l >= 0 ? l : r;
    switch (n.op) {
      case TreeOp::Vertical:
      case TreeOp::Add:
        note(n.id, fmt::format("{} '{}' removed: one side is empty", treeOpName(n.op), n.id));
        return kept;
      case TreeOp::Horizontal: {
        // C = (1-w)Cb + w Cf with one side empty is a coverage weight of the other.
        ValueId w = l >= 0 ? dag.make(Op::OneMinus, VType::Float, {n.a}) : n.a;
        return rewriteAsWeight(i, kept, w, "horizontal '{}' with an empty side is a coverage_weight");
      }
      case TreeOp::Select: {
        // a when value <= threshold: weight of a = step(value, threshold).
        ValueId pickA = dag.make(Op::Step, VType::Float, {n.a, n.b});
        ValueId w = l >= 0 ? pickA : dag.make(Op::OneMinus, VType::Float, {pickA});
        return rewriteAsWeight(i, kept, w, "select '{}' with an empty side is a coverage_weight");
      }
      default: return kept;
    }
  }

  void drop(int child, const std::string& why) {
    if (child >= 0) note(m_.nodes[child].id, why);
  }
  int rewriteAsWeight(int i, int kept, ValueId w, const char* why) {
    TreeNode& node = m_.nodes[i];
    note(node.id, fmt::format(fmt::runtime(why), node.id));
    node.op = TreeOp::CoverageWeight;
    node.left = kept;
    node.right = -1;
    node.a = w;
    node.b = kNoValue;
    return i;
  }
  void note(const std::string& what, std::string why) { m_.culled.push_back({what, std::move(why)}); }

  /// A statically positive thickness: `layer`'s constant, or the surface
  /// thickness; with `anyThickness`, every thickness that is not the constant 0.
  bool thick(ValueId layer, bool anyThickness) const {
    if (layer == kNoValue) return m_.settings.surfaceThickness > 0;
    if (anyThickness) return !m_.values.isConstEqual(layer, 0);
    return m_.values.isConst(layer) && m_.values.node(layer).c[0] > 0;
  }
  /// The subtree at `i`, in a layer of thickness `layer`, has coverage 1 and
  /// transmittance 0 whatever the inputs: its light never reaches below it.
  /// A slab: coverage constant 1 (or none), sss_mfp the constant 0 (no
  /// medium: T = exp(-d / 0) = 0 for d > 0) and a positive constant thickness;
  /// horizontal, select, add: both sides opaque (C = 1, T = 0 whatever the
  /// mix); coverage_weight: weight constant 1 over an opaque subtree;
  /// vertical: its top (in the vertical's thickness) or its base opaque
  /// (substrate_op_vertical: C = 1, T = 0). With `anyThickness`: the same for
  /// every run-time thickness > 0 (for the warning only).
  bool opaque(int i, ValueId layer, bool anyThickness) const {
    const TreeNode& n = m_.nodes[i];
    switch (n.op) {
      case TreeOp::Slab: {
        const Slab& s = m_.slabs[n.slab];
        return (s.coverage == kNoValue || m_.values.isConstEqual(s.coverage, 1)) &&
               m_.values.isConstEqual(s.pin(SlabPin::SssMfp), 0) && thick(layer, anyThickness);
      }
      case TreeOp::Horizontal:
      case TreeOp::Select:
      case TreeOp::Add: return opaque(n.left, layer, anyThickness) && opaque(n.right, layer, anyThickness);
      case TreeOp::CoverageWeight: return m_.values.isConstEqual(n.a, 1) && opaque(n.left, layer, anyThickness);
      case TreeOp::Vertical: return opaque(n.left, n.a, anyThickness) || opaque(n.right, layer, anyThickness);
    }
    return false;
  }

  /// The warning on the top `l` of vertical `v` that hides its base (always,
  /// or for every thickness > 0); once per vertical over the pass's rounds.
  void warnHidden(const TreeNode& v, int l, bool always) {
    if (!warned_.insert(v.id).second) return;
    const TreeNode& top = m_.nodes[l];
    diags_.warning(top.pointer,
                   fmt::format("'{}' hides the base '{}' of vertical '{}'{}: it has no medium (sss_mfp is 0 or absent), "
                               "so no light crosses it; to make it a transparent coat give it an sss_mfp (e.g. 1e6 for "
                               "a clear coat), or one from a transmittance with the `transmittance_to_mfp` helper",
                               top.id, m_.nodes[v.right].id, v.id, always ? "" : " whenever its thickness is > 0"));
  }

  Material& m_;
  Diagnostics& diags_;
  std::set<std::string> warned_;  // verticals already warned about
};

}  // namespace

namespace {

/// A volume whose extinction and emissive are both the constant 0 neither
/// hides, scatters nor emits anything: a warning at the fog cloud (it still
/// compiles, like a slab under a weight that happens to be 0 at run time).
void warnInvisibleVolume(const Material& m, Diagnostics& diags) {
  if (!isVolumeMaterial(m)) return;
  const TreeNode& n = m.nodes[m.root];
  const Slab& fog = m.slabs[n.slab];
  if (m.values.isConstEqual(fog.pin(SlabPin::Extinction), 0) && m.values.isConstEqual(fog.pin(SlabPin::Emissive), 0))
    diags.warning(n.pointer, fmt::format("volumetric fog cloud '{}' has extinction 0 and emissive 0: it shows nothing",
                                         n.id));
}

/// An eye whose iris mask is the constant 0 is lit as the slab its pins
/// describe (its cornea's F0 0.04 is a slab's default; runtime_shaders/
/// substrate_eye.h): it becomes that slab, and stores no iris.
void cullIrislessEye(Material& m) {
  const TreeNode& n = m.nodes[m.root];
  if (!isLeafOfKind(m, n, BsdfKind::Eye)) return;
  Slab& eye = m.slabs[n.slab];
  if (!m.values.isConstEqual(eye.pin(SlabPin::IrisMask), 0)) return;
  eye.kind = BsdfKind::Slab;
  m.culled.push_back({n.id + " (iris)", fmt::format("iris_mask is the constant 0: eye '{}' is the slab its cornea and "
                                                    "sclera describe (F0 0.04), with no iris to store",
                                                    n.id)});
}

}  // namespace

bool cullStaticMatter(Material& m, Diagnostics& diags) {
  if (m.root < 0) return false;
  // Rounds until nothing more is removed: replacing a vertical by its opaque
  // top moves that top's slabs into the enclosing layer, which can make a top
  // nested in it provably opaque in turn. Each round that changes the tree
  // removes a node, so there are at most as many rounds as nodes.
  Culler culler(m, diags);
  int root = m.root;
  for (std::size_t round = 0; round <= m.nodes.size(); ++round) {
    const std::size_t before = m.culled.size();
    root = culler.visit(root, kNoValue);
    if (root < 0 || m.culled.size() == before) break;
  }
  if (root < 0) {
    diags.error("/output", "no matter is left after static culling (every slab is under a constant zero weight)");
    return false;
  }
  m.root = root;
  cullIrislessEye(m);  // an eye is always the root (build_tree)
  warnInvisibleVolume(m, diags);
  return true;
}

}  // namespace substratec
