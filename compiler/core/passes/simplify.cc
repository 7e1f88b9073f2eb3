#include "passes/simplify.h"

#include <fmt/format.h>

#include "ir/tree_info.h"
#include "passes/blend.h"
#include "ir/dump.h"

namespace substratec {

const std::vector<std::uint16_t>& featureDisableOrder() {
  // bytes saved / visual loss (docs/simplification.md): glint 136 bits, a
  // fine-scale sparkle; F90 20, a grazing hue shift; haze 16, folded into the
  // roughness; fuzz 32, folded into the diffuse albedo; SSS 28, the slab
  // becomes opaque diffuse; anisotropy 8 + a 14-bit tangent, highlights turn
  // round; specular profile 8, a whole artistic LUT lost.
  static const std::vector<std::uint16_t> order = {kFeatGlint, kFeatF90,        kFeatHaze,
                                                   kFeatFuzz,  kFeatSss,        kFeatAnisotropy,
                                                   kFeatSpecularProfile};
  return order;
}

void disableFeature(Material& m, std::uint16_t feature) {
  for (Slab& s : m.slabs) {
    if (!(s.features & feature)) continue;
    switch (feature) {
      case kFeatGlint: s.pin(SlabPin::GlintValue) = m.values.scalar(1); break;
      case kFeatF90: s.pin(SlabPin::F90) = m.values.splat(VType::Vec3, 1); break;
      case kFeatHaze:
      case kFeatFuzz: {
        // Folded rather than dropped: the slab keeps its energy.
        Slab folded = foldToSingleInterface(m, s);
        if (feature == kFeatHaze) {
          s.pin(SlabPin::Roughness) = folded.pin(SlabPin::Roughness);
          s.pin(SlabPin::SecondRoughnessWeight) = folded.pin(SlabPin::SecondRoughnessWeight);
        } else {
          s.pin(SlabPin::DiffuseAlbedo) = folded.pin(SlabPin::DiffuseAlbedo);
          s.pin(SlabPin::FuzzAmount) = folded.pin(SlabPin::FuzzAmount);
        }
        break;
      }
      case kFeatSss:
        s.sssType = SssType::None;
        s.sssTypeExplicit = true;
        break;
      case kFeatAnisotropy: s.pin(SlabPin::Anisotropy) = m.values.scalar(0); break;
      case kFeatSpecularProfile: s.specularProfileInput = -1; break;
      case kFeatEmissive: s.pin(SlabPin::Emissive) = m.values.splat(VType::Vec3, 0); break;
      default: break;
    }
  }
}

namespace {

/// A slab leaf that parameter blending can merge: not an unlit, which holds
/// no closure (collapsing it saves nothing) and has no pins to blend.
bool blendableLeaf(const Material& m, int node) {
  return node < 0 || (m.nodes[node].op == TreeOp::Slab && !isUnlitLeaf(m, m.nodes[node]));
}

/// The next operator to collapse: deepest first; at equal depth horizontal,
/// add, select and coverage weight before vertical; then the smallest tree id.
/// Only operators over two slabs (or one, for a weight): one over an unlit
/// never collapses, nor therefore do those above it.
int pickOperator(const Material& m, const TreeInfo& t) {
  int best = -1;
  auto rank = [&](int n) {
    bool vertical = m.nodes[n].op == TreeOp::Vertical;
    return std::tuple<int, int, int>(-t.depth[n], vertical ? 1 : 0, t.reportId[n]);
  };
  for (int n : t.preorder) {
    const TreeNode& node = m.nodes[n];
    if (node.op == TreeOp::Slab || !blendableLeaf(m, node.left) || !blendableLeaf(m, node.right)) continue;
    if (best < 0 || rank(n) < rank(best)) best = n;
  }
  return best;
}

/// Why the material cannot shrink further when it holds an unlit leaf ("" otherwise).
std::string unlitNote(const Material& m) {
  for (int n : analyzeTree(m).preorder)
    if (isUnlitLeaf(m, m.nodes[n]))
      return " (an operator over an unlit node is never collapsed: the unlit holds no closure to blend)";
  return "";
}

/// Collapses operator `n` (whose children are slabs: it is the deepest).
void collapse(Material& m, int n, BlendRule rule) {
  TreeNode node = m.nodes[n];
  const Slab& l = m.slabs[m.nodes[node.left].slab];
  const Slab* r = node.right >= 0 ? &m.slabs[m.nodes[node.right].slab] : nullptr;
  Slab merged;
  switch (node.op) {
    case TreeOp::Horizontal: merged = blendHorizontal(m, l, *r, node.a, rule); break;
    case TreeOp::Vertical: merged = blendVertical(m, l, *r, node.a, rule); break;
    case TreeOp::Add: merged = blendAdd(m, l, *r, rule); break;
    case TreeOp::CoverageWeight: merged = blendCoverageWeight(m, l, node.a); break;
    case TreeOp::Select: merged = blendSelect(m, l, *r, node.a, node.b, rule); break;
    case TreeOp::Slab: return;
  }
  merged.id = node.id;
  merged.pointer = node.pointer;
  merged.collapsedFrom = std::string(treeOpName(node.op));
  // The metalness provenance holds only while the pins are still the helper's
  // outputs (a coverage weight keeps them; a blend does not).
  if (merged.metalness && (merged.metalness->diffuse != merged.pin(SlabPin::DiffuseAlbedo) ||
                           merged.metalness->f0 != merged.pin(SlabPin::F0)))
    merged.metalness.reset();
  TreeNode& dst = m.nodes[n];
  dst.op = TreeOp::Slab;
  dst.left = dst.right = -1;
  dst.a = dst.b = kNoValue;
  dst.slab = static_cast<int>(m.slabs.size());
  m.slabs.push_back(std::move(merged));
}

bool present(const Material& m, std::uint16_t f) {
  for (int s : analyzeTree(m).slabOrder)
    if (m.slabs[s].features & f) return true;
  return false;
}

/// Disables every feature of `mask` the material uses, in the documented
/// order (emissive last), recording each as `action`.
void disableAll(Material& m, std::uint16_t mask, const char* action, Reprice reprice, StorageLayout& layout,
                std::vector<SimplifyStep>& steps) {
  std::vector<std::uint16_t> order = featureDisableOrder();
  order.push_back(kFeatEmissive);
  for (std::uint16_t f : order) {
    if (!(mask & f) || !present(m, f)) continue;
    SimplifyStep step{action, featureList(f), "feature", 0, layout.bytes(), 0,
                      static_cast<int>(layout.closures.size()), 0};
    disableFeature(m, f);
    layout = reprice(m);
    step.bytesAfter = layout.bytes();
    step.closuresAfter = static_cast<int>(layout.closures.size());
    steps.push_back(step);
  }
}

bool over(const StorageLayout& L, const SimplifyBudget& b) {
  if (b.full) return L.closures.size() > 1 || L.bytes() > kFullSimplificationBytes;
  return L.bytes() > b.bytesPerPixel || static_cast<int>(L.closures.size()) > b.maxClosures;
}

}  // namespace

bool simplifyToBudget(Material& m, const SimplifyBudget& budget, Reprice reprice, StorageLayout& layout,
                      std::vector<SimplifyStep>& steps, Diagnostics& diags) {
  // A volume stores no pixel: the budget is the GBuffer's, and its froxel
  // payload is fixed (storage/layout.h, LayoutClass::Volume).
  if (isVolumeMaterial(m)) return true;
  // What the platform's lighting does not evaluate goes first.
  disableAll(m, budget.disallowed, "disallow", reprice, layout, steps);
  while (over(layout, budget)) {
    TreeInfo t = analyzeTree(m);
    int n = pickOperator(m, t);
    if (n < 0) break;
    SimplifyStep step{"collapse", m.nodes[n].id, std::string(treeOpName(m.nodes[n].op)), t.depth[n],
                      layout.bytes(), 0, static_cast<int>(layout.closures.size()), 0};
    collapse(m, n, budget.rule);
    layout = reprice(m);
    step.bytesAfter = layout.bytes();
    step.closuresAfter = static_cast<int>(layout.closures.size());
    steps.push_back(step);
  }
  for (std::uint16_t f : featureDisableOrder()) {
    if (!over(layout, budget)) break;
    disableAll(m, f, "disable", reprice, layout, steps);
  }
  // A collapse blends a disallowed feature's neutral value with another
  // slab's: the blend may use it again.
  disableAll(m, budget.disallowed, "disallow", reprice, layout, steps);
  if (over(layout, budget)) {
    if (budget.full)
      diags.error("", fmt::format("full simplification cannot fit a {}-byte payload: the smallest reachable size is {} "
                                  "bytes per pixel{}",
                                  kFullSimplificationBytes, layout.bytes(), unlitNote(m)));
    else
      diags.error("", fmt::format("material does not fit the budget of {} bytes per pixel and {} closures{}: the "
                                  "smallest reachable size is {} bytes per pixel with {} closure(s){}",
                                  budget.bytesPerPixel, budget.maxClosures,
                                  budget.platform.empty() ? "" : " (platform " + quoteForDiagnostic(budget.platform) + ")",
                                  layout.bytes(), layout.closures.size(), unlitNote(m)));
    return false;
  }
  return true;
}

}  // namespace substratec
