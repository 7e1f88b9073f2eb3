// Structural facts about the Substrate tree that several passes and the
// report need: parents, pre-order ids, distance from leaves, layer depth,
// top/bottom flags, and whether a slab's view throughput is statically 1.
#pragma once
#include <vector>

#include "ir/material.h"

namespace substratec {

struct TreeInfo {
  std::vector<int> preorder;     // reachable node indices, root first, left before right
  std::vector<int> reportId;     // node index -> pre-order id (-1 if unreachable)
  std::vector<int> parent;       // node index -> parent node index (-1 for root)
  std::vector<int> distanceFromLeaves;
  std::vector<int> depth;        // distance from the root
  std::vector<int> layerDepth;   // number of vertical "base" edges above
  std::vector<bool> isTop;       // slabs: nothing layered above (layerDepth == 0)
  std::vector<bool> isBottom;    // slabs: nothing layered below (never a vertical top)
  std::vector<bool> unitWeight;  // slabs: the mix/coverage weights on the path to the
                                 // root are statically 1 (transmittance not included), and no
                                 // layer above holds fuzz (fuzzyLayer)
  std::vector<bool> unitCoverageAbove;  // slabs: every layer above has coverage statically 1
  std::vector<bool> unitCoverage;       // any node: the subtree's coverage is statically 1
  std::vector<bool> holdsFuzz;          // any node: the subtree holds a slab with fuzz (fuzzyLayer)
  std::vector<int> interfaces;   // any node: the most interfaces a path down through the subtree
                                 // crosses (slab 1, unlit 0, vertical top + base, other operators the larger side)
  std::vector<int> interfacesAbove;  // slabs: the interfaces of the tops of the verticals whose base
                                     // holds the slab, summed (0 on top): what the light crosses to it
  std::vector<int> slabOrder;    // slab indices in pre-order (the BSDF / closure order); not the
                                 // unlit leaves, which are no closures (slabNode still has them)
  std::vector<int> bsdfId;       // slab index -> position in slabOrder
  std::vector<int> slabNode;     // slab index -> its tree node (-1 if not in the tree)
  std::vector<int> layerVertical;  // node -> the nearest vertical whose top layer holds it, through
                                   // mixes, adds, weights, selects and the bases of verticals nested in
                                   // that layer (its thickness is the node's); -1: none (the surface
                                   // thickness applies)
  std::vector<int> bottomUpOperators;  // operator nodes by distance from leaves, then pre-order:
                                       // an order that evaluates every operand before its operator
  int maxDistanceFromLeaves = 0;
};

TreeInfo analyzeTree(const Material& m);

/// The subtree at `node` holds a slab with fuzz (TreeInfo::holdsFuzz, false
/// for -1): as (or in) the top layer of a vertical, that fuzz reflects a share
/// of the view's light that no longer reaches the layers under it, whose
/// closures' weight takes what the layer lets through
/// (substrate_fuzz_transmission, combined through the layer's operators as its
/// transmittance is; issue 19 steps 7 and 8): their weight is not statically 1.
inline bool fuzzyLayer(const TreeInfo& t, int node) { return node >= 0 && t.holdsFuzz[node]; }

/// The most interfaces beyond the first one above a closure that its stored
/// extra-interface count holds (2 bits: docs/storage.md); the lighting applies
/// the angular part of 1 + that many interfaces, the emitter folds the rest
/// into the layers' transmittance (substrate_extra_interfaces).
inline constexpr int kMaxStoredExtraInterfaces = 3;

/// The extra-interface count a closure under `interfacesAbove` interfaces
/// stores: min(n - 1, 3), 0 on top.
inline int storedExtraInterfaces(int interfacesAbove) {
  return interfacesAbove <= 1 ? 0 : (interfacesAbove - 1 < kMaxStoredExtraInterfaces ? interfacesAbove - 1
                                                                                     : kMaxStoredExtraInterfaces);
}

/// Walking the tops above a closure from the root down, with `budget` the
/// interfaces the lighting still applies (1 + storedExtraInterfaces at the
/// root): how many of the next top's `interfaces` are folded into its
/// transmittance (budget updated). Its first ones are the lighting's.
inline int foldedInterfaces(int interfaces, int& budget) {
  const int lit = interfaces < budget ? interfaces : budget;
  budget -= lit;
  return interfaces - lit;
}

}  // namespace substratec
