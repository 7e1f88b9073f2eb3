#include "passes/resolve.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>
#include <cstdlib>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include <fmt/format.h>

namespace substratec {

namespace {

// ---------------------------------------------------------------------------
// Tables: value node kinds and their pins.

enum class PinKind : std::uint8_t {
  Value,      // any value (math ops: types checked by the op's rule)
  Float,      // a scalar value
  Color,      // vec3, a Float broadcasts to grey
  Vec3,       // a direction/vector, exactly vec3
  Vec2,       // exactly vec2
  TextureRef, // "$name" of a texture2d input
  Attribute,  // geometry attribute name
  Channels,   // swizzle channel string
};

struct PinSpec {
  const char* name;
  PinKind kind;
  bool required;
  double def;       // default for optional scalar/colour pins
  int geoDefault;   // GeometryAttr default, or -1
};

struct OpSpec {
  const char* kind;
  Op op;
  std::vector<PinSpec> pins;
  std::vector<const char*> outputs;  // empty: a single unnamed output
};

constexpr int G_N = static_cast<int>(GeometryAttr::Normal);
constexpr int G_UV0 = static_cast<int>(GeometryAttr::Uv0);

const std::vector<OpSpec>& opSpecs() {
  static const std::vector<OpSpec> specs = [] {
    std::vector<OpSpec> v;
    auto binary = [&](const char* k, Op op) {
      v.push_back({k, op, {{"a", PinKind::Value, true, 0, -1}, {"b", PinKind::Value, true, 0, -1}}, {}});
    };
    auto unary = [&](const char* k, Op op) {
      v.push_back({k, op, {{"x", PinKind::Value, true, 0, -1}}, {}});
    };
    v.push_back({"geometry", Op::Geometry, {{"attribute", PinKind::Attribute, true, 0, -1}}, {}});
    v.push_back({"texture",
                 Op::Sample,
                 {{"texture", PinKind::TextureRef, true, 0, -1}, {"uv", PinKind::Vec2, false, 0, G_UV0}},
                 {"rgb", "r", "g", "b", "a"}});
    const std::pair<const char*, Op> binaries[] = {{"add", Op::Add}, {"subtract", Op::Subtract},
                                                   {"multiply", Op::Multiply}, {"divide", Op::Divide},
                                                   {"min", Op::Min}, {"max", Op::Max}};
    for (const auto& [k, op] : binaries) binary(k, op);
    v.push_back({"lerp", Op::Lerp,
                 {{"a", PinKind::Value, true, 0, -1}, {"b", PinKind::Value, true, 0, -1},
                  {"t", PinKind::Value, true, 0, -1}}, {}});
    v.push_back({"clamp", Op::Clamp,
                 {{"x", PinKind::Value, true, 0, -1}, {"lo", PinKind::Value, true, 0, -1},
                  {"hi", PinKind::Value, true, 0, -1}}, {}});
    const std::pair<const char*, Op> unaries[] = {{"saturate", Op::Saturate}, {"one_minus", Op::OneMinus},
                                                  {"abs", Op::Abs}, {"sqrt", Op::Sqrt},
                                                  {"normalize", Op::Normalize}, {"length", Op::Length}};
    for (const auto& [k, op] : unaries) unary(k, op);
    v.push_back({"pow", Op::Pow, {{"x", PinKind::Value, true, 0, -1}, {"y", PinKind::Value, true, 0, -1}}, {}});
    v.push_back({"dot", Op::Dot, {{"a", PinKind::Value, true, 0, -1}, {"b", PinKind::Value, true, 0, -1}}, {}});
    v.push_back({"swizzle", Op::Swizzle,
                 {{"x", PinKind::Value, true, 0, -1}, {"channels", PinKind::Channels, true, 0, -1}}, {}});
    v.push_back({"combine", Op::Combine,
                 {{"x", PinKind::Float, true, 0, -1}, {"y", PinKind::Float, true, 0, -1},
                  {"z", PinKind::Float, false, 0, -1}, {"w", PinKind::Float, false, 0, -1}}, {}});
    v.push_back({"metalness_to_diffuse_f0", Op::MetalnessToDiffuseF0,
                 {{"base_color", PinKind::Color, false, 0.18, -1}, {"metallic", PinKind::Float, false, 0, -1},
                  {"specular", PinKind::Float, false, 0.5, -1}},
                 {"diffuse_albedo", "f0"}});
    v.push_back({"ior_to_f0", Op::IorToF0, {{"ior", PinKind::Float, false, 1.5, -1}}, {}});
    v.push_back({"haziness_to_second_roughness", Op::HazinessToSecondRoughness,
                 {{"roughness", PinKind::Float, false, 0.5, -1}, {"haziness", PinKind::Float, false, 0, -1}},
                 {"second_roughness", "second_roughness_weight"}});
    v.push_back({"transmittance_to_mfp", Op::TransmittanceToMfp,
                 {{"transmittance", PinKind::Color, false, 0.5, -1},
                  {"thickness", PinKind::Float, false, 0.0001, -1}},
                 {"mfp", "thickness"}});
    v.push_back({"thin_film", Op::ThinFilm,
                 {{"normal", PinKind::Vec3, false, 0, G_N}, {"f0", PinKind::Color, false, 0.04, -1},
                  {"f90", PinKind::Color, false, 1.0, -1}, {"thickness", PinKind::Float, false, 0, -1},
                  {"ior", PinKind::Float, false, 1.5, -1}},
                 {"f0", "f90"}});
    v.push_back({"rotation_to_tangent", Op::RotationToTangent,
                 {{"angle", PinKind::Float, false, 0, -1}, {"normal", PinKind::Vec3, false, 0, G_N}}, {}});
    v.push_back({"view_dependent_coverage", Op::ViewDependentCoverage,
                 {{"coverage", PinKind::Float, false, 1, -1}, {"normal", PinKind::Vec3, false, 0, G_N}}, {}});
    v.push_back({"flip_flop", Op::FlipFlop,
                 {{"facing", PinKind::Value, false, 0, -1}, {"grazing", PinKind::Value, false, 1, -1},
                  {"falloff", PinKind::Float, false, 1, -1}, {"normal", PinKind::Vec3, false, 0, G_N}}, {}});
    return v;
  }();
  return specs;
}

const OpSpec* findOpSpec(const std::string& kind) {
  for (const auto& s : opSpecs())
    if (kind == s.kind) return &s;
  return nullptr;
}

std::optional<TreeOp> substrateKind(const std::string& kind) {
  if (bsdfKindByName(kind)) return TreeOp::Slab;  // BSDF leaves (SNode::kind)
  if (kind == "horizontal") return TreeOp::Horizontal;
  if (kind == "vertical") return TreeOp::Vertical;
  if (kind == "coverage_weight") return TreeOp::CoverageWeight;
  if (kind == "select") return TreeOp::Select;
  return std::nullopt;  // "add" is decided by its operands
}

const char* const kReserved[] = {
    // C / C++
    "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else", "enum",
    "extern", "float", "for", "goto", "if", "inline", "int", "long", "register", "restrict",
    "return", "short", "signed", "sizeof", "static", "struct", "switch", "typedef", "union",
    "unsigned", "void", "volatile", "while", "bool", "true", "false", "class", "namespace",
    "template", "this", "new", "delete", "main",
    // GLSL
    "attribute", "uniform", "varying", "layout", "centroid", "flat", "smooth", "noperspective",
    "patch", "sample", "buffer", "shared", "coherent", "readonly", "writeonly", "precise", "in",
    "out", "inout", "lowp", "mediump", "highp", "precision", "invariant", "discard", "subroutine",
    "uint", "vec2", "vec3", "vec4", "ivec2", "ivec3", "ivec4", "uvec2", "uvec3", "uvec4", "bvec2",
    "bvec3", "bvec4", "dvec2", "dvec3", "dvec4", "mat2", "mat3", "mat4", "sampler2D", "texture",
    "image2D", "input", "output", "filter", "common", "partition", "active", "asm", "fixed",
    "half", "hvec2", "hvec3", "hvec4", "superp", "cast", "using", "public", "static_assert",
    "demote", "terminateInvocation",
    // HLSL
    "float2", "float3", "float4", "float3x3", "float4x4", "half2", "half3", "half4", "int2",
    "int3", "int4", "uint2", "uint3", "uint4", "cbuffer", "tbuffer", "Texture2D", "SamplerState",
    "groupshared", "nointerpolation", "linear", "centroid", "row_major", "column_major", "snorm",
    "unorm", "technique", "pass", "string", "matrix", "vector", "register", "packoffset",
    "globallycoherent", "export", "typename", "lerp", "saturate", "mix", "clamp", "dot", "pow",
    "sqrt", "abs", "min", "max", "length", "normalize",
    // More GLSL and HLSL types and keywords
    "mat2x2", "mat2x3", "mat2x4", "mat3x2", "mat3x3", "mat3x4", "mat4x2", "mat4x3", "mat4x4", "dmat2", "dmat3",
    "dmat4", "sampler", "sampler1D", "sampler3D", "samplerCube", "sampler2DShadow", "sampler2DArray", "texture2D",
    "image", "atomic_uint", "struct", "subroutine", "sampler_state", "SamplerComparisonState", "Texture1D",
    "Texture3D", "TextureCube", "Texture2DArray", "RWTexture2D", "Buffer", "RWBuffer", "ByteAddressBuffer",
    "StructuredBuffer", "RWStructuredBuffer", "ConstantBuffer", "float1", "float2x2", "float2x3", "float3x2",
    "float3x4", "float4x3", "half1", "double1", "double2", "double3", "double4", "int1", "uint1", "bool1", "bool2",
    "bool3", "bool4", "dword", "min16float", "min10float", "min16int", "min12int", "min16uint", "uniform",
    "static", "const", "inline", "discard", "nointerpolation", "sample", "triangle", "line", "point", "lineadj",
    "triangleadj", "vertices", "indices", "primitives", "payload", "in", "out", "inout", "NULL", "compile",
    "compile_fragment", "pixelfragment", "vertexfragment", "stateblock", "stateblock_state", "shared", "interface",
    "pixelshader", "vertexshader", "sizeof", "typedef", "Texture", "TEXTURE", "SAMPLER", "Sampler",
    // GLSL and HLSL built-in functions
    "radians", "degrees", "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "exp", "log", "exp2", "log2", "log10", "inversesqrt", "rsqrt", "rcp", "sign", "floor",
    "ceil", "trunc", "round", "roundEven", "fract", "frac", "mod", "fmod", "modf", "step", "smoothstep", "isnan",
    "isinf", "isfinite", "fma", "mad", "frexp", "ldexp", "distance", "cross", "faceforward", "reflect", "refract",
    "matrixCompMult", "outerProduct", "transpose", "determinant", "inverse", "mul", "lessThan", "lessThanEqual",
    "greaterThan", "greaterThanEqual", "equal", "notEqual", "any", "all", "not", "textureSize", "textureLod",
    "textureGrad", "textureOffset", "texelFetch", "textureGather", "imageLoad", "imageStore", "imageSize",
    "dFdx", "dFdy", "fwidth", "ddx", "ddy", "ddx_coarse", "ddy_coarse", "ddx_fine", "ddy_fine", "clip", "lit",
    "noise", "sincos", "dst", "tex2D", "tex2Dlod", "tex2Dgrad", "tex2Dbias", "tex2Dproj", "texCUBE", "barrier",
    "memoryBarrier", "groupMemoryBarrier", "GroupMemoryBarrierWithGroupSync", "AllMemoryBarrier",
    "DeviceMemoryBarrier", "floatBitsToInt", "floatBitsToUint", "intBitsToFloat", "uintBitsToFloat", "asfloat",
    "asint", "asuint", "asdouble", "packUnorm2x16", "packSnorm2x16", "packUnorm4x8", "packSnorm4x8",
    "unpackUnorm2x16", "unpackSnorm2x16", "unpackUnorm4x8", "unpackSnorm4x8", "packHalf2x16", "unpackHalf2x16",
    "f16tof32", "f32tof16", "bitfieldExtract", "bitfieldInsert", "bitfieldReverse", "bitCount", "findLSB",
    "findMSB", "countbits", "firstbithigh", "firstbitlow", "reversebits", "uaddCarry", "usubBorrow", "umulExtended",
    "imulExtended", "atomicAdd", "atomicMin", "atomicMax", "atomicAnd", "atomicOr", "atomicXor", "atomicExchange",
    "atomicCompSwap", "InterlockedAdd", "EmitVertex", "EndPrimitive", "interpolateAtCentroid",
    "interpolateAtSample", "interpolateAtOffset", "subpassLoad", "errorf", "printf", "abort", "source_mark"};

}  // namespace

bool isIdentifier(const std::string& s, std::size_t maxBytes) {
  if (s.empty() || s.size() > maxBytes) return false;
  auto alpha = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; };
  if (!alpha(s[0]) || s[0] == '_') return false;  // generated code prefixes it: "i_" + "_x" would hold "__"
  for (char c : s)
    if (!alpha(c) && !(c >= '0' && c <= '9')) return false;
  return s.find("__") == std::string::npos;  // reserved in GLSL and C++
}

