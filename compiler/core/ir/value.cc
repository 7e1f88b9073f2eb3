#include "ir/value.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <functional>

#include <fmt/format.h>

#include "ir/helper_math.h"

namespace substratec {

std::string_view typeName(VType t) {
  switch (t) {
    case VType::Float: return "float";
    case VType::Vec2: return "vec2";
    case VType::Vec3: return "vec3";
    case VType::Vec4: return "vec4";
    case VType::Texture: return "texture2d";
    default: return "invalid";
  }
}

std::string_view opName(Op op) {
  static constexpr std::string_view names[] = {
      "const", "input", "geometry", "texture", "add", "subtract", "multiply", "divide", "min",
      "max", "lerp", "clamp", "saturate", "one_minus", "abs", "sqrt", "normalize", "length", "pow",
      "dot", "swizzle", "combine", "step", "exp", "metalness_to_diffuse_f0", "ior_to_f0",
      "haziness_to_second_roughness", "transmittance_to_mfp", "thin_film", "rotation_to_tangent",
      "view_dependent_coverage", "flip_flop"};
  static_assert(sizeof(names) / sizeof(names[0]) == static_cast<std::size_t>(Op::Count_));
  return names[static_cast<int>(op)];
}

bool isHelper(Op op) { return op >= Op::MetalnessToDiffuseF0 && op < Op::Count_; }

std::string_view geometryAttrName(GeometryAttr a) { return enumName(kGeometryAttrNames, a, "normal"); }

VType geometryAttrType(GeometryAttr a) {
  switch (a) {
    case GeometryAttr::Uv0:
    case GeometryAttr::Uv1: return VType::Vec2;
    case GeometryAttr::VertexColor: return VType::Vec4;
    default: return VType::Vec3;
  }
}

bool ValueNode::operator==(const ValueNode& o) const {
  if (op != o.op || type != o.type || attr != o.attr || argCount != o.argCount) return false;
  for (int i = 0; i < argCount; ++i)
    if (args[i] != o.args[i]) return false;
  if (op == Op::Const) {
    // Bitwise comparison: -0.0 and 0.0 stay distinct, which is harmless.
    return std::memcmp(c.data(), o.c.data(), sizeof(double) * 4) == 0;
  }
  return true;
}

std::size_t ValueDag::Hash::operator()(const ValueNode& n) const {
  std::size_t h = static_cast<std::size_t>(n.op) * 0x9E3779B97F4A7C15ull;
  auto mix = [&h](std::uint64_t v) { h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2); };
  mix(static_cast<std::uint64_t>(n.type));
  mix(n.attr);
  for (int i = 0; i < n.argCount; ++i) mix(n.args[i]);
  if (n.op == Op::Const) {
    for (double d : n.c) {
      std::uint64_t bits;
      std::memcpy(&bits, &d, sizeof bits);
      mix(bits);
    }
  }
  return h;
}

ValueId ValueDag::intern(const ValueNode& n) {
  auto it = index_.find(n);
  if (it != index_.end()) return it->second;
  ValueId id = static_cast<ValueId>(nodes_.size());
  nodes_.push_back(n);
  index_.emplace(n, id);
  return id;
}

ValueId ValueDag::constant(VType type, std::array<double, 4> c) {
  ValueNode n;
  n.op = Op::Const;
  n.type = type;
  int k = componentCount(type);
  for (int i = k; i < 4; ++i) c[i] = 0;
  for (int i = 0; i < k; ++i)
    if (c[i] == 0.0) c[i] = 0.0;  // fold -0 into +0 so equal constants hash equal
  n.c = c;
  return intern(n);
}

ValueId ValueDag::input(std::uint16_t index, VType type) {
  ValueNode n;
  n.op = Op::Input;
  n.type = type;
  n.attr = index;
  return intern(n);
}

