// Evaluates value-DAG nodes on the CPU in double precision for one shading
// point: inputs take given values (their defaults unless overridden),
// geometry a given frame, textures a given constant sample. Used where the
// compiler must decide something from typical values (which side of a mix
// dominates) and by tests of parameter blending.
#pragma once
#include <array>
#include <vector>

#include "ir/material.h"

namespace substratec {

struct EvalPoint {
  std::array<double, 3> normal{0, 0, 1};
  std::array<double, 3> tangent{1, 0, 0};
  std::array<double, 3> view{0, 0, 1};
  std::array<double, 3> position{0, 0, 0};
  std::array<double, 2> uv0{0.5, 0.5}, uv1{0.5, 0.5};
  std::array<double, 4> vertexColor{1, 1, 1, 1};
  std::array<double, 4> textureSample{0.5, 0.5, 0.5, 1};
  std::vector<std::array<double, 4>> inputs;  // empty: every input at its default
};

/// Values of every DAG node up to and including `upTo` (the DAG is
/// topologically ordered, so one forward sweep suffices).
std::vector<std::array<double, 4>> evaluateDag(const Material& m, const EvalPoint& p, ValueId upTo);

/// One node's value.
std::array<double, 4> evaluateValue(const Material& m, ValueId v, const EvalPoint& p = {});

}  // namespace substratec
