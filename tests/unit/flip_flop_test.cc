// The flip_flop helper (docs/value-nodes.md, "flip_flop"; issue 23): a value
// that turns from `facing` to `grazing` as the view leaves the normal,
//   lerp(facing, grazing, (1 − saturate(N·V))^max(falloff, 0)),
// lowered by buildValueDag to the primitives it is made of. Checked through
// the whole compiler and the CPU reference's evaluation of the closure it
// feeds (the GPU suites hold the shaders to that reference).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"
#include "test_util.h"

namespace substratec {
namespace flip_flop_test {

using test::diagnosticsOf;
using test::material;

/// The diffuse albedo of the one closure of `r` seen along the tangent-space view `V` (normal +Z).
std::array<double, 3> albedoSeenFrom(const CompileResult& r, const std::array<double, 3>& V) {
  reference::Geometry g;
  g.V = V;
  const auto m = reference::evaluateMaterial<double>(r, g, {}, {});
  EXPECT_EQ(m.closures.size(), 1u);
  return m.closures.empty() ? std::array<double, 3>{} : m.closures[0].diffuseAlbedo;
}

TEST(FlipFlop, TurnsFromFacingToGrazingByTheFalloffPowerOfOneMinusNoV) {
  const CompileResult r = test::compiled(material(R"("root": {"kind": "slab", "diffuse_albedo": {"kind": "flip_flop",
      "facing": [0.8, 0.1, 0.1], "grazing": [0.1, 0.2, 0.9], "falloff": 2}})"));
  int cases = 0;
  for (double nov : {1.0, 0.8, 0.5, 0.2, 0.05}) {
    const double t = std::pow(1 - nov, 2);
    const auto a = albedoSeenFrom(r, {std::sqrt(1 - nov * nov), 0, nov});
    const double want[3] = {0.8 + (0.1 - 0.8) * t, 0.1 + (0.2 - 0.1) * t, 0.1 + (0.9 - 0.1) * t};
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], want[c], 1e-12) << "NoV " << nov << " channel " << c;
    ++cases;
  }
  EXPECT_EQ(cases, 5);
  // Seen from below the surface the view is as grazing as it gets.
  const auto below = albedoSeenFrom(r, {0.6, 0, -0.8});
  EXPECT_NEAR(below[2], 0.9, 1e-12);
}

TEST(FlipFlop, TakesItsOwnNormalAndBroadcastsAFloat) {
  // The normal tilted toward the view: head-on for it, so the facing value.
  const CompileResult r = test::compiled(material(R"("root": {"kind": "slab", "diffuse_albedo": {"kind": "flip_flop",
      "facing": 0.25, "grazing": [1, 0.5, 0], "normal": [0.6, 0, 0.8]}})"));
  const auto a = albedoSeenFrom(r, {0.6, 0, 0.8});
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], 0.25, 1e-12);
  // Its defaults: facing 0, grazing 1, falloff 1, the geometric normal: t = 1 − NoV.
  const CompileResult d = test::compiled(material(R"("root": {"kind": "slab", "roughness": {"kind": "flip_flop"},
      "diffuse_albedo": 0.5})"));
  reference::Geometry g;
  g.V = {0.6, 0, 0.8};
  EXPECT_NEAR(reference::evaluateMaterial<double>(d, g, {}, {}).closures.at(0).roughness, 0.2, 1e-12);
}

TEST(FlipFlop, AFalloffOf0IsGrazingEverywhereAndANegativeOneIsGuarded) {
  for (const char* falloff : {"0", "-3"}) {
    const CompileResult r = test::compiled(material(std::string(R"("root": {"kind": "slab", "diffuse_albedo": {"kind":
        "flip_flop", "facing": 0.2, "grazing": 0.7, "falloff": )") + falloff + "}}"));
    const auto a = albedoSeenFrom(r, {0, 0, 1});
    EXPECT_NEAR(a[0], 0.7, 1e-12) << falloff;
    EXPECT_TRUE(std::isfinite(a[0]));
  }
}

TEST(FlipFlop, BadPinsAreLocatedErrors) {
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "diffuse_albedo": {"kind": "flip_flop",
      "facing": [1, 0, 0], "grazing": [0, 1]}})"))
                .find("cannot combine vec3 \"facing\" with vec2 \"grazing\""),
            std::string::npos);
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "diffuse_albedo": {"kind": "flip_flop",
      "falloff": [1, 2, 3]}})"))
                .find("/nodes/root/diffuse_albedo/falloff"),
            std::string::npos);
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "diffuse_albedo": {"kind": "flip_flop",
      "colour": 1}})"))
                .find("/nodes/root/diffuse_albedo"),
            std::string::npos);
}

}  // namespace flip_flop_test
}  // namespace substratec