bool hasReservedPrefix(const std::string& s) {
  // "gl_" in any letter case: the material's macros are its name in upper case (GL_..., reserved in GLSL).
  return s.size() >= 3 && (s[0] == 'g' || s[0] == 'G') && (s[1] == 'l' || s[1] == 'L') && s[2] == '_';
}

bool isReservedWord(const std::string& s) {
  static const std::unordered_set<std::string> words(std::begin(kReserved), std::end(kReserved));
  return words.count(s) != 0;
}

bool isUsableIdentifier(const std::string& s, std::size_t maxBytes) {
  if (!isIdentifier(s, maxBytes)) return false;
  if (s.back() == '_') return false;  // generated code suffixes it: "x_" + "_evaluate" would hold "__"
  return !hasReservedPrefix(s) && !isReservedWord(s);
}

namespace {

/// A node's "kind" if it is an object with a string kind, else "" (never
/// throws: a fuzzed file gave a node an object for its kind).
std::string kindOf(const Json& node) {
  if (!node.is_object()) return "";
  auto k = node.find("kind");
  return k != node.end() && k->is_string() ? k->get<std::string>() : "";
}

/// The enumerator of `table` that the JSON string `v` names; otherwise the
/// error "expected one of <the table's names, in order>; got <v's kind>" at `ptr`.
template <class E, std::size_t N>
std::optional<E> enumOfJson(const EnumName<E> (&table)[N], const Json& v, const std::string& ptr, Diagnostics& d) {
  const std::optional<E> e = v.is_string() ? enumByName(table, v.get_ref<const std::string&>()) : std::nullopt;
  if (!e) d.error(ptr, fmt::format("expected one of {}; got {}", enumNameList(table), kindOfJson(v)));
  return e;
}

/// "a -> b -> c -> a", with long cycles shortened to their first and last
/// nodes (a cycle through 20000 nodes must not make a megabyte-long line).
std::string cycleChain(const std::vector<std::string>& names) {
  constexpr std::size_t kHead = 6, kTail = 3;
  std::string chain;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names.size() > kHead + kTail + 1 && i == kHead) {
      chain += fmt::format("... ({} more) -> ", names.size() - kHead - kTail);
      i = names.size() - kTail - 1;
      continue;
    }
    chain += quoteForDiagnostic(names[i], 64).substr(1);
    chain.pop_back();  // the names are identifiers or pointers: shown unquoted
    if (i + 1 < names.size()) chain += " -> ";
  }
  return chain;
}

std::string typeWord(VType t, bool color) {
  if (color && t == VType::Vec3) return "color";
  return std::string(typeName(t));
}

// ---------------------------------------------------------------------------

class Resolver {
 public:
  Resolver(const Json& doc, Diagnostics& diags, const ResolveLimits& limits)
      : doc_(doc), d_(diags), limits_(limits) {}

  std::optional<ResolvedDoc> run();

 private:
  // --- top level
  void readTop();
  void readHeader();
  bool indexNamedNodes();
  bool readNamedNodeBodies();
  void checkOutput();
  void readSettings(const Json& s, const std::string& ptr);
  void readInputs(const Json& s, const std::string& ptr);
  void readInput(const std::string& name, const Json& v, const std::string& p);
  void readInputKey(Input& in, Json::const_iterator k, const std::string& p, bool& ok);
  bool readTextureKey(Input& in, const std::string& key, const Json& value, const std::string& kp);
  void classifyNodes();
  void classifyAdds(const std::vector<std::string>& adds);
  int resolveValueNode(const std::string& id);
  int resolveSubstrateNode(const std::string& id);

  // --- values
  PinRef readValuePin(const Json& j, const std::string& ptr, const std::string& pinName);
  PinRef readInputPin(const std::string& s, const std::string& ptr);
  PinRef readReferencePin(const std::string& s, const std::string& ptr, const std::string& pinName);
  void selectNamedOutput(PinRef& r, const OpSpec* spec, const std::string& id, const std::string& output,
                         const std::string& ptr, const std::string& pinName);
  PinRef readInlineValuePin(const Json& j, const std::string& ptr, const std::string& pinName);
  int makeInlineValueNode(const Json& j, const std::string& ptr);
  void readValueNodeBody(int index, const Json& j, const std::string& ptr, const OpSpec& spec);
  void checkValueNodeKeys(const Json& j, const std::string& ptr, const OpSpec& spec);
  void readTextureRefPin(const Json& v, const std::string& pp, std::uint16_t& attr, PinRef& pin);
  void readChannelsPin(const Json& v, const std::string& pp, std::uint16_t& attr, PinRef& pin);
  bool expectPinType(PinRef& pin, PinKind kind, const std::string& ptr, bool* color = nullptr);
  PinRef defaultPin(const PinSpec& ps);

  // --- substrate
  int readSubstratePin(const Json& j, const std::string& ptr, const std::string& nameForInline);
  void fillSubstrateNode(int index, const Json& j, const std::string& ptr, TreeOp op);
  /// The pins of an operator node (HORIZONTAL, VERTICAL, ADD, WEIGHT, SELECT) into `node`.
  void fillOperatorNode(int index, const Json& j, const std::string& ptr, TreeOp op, SNode& node);
  /// The pins, SSS type and specular profile of a slab node into `node`.
  void fillSlabNode(int index, const Json& j, const std::string& ptr, SNode& node);
  /// Slab pin `p` of slab node `index` (the node's JSON `j`) into `dst`: its default when absent.
  void readSlabPin(int index, const Json& j, const std::string& ptr, int p, PinRef& dst);
  bool isSubstrateValue(const Json& j) const;
  /// The building block of kind `kind` (limits_.blocks), or null.
  const BlockSignature* blockOf(const std::string& kind) const {
    if (limits_.blocks)
      for (const BlockSignature& b : *limits_.blocks)
        if (kind == b.kind) return &b;
    return nullptr;
  }
  /// The tree op of a Substrate kind: a building block is a (placeholder) slab.
  std::optional<TreeOp> treeKind(const std::string& kind) const {
    return blockOf(kind) ? std::optional<TreeOp>(TreeOp::Slab) : substrateKind(kind);
  }
  /// A building block's pins, checked against its signature; its Substrate
  /// pins become the placeholder's children (for the cycle check).
  void fillBlockNode(int index, const Json& j, const std::string& ptr, const BlockSignature& sig, SNode& node);
  /// One value pin of a building block (Float, Color, Vec3, Vec2).
  void readBlockValuePin(int index, const Json& v, const std::string& pp, const BlockPin& pin);
  void checkRange(const PinRef& pin, const Json& j, const std::string& ptr, double lo, double hi,
                  const char* what);

  // --- typing and cycles
  void typeValueNodes();
  /// The type of what pin `p` reads: its own, or its value node's output.
  VType valueOutputType(const PinRef& p) const;
  /// Types value node i, whose arguments are typed (post-order); reports mismatches.
  void typeValueNode(int i);
  /// The output types of a math, geometry or texture node with typed pins.
  void typeOperatorNode(VNode& v, const OpSpec* spec);
  /// The output types of a helper node (its pins' kinds are checked here).
  void typeHelperNode(VNode& v, const OpSpec* spec);
  void checkSubstrateCycles();

  bool isValueKindName(const std::string& id) const {
    auto it = namedKind_.find(id);
    return it != namedKind_.end() && it->second == 1;
  }
  bool isSubstrateName(const std::string& id) const {
    auto it = namedKind_.find(id);
    return it != namedKind_.end() && it->second == 2;
  }
  /// Counts one more node (named or inline); false past the node-count limit,
  /// which is reported once, at the first node over it.
  bool budget(const std::string& ptr) {
    if (++nodeCount_ > limits_.maxNodes) {
      if (!nodeLimitReported_) {
        d_.error(ptr, fmt::format("material has more than {} nodes, named and inline (the node-count limit)",
                                  limits_.maxNodes));
        nodeLimitReported_ = true;
      }
      return false;
    }
    return true;
  }
  /// The diagnostic for a name that is not an identifier: the identifier-length
  /// limit when it is only too long, else what an identifier is.
  std::string identifierError(const std::string& what, const std::string& name) const {
    if (name.size() > limits_.maxIdentifierBytes && isIdentifier(name, name.size()))
      return fmt::format("{} {} of {} bytes is longer than the limit of {} bytes (the identifier-length limit)", what,
                         quoteForDiagnostic(name), name.size(), limits_.maxIdentifierBytes);
    return fmt::format("{} {} is not a C identifier of at most {} bytes (letters, digits, '_'; no leading digit or "
                       "'_', no \"__\")",
                       what, quoteForDiagnostic(name), limits_.maxIdentifierBytes);
  }

