#include "passes/shared_bases.h"

#include "ir/tree_info.h"

namespace substratec {

void shareLocalBases(Material& m) {
  m.bases.clear();
  const TreeInfo info = analyzeTree(m);
  // Anisotropic slabs (and a hair, whose tangent is the fibre's) first fix the (normal, tangent) pairs; isotropic slabs
  // then join any basis with their normal. Both loops run in closure order.
  auto findBasis = [&](ValueId n, ValueId t, bool anyTangent) -> int {
    for (std::size_t b = 0; b < m.bases.size(); ++b)
      if (m.bases[b].normal == n && (anyTangent || m.bases[b].tangent == t)) return static_cast<int>(b);
    return -1;
  };
  std::vector<int> basisOf(m.slabs.size(), -1);
  for (int pass = 0; pass < 2; ++pass) {
    for (int s : info.slabOrder) {
      Slab& slab = m.slabs[s];
      bool aniso = slab.features & kTangentFeatures;  // its basis has a tangent
      if ((pass == 0) != aniso) continue;
      ValueId n = slab.pin(SlabPin::Normal);
      ValueId t = aniso ? slab.pin(SlabPin::Tangent) : kNoValue;
      int b = findBasis(n, t, !aniso);
      if (b < 0) {
        b = static_cast<int>(m.bases.size());
        m.bases.push_back({n, t, {}});
      }
      basisOf[s] = b;
    }
  }
  // Renumber in order of first use along the closure order (deterministic and
  // makes basis 0 the first top slab's basis).
  std::vector<int> remap(m.bases.size(), -1);
  std::vector<Basis> ordered;
  for (int s : info.slabOrder) {
    int b = basisOf[s];
    if (remap[b] < 0) {
      remap[b] = static_cast<int>(ordered.size());
      ordered.push_back({m.bases[b].normal, m.bases[b].tangent, {}});
    }
    m.slabs[s].basis = remap[b];
    ordered[remap[b]].slabs.push_back(s);
  }
  m.bases = std::move(ordered);
}

}  // namespace substratec
