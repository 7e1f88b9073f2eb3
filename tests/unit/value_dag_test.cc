// Tests for the value DAG (compiler/core/ir/value.h), written as its specification:
// every node is created through ValueDag::make, which (1) folds an op whose
// arguments are all constant, with the guarded formulas of docs/value-nodes.md,
// (2) applies algebraic identities, and (3) returns the existing node when an
// equal one exists (structural hashing). Ids are creation-ordered, so the node
// vector is topologically sorted.
#include "ir/value.h"

#include <gtest/gtest.h>

#include <array>
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "ir/helper_math.h"
#include "test_util.h"

namespace substratec {
namespace {

using C = std::array<double, 4>;

// Swizzle attribute: channel indices (2 bits each) | count << 8.
std::uint16_t channels(std::initializer_list<int> cs) {
  std::uint16_t a = 0;
  int i = 0;
  for (int c : cs) a |= static_cast<std::uint16_t>(c << (2 * i++));
  return static_cast<std::uint16_t>(a | (cs.size() << 8));
}

class ValueDagTest : public ::testing::Test {
 protected:
  ValueDag dag;

  ValueId f(double v) { return dag.scalar(v); }
  ValueId v2(double x, double y) { return dag.constant(VType::Vec2, {x, y, 0, 0}); }
  ValueId v3(double x, double y, double z) { return dag.constant(VType::Vec3, {x, y, z, 0}); }
  ValueId x() { return dag.input(0, VType::Float); }   // a run-time float
  ValueId y() { return dag.input(1, VType::Float); }   // another one
  ValueId c3() { return dag.input(2, VType::Vec3); }   // a run-time colour

  std::string op(ValueId id) const { return std::string(opName(dag.node(id).op)); }
  std::string type(ValueId id) const { return std::string(typeName(dag.node(id).type)); }

