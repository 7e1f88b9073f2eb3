// The accuracy metric (accuracy/accuracy.h): a slab whose analytic model and
// truth agree, determinism (same samples, same bits; the thread count changes
// no bit), every row present, and a black truth reported rather than passed.
// Cheap: a few hundred walks per figure.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "accuracy/accuracy.h"
#include "diag/diagnostics.h"
#include "pipeline/pipeline.h"
#include "test_util.h"

namespace substratec {
namespace accuracy_test {

CompileResult compileSlab(const std::string& slab) {
  Diagnostics d("slab.json");
  CompileOptions o;
  o.budgetOverride = 1024;
  o.maxClosuresOverride = 8;
  auto r = compileText("slab.json", test::material(R"("root": )" + slab), o, d);
  EXPECT_TRUE(r) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

accuracy::Options cheap(int threads) {
  accuracy::Options o;
  o.samples = 2048;
  o.evalSamples = 64;
  o.envSamples = 1024;
  o.threads = threads;
  o.diffuseModel = reference::kDiffuseLambert;
  return o;
}

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// `top` over `base` (each a slab's JSON), `thickness` mm apart, under the
// largest budget (every closure kept).
CompileResult compileLayered(const std::string& top, const std::string& base, const std::string& thickness) {
  Diagnostics d("layered.json");
  CompileOptions co;
  co.budgetOverride = 1024;
  co.maxClosuresOverride = 8;
  auto r = compileText("layered.json", test::material(R"("coat": )" + top + R"(, "base": )" + base + R"(,
      "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": )" + thickness + "}"),
                       co, d);
  EXPECT_TRUE(r) << d.formatAll();
  return r ? std::move(*r) : CompileResult{};
}

TEST(Accuracy, ALambertianSlabAgreesWithItsTruthNearNormalIncidence) {
  // No specular to speak of (F0 0): the walk's Lambertian and the analytic
  // Lambert diffuse are the same model; they part where the analytic model's
  // Schlick Fresnel (F90 1) takes from the diffuse: at grazing views, and, by
  // the diffuse's light-side coupling, for grazing lights (about 1.7 % of the
  // BRDF at the grid's median near normal view: the coupling's 1 / (1 - E_avg)
  // with E_avg 0.05 lifts the rest).
  const CompileResult r = compileSlab(R"({"kind": "slab", "diffuse_albedo": 0.5, "f0": 0, "roughness": 0.5})");
  const accuracy::Options o = cheap(2);
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  EXPECT_TRUE(c.problems.empty());
  int checked = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.brdfMedianRelError && row.brdfP95RelError);
    EXPECT_EQ(row.brdfTotal, 48);
    EXPECT_GT(row.brdfCounted, 0);
    EXPECT_GE(row.reciprocityMaxRatio, 1.0);
    EXPECT_GT(row.truthWalks, 0);
    if (row.nov < 0.8) continue;
    EXPECT_NEAR(*row.relError, 0, 0.005);
    EXPECT_LT(*row.brdfMedianRelError, 0.025);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(row.truth[k], 0.5, 0.005);
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

TEST(Accuracy, ADiffuseUnderAnInterfaceIsReciprocal) {
  // The diffuse lobe takes 1 - E_spec from the view and, by the light-side
  // coupling, (1 - E_spec(NoL)) / (1 - E_avg) from the light: f(v, l) = f(l, v)
  // for its part. Before the coupling this slab read 1.16 (the lobe took the
  // interface's reflection along the view alone). Since issue 19 step 4 it
  // reads 1.052 (1.045 before; the issue's goal is 1.05): the view side takes
  // the exact Fresnel curve's albedo from the tables, the light side Karis'
  // closed form refitted to that curve; the tables' form on the light side
  // too keeps it below 1.05 but costs about 35 instructions per closure and
  // broke the step's cost budget (docs/accuracy.md, step 4).
  const CompileResult r = compileSlab(R"({"kind": "slab", "diffuse_albedo": 0.8, "f0": 0.04, "roughness": 0.45})");
  const accuracy::Options o = cheap(2);
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  int pairs = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    EXPECT_LT(row.reciprocityMaxRatio, 1.055);
    pairs += row.reciprocityPairs;
  }
  EXPECT_GE(pairs, 100);
}

TEST(Accuracy, ACoatGivesBackWhatItsUndersideReflects) {
  // Issue 19, step 2: a nearly smooth coat of F0 0.04 over a Lambertian of
  // albedo 0.5 under its own F0 0.04 (bench/materials' two coat controls: clear,
  // and absorbing red light). The base is index-matched to the coat (its F0 is
  // taken relative to it), the media are crossed along the refracted cosine,
  // and the light the coat's underside sends back down returns. Before: the
  // clear coat read -3.0 / -4.0 / -5.8 / -6.3 / -7.0 / -10.5 % (NoV 1 .. 0.1),
  // the absorbing one +13.5 .. -11.5 %, BRDF medians 77 % and 58 %, reciprocity
  // 1.16; the issue's goal is +-5 % for NoV >= 0.2 and +-8 % at 0.1, BRDF
  // median <= 10 % and reciprocity within 1.05. Step 18: the same clear coat
  // of IOR 1.8 (F0 0.08; bench/materials/clear_coat_ior_1_8_over_lambert.json),
  // whose T_N of 0.92 read as media of IOR 1.5's interface absorbing the
  // trapped light: -11.1 / -11.7 / -11.6 / -10.7 / -6.9 / -3.9 %, furnace 0.79.
  int rows = 0;
  struct Coat {
    const char* f0;
    const char* mfp;
  };
  for (const Coat& coat : {Coat{"0.04", "10"}, Coat{"0.04", "[0.2, 1, 5]"}, Coat{"0.08", "10"}}) {
    SCOPED_TRACE(std::string("coat F0 ") + coat.f0 + ", MFP " + coat.mfp);
    const CompileResult r = compileLayered(std::string(R"({"kind": "slab", "diffuse_albedo": 0, "f0": )") + coat.f0 +
                                               R"(, "roughness": 0.05, "sss_mfp": )" + coat.mfp + "}",
                                           R"({"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.05})",
                                           "0.1");
    ASSERT_GE(r.material.root, 0);
    accuracy::Options o = cheap(2);
    o.samples = 8192;
    o.evalSamples = 512;  // the BRDF grid's noise near the coat's mirror peak at 64 walks reads ~19 %
    const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
    ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
    for (const auto& row : c.rows) {
      SCOPED_TRACE(row.nov);
      ASSERT_TRUE(row.relError && row.brdfMedianRelError);
      EXPECT_LE(std::fabs(*row.relError), row.nov >= 0.2 ? 0.05 : 0.08);
      EXPECT_LE(*row.brdfMedianRelError, 0.10);
      EXPECT_LE(row.reciprocityMaxRatio, 1.05);
      ASSERT_TRUE(row.furnaceAnalytic);
      for (int k = 0; k < 3; ++k) {
        EXPECT_GE((*row.furnaceAnalytic)[k], 0.97);
        EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
      }
      ++rows;
    }
  }
  EXPECT_EQ(rows, 18);
}