ValueId ValueDag::geometry(GeometryAttr a) {
  ValueNode n;
  n.op = Op::Geometry;
  n.type = geometryAttrType(a);
  n.attr = static_cast<std::uint16_t>(a);
  return intern(n);
}

ValueId ValueDag::sample(std::uint16_t textureInput, ValueId uv) {
  ValueNode n;
  n.op = Op::Sample;
  n.type = VType::Vec4;
  n.attr = textureInput;
  n.argCount = 1;
  n.args[0] = uv;
  return intern(n);
}

bool ValueDag::isConstEqual(ValueId id, double v) const {
  const ValueNode& n = nodes_[id];
  if (n.op != Op::Const) return false;
  for (int i = 0; i < componentCount(n.type); ++i)
    if (n.c[i] != v) return false;
  return true;
}

ValueId ValueDag::broadcast(ValueId v, VType to) {
  const ValueNode& n = nodes_[v];
  if (n.type == to || n.type != VType::Float) return v;
  if (n.op == Op::Const) return splat(to, n.c[0]);
  // Swizzle .xxx of a scalar: channels all 0, count = target size.
  int k = componentCount(to);
  return make(Op::Swizzle, to, {v}, static_cast<std::uint16_t>(k << 8));
}

namespace {

double componentOf(const std::array<double, 4>& a, VType t, int i) {
  return t == VType::Float ? a[0] : a[i];
}

}  // namespace

