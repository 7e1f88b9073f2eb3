// The ground truth of a compiled material (reference/ground_truth.h): the tree
// as a weighted sum of stacks, each walked by layeredEval.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"
#include "reference/common.h"
#include "reference/ground_truth.h"
#include "test_util.h"
#include "../examples.h"

namespace substratec {
namespace ground_truth_test {

using namespace reference;
using D3 = V3<double>;

D3 dir(double mu, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  return {s * std::cos(phi), s * std::sin(phi), mu};
}

WalkOptions opts(int samples, std::uint32_t seed = 1, int maxDepth = 64) {
  WalkOptions o;
  o.samples = samples;
  o.seed = seed;
  o.maxDepth = maxDepth;
  return o;
}

CompileResult compileUnsimplified(const std::string& name, const std::string& text) {
  Diagnostics d(name);
  CompileOptions o;
  o.budgetOverride = 1 << 20;
  o.maxClosuresOverride = 64;
  auto r = compileText(name, text, o, d);
  EXPECT_TRUE(r) << d.formatAll();
  if (!r) return CompileResult{};
  EXPECT_TRUE(r->steps.empty()) << name << " was simplified";
  return std::move(*r);
}

TEST(RandomWalkGroundTruth, TheTreeIsAWeightedSumOfStacks) {
  // A coat of coverage 0.25 over a 70/30 mix of an opaque slab a and an SSS slab b:
  //   coat/a 0.25 * 0.7, coat/b 0.25 * 0.3, a 0.75 * 0.7, b 0.75 * 0.3.
  const std::string nodes = R"(
    "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.1, "sss_mfp": 2, "sss_mfp_scale": 0.5},
    "a": {"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.4},
    "b": {"kind": "slab", "diffuse_albedo": [0.2, 0.3, 0.4], "f0": 0.04, "roughness": 0.6, "sss_mfp": [0.01, 0.02, 0.03]},
    "mix": {"kind": "horizontal", "background": "a", "foreground": "b", "mix": 0.3},
    "wc": {"kind": "coverage_weight", "a": "coat", "weight": 0.25},
    "root": {"kind": "vertical", "top": "wc", "base": "mix", "thickness": 0.002})";
  CompileResult r = compileUnsimplified("tree.json", test::material(nodes));
  std::vector<WalkTerm> t = groundTruthTerms(r, Geometry{}, {});
  ASSERT_EQ(t.size(), 4u);
  const double w[4] = {0.175, 0.075, 0.525, 0.225};
  const std::size_t layers[4] = {2, 2, 1, 1};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(t[i].weight, w[i], 1e-12) << i;
    EXPECT_EQ(t[i].stack.size(), layers[i]) << i;
  }
  const WalkLayer& coat = t[0].stack[0];
  EXPECT_DOUBLE_EQ(coat.thickness, 0.002);  // the vertical's
  EXPECT_DOUBLE_EQ(coat.mfp[1], 1.0);       // sss_mfp * sss_mfp_scale
  EXPECT_FALSE(coat.opaqueBase);
  EXPECT_DOUBLE_EQ(coat.roughness, 0.1);
  EXPECT_TRUE(t[0].stack[1].opaqueBase);    // a: MFP 0 is opaque
  EXPECT_DOUBLE_EQ(t[0].stack[1].diffuseAlbedo[2], 0.5);
  EXPECT_FALSE(t[1].stack[1].opaqueBase);   // b: an SSS medium
  EXPECT_DOUBLE_EQ(t[1].stack[1].mfp[2], 0.03);
  EXPECT_DOUBLE_EQ(t[1].stack[1].roughness, 0.6);
}

std::vector<std::filesystem::path> examples() { return test::exampleFiles(test::Examples::Surfaces); }

std::string readText(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(RandomWalkGroundTruth, OneStackIsLayeredEvalInTheGeometricFrame) {
  // row40_coating: a clear coat over the base slab, one term; in the identity
  // frame groundTruth is layeredEval of that stack with the same seed.
  const auto path = std::filesystem::path(SUBSTRATEC_SOURCE_DIR "/examples/row40_coating.json");
  CompileResult r = compileUnsimplified(path.string(), readText(path));
  Geometry g;
  g.V = dir(0.6, 0.3);
  std::vector<WalkTerm> t = groundTruthTerms(r, g, {});
  ASSERT_EQ(t.size(), 1u);
  ASSERT_EQ(t[0].stack.size(), 2u);
  EXPECT_DOUBLE_EQ(t[0].stack[0].thickness, 0.0001);
  EXPECT_DOUBLE_EQ(t[0].stack[0].roughness, 0.05);
  EXPECT_DOUBLE_EQ(t[0].stack[1].mfp[0], 0.006);
  D3 L = dir(0.8, 2.0);
  D3 a = groundTruth(r, g, L, {}, opts(512, 9));
  D3 b = layeredEval(t[0].stack, g.V, L, opts(512, 9));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-12 * b[c]);
  // A tilted frame: the same directions relative to N give the same value.
  Geometry tilted;
  const D3 N = {0, std::sin(0.5), std::cos(0.5)}, T = {1, 0, 0}, B = {0, std::cos(0.5), -std::sin(0.5)};
  auto world = [&](const D3& v) {
    return D3{T[0] * v[0] + B[0] * v[1] + N[0] * v[2], T[1] * v[0] + B[1] * v[1] + N[1] * v[2],
              T[2] * v[0] + B[2] * v[1] + N[2] * v[2]};
  };
  tilted.N = N;
  tilted.T = T;
  tilted.V = world(g.V);
  D3 c = groundTruth(r, tilted, world(L), {}, opts(512, 9));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], b[k], 1e-9 * b[k]);
  // Light below the horizon: nothing.
  D3 below = groundTruth(r, g, D3{0.3, 0, -0.9}, {}, opts(64));
  EXPECT_EQ(below[0] + below[1] + below[2], 0);
}

