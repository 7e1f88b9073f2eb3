// The eye BSDF (docs/format.md, "The eye BSDF"; docs/storage.md, "Eye";
// runtime_shaders/substrate_eye.h): its pins, that it is the whole material,
// what it stores, and what its iris does to a slab's lighting (the CPU
// mirror; the GPU suites hold the shaders to it).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"
#include "reference/bsdf.h"
#include "reference/reference.h"
#include "storage/pack.h"
#include "test_util.h"

namespace substratec {
namespace eye_test {

using test::diagnosticsOf;
using test::material;
using V3 = reference::V3<double>;

// ---------------------------------------------------------------------------
// The node

TEST(Eye, TakesItsPinsAndNoOther) {
  EXPECT_EQ(diagnosticsOf(material(R"("root": {"kind": "eye", "diffuse_albedo": [0.8, 0.7, 0.6], "roughness": 0.1,
      "normal": [0, 0, 1], "iris_normal": [0, 0.2, 0.98], "iris_plane_normal": [0, -0.1, 0.99], "iris_mask": 1,
      "iris_distance": 0.4, "emissive": 0})")),
            "");
  const std::string d = diagnosticsOf(material(R"("root": {"kind": "eye", "anisotropy": 0.5})"));
  EXPECT_NE(d.find("unknown pin \"anisotropy\" for an eye node (pins: diffuse_albedo, roughness, normal, sss_mfp, "
                   "sss_mfp_scale, sss_phase_anisotropy, emissive, iris_normal, iris_plane_normal, iris_mask, "
                   "iris_distance) [/nodes/root/anisotropy]"),
            std::string::npos)
      << d;
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "eye", "iris_mask": 2})")).find("/nodes/root/iris_mask"),
            std::string::npos);
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "eye", "iris_distance": -1})")).find("/nodes/root/iris_distance"),
            std::string::npos);
  // A slab takes none of the eye's own pins.
  EXPECT_NE(diagnosticsOf(material(R"("root": {"kind": "slab", "iris_mask": 0.5})")).find("unknown slab pin \"iris_mask\""),
            std::string::npos);
}

TEST(Eye, IsTheWholeMaterialNeverAnOperand) {
  for (const char* op : {R"("root": {"kind": "horizontal", "background": "s", "foreground": "e", "mix": 0.5})",
                         R"("root": {"kind": "coverage_weight", "a": "e", "weight": 0.5})",
                         R"("root": {"kind": "add", "a": "e", "b": "s"})",
                         R"("root": {"kind": "vertical", "top": "s", "base": "e"})"}) {
    Diagnostics d("test.json");
    const std::string json = material(std::string(R"("e": {"kind": "eye"}, "s": {"kind": "slab"}, )") + op);
    EXPECT_FALSE(compileText("test.json", json, {}, d).has_value()) << op;
    const std::string all = d.formatAll();
    EXPECT_NE(all.find("eye 'e' is an operand of"), std::string::npos) << all;
    EXPECT_NE(all.find("an eye BSDF must be the whole material"), std::string::npos) << all;
    EXPECT_NE(all.find("[/nodes/e]"), std::string::npos) << all;
  }
}

// ---------------------------------------------------------------------------
// What it stores (docs/storage.md, "Eye")

TEST(Eye, StoresColourTheIrisAndRoughnessIn20Bytes) {
  const CompileResult r = test::compiled(material(R"("root": {"kind": "eye", "iris_mask": 0.5})"));
  const StorageLayout& L = r.after;
  EXPECT_EQ(L.layoutClass, LayoutClass::Special);
  ASSERT_EQ(L.closures.size(), 1u);
  std::string names;
  for (const auto& f : L.fields) names += f.name + ":" + std::to_string(f.bits) + " ";
  EXPECT_EQ(names, "header:16 closure0.diffuse_albedo:20 closure0.iris_normal:32 closure0.iris:32 closure0.roughness:8 ");
  EXPECT_EQ(L.bytes(), 20);  // 108 bits in 4 words, and the top-layer word (the cornea's normal)
  EXPECT_EQ(r.material.slabs[r.material.nodes[r.material.root].slab].features, kFeatEye);
  // An iris mask from an input may be 0 at run time: still an eye.
  EXPECT_EQ(test::compiled(test::material(R"("root": {"kind": "eye", "iris_mask": "$m"})",
                                       R"({"m": {"type": "float", "default": 0}})"))
                .after.bytes(),
            20);
}