// long: one case per Op, the folding table of the value ops (a switch the
// compiler checks for every Op); split, the table would be read in pieces.
bool evalConstOp(Op op, std::uint16_t attr, VType rt, const std::array<double, 4>* a,
                 const VType* at, int n, std::array<double, 4>& out) {
  out = {0, 0, 0, 0};
  const int k = componentCount(rt);
  auto binary = [&](auto f) {
    for (int i = 0; i < k; ++i) out[i] = f(componentOf(a[0], at[0], i), componentOf(a[1], at[1], i));
    return true;
  };
  auto unary = [&](auto f) {
    for (int i = 0; i < k; ++i) out[i] = f(a[0][i]);
    return true;
  };
  auto vec3 = [&](int i) {
    return helpers::Vec3{componentOf(a[i], at[i], 0), componentOf(a[i], at[i], 1),
                         componentOf(a[i], at[i], 2)};
  };
  switch (op) {
    case Op::Add: return binary([](double x, double y) { return x + y; });
    case Op::Subtract: return binary([](double x, double y) { return x - y; });
    case Op::Multiply: return binary([](double x, double y) { return x * y; });
    case Op::Divide: return binary([](double x, double y) { return y == 0.0 ? 0.0 : x / y; });
    case Op::Min: return binary([](double x, double y) { return std::min(x, y); });
    case Op::Max: return binary([](double x, double y) { return std::max(x, y); });
    case Op::Pow:
      // Guarded: a negative base is clamped to 0, and 0 to a negative power is
      // 0 rather than infinity (the runtime's substrate_pow does the same).
      return binary([](double x, double y) {
        double b = std::max(x, 0.0);
        if (b == 0.0) return y == 0.0 ? 1.0 : 0.0;
        return std::pow(b, y);
      });
    case Op::Lerp:
      for (int i = 0; i < k; ++i) {
        double x = componentOf(a[0], at[0], i), y = componentOf(a[1], at[1], i),
               t = componentOf(a[2], at[2], i);
        out[i] = x + (y - x) * t;
      }
      return true;
    case Op::Clamp:
      for (int i = 0; i < k; ++i)
        out[i] = std::min(std::max(componentOf(a[0], at[0], i), componentOf(a[1], at[1], i)),
                          componentOf(a[2], at[2], i));
      return true;
    case Op::Saturate: return unary([](double x) { return std::min(std::max(x, 0.0), 1.0); });
    case Op::OneMinus: return unary([](double x) { return 1.0 - x; });
    case Op::Abs: return unary([](double x) { return std::fabs(x); });
    case Op::Sqrt: return unary([](double x) { return std::sqrt(std::max(x, 0.0)); });
    case Op::Normalize: {
      int m = componentCount(at[0]);
      double s = 0;
      for (int i = 0; i < m; ++i) s += a[0][i] * a[0][i];
      double len = std::sqrt(s);
      for (int i = 0; i < m; ++i) out[i] = len > 0 ? a[0][i] / len : 0.0;
      return true;
    }
    case Op::Length: {
      double s = 0;
      for (int i = 0; i < componentCount(at[0]); ++i) s += a[0][i] * a[0][i];
      out[0] = std::sqrt(s);
      return true;
    }
    case Op::Dot: {
      double s = 0;
      for (int i = 0; i < componentCount(at[0]); ++i) s += a[0][i] * a[1][i];
      out[0] = s;
      return true;
    }
    case Op::Swizzle:
      for (int i = 0; i < k; ++i) out[i] = a[0][(attr >> (2 * i)) & 3];
      return true;
    case Op::Combine:
      for (int i = 0; i < n; ++i) out[i] = a[i][0];
      return true;
    case Op::Step: out[0] = a[1][0] >= a[0][0] ? 1.0 : 0.0; return true;
    case Op::Exp:
      // Capped at the largest float, as the runtime's substrate_value_exp (a
      // float overflows from x ~ 88.72): finite for every finite input.
      return unary([](double x) { return std::min(std::exp(std::min(x, 700.0)), double{FLT_MAX}); });
    case Op::MetalnessToDiffuseF0: {
      auto r = helpers::metalnessToDiffuseF0(vec3(0), a[1][0], a[2][0]);
      const auto& v = attr == 0 ? r.diffuse_albedo : r.f0;
      out = {v[0], v[1], v[2], 0};
      return true;
    }
    case Op::IorToF0: out[0] = helpers::iorToF0(a[0][0]); return true;
    case Op::HazinessToSecondRoughness: {
      auto r = helpers::hazinessToSecondRoughness(a[0][0], a[1][0]);
      out[0] = attr == 0 ? r.second_roughness : r.second_roughness_weight;
      return true;
    }
    case Op::TransmittanceToMfp: {
      auto r = helpers::transmittanceToMfp(vec3(0), a[1][0]);
      if (attr == 0) out = {r.mfp[0], r.mfp[1], r.mfp[2], 0};
      else out[0] = r.thickness;
      return true;
    }
    case Op::RotationToTangent: {
      auto t = helpers::rotationToTangent(a[0][0], vec3(1));
      out = {t[0], t[1], t[2], 0};
      return true;
    }
    default: return false;  // inputs, geometry, samples, view-dependent helpers
  }
}

bool ValueDag::tryFold(ValueNode& n) const {
  std::array<std::array<double, 4>, 5> a{};
  std::array<VType, 5> at{};
  for (int i = 0; i < n.argCount; ++i) {
    const ValueNode& arg = nodes_[n.args[i]];
    if (arg.op != Op::Const) return false;
    a[i] = arg.c;
    at[i] = arg.type;
  }
  std::array<double, 4> out;
  if (!evalConstOp(n.op, n.attr, n.type, a.data(), at.data(), n.argCount, out)) return false;
  for (double d : out)
    if (!std::isfinite(d)) return false;  // keep the expression; the runtime guards it
  n.op = Op::Const;
  n.argCount = 0;
  n.args.fill(kNoValue);
  n.attr = 0;
  n.c = out;
  return true;
}