TEST(Accuracy, ADarkBaseUnderASmoothInterfaceFollowsExactFresnel) {
  // Issue 19, item 3 (bench/materials/dark_under_smooth_interface.json): a
  // Lambertian of albedo 0.2 under a nearly smooth interface of F0 0.04, whose
  // reflection is much of the albedo. With Schlick's curve it read -1.2 / +0.3
  // / -6.7 / -5.1 / +3.5 / +4.5 % (NoV 1 .. 0.1) and reciprocity 1.13 (the
  // light side's fit and the view side's Schlick parted); with the exact curve
  // of IOR 1.5 (the ground truth's dielectric) -1.4 / +1.3 / -2.4 / -0.4 / +0.6
  // / -0.4 % and 1.03.
  const CompileResult r =
      compileSlab(R"({"kind": "slab", "diffuse_albedo": 0.2, "f0": 0.04, "roughness": 0.05, "sss_mfp": 0})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 512;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.035);
    EXPECT_LE(row.reciprocityMaxRatio, 1.05);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.97);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, ARoughDielectricReflectsWhatItsFacetsScatterMoreThanOnce) {
  // Issue 19, step 20 (bench/materials/rough_black_dielectric.json): a rough
  // dielectric over a black base returns only what its interface reflects, and
  // the truth's microsurface scatters light between its facets and through
  // them and out again. The single-scattering lobe with Turquin's W read, as the
  // mean over NoV 1 .. 0.1, -6.7 % at roughness 0.7 and -13.4 % at 1 (F0 0.04),
  // -8.0 % at 0.7 for F0 0.08 (65,536 walks); with 1 + 0.125 r on a
  // dielectric's lobe the means are within 3 % and every NoV within the goal
  // but for the truth's own noise (a black base lets few walks back out: its
  // standard error is 1 ... 2 % of the albedo at 131,072 walks).
  int rows = 0;
  for (const char* slab : {R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.7, "sss_mfp": 0})",
                           R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 1, "sss_mfp": 0})",
                           R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.08, "roughness": 0.7, "sss_mfp": 0})"}) {
    SCOPED_TRACE(slab);
    const CompileResult r = compileSlab(slab);
    accuracy::Options o = cheap(2);
    o.samples = 131072;
    const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
    ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
    double mean = 0;
    for (const auto& row : c.rows) {
      SCOPED_TRACE(row.nov);
      ASSERT_TRUE(row.relError && row.furnaceAnalytic);
      const double sigma = row.truthStderr[1] / row.truth[1];  // grey: every channel alike
      EXPECT_LE(std::fabs(*row.relError), (row.nov >= 0.2 ? 0.05 : 0.08) + 2 * sigma);
      // Turquin's W reads the view only: 1.071 at roughness 1, before this step
      // as after (its factor is the same at every view, so the lobe keeps its reciprocity).
      EXPECT_LE(row.reciprocityMaxRatio, 1.08);
      for (int k = 0; k < 3; ++k) EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
      mean += *row.relError / static_cast<double>(c.rows.size());
      ++rows;
    }
    EXPECT_LE(std::fabs(mean), 0.03);
  }
  EXPECT_EQ(rows, 18);
}