TEST(Eye, WithAConstantIrisMaskOf0ItIsTheSlabItsCorneaAndScleraAre) {
  // No iris: culled (it is lit as that slab bit for bit, AtIrisMask0...), and it
  // stores what that slab stores: SIMPLE, 12 bytes, no iris fields.
  const CompileResult r =
      test::compiled(material(R"("root": {"kind": "eye", "diffuse_albedo": [0.8, 0.76, 0.72], "roughness": 0.08,
                                       "iris_normal": [0, 0.3, 0.95], "iris_distance": 0.5})"));
  const Slab& s = r.material.slabs[r.material.nodes[r.material.root].slab];
  EXPECT_EQ(s.kind, BsdfKind::Slab);
  EXPECT_EQ(s.features, 0);
  EXPECT_TRUE(r.material.values.isConstEqual(s.pin(SlabPin::F0), 0.04));
  EXPECT_EQ(r.after.layoutClass, LayoutClass::Simple);
  EXPECT_EQ(r.after.bytes(), 12);
  ASSERT_EQ(r.material.culled.size(), 1u);
  EXPECT_EQ(r.material.culled[0].what, "root (iris)");
  EXPECT_NE(r.material.culled[0].why.find("iris_mask is the constant 0"), std::string::npos);
}

// UE's eye takes a subsurface profile for its sclera: here its mean free
// path, as a slab's (docs/format.md). It scatters under a scattering albedo
// (an eye is always the bottom), stores the slab's SSS field after the iris
// (+28 bits: 24 bytes) and its SSS type in the header; it pays nothing
// without it.
TEST(Eye, ItsScleraScattersUnderTheSurfaceByItsMeanFreePath) {
  const CompileResult r = test::compiled(material(R"("root": {"kind": "eye", "iris_mask": 0.5,
      "sss_mfp": [0.008, 0.004, 0.002], "sss_phase_anisotropy": 0.5})"));
  const Slab& s = r.material.slabs[r.material.nodes[r.material.root].slab];
  EXPECT_EQ(s.features, kFeatEye | kFeatSss);
  EXPECT_EQ(s.sssType, SssType::Diffusion);
  std::string names;
  for (const auto& f : r.after.fields) names += f.name + ":" + std::to_string(f.bits) + " ";
  EXPECT_EQ(names,
            "header:16 closure0.diffuse_albedo:20 closure0.iris_normal:32 closure0.iris:32 closure0.roughness:8 "
            "closure0.sss:28 ");
  EXPECT_EQ(r.after.bytes(), 24);
  ClosureValues v;
  v.diffuseAlbedo = {0.8, 0.76, 0.72};
  v.roughness = 0.08;
  v.irisN = {0.0, 0.6, 0.8};
  v.iris = {0.5, 0.3};
  v.sssMfp = {0.008, 0.004, 0.002};
  v.sssPhaseAnisotropy = 0.5;
  v.sssType = static_cast<std::uint32_t>(SssType::Diffusion);
  BasisValues b;
  b.normal = {0, 0, 1};
  const auto words = packMaterial(r.after, {v}, {b}, 0.5);
  EXPECT_EQ((words[0] >> 10) & 3u, static_cast<std::uint32_t>(SssType::Diffusion));
  EXPECT_NE(words[0] & packfmt::kEyeHeaderBit, 0u);
  const UnpackedMaterial u = unpackMaterial(words.data(), words.size(), packTopLayer({b.normal, 0.08}, 0.5));
  ASSERT_EQ(u.closures.size(), 1u);
  const ClosureValues& g = u.closures[0];
  EXPECT_EQ(g.sssType, static_cast<std::uint32_t>(SssType::Diffusion));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(g.sssMfp[k] / v.sssMfp[k], 1.0, 0.091);  // docs/storage.md: 9.1 %
  EXPECT_NEAR(g.iris[0], 0.5, 0.5 / 255 + 1e-9);  // the iris before it, unmoved
  EXPECT_NEAR(g.roughness, 0.08, 0.5 / 255 + 1e-9);
  // Under a budget of 20 bytes simplification turns the sclera's SSS off.
  CompileOptions o;
  o.budgetOverride = 20;
  Diagnostics d("test.json");
  const auto small = compileText("test.json", material(R"("root": {"kind": "eye", "iris_mask": 0.5,
      "sss_mfp": [0.008, 0.004, 0.002]})"), o, d);
  ASSERT_TRUE(small.has_value()) << d.formatAll();
  EXPECT_EQ(small->after.bytes(), 20);
  EXPECT_EQ(small->material.slabs[small->material.nodes[small->material.root].slab].features, kFeatEye);
  // No mean free path, or nothing to scatter: no SSS, 20 bytes.
  for (const char* pins : {R"("iris_mask": 0.5)", R"("iris_mask": 0.5, "sss_mfp": 0.01, "diffuse_albedo": 0)",
                           R"("iris_mask": 0.5, "sss_mfp": 0.01, "sss_mfp_scale": 0)"}) {
    const CompileResult plain = test::compiled(material(std::string(R"("root": {"kind": "eye", )") + pins + "}"));
    EXPECT_EQ(plain.after.bytes(), 20) << pins;
    EXPECT_EQ(plain.material.slabs[plain.material.nodes[plain.material.root].slab].sssType, SssType::None) << pins;
  }
}

