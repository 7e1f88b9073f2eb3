#include "ir/tree_info.h"

#include <algorithm>

namespace substratec {

namespace {

/// Static coverage, interface counts and fuzz (children before parents): the
/// coverage of a subtree is 1 for a slab and stays 1 through operators whose
/// rule keeps it there; a subtree holds fuzz where one of its slabs does.
void analyzeCoverage(const Material& m, TreeInfo& t) {
  std::vector<int> order;
  std::vector<int> st{m.root};
  while (!st.empty()) {
    int i = st.back();
    st.pop_back();
    order.push_back(i);
    if (m.nodes[i].left >= 0) st.push_back(m.nodes[i].left);
    if (m.nodes[i].right >= 0) st.push_back(m.nodes[i].right);
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const TreeNode& node = m.nodes[*it];
    auto c = [&](int k) { return k >= 0 && t.unitCoverage[k]; };
    bool one = false;
    switch (node.op) {
      case TreeOp::Slab: {
        ValueId c = m.slabs[node.slab].coverage;
        one = c == kNoValue || m.values.isConstEqual(c, 1);
        break;
      }
      case TreeOp::CoverageWeight: one = c(node.left) && m.values.isConstEqual(node.a, 1); break;
      case TreeOp::Horizontal:
      case TreeOp::Select: one = c(node.left) && c(node.right); break;   // (1-w)*1 + w*1
      case TreeOp::Add:
      case TreeOp::Vertical: one = c(node.left) || c(node.right); break; // sat(a+1), Ct + 1*(1-Ct)
    }
    t.unitCoverage[*it] = one;
    auto f = [&](int j) { return j >= 0 && t.holdsFuzz[j]; };
    t.holdsFuzz[*it] = node.op == TreeOp::Slab ? (m.slabs[node.slab].features & kFeatFuzz) != 0 : f(node.left) || f(node.right);
    auto k = [&](int j) { return j >= 0 ? t.interfaces[j] : 0; };
    t.interfaces[*it] = node.op == TreeOp::Slab       ? (bsdfIsClosure(m.slabs[node.slab].kind) ? 1 : 0)
                        : node.op == TreeOp::Vertical ? k(node.left) + k(node.right)
                                                      : std::max(k(node.left), k(node.right));
  }
}

/// Pre-order with the facts that flow down from the root.
struct PreorderItem {
  int node;
  int parent;
  int depth;
  int layerDepth;
  bool onTopSide;   // some ancestor vertical has this subtree as its top
  bool unit;        // every weight on the path so far is exactly 1
  bool coverAbove;  // every layer above has coverage exactly 1
  int layer;        // the nearest vertical whose top layer holds this subtree (-1: none)
  int above;        // interfaces of the tops above (TreeInfo::interfacesAbove)
};

/// The pre-order walk: ids, parents, depths, layers, and each slab's facts.
void analyzePreorder(const Material& m, TreeInfo& t) {
  std::vector<PreorderItem> stack{{m.root, -1, 0, 0, false, true, true, -1, 0}};
  while (!stack.empty()) {
    PreorderItem it = stack.back();
    stack.pop_back();
    const TreeNode& node = m.nodes[it.node];
    t.reportId[it.node] = static_cast<int>(t.preorder.size());
    t.preorder.push_back(it.node);
    t.parent[it.node] = it.parent;
    t.depth[it.node] = it.depth;
    t.layerDepth[it.node] = it.layerDepth;
    t.layerVertical[it.node] = it.layer;
    if (node.op == TreeOp::Slab) {
      t.isTop[it.node] = it.layerDepth == 0;
      t.isBottom[it.node] = !it.onTopSide;
      t.unitWeight[it.node] = it.unit && t.unitCoverage[it.node];  // a blended slab may carry a coverage
      t.unitCoverageAbove[it.node] = it.coverAbove;
      t.interfacesAbove[it.node] = it.above;
      t.slabNode[node.slab] = it.node;
      if (!bsdfIsClosure(m.slabs[node.slab].kind)) continue;  // unlit, fog cloud: no closure
      t.bsdfId[node.slab] = static_cast<int>(t.slabOrder.size());
      t.slabOrder.push_back(node.slab);
      continue;
    }
    PreorderItem l{node.left, it.node, it.depth + 1, it.layerDepth, it.onTopSide, it.unit, it.coverAbove, it.layer, it.above};
    PreorderItem r{node.right, it.node, it.depth + 1, it.layerDepth, it.onTopSide, it.unit, it.coverAbove, it.layer, it.above};
    switch (node.op) {
      case TreeOp::Vertical:
        l.onTopSide = true;           // the top has a layer below it
        l.layer = it.node;            // the top is this vertical's layer (the base stays in the enclosing one)
        r.layerDepth += 1;            // the base is under one more layer
        r.coverAbove = it.coverAbove && t.unitCoverage[node.left];
        r.unit = it.unit && !fuzzyLayer(t, node.left);  // the base is weighted by what the fuzz lets through
        r.above += node.left >= 0 ? t.interfaces[node.left] : 0;
        break;
      case TreeOp::Horizontal:
      case TreeOp::CoverageWeight:
      case TreeOp::Select:
        l.unit = r.unit = false;      // weighted by a run-time value
        break;
      default: break;                 // Add keeps both sides at full weight
    }
    if (node.right >= 0) stack.push_back(r);
    if (node.left >= 0) stack.push_back(l);
  }
}

/// Distances from the leaves and the bottom-up order of the operators.
void analyzeDistances(const Material& m, TreeInfo& t) {
  // Distance from leaves: reverse pre-order visits children before parents.
  for (auto it = t.preorder.rbegin(); it != t.preorder.rend(); ++it) {
    const TreeNode& node = m.nodes[*it];
    int d = 0;
    if (node.left >= 0) d = std::max(d, t.distanceFromLeaves[node.left] + 1);
    if (node.right >= 0) d = std::max(d, t.distanceFromLeaves[node.right] + 1);
    t.distanceFromLeaves[*it] = d;
  }
  t.maxDistanceFromLeaves = t.distanceFromLeaves[m.root];
  for (int n : t.preorder)
    if (m.nodes[n].op != TreeOp::Slab) t.bottomUpOperators.push_back(n);
  std::stable_sort(t.bottomUpOperators.begin(), t.bottomUpOperators.end(),
                   [&](int a, int b) { return t.distanceFromLeaves[a] < t.distanceFromLeaves[b]; });
}

}  // namespace

TreeInfo analyzeTree(const Material& m) {
  TreeInfo t;
  const std::size_t n = m.nodes.size();
  t.reportId.assign(n, -1);
  t.parent.assign(n, -1);
  t.distanceFromLeaves.assign(n, 0);
  t.depth.assign(n, 0);
  t.layerDepth.assign(n, 0);
  t.isTop.assign(n, false);
  t.isBottom.assign(n, false);
  t.unitWeight.assign(n, false);
  t.unitCoverageAbove.assign(n, false);
  t.unitCoverage.assign(n, false);
  t.holdsFuzz.assign(n, false);
  t.interfaces.assign(n, 0);
  t.interfacesAbove.assign(n, 0);
  t.bsdfId.assign(m.slabs.size(), -1);
  t.slabNode.assign(m.slabs.size(), -1);
  t.layerVertical.assign(n, -1);
  if (m.root < 0) return t;

  analyzeCoverage(m, t);
  analyzePreorder(m, t);
  analyzeDistances(m, t);
  return t;
}

}  // namespace substratec
