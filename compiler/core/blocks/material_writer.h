// Writing a substrate-material/1 document (an importer's, or a building
// block's expansion into a document: NodeWriter): unique C
// identifiers for inputs and nodes (one namespace, as the format wants),
// inputs with their source's names and values, named value and Substrate
// nodes, settings, the output; and small constructors for value expressions
// that fold the identities an importer produces all the time (x * 1, x + 0,
// lerp by a literal 0 or 1, literal arithmetic) so that the JSON stays
// readable. The result is text: it goes through the normal parser and
// pipeline (compileText) like any hand-written material.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <nlohmann/json.hpp>

namespace substratec::blocks {

using Json = nlohmann::ordered_json;

/// A pin's value: a literal (number or array), a reference ("$input",
/// "node", "node.output") or an inline value node (an object with "kind").
/// A null Json means "not given" wherever a Value is optional.
using Value = Json;

/// The longest identifier the sanitizer makes: the format allows 128 bytes,
/// which leaves room for a "_<k>" suffix of up to 7 digits.
inline constexpr std::size_t kMaxSanitizedIdentifier = 120;

/// `s` made an identifier usable for every name that reaches generated code
/// (a material, an input, a node; isUsableIdentifier in passes/resolve.h), in
/// one pass: characters other than [A-Za-z0-9_] become '_', runs of '_'
/// collapse, leading and trailing '_' go (generated code adds prefixes and
/// suffixes, so they would make a reserved "__"); a name that would then begin
/// with a digit or with "gl_" in any case, or be a C/GLSL/HLSL keyword or
/// built-in function, gets `prefix` and '_' in front (`gl_Pos` -> `m_gl_Pos`,
/// `float` -> `m_float`); at most kMaxSanitizedIdentifier bytes. Empty when
/// nothing usable is left (the caller's fallback then names it). `prefix`
/// must itself be usable.
std::string sanitizeIdentifier(std::string_view s, std::string_view prefix = "m");

/// Names taken in one namespace, and the search for a free one. Every name it
/// gives out is `base` or `base_<k>`: `claim` tries k = 2, 3, ... from where
/// the last search for the same base stopped (so n equal names cost O(n), not
/// O(n^2)), and gives up with an exception after `maxTries` tries (at most
/// size() + 1 tries can be needed, since every try is a distinct name). With
/// `caseInsensitive`, names that differ only in letter case collide (material
/// names: they become file names and upper-case macros).
class NameSet {
 public:
  explicit NameSet(bool caseInsensitive = false, std::size_t maxTries = std::size_t{1} << 24)
      : caseInsensitive_(caseInsensitive), maxTries_(maxTries) {}
  bool contains(const std::string& name) const { return used_.count(key(name)) != 0; }
  void insert(const std::string& name) { used_.insert(key(name)); }
  std::size_t size() const { return used_.size(); }
  /// A free name like `base` (a usable identifier of at most
  /// kMaxSanitizedIdentifier bytes), now taken.
  std::string claim(const std::string& base);

 private:
  std::string key(const std::string& s) const;
  bool caseInsensitive_;
  std::size_t maxTries_;
  std::unordered_set<std::string> used_;
  std::unordered_map<std::string, std::size_t> next_;  // key(base) -> the next suffix to try
};

/// What an importer writes: its shading model as the format's building block
/// (a `gltf_pbr` node; what the author of the source wrote), or that block's
/// expansion (the slabs, operators and value nodes; `import --expand`).
enum class ImportForm { Blocks, Expanded };

/// One imported material: what its source calls it, its identifier (the
/// material's `name`, unique within its source) and its text.
struct ImportedMaterial {
  std::string sourceName;  // as written in the source ("" when unnamed)
  std::string name;        // a usable identifier, unique among the source's materials
  std::string location;    // where the source defines it (JSON pointer or "line N")
  std::string text;        // substrate-material/1 JSON
  /// Images embedded in the source, by the file name its texture inputs give
  /// them (`file`, relative to the material): bytes as stored (PNG, JPEG).
  std::map<std::string, std::string> images;
};

/// A material identifier for `wanted` (sanitized; `fallback` when that is
/// empty) not yet in `used` (case-insensitively), which it joins.
std::string uniqueMaterialName(NameSet& used, std::string_view wanted, const std::string& fallback);

/// Text from a source (a name, a file name) made fit for a description: valid
/// UTF-8 kept as it is (non-ASCII names stay readable), control characters and
/// bytes that are not UTF-8 written as \xNN, at most `maxBytes` bytes (cut at
/// a character boundary, "..." appended).
std::string descriptionText(std::string_view s, std::size_t maxBytes = 256);
/// `"` + descriptionText(s) + `"`.
std::string quoteForDescription(std::string_view s, std::size_t maxBytes = 256);

/// Where a shading model's unit writes the nodes it names: a material being
/// written (MaterialWriter, the importers) or a document whose building
/// blocks are being expanded (blocks/expand.cc).
class NodeWriter {
 public:
  virtual ~NodeWriter() = default;
  /// A named node (value or Substrate) like `wantedId`; returns its id as a reference.
  virtual Value node(std::string_view wantedId, Json body) = 0;
  /// What a presence that folds to the constant 0 becomes: the literal 0 (the
  /// material has no matter left), or an input of 0 (an importer's, a
  /// block's expansion: the invisible material is kept as one whose coverage
  /// can be raised).
  virtual Value invisiblePresence() { return Value(0.0); }
};

/// A NodeWriter that keeps nothing: a unit run for what it decides (the
/// settings a surface needs), not for its nodes.
class DiscardingNodeWriter final : public NodeWriter {
 public:
  Value node(std::string_view wantedId, Json) override { return std::string(wantedId); }
};

class MaterialWriter : public NodeWriter {
 public:
  /// `name` is the material's name (sanitized; made unique by the caller).
  explicit MaterialWriter(const std::string& name);