TEST(Eye, HeaderBit13AndTheIrisFieldsRoundTrip) {
  const CompileResult r = test::compiled(material(R"("root": {"kind": "eye", "iris_mask": 0.5})"));
  ClosureValues v;
  v.diffuseAlbedo = {0.3, 0.2, 0.07};
  v.roughness = 0.08;
  v.irisN = {0.0, 0.6, 0.8};
  v.irisPlaneN = {-0.28, 0.0, 0.96};
  v.iris = {0.75, 0.3};
  BasisValues b;
  b.normal = {0, 0, 1};
  const auto words = packMaterial(r.after, {v}, {b}, 0.5);
  EXPECT_EQ(words[0] & 0xffffu, 3u | packfmt::kEyeHeaderBit);  // SPECIAL, no header feature bit, eye
  const UnpackedMaterial u = unpackMaterial(words.data(), words.size(), packTopLayer({b.normal, 0.08}, 0.5));
  ASSERT_EQ(u.closures.size(), 1u);
  const ClosureValues& g = u.closures[0];
  EXPECT_EQ(g.features, static_cast<std::uint32_t>(kClosureEye));
  EXPECT_EQ(g.f0, ClosureValues{}.f0);  // 0.04: not stored
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(g.irisN[k], v.irisN[k], 1e-4);            // octahedral 2 x snorm16
    EXPECT_NEAR(g.irisPlaneN[k], v.irisPlaneN[k], 0.02);  // octahedral 2 x unorm8
  }
  EXPECT_NEAR(g.iris[0], 0.75, 0.5 / 255 + 1e-9);
  EXPECT_NEAR(g.iris[1], 0.3, 0.5 / 255 + 1e-9);
}

// ---------------------------------------------------------------------------
// The iris's lighting (the CPU mirror of substrate_eye.h)

