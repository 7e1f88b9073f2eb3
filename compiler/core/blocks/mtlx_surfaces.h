// The MaterialX shading models that are also building blocks, one unit each,
// each turning its shader's parameters (SurfaceParams: a MaterialX node's
// inputs, or a block's pins) into a LayeredSurface with its own formulas
// (docs/import.md, "MaterialX"):
//   mtlx_standard_surface.cc      Autodesk Standard Surface 1.0.1 (block standard_surface)
//   mtlx_open_pbr.cc              OpenPBR Surface 1.1 (block open_pbr_surface)
//   mtlx_disney_principled.cc     Disney principled 2015 (block disney_principled)
// (import/mtlx_surfaces.h has MaterialX's other models: gltf_pbr, UsdPreviewSurface, hair.)
#pragma once
#include "blocks/layered_surface.h"
#include "blocks/surface_params.h"

namespace substratec::blocks {

LayeredSurface standardSurface(SurfaceParams& params, NodeWriter& w);
LayeredSurface openPbrSurface(SurfaceParams& params, NodeWriter& w);
LayeredSurface disneyPrincipled(SurfaceParams& params, NodeWriter& w);

// Shared by the units: MaterialX's roughness_anisotropy (Standard Surface):
// a = max(r², ε), aspect = sqrt(1 − min(A, 0.98)), at = min(a / aspect, 1),
// ab = a · aspect, as the slab's (roughness, anisotropy).
/// Transmission of Standard Surface and OpenPBR (`weight` not 0): the
/// transmitting dielectric tinted by transmission_color, and a warning for
/// each of what is not represented (refraction; transmission_depth, whose
/// tint is applied once; scatter; the model's dispersion input `dispersion`).
void mtlxTransmission(SurfaceParams& params, const Value& weight, const char* dispersion, LayeredSurface& s);

RoughnessAnisotropy mtlxRoughnessAnisotropy(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                            const std::string& prefix);

/// An anisotropic roughness model (values named with `prefix`).
using AnisotropyModel = RoughnessAnisotropy (*)(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                                const std::string& prefix);
/// The slab's (roughness, anisotropy): `roughness` alone (no anisotropy) when
/// `anisotropy` is null or 0, else through `model`, its roughness named
/// "<prefix>anisotropic_roughness" (the specular's without the prefix).
RoughnessAnisotropy roughnessPins(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                  const std::string& prefix, AnisotropyModel model = mtlxRoughnessAnisotropy);

}  // namespace substratec::blocks

namespace substratec::blocks {

/// A parameter a MaterialX model's unit reads, as it reads it.
struct ModelParam {
  std::string name, type;  // MaterialX name and type ("float", "color3", "vector3", "boolean")
  std::vector<double> def;
  ParamKind kind = ParamKind::Plain;
  bool constantOnly = true;  // read only as a constant (C), never as a value (P)
};

using SurfaceUnit = LayeredSurface (*)(SurfaceParams& params, NodeWriter& w);

/// The unit of the MaterialX model `kind` that is a building block
/// ("standard_surface", "open_pbr_surface", "disney_principled"), or null.
SurfaceUnit blockModelUnit(const std::string& kind);

/// The parameters the block model `kind`'s unit reads: found once by running
/// it against a probe that gives every parameter as a varying value, so that
/// every branch that reads one runs. They are the block's pins.
const std::vector<ModelParam>& blockModelParams(const std::string& kind);

/// The block that says what `params` gives of model `kind`'s parameters:
/// each given parameter as the source has it (a value read as a constant
/// only, as its constant). What the MaterialX importer writes.
Json blockModelBlock(const std::string& kind, SurfaceParams& params);

/// `block`'s pins as a unit reads them; "$input" pins read as constants take
/// the input's default in `document`; warnings go to `warnings`.
class BlockParams final : public SurfaceParams {
 public:
  BlockParams(const Json& block, const Json& document, std::vector<std::string>& warnings)
      : block_(block), document_(document), warnings_(warnings) {}
  Value param(const std::string& name, const std::string& type, const std::vector<double>& def,
              ParamKind kind) override;
  std::optional<std::vector<double>> constant(const std::string& name, const std::string& type,
                                              const std::vector<double>& def) override;
  bool given(const std::string& name) const override { return block_.contains(name); }
  void warn(const std::string& what) override { warnings_.push_back(what); }

 private:
  const Json& block_;
  const Json& document_;
  std::vector<std::string>& warnings_;
};

}  // namespace substratec::blocks