TEST(Accuracy, AScatteringMediumReturnsLessHeadOnThanAtGrazing) {
  // Issue 19, step 12: a semi-infinite medium of albedo 0.35 under an interface
  // of F0 0.04. Light that enters head-on goes deep and less of it returns than
  // at grazing; a Lambertian returns the same at every angle. With the diffuse
  // of a Lambertian the model read +11.5 / +10.3 / +7.8 / +4.8 / +0.6 / -0.1 %
  // (NoV 1 .. 0.1, nearly smooth) and +11.1 / +9.3 / +3.6 / +1.4 / -2.1 / -3.5 %
  // (roughness 0.45), BRDF medians up to 12.3 %; with the medium's weight
  // (substrate_bsdf.h, "A slab's medium") -0.3 / +0.2 / -0.0 / -0.3 / -1.6 /
  // -1.0 % and -0.7 / -0.1 / -2.8 / -2.5 / -3.6 / -4.0 % (these counts), BRDF
  // medians 4.3 % at most, and the lobe stays as reciprocal (1.031 at most).
  int rows = 0;
  int pairs = 0;
  for (const char* roughness : {"0.05", "0.45"}) {
    SCOPED_TRACE(roughness);
    const CompileResult r = compileSlab(std::string(R"({"kind": "slab", "diffuse_albedo": 0.35, "f0": 0.04, "roughness": )") +
                                        roughness + R"(, "sss_mfp": 1})");
    accuracy::Options o = cheap(2);
    o.samples = 8192;
    o.evalSamples = 256;
    const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
    ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
    for (const auto& row : c.rows) {
      SCOPED_TRACE(row.nov);
      ASSERT_TRUE(row.relError && row.brdfMedianRelError);
      EXPECT_LE(std::fabs(*row.relError), 0.05);
      EXPECT_LE(*row.brdfMedianRelError, 0.06);
      EXPECT_GT(row.brdfCounted, 0);
      EXPECT_LE(row.reciprocityMaxRatio, 1.05);
      pairs += row.reciprocityPairs;
      ++rows;
    }
  }
  EXPECT_EQ(rows, 12);
  EXPECT_GE(pairs, 100);
}

TEST(Accuracy, AMetalnessSlabReturnsTheMixItStandsFor) {
  // Issue 19, item 5 (bench/materials/metalness_mix.json): one slab from
  // metalness_to_diffuse_f0 (base colour (0.8, 0.5, 0.2), metallic 0.6,
  // specular 0.5) stands for a conductor of F0 = base colour beside a
  // dielectric of F0 0.04 over a diffuse of the base colour, which is how the
  // truth walks it. Its diffuse attenuated by the specular albedo of the mixed
  // F0 (0.5 in red) read -13.8 / -14.4 / -12.6 / -11.0 % (NoV 1 / 0.6 / 0.2 /
  // 0.1) and a white furnace of 0.76; attenuated by the dielectric part's
  // (substrate_closure_dielectric_part) -1.2 / -2.7 / -3.7 / -2.8 % and 0.97.
  Diagnostics d("metalness.json");
  CompileOptions co;
  co.budgetOverride = 1024;
  co.maxClosuresOverride = 8;
  auto compiled = compileText("metalness.json", test::material(R"(
      "paint": {"kind": "metalness_to_diffuse_f0", "base_color": [0.8, 0.5, 0.2], "metallic": 0.6, "specular": 0.5},
      "root": {"kind": "slab", "diffuse_albedo": "paint.diffuse_albedo", "f0": "paint.f0", "roughness": 0.4,
               "sss_mfp": 0})"),
                              co, d);
  ASSERT_TRUE(compiled) << d.formatAll();
  const CompileResult& r = *compiled;
  ASSERT_TRUE(r.material.slabs.at(0).metalness) << "the slab must carry its metalness provenance";
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.97);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, EachPartOfAMetalnessMixScattersAmongItsOwnFacets) {
  // Issue 19, step 15: a rough metalness slab (metallic 0.5, roughness 0.8)
  // is a conductor and a dielectric side by side, each compensated for its
  // own multiple scattering; one lobe of the mixed F0 compensated by Turquin's
  // W = 1 + F (1 - E) / E returned 0.896 of a white furnace head-on and
  // -5.6 / -5.6 / -5.9 / -5.7 / -4.8 / -3.9 % of the coloured truth (NoV 1 ...
  // 0.1). The F0-weighted mean of the parts' W reads F + Var / F
  // (substrate_closure_compensated_f0): +0.6 / +0.4 / -0.3 / -0.9 / -1.4 / -1.6 %.
  Diagnostics d("metalness.json");
  CompileOptions co;
  co.budgetOverride = 1024;
  co.maxClosuresOverride = 8;
  auto compiled = compileText("metalness.json", test::material(R"(
      "paint": {"kind": "metalness_to_diffuse_f0", "base_color": [0.8, 0.5, 0.2], "metallic": 0.5, "specular": 0.5},
      "root": {"kind": "slab", "diffuse_albedo": "paint.diffuse_albedo", "f0": "paint.f0", "roughness": 0.8,
               "sss_mfp": 0})"),
                              co, d);
  ASSERT_TRUE(compiled) << d.formatAll();
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(*compiled, o), accuracy::truthOf(*compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.03);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.98);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, AMetalnessMixUnderACoatIsIndexMatchedInItsDielectricPart) {
  // Issue 19, step 25 (bench/materials/metalness_under_clear_coat.json,
  // car_paint's paint without its haze): a metalness mix (base colour (0.55,
  // 0.03, 0.04), metallic 0.6) under a nearly smooth clear coat. Its
  // dielectric part, F0 0.04 against air, is index-matched under the coat;
  // its conductor part keeps its F0. The mix kept its 0.4 share of F0 0.04 and
  // of F90 1 under the coat: +9.4 / +9.0 / +9.7 / +12.4 / +9.6 / +5.2 % (NoV 1
  // .. 0.1; green and blue +18.2 / +16.1 % head-on, 32,768 walks). With that
  // share relative to the coat (substrate_closure_mix_under): +1.4 / +1.5 /
  // +2.4 / +5.0 / +4.4 / +2.5 %, green and blue -0.4 / -0.5 % head-on.
  Diagnostics d("metalness_under_coat.json");
  CompileOptions co;
  co.budgetOverride = 1024;
  co.maxClosuresOverride = 8;
  auto r = compileText("metalness_under_coat.json", test::material(R"(
      "paint": {"kind": "metalness_to_diffuse_f0", "base_color": [0.55, 0.03, 0.04], "metallic": 0.6, "specular": 0.5},
      "base": {"kind": "slab", "diffuse_albedo": "paint.diffuse_albedo", "f0": "paint.f0", "roughness": 0.4,
               "sss_mfp": 0},
      "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.03, "sss_mfp": 10},
      "root": {"kind": "vertical", "top": "coat", "base": "base", "thickness": 0.05})"),
                       co, d);
  ASSERT_TRUE(r) << d.formatAll();
  const CompileResult& compiled = *r;
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 128;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(compiled, o), accuracy::truthOf(compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0, channels = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    std::printf("[ accuracy ] metalness mix under a clear coat, NoV %.1f: %+.2f %%\n", row.nov, 100 * *row.relError);
    EXPECT_LE(std::fabs(*row.relError), row.nov >= 0.2 ? 0.06 : 0.08);
    // Head-on every channel, green and blue too, where the dielectric part's
    // F0 is most of what the base reflects.
    if (row.nov >= 0.6) {
      for (const auto& e : row.channelRelError) {
        ASSERT_TRUE(e);
        EXPECT_LE(std::fabs(*e), 0.05);
        ++channels;
      }
    }
    for (int k = 0; k < 3; ++k) EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    ++rows;
  }
  EXPECT_EQ(rows, 6);
  EXPECT_EQ(channels, 9);
}