  /// Expects `id` to be a constant of `type` with components `want`.
  void expectConst(ValueId id, VType type, C want) {
    const ValueNode& n = dag.node(id);
    ASSERT_EQ(op(id), "const") << "got " << dag.render(id);
    EXPECT_EQ(typeName(n.type), typeName(type));
    for (int i = 0; i < componentCount(type); ++i) EXPECT_DOUBLE_EQ(n.c[i], want[i]) << "component " << i;
    for (int i = componentCount(type); i < 4; ++i) EXPECT_EQ(n.c[i], 0.0) << "unused component " << i;
  }
  void expectScalar(ValueId id, double want) { expectConst(id, VType::Float, {want, 0, 0, 0}); }
};

// ---------------------------------------------------------------------------
// Structural hashing

TEST_F(ValueDagTest, SameExpressionBuiltTwiceIsOneNode) {
  ValueId a = dag.make(Op::Multiply, VType::Float, {x(), f(2)});
  const std::size_t size = dag.size();
  ValueId b = dag.make(Op::Multiply, VType::Float, {x(), f(2)});
  EXPECT_EQ(a, b);
  EXPECT_EQ(dag.size(), size) << "the second build must not create nodes";
}

TEST_F(ValueDagTest, DeepExpressionBuiltTwiceIsOneNode) {
  auto build = [&] {
    ValueId uv = dag.make(Op::Multiply, VType::Vec2, {dag.geometry(GeometryAttr::Uv0), v2(4, 4)});
    ValueId s = dag.sample(3, uv);
    ValueId rgb = dag.make(Op::Swizzle, VType::Vec3, {s}, channels({0, 1, 2}));
    return dag.make(Op::Lerp, VType::Vec3, {rgb, c3(), dag.broadcast(x(), VType::Vec3)});
  };
  ValueId a = build();
  const std::size_t size = dag.size();
  EXPECT_EQ(build(), a);
  EXPECT_EQ(dag.size(), size);
}

TEST_F(ValueDagTest, EqualConstantsAreOneNode) {
  EXPECT_EQ(f(0.5), f(0.5));
  EXPECT_EQ(dag.splat(VType::Vec3, 0.25), v3(0.25, 0.25, 0.25));
  // Components beyond the type's size are ignored.
  EXPECT_EQ(dag.constant(VType::Vec2, {1, 2, 7, 9}), v2(1, 2));
  // -0 and +0 are one constant.
  EXPECT_EQ(f(-0.0), f(0.0));
  EXPECT_EQ(v3(-0.0, 1, -0.0), v3(0, 1, 0));
}

TEST_F(ValueDagTest, ConstantsOfDifferentTypeOrValueAreDistinct) {
  EXPECT_NE(f(1), dag.splat(VType::Vec2, 1));
  EXPECT_NE(dag.splat(VType::Vec2, 1), dag.splat(VType::Vec3, 1));
  EXPECT_NE(f(1), f(1.0000001));
  EXPECT_NE(v3(1, 2, 3), v3(3, 2, 1));
}

TEST_F(ValueDagTest, LeavesAreHashConsed) {
  EXPECT_EQ(dag.input(4, VType::Vec2), dag.input(4, VType::Vec2));
  EXPECT_NE(dag.input(4, VType::Float), dag.input(5, VType::Float));
  EXPECT_EQ(dag.geometry(GeometryAttr::Normal), dag.geometry(GeometryAttr::Normal));
  EXPECT_NE(dag.geometry(GeometryAttr::Normal), dag.geometry(GeometryAttr::Tangent));
  ValueId uv = dag.geometry(GeometryAttr::Uv0);
  EXPECT_EQ(dag.sample(0, uv), dag.sample(0, uv));
  EXPECT_NE(dag.sample(0, uv), dag.sample(1, uv)) << "different textures";
  EXPECT_NE(dag.sample(0, uv), dag.sample(0, dag.geometry(GeometryAttr::Uv1))) << "different uvs";
}

TEST_F(ValueDagTest, CommutativeOpsAreOneNodeInEitherOrder) {
  for (Op op : {Op::Add, Op::Multiply, Op::Min, Op::Max}) {
    EXPECT_EQ(dag.make(op, VType::Float, {x(), y()}), dag.make(op, VType::Float, {y(), x()})) << opName(op);
  }
  ValueId n = dag.geometry(GeometryAttr::Normal), v = dag.geometry(GeometryAttr::View);
  EXPECT_EQ(dag.make(Op::Dot, VType::Float, {n, v}), dag.make(Op::Dot, VType::Float, {v, n}));
  // a + b == b + a also with a constant operand.
  EXPECT_EQ(dag.make(Op::Add, VType::Float, {x(), f(3)}), dag.make(Op::Add, VType::Float, {f(3), x()}));
}

TEST_F(ValueDagTest, NonCommutativeOpsKeepTheirOrder) {
  for (Op op : {Op::Subtract, Op::Divide, Op::Pow}) {
    EXPECT_NE(dag.make(op, VType::Float, {x(), y()}), dag.make(op, VType::Float, {y(), x()})) << opName(op);
  }
  ValueId a = dag.make(Op::Lerp, VType::Float, {x(), y(), dag.input(9, VType::Float)});
  ValueId b = dag.make(Op::Lerp, VType::Float, {y(), x(), dag.input(9, VType::Float)});
  EXPECT_NE(a, b);
}

TEST_F(ValueDagTest, AttributeIsPartOfTheKey) {
  ValueId a = dag.make(Op::Swizzle, VType::Float, {c3()}, channels({0}));
  ValueId b = dag.make(Op::Swizzle, VType::Float, {c3()}, channels({1}));
  EXPECT_NE(a, b);
  EXPECT_EQ(a, dag.make(Op::Swizzle, VType::Float, {c3()}, channels({0})));
}

TEST_F(ValueDagTest, OutputIndexAndTypeArePartOfTheKey) {
  // The outputs of a multi-output helper differ only by their output index (attr).
  ValueId a = dag.make(Op::HazinessToSecondRoughness, VType::Float, {x(), y()}, 0);
  ValueId b = dag.make(Op::HazinessToSecondRoughness, VType::Float, {x(), y()}, 1);
  EXPECT_NE(a, b);
  // Same op and arguments, different result type.
  EXPECT_NE(dag.make(Op::Abs, VType::Float, {x()}), dag.make(Op::Abs, VType::Vec3, {x()}));
}

TEST(ValueDagFromDocument, RepeatedAndCommutedExpressionsAreOneNode) {
  // The value DAG is built once per material: the same inline expression in
  // two pins, or with its operands swapped, is one node.
  Material m = test::runUntil(test::material(R"("root": {"kind": "slab",
      "roughness": {"kind": "multiply", "a": "$m", "b": 0.5},
      "second_roughness": {"kind": "multiply", "a": "$m", "b": 0.5},
      "fuzz_amount": {"kind": "add", "a": "$m", "b": "$n"},
      "fuzz_roughness": {"kind": "add", "a": "$n", "b": "$m"}})",
                                                  R"({"m": {"type": "float", "default": 0.5},
                                                      "n": {"type": "float", "default": 0.25}})"),
                              "build-tree");
  ASSERT_EQ(m.slabs.size(), 1u);
  const Slab& s = m.slabs[0];
  EXPECT_EQ(s.pin(SlabPin::Roughness), s.pin(SlabPin::SecondRoughness));
  EXPECT_EQ(s.pin(SlabPin::FuzzAmount), s.pin(SlabPin::FuzzRoughness));
  EXPECT_NE(s.pin(SlabPin::Roughness), s.pin(SlabPin::FuzzAmount));
}

