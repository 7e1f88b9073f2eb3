// A readable, deterministic dump of the material IR (tree, slabs with their
// non-default pins, features, bases). Used by --print-after-all and by the
// per-pass tests, which compare dumps before and after one pass.
#pragma once
#include <string>

#include "ir/material.h"

namespace substratec {

std::string dumpMaterial(const Material& m);

/// Names of the features set in `mask`, comma separated ("" if none).
std::string featureList(std::uint16_t mask);

}  // namespace substratec