  const Json& doc_;
  Diagnostics& d_;
  ResolveLimits limits_;
  ResolvedDoc out_;
  const Json* nodes_ = nullptr;
  std::unordered_map<std::string, int> inputIndex_;
  std::unordered_set<std::string> badInputs_;  // reported once; references stay silent
  std::unordered_map<std::string, const Json*> namedJson_;
  std::unordered_map<std::string, int> namedKind_;   // 1 value, 2 substrate, 0 invalid
  std::unordered_map<std::string, int> namedValue_;  // id -> VNode index (-1 while resolving)
  std::unordered_map<std::string, int> namedSubstrate_;
  struct DeferredPinCheck {
    int snode;
    int pin;  // slab pin index, or -1 (a) / -2 (b) for operator values, or -3 - k for blockPins_[k]
    PinKind kind;
    std::string pointer;
  };
  std::vector<DeferredPinCheck> deferred_;  // pins referencing value nodes: typed after typeValueNodes
  std::deque<PinRef> blockPins_;            // building blocks' value pins (checked, then dropped)
  void checkDeferredPins();
  std::size_t nodeCount_ = 0;
  bool nodeLimitReported_ = false;
  std::string outputId_;
};

std::optional<ResolvedDoc> Resolver::run() {
  if (!doc_.is_object()) {
    d_.error("", fmt::format("expected the material object at the top level, got {}", kindOfJson(doc_)));
    return std::nullopt;
  }
  readTop();
  if (d_.limitReached()) return std::nullopt;
  typeValueNodes();
  checkDeferredPins();
  checkSubstrateCycles();
  if (d_.hasErrors()) return std::nullopt;
  return std::move(out_);
}

void Resolver::readTop() {
  readHeader();

  if (auto it = doc_.find("settings"); it != doc_.end()) readSettings(*it, "/settings");
  if (auto it = doc_.find("inputs"); it != doc_.end()) readInputs(*it, "/inputs");

  auto nodesIt = doc_.find("nodes");
  if (nodesIt == doc_.end()) {
    d_.error("", "missing required key \"nodes\"");
  } else if (!nodesIt->is_object()) {
    d_.error("/nodes", fmt::format("expected an object of nodes keyed by id, got {}", kindOfJson(*nodesIt)));
  } else {
    nodes_ = &*nodesIt;
  }

  auto outIt = doc_.find("output");
  if (outIt == doc_.end()) {
    d_.error("", "missing required key \"output\" (the id of the root Substrate node)");
  } else if (!outIt->is_string()) {
    d_.error("/output", fmt::format("expected a Substrate node id, got {}", kindOfJson(*outIt)));
  } else if (outIt->get_ref<const std::string&>().empty()) {  // checkOutput reads "" as "not given"
    d_.error("/output", "expected a Substrate node id, got an empty string");
  } else {
    outputId_ = outIt->get<std::string>();
  }

  if (!nodes_) return;
  if (nodes_->size() > limits_.maxNodes) {  // named nodes alone: nothing else is worth reading
    auto over = nodes_->begin();
    std::advance(over, limits_.maxNodes);  // the first node over the limit
    d_.error("/nodes/" + pointerToken(over.key()),
             fmt::format("material has {} named nodes, more than {} (the node-count limit)", nodes_->size(),
                         limits_.maxNodes));
    nodeLimitReported_ = true;
    return;
  }
  classifyNodes();
  // Every named node gets its index first, so that references never recurse
  // (a chain of 100k named nodes must not deepen the stack); then each body
  // is read, in file order, so unused nodes are checked too.
  if (!indexNamedNodes() || !readNamedNodeBodies()) return;
  checkOutput();
}

/// The top-level keys, "format", "$schema", "description" and "name" (into out_.name).
void Resolver::readHeader() {
  static const std::set<std::string> known = {"$schema", "format", "name", "settings",
                                              "inputs", "nodes", "output", "description"};
  for (auto it = doc_.begin(); it != doc_.end(); ++it)
    if (!known.count(it.key()))
      d_.error("/" + pointerToken(it.key()),
               fmt::format("unknown key {} (expected one of: format, name, settings, inputs, nodes, output)",
                           quoteForDiagnostic(it.key())));

  auto fmtIt = doc_.find("format");
  if (fmtIt == doc_.end()) {
    d_.error("", "missing required key \"format\" (expected \"substrate-material/1\")");
  } else if (!fmtIt->is_string() || fmtIt->get<std::string>() != "substrate-material/1") {
    d_.error("/format", fmt::format("expected \"substrate-material/1\", got {}", kindOfJson(*fmtIt)));
  }
  if (auto it = doc_.find("$schema"); it != doc_.end() && !it->is_string())
    d_.error("/$schema", "expected a string");
  if (auto it = doc_.find("description"); it != doc_.end() && !it->is_string())
    d_.error("/description", "expected a string");

  auto nameIt = doc_.find("name");
  if (nameIt == doc_.end()) {
    d_.error("", "missing required key \"name\"");
  } else if (!nameIt->is_string()) {
    d_.error("/name", fmt::format("expected a C identifier string, got {}", kindOfJson(*nameIt)));
  } else if (const std::string& name = nameIt->get_ref<const std::string&>();
             name.size() > limits_.maxIdentifierBytes && isUsableIdentifier(name, name.size())) {
    d_.error("/name", identifierError("name", name));
  } else if (!isUsableIdentifier(nameIt->get<std::string>(), limits_.maxIdentifierBytes)) {
    d_.error("/name", fmt::format("{} is not usable as a name: it must be a C identifier of at most {} "
                                  "bytes, without \"__\", not beginning with '_' or \"gl_\" (in any case), not "
                                  "ending with '_', and not a C/GLSL/HLSL keyword or built-in function",
                                  quoteForDiagnostic(nameIt->get<std::string>()), limits_.maxIdentifierBytes));
  } else {
    out_.name = nameIt->get<std::string>();
  }
}

/// Gives every named node its index in out_.values or out_.substrate, in file
/// order; false past the node-count limit (reported by budget()).
bool Resolver::indexNamedNodes() {
  for (auto it = nodes_->begin(); it != nodes_->end(); ++it) {
    const std::string& id = it.key();
    std::string p = "/nodes/" + pointerToken(id);
    if (isValueKindName(id)) {
      if (!budget(p)) return false;
      namedValue_[id] = static_cast<int>(out_.values.size());
      out_.values.emplace_back();
      out_.values.back().id = id;
      out_.values.back().pointer = p;
    } else if (isSubstrateName(id)) {
      if (!budget(p)) return false;
      namedSubstrate_[id] = static_cast<int>(out_.substrate.size());
      out_.substrate.emplace_back();
      out_.substrate.back().id = id;
      out_.substrate.back().pointer = p;
    }
  }
  return true;
}

/// Reads the body of every named node, in file order; false once the
/// diagnostic limit is reached.
bool Resolver::readNamedNodeBodies() {
  for (auto it = nodes_->begin(); it != nodes_->end(); ++it) {
    if (d_.limitReached()) return false;
    const std::string& id = it.key();
    std::string p = "/nodes/" + pointerToken(id);
    std::string kind = isValueKindName(id) || isSubstrateName(id) ? (*it)["kind"].get<std::string>() : "";
    if (isValueKindName(id)) {
      const OpSpec* spec = findOpSpec(kind);
      int index = namedValue_[id];
      out_.values[index].op = spec->op;
      readValueNodeBody(index, *it, p, *spec);
    } else if (isSubstrateName(id)) {
      fillSubstrateNode(namedSubstrate_[id], *it, p, kind == "add" ? TreeOp::Add : *treeKind(kind));
    }
  }
  return true;
}

/// Checks that "output" names a Substrate node and records it in out_.output.
void Resolver::checkOutput() {
  if (!outputId_.empty()) {
    if (!namedKind_.count(outputId_)) {
      if (inputIndex_.count(outputId_))
        d_.error("/output", fmt::format("{} is an input, not a Substrate node", quoteForDiagnostic(outputId_)));
      else
        d_.error("/output", fmt::format("unknown node {}", quoteForDiagnostic(outputId_)));
    } else if (isValueKindName(outputId_)) {
      d_.error("/output", fmt::format("{} is a value node; the output must be a Substrate node "
                                      "(slab, unlit, hair, volumetric_fog_cloud, eye, single_layer_water, horizontal, vertical, add, coverage_weight, select)",
                                      quoteForDiagnostic(outputId_)));
    } else if (isSubstrateName(outputId_)) {
      out_.output = namedSubstrate_[outputId_];
    }
  }
}

void Resolver::readSettings(const Json& s, const std::string& ptr) {
  if (!s.is_object()) {
    d_.error(ptr, fmt::format("expected an object, got {}", kindOfJson(s)));
    return;
  }
  Settings& st = out_.settings;
  for (auto it = s.begin(); it != s.end(); ++it) {
    const std::string& k = it.key();
    const Json& v = *it;
    std::string p = ptr + "/" + pointerToken(k);
    auto intIn = [&](int lo, int hi, int& dst) {
      if (!v.is_number() || (v.is_number_float() && v.get<double>() != std::floor(v.get<double>()))) {
        d_.error(p, fmt::format("expected an integer in [{},{}], got {}", lo, hi, kindOfJson(v)));
        return;
      }
      double x = v.get<double>();
      if (x < lo || x > hi) {
        d_.error(p, fmt::format("expected an integer in [{},{}], got {}", lo, hi, kindOfJson(v)));
        return;
      }
      dst = static_cast<int>(x);
    };
    if (k == "bytes_per_pixel") {
      intIn(8, 1024, st.bytesPerPixel);
    } else if (k == "max_closures") {
      intIn(1, 8, st.maxClosures);
    } else if (k == "thin_surface") {
      if (!v.is_boolean()) d_.error(p, fmt::format("expected true or false, got {}", kindOfJson(v)));
      else st.thinSurface = v.get<bool>();
    } else if (k == "surface_thickness") {
      if (!v.is_number() || v.get<double>() < 0)
        d_.error(p, fmt::format("expected a thickness in meters >= 0, got {}", kindOfJson(v)));
      else st.surfaceThickness = v.get<double>();
    } else if (k == "blend_mode") {
      if (auto m = enumOfJson(kBlendModeNames, v, p, d_)) st.blendMode = *m;
    } else {
      d_.error(p, fmt::format("unknown setting {} (expected bytes_per_pixel, max_closures, thin_surface, "
                              "surface_thickness or blend_mode)", quoteForDiagnostic(k)));
    }
  }
}

