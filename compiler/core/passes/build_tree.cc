#include "passes/build_tree.h"

#include <unordered_set>

#include <fmt/format.h>

#include "ir/tree_info.h"

namespace substratec {

namespace {

class TreeBuilder {
 public:
  TreeBuilder(const ResolvedDoc& doc, const ValueTable& table, Material& m, Diagnostics& diags)
      : doc_(doc), table_(table), m_(m), diags_(diags) {
    // Every user-visible id is reserved so generated instance names never clash.
    for (const auto& s : doc.substrate)
      if (s.pointer == "/nodes/" + s.id) used_.insert(s.id);  // author ids (inline names are generated)
    for (const auto& v : doc.values) used_.insert(v.id);
    for (const auto& in : doc.inputs) used_.insert(in.name);
  }

  /// Instances Substrate node `s` and its subtree (pre-order, left before
  /// right). Recursive to the tree's depth (at most 512 for the 1024-node
  /// limit): the frame holds only ints; the node and its slab are built by
  /// addNode, out of line (docs/stability.md, "Deep and wide trees").
  int instance(int s) {
    const int index = addNode(s);
    const SNode& src = doc_.substrate[s];
    if (src.op == TreeOp::Slab) return index;
    auto value = [&](const PinRef& p) { return pinToValue(p, VType::Float, table_, m_); };
    ValueId a = src.op == TreeOp::Add ? kNoValue : value(src.a);
    ValueId b = src.op == TreeOp::Select ? value(src.b) : kNoValue;
    int left = src.left >= 0 ? instance(src.left) : -1;
    int right = src.right >= 0 ? instance(src.right) : -1;
    TreeNode& n = m_.nodes[index];
    n.left = left;
    n.right = right;
    n.a = a;
    n.b = b;
    return index;
  }

 private:
  /// The tree node of `s` (and, for a slab, its Slab with every pin); its index.
  [[gnu::noinline]] int addNode(int s) {
    const SNode& src = doc_.substrate[s];
    TreeNode node;
    node.op = src.op;
    node.pointer = src.pointer;
    node.id = uniqueId(src.id, src.pointer == "/nodes/" + src.id);
    int index = static_cast<int>(m_.nodes.size());
    m_.nodes.push_back(node);
    if (src.op == TreeOp::Slab) {
      Slab slab;
      slab.kind = src.kind;
      slab.id = m_.nodes[index].id;
      slab.pointer = src.pointer;
      for (int p = 0; p < kSlabPinCount; ++p) {
        const SlabPinInfo& info = slabPinInfo(static_cast<SlabPin>(p));
        slab.pins[p] = pinToValue(src.slabPins[p], info.type, table_, m_);
        if (src.slabPins[p].tag == PinRef::Node) checkConstantRange(slab.pins[p], info, src.pointer);
      }
      slab.metalness = metalnessSource(src, slab);
      if (slab.metalness) m_.metalnessMix = true;
      slab.specularProfileInput = src.specularProfileInput;
      slab.sssType = src.sssType;
      slab.sssTypeExplicit = src.sssTypeExplicit;
      m_.nodes[index].slab = static_cast<int>(m_.slabs.size());
      m_.slabs.push_back(std::move(slab));
    }
    return index;
  }

  /// The metalness_to_diffuse_f0 node whose outputs 0 and 1 are the slab's
  /// diffuse_albedo and f0 pins (the same node), read from the resolved
  /// document (the DAG may have folded the helper into constants): its
  /// arguments as DAG values. The DAG is hash-consed and append-only, so
  /// pinToValue of the helper's pins returns the ids its outputs were built
  /// from (base_color broadcast to grey, as build_values does).
  std::optional<MetalnessSource> metalnessSource(const SNode& src, const Slab& slab) {
    const PinRef& d = src.slabPins[static_cast<int>(SlabPin::DiffuseAlbedo)];
    const PinRef& f = src.slabPins[static_cast<int>(SlabPin::F0)];
    if (d.tag != PinRef::Node || f.tag != PinRef::Node || d.index != f.index || d.output != 0 || f.output != 1)
      return std::nullopt;
    const VNode& v = doc_.values[d.index];
    if (v.op != Op::MetalnessToDiffuseF0 || v.pins.size() < 3) return std::nullopt;
    MetalnessSource ms;
    ms.baseColor = m_.values.broadcast(pinToValue(v.pins[0], VType::Invalid, table_, m_), VType::Vec3);
    ms.metallic = pinToValue(v.pins[1], VType::Invalid, table_, m_);
    ms.specular = pinToValue(v.pins[2], VType::Invalid, table_, m_);
    ms.diffuse = slab.pin(SlabPin::DiffuseAlbedo);
    ms.f0 = slab.pin(SlabPin::F0);
    return ms;
  }

