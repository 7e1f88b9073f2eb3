#include "passes/cull.h"

#include <fmt/format.h>

namespace substratec {

namespace {

class Culler {
 public:
  explicit Culler(Material& m) : m_(m) {}

  /// Returns the node that replaces `i`, or -1 if the subtree is empty.
  int visit(int i) {
    TreeNode n = m_.nodes[i];  // copy: m_.nodes may grow
    ValueDag& dag = m_.values;
    auto drop = [&](int child, const std::string& why) {
      if (child >= 0) note(m_.nodes[child].id, why);
    };
    switch (n.op) {
      case TreeOp::Slab: return i;
      case TreeOp::Horizontal:
        if (dag.isConstEqual(n.a, 0)) {
          drop(n.right, fmt::format("foreground of horizontal '{}': mix is constant 0", n.id));
          note(n.id, "horizontal with constant mix 0 replaced by its background");
          return visit(n.left);
        }
        if (dag.isConstEqual(n.a, 1)) {
          drop(n.left, fmt::format("background of horizontal '{}': mix is constant 1", n.id));
          note(n.id, "horizontal with constant mix 1 replaced by its foreground");
          return visit(n.right);
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
          return visit(n.left);
        }
        break;
      case TreeOp::Select:
        if (dag.isConst(n.a) && dag.isConst(n.b)) {
          bool pickA = dag.node(n.a).c[0] <= dag.node(n.b).c[0];
          drop(pickA ? n.right : n.left,
               fmt::format("side {} of select '{}': the constant value always picks {}", pickA ? "b" : "a", n.id,
                           pickA ? "a" : "b"));
          note(n.id, fmt::format("select with a constant value replaced by side {}", pickA ? "a" : "b"));
          return visit(pickA ? n.left : n.right);
        }
        break;
      default: break;
    }
    int l = n.left >= 0 ? visit(n.left) : -1;
    int r = n.right >= 0 ? visit(n.right) : -1;
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

 private:
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
  Material& m_;
};

}  // namespace

bool cullStaticMatter(Material& m, Diagnostics& diags) {
  if (m.root < 0) return false;
  int root = Culler(m).visit(m.root);
  if (root < 0) {
    diags.error("/output", "no matter is left after static culling (every slab is under a constant zero weight)");
    return false;
  }
  m.root = root;
  return true;
}

}  // namespace substratec
