#include "ir/dump.h"

#include <fmt/format.h>

#include "ir/tree_info.h"

namespace substratec {

std::string featureList(std::uint16_t mask) {
  std::string s;
  for (int b = 0; b < kFeatureCount; ++b)
    if (mask & (1u << b)) s += (s.empty() ? "" : ",") + std::string(featureName(b));
  return s;
}

std::string dumpMaterial(const Material& m) {
  std::string out;
  if (m.root < 0) return "(empty)\n";
  const TreeInfo info = analyzeTree(m);
  // Tree, indented by depth, in pre-order.
  for (int n : info.preorder) {
    const TreeNode& node = m.nodes[n];
    std::string line(static_cast<std::size_t>(info.depth[n]) * 2, ' ');
    line += fmt::format("{} {}", nodeOpName(m, node), node.id);
    switch (node.op) {
      case TreeOp::Horizontal: line += " mix=" + renderValue(m, node.a); break;
      case TreeOp::Vertical: line += " thickness=" + renderValue(m, node.a); break;
      case TreeOp::CoverageWeight: line += " weight=" + renderValue(m, node.a); break;
      case TreeOp::Select:
        line += " value=" + renderValue(m, node.a) + " threshold=" + renderValue(m, node.b);
        break;
      default: break;
    }
    out += line + "\n";
    if (node.op != TreeOp::Slab) continue;
    const Slab& s = m.slabs[node.slab];
    std::string pad(static_cast<std::size_t>(info.depth[n]) * 2 + 4, ' ');
    for (int p = 0; p < kSlabPinCount; ++p) {
      if (!bsdfTakesPin(s.kind, static_cast<SlabPin>(p))) continue;
      const SlabPinInfo& pi = slabPinInfo(static_cast<SlabPin>(p));
      ValueId v = s.pins[p];
      bool isDefault = pi.geometryDefault >= 0
                           ? (m.values.node(v).op == Op::Geometry && m.values.node(v).attr == pi.geometryDefault)
                           : m.values.isConstEqual(v, pi.defaultValue);
      if (!isDefault) out += fmt::format("{}{} = {}\n", pad, pi.name, renderValue(m, v));
    }
    if (s.specularProfileInput >= 0) out += fmt::format("{}specular_profile = ${}\n", pad, m.inputs[s.specularProfileInput].name);
    if (s.sssType != SssType::None) out += fmt::format("{}sss_type = {}\n", pad, sssTypeName(s.sssType));
    if (s.features) out += fmt::format("{}features = {}\n", pad, featureList(s.features));
    if (s.coverage != kNoValue) out += fmt::format("{}coverage = {}\n", pad, renderValue(m, s.coverage));
    if (s.thickness != kNoValue) out += fmt::format("{}thickness = {}\n", pad, renderValue(m, s.thickness));
    if (s.basis >= 0) out += fmt::format("{}basis = {}\n", pad, s.basis);
  }
  for (std::size_t b = 0; b < m.bases.size(); ++b) {
    const Basis& basis = m.bases[b];
    out += fmt::format("basis {}: normal = {}{}\n", b, renderValue(m, basis.normal),
                       basis.tangent != kNoValue ? ", tangent = " + renderValue(m, basis.tangent) : "");
  }
  for (const auto& c : m.culled) out += fmt::format("culled {}: {}\n", c.what, c.why);
  return out;
}

}  // namespace substratec