TEST(RandomWalkGroundTruth, RunsOnEveryExample) {
  // Every example, unsimplified, at its defaults, for a few geometries (one
  // with a procedural texture sampler): finite, non-negative, and not all zero.
  const TextureFn tex = [](int, double u, double v) {
    return std::array<double, 4>{0.5 + 0.4 * std::sin(7 * u), 0.5 + 0.4 * std::cos(5 * v), 0.3, 1};
  };
  int count = 0, unlit = 0, hair = 0;
  for (const auto& path : examples()) {
    CompileResult r = compileUnsimplified(path.filename().string(), readText(path));
    ASSERT_GE(r.material.root, 0) << path;
    if (isHairLeaf(r.material, r.material.nodes[r.material.root])) {  // a fibre: its truth is hair_truth.h
      EXPECT_TRUE(groundTruthTerms(r, Geometry{}, {}).empty()) << path;
      ++hair;
      continue;
    }
    if (r.after.closures.empty()) {  // unlit nodes only: nothing reflects, so no term and no light
      EXPECT_TRUE(groundTruthTerms(r, Geometry{}, {}).empty()) << path;
      const D3 f = groundTruth(r, Geometry{}, dir(0.5, 2.5), {}, opts(64));
      EXPECT_EQ(f[0] + f[1] + f[2], 0) << path;
      ++unlit;
      continue;
    }
    EXPECT_FALSE(groundTruthTerms(r, Geometry{}, {}).empty()) << path;
    double total = 0;
    for (int k = 0; k < 3; ++k) {
      Geometry g;
      if (k == 1) {
        g.N = {0.2, -0.3, 0.93};
        g.T = {1, 0.1, 0};
      }
      g.V = k == 2 ? dir(0.1, 0) : dir(0.7, 0.5);
      g.uv0 = {0.25 + 0.3 * k, 0.75};
      const D3 L = k == 1 ? D3{-0.3, 0.2, 0.93} : dir(0.5, 2.5);
      D3 f = groundTruth(r, g, L, k == 1 ? tex : TextureFn{}, opts(64, 1 + k));
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(f[c])) << path << " geometry " << k;
        EXPECT_GE(f[c], 0) << path << " geometry " << k;
        total += f[c];
      }
    }
    EXPECT_GT(total, 0) << path;
    ++count;
  }
  EXPECT_GE(count, 16);
  EXPECT_GE(unlit, 1);  // examples/unlit_hologram.json
  EXPECT_GE(hair, 2);   // examples/hair_*.json
}