void Resolver::readInputs(const Json& s, const std::string& ptr) {
  if (!s.is_object()) {
    d_.error(ptr, fmt::format("expected an object of inputs keyed by name, got {}", kindOfJson(s)));
    return;
  }
  std::size_t count = 0;
  for (auto it = s.begin(); it != s.end(); ++it) {
    const std::string& name = it.key();
    std::string p = ptr + "/" + pointerToken(name);
    const Json& v = *it;
    if (++count > limits_.maxInputs) {
      // Past the input-count limit: reported once; later names are only
      // remembered so that references to them stay silent.
      if (count == limits_.maxInputs + 1)
        d_.error(p, fmt::format("material has {} inputs, more than {} (the input-count limit)", s.size(),
                                limits_.maxInputs));
      badInputs_.insert(name);
      continue;
    }
    if (!isIdentifier(name, limits_.maxIdentifierBytes)) {
      d_.error(p, identifierError("input name", name));
      badInputs_.insert(name);
      continue;
    }
    if (!v.is_object()) {
      d_.error(p, fmt::format("expected an input object like {{\"type\": \"float\", \"default\": 0.5}}, got {}",
                              kindOfJson(v)));
      badInputs_.insert(name);
      continue;
    }
    readInput(name, v, p);
  }
}

/// Input `name` (its JSON `v`, at pointer `p`) into out_.inputs; a bad one
/// into badInputs_, so that references to it stay silent.
void Resolver::readInput(const std::string& name, const Json& v, const std::string& p) {
  Input in;
  in.name = name;
  in.pointer = p;
  bool ok = true;
  auto t = v.find("type");
  if (t == v.end() || !t->is_string()) {
    d_.error(p + (t == v.end() ? "" : "/type"),
             "expected \"type\": one of float, vec2, vec3, color, texture2d");
    badInputs_.insert(name);
    return;
  }
  std::string ts = t->get<std::string>();
  if (ts == "float") in.type = VType::Float;
  else if (ts == "vec2") in.type = VType::Vec2;
  else if (ts == "vec3") in.type = VType::Vec3;
  else if (ts == "color") { in.type = VType::Vec3; in.isColor = true; }
  else if (ts == "texture2d") in.type = VType::Texture;
  else {
    d_.error(p + "/type", fmt::format("unknown input type {} (expected float, vec2, vec3, color or texture2d)",
                                      quoteForDiagnostic(ts)));
    badInputs_.insert(name);
    return;
  }
  for (auto k = v.begin(); k != v.end(); ++k) readInputKey(in, k, p, ok);
  if (in.type != VType::Texture && !v.contains("default")) {
    d_.error(p, fmt::format("missing \"default\" for {} input", typeWord(in.type, in.isColor)));
    ok = false;
  }
  for (int i = 0; in.min && in.max && i < componentCount(in.type); ++i) {
    if ((*in.min)[i] > (*in.max)[i]) {
      d_.error(p + "/min", fmt::format("min {:g} is greater than max {:g}", (*in.min)[i], (*in.max)[i]));
      ok = false;
      break;
    }
  }
  if (ok && in.type != VType::Texture && v.contains("default")) {
    for (int i = 0; i < componentCount(in.type); ++i) {
      double x = in.defaultValue[i];
      if ((in.min && x < (*in.min)[i]) || (in.max && x > (*in.max)[i])) {
        d_.error(p + "/default", fmt::format("default {:g} is outside [{}, {}]", x,
                                             in.min ? fmt::format("{:g}", (*in.min)[i]) : "-inf",
                                             in.max ? fmt::format("{:g}", (*in.max)[i]) : "inf"));
        break;
      }
    }
  }
  inputIndex_[name] = static_cast<int>(out_.inputs.size());
  out_.inputs.push_back(std::move(in));
}

/// A texture2d input's own keys (colorspace, wrap, filter, file) into `in`;
/// false for any other key. `kp` is the key's pointer.
bool Resolver::readTextureKey(Input& in, const std::string& key, const Json& value, const std::string& kp) {
  if (key == "colorspace") {
    if (in.type != VType::Texture) d_.error(kp, "\"colorspace\" applies to texture2d inputs only");
    else if (!value.is_string() || (value.get<std::string>() != "srgb" && value.get<std::string>() != "linear"))
      d_.error(kp, fmt::format("expected \"srgb\" or \"linear\", got {}", kindOfJson(value)));
    else in.srgb = value.get<std::string>() == "srgb";
    return true;
  }
  if (key == "wrap" || key == "filter") {
    if (in.type != VType::Texture) {
      d_.error(kp, fmt::format("\"{}\" applies to texture2d inputs only", key));
      return true;
    }
    if (key == "filter") {
      if (!value.is_string() || (value.get<std::string>() != "linear" && value.get<std::string>() != "nearest"))
        d_.error(kp, fmt::format("expected \"linear\" or \"nearest\", got {}", kindOfJson(value)));
      else in.nearest = value.get<std::string>() == "nearest";
      return true;
    }
    auto mode = [](const Json& j) -> std::optional<Wrap> {
      if (!j.is_string()) return std::nullopt;
      const std::string& s = j.get_ref<const std::string&>();
      if (s == "repeat") return Wrap::Repeat;
      if (s == "clamp") return Wrap::Clamp;
      if (s == "mirror") return Wrap::Mirror;
      return std::nullopt;
    };
    std::optional<Wrap> u, v;
    if (value.is_array() && value.size() == 2) {
      u = mode(value[0]);
      v = mode(value[1]);
    } else {
      u = v = mode(value);
    }
    if (!u || !v) {
      d_.error(kp, fmt::format("expected \"repeat\", \"clamp\" or \"mirror\", or an array of two (u, v), got {}",
                               kindOfJson(value)));
    } else {
      in.wrapU = *u;
      in.wrapV = *v;
    }
    return true;
  }
  if (key == "file") {
    if (in.type != VType::Texture) d_.error(kp, "\"file\" applies to texture2d inputs only (an image to bind)");
    else if (!value.is_string() || value.get<std::string>().empty())
      d_.error(kp, fmt::format("expected an image path (a non-empty string), got {}", kindOfJson(value)));
    else if (value.get<std::string>().find('\0') != std::string::npos)
      d_.error(kp, "an image path holding a NUL character");
    else in.file = value.get<std::string>();
    return true;
  }
  return false;
}

/// Key `k` of input `in` (at pointer `p`) other than its type; `ok` turns
/// false when the key makes the default unusable.
void Resolver::readInputKey(Input& in, Json::const_iterator k, const std::string& p, bool& ok) {
  const std::string& key = k.key();
  std::string kp = p + "/" + pointerToken(key);
  if (key == "type" || key == "description") {
    if (key == "description" && !k->is_string()) d_.error(kp, "expected a string");
    else if (key == "description") in.description = k->get<std::string>();
    return;
  }
  if (readTextureKey(in, key, *k, kp)) return;
  if (key == "min" || key == "max") {
    // A number bounds every component; an array bounds each component.
    auto& dst = key == "min" ? in.min : in.max;
    int n = componentCount(in.type);
    if (in.type == VType::Texture) {
      d_.error(kp, fmt::format("\"{}\" does not apply to a texture2d input", key));
      ok = false;
    } else if (k->is_number()) {
      double x = k->get<double>();
      dst = std::array<double, 4>{x, x, x, x};
    } else if (k->is_array() && static_cast<int>(k->size()) == n && n > 1 &&
               std::all_of(k->begin(), k->end(), [](const Json& e) { return e.is_number(); })) {
      std::array<double, 4> a{0, 0, 0, 0};
      for (int i = 0; i < n; ++i) a[i] = (*k)[i].get<double>();
      dst = a;
    } else {
      d_.error(kp, fmt::format("expected a number{}, got {}", n > 1 ? fmt::format(" or {} numbers", n) : "",
                               kindOfJson(*k)));
      ok = false;
    }
    return;
  }
  if (key == "default") {
    if (in.type == VType::Texture) {
      d_.error(kp, "a texture2d input has no default (it is bound at run time; "
                   "\"file\" names an image to bind when none is)");
      ok = false;
      return;
    }
    int n = componentCount(in.type);
    if (k->is_number() && (n == 1 || in.isColor)) {
      double x = k->get<double>();
      in.defaultValue = {x, x, x, 0};
    } else if (k->is_array() && static_cast<int>(k->size()) == n && n > 1 &&
               std::all_of(k->begin(), k->end(), [](const Json& e) { return e.is_number(); })) {
      for (int i = 0; i < n; ++i) in.defaultValue[i] = (*k)[i].get<double>();
    } else {
      d_.error(kp, fmt::format("expected a {} default ({}), got {}", typeWord(in.type, in.isColor),
                               n == 1 ? "a number" : fmt::format("an array of {} numbers", n),
                               kindOfJson(*k)));
      ok = false;
    }
    return;
  }
  d_.error(kp, fmt::format("unknown input key {} (expected type, default, min, max, description; "
                           "texture2d: colorspace, file, wrap, filter)",
                           quoteForDiagnostic(key)));
}

/// Decides for every named node whether it is a value node or a Substrate
/// node. "add" is both a math and a Substrate kind: an add is Substrate when
/// an operand is (transitively) Substrate matter.
void Resolver::classifyNodes() {
  std::vector<std::string> adds;
  for (auto it = nodes_->begin(); it != nodes_->end(); ++it) {
    const std::string& id = it.key();
    std::string p = "/nodes/" + pointerToken(id);
    namedKind_[id] = 0;
    if (!isIdentifier(id, limits_.maxIdentifierBytes)) {
      d_.error(p, identifierError("node id", id));
      continue;
    }
    if (inputIndex_.count(id)) {
      d_.error(p, fmt::format("node id {} is already an input name (ids and input names share one namespace)",
                              quoteForDiagnostic(id)));
      continue;
    }
    namedJson_[id] = &*it;
    if (!it->is_object()) {
      d_.error(p, fmt::format("expected a node object with a \"kind\", got {}", kindOfJson(*it)));
      continue;
    }
    auto k = it->find("kind");
    if (k == it->end() || !k->is_string()) {
      d_.error(p, "missing \"kind\" (a string naming the node kind)");
      continue;
    }
    std::string kind = k->get<std::string>();
    if (kind == "add") {
      adds.push_back(id);
      namedKind_[id] = 1;  // decided below
    } else if (treeKind(kind)) {
      namedKind_[id] = 2;
    } else if (findOpSpec(kind)) {
      namedKind_[id] = 1;
    } else {
      d_.error(p + "/kind", fmt::format("unknown node kind {}", quoteForDiagnostic(kind)));
    }
  }
  classifyAdds(adds);
}

