// The MaterialX shading models, one unit each, each turning its shader
// node's inputs (through MtlxValues) into a LayeredSurface with its own
// formulas (docs/import.md, "MaterialX"):
//   mtlx_standard_surface.cc      Autodesk Standard Surface 1.0.1
//   mtlx_open_pbr.cc              OpenPBR Surface 1.1
//   mtlx_gltf_pbr.cc              MaterialX's gltf_pbr (through gltf_pbr.h)
//   mtlx_usd_preview_surface.cc   UsdPreviewSurface
//   mtlx_disney_principled.cc     Disney principled (2015)
// and a `surface` of MaterialX's chiang_hair_bsdf, written straight as the
// format's hair node (chiangHairSurface in mtlx_import.cc; mtlx_hair.h).
#pragma once
#include <pugixml.hpp>

#include "blocks/layered_surface.h"
#include "import/mtlx_graph.h"

namespace substratec::import {

// The value writer, the layered surface and the glTF model live in blocks/,
// shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

LayeredSurface standardSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface openPbrSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface mtlxGltfPbr(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface usdPreviewSurface(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
LayeredSurface disneyPrincipled(pugi::xml_node shader, MtlxValues& v, MaterialWriter& w);
/// A `surface` whose bsdf is a chiang_hair_bsdf: the hair node, the output of `w`.
void chiangHairSurface(pugi::xml_node surface, pugi::xml_node bsdf, MtlxValues& v, MaterialWriter& w);

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

/// An anisotropic roughness model (values named with `prefix`).
using AnisotropyModel = RoughnessAnisotropy (*)(const Value& roughness, const Value& anisotropy, MaterialWriter& w,
                                                const std::string& prefix);
/// The slab's (roughness, anisotropy): `roughness` alone (no anisotropy) when
/// `anisotropy` is null or 0, else through `model`, its roughness named
/// "<prefix>anisotropic_roughness" (the specular's without the prefix).
RoughnessAnisotropy roughnessPins(const Value& roughness, const Value& anisotropy, MaterialWriter& w,
                                  const std::string& prefix, AnisotropyModel model = mtlxRoughnessAnisotropy);

/// A shading node's inputs as the units read them: P(name, type, default
/// [, kind]) its value (MtlxValues::param); C(name, type, default) its
/// constant at import, the default when it varies (MtlxValues::constant).
struct MtlxParam {
  pugi::xml_node n;
  MtlxValues& v;
  Value operator()(const char* name, const char* type, const std::vector<double>& def,
                   ParamKind k = ParamKind::Plain) const {
    return v.param(n, name, type, def, k);
  }
};
struct MtlxConstant {
  pugi::xml_node n;
  MtlxValues& v;
  std::vector<double> operator()(const char* name, const char* type, const std::vector<double>& def) const {
    return v.constant(n, name, type, def).value_or(def);
  }
};

}  // namespace substratec::import