TEST(RandomWalkGroundTruth, MetalnessSlabSplitsIntoConductorAndDielectric) {
  // car_paint: base = metalness_to_diffuse_f0(paint_color, 0.6, 0.5) under a clear coat.
  const auto path = std::filesystem::path(SUBSTRATEC_SOURCE_DIR "/examples/car_paint.json");
  CompileResult r = compileUnsimplified(path.string(), readText(path));
  int withProvenance = 0;
  for (const Slab& s : r.material.slabs) withProvenance += s.metalness.has_value();
  EXPECT_EQ(withProvenance, 1);
  std::vector<WalkTerm> t = groundTruthTerms(r, Geometry{}, {});
  int metal = 0, dielectric = 0;
  double total = 0;
  for (const WalkTerm& w : t) {
    total += w.weight;
    const WalkLayer& base = w.stack.back();
    if (base.conductor) {
      ++metal;
      EXPECT_NEAR(w.weight, 0.6, 1e-12);
      EXPECT_DOUBLE_EQ(base.f0[0], 0.55);
      EXPECT_DOUBLE_EQ(base.f0[1], 0.03);
      EXPECT_DOUBLE_EQ(base.diffuseAlbedo[0], 0);
    } else {
      ++dielectric;
      EXPECT_NEAR(w.weight, 0.4, 1e-12);
      EXPECT_NEAR(base.f0[0], 0.04, 1e-12);  // 0.08 * specular
      EXPECT_DOUBLE_EQ(base.diffuseAlbedo[0], 0.55);
    }
    EXPECT_EQ(w.stack.size(), 2u);  // the clear coat on top
  }
  EXPECT_EQ(metal, 1);
  EXPECT_EQ(dielectric, 1);
  EXPECT_NEAR(total, 1, 1e-12);
}

TEST(RandomWalkGroundTruth, NoProvenanceWhenOnlyF0ComesFromTheHelper) {
  const std::string nodes = R"(
    "h": {"kind": "metalness_to_diffuse_f0", "base_color": [0.8, 0.5, 0.2], "metallic": 0.5, "specular": 0.5},
    "root": {"kind": "slab", "diffuse_albedo": 0.3, "f0": "h.f0", "roughness": 0.4})";
  CompileResult r = compileUnsimplified("f0only.json", test::material(nodes));
  int checked = 0;
  for (const Slab& s : r.material.slabs) {
    EXPECT_FALSE(s.metalness.has_value());
    ++checked;
  }
  EXPECT_EQ(checked, 1);
  std::vector<WalkTerm> t = groundTruthTerms(r, Geometry{}, {});
  ASSERT_EQ(t.size(), 1u);
  EXPECT_FALSE(t[0].stack[0].conductor);
  // F0 0.42 in red: above the plausible dielectric range, a documented reading.
  std::vector<std::string> ex = groundTruthExcluded(r);
  EXPECT_NE(std::find(ex.begin(), ex.end(), "implausible dielectric f0"), ex.end());
  // Both pins from the helper, constant arguments folded: the provenance survives.
  const std::string both = R"(
    "h": {"kind": "metalness_to_diffuse_f0", "base_color": [0.8, 0.5, 0.2], "metallic": 0.5, "specular": 0.5},
    "root": {"kind": "slab", "diffuse_albedo": "h.diffuse_albedo", "f0": "h.f0", "roughness": 0.4})";
  CompileResult r2 = compileUnsimplified("both.json", test::material(both));
  ASSERT_EQ(r2.material.slabs.size(), 1u);
  EXPECT_TRUE(r2.material.slabs[0].metalness.has_value());
  EXPECT_EQ(groundTruthTerms(r2, Geometry{}, {}).size(), 2u);
  EXPECT_TRUE(groundTruthExcluded(r2).empty());
}