ValueId ValueDag::trySimplify(const ValueNode& n) {
  auto sameType = [&](ValueId v) { return nodes_[v].type == n.type; };
  auto is = [&](int i, double v) { return isConstEqual(n.args[i], v); };
  switch (n.op) {
    case Op::Add:
      if (is(1, 0) && sameType(n.args[0])) return n.args[0];
      if (is(0, 0) && sameType(n.args[1])) return n.args[1];
      break;
    case Op::Subtract:
      if (is(1, 0) && sameType(n.args[0])) return n.args[0];
      break;
    case Op::Multiply:
      if (is(1, 1) && sameType(n.args[0])) return n.args[0];
      if (is(0, 1) && sameType(n.args[1])) return n.args[1];
      if (is(0, 0) || is(1, 0)) return splat(n.type, 0.0);
      break;
    case Op::Divide:
      if (is(1, 1) && sameType(n.args[0])) return n.args[0];
      break;
    case Op::Min:
    case Op::Max:
      if (n.args[0] == n.args[1]) return n.args[0];
      break;
    case Op::Lerp:
      if (is(2, 0) && sameType(n.args[0])) return n.args[0];
      if (is(2, 1) && sameType(n.args[1])) return n.args[1];
      if (n.args[0] == n.args[1] && sameType(n.args[0])) return n.args[0];
      break;
    case Op::Saturate:
      if (nodes_[n.args[0]].op == Op::Saturate) return n.args[0];
      break;
    case Op::OneMinus:
      if (nodes_[n.args[0]].op == Op::OneMinus) return nodes_[n.args[0]].args[0];
      break;
    case Op::Clamp:
      if (is(1, 0) && is(2, 1)) return make(Op::Saturate, n.type, {n.args[0]});
      break;
    case Op::Swizzle: {
      const int k = componentCount(n.type);
      if (nodes_[n.args[0]].type == n.type && k > 1) {
        bool identity = true;
        for (int i = 0; i < k; ++i)
          if (((n.attr >> (2 * i)) & 3) != i) identity = false;
        if (identity) return n.args[0];
      }
      break;
    }
    default: break;
  }
  return kNoValue;
}

ValueId ValueDag::makeN(Op op, VType resultType, const ValueId* args, int count,
                        std::uint16_t attr) {
  ValueNode n;
  n.op = op;
  n.type = resultType;
  n.attr = attr;
  n.argCount = static_cast<std::uint8_t>(count);
  for (int i = 0; i < count; ++i) n.args[i] = args[i];
  // Commutative ops: canonical argument order so a+b and b+a are one node.
  if ((op == Op::Add || op == Op::Multiply || op == Op::Min || op == Op::Max || op == Op::Dot) &&
      n.args[0] > n.args[1])
    std::swap(n.args[0], n.args[1]);
  if (tryFold(n)) return constant(n.type, n.c);
  ValueId s = trySimplify(n);
  if (s != kNoValue) return s;
  return intern(n);
}

ValueId ValueDag::make(Op op, VType resultType, std::initializer_list<ValueId> args,
                       std::uint16_t attr) {
  return makeN(op, resultType, args.begin(), static_cast<int>(args.size()), attr);
}

std::string ValueDag::render(ValueId id, int budget) const {
  const ValueNode& n = nodes_[id];
  auto num = [](double d) { return fmt::format("{:g}", d); };
  switch (n.op) {
    case Op::Const: {
      int k = componentCount(n.type);
      bool same = true;
      for (int i = 1; i < k; ++i)
        if (n.c[i] != n.c[0]) same = false;
      if (k == 1 || same) return num(n.c[0]);
      std::string s = "[";
      for (int i = 0; i < k; ++i) s += (i ? ", " : "") + num(n.c[i]);
      return s + "]";
    }
    case Op::Input: return fmt::format("input#{}", n.attr);
    case Op::Geometry: return std::string(geometryAttrName(static_cast<GeometryAttr>(n.attr)));
    default: break;
  }
  if (budget <= 0) return "...";
  std::string s = std::string(opName(n.op)) + "(";
  for (int i = 0; i < n.argCount; ++i) s += (i ? ", " : "") + render(n.args[i], budget - 1);
  return s + ")";
}

}  // namespace substratec
