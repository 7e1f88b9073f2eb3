#include "ir/value_eval.h"

#include <cmath>

#include "ir/helper_math.h"

namespace substratec {

std::vector<std::array<double, 4>> evaluateDag(const Material& m, const EvalPoint& p, ValueId upTo) {
  std::vector<std::array<double, 4>> val(static_cast<std::size_t>(upTo) + 1);
  std::array<std::array<double, 4>, 5> args{};
  std::array<VType, 5> types{};
  for (ValueId id = 0; id <= upTo; ++id) {
    const ValueNode& n = m.values.node(id);
    std::array<double, 4>& out = val[id];
    out = {0, 0, 0, 0};
    switch (n.op) {
      case Op::Const: out = n.c; continue;
      case Op::Input:
        out = n.attr < p.inputs.size() ? p.inputs[n.attr] : m.inputs[n.attr].defaultValue;
        continue;
      case Op::Geometry:
        switch (static_cast<GeometryAttr>(n.attr)) {
          case GeometryAttr::Normal: out = {p.normal[0], p.normal[1], p.normal[2], 0}; break;
          case GeometryAttr::Tangent: out = {p.tangent[0], p.tangent[1], p.tangent[2], 0}; break;
          case GeometryAttr::View: out = {p.view[0], p.view[1], p.view[2], 0}; break;
          case GeometryAttr::Position: out = {p.position[0], p.position[1], p.position[2], 0}; break;
          case GeometryAttr::Uv0: out = {p.uv0[0], p.uv0[1], 0, 0}; break;
          case GeometryAttr::Uv1: out = {p.uv1[0], p.uv1[1], 0, 0}; break;
          case GeometryAttr::VertexColor: out = p.vertexColor; break;
        }
        continue;
      case Op::Sample:
        if (p.sampler) {
          const std::array<double, 4>& uv = val[n.args[0]];
          out = p.sampler(static_cast<int>(n.attr), uv[0], uv[1]);
        } else {
          out = p.textureSample;
        }
        continue;
      default: break;
    }
    for (int i = 0; i < n.argCount; ++i) {
      args[i] = val[n.args[i]];
      types[i] = m.values.node(n.args[i]).type;
    }
    if (n.op == Op::ThinFilm || n.op == Op::ViewDependentCoverage) {
      // View-dependent helpers: NoV from the point's view and the given normal.
      const auto& nn = n.op == Op::ThinFilm ? args[0] : args[1];
      double len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
      double NoV = len > 0 ? (nn[0] * p.view[0] + nn[1] * p.view[1] + nn[2] * p.view[2]) / len : 0.0;
      if (n.op == Op::ViewDependentCoverage) {
        out[0] = helpers::viewDependentCoverage(args[0][0], NoV);
      } else {
        auto r = helpers::thinFilm(NoV, {args[1][0], args[1][1], args[1][2]}, {args[2][0], args[2][1], args[2][2]},
                                   args[3][0], args[4][0]);
        const auto& c = n.attr == 0 ? r.f0 : r.f90;
        out = {c[0], c[1], c[2], 0};
      }
      continue;
    }
    evalConstOp(n.op, n.attr, n.type, args.data(), types.data(), n.argCount, out);
  }
  return val;
}

std::array<double, 4> evaluateValue(const Material& m, ValueId v, const EvalPoint& p) {
  return evaluateDag(m, p, v)[v];
}

}  // namespace substratec
