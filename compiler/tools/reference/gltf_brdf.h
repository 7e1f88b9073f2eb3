// An independent oracle for imported glTF materials: the glTF 2.0
// specification's reference BRDF (Appendix B: the metal/dielectric mix of a
// GGX lobe — Trowbridge-Reitz D, height-correlated Smith V — and Lambert,
// with Schlick Fresnel), with the ratified extensions' formulas for
// KHR_materials_ior and _specular (dielectric F0/F90 and the max-channel
// fresnel_mix), _clearcoat (fresnel_coat on top), _sheen (Charlie lobe over
// the base with the albedo scaling min(1 − max(sheen)·E(NoV), 1 −
// max(sheen)·E(NoL))), _anisotropy (anisotropic GGX along the rotated
// tangent), and, for light and view above the surface, _transmission and
// _diffuse_transmission (their BTDFs are then zero: the dielectric's diffuse
// is scaled by 1 − transmission, the diffuse by 1 − diffuse transmission).
// Double precision, written from the specification, sharing nothing with the
// Substrate model (reference.h) it judges.
#pragma once
#include <array>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/pipeline.h"

namespace substratec::reference {

using Rgb = std::array<double, 3>;

struct GltfMaterial {
  Rgb baseColor{1, 1, 1};
  double metallic = 1, roughness = 1;
  double ior = 1.5, specular = 1;
  Rgb specularColor{1, 1, 1};
  double clearcoat = 0, clearcoatRoughness = 0;
  Rgb sheenColor{0, 0, 0};
  double sheenRoughness = 0;
  double anisotropyStrength = 0, anisotropyRotation = 0;
  double transmission = 0, diffuseTransmission = 0;
  bool unlit = false;
  double coverage = 1;  // alphaMode BLEND: alpha; MASK: alpha >= alphaCutoff ? 1 : 0 (the share the surface adds)
};

/// The glTF parameters of a material without textures (factors and the
/// extensions above); nullopt with `*why` when it uses a texture or an
/// extension the oracle does not model (reflection is all it judges, so
/// emission, volume, dispersion and diffuse roughness are not needed).
std::optional<GltfMaterial> gltfMaterialOf(const nlohmann::ordered_json& material, std::string* why);

/// The reflected radiance toward V of a unit directional light from L, f(V, L)·NoL, in the
/// tangent frame (N = +z, T = +x, B = +y); zero when V or L is below the surface.
Rgb gltfReflectance(const GltfMaterial& m, const Rgb& V, const Rgb& L);

/// E(mu): the directional albedo of glTF's sheen lobe (Charlie D, the
/// Estevez-Kulla visibility) of white sheen at roughness `r`, integrated
/// numerically (the specification leaves it to a table).
double gltfSheenAlbedo(double mu, double r);

/// The fixed probes of the comparison: directions above the surface in the
/// tangent frame (a Fibonacci set), views and lights alike.
const std::vector<Rgb>& gltfProbeDirections();

struct GltfComparison {
  double relMse = 0;       // mean((x − y)² / (y² + 0.01)), x Substrate, y the oracle
  double energyRatio = 0;  // sum x / sum y (1: the same total reflection; 0 when y is 0)
};
/// The Substrate material `r` (the CPU reference's direct light with
/// `diffuseModel`, inputs at their defaults) against the oracle, over every
/// view × light pair of gltfProbeDirections() and channel.
GltfComparison compareWithGltf(const CompileResult& r, const GltfMaterial& m, int diffuseModel);

}  // namespace substratec::reference