/// Named adds: an add is Substrate if an operand is Substrate. Inline content
/// decides directly; references to other named adds propagate backwards.
void Resolver::classifyAdds(const std::vector<std::string>& adds) {
  std::unordered_map<std::string, std::vector<std::string>> referencedBy;
  std::deque<std::string> queue;
  std::function<bool(const Json&, const std::string&)> scan = [&](const Json& j,
                                                                  const std::string& owner) -> bool {
    if (j.is_string()) {
      const std::string& s = j.get_ref<const std::string&>();
      if (isSubstrateName(s)) return true;
      auto f = namedJson_.find(s);
      if (f != namedJson_.end() && kindOf(*f->second) == "add")
        referencedBy[s].push_back(owner);
      return false;
    }
    if (!j.is_object()) return false;
    auto k = j.find("kind");
    if (k == j.end() || !k->is_string()) return false;
    std::string kind = k->get<std::string>();
    if (treeKind(kind)) return true;
    if (kind != "add") return false;
    bool any = false;
    for (const char* pin : {"a", "b"})
      if (auto p = j.find(pin); p != j.end()) any = scan(*p, owner) || any;
    return any;
  };
  for (const auto& id : adds) {
    const Json& j = *namedJson_[id];
    bool direct = false;
    for (const char* pin : {"a", "b"})
      if (auto p = j.find(pin); p != j.end()) direct = scan(*p, id) || direct;
    if (direct) {
      namedKind_[id] = 2;
      queue.push_back(id);
    }
  }
  while (!queue.empty()) {
    std::string id = queue.front();
    queue.pop_front();
    for (const auto& owner : referencedBy[id])
      if (namedKind_[owner] != 2) {
        namedKind_[owner] = 2;
        queue.push_back(owner);
      }
  }
}

bool Resolver::isSubstrateValue(const Json& j) const {
  if (j.is_string()) return isSubstrateName(j.get_ref<const std::string&>());
  if (!j.is_object()) return false;
  auto k = j.find("kind");
  if (k == j.end() || !k->is_string()) return false;
  std::string kind = k->get<std::string>();
  if (treeKind(kind)) return true;
  if (kind == "add") {
    for (const char* pin : {"a", "b"})
      if (auto p = j.find(pin); p != j.end() && isSubstrateValue(*p)) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------
// Values

int Resolver::resolveValueNode(const std::string& id) {
  auto it = namedValue_.find(id);
  return it == namedValue_.end() ? -1 : it->second;
}

int Resolver::makeInlineValueNode(const Json& j, const std::string& ptr) {
  if (!budget(ptr)) return -1;
  const std::string kind = j["kind"].get<std::string>();
  const OpSpec* spec = findOpSpec(kind);
  int index = static_cast<int>(out_.values.size());
  out_.values.emplace_back();
  out_.values[index].op = spec->op;
  out_.values[index].pointer = ptr;
  readValueNodeBody(index, j, ptr, *spec);
  return index;
}

PinRef Resolver::defaultPin(const PinSpec& ps) {
  PinRef r;
  r.tag = PinRef::Default;
  if (ps.geoDefault >= 0) {
    r.index = ps.geoDefault;
    r.type = geometryAttrType(static_cast<GeometryAttr>(ps.geoDefault));
  } else {
    r.literal = {ps.def, ps.def, ps.def, ps.def};
    r.literalCount = ps.kind == PinKind::Color ? 3 : 1;
    r.type = ps.kind == PinKind::Color ? VType::Vec3 : VType::Float;
  }
  return r;
}

void Resolver::readValueNodeBody(int index, const Json& j, const std::string& ptr, const OpSpec& spec) {
  std::vector<PinRef> pins(spec.pins.size());
  std::uint16_t attr = 0;
  checkValueNodeKeys(j, ptr, spec);
  for (std::size_t i = 0; i < spec.pins.size(); ++i) {
    const PinSpec& ps = spec.pins[i];
    std::string pp = ptr + "/" + ps.name;
    auto it = j.find(ps.name);
    if (it == j.end()) {
      if (ps.required) d_.error(ptr, fmt::format("missing required pin \"{}\" of a {} node", ps.name, spec.kind));
      pins[i] = defaultPin(ps);
      if (ps.required) pins[i].type = VType::Invalid;
      continue;
    }
    const Json& v = *it;
    switch (ps.kind) {
      case PinKind::Attribute: {
        const std::optional<GeometryAttr> a = enumOfJson(kGeometryAttrNames, v, pp, d_);
        if (a) attr = static_cast<std::uint16_t>(*a);
        pins[i].type = a ? geometryAttrType(*a) : VType::Invalid;
        break;
      }
      case PinKind::TextureRef:
        readTextureRefPin(v, pp, attr, pins[i]);
        break;
      case PinKind::Channels:
        readChannelsPin(v, pp, attr, pins[i]);
        break;
      default:
        pins[i] = readValuePin(v, pp, ps.name);
        break;
    }
  }
  out_.values[index].pins = std::move(pins);
  out_.values[index].attr = attr;
}

/// Reports every key of value node `j` that is neither "kind", "comment" nor a pin of `spec`.
void Resolver::checkValueNodeKeys(const Json& j, const std::string& ptr, const OpSpec& spec) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& key = it.key();
    if (key == "kind" || key == "comment") {
      if (key == "comment" && !it->is_string()) d_.error(ptr + "/comment", "expected a string");
      continue;
    }
    auto ps = std::find_if(spec.pins.begin(), spec.pins.end(), [&](const PinSpec& p) { return key == p.name; });
    if (ps == spec.pins.end()) {
      std::string list;
      for (const auto& p : spec.pins) list += (list.empty() ? "" : ", ") + std::string(p.name);
      d_.error(ptr + "/" + pointerToken(key), fmt::format("unknown pin {} for a {} node (pins: {})",
                                                          quoteForDiagnostic(key), spec.kind, list));
    }
  }
}

/// A texture pin `v` (a "$name" texture2d input reference) into `attr` (the input index) and `pin`.
void Resolver::readTextureRefPin(const Json& v, const std::string& pp, std::uint16_t& attr, PinRef& pin) {
  if (v.is_string() && !v.get<std::string>().empty() && v.get<std::string>()[0] == '$') {
    std::string n = v.get<std::string>().substr(1);
    auto f = inputIndex_.find(n);
    if (f == inputIndex_.end()) {
      if (!badInputs_.count(n)) d_.error(pp, fmt::format("unknown input {}", quoteForDiagnostic("$" + n)));
    } else if (out_.inputs[f->second].type != VType::Texture) {
      d_.error(pp, fmt::format("input {} is a {}, expected a texture2d input",
                               quoteForDiagnostic("$" + n),
                               typeWord(out_.inputs[f->second].type, out_.inputs[f->second].isColor)));
    } else {
      attr = static_cast<std::uint16_t>(f->second);
      pin.type = VType::Texture;
    }
  } else {
    d_.error(pp, fmt::format("expected a texture2d input reference like \"$albedo\", got {}", kindOfJson(v)));
  }
}

/// A swizzle pin `v` (1-4 of xyzw or rgba) packed into `attr`; `pin` is typed as a marker only.
void Resolver::readChannelsPin(const Json& v, const std::string& pp, std::uint16_t& attr, PinRef& pin) {
  bool ok = v.is_string() && !v.get<std::string>().empty() && v.get<std::string>().size() <= 4;
  std::uint16_t packed = 0;
  if (ok) {
    std::string s = v.get<std::string>();
    for (std::size_t c = 0; c < s.size(); ++c) {
      int idx = -1;
      switch (s[c]) {
        case 'x': case 'r': idx = 0; break;
        case 'y': case 'g': idx = 1; break;
        case 'z': case 'b': idx = 2; break;
        case 'w': case 'a': idx = 3; break;
        default: ok = false;
      }
      if (idx >= 0) packed |= static_cast<std::uint16_t>(idx << (2 * c));
    }
    packed |= static_cast<std::uint16_t>(s.size() << 8);
  }
  if (!ok) d_.error(pp, fmt::format("expected 1 to 4 channels from xyzw or rgba, got {}", kindOfJson(v)));
  attr = ok ? packed : 0;
  pin.type = ok ? VType::Float : VType::Invalid;  // marker only
}

PinRef Resolver::readValuePin(const Json& j, const std::string& ptr, const std::string& pinName) {
  PinRef r;
  if (j.is_number()) {
    r.tag = PinRef::Literal;
    double x = j.get<double>();
    r.literal = {x, x, x, x};
    r.literalCount = 1;
    r.type = VType::Float;
    return r;
  }
  if (j.is_array()) {
    if (j.size() < 2 || j.size() > 4 || !std::all_of(j.begin(), j.end(), [](const Json& e) { return e.is_number(); })) {
      d_.error(ptr, fmt::format("expected a number or an array of 2, 3 or 4 numbers, got {}",
                                j.size() >= 2 && j.size() <= 4 ? "an array with a non-number" : kindOfJson(j)));
      return r;
    }
    r.tag = PinRef::Literal;
    r.literalCount = static_cast<int>(j.size());
    for (std::size_t i = 0; i < j.size(); ++i) r.literal[i] = j[i].get<double>();
    r.type = vectorType(r.literalCount);
    return r;
  }
  if (j.is_string()) return readReferencePin(j.get<std::string>(), ptr, pinName);
  if (j.is_object()) return readInlineValuePin(j, ptr, pinName);
  d_.error(ptr, fmt::format("expected a value (a number, an array of 2-4 numbers, a reference or an inline "
                            "node), got {}", kindOfJson(j)));
  return r;
}

