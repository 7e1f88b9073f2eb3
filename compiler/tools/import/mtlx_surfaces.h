// MaterialX's shading models: the ones that are also building blocks
// (Standard Surface, OpenPBR, Disney principled: blocks/mtlx_surfaces.h) and
// the others, one unit each, each turning its shader node's inputs (through
// SurfaceParams) into a LayeredSurface with its own formulas (docs/import.md,
// "MaterialX"):
//   mtlx_gltf_pbr.cc              MaterialX's gltf_pbr (through gltf_pbr.h; block gltf_pbr)
//   mtlx_usd_preview_surface.cc   UsdPreviewSurface
// and a `surface` of MaterialX's chiang_hair_bsdf, written straight as the
// format's hair node (chiangHairSurface in mtlx_import.cc; mtlx_hair.h).
#pragma once
#include <pugixml.hpp>

#include "blocks/gltf_pbr.h"
#include "blocks/mtlx_surfaces.h"
#include "import/mtlx_graph.h"

namespace substratec::import {

// The value writer, the layered surface and the shared models live in
// blocks/, shared with the building blocks' expansion.
using namespace substratec::blocks;  // NOLINT(google-build-using-namespace)

/// A MaterialX shader node's inputs as a unit reads them (MtlxValues).
class ShaderParams final : public SurfaceParams {
 public:
  ShaderParams(pugi::xml_node shader, MtlxValues& values) : n_(shader), v_(values) {}
  Value param(const std::string& name, const std::string& type, const std::vector<double>& def,
              ParamKind kind) override {
    return v_.param(n_, name, type, def, kind);
  }
  std::optional<std::vector<double>> constant(const std::string& name, const std::string& type,
                                              const std::vector<double>& def) override {
    return v_.constant(n_, name, type, def);
  }
  bool given(const std::string& name) const override { return v_.given(n_, name); }
  void warn(const std::string& what) override { v_.warn(n_, what); }

 private:
  pugi::xml_node n_;
  MtlxValues& v_;
};

LayeredSurface mtlxGltfPbr(SurfaceParams& params, NodeWriter& w);
/// MaterialX's gltf_pbr as the glTF parameters (the gltf_pbr block's pins).
GltfPbr mtlxGltfPbrParams(SurfaceParams& params);
LayeredSurface usdPreviewSurface(SurfaceParams& params, NodeWriter& w);
/// A `surface` whose bsdf is a chiang_hair_bsdf: the hair node, the output of `w`.
void chiangHairSurface(pugi::xml_node surface, pugi::xml_node bsdf, MtlxValues& v, MaterialWriter& w);

}  // namespace substratec::import