reference::Closure<double> eye(double mask, double distance, const V3& irisN, const V3& planeN) {
  reference::Closure<double> c;
  c.features = reference::kFeatureEye;
  c.diffuseAlbedo = {1, 1, 1};
  c.roughness = 0.3;
  c.irisN = irisN;
  c.irisPlaneN = planeN;
  c.iris = {mask, distance};
  return c;
}

constexpr int kLambert = reference::kDiffuseLambert;

/// The integral over the hemisphere of light directions (midpoint rule in
/// cos theta and phi) of f(L).
template <class F>
double hemisphereIntegral(F f, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 4 * n; ++j) {
      const double mu = (i + 0.5) / n, phi = 2 * M_PI * (j + 0.5) / (4 * n), s = std::sqrt(1 - mu * mu);
      sum += f(V3{s * std::cos(phi), s * std::sin(phi), mu}) * (1.0 / n) * (2 * M_PI / (4 * n));
    }
  return sum;
}

/// The closure's response integrated over the light directions: its albedo seen from V (green).
double albedo(const reference::Closure<double>& c, const V3& V, int n) {
  return hemisphereIntegral([&](const V3& L) { return reference::evalClosure<double>(c, V, L, kLambert)[1]; }, n);
}

/// The iris's cosine integrated over the light directions, over pi (a Lambertian's is 1).
double irisMean(const reference::Closure<double>& c, int n) {
  return hemisphereIntegral([&](const V3& L) { return reference::eyeIrisCosine<double>(c, c.N, L); }, n) / M_PI;
}

TEST(Eye, AtIrisMask0ItIsTheSlabItsPinsDescribe) {
  // The sclera: the cornea's interface (F0 0.04, F90 1) over the slab's diffuse, bit for bit.
  // With a scattering sclera too: the slab's medium (the same SSS pins).
  int cases = 0;
  for (bool sss : {false, true}) {
    reference::Closure<double> e = eye(0, 0.7, {0.3, 0, 0.954}, {-0.2, 0.1, 0.97});
    if (sss) {
      e.sssType = static_cast<std::uint32_t>(SssType::Diffusion);
      e.sssMfp = {0.008, 0.004, 0.002};
    }
    reference::Closure<double> s = e;
    s.features = 0;
    for (double mv : {1.0, 0.5, 0.1})
      for (double ml : {1.0, 0.6, 0.2, 0.02}) {
        const V3 V{std::sqrt(1 - mv * mv), 0, mv}, L{-std::sqrt(1 - ml * ml) * 0.6, std::sqrt(1 - ml * ml) * 0.8, ml};
        for (int model : {reference::kDiffuseLambert, reference::kDiffuseChan2024}) {
          EXPECT_EQ(reference::evalClosure<double>(e, V, L, model), reference::evalClosure<double>(s, V, L, model));
          ++cases;
        }
      }
  }
  EXPECT_EQ(cases, 48);
}

TEST(Eye, TheIrisCausticIsNormalizedToALambertiansLight) {
  // A white iris with its caustic on its normal (distance 0) takes in over the
  // hemisphere what a Lambertian does: UE's caustic takes in 1.0412 times as
  // much, SUBSTRATE_EYE_CAUSTIC_MEAN divides it out.
  const V3 up{0, 0, 1};
  EXPECT_NEAR(irisMean(eye(1, 0, up, up), 512), 1.0, 1e-4);
  EXPECT_GT(SUBSTRATE_EYE_CAUSTIC_MEAN, 1.04);
  // Through the cornea the two differ by the coupling's weight on the light's
  // angle (the caustic's light comes from nearer the normal): within 1 %.
  const V3 V{0, 0, 1};
  const double sclera = albedo(eye(0, 0, up, up), V, 256), iris = albedo(eye(1, 0, up, up), V, 256);
  EXPECT_NEAR(iris / sclera, 1.0, 0.01) << iris << " vs " << sclera;
}

