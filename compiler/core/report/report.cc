#include "report/report.h"

#include <fmt/format.h>

#include "ir/dump.h"

namespace substratec {

namespace {

std::string bitFlag(std::uint16_t mask, std::uint16_t bit) { return (mask & bit) ? "1" : "0"; }

std::string featureLine(const Slab& s) {
  const std::uint16_t f = s.features;
  return fmt::format("F90={} Aniso={} SSS={} Haze={} Fuzz={} Glint={} SpecularProfile={} Emissive={} Medium={} "
                     "SSSType={} Basis={}",
                     bitFlag(f, kFeatF90), bitFlag(f, kFeatAnisotropy), bitFlag(f, kFeatSss), bitFlag(f, kFeatHaze),
                     bitFlag(f, kFeatFuzz), bitFlag(f, kFeatGlint), bitFlag(f, kFeatSpecularProfile),
                     bitFlag(f, kFeatEmissive), bitFlag(f, kFeatMedium), sssTypeName(s.sssType), s.basis);
}

std::uint16_t featureUnion(const Material& m, const TreeInfo& t) {
  std::uint16_t all = 0;
  for (int s : t.slabOrder) all |= m.slabs[s].features;
  if (isVolumeMaterial(m)) all |= m.slabs[m.nodes[m.root].slab].features;  // the fog cloud is no closure
  return all;
}

/// What a layout's bytes are made of: the GBuffer's words and top-layer word,
/// or a volume's froxel words.
std::string bytesNote(const StorageLayout& L) {
  return L.layoutClass == LayoutClass::Volume
             ? fmt::format("{} UINT32 per froxel: a volume stores no pixel", L.words())
             : fmt::format("{} UINT32 + 4 top-layer bytes", L.words());
}

/// The features line of a closure: a slab's (featureLine); a hair, an eye
/// and a water have no optional slab feature (but an eye's subsurface
/// scattering), so theirs says what they are.
std::string bsdfFeatureLine(const Slab& s) {
  const int emissive = (s.features & kFeatEmissive) ? 1 : 0;
  switch (s.kind) {
    case BsdfKind::Hair:
      return fmt::format("Hair=1 Emissive={} Basis={} (a fibre: R, TT, TRT lobes and the rest; its basis stores the "
                         "fibre's tangent)",
                         emissive, s.basis);
    case BsdfKind::Eye:
      return fmt::format("Eye=1 SSS={} Emissive={} Basis={} (a cornea's GGX interface, F0 0.04, over the sclera's "
                         "diffuse{} and an iris of its own normal and caustic)",
                         (s.features & kFeatSss) ? 1 : 0, emissive, s.basis,
                         (s.features & kFeatSss) ? ", scattering under the surface," : "");
    case BsdfKind::Water:
      return fmt::format("Water=1 Emissive={} Basis={} (a water surface, a slab of the water's F0 and its top "
                         "material; its body, what lies behind it through the water, added by the forward and base "
                         "passes)",
                         emissive, s.basis);
    default: return featureLine(s);
  }
}

}  // namespace

std::string formatReportText(const CompileResult& r) {
  const Material& m = r.material;
  const TreeInfo& t = r.tree;
  std::string o;
  o += fmt::format("----- SUBSTRATE - {} -----\n", m.name);
  o += fmt::format("- Byte per pixel budget: {}\n", r.budgetBytes);
  o += fmt::format("- Closure budget: {}\n", r.maxClosures);
  o += fmt::format("- Requested bytes before simplification: {} ({})\n", r.before.bytes(), bytesNote(r.before));
  o += fmt::format("- Requested bytes after simplification: {} ({})\n", r.after.bytes(), bytesNote(r.after));
  o += fmt::format("- Closures before simplification: {}\n", r.before.closures.size());
  o += fmt::format("- Closures after simplification: {}\n", r.after.closures.size());
  o += fmt::format("- Material complexity: {}\n", layoutClassName(r.after.layoutClass));
  o += fmt::format("- Blend mode: {}\n", blendModeName(m.settings.blendMode));
  std::string feats = featureList(featureUnion(m, t));
  o += fmt::format("- Features: {}\n", feats.empty() ? "none" : feats);
  o += fmt::format("- Shared local bases: {}{}\n", m.bases.size(),
                   r.after.basis0NormalElided && !m.bases.empty() ? " (basis 0 normal is the top-layer normal)" : "");
  for (std::size_t b = 0; b < m.bases.size(); ++b) {
    std::string slabs;
    for (int s : m.bases[b].slabs) slabs += (slabs.empty() ? "" : ", ") + m.slabs[s].id;
    o += fmt::format("  - basis {}: normal={}{} used by {}\n", b, renderValue(m, m.bases[b].normal),
                     m.bases[b].tangent != kNoValue ? " tangent=" + renderValue(m, m.bases[b].tangent) : "", slabs);
  }
  o += fmt::format("----- SUBSTRATE TREE - {} -----\n", m.name);
  o += fmt::format("Maximum distance to leaves: {}\n", t.maxDistanceFromLeaves);
  for (int d = t.maxDistanceFromLeaves; d >= 0; --d) {
    o += fmt::format("----- DistanceFromLeaves = {} -----\n", d);
    for (int n : t.preorder) {
      if (t.distanceFromLeaves[n] != d) continue;
      const TreeNode& node = m.nodes[n];
      bool slab = node.op == TreeOp::Slab;
      o += fmt::format("Id={} Op={} ParentId={} Left={} Right={} BSDFId={} LayerDepth={} IsTop={} IsBottom={} Node={}\n",
                       t.reportId[n], nodeOpName(m, node), t.parent[n] >= 0 ? t.reportId[t.parent[n]] : -1,
                       node.left >= 0 ? t.reportId[node.left] : -1, node.right >= 0 ? t.reportId[node.right] : -1,
                       slab ? t.bsdfId[node.slab] : -1, t.layerDepth[n], slab && t.isTop[n] ? 1 : 0,
                       slab && t.isBottom[n] ? 1 : 0, node.id);
    }
  }
  if (!r.blocks.empty()) {  // the tree above is their expansion (blocks/expand.h)
    o += fmt::format("----- Building blocks - {} -----\n", m.name);
    for (const auto& b : r.blocks) {
      std::string nodes;
      for (const auto& n : b.nodes) nodes += (nodes.empty() ? "" : ", ") + n;
      o += fmt::format("{} ({} at {}) expanded into: {}\n", b.id, b.kind, b.pointer, nodes.empty() ? "(its base)" : nodes);
    }
  }
  o += fmt::format("----- BSDF features - {} -----\n", m.name);
  for (std::size_t i = 0; i < t.slabOrder.size(); ++i) {
    const Slab& s = m.slabs[t.slabOrder[i]];
    o += fmt::format("BSDF {} ({}): {}\n", i, s.id, bsdfFeatureLine(s));
  }
  for (int n : t.preorder)  // unlit leaves: no closure, no bytes
    if (isUnlitLeaf(m, m.nodes[n]))
      o += fmt::format("Unlit ({}): Emissive={} (no closure: it emits and lets through, and stores nothing)\n",
                       m.nodes[n].id, (m.slabs[m.nodes[n].slab].features & kFeatEmissive) ? 1 : 0);
  if (isVolumeMaterial(m))  // the root: no closure, sampled per point
    o += fmt::format("Volumetric fog cloud ({}): Emissive={} (no closure: a medium sampled per point by "
                     "{}_sample into the froxel payload below)\n",
                     m.nodes[m.root].id, (m.slabs[m.nodes[m.root].slab].features & kFeatEmissive) ? 1 : 0, m.name);
  o += fmt::format("----- Culled - {} -----\n", m.name);
  if (m.culled.empty()) o += "(nothing)\n";
  for (const auto& c : m.culled) o += fmt::format("{}: {}\n", c.what, c.why);
  o += fmt::format("----- Simplification - {} -----\n", m.name);
  if (isVolumeMaterial(m)) o += "(none: a volume stores no pixel, so no budget applies)\n";
  else if (r.steps.empty()) o += "(no step: the material fits its budget)\n";
  for (std::size_t i = 0; i < r.steps.size(); ++i) {
    const SimplifyStep& s = r.steps[i];
    o += fmt::format("Step {}: {} {} '{}' (depth {}): {} B / {} closures -> {} B / {} closures\n", i + 1, s.action,
                     s.kind, s.node, s.depth, s.bytesBefore, s.closuresBefore, s.bytesAfter, s.closuresAfter);
  }
  o += fmt::format("----- Storage layout - {} -----\n", m.name);
  for (const auto& f : r.after.fields) o += fmt::format("{:<32} {:>3} bits  {}\n", f.name, f.bits, f.encoding);
  o += fmt::format("{:<32} {:>3} bits  (packed into {} UINT32)\n", "total", r.after.totalBits, r.after.words());
  if (r.after.layoutClass == LayoutClass::Volume)
    o += fmt::format("{:<32} {:>3} bits  (a volume has no surface)\n", "top_layer", 0);
  else
    o += fmt::format("{:<32} {:>3} bits  octahedral normal 2 x unorm12 | roughness unorm8\n", "top_layer", 32);
  return o;
}

nlohmann::ordered_json reportJson(const CompileResult& r) {
  using J = nlohmann::ordered_json;
  const Material& m = r.material;
  const TreeInfo& t = r.tree;
  auto features = [](std::uint16_t mask) {
    J a = J::array();
    for (int b = 0; b < kFeatureCount; ++b)
      if (mask & (1u << b)) a.push_back(std::string(featureName(b)));
    return a;
  };
  auto price = [](const StorageLayout& L) {
    return J{{"bytes", L.bytes()}, {"words", L.words()}, {"bits", L.totalBits},
             {"closures", L.closures.size()}, {"layout", std::string(layoutClassName(L.layoutClass))}};
  };
  J j;
  j["name"] = m.name;
  j["budget"] = {{"bytes_per_pixel", r.budgetBytes}, {"max_closures", r.maxClosures}};
  j["before"] = price(r.before);
  j["after"] = price(r.after);
  j["layout"] = std::string(layoutClassName(r.after.layoutClass));
  j["blend_mode"] = std::string(blendModeName(m.settings.blendMode));
  j["features"] = features(featureUnion(m, t));
  J tree = J::array();
  for (int n : t.preorder) {
    const TreeNode& node = m.nodes[n];
    bool slab = node.op == TreeOp::Slab;
    tree.push_back({{"id", t.reportId[n]},
                    {"node", node.id},
                    {"op", std::string(nodeOpName(m, node))},
                    {"parent", t.parent[n] >= 0 ? t.reportId[t.parent[n]] : -1},
                    {"left", node.left >= 0 ? t.reportId[node.left] : -1},
                    {"right", node.right >= 0 ? t.reportId[node.right] : -1},
                    {"bsdf", slab ? t.bsdfId[node.slab] : -1},
                    {"distance_from_leaves", t.distanceFromLeaves[n]},
                    {"layer_depth", t.layerDepth[n]},
                    {"is_top", slab && t.isTop[n]},
                    {"is_bottom", slab && t.isBottom[n]}});
  }
  j["tree"] = tree;
  if (!r.blocks.empty()) {
    J blocks = J::array();
    for (const auto& b : r.blocks)
      blocks.push_back({{"id", b.id}, {"kind", b.kind}, {"pointer", b.pointer}, {"nodes", b.nodes}});
    j["building_blocks"] = blocks;
  }
  J bsdfs = J::array();
  for (std::size_t i = 0; i < t.slabOrder.size(); ++i) {
    const Slab& s = m.slabs[t.slabOrder[i]];
    bsdfs.push_back({{"bsdf", i}, {"node", s.id}, {"features", features(s.features)},
                     {"sss_type", std::string(sssTypeName(s.sssType))}, {"basis", s.basis}});
  }
  j["bsdfs"] = bsdfs;
  J bases = J::array();
  for (std::size_t b = 0; b < m.bases.size(); ++b) {
    J used = J::array();
    for (int s : m.bases[b].slabs) used.push_back(m.slabs[s].id);
    bases.push_back({{"basis", b}, {"normal", renderValue(m, m.bases[b].normal)},
                     {"tangent", m.bases[b].tangent != kNoValue ? J(renderValue(m, m.bases[b].tangent)) : J(nullptr)},
                     {"normal_stored", !(r.after.basis0NormalElided && b == 0) && r.after.closures.size() > 1},
                     {"slabs", used}});
  }
  j["bases"] = bases;
  J steps = J::array();
  for (const auto& s : r.steps)
    steps.push_back({{"action", s.action}, {"kind", s.kind}, {"node", s.node}, {"depth", s.depth},
                     {"bytes_before", s.bytesBefore}, {"bytes_after", s.bytesAfter},
                     {"closures_before", s.closuresBefore}, {"closures_after", s.closuresAfter}});
  j["steps"] = steps;
  J culled = J::array();
  for (const auto& c : m.culled) culled.push_back({{"node", c.what}, {"reason", c.why}});
  j["culled"] = culled;
  J fields = J::array();
  for (const auto& f : r.after.fields)
    fields.push_back({{"name", f.name}, {"bits", f.bits}, {"encoding", f.encoding}});
  j["storage"] = {{"fields", fields}, {"top_layer_bits", r.after.layoutClass == LayoutClass::Volume ? 0 : 32}};
  return j;
}

}  // namespace substratec