TEST(Accuracy, AConductorUnderACoatLosesWhatTheCoatTraps) {
  // Issue 19, step 6 (bench/materials/conductor_under_clear_coat.json): a
  // rough coloured conductor (F0 (0.55, 0.3, 0.1), roughness 0.5) under a
  // nearly smooth clear coat. The coat's top sends what the lobe spreads below
  // the critical angle back down, where the conductor absorbs part of it again;
  // returning the lobe whole read +21.1 / +32.6 / +18.9 / +11.1 % (NoV 1 / 0.6
  // / 0.2 / 0.1) and a white furnace of 0.88. With the trapped share and its
  // returns (substrate_closure_coat_specular): +1.5 / +1.3 / +3.2 / +3.2 %,
  // furnace 0.91 .. 0.97, reciprocity 1.04 as before. Since step 13 the escape
  // counts the interface's own head-on transmission, so the 4 % it reflects on
  // the way out returns too: +2.7 / +2.2 / +3.5 / +3.4 %, furnace 0.94 .. 0.99.
  const CompileResult compiled =
      compileLayered(R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.05, "sss_mfp": 10})",
                     R"({"kind": "slab", "diffuse_albedo": 0, "f0": [0.55, 0.3, 0.1], "roughness": 0.5})", "0.1");
  ASSERT_GE(compiled.material.root, 0);
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(compiled, o), accuracy::truthOf(compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    EXPECT_GT(row.reciprocityPairs, 0);
    EXPECT_LE(row.reciprocityMaxRatio, 1.07);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.94);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

// A white conductor of roughness `base` under a top of roughness `top` whose
// medium lets 0.7 through head-on (an MFP of 2.8037e-4 mm over 1e-4 mm), as
// MaterialX's coat_color does: its albedo against the truth, per NoV.
std::vector<double> conductorUnderTintedCoat(const std::string& top, const std::string& base) {
  const CompileResult r =
      compileLayered(R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": )" + top +
                         R"(, "sss_mfp": 0.00028036732})",
                     R"({"kind": "slab", "diffuse_albedo": 0, "f0": 1, "roughness": )" + base + "}", "0.0001");
  if (r.material.root < 0) return {};
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 64;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  std::vector<double> errors;
  for (const auto& row : c.rows) {
    EXPECT_TRUE(row.relError);
    if (row.relError) errors.push_back(*row.relError);
  }
  return errors;
}