TEST(ValueDagFromDocument, ConstantExpressionsAreFoldedWhenTheDocumentIsBuilt) {
  Material m = test::runUntil(test::material(R"("root": {"kind": "slab",
      "roughness": {"kind": "multiply", "a": {"kind": "sqrt", "x": 0.25}, "b": {"kind": "one_minus", "x": 0.2}},
      "f0": {"kind": "ior_to_f0", "ior": 1.5}})"),
                              "build-tree");
  const Slab& s = m.slabs[0];
  ASSERT_TRUE(m.values.isConst(s.pin(SlabPin::Roughness)));
  EXPECT_DOUBLE_EQ(m.values.node(s.pin(SlabPin::Roughness)).c[0], 0.4);
  // A float helper result in a colour pin is broadcast to grey.
  ValueId f0 = s.pin(SlabPin::F0);
  ASSERT_TRUE(m.values.isConst(f0));
  EXPECT_TRUE(m.values.isConstEqual(f0, helpers::iorToF0(1.5)));
  EXPECT_EQ(typeName(m.values.node(f0).type), "vec3");
}

// ---------------------------------------------------------------------------
// Constant folding: every math op

TEST_F(ValueDagTest, Fold_BinaryOps) {
  expectScalar(dag.make(Op::Add, VType::Float, {f(1), f(2)}), 3);
  expectScalar(dag.make(Op::Subtract, VType::Float, {f(5), f(2)}), 3);
  expectScalar(dag.make(Op::Multiply, VType::Float, {f(3), f(4)}), 12);
  expectScalar(dag.make(Op::Divide, VType::Float, {f(1), f(4)}), 0.25);
  expectScalar(dag.make(Op::Min, VType::Float, {f(2), f(3)}), 2);
  expectScalar(dag.make(Op::Max, VType::Float, {f(2), f(3)}), 3);
  expectScalar(dag.make(Op::Pow, VType::Float, {f(2), f(3)}), 8);
}

TEST_F(ValueDagTest, Fold_VectorOpsArePerComponent) {
  expectConst(dag.make(Op::Add, VType::Vec3, {v3(1, 2, 3), v3(10, 20, 30)}), VType::Vec3, {11, 22, 33, 0});
  expectConst(dag.make(Op::Subtract, VType::Vec2, {v2(1, 2), v2(3, 5)}), VType::Vec2, {-2, -3, 0, 0});
  expectConst(dag.make(Op::Min, VType::Vec3, {v3(1, 5, 3), v3(2, 4, 3)}), VType::Vec3, {1, 4, 3, 0});
  expectConst(dag.make(Op::Max, VType::Vec3, {v3(1, 5, 3), v3(2, 4, 3)}), VType::Vec3, {2, 5, 3, 0});
}

TEST_F(ValueDagTest, Fold_Lerp) {
  expectScalar(dag.make(Op::Lerp, VType::Float, {f(2), f(4), f(0.25)}), 2.5);
  // t is not clamped: it extrapolates.
  expectScalar(dag.make(Op::Lerp, VType::Float, {f(2), f(4), f(2)}), 6);
  // Per-component t.
  expectConst(dag.make(Op::Lerp, VType::Vec2, {v2(0, 0), v2(10, 10), v2(0.5, 0.25)}), VType::Vec2,
              {5, 2.5, 0, 0});
}

