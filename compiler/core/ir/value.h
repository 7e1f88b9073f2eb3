// The value DAG: every expression a material computes (inputs, geometry,
// textures, math, helper conversions), hash-consed so that structurally
// identical subexpressions are one node, and folded where constant.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "ir/enums.h"  // GeometryAttr (and the IR's other enums, with their names)

namespace substratec {

/// Value types. Colors are Vec3. Texture is only the type of a texture2d input.
enum class VType : std::uint8_t { Invalid = 0, Float = 1, Vec2 = 2, Vec3 = 3, Vec4 = 4, Texture = 5 };
inline int componentCount(VType t) {
  return (t >= VType::Float && t <= VType::Vec4) ? static_cast<int>(t) : 0;
}
inline VType vectorType(int n) { return n >= 1 && n <= 4 ? static_cast<VType>(n) : VType::Invalid; }
std::string_view typeName(VType t);

enum class Op : std::uint8_t {
  Const,
  Input,     // attr = input index
  Geometry,  // attr = GeometryAttr
  Sample,    // texture sample (vec4): attr = input index of the texture; args[0] = uv
  // math
  Add, Subtract, Multiply, Divide, Min, Max,  // binary, broadcasting
  Lerp,                                       // a, b, t
  Clamp,                                      // x, lo, hi
  Saturate, OneMinus, Abs, Sqrt, Normalize, Length,
  Pow, Dot,
  Swizzle,   // attr = packed channel indices (2 bits each) | count << 8
  Combine,   // 2..4 scalar args
  Step,      // internal (not a format kind): step(edge, x) = x >= edge ? 1 : 0
  Exp,       // internal: exp(x), for transmittance exp(-d/mfp)
  // helpers (attr = output index for multi-output helpers)
  MetalnessToDiffuseF0,      // base_color, metallic, specular -> 0: diffuse_albedo, 1: f0
  IorToF0,                   // ior
  HazinessToSecondRoughness, // roughness, haziness -> 0: second_roughness, 1: weight
  TransmittanceToMfp,        // transmittance, thickness -> 0: mfp, 1: thickness
  ThinFilm,                  // normal, f0, f90, thickness, ior -> 0: f0, 1: f90
  RotationToTangent,         // angle, normal
  ViewDependentCoverage,     // coverage, normal
  FlipFlop,                  // facing, grazing, falloff, normal: lowered by buildValueDag, never in the DAG
  Count_
};
std::string_view opName(Op op);
bool isHelper(Op op);

std::string_view geometryAttrName(GeometryAttr a);
VType geometryAttrType(GeometryAttr a);

using ValueId = std::uint32_t;
inline constexpr ValueId kNoValue = 0xffffffffu;

struct ValueNode {
  Op op = Op::Const;
  VType type = VType::Invalid;
  std::uint16_t attr = 0;
  std::uint8_t argCount = 0;
  std::array<ValueId, 5> args{kNoValue, kNoValue, kNoValue, kNoValue, kNoValue};
  std::array<double, 4> c{0, 0, 0, 0};  // Const only

  bool operator==(const ValueNode& o) const;
};

/// The DAG. Nodes are created only through make(), which folds constants and
/// applies algebraic identities, then returns the existing node if an equal
/// one exists (structural hashing). Ids are dense and creation-ordered, so a
/// node's arguments always have smaller ids (the vector is topologically sorted).
class ValueDag {
 public:
  ValueId constant(VType type, std::array<double, 4> c);
  ValueId scalar(double v) { return constant(VType::Float, {v, 0, 0, 0}); }
  ValueId splat(VType type, double v) { return constant(type, {v, v, v, v}); }
  ValueId input(std::uint16_t index, VType type);
  ValueId geometry(GeometryAttr a);
  ValueId sample(std::uint16_t textureInput, ValueId uv);
  /// Generic creation; args must already be type-checked. `resultType` is the
  /// type computed by the caller (see resultTypeOf).
  ValueId make(Op op, VType resultType, std::initializer_list<ValueId> args, std::uint16_t attr = 0);
  ValueId makeN(Op op, VType resultType, const ValueId* args, int n, std::uint16_t attr = 0);

  /// Broadcasts a Float to `to` (Vec2..Vec4); identity if types match.
  ValueId broadcast(ValueId v, VType to);

  const ValueNode& node(ValueId id) const { return nodes_[id]; }
  std::size_t size() const { return nodes_.size(); }
  bool isConst(ValueId id) const { return nodes_[id].op == Op::Const; }
  /// True if `id` is a constant whose every component equals v.
  bool isConstEqual(ValueId id, double v) const;
  /// Short human-readable rendering for dumps and reports (bounded length).
  std::string render(ValueId id, int budget = 6) const;

 private:
  ValueId intern(const ValueNode& n);
  bool tryFold(ValueNode& n) const;
  ValueId trySimplify(const ValueNode& n);

  struct Hash {
    std::size_t operator()(const ValueNode& n) const;
  };
  std::vector<ValueNode> nodes_;
  std::unordered_map<ValueNode, ValueId, Hash> index_;
};

/// Evaluates a pure op on constant arguments (double precision, guarded:
/// divide by zero gives 0, sqrt/pow clamp their base at 0, normalize(0) = 0).
/// Returns false for ops that cannot be folded (inputs, geometry, samples,
/// view-dependent helpers).
bool evalConstOp(Op op, std::uint16_t attr, VType resultType, const std::array<double, 4>* args,
                 const VType* argTypes, int argCount, std::array<double, 4>& out);

}  // namespace substratec