TEST(Accuracy, AConductorUnderAStretchedCoatGetsBackTheSpreadItsTopGave) {
  // Issue 19, step 19: a conductor of roughness 0.4 under a clear coat of
  // roughness 0.6 stretched to anisotropy 0.8. The conductor's roughness holds
  // the top's spread (Belcour's widening of the top's roughness), which the
  // trapped share reads back out (substrate_closure_coat_top_alpha); a
  // stretched top gave none back: -6.1 / -7.3 / -6.0 / -5.1 % (NoV 1 / 0.6 /
  // 0.2 / 0.1). With its alphas' mean: -3.0 / -4.8 / -4.9 / -4.2 % (the
  // isotropic coat of roughness 0.6: -2.7 / -2.0 / -3.7 / -3.5 %).
  const CompileResult compiled = compileLayered(
      R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.6, "anisotropy": 0.8, "sss_mfp": 1000})",
      R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.9, "roughness": 0.4})", "0.0001");
  ASSERT_GE(compiled.material.root, 0);
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 128;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(compiled, o), accuracy::truthOf(compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    std::printf("[ accuracy ] conductor under a stretched coat, NoV %.1f: %+.2f %%\n", row.nov, 100 * *row.relError);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    for (int k = 0; k < 3; ++k) EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, TheLightATintedCoatTrapsCrossesItsMediumTwiceAsFar) {
  // Issue 19, step 14: what a rough lobe sends below the critical angle is
  // reflected back down by the top and crosses the medium at its grazing
  // angles, twice the vertical path or more; returned through T_m^2 a white
  // conductor of roughness 0.7 under a smooth top of transmittance 0.7 read
  // +19.8 / +16.2 / +12.7 / +9.8 / +4.5 / +1.3 % (NoV 1 .. 0.1, 16,384 walks),
  // through T_m^4 (substrate_closure_coat_specular) +6.3 / +2.4 / -0.3 / -0.5 /
  // -0.6 / -1.0 %; head-on the goal's 5 % is not met yet.
  const std::vector<double> errors = conductorUnderTintedCoat("0.05", "0.7");
  ASSERT_EQ(errors.size(), accuracy::kNoV.size());
  for (std::size_t i = 0; i < errors.size(); ++i) {
    SCOPED_TRACE(accuracy::kNoV[i]);
    EXPECT_LE(std::fabs(errors[i]), accuracy::kNoV[i] == 1.0 ? 0.08 : 0.05);
  }
}

TEST(Accuracy, ARoughTintedTopDoesNotTrapTheSpreadItGives) {
  // Issue 19, step 14 (MaterialX Tiled_Brass: base and coat of one roughness):
  // a white conductor of roughness 0.4 under a top of roughness 0.4 and
  // transmittance 0.7. The closure's roughness holds the top's spread, which
  // the way out mostly undoes, and grazing light refracted by the top's tilted
  // facets runs flatter through the medium than 1 / mu_t:
  // -5.2 / +1.0 / +9.8 / +15.0 / +17.5 / +19.7 % before, -5.3 / -2.1 / +1.4 /
  // +1.5 / +2.5 / +5.2 % with both (16,384 walks, scripts/scan_tinted_coat.py).
  const std::vector<double> errors = conductorUnderTintedCoat("0.4", "0.4");
  ASSERT_EQ(errors.size(), accuracy::kNoV.size());
  for (std::size_t i = 0; i < errors.size(); ++i) {
    SCOPED_TRACE(accuracy::kNoV[i]);
    EXPECT_LE(std::fabs(errors[i]), accuracy::kNoV[i] >= 0.2 ? 0.06 : 0.08);
  }
}

// A slab under a nearly smooth clear coat, as row40_coating has it (thickness 0.1 mm).
CompileResult compileUnderClearCoat(const std::string& base) {
  return compileLayered(R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.05, "sss_mfp": 10})", base,
                        "0.0001");
}

TEST(Accuracy, AWrapLobeUnderAClearCoatMeetsItAtItsOwnCosine) {
  // Issue 19, step 13: row40_coating's slab without its fuzz, haze, anisotropy
  // and edge tint (albedo (0.55, 0.35, 0.25), F0 0.04, roughness 0.45, a wrap
  // lobe of MFP (6, 3, 1.5) mm) under its clear coat. The wrap lobe lights down
  // to NoL = -w; lit through the coat at NoL, its light from below the horizon
  // met a transmission of 0 and the light near it little: -12.4 / -10.8 / -11.0
  // / -8.7 / -5.6 / -3.0 % (NoV 1 .. 0.1, these counts), a white furnace of
  // 0.87 .. 0.94 in luminance. Lit at its own cosine (substrate_wrap_light_cosine):
  // -3.7 / -2.1 / -2.8 / -1.8 / -1.5 / -0.8 %, furnace 0.95 .. 0.98 (0.917 in
  // red, which wraps furthest: the cosine is the smallest channel's). (Its truth
  // has no wrap lobe: the BRDF's shape and its reciprocity are not compared.)
  const CompileResult r = compileUnderClearCoat(
      R"({"kind": "slab", "diffuse_albedo": [0.55, 0.35, 0.25], "f0": 0.04, "roughness": 0.45,
          "sss_mfp": [0.006, 0.003, 0.0015], "sss_type": "wrap"})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.91);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, AFuzzUnderAClearCoatSeesTheRefractedLight) {
  // Issue 19, step 13: a Lambertian of albedo 0.5 (F0 0.04, roughness 0.45)
  // under fuzz (amount 0.5, white, roughness 0.6) under a clear coat. The
  // sheen's peak is at grazing angles, which light refracted into the coat
  // never reaches (NoL' >= 0.745). Evaluated at the angles in air the fuzz read
  // -1.8 / +1.7 / +5.1 / +7.5 / +7.3 / +5.7 % (NoV 1 .. 0.1, these counts), BRDF
  // medians up to 19.7 %; at the refracted angles (substrate_fuzz_under_layers)
  // -1.6 / -1.8 / -2.1 / -2.5 / -2.0 / -0.4 %, medians 10.4 % at most (3.9 ..
  // 4.8 % for NoV >= 0.2), and the lobe reciprocal.
  const CompileResult r = compileUnderClearCoat(
      R"({"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.45,
          "fuzz_amount": 0.5, "fuzz_color": 1, "fuzz_roughness": 0.6})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  int pairs = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.brdfMedianRelError);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    EXPECT_GT(row.brdfCounted, 0);
    if (row.nov >= 0.2) EXPECT_LE(*row.brdfMedianRelError, 0.06);
    EXPECT_LE(row.reciprocityMaxRatio, 1.01);
    pairs += row.reciprocityPairs;
    ++rows;
  }
  EXPECT_EQ(rows, 6);
  EXPECT_GE(pairs, 100);
}

