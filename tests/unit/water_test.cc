// The single-layer water (docs/format.md, "The single-layer water";
// runtime_shaders/substrate_water.h): its pins, that it is the whole material,
// that its surface is the slab its top material and interface mix to (what it
// stores), and what its body returns (the CPU mirror; the GPU suites hold the
// shaders to it).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "diag/diagnostics.h"
#include "emit/kernel_emitter.h"
#include "emit/syntax.h"
#include "pipeline/pipeline.h"
#include "reference/reference.h"
#include "test_util.h"

namespace substratec {
namespace water_test {

using test::diagnosticsOf;
using test::material;
using V3 = reference::V3<double>;

TEST(Water, TakesItsPinsAndNoOther) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "single_layer_water", "base_color": 0.9, "metallic": 0,
      "specular": 0.25, "roughness": 0.05, "normal": [0, 0, 1], "emissive": 0, "top_material_opacity": 0.2,
      "water_albedo": [0.1, 0.5, 0.4], "water_extinction": [4, 1, 0.5], "water_phase_g": 0.3,
      "color_scale_behind_water": [1, 1, 1]})")),
            "");
  const std::string d = diagnosticsOf(material(R"("root": {"kind": "single_layer_water", "f0": 0.02})"));
  EXPECT_NE(d.find("unknown pin \"f0\" for a single_layer_water node (pins: roughness, normal, emissive, base_color, "
                   "metallic, specular, top_material_opacity, water_albedo, water_extinction, water_phase_g, "
                   "color_scale_behind_water) [/nodes/root/f0]"),
            std::string::npos)
      << d;
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "single_layer_water", "water_phase_g": 2})"))
                .find("/nodes/root/water_phase_g"),
            std::string::npos);
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "single_layer_water", "water_extinction": -1})"))
                .find("/nodes/root/water_extinction"),
            std::string::npos);
}

TEST(Water, IsTheWholeMaterialNeverAnOperand) {
  for (const char* op : {R"("root": {"kind": "horizontal", "background": "s", "foreground": "w", "mix": 0.5})",
                         R"("root": {"kind": "vertical", "top": "s", "base": "w"})"}) {
    Diagnostics d("test.json");
    const std::string json = material(std::string(R"("w": {"kind": "single_layer_water"}, "s": {"kind": "slab"}, )") + op);
    EXPECT_FALSE(compileText("test.json", json, {}, d).has_value()) << op;
    const std::string all = d.formatAll();
    EXPECT_NE(all.find("single_layer_water 'w' is an operand of"), std::string::npos) << all;
    EXPECT_NE(all.find("a single-layer water must be the whole material"), std::string::npos) << all;
  }
}

TEST(Water, ItsSurfaceIsTheSlabItsTopMaterialAndInterfaceMixTo) {
  // t = 0.4 of the surface is a half-metallic top of base colour b; the rest
  // the water's interface, F0 0.08 x 0.25 = 0.02: diffuse b t (1 - m),
  // F0 0.02 + t m (b - 0.02).
  const CompileResult r = test::compiled(material(R"("root": {"kind": "single_layer_water",
      "base_color": [0.8, 0.6, 0.2], "metallic": 0.5, "specular": 0.25, "top_material_opacity": 0.4,
      "roughness": 0.1})"));
  const auto m = reference::evaluateMaterial<double>(r, {}, {}, {});
  ASSERT_EQ(m.closures.size(), 1u);
  const V3 b{0.8, 0.6, 0.2};
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(m.closures[0].diffuseAlbedo[k], b[k] * 0.4 * 0.5, 1e-12);
    EXPECT_NEAR(m.closures[0].f0[k], 0.02 + 0.4 * 0.5 * (b[k] - 0.02), 1e-12);
  }
  EXPECT_EQ(m.closures[0].features, 0u);  // lit as a slab
  ASSERT_TRUE(m.water.has_value());
  EXPECT_NEAR(m.water->opacity, 0.4, 1e-12);
  EXPECT_NEAR(m.water->f0, 0.02, 1e-12);
  // It stores what that slab stores: nothing of its body.
  EXPECT_EQ(r.after.layoutClass, LayoutClass::Simple);
  EXPECT_EQ(r.after.bytes(), 12);
  EXPECT_EQ(r.material.slabs[r.material.nodes[r.material.root].slab].features, kFeatWater);
}