  /// The first instance of an author node keeps its id; every other name
  /// (later instances, inline nodes) takes the first free `base`, `base_2`, ...
  /// that is neither an author id nor already generated.
  std::string uniqueId(const std::string& base, bool authorNode) {
    auto& count = seen_[base];
    ++count;
    if (!generated_.count(base) && (authorNode || !used_.count(base))) {
      generated_.insert(base);
      return base;
    }
    for (int k = std::max(count, 2);; ++k) {
      std::string candidate = fmt::format("{}_{}", base, k);
      if (!used_.count(candidate) && !generated_.count(candidate)) {
        generated_.insert(candidate);
        count = k;
        return candidate;
      }
    }
  }

  /// An expression that folds to a constant must obey the pin's range, like a
  /// literal (literals were checked by resolve).
  void checkConstantRange(ValueId v, const SlabPinInfo& info, const std::string& ptr) {
    const ValueNode& n = m_.values.node(v);
    if (n.op != Op::Const || info.type == VType::Vec2) return;
    std::string where = ptr + "/" + std::string(info.name);
    if (!reported_.insert(where).second) return;  // a node instanced twice reports once
    if (info.type == VType::Vec3 && !info.color) {
      if (n.c[0] * n.c[0] + n.c[1] * n.c[1] + n.c[2] * n.c[2] < 1e-12)
        diags_.error(where, "expected a non-zero direction, but the expression is the constant zero vector");
      return;
    }
    for (int i = 0; i < componentCount(n.type); ++i) {
      if (n.c[i] < info.lo || n.c[i] > info.hi) {
        std::string range = info.hi >= 1e300 ? fmt::format(">= {:g}", info.lo) : fmt::format("in [{:g},{:g}]", info.lo, info.hi);
        diags_.error(where, fmt::format("expected {} {}, but the expression is the constant {}",
                                        info.color ? "a color with components" : "a float", range, m_.values.render(v)));
        return;
      }
    }
  }