TEST(Accuracy, ARoughClearCoatLetsTheGrazingLightThrough) {
  // Issue 19, step 9 (bench/materials/rough_clear_coat_over_lambert.json): a
  // Lambertian of albedo 0.9 under a clear coat of roughness 0.6. The layers'
  // angular term was a smooth interface's, 1 - chi(mu), which falls to 0 at
  // grazing angles where the rough coat reflects little: -1.1 / -2.9 / -24.6 /
  // -44.3 % (NoV 1 / 0.6 / 0.2 / 0.1), a white furnace of 0.55 at NoV 0.1. With
  // the rough top's floor (substrate_coat_transmission): -1.2 / -3.0 / -7.0 /
  // -7.3 %, furnace 0.93 .. 0.99, reciprocity 1.00 as before.
  const CompileResult compiled =
      compileLayered(R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.6, "sss_mfp": 1000})",
                     R"({"kind": "slab", "diffuse_albedo": 0.9, "f0": 0.04, "roughness": 0.5})", "0.0001");
  ASSERT_GE(compiled.material.root, 0);
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(compiled, o), accuracy::truthOf(compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.08);
    EXPECT_GT(row.reciprocityPairs, 0);
    EXPECT_LE(row.reciprocityMaxRatio, 1.02);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.92);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, AStretchedClearCoatLetsTheGrazingLightThroughAlongItsRoughAxis) {
  // Issue 19, step 19 (bench/materials/stretched_clear_coat_over_lambert.json):
  // the rough clear coat above, stretched along its tangent (anisotropy 0.8),
  // seen along that rough axis. A stretched top had no rough floor, so the
  // layers' term was a smooth interface's at every azimuth: -1.3 / -3.5 /
  // -28.4 / -49.7 % (NoV 1 / 0.6 / 0.2 / 0.1), a white furnace of 0.50 at NoV
  // 0.1. With the floor of the roughness the lobe projects on the direction's
  // azimuth (substrate_coat_floor_along): -1.4 / -3.1 / -6.7 / -7.3 %, furnace
  // 0.93 .. 0.99: the isotropic coat's figures.
  const CompileResult compiled = compileLayered(
      R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.6, "anisotropy": 0.8, "sss_mfp": 1000})",
      R"({"kind": "slab", "diffuse_albedo": 0.9, "f0": 0.04, "roughness": 0.5})", "0.0001");
  ASSERT_GE(compiled.material.root, 0);
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  o.evalSamples = 256;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(compiled, o), accuracy::truthOf(compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic && row.brdfMedianRelError);
    EXPECT_LE(std::fabs(*row.relError), 0.08);
    EXPECT_LE(*row.brdfMedianRelError, 0.10);
    EXPECT_GT(row.reciprocityPairs, 0);
    EXPECT_LE(row.reciprocityMaxRatio, 1.02);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.92);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, AStretchedConductorKeepsItsEnergy) {
  // Issue 19, item 1: a coloured conductor of roughness 0.6 stretched to
  // |A| 0.8 (bench/materials/stretched_conductor.json) against the walk, whose
  // microsurface scatters multiply. Its energy compensation reads the lobe's
  // largest albedo over the view's azimuth (substrate_energy_aniso); before, it
  // was widened toward none and the control read -23.1 / -21.1 / -12.4 / -8.1 %
  // (NoV 1 / 0.6 / 0.2 / 0.1), a white furnace of 0.73 head-on; then -2.1 / -1.8 /
  // -2.4 / -2.4 % and a furnace of 0.973 (the table's slices at |A| 0.5 and 1,
  // raised to bound |A| 0.8 between them, gave back a little); since step 21
  // (slices at 1/3, 2/3 and 1, each node as low as the bound allows) -0.2 /
  // -0.3 / -0.5 / -0.4 % at 32,768 walks, a furnace of 0.996. Reciprocity is
  // not bounded here: Turquin's W depends on the view alone (1.16-1.20 for this
  // lobe, 1.05-1.11 for the isotropic one).
  const CompileResult r = compileSlab(
      R"({"kind": "slab", "diffuse_albedo": 0, "f0": [1.0, 0.78, 0.34], "roughness": 0.6, "anisotropy": 0.8})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.03);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.985);
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    }
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, AHalfCoatIsCrossedOnBothSidesOrOnNeither) {
  // Issue 19, step 22 (bench/materials/tinted_half_coat_over_lambert.json): a
  // coat absorbing green and blue (transmittance 1 / 0.59 / 0.32 along the
  // normal) over half the surface. A path meets it on the way in and out or
  // not at all: the base is lit by (1 - C) + C t_V t_L, and only the covered
  // half loses what the coat's top traps. The lighting took the product of the
  // view's and the light's blends (lower by C (1 - C)(1 - t_V)(1 - t_L)) and
  // darkened the whole diffuse by what the covered half absorbs: -19.6 / -20.4
  // / -20.8 / -20.9 / -20.1 / -19.4 % (NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1)
  // against the walk (which picks the coat's presence per path), now -0.4 /
  // -1.0 / -1.5 / -2.4 / -3.3 / -3.9 % (32,768 walks).
  Diagnostics d("half_coat.json");
  CompileOptions co;
  co.budgetOverride = 1024;
  co.maxClosuresOverride = 8;
  auto compiled = compileText("half_coat.json", test::material(R"(
      "coat": {"kind": "slab", "diffuse_albedo": 0, "f0": 0.04, "roughness": 0.06, "sss_mfp": [1000, 0.19, 0.088]},
      "half_coat": {"kind": "coverage_weight", "a": "coat", "weight": 0.5},
      "base": {"kind": "slab", "diffuse_albedo": 0.8, "f0": 0.04, "roughness": 0.4},
      "root": {"kind": "vertical", "top": "half_coat", "base": "base", "thickness": 0.1})"),
                              co, d);
  ASSERT_TRUE(compiled) << d.formatAll();
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(*compiled, o), accuracy::truthOf(*compiled, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), row.nov >= 0.2 ? 0.05 : 0.08);
    for (int k = 0; k < 3; ++k) EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, ADarkConductorFollowsItsOwnFresnelCurve) {
  // Issue 19, step 23 (bench/materials/dark_grey_conductor.json): a grey
  // conductor of F0 0.25 at roughness 0.5. The truth's conductor (Gulbrandsen's
  // complex IOR from F0 and its edge tint) rises earlier toward grazing angles
  // than Schlick's curve, which every conductor followed: -1.2 / -3.6 / -7.9 /
  // -10.5 / -9.4 / -6.7 % (NoV 1 / 0.8 / 0.6 / 0.4 / 0.2 / 0.1, 32,768 walks);
  // with its own curve per channel (substrate_fresnel_curve) -1.1 / -1.8 / -3.2
  // / -4.5 / -5.0 / -3.4 %. The bound (6 %) holds that, with the walks' noise at
  // 8,192; Schlick's curve fails it at NoV 0.6 … 0.1.
  const CompileResult r = compileSlab(R"({"kind": "slab", "diffuse_albedo": 0, "f0": 0.25, "roughness": 0.5})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.06);
    for (int k = 0; k < 3; ++k) EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
    std::printf("[ accuracy ] dark grey conductor, NoV %.1f: %+.2f %%\n", row.nov, 100 * *row.relError);
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, ALowIorDielectricFollowsItsOwnFresnelCurve) {
  // Issue 19, step 24 (bench/materials/low_ior_dielectric.json): a dielectric
  // of F0 0.005 (IOR 1.15) over a Lambertian of albedo 0.05 at roughness 0.5.
  // The truth walks the exact Fresnel of that IOR, which rises toward grazing
  // later than chi (IOR 1.5's), every interface's curve before: +7.1 / +21.4 /
  // +36.6 / +40.3 / +36.5 % at NoV 0.8 … 0.1 (32,768 walks); with its own
  // curve (substrate_fresnel_curve) within 1.5 %. The bound (5 %) holds that,
  // with the walks' noise at 8,192; chi fails it from NoV 0.8.
  const CompileResult r =
      compileSlab(R"({"kind": "slab", "diffuse_albedo": 0.05, "f0": 0.005, "roughness": 0.5})");
  accuracy::Options o = cheap(2);
  o.samples = 8192;
  const accuracy::Comparison c = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
  int rows = 0;
  for (const auto& row : c.rows) {
    SCOPED_TRACE(row.nov);
    ASSERT_TRUE(row.relError && row.furnaceAnalytic);
    EXPECT_LE(std::fabs(*row.relError), 0.05);
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE((*row.furnaceAnalytic)[k], 1.001);
      EXPECT_GE((*row.furnaceAnalytic)[k], 0.97);
    }
    std::printf("[ accuracy ] low-IOR dielectric, NoV %.1f: %+.2f %%\n", row.nov, 100 * *row.relError);
    ++rows;
  }
  EXPECT_EQ(rows, 6);
}