// `sweep` times what a water costs: its cost kernel runs the body as well as
// the surface (a forward pass does both).
TEST(Water, ItsCostKernelRunsItsBody) {
  const CompileResult r = test::compiled(material(R"("root": {"kind": "single_layer_water"})"));
  const CompileResult slab = test::compiled(material(R"("root": {"kind": "slab"})"));
  for (Target t : {Target::Glsl, Target::Hlsl}) {
    EXPECT_NE(emitKernel(r.material, r.after, syntaxFor(t), KernelMode::Throughput, {}).find("substrate_water_seen("),
              std::string::npos);
    EXPECT_EQ(emitKernel(slab.material, slab.after, syntaxFor(t), KernelMode::Throughput, {})
                  .find("substrate_water_seen("),
              std::string::npos);
  }
}

reference::Water<double> water(const V3& albedo, const V3& extinction, double g = 0) {
  reference::Water<double> w;
  w.albedo = albedo;
  w.extinction = extinction;
  w.phaseG = g;
  return w;
}

TEST(Water, ItsBodyIsTheBackgroundThroughTheWaterAndTheLightItScatters) {
  const V3 bg{0.5, 0.25, 1.0}, light{2, 2, 2};
  // Clear water: the background scaled, whatever the distance.
  reference::Water<double> clear = water({0.3, 0.3, 0.3}, {0, 0, 0});
  clear.scaleBehind = {1, 2, 0.5};
  const V3 a = reference::waterBody<double>(clear, bg, 7.0, 0.3, light);
  EXPECT_NEAR(a[0], 0.5, 1e-12);
  EXPECT_NEAR(a[1], 0.5, 1e-12);
  EXPECT_NEAR(a[2], 0.5, 1e-12);
  // 1 m of extinction (4, 1, 0.45): exp(-x) of the background, plus albedo (1 - T) light / (4 pi) (isotropic).
  const reference::Water<double> lake = water({0.1, 0.5, 0.4}, {4, 1, 0.45});
  const V3 e = reference::waterBody<double>(lake, bg, 1.0, 0.0, light);
  const double ext[3] = {4, 1, 0.45}, alb[3] = {0.1, 0.5, 0.4};
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(e[k], bg[k] * std::exp(-ext[k]) + alb[k] * (1 - std::exp(-ext[k])) * 2 / (4 * M_PI), 1e-12);
  // Deep water: the background is gone, the scattered light saturates.
  const V3 deep = reference::waterBody<double>(lake, bg, 1e30, 0.0, light);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(deep[k], alb[k] * 2 / (4 * M_PI), 1e-12);
  // Forward scattering (g 0.6) is brighter looking into the light (cos 1) than away from it.
  const reference::Water<double> forward = water({0.5, 0.5, 0.5}, {1, 1, 1}, 0.6);
  EXPECT_GT(reference::waterBody<double>(forward, {0, 0, 0}, 1.0, 1.0, light)[0],
            10 * reference::waterBody<double>(forward, {0, 0, 0}, 1.0, -1.0, light)[0]);
}

TEST(Water, TheSurfaceLetsThroughWhatItDoesNotReflectOfTheUncoveredWater) {
  // Opacity 1: no water shows. From below the surface: not this model's, 0.
  // Head-on through a smooth interface of F0 0.02: about 98 % of the body.
  const CompileResult r = test::compiled(material(R"("root": {"kind": "single_layer_water", "specular": 0.25,
      "roughness": 0.0, "water_extinction": 0})"));
  const auto m = reference::evaluateMaterial<double>(r, {}, {}, {});
  ASSERT_TRUE(m.water.has_value());
  const reference::V4<double> behind{1, 1, 1, 3};
  const V3 up{0, 0, 1}, L{0, 0, 1}, none{0, 0, 0};
  const V3 seen = reference::waterSeen<double>(m.closures[0], *m.water, behind, 1.0, up, L, none);
  EXPECT_GT(seen[0], 0.97);
  EXPECT_LT(seen[0], 0.99);
  EXPECT_EQ(reference::waterSeen<double>(m.closures[0], *m.water, behind, 1.0, V3{0, 0, -1}, L, none), none);
  reference::Water<double> foam = *m.water;
  foam.opacity = 1;
  EXPECT_EQ(reference::waterSeen<double>(m.closures[0], foam, behind, 1.0, up, L, none), none);
}

TEST(Water, NeverReturnsNonFiniteValuesOnHardInputs) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  int cases = 0;
  for (double ext : {0.0, 1e-9, 1e6, inf, nan})
    for (double dist : {0.0, -1.0, 1e30, inf, nan})
      for (double bgv : {0.0, 1e30, inf, nan}) {
        const V3 b = reference::waterBody<double>(water({1, 1, 1}, {ext, ext, ext}, 0.99), {bgv, bgv, bgv}, dist,
                                                  1.0, {1e30, 1, 0});
        for (double x : b) EXPECT_TRUE(std::isfinite(x)) << ext << " " << dist << " " << bgv;
        ++cases;
      }
  EXPECT_EQ(cases, 100);
}

}  // namespace water_test
}  // namespace substratec