TEST_F(ValueDagTest, Fold_ClampAndSaturate) {
  expectScalar(dag.make(Op::Clamp, VType::Float, {f(5), f(0), f(2)}), 2);
  expectScalar(dag.make(Op::Clamp, VType::Float, {f(-1), f(0), f(2)}), 0);
  expectScalar(dag.make(Op::Clamp, VType::Float, {f(1), f(0), f(2)}), 1);
  // lo > hi gives hi.
  expectScalar(dag.make(Op::Clamp, VType::Float, {f(0.5), f(3), f(1)}), 1);
  expectScalar(dag.make(Op::Saturate, VType::Float, {f(1.5)}), 1);
  expectScalar(dag.make(Op::Saturate, VType::Float, {f(-0.5)}), 0);
  expectConst(dag.make(Op::Saturate, VType::Vec3, {v3(-1, 0.5, 2)}), VType::Vec3, {0, 0.5, 1, 0});
}

TEST_F(ValueDagTest, Fold_UnaryOps) {
  expectScalar(dag.make(Op::OneMinus, VType::Float, {f(0.25)}), 0.75);
  expectConst(dag.make(Op::OneMinus, VType::Vec3, {v3(0, 0.5, 1)}), VType::Vec3, {1, 0.5, 0, 0});
  expectScalar(dag.make(Op::Abs, VType::Float, {f(-3)}), 3);
  expectScalar(dag.make(Op::Sqrt, VType::Float, {f(9)}), 3);
  expectConst(dag.make(Op::Normalize, VType::Vec3, {v3(3, 0, 4)}), VType::Vec3, {0.6, 0, 0.8, 0});
  expectScalar(dag.make(Op::Length, VType::Float, {v3(3, 4, 12)}), 13);
  expectScalar(dag.make(Op::Dot, VType::Float, {v3(1, 2, 3), v3(4, 5, 6)}), 32);
}

TEST_F(ValueDagTest, Fold_NormalizeAndLengthOfAFloat) {
  // On a float, normalize is the sign and length the absolute value.
  expectScalar(dag.make(Op::Normalize, VType::Float, {f(-2.5)}), -1);
  expectScalar(dag.make(Op::Normalize, VType::Float, {f(7)}), 1);
  expectScalar(dag.make(Op::Length, VType::Float, {f(-2.5)}), 2.5);
  // dot of two floats is their product.
  expectScalar(dag.make(Op::Dot, VType::Float, {f(3), f(-2)}), -6);
}

TEST_F(ValueDagTest, Fold_SwizzleAndCombine) {
  expectConst(dag.make(Op::Swizzle, VType::Vec2, {v3(1, 2, 3)}, channels({2, 0})), VType::Vec2, {3, 1, 0, 0});
  expectConst(dag.make(Op::Swizzle, VType::Vec3, {v3(1, 2, 3)}, channels({2, 1, 0})), VType::Vec3, {3, 2, 1, 0});
  expectScalar(dag.make(Op::Swizzle, VType::Float, {v3(1, 2, 3)}, channels({1})), 2);
  // "xxx" spreads a float.
  expectConst(dag.make(Op::Swizzle, VType::Vec3, {f(4)}, channels({0, 0, 0})), VType::Vec3, {4, 4, 4, 0});
  expectConst(dag.make(Op::Combine, VType::Vec3, {f(1), f(2), f(3)}), VType::Vec3, {1, 2, 3, 0});
  expectConst(dag.make(Op::Combine, VType::Vec2, {f(5), f(6)}), VType::Vec2, {5, 6, 0, 0});
}

TEST_F(ValueDagTest, Fold_Step) {
  // step(edge, x) = x >= edge ? 1 : 0
  expectScalar(dag.make(Op::Step, VType::Float, {f(0.5), f(0.5)}), 1);
  expectScalar(dag.make(Op::Step, VType::Float, {f(0.5), f(0.7)}), 1);
  expectScalar(dag.make(Op::Step, VType::Float, {f(0.5), f(0.3)}), 0);
}