/// A pin given as "$input": the input, unless unknown or a texture.
PinRef Resolver::readInputPin(const std::string& s, const std::string& ptr) {
  PinRef r;
  std::string n = s.substr(1);
  auto f = inputIndex_.find(n);
  if (f == inputIndex_.end()) {
    if (!badInputs_.count(n)) d_.error(ptr, fmt::format("unknown input {}", quoteForDiagnostic(s)));
    return r;
  }
  if (out_.inputs[f->second].type == VType::Texture) {
    d_.error(ptr, fmt::format("{} is a texture2d input; sample it with a \"texture\" node", quoteForDiagnostic(s)));
    return r;
  }
  r.tag = PinRef::Input;
  r.index = f->second;
  r.type = out_.inputs[f->second].type;
  return r;
}

/// A pin given as a string `s`: an input "$name", or a reference "id" or
/// "id.output" to a named value node.
PinRef Resolver::readReferencePin(const std::string& s, const std::string& ptr, const std::string& pinName) {
  PinRef r;
  if (!s.empty() && s[0] == '$') return readInputPin(s, ptr);
  {
    char* end = nullptr;
    std::strtod(s.c_str(), &end);
    if (!s.empty() && end && *end == '\0') {
      d_.error(ptr, fmt::format("expected a number, got the string {} (remove the quotes)", quoteForDiagnostic(s)));
      return r;
    }
  }
  std::string id = s, output;
  if (auto dot = s.find('.'); dot != std::string::npos) {
    id = s.substr(0, dot);
    output = s.substr(dot + 1);
  }
  if (!namedKind_.count(id)) {
    if (inputIndex_.count(id))
      d_.error(ptr, fmt::format("unknown node {}; to use the input write {}", quoteForDiagnostic(id),
                                quoteForDiagnostic("$" + id)));
    else
      d_.error(ptr, fmt::format("unknown node {}", quoteForDiagnostic(id)));
    return r;
  }
  if (isSubstrateName(id)) {
    d_.error(ptr, fmt::format("expected a value, got Substrate node {}", quoteForDiagnostic(id)));
    return r;
  }
  if (namedKind_[id] != 1) return r;  // already reported
  int index = resolveValueNode(id);
  if (index < 0) return r;
  r.tag = PinRef::Node;
  r.index = index;
  const OpSpec* spec = findOpSpec(kindOf(*namedJson_[id]));
  if (!spec) return r;
  selectNamedOutput(r, spec, id, output, ptr, pinName);
  return r;
}

/// The output of node `id` (of kind `spec`) that reference `r` reads: `output`
/// when named, else the one named like the pin of a multi-output helper.
void Resolver::selectNamedOutput(PinRef& r, const OpSpec* spec, const std::string& id, const std::string& output,
                                 const std::string& ptr, const std::string& pinName) {
  if (output.empty()) {
    if (spec->outputs.size() > 1 && spec->op != Op::Sample) {
      // An unnamed reference to a multi-output helper picks the output named
      // like the pin (f0 -> .f0), which is what an author writing it means.
      auto f = std::find(spec->outputs.begin(), spec->outputs.end(), pinName);
      if (f == spec->outputs.end()) {
        std::string list;
        for (auto* o : spec->outputs) list += (list.empty() ? "." : ", .") + std::string(o);
        d_.error(ptr, fmt::format("node {} has several outputs; name one ({})", quoteForDiagnostic(id), list));
        r.tag = PinRef::Default;
        return;
      }
      r.output = static_cast<int>(f - spec->outputs.begin());
    }
  } else {
    auto f = std::find(spec->outputs.begin(), spec->outputs.end(), output);
    if (f == spec->outputs.end()) {
      if (spec->outputs.empty())
        d_.error(ptr, fmt::format("node {} has a single output; write {} without a suffix",
                                  quoteForDiagnostic(id), quoteForDiagnostic(id)));
      else {
        std::string list;
        for (auto* o : spec->outputs) list += (list.empty() ? "." : ", .") + std::string(o);
        d_.error(ptr, fmt::format("node {} has no output {} (outputs: {})", quoteForDiagnostic(id),
                                  quoteForDiagnostic("." + output), list));
      }
      r.tag = PinRef::Default;
      return;
    }
    r.output = static_cast<int>(f - spec->outputs.begin());
  }
}

/// A pin given as an inline value node `j`.
PinRef Resolver::readInlineValuePin(const Json& j, const std::string& ptr, const std::string& pinName) {
  PinRef r;
  auto k = j.find("kind");
  if (k == j.end() || !k->is_string()) {
    d_.error(ptr, "inline node is missing \"kind\"");
    return r;
  }
  std::string kind = k->get<std::string>();
  if (isSubstrateValue(j)) {
    d_.error(ptr, fmt::format("expected a value, got an inline Substrate node ({})", kind));
    return r;
  }
  const OpSpec* spec = findOpSpec(kind);
  if (!spec) {
    d_.error(ptr + "/kind", fmt::format("unknown node kind {}", quoteForDiagnostic(kind)));
    return r;
  }
  int index = makeInlineValueNode(j, ptr);
  if (index < 0) return r;
  r.tag = PinRef::Node;
  r.index = index;
  if (spec->outputs.size() > 1 && spec->op != Op::Sample) {
    auto f = std::find(spec->outputs.begin(), spec->outputs.end(), pinName);
    if (f == spec->outputs.end()) {
      std::string list;
      for (auto* o : spec->outputs) list += (list.empty() ? "." : ", .") + std::string(o);
      d_.error(ptr, fmt::format("inline {} node has several outputs ({}) and none is named \"{}\"; "
                                "make it a named node and reference one output",
                                kind, list, pinName));
      r.tag = PinRef::Default;
      return r;
    }
    r.output = static_cast<int>(f - spec->outputs.begin());
  }
  return r;
}

// ---------------------------------------------------------------------------
// Substrate

int Resolver::resolveSubstrateNode(const std::string& id) {
  auto it = namedSubstrate_.find(id);
  return it == namedSubstrate_.end() ? -1 : it->second;
}

int Resolver::readSubstratePin(const Json& j, const std::string& ptr, const std::string& nameForInline) {
  if (j.is_string()) {
    const std::string& s = j.get_ref<const std::string&>();
    if (isSubstrateName(s)) return resolveSubstrateNode(s);
    if (!s.empty() && s[0] == '$')
      d_.error(ptr, fmt::format("expected a Substrate node, got input {}", quoteForDiagnostic(s)));
    else if (isValueKindName(s.substr(0, s.find('.'))))
      d_.error(ptr, fmt::format("expected a Substrate node, got value node {}", quoteForDiagnostic(s)));
    else if (!namedKind_.count(s))
      d_.error(ptr, fmt::format("unknown node {}", quoteForDiagnostic(s)));
    return -1;
  }
  if (j.is_object()) {
    auto k = j.find("kind");
    if (k == j.end() || !k->is_string()) {
      d_.error(ptr, "inline node is missing \"kind\"");
      return -1;
    }
    std::string kind = k->get<std::string>();
    if (kind == "add" ? isSubstrateValue(j) : treeKind(kind).has_value())
    {
      if (!budget(ptr)) return -1;
      int index = static_cast<int>(out_.substrate.size());
      out_.substrate.emplace_back();
      out_.substrate[index].id = nameForInline;
      out_.substrate[index].pointer = ptr;
      fillSubstrateNode(index, j, ptr, kind == "add" ? TreeOp::Add : *treeKind(kind));
      return index;
    }
    if (findOpSpec(kind))
      d_.error(ptr, fmt::format("expected a Substrate node, got an inline {} value node", kind));
    else
      d_.error(ptr + "/kind", fmt::format("unknown node kind {}", quoteForDiagnostic(kind)));
    return -1;
  }
  d_.error(ptr, fmt::format("expected a Substrate node (an id or an inline slab/operator), got {}", kindOfJson(j)));
  return -1;
}

void Resolver::checkRange(const PinRef& pin, const Json& j, const std::string& ptr, double lo, double hi,
                          const char* what) {
  if (pin.tag != PinRef::Literal) return;
  for (int i = 0; i < pin.literalCount; ++i) {
    if (pin.literal[i] < lo || pin.literal[i] > hi) {
      std::string range = hi >= 1e300 ? fmt::format(">= {:g}", lo) : fmt::format("in [{:g},{:g}]", lo, hi);
      d_.error(ptr, fmt::format("expected {} {}, got {}", what, range, kindOfJson(j).substr(0, 80)));
      return;
    }
  }
}

bool Resolver::expectPinType(PinRef& pin, PinKind kind, const std::string& ptr, bool* color) {
  if (pin.type == VType::Invalid) return false;
  VType want = VType::Invalid;
  bool broadcast = false;
  switch (kind) {
    case PinKind::Float: want = VType::Float; break;
    case PinKind::Color: want = VType::Vec3; broadcast = true; break;
    case PinKind::Vec3: want = VType::Vec3; break;
    case PinKind::Vec2: want = VType::Vec2; break;
    default: return true;
  }
  if (color) *color = broadcast;
  if (pin.type == want || (broadcast && pin.type == VType::Float)) return true;
  d_.error(ptr, fmt::format("expected a {}, got a {}", kind == PinKind::Color ? "color" : std::string(typeName(want)),
                            typeName(pin.type)));
  pin.type = VType::Invalid;
  return false;
}

void Resolver::fillSubstrateNode(int index, const Json& j, const std::string& ptr, TreeOp op) {
  out_.substrate[index].op = op;
  SNode node;  // filled locally: out_.substrate may reallocate during recursion
  if (const BlockSignature* block = op == TreeOp::Slab ? blockOf(j["kind"].get<std::string>()) : nullptr)
    fillBlockNode(index, j, ptr, *block, node);
  else if (op == TreeOp::Slab)
    fillSlabNode(index, j, ptr, node);
  else
    fillOperatorNode(index, j, ptr, op, node);
  SNode& dst = out_.substrate[index];
  node.op = dst.op;
  node.id = dst.id;
  node.pointer = dst.pointer;
  dst = std::move(node);
}

