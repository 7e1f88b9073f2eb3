// The glTF 2.0 reference BRDF (compiler/tools/reference/gltf_brdf.h), the oracle of
// the imported glTF materials: values worked out by hand from the
// specification's formulas, reciprocity, energy bounds; and the import
// measured against it where both models agree (a dielectric, with Lambert).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "import/import.h"
#include "pipeline/pipeline.h"
#include "reference/gltf_brdf.h"
#include "reference/reference.h"

using namespace substratec;
using reference::GltfMaterial;
using reference::Rgb;

namespace {


Rgb dir(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

/// The directional albedo: integral of f cos over the hemisphere (midpoint rule).
double albedo(const GltfMaterial& m, const Rgb& V) {
  const int nt = 200, np = 200;
  double e = 0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double mu = (i + 0.5) / nt, phi = 2 * std::numbers::pi * (j + 0.5) / np;
      const Rgb L{std::sqrt(1 - mu * mu) * std::cos(phi), std::sqrt(1 - mu * mu) * std::sin(phi), mu};
      e += reference::gltfReflectance(m, V, L)[0];
    }
  return e * (1.0 / nt) * (2 * std::numbers::pi / np);
}

}  // namespace

TEST(GltfOracle, NormalIncidenceIsTheSpecificationsFormula) {
  GltfMaterial m;
  m.baseColor = {0.5, 0.25, 1.0};
  m.metallic = 0;
  m.roughness = 0.5;
  const Rgb N{0, 0, 1};
  const Rgb f = reference::gltfReflectance(m, N, N);
  // V = L = N: VoH = 1, F = 0.04; D = 1 / (pi a²), V = 0.5 / (1 + 1); diffuse (1 − F) c / pi.
  const double a = 0.25, spec = 0.04 / (std::numbers::pi * a * a) * 0.25;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], (1 - 0.04) * m.baseColor[k] / std::numbers::pi + spec, 1e-12);
  m.metallic = 1;  // a metal: F0 = base colour, no diffuse
  const Rgb g = reference::gltfReflectance(m, N, N);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(g[k], m.baseColor[k] / (std::numbers::pi * a * a) * 0.25, 1e-12);
}

TEST(GltfOracle, TheCoreBrdfIsReciprocal) {
  GltfMaterial m;
  m.baseColor = {0.7, 0.3, 0.2};
  m.metallic = 0.3;
  m.roughness = 0.4;
  m.anisotropyStrength = 0.5;
  m.anisotropyRotation = 0.7;
  for (double tv : {0.1, 0.6, 1.2})
    for (double tl : {0.2, 0.9, 1.4}) {
      const Rgb V = dir(tv, 0.3), L = dir(tl, 2.1);
      const Rgb a = reference::gltfReflectance(m, V, L), b = reference::gltfReflectance(m, L, V);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(a[k] / L[2], b[k] / V[2], 1e-12 * (1 + a[k] / L[2]));
    }
}

TEST(GltfOracle, SingleScatteringLosesEnergyOnRoughMetals) {
  GltfMaterial m;  // white metal
  m.metallic = 1;
  const Rgb V = dir(std::acos(0.5), 0);
  m.roughness = 0.2;
  const double smooth = albedo(m, V);
  m.roughness = 1;
  const double rough = albedo(m, V);
  EXPECT_LE(smooth, 1.0);
  EXPECT_GT(smooth, 0.95);
  // glTF's GGX is single scattering: a white metal at roughness 1 reflects about
  // half of the light at NoV = 0.5 (what Substrate's energy compensation restores).
  EXPECT_LT(rough, 0.6);
  EXPECT_GT(rough, 0.4);
  RecordProperty("white_metal_albedo_r1_nov05", std::to_string(rough));
}

