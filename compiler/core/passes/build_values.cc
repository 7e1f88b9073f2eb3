#include "passes/build_values.h"

namespace substratec {

ValueId pinToValue(const PinRef& pin, VType want, const ValueTable& table, Material& m) {
  ValueId v = kNoValue;
  switch (pin.tag) {
    case PinRef::Default:
      if (pin.index >= 0 && pin.literalCount == 0) {
        v = m.values.geometry(static_cast<GeometryAttr>(pin.index));
      } else {
        VType t = vectorType(pin.literalCount > 0 ? pin.literalCount : 1);
        v = m.values.constant(t, pin.literal);
      }
      break;
    case PinRef::Literal:
      v = m.values.constant(vectorType(pin.literalCount), pin.literal);
      break;
    case PinRef::Input:
      v = m.values.input(static_cast<std::uint16_t>(pin.index), m.inputs[pin.index].type);
      break;
    case PinRef::Node:
      v = table.outputs[pin.index][pin.output];
      break;
  }
  if (want != VType::Invalid) v = m.values.broadcast(v, want);
  return v;
}

namespace {

/// flip_flop as the primitives of its formula (docs/value-nodes.md, "flip_flop"),
/// lerp(facing, grazing, (1 - saturate(dot(normalize(normal), view)))^max(falloff, 0)),
/// so every later pass, the emitters and the CPU evaluation see nothing new.
ValueId flipFlop(ValueDag& dag, VType r, ValueId facing, ValueId grazing, ValueId falloff, ValueId normal) {
  const ValueId n = dag.make(Op::Normalize, VType::Vec3, {normal});
  const ValueId nov = dag.make(Op::Dot, VType::Float, {n, dag.geometry(GeometryAttr::View)});
  const ValueId away = dag.make(Op::OneMinus, VType::Float, {dag.make(Op::Saturate, VType::Float, {nov})});
  const ValueId t = dag.make(Op::Pow, VType::Float, {away, dag.make(Op::Max, VType::Float, {falloff, dag.scalar(0)})});
  return dag.make(Op::Lerp, r, {facing, grazing, dag.broadcast(t, r)});
}

/// The values one resolved value node computes, in `out` (one per output pin),
/// built from its pins' values (earlier nodes' outputs in `table`).
void emitValueNodeOutputs(const VNode& v, const ValueTable& table, Material& m, std::vector<ValueId>& out) {
  ValueDag& dag = m.values;
  const VType r = v.outputTypes.empty() ? VType::Invalid : v.outputTypes[0];
  auto arg = [&](int k, VType want) { return pinToValue(v.pins[k], want, table, m); };
  switch (v.op) {
    case Op::Geometry:
      out = {dag.geometry(static_cast<GeometryAttr>(v.attr))};
      break;
    case Op::Sample: {
      ValueId s = dag.sample(v.attr, arg(1, VType::Vec2));
      auto sw = [&](VType t, std::uint16_t channels) {
        return dag.make(Op::Swizzle, t, {s}, channels);
      };
      out = {sw(VType::Vec3, 0 | (1 << 2) | (2 << 4) | (3 << 8)), sw(VType::Float, 0 | (1 << 8)),
             sw(VType::Float, 1 | (1 << 8)), sw(VType::Float, 2 | (1 << 8)), sw(VType::Float, 3 | (1 << 8))};
      break;
    }
    case Op::Add: case Op::Subtract: case Op::Multiply: case Op::Divide: case Op::Min:
    case Op::Max: case Op::Pow:
      out = {dag.make(v.op, r, {arg(0, r), arg(1, r)})};
      break;
    case Op::Lerp:
      out = {dag.make(v.op, r, {arg(0, r), arg(1, r), arg(2, r)})};
      break;
    case Op::FlipFlop: {  // its pins in order (a call's arguments are not sequenced): the same DAG everywhere
      const ValueId facing = arg(0, r), grazing = arg(1, r), falloff = arg(2, VType::Float), normal = arg(3, VType::Vec3);
      out = {flipFlop(dag, r, facing, grazing, falloff, normal)};
      break;
    }
    case Op::Clamp:
      out = {dag.make(v.op, r, {arg(0, r), arg(1, r), arg(2, r)})};
      break;
    case Op::Saturate: case Op::OneMinus: case Op::Abs: case Op::Sqrt: case Op::Normalize:
    case Op::Length:
      out = {dag.make(v.op, r, {arg(0, VType::Invalid)})};
      break;
    case Op::Dot:
      out = {dag.make(v.op, r, {arg(0, VType::Invalid), arg(1, VType::Invalid)})};
      break;
    case Op::Swizzle:
      out = {dag.make(v.op, r, {arg(0, VType::Invalid)}, v.attr)};
      break;
    case Op::Combine: {
      int n = componentCount(r);
      ValueId a[4];
      for (int k = 0; k < n; ++k) a[k] = arg(k, VType::Float);
      out = {dag.makeN(v.op, r, a, n)};
      break;
    }
    case Op::MetalnessToDiffuseF0:
    case Op::HazinessToSecondRoughness:
    case Op::TransmittanceToMfp:
    case Op::ThinFilm: {
      std::vector<ValueId> args;
      for (std::size_t k = 0; k < v.pins.size(); ++k) args.push_back(arg(static_cast<int>(k), VType::Invalid));
      // Colour pins broadcast a scalar to grey.
      auto grey = [&](int k) { args[k] = dag.broadcast(args[k], VType::Vec3); };
      if (v.op == Op::MetalnessToDiffuseF0) grey(0);
      if (v.op == Op::TransmittanceToMfp) grey(0);
      if (v.op == Op::ThinFilm) { grey(1); grey(2); }
      for (std::size_t o = 0; o < v.outputTypes.size(); ++o)
        out.push_back(dag.makeN(v.op, v.outputTypes[o], args.data(), static_cast<int>(args.size()),
                                static_cast<std::uint16_t>(o)));
      break;
    }
    case Op::IorToF0:
    case Op::RotationToTangent:
    case Op::ViewDependentCoverage: {
      ValueId a0 = arg(0, VType::Invalid), a1 = v.pins.size() > 1 ? arg(1, VType::Invalid) : kNoValue;
      out = {v.pins.size() > 1 ? dag.make(v.op, r, {a0, a1}) : dag.make(v.op, r, {a0})};
      break;
    }
    default:
      out = {dag.scalar(0)};
  }
}

/// Names the computed outputs of a node with an id for the generated code:
/// the id, with the output pin's name after it when there are several.
void nameValueNodeOutputs(const VNode& v, const std::vector<ValueId>& out, Material& m) {
  const ValueDag& dag = m.values;
  if (!v.id.empty()) {
    static const char* const kTextureOutputs[] = {"rgb", "r", "g", "b", "a"};
    static const char* const kHelperOutputs[][2] = {{"diffuse_albedo", "f0"}, {"second_roughness", "second_roughness_weight"},
                                                    {"mfp", "thickness"}, {"f0", "f90"}};
    for (std::size_t o = 0; o < out.size(); ++o) {
      const ValueNode& node = dag.node(out[o]);
      if (node.op == Op::Const || node.op == Op::Input || node.op == Op::Geometry) continue;
      std::string name = v.id;
      if (out.size() > 1) {
        const char* suffix = v.op == Op::Sample ? kTextureOutputs[o]
                             : v.op == Op::MetalnessToDiffuseF0 ? kHelperOutputs[0][o]
                             : v.op == Op::HazinessToSecondRoughness ? kHelperOutputs[1][o]
                             : v.op == Op::TransmittanceToMfp ? kHelperOutputs[2][o]
                                                              : kHelperOutputs[3][o];
        name += std::string("_") + suffix;
      }
      m.valueNames.emplace(out[o], name);  // the first name given to a node wins
    }
  }
}

}  // namespace

ValueTable buildValueDag(const ResolvedDoc& doc, Material& m) {
  m.name = doc.name;
  m.settings = doc.settings;
  m.inputs = doc.inputs;
  ValueTable table;
  table.outputs.resize(doc.values.size());
  for (int index : doc.valueOrder) {
    const VNode& v = doc.values[index];
    std::vector<ValueId>& out = table.outputs[index];
    emitValueNodeOutputs(v, table, m, out);
    nameValueNodeOutputs(v, out, m);
  }
  return table;
}

}  // namespace substratec