TEST_F(ValueDagTest, Fold_Helpers) {
  expectScalar(dag.make(Op::IorToF0, VType::Float, {f(1.5)}), helpers::iorToF0(1.5));
  auto r = helpers::metalnessToDiffuseF0({0.9, 0.5, 0.1}, 0.25, 0.5);
  ValueId args[] = {v3(0.9, 0.5, 0.1), f(0.25), f(0.5)};
  expectConst(dag.makeN(Op::MetalnessToDiffuseF0, VType::Vec3, args, 3, 0), VType::Vec3,
              {r.diffuse_albedo[0], r.diffuse_albedo[1], r.diffuse_albedo[2], 0});
  expectConst(dag.makeN(Op::MetalnessToDiffuseF0, VType::Vec3, args, 3, 1), VType::Vec3,
              {r.f0[0], r.f0[1], r.f0[2], 0});
  auto h = helpers::hazinessToSecondRoughness(0.3, 0.6);
  expectScalar(dag.make(Op::HazinessToSecondRoughness, VType::Float, {f(0.3), f(0.6)}, 0), h.second_roughness);
  expectScalar(dag.make(Op::HazinessToSecondRoughness, VType::Float, {f(0.3), f(0.6)}, 1),
               h.second_roughness_weight);
}

// ---------------------------------------------------------------------------
// Constant folding: broadcasting

TEST_F(ValueDagTest, Fold_ScalarBroadcastsAgainstAVector) {
  expectConst(dag.make(Op::Add, VType::Vec3, {v3(1, 2, 3), f(10)}), VType::Vec3, {11, 12, 13, 0});
  expectConst(dag.make(Op::Multiply, VType::Vec3, {f(2), v3(1, 2, 3)}), VType::Vec3, {2, 4, 6, 0});
  expectConst(dag.make(Op::Subtract, VType::Vec2, {f(1), v2(0.25, 0.5)}), VType::Vec2, {0.75, 0.5, 0, 0});
  expectConst(dag.make(Op::Divide, VType::Vec2, {v2(1, 3), f(2)}), VType::Vec2, {0.5, 1.5, 0, 0});
  expectConst(dag.make(Op::Lerp, VType::Vec3, {v3(0, 0, 0), v3(2, 4, 8), f(0.5)}), VType::Vec3, {1, 2, 4, 0});
  expectConst(dag.make(Op::Clamp, VType::Vec3, {v3(-1, 0.5, 3), f(0), f(1)}), VType::Vec3, {0, 0.5, 1, 0});
}

TEST_F(ValueDagTest, Broadcast_ConstantBecomesASplatAndRunTimeAFloatSwizzle) {
  EXPECT_EQ(dag.broadcast(f(0.3), VType::Vec3), dag.splat(VType::Vec3, 0.3));
  ValueId b = dag.broadcast(x(), VType::Vec3);
  const ValueNode& n = dag.node(b);
  EXPECT_EQ(op(b), "swizzle");
  EXPECT_EQ(type(b), "vec3");
  EXPECT_EQ(n.args[0], x());
  EXPECT_EQ(n.attr, channels({0, 0, 0}));
  // Identity when the types already match; vectors are never broadcast.
  EXPECT_EQ(dag.broadcast(c3(), VType::Vec3), c3());
  EXPECT_EQ(dag.broadcast(v2(1, 2), VType::Vec3), v2(1, 2));
}

// ---------------------------------------------------------------------------
// Constant folding: guards

TEST_F(ValueDagTest, Fold_DivideByZeroIsZero) {
  expectScalar(dag.make(Op::Divide, VType::Float, {f(1), f(0)}), 0);
  expectScalar(dag.make(Op::Divide, VType::Float, {f(0), f(0)}), 0);
  // Per component.
  expectConst(dag.make(Op::Divide, VType::Vec2, {v2(1, 2), v2(0, 4)}), VType::Vec2, {0, 0.5, 0, 0});
}

TEST_F(ValueDagTest, Fold_SqrtOfNegativeIsZero) {
  expectScalar(dag.make(Op::Sqrt, VType::Float, {f(-4)}), 0);
  expectConst(dag.make(Op::Sqrt, VType::Vec3, {v3(-1, 4, 0)}), VType::Vec3, {0, 2, 0, 0});
}

