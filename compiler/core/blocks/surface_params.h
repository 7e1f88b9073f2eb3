// Where a shading model's unit reads its parameters: a MaterialX shader node
// (import/mtlx_graph.h's MtlxValues, through import's ShaderParams) or a
// building block's pins (blocks/mtlx_blocks.cc). The unit asks for each
// parameter by its source name, MaterialX type and default, and does not
// know which it reads from: the importer's flat form and the block's
// expansion are the same code.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "blocks/material_writer.h"

namespace substratec::blocks {

/// How a shading node's own value becomes a Substrate value (as for glTF):
/// Plain: a material input when the document gives it; Switch: a literal at
/// 0 and 1 (a weight's off and fully-on values), else an input.
enum class ParamKind { Plain, Switch };

class SurfaceParams {
 public:
  virtual ~SurfaceParams() = default;
  /// Parameter `name` of MaterialX type `type` ("float", "color3",
  /// "vector3", "boolean"): what the source gives, or `def` as a literal.
  virtual Value param(const std::string& name, const std::string& type, const std::vector<double>& def,
                      ParamKind kind) = 0;
  /// Its value as numbers when the source knows it (nullopt when it varies);
  /// `def` when not given. For static settings (thin_walled, rotations).
  virtual std::optional<std::vector<double>> constant(const std::string& name, const std::string& type,
                                                      const std::vector<double>& def) = 0;
  /// True when the source sets or connects it.
  virtual bool given(const std::string& name) const = 0;
  /// Something the source says that Substrate does not represent.
  virtual void warn(const std::string& what) = 0;
};

/// A unit's readers: P(name, type, default [, kind]) a parameter's value;
/// C(name, type, default) its constant, the default when it varies.
struct MtlxParam {
  SurfaceParams& params;
  Value operator()(const char* name, const char* type, const std::vector<double>& def,
                   ParamKind k = ParamKind::Plain) const {
    return params.param(name, type, def, k);
  }
};
struct MtlxConstant {
  SurfaceParams& params;
  std::vector<double> operator()(const char* name, const char* type, const std::vector<double>& def) const {
    return params.constant(name, type, def).value_or(def);
  }
};

}  // namespace substratec::blocks
