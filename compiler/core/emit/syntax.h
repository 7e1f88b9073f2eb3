// Per-target syntax tables (MaterialX style): everything lexical that differs
// between GLSL and HLSL goes through one Syntax object, so one emitter
// writes both targets.
#pragma once
#include <string>
#include <string_view>

#include "ir/value.h"

namespace substratec {

enum class Target { Glsl, Hlsl };

struct Syntax {
  Target target;
  std::string_view name;              // "glsl" / "hlsl"
  std::string_view materialExtension; // ".material.glsl" / ".material.hlsl"
  std::string_view prelude;           // runtime prelude file to include

  /// Type names: float, vec2/float2, ...; uint.
  std::string type(VType t) const;
  std::string_view uintType() const { return "uint"; }
  /// A float literal that parses the same in both languages ("0.5", "1.0", "1e-05").
  static std::string literal(double v);
  /// A vector constructor from component strings.
  std::string construct(VType t, const std::string& args) const { return type(t) + "(" + args + ")"; }
  std::string lerp(const std::string& a, const std::string& b, const std::string& t) const;
  std::string saturate(const std::string& x) const;
  /// A material input inside its uniform block / constant buffer.
  std::string inputAccess(std::string_view material, std::string_view input) const;
  /// Sampling a texture input (the SUBSTRATE_SAMPLE macro the material file defines).
  std::string sample(std::string_view texture, const std::string& uv) const;
};

const Syntax& syntaxFor(Target t);

}  // namespace substratec