TEST(RandomWalkGroundTruth, ABlackSlabIsAConductorOnlyWhereItsF0IsNoDielectrics) {
  // Black plastic (F0 0.04) and a black fabric's F0 0.005 are dielectric
  // interfaces over matter that absorbs what enters; a black slab of F0 0.9 in
  // one channel is a conductor, and a conductor hides nothing below it.
  struct Case {
    const char* f0;
    bool conductor;
  };
  int checked = 0;
  for (const Case& c : {Case{"0.04", false}, Case{"0.005", false}, Case{"0.1", false}, Case{"[0.9, 0.6, 0.3]", true},
                        Case{"0.11", true}}) {
    const std::string nodes = std::string(R"("root": {"kind": "slab", "diffuse_albedo": 0, "f0": )") + c.f0 +
                              R"(, "roughness": 0.5, "sss_mfp": 0})";
    CompileResult r = compileUnsimplified("black.json", test::material(nodes));
    std::vector<WalkTerm> t = groundTruthTerms(r, Geometry{}, {});
    ASSERT_EQ(t.size(), 1u) << c.f0;
    ASSERT_EQ(t[0].stack.size(), 1u) << c.f0;
    EXPECT_EQ(t[0].stack[0].conductor, c.conductor) << c.f0;
    EXPECT_TRUE(t[0].stack[0].opaqueBase) << c.f0;
    ++checked;
  }
  EXPECT_EQ(checked, 5);
}

TEST(RandomWalkGroundTruth, ATiltedNormalPinRotatesTheTruth) {
  // A slab whose normal pin tilts by 0.4 rad about x equals the untilted slab
  // seen with the view and light rotated the other way.
  const double a = 0.4;
  const std::string tilted = "\"root\": {\"kind\": \"slab\", \"diffuse_albedo\": 0.5, \"f0\": 0.04, \"roughness\": 0.3,"
                             " \"normal\": [0, " + std::to_string(std::sin(a)) + ", " + std::to_string(std::cos(a)) + "]}";
  const std::string flat = R"("root": {"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.3})";
  CompileResult rt = compileUnsimplified("tilted.json", test::material(tilted));
  CompileResult rf = compileUnsimplified("flat.json", test::material(flat));
  const std::vector<WalkTerm> t = groundTruthTerms(rt, Geometry{}, {});
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NEAR(t[0].N[1], std::sin(a), 1e-5);
  // World directions; their coordinates in the tilted frame (T = x, N tilted, B = N x T).
  using reference::detail::cross;
  using reference::detail::dot;
  const D3 N = t[0].N, T = t[0].T, B = cross(N, T);
  int cases = 0;
  for (double mu : {0.9, 0.5}) {
    Geometry g;
    g.V = dir(mu, 1.2);
    const D3 L = dir(0.7, 3.9);
    auto local = [&](const D3& w) { return D3{dot(w, T), dot(w, B), dot(w, N)}; };
    Geometry gf;
    gf.V = local(g.V);
    const D3 a1 = groundTruth(rt, g, L, {}, opts(256, 3));
    const D3 b1 = groundTruth(rf, gf, local(L), {}, opts(256, 3));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a1[c], b1[c], 1e-9 * (1 + b1[c])) << mu;
    ++cases;
  }
  EXPECT_EQ(cases, 2);
}

