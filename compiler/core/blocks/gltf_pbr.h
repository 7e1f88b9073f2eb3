// The glTF 2.0 PBR model (metallic-roughness and the ratified KHR_materials_*
// extensions, plus the DisplayXR KHR_materials_coat / KHR_materials_fuzz
// drafts) in Substrate terms: the glTF parameters, already multiplied by their
// textures, turned into a LayeredSurface (blocks/layered_surface.h) with the
// formulas of the glTF specification (docs/import.md, "glTF"). The mapping
// unit of the `gltf_pbr` building block (its pins are GltfPbr's members,
// gltfPbrSignature), of the glTF reader (import/gltf_import.cc, which writes
// that block) and of MaterialX's gltf_pbr node (import/mtlx_gltf_pbr.cc).
#pragma once
#include "blocks/layered_surface.h"
#include "blocks/material_writer.h"
#include "passes/resolve.h"
#include "substrate_constants.h"  // runtime_shaders/

namespace substratec::blocks {

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
LayeredSurface gltfPbrSurface(const GltfPbr& g, NodeWriter& w);

/// The `gltf_pbr` block's pins: GltfPbr's members in snake_case (base_color,
/// alpha, metallic, ..., alpha_mode "opaque" | "mask" | "blend").
BlockSignature gltfPbrSignature();
/// The block that says `g` (`{"kind": "gltf_pbr", ...}`, the pins not given left out).
Json gltfPbrBlock(const GltfPbr& g);
/// The GltfPbr a checked `gltf_pbr` block says (gltfPbrBlock's inverse).
GltfPbr gltfPbrOfBlock(const Json& block);
/// `g` into `w` as one `gltf_pbr` block (node "surface", the output) and the
/// settings its surface needs (layeredSurfaceSettings): what the importers
/// write. An alpha whose presence folds to 0 becomes w's invisiblePresence().
void writeGltfPbrBlock(GltfPbr g, MaterialWriter& w);

/// The SUBSTRATE_SSS_WRAP_MFP_SCALE of the runtime (metres,
/// runtime_shaders/substrate_constants.h): wrap amount w = mfp / (mfp + scale),
/// so mfp = scale · w / (1 − w).
inline constexpr double kWrapMfpScale = SUBSTRATE_SSS_WRAP_MFP_SCALE;

}  // namespace substratec::blocks