TEST(Accuracy, SameSamplesSameBitsWhateverTheThreads) {
  const CompileResult r =
      compileSlab(R"({"kind": "slab", "diffuse_albedo": [0.6, 0.3, 0.2], "f0": 0.04, "roughness": 0.3})");
  accuracy::Options one = cheap(1), two = cheap(2);
  one.samples = two.samples = 256;
  const accuracy::Comparison a = accuracy::compare(accuracy::analyticOf(r, one), accuracy::truthOf(r, one));
  const accuracy::Comparison b = accuracy::compare(accuracy::analyticOf(r, two), accuracy::truthOf(r, two));
  const accuracy::Comparison again = accuracy::compare(accuracy::analyticOf(r, two), accuracy::truthOf(r, two));
  ASSERT_EQ(a.rows.size(), accuracy::kNoV.size());
  ASSERT_EQ(b.rows.size(), a.rows.size());
  int compared = 0;
  for (std::size_t v = 0; v < a.rows.size(); ++v)
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(sameBits(a.rows[v].truth[k], b.rows[v].truth[k]));
      EXPECT_TRUE(sameBits(a.rows[v].truthStderr[k], b.rows[v].truthStderr[k]));
      EXPECT_TRUE(sameBits(a.rows[v].analytic[k], b.rows[v].analytic[k]));
      EXPECT_TRUE(sameBits(b.rows[v].truth[k], again.rows[v].truth[k]));
      EXPECT_TRUE(sameBits(*a.rows[v].brdfP95RelError, *b.rows[v].brdfP95RelError));
      ++compared;
    }
  EXPECT_EQ(compared, 18);
  // Another seed is another estimate (the seeds do reach the walks).
  accuracy::Options other = one;
  other.seed = 2;
  EXPECT_FALSE(sameBits(accuracy::truthOf(r, other).rows[0].albedo.value[0], a.rows[0].truth[0]));
}