void Resolver::fillOperatorNode(int index, const Json& j, const std::string& ptr, TreeOp op, SNode& node) {
  const std::string id = out_.substrate[index].id;
  auto checkKeys = [&](std::initializer_list<const char*> keys) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      const std::string& k = it.key();
      if (k == "kind" || k == "comment") continue;
      bool known = false;
      for (const char* kk : keys) known = known || k == kk;
      if (!known) {
        std::string list;
        for (const char* kk : keys) list += (list.empty() ? "" : ", ") + std::string(kk);
        d_.error(ptr + "/" + pointerToken(k), fmt::format("unknown pin {} for a {} node (pins: {})",
                                                          quoteForDiagnostic(k), j["kind"].get<std::string>(), list));
      }
    }
  };
  auto sub = [&](const char* pin, bool required, int& dst) {
    auto it = j.find(pin);
    if (it == j.end()) {
      if (required) d_.error(ptr, fmt::format("missing required pin \"{}\"", pin));
      return;
    }
    dst = readSubstratePin(*it, ptr + "/" + pin, (id.empty() ? std::string("node") : id) + "_" + pin);
  };
  auto val = [&](const char* pin, bool required, double def, double lo, double hi, PinRef& dst) {
    auto it = j.find(pin);
    if (it == j.end()) {
      if (required) d_.error(ptr, fmt::format("missing required pin \"{}\"", pin));
      dst.tag = PinRef::Default;
      dst.literal = {def, def, def, def};
      dst.literalCount = 1;
      dst.type = VType::Float;
      return;
    }
    dst = readValuePin(*it, ptr + "/" + pin, pin);
    if (dst.tag == PinRef::Node) deferred_.push_back({index, &dst == &node.a ? -1 : -2, PinKind::Float, ptr + "/" + pin});
    if (expectPinType(dst, PinKind::Float, ptr + "/" + pin)) checkRange(dst, *it, ptr + "/" + pin, lo, hi, "a float");
  };
  constexpr double kBig = 1e300;
  switch (op) {
    case TreeOp::Horizontal:
      checkKeys({"background", "foreground", "mix"});
      sub("background", true, node.left);
      sub("foreground", true, node.right);
      val("mix", true, 0.5, 0, 1, node.a);
      break;
    case TreeOp::Vertical:
      checkKeys({"top", "base", "thickness"});
      sub("top", true, node.left);
      sub("base", true, node.right);
      val("thickness", false, 0.0001, 0, kBig, node.a);
      break;
    case TreeOp::Add:
      checkKeys({"a", "b"});
      sub("a", true, node.left);
      sub("b", true, node.right);
      break;
    case TreeOp::CoverageWeight:
      checkKeys({"a", "weight"});
      sub("a", true, node.left);
      val("weight", true, 1, 0, 1, node.a);
      break;
    case TreeOp::Select:
      checkKeys({"a", "b", "value", "threshold"});
      sub("a", true, node.left);
      sub("b", true, node.right);
      val("value", true, 0, -kBig, kBig, node.a);
      val("threshold", false, 0.5, -kBig, kBig, node.b);
      break;
    case TreeOp::Slab: break;  // fillSlabNode
  }
}

void Resolver::fillBlockNode(int index, const Json& j, const std::string& ptr, const BlockSignature& sig,
                             SNode& node) {
  const std::string id = out_.substrate[index].id.empty() ? std::string("node") : out_.substrate[index].id;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k == "kind" || k == "comment") continue;
    if (std::none_of(sig.pins.begin(), sig.pins.end(), [&](const BlockPin& p) { return k == p.name; })) {
      std::string list;
      for (const BlockPin& p : sig.pins) list += (list.empty() ? "" : ", ") + std::string(p.name);
      d_.error(ptr + "/" + pointerToken(k),
               fmt::format("unknown pin {} for a {} node (pins: {})", quoteForDiagnostic(k), sig.kind, list));
    }
  }
  node.kind = BsdfKind::Slab;  // a placeholder: every slab pin keeps its default
  for (int p = 0; p < kSlabPinCount; ++p) readSlabPin(index, Json::object(), ptr, p, node.slabPins[p]);
  for (const BlockPin& pin : sig.pins) {
    auto it = j.find(pin.name);
    if (it == j.end()) {
      if (pin.required) d_.error(ptr, fmt::format("missing required pin \"{}\"", pin.name));
      continue;
    }
    const std::string pp = ptr + "/" + pin.name;
    switch (pin.kind) {
      case BlockPin::Kind::Substrate: {
        const int child = readSubstratePin(*it, pp, id + "_" + pin.name);
        (node.left < 0 ? node.left : node.right) = child;
        break;
      }
      case BlockPin::Kind::Number:
        if (!it->is_number())
          d_.error(pp, fmt::format("expected a literal number (it decides the {}'s expansion), got {}", sig.kind,
                                   kindOfJson(*it)));
        else if (it->get<double>() < pin.lo || it->get<double>() > pin.hi)
          d_.error(pp, fmt::format("expected a number in [{:g},{:g}], got {}", pin.lo, pin.hi, kindOfJson(*it)));
        break;
      case BlockPin::Kind::Choice:
        if (!it->is_string() || std::none_of(pin.choices.begin(), pin.choices.end(),
                                             [&](const char* c) { return it->get<std::string>() == c; })) {
          std::string list;
          for (const char* c : pin.choices) list += (list.empty() ? "\"" : ", \"") + std::string(c) + "\"";
          d_.error(pp, fmt::format("expected one of {}, got {}", list, kindOfJson(*it)));
        }
        break;
      case BlockPin::Kind::Flag:
        if (!it->is_boolean()) d_.error(pp, fmt::format("expected true or false, got {}", kindOfJson(*it)));
        break;
      default: readBlockValuePin(index, *it, pp, pin);
    }
  }
}

void Resolver::readBlockValuePin(int index, const Json& v, const std::string& pp, const BlockPin& pin) {
  const PinKind kind = pin.kind == BlockPin::Kind::Float   ? PinKind::Float
                       : pin.kind == BlockPin::Kind::Color ? PinKind::Color
                       : pin.kind == BlockPin::Kind::Vec3  ? PinKind::Vec3
                                                           : PinKind::Vec2;
  blockPins_.push_back(readValuePin(v, pp, pin.name));
  PinRef& dst = blockPins_.back();
  if (dst.tag == PinRef::Node)
    deferred_.push_back({index, -3 - static_cast<int>(blockPins_.size() - 1), kind, pp});
  if (expectPinType(dst, kind, pp) && kind != PinKind::Vec2)
    checkRange(dst, v, pp, pin.lo, pin.hi, kind == PinKind::Color ? "a color with components" : "a float");
}


namespace {
/// The pins a BSDF kind other than the slab takes, for "unknown pin" errors.
std::string pinListOf(BsdfKind kind) {
  std::string list;
  for (int p = 0; p < kSlabPinCount; ++p)
    if (bsdfTakesPin(kind, static_cast<SlabPin>(p)))
      list += (list.empty() ? "" : ", ") + std::string(slabPinInfo(static_cast<SlabPin>(p)).name);
  return list;
}
}  // namespace

void Resolver::fillSlabNode(int index, const Json& j, const std::string& ptr, SNode& node) {
  node.kind = bsdfKindByName(j["kind"].get<std::string>()).value_or(BsdfKind::Slab);
  const bool slab = node.kind == BsdfKind::Slab;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k == "kind" || k == "comment" || (slab && (k == "sss_type" || k == "specular_profile"))) continue;
    const std::optional<SlabPin> p = slabPinByName(k);
    if (!p || !bsdfTakesPin(node.kind, *p))
      d_.error(ptr + "/" + pointerToken(k),
               slab ? fmt::format("unknown slab pin {}", quoteForDiagnostic(k))
                    : fmt::format("unknown pin {} for {} {} node (pins: {})", quoteForDiagnostic(k),
                                  std::string_view("aeiou").find(bsdfKindName(node.kind)[0]) != std::string_view::npos
                                      ? "an"
                                      : "a",
                                  bsdfKindName(node.kind),
                                  pinListOf(node.kind)));
  }
  // A pin the kind does not take keeps its default (an unlit's slab pins, a
  // hair's normal: nothing reads them).
  for (int p = 0; p < kSlabPinCount; ++p)
    if (bsdfTakesPin(node.kind, static_cast<SlabPin>(p)))
      readSlabPin(index, j, ptr, p, node.slabPins[p]);
    else
      readSlabPin(index, Json::object(), ptr, p, node.slabPins[p]);
  if (!slab) return;
  if (auto it = j.find("sss_type"); it != j.end()) {
    const std::optional<SssType> t = enumOfJson(kSssTypeNames, *it, ptr + "/sss_type", d_);
    if (t) node.sssType = *t;
    node.sssTypeExplicit = t.has_value();
  }
  if (auto it = j.find("specular_profile"); it != j.end()) {
    std::string pp = ptr + "/specular_profile";
    if (it->is_string() && !it->get<std::string>().empty() && it->get<std::string>()[0] == '$') {
      auto f = inputIndex_.find(it->get<std::string>().substr(1));
      if (f == inputIndex_.end())
        d_.error(pp, fmt::format("unknown input {}", quoteForDiagnostic(it->get<std::string>())));
      else if (out_.inputs[f->second].type != VType::Texture)
        d_.error(pp, fmt::format("specular profile {} must be a texture2d input (a view/light LUT)",
                                 quoteForDiagnostic(it->get<std::string>())));
      else
        node.specularProfileInput = f->second;
    } else {
      d_.error(pp, fmt::format("expected a texture2d input reference like \"$lut\", got {}", kindOfJson(*it)));
    }
  }
}

void Resolver::readSlabPin(int index, const Json& j, const std::string& ptr, int p, PinRef& dst) {
  const SlabPinInfo& info = slabPinInfo(static_cast<SlabPin>(p));
  auto it = j.find(std::string(info.name));
  if (it == j.end()) {
    dst.tag = PinRef::Default;
    if (info.geometryDefault >= 0) {
      dst.index = info.geometryDefault;
      dst.type = info.type;
    } else {
      dst.literal = {info.defaultValue, info.defaultValue, info.defaultValue, info.defaultValue};
      dst.literalCount = componentCount(info.type);
      dst.type = info.type;
    }
    return;
  }
  std::string pp = ptr + "/" + std::string(info.name);
  dst = readValuePin(*it, pp, std::string(info.name));
  PinKind kind = info.color ? PinKind::Color
                            : info.type == VType::Float ? PinKind::Float
                            : info.type == VType::Vec2 ? PinKind::Vec2 : PinKind::Vec3;
  if (dst.tag == PinRef::Node) deferred_.push_back({index, p, kind, pp});
  if (expectPinType(dst, kind, pp)) {
    const char* what = info.color ? "a color with components" : "a float";
    if (info.type == VType::Vec3 && !info.color) what = "a vector with components";
    if (info.type != VType::Vec2) checkRange(dst, *it, pp, info.lo, info.hi, what);
    if (dst.tag == PinRef::Literal && info.type == VType::Vec3 && !info.color) {
      double len2 = dst.literal[0] * dst.literal[0] + dst.literal[1] * dst.literal[1] +
                    dst.literal[2] * dst.literal[2];
      if (len2 < 1e-12) d_.error(pp, fmt::format("expected a non-zero direction, got {}", kindOfJson(*it)));
    }
  }
}

