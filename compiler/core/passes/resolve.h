// Pass 2 — resolve: reads the parsed JSON document against the format
// (material-format.md), checks every key, kind, type, range and reference,
// and produces a ResolvedDoc in which every reference is an index. Errors
// carry the JSON pointer of the offending value; all of them are reported.
//
// Rewrite: JSON document  ->  ResolvedDoc { settings, inputs, value nodes in
// dependency order (typed), Substrate nodes (acyclic), output }.
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "format/json_document.h"
#include "ir/material.h"

namespace substratec {

/// A pin of a building block (blocks/blocks.h), as the resolver checks it.
struct BlockPin {
  enum class Kind : std::uint8_t {
    Float,      // a scalar value
    Color,      // vec3, a Float broadcasts to grey
    Vec3,       // exactly vec3
    Vec2,       // exactly vec2
    Substrate,  // a Substrate node (an id or an inline node)
    Number,     // a literal number: it decides the expansion's shape
    Choice,     // one of `choices`, a string
    Flag,       // true or false
  };
  const char* name;
  Kind kind;
  double lo = -1e300, hi = 1e300;  // a literal's range (Float, Color, Number)
  bool required = false;
  std::vector<const char*> choices = {};  // Choice
};

/// A building block's kind and pins: the resolver checks a block's pins like
/// any node's (located errors); blocks/expand.h then rewrites it.
struct BlockSignature {
  const char* kind;
  std::vector<BlockPin> pins;
};

/// The resolver's limits (docs/robustness.md); each has its own diagnostic.
struct ResolveLimits {
  std::size_t maxNodes = 20000;        // named + inline nodes
  std::size_t maxInputs = 1024;        // inputs (uniform-block members and textures)
  std::size_t maxIdentifierBytes = 128;
  /// The building blocks the document may use (blocks::signatures()): each is
  /// checked and stands in the resolved document as a placeholder slab whose
  /// children are its Substrate pins, which is only fit for checking (the
  /// pipeline resolves the expanded document). Null: a block's kind is unknown.
  const std::vector<BlockSignature>* blocks = nullptr;
};

/// A pin's value after resolution.
struct PinRef {
  enum Tag : std::uint8_t { Default, Literal, Input, Node } tag = Default;
  std::array<double, 4> literal{0, 0, 0, 0};
  int literalCount = 0;  // 1..4
  int index = -1;        // input index (Input) or value-node index (Node)
  int output = 0;        // output index of a multi-output node
  VType type = VType::Invalid;  // type of the referenced value (after output selection)
};

/// A value node (named or inline), typed.
struct VNode {
  Op op = Op::Const;
  std::string id;        // named nodes only
  std::string pointer;
  std::vector<PinRef> pins;       // in the op's pin order (see resolve.cc table)
  std::uint16_t attr = 0;         // geometry attribute, swizzle channels, texture input
  std::vector<VType> outputTypes; // one per output
};

/// A Substrate node (named or inline).
struct SNode {
  TreeOp op = TreeOp::Slab;
  std::string id;      // named id, or a generated "<parent>_<pin>" name for inline nodes
  std::string pointer;
  int left = -1, right = -1;  // SNode indices
  PinRef a, b;                // operator values (mix/thickness/weight/value, threshold)
  BsdfKind kind = BsdfKind::Slab;  // BSDF leaves (op Slab): the node's kind
  std::array<PinRef, kSlabPinCount> slabPins{};
  int specularProfileInput = -1;
  SssType sssType = SssType::None;
  bool sssTypeExplicit = false;
};

struct ResolvedDoc {
  std::string name;
  Settings settings;
  std::vector<Input> inputs;
  std::vector<VNode> values;
  std::vector<int> valueOrder;  // value-node indices, dependencies first
  std::vector<SNode> substrate;
  int output = -1;  // SNode index
};

std::optional<ResolvedDoc> resolveDocument(const Json& doc, Diagnostics& diags,
                                           const ResolveLimits& limits = {});

/// True for C identifiers (letters, digits, '_', no leading digit or '_', no
/// "__"). Node ids and input names must be identifiers; generated code
/// prefixes them ("i_", "t_", "C_"...), so a leading '_' would make a "__",
/// reserved in GLSL and C++.
bool isIdentifier(const std::string& s, std::size_t maxBytes = 128);
/// Identifiers that are also usable as the material's (or a scene's) name,
/// which generated code suffixes ("_evaluate", "_Inputs") and upper-cases
/// (macros): no trailing '_', no "gl_" prefix in any letter case (GLSL
/// reserves "gl_" names and "GL_" macros), not a C, GLSL or HLSL keyword or
/// built-in function name.
bool isUsableIdentifier(const std::string& s, std::size_t maxBytes = 128);
/// "gl_" in any letter case starts `s` (reserved in GLSL as a name or a macro).
bool hasReservedPrefix(const std::string& s);
/// `s` is a C, GLSL or HLSL keyword, type or built-in function name.
bool isReservedWord(const std::string& s);

}  // namespace substratec