TEST(RandomWalkGroundTruth, ExcludedListsNameTheUnmodelledFeatures) {
  auto excluded = [](const char* file) {
    const auto path = std::filesystem::path(SUBSTRATEC_SOURCE_DIR "/examples") / file;
    return groundTruthExcluded(compileUnsimplified(path.string(), readText(path)));
  };
  auto has = [](const std::vector<std::string>& v, const char* s) { return std::find(v.begin(), v.end(), s) != v.end(); };
  EXPECT_TRUE(has(excluded("row60_glint.json"), "glint"));
  EXPECT_TRUE(has(excluded("row44_specular_profile.json"), "specular profile"));
  EXPECT_FALSE(has(excluded("row40_coating.json"), "glint"));
  EXPECT_FALSE(has(excluded("car_paint.json"), "implausible dielectric f0"));  // its metalness is split
}

TEST(RandomWalkGroundTruth, FurnaceMaterialIsWhiteForBothSides) {
  int count = 0;
  for (const auto& path : examples()) {
    CompileResult r = compileUnsimplified(path.filename().string(), readText(path));
    CompileResult f = furnaceMaterial(r);
    Geometry g;
    g.V = dir(0.6, 0.2);
    // The analytic side runs on it: finite closures.
    MaterialResult<double> a = evaluateMaterial<double>(f, g, InputValues{}, {});
    for (const auto& c : a.closures)
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(c.diffuseAlbedo[k]) && std::isfinite(c.f0[k])) << path;
    for (const WalkTerm& t : groundTruthTerms(f, g, {}))
      for (const WalkLayer& L : t.stack) {
        if (L.conductor && !L.opaqueBase) continue;
        if (L.conductor) EXPECT_DOUBLE_EQ(L.f0[0] * (L.diffuseAlbedo[0] == 0), L.f0[0]) << path;
        else if (L.opaqueBase) EXPECT_DOUBLE_EQ(L.diffuseAlbedo[1], 1.0) << path;
      }
    const Estimate e = groundTruthAlbedo(f, g, {}, opts(64, 5));
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(e.value[k]) && e.value[k] <= 1.05) << path;
    ++count;
  }
  EXPECT_GE(count, 16);
  // A white Lambertian under a smooth coat: the furnace truth is ~1.
  const std::string nodes = R"(
    "h": {"kind": "metalness_to_diffuse_f0", "base_color": [0.8, 0.5, 0.2], "metallic": 0.3, "specular": 0.5},
    "root": {"kind": "slab", "diffuse_albedo": "h.diffuse_albedo", "f0": "h.f0", "roughness": 0.0})";
  CompileResult w = furnaceMaterial(compileUnsimplified("white.json", test::material(nodes)));
  Geometry g;
  const Estimate e = groundTruthAlbedo(w, g, {}, opts(2048, 7, 1024));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(e.value[k], 1.0, 0.02) << k;
}

TEST(RandomWalkGroundTruth, FurnaceMetalnessSlabIsWhiteAtGrazingToo) {
  // A metal whose F90 is 0 (MaterialX's Standard Surface with specular 0, as
  // standard_surface_copper imports) absorbs at grazing angles: the furnace
  // whitens its F90 as it does a conductor's, so its analytic side is judged
  // white as the truth's is (Gulbrandsen's metal of F0 1 reflects everything).
  const std::string nodes = R"(
    "h": {"kind": "metalness_to_diffuse_f0", "base_color": [0.9, 0.5, 0.3], "metallic": 1.0, "specular": 0.0},
    "root": {"kind": "slab", "diffuse_albedo": "h.diffuse_albedo", "f0": "h.f0", "f90": 0.0, "roughness": 0.3})";
  CompileResult w = furnaceMaterial(compileUnsimplified("metal_f90_0.json", test::material(nodes)));
  int checked = 0;
  for (double mu : {1.0, 0.5, 0.2}) {
    Geometry g;
    g.V = dir(mu, 0.0);
    MaterialResult<double> a = evaluateMaterial<double>(w, g, InputValues{}, {});
    for (const auto& c : a.closures) {
      for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(c.f90[k], 1.0) << mu;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 3);
}


}  // namespace ground_truth_test
}  // namespace substratec