// ---------------------------------------------------------------------------
// Typing (value nodes) and cycle detection (values and Substrate)

void Resolver::typeValueNodes() {
  const int n = static_cast<int>(out_.values.size());
  std::vector<std::uint8_t> state(n, 0);  // 0 new, 1 on stack, 2 done
  // Iterative post-order DFS; a back edge is a cycle.
  for (int start = 0; start < n; ++start) {
    if (state[start]) continue;
    std::vector<std::pair<int, std::size_t>> stack{{start, 0}};
    state[start] = 1;
    while (!stack.empty()) {
      auto& [i, next] = stack.back();
      VNode& v = out_.values[i];
      if (next < v.pins.size()) {
        PinRef& p = v.pins[next++];
        if (p.tag != PinRef::Node) continue;
        if (state[p.index] == 1) {
          std::vector<std::string> names;
          bool on = false;
          for (auto& [si, sn] : stack) {
            if (si == p.index) on = true;
            if (on) names.push_back(out_.values[si].id.empty() ? out_.values[si].pointer : out_.values[si].id);
          }
          names.push_back(out_.values[p.index].id.empty() ? out_.values[p.index].pointer : out_.values[p.index].id);
          d_.error(v.pointer, fmt::format("cycle in values: {}", cycleChain(names)));
          p.tag = PinRef::Default;
          p.type = VType::Invalid;
          continue;
        }
        if (state[p.index] == 0) {
          state[p.index] = 1;
          stack.push_back({p.index, 0});
        }
        continue;
      }
      typeValueNode(i);
      state[i] = 2;
      out_.valueOrder.push_back(i);
      stack.pop_back();
    }
  }
}

VType Resolver::valueOutputType(const PinRef& p) const {
  if (p.tag != PinRef::Node) return p.type;
  const VNode& v = out_.values[p.index];
  if (v.outputTypes.empty()) return VType::Invalid;
  return v.outputTypes[std::min<std::size_t>(p.output, v.outputTypes.size() - 1)];
}

void Resolver::typeValueNode(int i) {
  VNode& v = out_.values[i];
  const OpSpec* spec = nullptr;
  for (const auto& s : opSpecs())
    if (s.op == v.op) spec = &s;
  for (auto& p : v.pins)
    if (p.tag == PinRef::Node) p.type = valueOutputType(p);
  bool bad = false;
  for (auto& p : v.pins)
    if (p.type == VType::Invalid) bad = true;
  if (bad) {
    v.outputTypes.assign(std::max<std::size_t>(1, spec->outputs.size()), VType::Invalid);
    return;
  }
  typeOperatorNode(v, spec);
}

// long: one case per operator's typing rule, the table of docs/value-nodes.md's
// types (the helpers, whose pins have fixed kinds, are typeHelperNode's).
void Resolver::typeOperatorNode(VNode& v, const OpSpec* spec) {
  auto err = [&](const std::string& pin, const std::string& msg) {
    d_.error(v.pointer + (pin.empty() ? "" : "/" + pin), msg);
    v.outputTypes.assign(std::max<std::size_t>(1, spec->outputs.size()), VType::Invalid);
  };
  auto combine2 = [&](VType a, VType b, const char* pa, const char* pb, VType& outT) -> bool {
    if (a == b || b == VType::Float) { outT = a; return true; }
    if (a == VType::Float) { outT = b; return true; }
    err("", fmt::format("cannot combine {} \"{}\" with {} \"{}\" (a float broadcasts; vectors must match)",
                        typeName(a), pa, typeName(b), pb));
    return false;
  };
  VType r = VType::Invalid;
  switch (v.op) {
    case Op::Geometry: r = geometryAttrType(static_cast<GeometryAttr>(v.attr)); break;
    case Op::Sample:
      if (v.pins[1].type != VType::Vec2) return err("uv", fmt::format("expected a vec2, got a {}", typeName(v.pins[1].type)));
      v.outputTypes = {VType::Vec3, VType::Float, VType::Float, VType::Float, VType::Float};
      return;
    case Op::Add: case Op::Subtract: case Op::Multiply: case Op::Divide: case Op::Min: case Op::Max:
      if (!combine2(v.pins[0].type, v.pins[1].type, "a", "b", r)) return;
      break;
    case Op::Pow:
      if (!combine2(v.pins[0].type, v.pins[1].type, "x", "y", r)) return;
      break;
    case Op::Lerp: {
      if (!combine2(v.pins[0].type, v.pins[1].type, "a", "b", r)) return;
      VType t = v.pins[2].type;
      if (t != VType::Float && t != r) return err("t", fmt::format("expected a float or a {}, got a {}", typeName(r), typeName(t)));
      break;
    }
    case Op::FlipFlop:  // facing and grazing as a lerp's a and b; falloff and normal by their kinds
      if (!combine2(v.pins[0].type, v.pins[1].type, "facing", "grazing", r)) return;
      if (!expectPinType(v.pins[2], PinKind::Float, v.pointer + "/falloff") ||
          !expectPinType(v.pins[3], PinKind::Vec3, v.pointer + "/normal"))
        return v.outputTypes.assign(1, VType::Invalid);
      break;
    case Op::Clamp:
      r = v.pins[0].type;
      for (int k = 1; k <= 2; ++k)
        if (v.pins[k].type != VType::Float && v.pins[k].type != r)
          return err(k == 1 ? "lo" : "hi", fmt::format("expected a float or a {}, got a {}", typeName(r), typeName(v.pins[k].type)));
      break;
    case Op::Saturate: case Op::OneMinus: case Op::Abs: case Op::Sqrt: case Op::Normalize:
      r = v.pins[0].type;
      break;
    case Op::Length: r = VType::Float; break;
    case Op::Dot:
      if (v.pins[0].type != v.pins[1].type)
        return err("", fmt::format("dot needs two values of one type, got {} and {}", typeName(v.pins[0].type),
                                   typeName(v.pins[1].type)));
      r = VType::Float;
      break;
    case Op::Swizzle: {
      int count = v.attr >> 8;
      int have = componentCount(v.pins[0].type);
      for (int c = 0; c < count; ++c)
        if (((v.attr >> (2 * c)) & 3) >= have)
          return err("channels", fmt::format("channel out of range for a {}", typeName(v.pins[0].type)));
      r = vectorType(count);
      break;
    }
    case Op::Combine: {
      int count = 0;
      for (std::size_t k = 0; k < v.pins.size(); ++k) {
        if (v.pins[k].tag == PinRef::Default && k >= 2) break;
        if (v.pins[k].type != VType::Float)
          return err(spec->pins[k].name, fmt::format("expected a float, got a {}", typeName(v.pins[k].type)));
        ++count;
      }
      // z without w is fine; w without z is not.
      if (v.pins.size() == 4 && v.pins[2].tag == PinRef::Default && v.pins[3].tag != PinRef::Default)
        return err("w", "\"w\" given without \"z\"");
      r = vectorType(count);
      break;
    }
    default:
      return typeHelperNode(v, spec);
  }
  v.outputTypes = {r};
}

void Resolver::typeHelperNode(VNode& v, const OpSpec* spec) {
  // helpers: pin types were fixed by their PinKind
  VType r = VType::Invalid;
  for (std::size_t k = 0; k < v.pins.size(); ++k) {
    PinRef& p = v.pins[k];
    if (!expectPinType(p, spec->pins[k].kind, v.pointer + "/" + spec->pins[k].name)) {
      v.outputTypes.assign(std::max<std::size_t>(1, spec->outputs.size()), VType::Invalid);
      return;
    }
  }
  switch (v.op) {
    case Op::MetalnessToDiffuseF0: v.outputTypes = {VType::Vec3, VType::Vec3}; return;
    case Op::IorToF0: r = VType::Float; break;
    case Op::HazinessToSecondRoughness: v.outputTypes = {VType::Float, VType::Float}; return;
    case Op::TransmittanceToMfp: v.outputTypes = {VType::Vec3, VType::Float}; return;
    case Op::ThinFilm: v.outputTypes = {VType::Vec3, VType::Vec3}; return;
    case Op::RotationToTangent: r = VType::Vec3; break;
    case Op::ViewDependentCoverage: r = VType::Float; break;
    default: r = VType::Invalid;
  }
  v.outputTypes = {r};
}

/// Pins of Substrate nodes that reference value nodes can only be typed once
/// every value node is typed; checked here with the same rule as literals.
void Resolver::checkDeferredPins() {
  for (const auto& c : deferred_) {
    SNode& s = out_.substrate[c.snode];
    PinRef& pin = c.pin >= 0    ? s.slabPins[c.pin]
                  : c.pin == -1 ? s.a
                  : c.pin == -2 ? s.b
                                : blockPins_[static_cast<std::size_t>(-3 - c.pin)];
    if (pin.tag != PinRef::Node) continue;
    const VNode& v = out_.values[pin.index];
    if (v.outputTypes.empty()) continue;
    pin.type = v.outputTypes[std::min<std::size_t>(pin.output, v.outputTypes.size() - 1)];
    if (pin.type == VType::Invalid) continue;  // already reported
    expectPinType(pin, c.kind, c.pointer);
  }
}

void Resolver::checkSubstrateCycles() {
  const int n = static_cast<int>(out_.substrate.size());
  std::vector<std::uint8_t> state(n, 0);
  for (int start = 0; start < n; ++start) {
    if (state[start]) continue;
    std::vector<std::pair<int, int>> stack{{start, 0}};
    state[start] = 1;
    while (!stack.empty()) {
      auto& [i, next] = stack.back();
      SNode& s = out_.substrate[i];
      if (next < 2) {
        int& child = next++ == 0 ? s.left : s.right;
        if (child < 0) continue;
        if (state[child] == 1) {
          std::vector<std::string> names;
          bool on = false;
          for (auto& [si, sn] : stack) {
            if (si == child) on = true;
            if (on) names.push_back(out_.substrate[si].id);
          }
          names.push_back(out_.substrate[child].id);
          d_.error(s.pointer, fmt::format("cycle in the Substrate graph: {}", cycleChain(names)));
          child = -1;
          continue;
        }
        if (state[child] == 0) {
          state[child] = 1;
          stack.push_back({child, 0});
        }
        continue;
      }
      state[i] = 2;
      stack.pop_back();
    }
  }
}

}  // namespace

std::optional<ResolvedDoc> resolveDocument(const Json& doc, Diagnostics& diags, const ResolveLimits& limits) {
  Resolver r(doc, diags, limits);
  return r.run();
}

}  // namespace substratec