TEST(Eye, TheIrisDistancePullsTheCausticInward) {
  // A tilted iris plane: the deeper the iris, the further the caustic's axis
  // turns toward -N, away from the light, and the less the iris takes in.
  const V3 up{0, 0, 1}, plane{0.5, 0, 0.866};
  double last = 1e9;
  int cases = 0;
  for (double d : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const double a = irisMean(eye(1, d, up, plane), 128);
    EXPECT_LT(a, last) << "distance " << d;
    last = a;
    ++cases;
  }
  EXPECT_EQ(cases, 5);
  // At depth 1 the axis is -N: no caustic, the iris keeps its constant 0.8 / 1.0412 of a Lambertian.
  EXPECT_NEAR(last, 0.8 / SUBSTRATE_EYE_CAUSTIC_MEAN, 1e-4);
}

TEST(Eye, TheIrisIsLitAlongItsOwnNormal) {
  // The diffuse (the response less the cornea's, an albedo-0 eye's) of an iris
  // leaning 53 degrees toward +x: dark where its normal is perpendicular to the
  // light although the cornea faces it, brightest along its normal, while the
  // sclera follows the cornea's cosine.
  const V3 V{0, 0, 1}, iris{0.8, 0, 0.6}, edgeOn{-0.6, 0, 0.8};
  auto diffuse = [&](double mask, const V3& L) {
    reference::Closure<double> c = eye(mask, 0, iris, iris), dark = c;
    dark.diffuseAlbedo = {0, 0, 0};
    return reference::evalClosure<double>(c, V, L, kLambert)[1] - reference::evalClosure<double>(dark, V, L, kLambert)[1];
  };
  EXPECT_NEAR(diffuse(1, edgeOn), 0.0, 1e-12);
  EXPECT_GT(diffuse(0, edgeOn), 0.1);
  // Along its normal: 1.2 / 1.0412 (the caustic at p = 1) against the cornea cosine 0.6.
  EXPECT_NEAR(diffuse(1, iris) / diffuse(0, iris), 1.2 / SUBSTRATE_EYE_CAUSTIC_MEAN / 0.6, 1e-9);
  EXPECT_NEAR(diffuse(0.5, iris), 0.5 * (diffuse(0, iris) + diffuse(1, iris)), 1e-12);  // the mask lerps
}

TEST(Eye, LightReachesTheIrisOnlyThroughTheCornea) {
  // The iris normal faces a light below the cornea's horizon: nothing.
  const reference::Closure<double> c = eye(1, 0, {0.8, 0, 0.6}, {0.8, 0, 0.6});
  const V3 V{0, 0, 1}, below{0.995, 0, -0.0998};
  EXPECT_EQ(reference::evalClosure<double>(c, V, below, kLambert), (V3{0, 0, 0}));
  // The same light just above the horizon lights it.
  EXPECT_GT(reference::evalClosure<double>(c, V, {0.995, 0, 0.0998}, kLambert)[1], 0.0);
}

TEST(Eye, NeverReturnsNonFiniteValuesOnDegenerateNormals) {
  // Zero-length, opposite and equal normals: the caustic's axis falls back to the iris plane's.
  int cases = 0;
  for (const V3& n : {V3{0, 0, 0}, V3{0, 0, -1}, V3{0, 0, 1}})
    for (double d : {0.0, 0.5, 1.0}) {
      const reference::Closure<double> c = eye(1, d, n, n);
      for (double ml : {1.0, 0.3, 1e-6}) {
        const V3 L{std::sqrt(1 - ml * ml), 0, ml};
        const V3 f = reference::evalClosure<double>(c, {0, 0, 1}, L, kLambert);
        for (double x : f) EXPECT_TRUE(std::isfinite(x));
        ++cases;
      }
    }
  EXPECT_EQ(cases, 27);
}

}  // namespace eye_test
}  // namespace substratec
