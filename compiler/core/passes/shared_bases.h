// Pass 7 — shared local bases: slabs whose normal (and, when anisotropic,
// tangent) expressions are structurally equal — the same value-DAG node —
// share one basis. Isotropic slabs need only a normal and join the first
// basis with their normal; anisotropic slabs with different tangents get
// different bases. Bases are numbered in closure (pre-)order, so basis 0 is
// the basis of the first top-layer slab.
// Must run after feature analysis (it needs the anisotropy flags).
#pragma once
#include "ir/material.h"

namespace substratec {

void shareLocalBases(Material& m);

}  // namespace substratec
