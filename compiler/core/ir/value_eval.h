// Evaluates value-DAG nodes on the CPU in double precision for one shading
// point: inputs take given values (their defaults unless overridden),
// geometry a given frame, textures a given constant sample or, when a sampler
// is set, that sampler at the node's uv. Used where the compiler must decide
// something from typical values (which side of a mix dominates), by tests of
// parameter blending, and by the CPU reference (compiler/tools/reference/).
#pragma once
#include <array>
#include <functional>
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
  /// When set, a texture node (Op::Sample) is this function of the texture
  /// input's index (into Material::inputs) and the node's uv operand (the
  /// format's default uv is geometry uv0, already in the DAG), as the generated
  /// shader's SUBSTRATE_SAMPLE(t_<input>, s_<input>, uv) is; the wrap and filter
  /// policy is the sampler's. Unset: every sample is `textureSample`.
  std::function<std::array<double, 4>(int inputIndex, double u, double v)> sampler;
  std::vector<std::array<double, 4>> inputs;  // empty: every input at its default
};

/// Values of every DAG node up to and including `upTo` (the DAG is
/// topologically ordered, so one forward sweep suffices).
std::vector<std::array<double, 4>> evaluateDag(const Material& m, const EvalPoint& p, ValueId upTo);

/// One node's value.
std::array<double, 4> evaluateValue(const Material& m, ValueId v, const EvalPoint& p = {});

}  // namespace substratec