TEST(GltfOracle, SheenAlbedoIsAFractionAndScalesTheBase) {
  for (double r : {0.1, 0.5, 1.0})
    for (double mu : {0.05, 0.5, 1.0}) {
      const double e = reference::gltfSheenAlbedo(mu, r);
      EXPECT_GT(e, 0.0) << r << " " << mu;
      EXPECT_LE(e, 1.0) << r << " " << mu;
    }
  GltfMaterial m;
  m.metallic = 0;
  m.roughness = 0.8;
  m.baseColor = {0.5, 0.5, 0.5};
  const Rgb V = dir(0.4, 0), L = dir(0.5, 3.0);
  const Rgb plain = reference::gltfReflectance(m, V, L);
  m.sheenColor = {1, 1, 1};
  m.sheenRoughness = 0.5;
  const Rgb sheen = reference::gltfReflectance(m, V, L);
  const double scale = std::min(1 - reference::gltfSheenAlbedo(V[2], 0.5), 1 - reference::gltfSheenAlbedo(L[2], 0.5));
  EXPECT_GT(sheen[0], plain[0] * scale);  // the sheen lobe on top of the scaled base
}

TEST(GltfOracle, ClearcoatMixesByItsFresnelAtTheView) {
  GltfMaterial m;
  m.metallic = 0;
  m.roughness = 0.5;
  const Rgb V = dir(0.3, 0), L = dir(0.6, 2.0);
  const Rgb base = reference::gltfReflectance(m, V, L);
  m.clearcoat = 0.8;
  m.clearcoatRoughness = 0.3;
  const Rgb coated = reference::gltfReflectance(m, V, L);
  // layer = D · V · NoL of GGX at alpha 0.09; coated = base (1 − w Fc) + w Fc layer, Fc = Schlick(0.04, NoV).
  const Rgb H = [&] {
    Rgb h{V[0] + L[0], V[1] + L[1], V[2] + L[2]};
    const double n = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
    return Rgb{h[0] / n, h[1] / n, h[2] / n};
  }();
  const double a = 0.09, a2 = a * a;
  const double D = a2 / (std::numbers::pi * std::pow(H[2] * H[2] * (a2 - 1) + 1, 2));
  const double Vis = 0.5 / (L[2] * std::sqrt(V[2] * V[2] * (1 - a2) + a2) + V[2] * std::sqrt(L[2] * L[2] * (1 - a2) + a2));
  const double w = 0.8 * (0.04 + 0.96 * std::pow(1 - V[2], 5));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(coated[k], base[k] * (1 - w) + w * D * Vis * L[2], 1e-12);
}

TEST(GltfOracle, AnImportedDielectricAgreesWithTheSpecification) {
  // A plain dielectric: Substrate's model differs from glTF's only by its
  // energy terms (multiple scattering, the diffuse under 1 − E_spec instead of
  // 1 − F(VoH)); with Lambert both agree closely.
  const std::string gltf = R"({"materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.3, 0.1, 1],
                                "metallicFactor": 0, "roughnessFactor": 0.5}}]})";
  Diagnostics d("t.gltf");
  auto imported = import::importText(import::SourceKind::Gltf, "t.gltf", gltf, ".", ReadLimits{}, d);
  ASSERT_TRUE(imported) << d.formatAll();
  auto r = compileText("t", (*imported)[0].text, CompileOptions{}, d);
  ASSERT_TRUE(r) << d.formatAll();
  std::string why;
  auto oracle = reference::gltfMaterialOf(nlohmann::ordered_json::parse(gltf)["materials"][0], &why);
  ASSERT_TRUE(oracle) << why;
  const auto lambert = reference::compareWithGltf(*r, *oracle, reference::kDiffuseLambert);
  EXPECT_LT(lambert.relMse, 0.005);
  EXPECT_NEAR(lambert.energyRatio, 1.0, 0.05);
  const auto chan = reference::compareWithGltf(*r, *oracle, reference::kDiffuseChan2024);
  EXPECT_LT(chan.relMse, 0.02);
}