TEST_F(ValueDagTest, Fold_NormalizeOfZeroIsZero) {
  expectConst(dag.make(Op::Normalize, VType::Vec3, {v3(0, 0, 0)}), VType::Vec3, {0, 0, 0, 0});
  expectScalar(dag.make(Op::Normalize, VType::Float, {f(0)}), 0);
}

TEST_F(ValueDagTest, Fold_PowClampsANegativeBase) {
  expectScalar(dag.make(Op::Pow, VType::Float, {f(-8), f(2)}), 0);
  // x^0 = 1, also for x <= 0.
  expectScalar(dag.make(Op::Pow, VType::Float, {f(-8), f(0)}), 1);
  expectScalar(dag.make(Op::Pow, VType::Float, {f(0), f(0)}), 1);
}

// docs/value-nodes.md, "Guards at a glance": pow with base 0 and y < 0 gives 0,
// and "the compiler folds a node whose pins are all constant with these
// formulas". BUG: evalConstOp computes pow(0, -1) = inf, tryFold refuses the
// non-finite result and the Pow node is kept instead of folding to 0.
TEST_F(ValueDagTest, Fold_PowOfZeroWithNegativeExponentIsZero) {
  expectScalar(dag.make(Op::Pow, VType::Float, {f(0), f(-1)}), 0);
  expectScalar(dag.make(Op::Pow, VType::Float, {f(-2), f(-0.5)}), 0);
}

TEST_F(ValueDagTest, Fold_ExpOverflowsToTheLargestFloat) {
  // As the runtime's substrate_value_exp: finite for every finite input, a
  // float's overflow (x above ~88.72) capped at FLT_MAX.
  expectScalar(dag.make(Op::Exp, VType::Float, {f(0)}), 1);
  expectScalar(dag.make(Op::Exp, VType::Float, {f(-1e30)}), 0);
  expectScalar(dag.make(Op::Exp, VType::Float, {f(89)}), FLT_MAX);
  expectScalar(dag.make(Op::Exp, VType::Float, {f(1e30)}), FLT_MAX);
}

TEST_F(ValueDagTest, Fold_NonFiniteResultIsNotFolded) {
  // 1e300 * 1e300 overflows: the expression is kept for the run-time guard.
  ValueId big = f(1e300);
  ValueId p = dag.make(Op::Multiply, VType::Float, {big, big});
  EXPECT_EQ(op(p), "multiply");
  EXPECT_EQ(dag.node(p).args[0], big);
  EXPECT_EQ(dag.node(p).args[1], big);
}

// ---------------------------------------------------------------------------
// Identities

TEST_F(ValueDagTest, Identity_MultiplyByOne) {
  EXPECT_EQ(dag.make(Op::Multiply, VType::Float, {x(), f(1)}), x());
  EXPECT_EQ(dag.make(Op::Multiply, VType::Float, {f(1), x()}), x());
  EXPECT_EQ(dag.make(Op::Multiply, VType::Vec3, {c3(), dag.splat(VType::Vec3, 1)}), c3());
}

TEST_F(ValueDagTest, Identity_MultiplyByZeroIsZero) {
  expectScalar(dag.make(Op::Multiply, VType::Float, {x(), f(0)}), 0);
  expectConst(dag.make(Op::Multiply, VType::Vec3, {dag.splat(VType::Vec3, 0), c3()}), VType::Vec3, {0, 0, 0, 0});
}

TEST_F(ValueDagTest, Identity_AddZero) {
  EXPECT_EQ(dag.make(Op::Add, VType::Float, {x(), f(0)}), x());
  EXPECT_EQ(dag.make(Op::Add, VType::Float, {f(0), x()}), x());
  EXPECT_EQ(dag.make(Op::Subtract, VType::Float, {x(), f(0)}), x());
}

TEST_F(ValueDagTest, Identity_DivideByOne) {
  EXPECT_EQ(dag.make(Op::Divide, VType::Float, {x(), f(1)}), x());
}

TEST_F(ValueDagTest, Identity_Lerp) {
  ValueId a = x(), b = y(), t = dag.input(7, VType::Float);
  EXPECT_EQ(dag.make(Op::Lerp, VType::Float, {a, b, f(0)}), a);
  EXPECT_EQ(dag.make(Op::Lerp, VType::Float, {a, b, f(1)}), b);
  EXPECT_EQ(dag.make(Op::Lerp, VType::Float, {a, a, t}), a);
}

