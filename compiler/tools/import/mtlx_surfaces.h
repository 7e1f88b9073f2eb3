// The MaterialX shading models, one unit each, each turning its shader
// node's inputs (through MtlxValues) into a LayeredSurface with its own
// formulas (docs/import.md, "MaterialX"):
//   mtlx_standard_surface.cc      Autodesk Standard Surface 1.0.1
//   mtlx_open_pbr.cc              OpenPBR Surface 1.1
//   mtlx_gltf_pbr.cc              MaterialX's gltf_pbr (through gltf_pbr.h)
//   mtlx_usd_preview_surface.cc   UsdPreviewSurface
//   mtlx_disney_principled.cc     Disney principled (2015)
#pragma once
#include <pugixml.hpp>

#include "import/layered_surface.h"
#include "import/mtlx_graph.h"

namespace substratec::import {

LayeredSurface standardSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface openPbrSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface mtlxGltfPbr(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface usdPreviewSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface disneyPrincipled(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);

// Shared by the units: MaterialX's roughness_anisotropy (Standard Surface):
// a = max(r², ε), aspect = sqrt(1 − min(A, 0.98)), at = min(a / aspect, 1),
// ab = a · aspect, as the slab's (roughness, anisotropy).
/// Transmission of Standard Surface and OpenPBR (`weight` not 0): the
/// transmitting dielectric tinted by transmission_color, and a warning for
/// each of what is not represented (refraction; transmission_depth, whose
/// tint is applied once; scatter; the model's dispersion input `dispersion`).
void mtlxTransmission(pugi::xml_node shader, MtlxValues& v, const Value& weight, const char* dispersion,
                      LayeredSurface& s);

RoughnessAnisotropy mtlxRoughnessAnisotropy(const Value& roughness, const Value& anisotropy, MaterialWriter& w,
                                            const std::string& prefix);

}  // namespace substratec::import