  /// A fresh identifier like `wanted` (sanitized; "value" when nothing is
  /// left), not yet used by an input, a node or the material's name.
  std::string uniqueId(std::string_view wanted);

  /// Inputs; each returns the reference "$name" (the name made unique).
  Value floatInput(std::string_view name, double value, std::optional<double> lo, std::optional<double> hi,
                   const std::string& description);
  Value colorInput(std::string_view name, const std::vector<double>& rgb, const std::string& description);
  Value vec2Input(std::string_view name, double x, double y, const std::string& description);
  Value vec3Input(std::string_view name, const std::vector<double>& xyz, const std::string& description);
  /// A texture input; `file` its image, `wrapU`/`wrapV` "repeat", "clamp" or
  /// "mirror" (written only when not both repeat), `nearest` its filter.
  Value textureInput(std::string_view name, bool srgb, const std::string& description, const std::string& file = "",
                     const std::string& wrapU = "repeat", const std::string& wrapV = "repeat", bool nearest = false);

  /// A named node (value or Substrate); returns its id as a reference.
  Value node(std::string_view wantedId, Json body) override;
  /// An input "presence" of 0 in [0, 1].
  Value invisiblePresence() override;

  void setDescription(const std::string& text) { description_ = text; }
  void setSetting(const std::string& key, Json value) { settings_[key] = std::move(value); }
  void setOutput(const Value& root) { output_ = root.get<std::string>(); }

  const std::string& name() const { return name_; }
  /// The inputs written so far (the document's "inputs" object).
  const Json& inputs() const { return inputs_; }
  /// The document as text (2-space indented JSON, '\n'-terminated).
  std::string text() const;

 private:
  Value addInput(std::string_view name, Json body);
  /// addInput with the body's "description" when `description` is not empty.
  Value describedInput(std::string_view name, Json body, const std::string& description);
  std::string name_, description_, output_;
  Json settings_ = Json::object(), inputs_ = Json::object(), nodes_ = Json::object();
  NameSet used_;
};

// ---------------------------------------------------------------------------
// Value expressions. Literals are numbers or arrays of numbers; every
// constructor folds what it can and otherwise returns an inline node.

bool isNull(const Value& v);
/// The literal's components (1 for a number), or nullopt for anything else.
std::optional<std::vector<double>> literalOf(const Value& v);
/// True when `v` is a literal whose every component equals `x`.
bool isLiteral(const Value& v, double x);
/// `x` rounded to 12 significant digits: the binary noise of a computed
/// literal rounded away, so that it reads like its source (0.1 * 3 is 0.3).
double tidy(double x);
/// A number (one component) or an array.
Value literal(const std::vector<double>& c);
Value literal3(double r, double g, double b);

Value mul(const Value& a, const Value& b);
Value add(const Value& a, const Value& b);
Value sub(const Value& a, const Value& b);
Value divide(const Value& a, const Value& b);
Value vmin(const Value& a, const Value& b);
Value vmax(const Value& a, const Value& b);
Value vlerp(const Value& a, const Value& b, const Value& t);
Value oneMinus(const Value& x);
Value saturate(const Value& x);
Value vabs(const Value& x);
Value vsqrt(const Value& x);
Value vpow(const Value& x, const Value& y);
Value vnormalize(const Value& x);
Value vdot(const Value& a, const Value& b);
Value vclamp(const Value& x, const Value& lo, const Value& hi);
Value vlength(const Value& x);
Value swizzle(const Value& x, const std::string& channels);
/// The largest of a colour's three channels (max(max(r, g), b)).
Value max3(const Value& rgb);
Value combine(const std::vector<Value>& components);
Value unaryNode(const std::string& kind, const Value& x);
Value binaryNode(const std::string& kind, const Value& a, const Value& b);
Value geometry(const std::string& attribute);
/// `{"kind": "texture", "texture": tex, "uv": uv}` (uv omitted when null).
Value textureSample(const Value& textureInput, const Value& uv);
/// `node.output` for a named node reference or an inline node's output.
Value outputOf(const Value& nodeRef, const std::string& name);
/// An inline expression as a named node of `w` (an expression used more than
/// once is then written once); references and literals as they are.
Value namedValue(NodeWriter& w, const std::string& id, const Value& v);
/// ((ior − 1) / (ior + 1))² (the ior_to_f0 helper), folded for a literal.
Value iorToF0Value(const Value& ior);

}  // namespace substratec::blocks
