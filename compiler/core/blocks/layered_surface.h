// The Substrate construction every imported shading model ends in: an
// uber-surface (a metal/dielectric base with optional subsurface, fuzz, thin
// film and emission; a transmitting dielectric; a coat; a presence) described
// in physical terms, written as slabs and operators. Each shading model's unit
// (gltf_pbr.cc, mtlx_*.cc) converts its own parameters into this description
// with its own formulas (docs/import.md); this unit owns the slab layout:
//
//   base slab     diffuse = diffuseColor·(1 − metallic), F0 = vlerp(specularF0, baseColor, metallic),
//                 F90 = vlerp(specularF90, metalF90, metallic) (only when either is given), through
//                 the metalness helper when the dielectric F0 is a grey literal <= 0.08; thin film
//                 F0 = vlerp(F0, thin_film(F0, F90, d, ior).f0, filmWeight); fuzz, SSS, emission.
//   transmission  a copy of the base slab without diffuse, its medium the transmittance through
//                 the surface (transmittance_to_mfp over the surface thickness), mixed in by a
//                 horizontal with mix = transmission·(1 − metallic); translucent_colored.
//   coat          vertical(top = coat slab (albedo 0, its own F0, roughness, normal, tangent, a
//                 medium of the per-pass coat transmittance), base = the rest); a coat weight
//                 below 1 is a coverage_weight on the top.
//   presence      coverage_weight(root, opacity): masked (weight = a 0.001-wide ramp around the
//                 cutoff) or translucent.
// Weights that are the literal 0 build nothing; the literal 1 builds no mix.
#pragma once
#include <string>

#include "blocks/material_writer.h"

namespace substratec::blocks {

enum class AlphaMode { Opaque, Mask, Blend };

/// What every importer says of a transmitting material (a warning).
inline constexpr const char* kTransmissionNote =
    "refraction and the blur of rough transmission are not represented; the background is seen through the "
    "slab's transmittance (blend mode translucent_colored)";

struct LayeredSurface {
  /// The surface is an unlit BSDF (KHR_materials_unlit): `emissive` is its
  /// radiance, `opacity` and the alpha mode its presence; nothing else is read.
  bool unlit = false;
  // Base.
  Value baseColor;      // color: the dielectric's diffuse colour and the metal's F0 (required)
  Value diffuseColor;   // color: the dielectric's diffuse colour when it is not baseColor
  Value metallic;       // float; null: 0
  Value specularF0;     // float or color: the dielectric's F0; null: 0.04
  Value specularF90;    // float or color: the dielectric's F90; null: 1
  Value metalF90;       // color: the metal's F90 (edge tint); null: 1
  Value roughness;      // float (required)
  Value anisotropy;     // float in [-1, 1]; null: 0
  Value tangent;        // vec3, tangent space; null: the geometric tangent
  Value normal;         // vec3, tangent space; null: the geometric normal
  Value sssMfp;         // color, metres: subsurface mean free path; null: none
  std::string sssType;  // "" (derived) or "wrap"
  Value fuzzAmount, fuzzColor, fuzzRoughness;
  Value filmWeight;     // float; null or 0: no thin film
  Value filmThickness;  // float, metres
  Value filmIor;        // float
  Value emissive;       // color, linear radiance; null: none
  // Transmission (of the dielectric part).
  Value transmission;   // float weight; null or 0: none
  Value transmittance;  // color through the surface once, at normal incidence; null: 1
  // Coat.
  Value coatWeight;     // float; null or 0: no coat
  Value coatF0;         // float or color; null: 0.04
  Value coatRoughness;  // float; null: 0
  Value coatAnisotropy, coatTangent, coatNormal;
  Value coatTransmittance;  // color per pass through the coat, at normal incidence; null: clear
  // Presence.
  Value opacity;        // float; null: 1
  AlphaMode alphaMode = AlphaMode::Opaque;
  double alphaCutoff = 0.5;
  bool thinWalled = false;
};

/// The nodes of `s` in `w`; returns its root (the presence's coverage weight
/// when it has one). A building block's expansion (blocks.h).
Value layeredSurfaceNodes(const LayeredSurface& s, NodeWriter& w);
/// The material settings `s` needs: "blend_mode" (translucent_colored when it
/// transmits, masked or translucent_grey with a presence; absent when opaque)
/// and "thin_surface" (when thin-walled).
Json layeredSurfaceSettings(const LayeredSurface& s);
/// True when the presence of `s` folds to the constant 0 (an alpha of 0, or
/// below a mask's cutoff, given as a literal): its nodes then take the
/// writer's invisiblePresence().
bool presenceFoldsToZero(const LayeredSurface& s);
/// `root` as the output of `w`, with the settings `s` needs
/// (layeredSurfaceSettings): the end of every importer's material.
void writeSurfaceOutput(const LayeredSurface& s, const Value& root, MaterialWriter& w);
/// Writes `s` into `w`: its nodes, its settings and its root as the output (the importers).
void writeLayeredSurface(const LayeredSurface& s, MaterialWriter& w);
/// `base` under the coat of `s` (coatWeight, coatF0, coatRoughness,
/// coatAnisotropy, coatTangent, coatNormal, coatTransmittance): the coat slab,
/// its coverage weight when coatWeight is not the literal 1, and the vertical.
Value coatedRoot(const LayeredSurface& s, NodeWriter& w, const Value& base);
/// The base's diffuse albedo, F0 and F90 (null: none) from the metallic workflow of `s`.
void baseReflectance(const LayeredSurface& s, NodeWriter& w, bool metal, Value& diffuse, Value& f0, Value& f90);

/// GGX alphas along the tangent and the bitangent, as a (roughness,
/// anisotropy) pair of the slab: a = (at + ab) / 2, roughness = sqrt(a),
/// anisotropy = (at − ab) / (at + ab) — exact for Substrate's
/// ax = a (1 + A), ay = a (1 − A).
struct RoughnessAnisotropy {
  Value roughness, anisotropy;
};
RoughnessAnisotropy fromAlphas(const Value& alphaT, const Value& alphaB);

/// The tangent-space tangent rotated by `angle` radians about the normal
/// (a literal angle gives a literal vector, else rotation_to_tangent).
Value rotatedTangent(const Value& angle);

}  // namespace substratec::blocks