  const ResolvedDoc& doc_;
  const ValueTable& table_;
  Material& m_;
  Diagnostics& diags_;
  std::unordered_set<std::string> reported_;
  std::unordered_set<std::string> used_, generated_;
  std::unordered_map<std::string, int> seen_;
};

/// An unlit leaf may sit anywhere but in a vertical (its top layer or its
/// base): it has no interface nor medium to layer matter under, and light
/// emitted under a layer would have to cross that layer's interface, which
/// the unlit path does not model. One error per unlit node (at its pointer),
/// naming the vertical.
void checkUnlitPlacement(const Material& m, Diagnostics& diags) {
  const TreeInfo t = analyzeTree(m);
  std::unordered_set<std::string> reported;
  for (int n : t.preorder) {
    const TreeNode& node = m.nodes[n];
    if (!isUnlitLeaf(m, node)) continue;
    for (int x = n, p = t.parent[n]; p >= 0; x = p, p = t.parent[p]) {
      if (m.nodes[p].op != TreeOp::Vertical) continue;
      if (reported.insert(node.pointer).second)
        diags.error(node.pointer,
                    fmt::format("unlit '{}' is in the {} of vertical '{}': an unlit BSDF cannot be layered (it has no "
                                "interface or medium to layer under, and its emission cannot cross a layer); mix it "
                                "with a horizontal, add or coverage_weight instead, or use a slab's emissive",
                                node.id, m.nodes[p].left == x ? "top layer" : "base", m.nodes[p].id));
      break;
    }
  }
}

/// A hair BSDF, an eye BSDF, a single-layer water and a volumetric fog cloud
/// are the whole material: a located error at such a leaf with a parent,
/// naming the operator. A hair's closure is lit by the fibre's own model (a
/// far field around the fibre, no interface or diffuse), which no operator
/// can blend, layer or weigh against a slab's lobes; an eye's iris is lit
/// through its cornea by a caustic of its own, which no operator's blend of
/// closures keeps; a water's body is what lies behind its surface, seen
/// through the water; a fog cloud is a medium sampled through a volume, not
/// a surface (UE's Substrate keeps all four alone at the root; the fog cloud
/// there sets the material's domain to volume).
void checkWholeMaterialPlacement(const Material& m, Diagnostics& diags) {
  const TreeInfo t = analyzeTree(m);
  std::unordered_set<std::string> reported;
  for (int n : t.preorder) {
    const TreeNode& node = m.nodes[n];
    if (node.op != TreeOp::Slab || !bsdfIsWholeMaterial(m.slabs[node.slab].kind) || t.parent[n] < 0 ||
        !reported.insert(node.pointer).second)
      continue;
    const TreeNode& p = m.nodes[t.parent[n]];
    const BsdfKind kind = m.slabs[node.slab].kind;
    const char* what = kind == BsdfKind::Hair  ? "a hair BSDF"
                       : kind == BsdfKind::Eye ? "an eye BSDF"
                       : kind == BsdfKind::Water ? "a single-layer water"
                                                 : "a volumetric fog cloud";
    const char* why =
        kind == BsdfKind::Hair  ? "its fibre lobes are a closure of their own kind that no operator can mix, layer or "
                                  "weigh with other matter"
        : kind == BsdfKind::Eye ? "its iris is lit through its cornea by a caustic of its own, a closure of its own "
                                  "kind that no operator can mix, layer or weigh with other matter"
        : kind == BsdfKind::Water ? "its body is what lies behind the surface seen through the water, which no "
                                    "operator can mix, layer or weigh with other matter"
                                : "it is a medium a ray-marcher samples through a volume, not a surface that an "
                                  "operator can mix, layer or weigh with other matter";
    diags.error(node.pointer, fmt::format("{} '{}' is an operand of {} '{}': {} must be the whole material (the "
                                          "output), since {}",
                                          bsdfKindName(kind), node.id, treeOpName(p.op), p.id, what, why));
  }
}

/// A single-layer water's surface is the slab that its top material's share
/// t = sat(top_material_opacity) (base colour b = sat(base_color), metallic
/// m = t sat(metallic)) and the water's interface (F0 w = 0.08 sat(specular))
/// mix to: its diffuse_albedo pin becomes b (t - m), its f0 pin w + m (b - w)
/// (a horizontal mix by parameter blending, exact for the lobes' linear F0).
/// The emitter, the reference and the truth then read a slab's pins; the
/// water's body keeps its own (the emitter's `water`).
void lowerWaterSurfaces(Material& m) {
  ValueDag& v = m.values;
  for (Slab& s : m.slabs) {
    if (s.kind != BsdfKind::Water) continue;
    const ValueId w = v.make(Op::Multiply, VType::Float, {v.splat(VType::Float, 0.08),
                                                          v.make(Op::Saturate, VType::Float, {s.pin(SlabPin::Specular)})});
    const ValueId t = v.make(Op::Saturate, VType::Float, {s.pin(SlabPin::TopMaterialOpacity)});
    const ValueId metal = v.make(Op::Multiply, VType::Float, {t, v.make(Op::Saturate, VType::Float, {s.pin(SlabPin::Metallic)})});
    const ValueId b = v.make(Op::Saturate, VType::Vec3, {s.pin(SlabPin::BaseColor)});
    s.pin(SlabPin::DiffuseAlbedo) = v.make(Op::Multiply, VType::Vec3, {b, v.make(Op::Subtract, VType::Float, {t, metal})});
    s.pin(SlabPin::F0) = v.make(Op::Add, VType::Vec3,
                                {w, v.make(Op::Multiply, VType::Vec3, {v.make(Op::Subtract, VType::Vec3, {b, w}), metal})});
  }
}

}  // namespace

bool buildSubstrateTree(const ResolvedDoc& doc, const ValueTable& table, Material& m, Diagnostics& diags,
                        const TreeLimits& limits) {
  if (doc.output < 0) return false;
  // Instance count per Substrate node (iterative post-order; saturating), so a
  // small DAG that would instance into a huge tree is rejected before any work.
  const std::size_t cap = limits.maxTreeNodes + 1;
  std::vector<std::size_t> size(doc.substrate.size(), 0);
  std::vector<std::pair<int, bool>> stack{{doc.output, false}};
  while (!stack.empty()) {
    auto [s, expanded] = stack.back();
    stack.pop_back();
    if (size[s]) continue;
    const SNode& n = doc.substrate[s];
    if (!expanded) {
      stack.push_back({s, true});
      if (n.left >= 0 && !size[n.left]) stack.push_back({n.left, false});
      if (n.right >= 0 && !size[n.right]) stack.push_back({n.right, false});
      continue;
    }
    std::size_t total = 1;
    if (n.left >= 0) total += size[n.left];
    if (n.right >= 0) total += size[n.right];
    size[s] = std::min(total, cap);
  }
  if (size[doc.output] > limits.maxTreeNodes) {
    diags.error(doc.substrate[doc.output].pointer,
                fmt::format("the Substrate tree would have more than {} nodes after instancing (a node "
                            "referenced twice is instanced twice); this is the tree-size limit",
                            limits.maxTreeNodes));
    return false;
  }
  TreeBuilder builder(doc, table, m, diags);
  m.root = builder.instance(doc.output);
  checkUnlitPlacement(m, diags);
  checkWholeMaterialPlacement(m, diags);
  lowerWaterSurfaces(m);
  return !diags.hasErrors();
}

}  // namespace substratec
