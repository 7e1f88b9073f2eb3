#include "emit/syntax.h"

#include <cmath>

#include <fmt/format.h>

namespace substratec {

std::string Syntax::type(VType t) const {
  const bool glsl = target == Target::Glsl;
  switch (t) {
    case VType::Float: return "float";
    case VType::Vec2: return glsl ? "vec2" : "float2";
    case VType::Vec3: return glsl ? "vec3" : "float3";
    case VType::Vec4: return glsl ? "vec4" : "float4";
    default: return "float";
  }
}

std::string Syntax::literal(double v) {
  if (!std::isfinite(v)) v = v > 0 ? 3.0e38 : (v < 0 ? -3.0e38 : 0.0);
  if (v == 0) return "0.0";
  std::string s = fmt::format("{:.9g}", v);
  if (s.find_first_of(".eE") == std::string::npos) s += ".0";
  if (s.find_first_of("eE") != std::string::npos && s.find('.') == std::string::npos) {
    auto e = s.find_first_of("eE");
    s.insert(e, ".0");
  }
  if (v < 0) s = "(" + s + ")";
  return s;
}

std::string Syntax::lerp(const std::string& a, const std::string& b, const std::string& t) const {
  return fmt::format("{}({}, {}, {})", target == Target::Glsl ? "mix" : "lerp", a, b, t);
}

std::string Syntax::saturate(const std::string& x) const {
  return target == Target::Glsl ? fmt::format("clamp({}, 0.0, 1.0)", x) : fmt::format("saturate({})", x);
}

std::string Syntax::inputAccess(std::string_view material, std::string_view input) const {
  if (target == Target::Glsl) return fmt::format("{}_inputs.i_{}", material, input);
  return fmt::format("{}_i_{}", material, input);
}

std::string Syntax::sample(std::string_view texture, const std::string& uv) const {
  return fmt::format("SUBSTRATE_SAMPLE(t_{0}, s_{0}, {1})", texture, uv);
}

const Syntax& syntaxFor(Target t) {
  static const Syntax glsl{Target::Glsl, "glsl", ".material.glsl", "substrate_prelude.glsl"};
  static const Syntax hlsl{Target::Hlsl, "hlsl", ".material.hlsl", "substrate_prelude.hlsl"};
  return t == Target::Glsl ? glsl : hlsl;
}

}  // namespace substratec
