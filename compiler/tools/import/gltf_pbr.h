// The glTF 2.0 PBR model (metallic-roughness and the ratified KHR_materials_*
// extensions, plus the DisplayXR KHR_materials_coat / KHR_materials_fuzz
// drafts) in Substrate terms: the glTF parameters, already multiplied by their
// textures, turned into a LayeredSurface (import/layered_surface.h) with the
// formulas of the glTF specification (docs/import.md, "glTF"). Used by the
// glTF reader (gltf_import.cc) and by MaterialX's gltf_pbr node
// (mtlx_gltf_pbr.cc), which has the same parameters.
#pragma once
#include "import/layered_surface.h"
#include "import/material_writer.h"
#include "substrate_constants.h"  // runtime_shaders/

namespace substratec::import {

/// The glTF parameters of one material. A null Value is "not given" (the
/// specification's default); colours are linear RGB.
struct GltfPbr {
  Value baseColor;                 // color (baseColorFactor.rgb × texture.rgb); null: 1
  Value alpha;                     // float (baseColorFactor.a × texture.a); null: 1
  Value metallic, roughness;       // floats; null: 1, 1
  Value normal;                    // tangent-space vec3 (normal texture, scaled); null: geometric
  Value emissive;                  // color (factor × texture × emissive_strength); null: none
  Value ior;                       // KHR_materials_ior; null: 1.5
  Value specular, specularColor;   // KHR_materials_specular; null: 1, white
  Value clearcoat, clearcoatRoughness, clearcoatNormal;                   // KHR_materials_clearcoat
  Value coat, coatRoughness, coatIor, coatColor, coatNormal;              // KHR_materials_coat
  Value coatAnisotropyStrength, coatAnisotropyRotation;
  Value sheenColor, sheenRoughness;                                       // KHR_materials_sheen
  Value fuzz, fuzzColor, fuzzRoughness;                                   // KHR_materials_fuzz
  Value transmission;                                                     // KHR_materials_transmission
  Value thickness, attenuationColor;                                      // KHR_materials_volume
  double attenuationDistance = 0;  // 0: infinite (no attenuation)
  Value iridescence, iridescenceIor, iridescenceThickness;                // KHR_materials_iridescence (nm)
  Value anisotropyStrength;        // KHR_materials_anisotropy: float
  Value anisotropyDirection;       // vec2 in the tangent plane (texture rg·2−1); null: the tangent
  double anisotropyRotation = 0;   // radians, counter-clockwise from the tangent
  Value diffuseTransmission, diffuseTransmissionColor;                    // KHR_materials_diffuse_transmission
  bool unlit = false;              // KHR_materials_unlit
  AlphaMode alphaMode = AlphaMode::Opaque;
  double alphaCutoff = 0.5;
};

/// The surface of `g` (may add value nodes to `w` for values used twice).
LayeredSurface gltfPbrSurface(const GltfPbr& g, MaterialWriter& w);

/// The SUBSTRATE_SSS_WRAP_MFP_SCALE of the runtime (metres,
/// runtime_shaders/substrate_constants.h): wrap amount w = mfp / (mfp + scale),
/// so mfp = scale · w / (1 − w).
inline constexpr double kWrapMfpScale = SUBSTRATE_SSS_WRAP_MFP_SCALE;

}  // namespace substratec::import