TEST_F(ValueDagTest, Identity_MinMaxOfTheSameValue) {
  EXPECT_EQ(dag.make(Op::Min, VType::Float, {x(), x()}), x());
  EXPECT_EQ(dag.make(Op::Max, VType::Float, {x(), x()}), x());
}

TEST_F(ValueDagTest, Identity_OneMinusOfOneMinus) {
  ValueId om = dag.make(Op::OneMinus, VType::Float, {x()});
  EXPECT_EQ(op(om), "one_minus");
  EXPECT_EQ(dag.make(Op::OneMinus, VType::Float, {om}), x());
}

TEST_F(ValueDagTest, Identity_SaturateOfSaturate) {
  ValueId s = dag.make(Op::Saturate, VType::Float, {x()});
  EXPECT_EQ(dag.make(Op::Saturate, VType::Float, {s}), s);
}

TEST_F(ValueDagTest, Identity_ClampToUnitIsSaturate) {
  ValueId c = dag.make(Op::Clamp, VType::Float, {x(), f(0), f(1)});
  EXPECT_EQ(op(c), "saturate");
  EXPECT_EQ(dag.node(c).args[0], x());
  EXPECT_EQ(c, dag.make(Op::Saturate, VType::Float, {x()}));
  // Also for a vector with a vector unit range.
  ValueId cv = dag.make(Op::Clamp, VType::Vec3, {c3(), dag.splat(VType::Vec3, 0), dag.splat(VType::Vec3, 1)});
  EXPECT_EQ(cv, dag.make(Op::Saturate, VType::Vec3, {c3()}));
}

TEST_F(ValueDagTest, Identity_IdentitySwizzle) {
  EXPECT_EQ(dag.make(Op::Swizzle, VType::Vec3, {c3()}, channels({0, 1, 2})), c3());
}

TEST_F(ValueDagTest, NoModify_IdentitiesNeedTheExactNeutralValue) {
  ValueId m = dag.make(Op::Multiply, VType::Float, {x(), f(2)});
  EXPECT_EQ(op(m), "multiply");
  ValueId s = dag.make(Op::Subtract, VType::Float, {f(0), x()});  // 0 - x is not x
  EXPECT_EQ(op(s), "subtract");
  ValueId d = dag.make(Op::Divide, VType::Float, {f(1), x()});  // 1 / x is not x
  EXPECT_EQ(op(d), "divide");
  ValueId l = dag.make(Op::Lerp, VType::Float, {x(), y(), f(0.5)});
  EXPECT_EQ(op(l), "lerp");
  ValueId c = dag.make(Op::Clamp, VType::Float, {x(), f(0), f(2)});
  EXPECT_EQ(op(c), "clamp");
  ValueId sw = dag.make(Op::Swizzle, VType::Vec3, {c3()}, channels({2, 1, 0}));
  EXPECT_EQ(op(sw), "swizzle");
  // A vector with one component 1 is not "one".
  ValueId mv = dag.make(Op::Multiply, VType::Vec3, {c3(), v3(1, 1, 0.5)});
  EXPECT_EQ(op(mv), "multiply");
}

TEST_F(ValueDagTest, NoModify_IdentityMustNotChangeTheType) {
  // float x + vec3(0) is a vec3: returning x would change the type.
  ValueId a = dag.make(Op::Add, VType::Vec3, {x(), dag.splat(VType::Vec3, 0)});
  EXPECT_NE(a, x());
  EXPECT_EQ(op(a), "add");
  EXPECT_EQ(type(a), "vec3");
  ValueId m = dag.make(Op::Multiply, VType::Vec3, {x(), dag.splat(VType::Vec3, 1)});
  EXPECT_EQ(op(m), "multiply");
  EXPECT_EQ(type(m), "vec3");
}

// ---------------------------------------------------------------------------
// Non-foldable values stay