TEST(Accuracy, AGlintIsComparedAtItsMean) {
  // The truth walks a glint as the plain lobe; the analytic side takes the
  // glint's expectation (density 1) rather than its noise at one shading point
  // (car_paint read -41 % that way): a glinting slab's analytic figures are
  // the plain slab's, bit for bit.
  const std::string plain = R"({"kind": "slab", "diffuse_albedo": [0.3, 0.2, 0.1], "f0": 0.5, "roughness": 0.3)";
  const CompileResult glint = compileSlab(plain + R"(, "glint_value": 0.3, "glint_uv": [0.25, 0.5]})");
  const CompileResult none = compileSlab(plain + "}");
  ASSERT_NE(glint.after.bytes(), none.after.bytes()) << "the glint is stored: the two differ as compiled";
  const accuracy::Analytic a = accuracy::analyticOf(glint, cheap(1)), b = accuracy::analyticOf(none, cheap(1));
  ASSERT_EQ(a.rows.size(), accuracy::kNoV.size());
  int compared = 0;
  for (std::size_t v = 0; v < a.rows.size(); ++v)
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(sameBits(a.rows[v].albedo[k], b.rows[v].albedo[k])) << "NoV " << a.rows[v].nov;
      for (std::size_t j = 0; j < a.rows[v].grid.size(); ++j, ++compared)
        EXPECT_TRUE(sameBits(a.rows[v].grid[j][k], b.rows[v].grid[j][k]));
    }
  EXPECT_EQ(compared, 6 * 48 * 3);
}

TEST(Accuracy, ABlackTruthIsReportedNotPassed) {
  // compare() on a truth that is 0 everywhere, or as good as 0 (a conductor of
  // F0 0 reflects 1e-67 in the walk, from rounding): no relative error, no BRDF
  // error, and problems that say so (the command exits non-zero on them).
  int checked = 0;
  for (double level : {0.0, 1e-67}) {
    accuracy::Truth black;
    accuracy::Analytic analytic;
    for (double nov : accuracy::kNoV) {
      reference::Estimate tiny;
      tiny.value = {level, level, level};
      black.rows.push_back({nov, tiny, std::vector<reference::Estimate>(48, tiny), std::nullopt});
      analytic.rows.push_back({nov, accuracy::Rgb{0.1, 0.1, 0.1}, std::vector<accuracy::Rgb>(48, {0.01, 0.01, 0.01}),
                               1, 0, std::nullopt});
    }
    const accuracy::Comparison c = accuracy::compare(analytic, black);
    ASSERT_EQ(c.rows.size(), accuracy::kNoV.size());
    for (const auto& row : c.rows) {
      EXPECT_FALSE(row.relError) << level;
      for (const auto& e : row.channelRelError) EXPECT_FALSE(e) << level;
      EXPECT_FALSE(row.brdfMedianRelError) << level;
      EXPECT_FALSE(row.brdfP95RelError) << level;
      EXPECT_EQ(row.brdfCounted, 0) << level;
    }
    ASSERT_FALSE(c.problems.empty());
    EXPECT_NE(c.problems.front().find("black at every NoV"), std::string::npos) << c.problems.front();
    EXPECT_EQ(c.problems.size(), accuracy::kNoV.size() + 1) << level;
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

TEST(Accuracy, TheJsonHasEveryKeyOfEveryRow) {
  const CompileResult r = compileSlab(R"({"kind": "slab", "diffuse_albedo": 0.5, "f0": 0.04, "roughness": 0.5})");
  const accuracy::Options o = cheap(2);
  accuracy::Report report;
  report.material = "m";
  report.options = o;
  report.vsAuthored = accuracy::compare(accuracy::analyticOf(r, o), accuracy::truthOf(r, o));
  const auto j = nlohmann::json::parse(accuracy::formatJson(report));
  for (const char* key : {"truth_samples", "excluded", "problems", "rows", "truth_compiled", "brdf_threshold", "grid"})
    EXPECT_TRUE(j.contains(key)) << key;
  ASSERT_EQ(j["rows"].size(), accuracy::kNoV.size());
  int checked = 0;
  for (const auto& row : j["rows"])
    for (const char* key : {"nov", "analytic", "truth", "truth_stderr", "rel_error", "brdf_median_rel_error",
                            "brdf_p95_rel_error", "reciprocity_max_ratio", "furnace_analytic", "furnace_truth"}) {
      EXPECT_TRUE(row.contains(key)) << key;
      ++checked;
    }
  EXPECT_EQ(checked, 60);
  EXPECT_NE(accuracy::formatTable(report).find("rel_err"), std::string::npos);
}

}  // namespace accuracy_test
}  // namespace substratec