TEST_F(ValueDagTest, NoModify_RunTimeLeavesAreNotConstants) {
  EXPECT_EQ(op(x()), "input");
  EXPECT_FALSE(dag.isConst(x()));
  EXPECT_EQ(op(dag.geometry(GeometryAttr::Normal)), "geometry");
  EXPECT_EQ(type(dag.geometry(GeometryAttr::Uv0)), "vec2");
  EXPECT_EQ(type(dag.geometry(GeometryAttr::VertexColor)), "vec4");
  // A texture sample at a constant uv is still a run-time value.
  ValueId s = dag.sample(0, v2(0.5, 0.5));
  EXPECT_EQ(op(s), "texture");
  EXPECT_EQ(type(s), "vec4");
  ValueId r = dag.make(Op::Swizzle, VType::Float, {s}, channels({0}));
  EXPECT_EQ(op(r), "swizzle");
}

TEST_F(ValueDagTest, NoModify_OpsOnRunTimeValuesStay) {
  ValueId n = dag.geometry(GeometryAttr::Normal);
  ValueId a = dag.make(Op::Add, VType::Vec3, {n, dag.splat(VType::Vec3, 1)});
  EXPECT_EQ(op(a), "add");
  ValueId m = dag.make(Op::Multiply, VType::Float, {x(), f(0.5)});
  EXPECT_EQ(op(m), "multiply");
  EXPECT_EQ(dag.node(m).argCount, 2);
}

TEST_F(ValueDagTest, NoModify_ViewDependentHelpersAreNeverFolded) {
  // thin_film and view_dependent_coverage depend on the camera.
  ValueId args[] = {v3(0, 0, 1), dag.splat(VType::Vec3, 0.04), dag.splat(VType::Vec3, 1), f(3e-7), f(1.5)};
  for (std::uint16_t out : {0, 1}) {
    ValueId t = dag.makeN(Op::ThinFilm, VType::Vec3, args, 5, out);
    EXPECT_EQ(op(t), "thin_film") << "output " << out;
    EXPECT_EQ(dag.node(t).attr, out);
  }
  ValueId c = dag.make(Op::ViewDependentCoverage, VType::Float, {f(0.5), v3(0, 0, 1)});
  EXPECT_EQ(op(c), "view_dependent_coverage");
}

TEST_F(ValueDagTest, IsConstEqualNeedsEveryComponent) {
  EXPECT_TRUE(dag.isConstEqual(dag.splat(VType::Vec3, 1), 1));
  EXPECT_FALSE(dag.isConstEqual(v3(1, 1, 0.5), 1));
  EXPECT_TRUE(dag.isConstEqual(f(0), 0));
  EXPECT_FALSE(dag.isConstEqual(x(), 0));
}

// ---------------------------------------------------------------------------
// Topological order

TEST_F(ValueDagTest, IdsAreTopological_ArgumentsHaveSmallerIds) {
  // A mix of leaves, folds, identities and hash hits.
  ValueId n = dag.geometry(GeometryAttr::Normal);
  ValueId tex = dag.sample(1, dag.make(Op::Multiply, VType::Vec2, {dag.geometry(GeometryAttr::Uv0), f(8)}));
  ValueId rgb = dag.make(Op::Swizzle, VType::Vec3, {tex}, channels({0, 1, 2}));
  ValueId nm = dag.make(Op::Normalize, VType::Vec3,
                        {dag.make(Op::Subtract, VType::Vec3, {dag.make(Op::Multiply, VType::Vec3, {rgb, f(2)}), f(1)})});
  ValueId k = dag.make(Op::Add, VType::Float, {f(1), f(2)});  // folded after its arguments exist
  ValueId w = dag.make(Op::Lerp, VType::Float, {x(), dag.make(Op::OneMinus, VType::Float, {x()}), k});
  dag.make(Op::Dot, VType::Float, {nm, n});
  dag.make(Op::Dot, VType::Float, {n, nm});
  dag.make(Op::Clamp, VType::Float, {w, f(0), f(1)});
  ASSERT_GT(dag.size(), 15u);
  for (ValueId id = 0; id < dag.size(); ++id) {
    const ValueNode& node = dag.node(id);
    if (node.op == Op::Const) EXPECT_EQ(node.argCount, 0) << id;
    for (int i = 0; i < node.argCount; ++i) EXPECT_LT(node.args[i], id) << "node " << id << " arg " << i;
  }
}

}  // namespace
}  // namespace substratec
