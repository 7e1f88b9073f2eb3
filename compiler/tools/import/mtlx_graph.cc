#include "import/mtlx_graph.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <fmt/format.h>

#include "import/mtlx_hair.h"

namespace substratec::import {

namespace {

constexpr int kMaxNodes = 256;            // nodes along one chain of connections
constexpr int kMaxDepth = 2 * kMaxNodes;  // each node is two calls deep (its input, then itself)

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

std::string str(pugi::xml_node n, const char* attr) { return n.attribute(attr).as_string(); }

bool isColor(const std::string& type) { return type == "color3" || type == "color4"; }

/// Procedural nodes: no value node and no constant to fold; baked into a texture.
const char* const kProceduralKinds[] = {"noise2d", "noise3d", "fractal2d", "fractal3d", "cellnoise2d", "cellnoise3d",
                                      "worleynoise2d", "worleynoise3d", "unifiednoise2d", "unifiednoise3d",
                                      "checkerboard", "randomfloat", "randomcolor", "circle", "cloverleaf",
                                      "hexagon", "grid", "crosshatch", "tiledcircles", "tiledcloverleafs",
                                      "tiledhexagons", "ramp4", "splitlr", "splittb", "ramplr", "ramptb"};

bool isProcedural(const std::string& kind) {
  return std::find(std::begin(kProceduralKinds), std::end(kProceduralKinds), kind) != std::end(kProceduralKinds);
}

/// Nodes without a value node that are evaluated at import when constant.
const char* const kFoldableKinds[] = {"rgbtohsv", "hsvtorgb", "sin", "cos", "tan", "asin", "acos", "atan2", "floor",
                                      "ceil", "round", "modulo", "fract", "exp", "ln", "sign", "smoothstep",
                                      "ifgreater", "ifgreatereq", "ifequal", "rotate2d"};

std::array<double, 3> rgbToHsv(double r, double g, double b) {
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b}), delta = mx - mn;
  double h = 0;
  const double s = mx > 0 ? delta / mx : 0;
  if (delta > 0) {
    if (r >= mx) h = (g - b) / delta;
    else if (g >= mx) h = 2 + (b - r) / delta;
    else h = 4 + (r - g) / delta;
    h /= 6;
    if (h < 0) h += 1;
  }
  return {h, s, mx};
}

std::array<double, 3> hsvToRgb(double h, double s, double v) {
  std::array<double, 3> rgb;
  const double k[3] = {1.0, 2.0 / 3.0, 1.0 / 3.0};
  for (int i = 0; i < 3; ++i) {
    const double x = h + k[i];
    const double p = std::fabs((x - std::floor(x)) * 6 - 3);
    rgb[i] = v * (1 + (std::clamp(p - 1, 0.0, 1.0) - 1) * s);
  }
  return rgb;
}

}  // namespace

Value mtlxLiteral(const std::vector<double>& v, const std::string& type, const std::string& colorspace) {
  const int n = std::max(1, mtlxComponents(type));
  std::vector<double> c = v;
  if (c.size() == 1 && n > 1) c.assign(n, v[0]);
  c.resize(n, c.empty() ? 0.0 : c.back());
  if (isColor(type) && colorspace == "srgb_texture")
    for (int i = 0; i < std::min(n, 3); ++i) c[i] = srgbToLinear(c[i]);
  return literal(c);
}

void MtlxValues::warn(pugi::xml_node at, const std::string& what) {
  int line = 0, column = 0;
  doc_.lineColumn(at, line, column);
  const std::string m = fmt::format("material {}: {}: {}", label_, doc_.describe(at), what);
  if (!warned_.insert(m).second) return;
  d_.warningAt(line, column, m);
}

void MtlxValues::error(pugi::xml_node at, const std::string& what) {
  int line = 0, column = 0;
  doc_.lineColumn(at, line, column);
  d_.errorAt(line, column, fmt::format("{}: {}", doc_.describe(at), what));
  ok_ = false;
}

bool MtlxValues::given(pugi::xml_node shader, const std::string& name) const {
  return static_cast<bool>(shader.find_child_by_attribute("input", "name", name.c_str()));
}

Value MtlxValues::value(pugi::xml_node node, const std::string& name, const std::string& type,
                       const std::vector<double>& def) {
  return inputOf(node, name, type, def, false, 0).v;
}

std::pair<pugi::xml_node, std::string> MtlxValues::upstream(pugi::xml_node node, const std::string& name) const {
  pugi::xml_node in = node.find_child_by_attribute("input", "name", name.c_str());
  if (!in || !in.attribute("nodename")) return {};
  pugi::xml_node n = resolveNodeName(node, str(in, "nodename"));
  if (!n || std::string(n.name()) == "nodegraph") return {};
  return {n, str(in, "output")};
}

std::vector<std::string> MtlxValues::frozenInputsSince(std::size_t count) const {
  std::vector<std::string> names;
  for (std::size_t i = count; i < frozenNames_.size(); ++i)
    if (std::find(names.begin(), names.end(), frozenNames_[i]) == names.end()) names.push_back(frozenNames_[i]);
  return names;
}

pugi::xml_node MtlxValues::resolveNodeName(pugi::xml_node user, const std::string& name) const {
  // A node's inputs name siblings: inside a node graph, the graph's nodes; at
  // the top level, the document's.
  pugi::xml_node scope = user.parent();
  if (scope && std::string(scope.name()) != "materialx") {
    for (pugi::xml_node c : scope.children())
      if (c.type() == pugi::node_element && name == c.attribute("name").as_string() && std::string(c.name()) != "input" &&
          std::string(c.name()) != "output")
        return c;
    return {};
  }
  return doc_.find(name);
}

std::pair<pugi::xml_node, std::string> MtlxValues::resolveGraphOutput(pugi::xml_node graph, const std::string& output,
                                                                      pugi::xml_node at) {
  pugi::xml_node out = output.empty() ? graph.child("output") : graph.find_child_by_attribute("output", "name", output.c_str());
  if (out && output.empty() && out.next_sibling("output")) {  // MaterialX: several outputs need a name
    error(at, fmt::format("node graph '{}' has several outputs: the connection must name one (output=\"...\")",
                          str(graph, "name")));
    return {};
  }
  if (!out) {
    error(at, fmt::format("node graph '{}' has no output '{}'", str(graph, "name"), output));
    return {};
  }
  const std::string nodename = str(out, "nodename");
  pugi::xml_node node;
  for (pugi::xml_node c : graph.children())
    if (c.type() == pugi::node_element && nodename == c.attribute("name").as_string() && std::string(c.name()) != "output" &&
        std::string(c.name()) != "input")
      node = c;
  if (!node) {
    error(out, nodename.empty() ? std::string("the output connects to no node")
                                : fmt::format("the output reads node '{}', which the graph does not have", nodename));
    return {};
  }
  return {node, str(out, "output")};
}

std::optional<MtlxValues::Binding> MtlxValues::implementation(pugi::xml_node instance) const {
  const std::string kind = instance.name();
  for (pugi::xml_node def : doc_.topLevel()) {
    if (std::string(def.name()) != "nodedef" || kind != def.attribute("node").as_string()) continue;
    const std::string defName = str(def, "name");
    for (pugi::xml_node g : doc_.topLevel())
      if (std::string(g.name()) == "nodegraph" && defName == g.attribute("nodedef").as_string())
        return Binding{instance, def, g};
  }
  return std::nullopt;
}

Value MtlxValues::valueInput(const std::string& name, const std::string& type, const std::vector<double>& v,
                             const std::string& what) {
  const Value lit = mtlxLiteral(v, type, "");
  if (type == "float") return w_.floatInput(name, literalOf(lit)->at(0), std::nullopt, std::nullopt, what);
  if (type == "color3") return w_.colorInput(name, *literalOf(lit), what);
  if (type == "vector2") return w_.vec2Input(name, literalOf(lit)->at(0), literalOf(lit)->at(1), what);
  if (type == "vector3") return w_.vec3Input(name, *literalOf(lit), what);
  return lit;  // integer, boolean, 4-vectors: static
}

Value MtlxValues::interfaceInput(pugi::xml_node graphInput, const std::string& name, const std::string& type) {
  const std::string key = std::to_string(graphInput.hash_value());
  auto it = interface_.find(key);
  if (it != interface_.end()) return it->second;
  const auto v = parseMtlxNumbers(str(graphInput, "value"));
  if (!v) {
    error(graphInput, fmt::format("interface input '{}' has no value of type {}", name, type));
    return Value();
  }
  std::vector<double> c = *v;
  if (isColor(type) && str(graphInput, "colorspace") == "srgb_texture") c = *literalOf(mtlxLiteral(c, type, "srgb_texture"));
  Value r = valueInput(name, type, c,
                       fmt::format("{}", doc_.describe(graphInput)));
  interface_[key] = r;
  return r;
}

MtlxValues::Typed MtlxValues::connection(pugi::xml_node input, const std::string& type, bool frozen, int depth,
                                         bool* connected) {
  *connected = true;
  if (depth > kMaxDepth) {
    error(input, fmt::format("the graph is deeper than {} nodes", kMaxNodes));
    return {Value(), type};
  }
  const std::string output = str(input, "output");
  if (input.attribute("nodename")) {
    pugi::xml_node node = resolveNodeName(input.parent(), str(input, "nodename"));
    if (!node) {
      error(input, fmt::format("input '{}' reads node '{}', which is not in its scope", str(input, "name"), str(input, "nodename")));
      return {Value(), type};
    }
    if (std::string(node.name()) == "nodegraph") {
      auto [n, o] = resolveGraphOutput(node, output, input);
      if (!n) return {Value(), type};
      return nodeValue(n, o, frozen, depth + 1);
    }
    return nodeValue(node, output, frozen, depth + 1);
  }
  if (input.attribute("nodegraph")) {
    pugi::xml_node graph = doc_.find(str(input, "nodegraph"));
    if (!graph || std::string(graph.name()) != "nodegraph") {
      error(input, fmt::format("input '{}' reads node graph '{}', which the document does not have", str(input, "name"),
                               str(input, "nodegraph")));
      return {Value(), type};
    }
    auto [n, o] = resolveGraphOutput(graph, output, input);
    if (!n) return {Value(), type};
    return nodeValue(n, o, frozen, depth + 1);
  }
  if (input.attribute("interfacename")) {
    const std::string iname = str(input, "interfacename");
    pugi::xml_node graph = input.parent().parent();
    if (!bindings_.empty() && bindings_.back().graph == graph) {
      const Binding b = bindings_.back();
      pugi::xml_node instIn = b.instance.find_child_by_attribute("input", "name", iname.c_str());
      pugi::xml_node defIn = b.nodedef.find_child_by_attribute("input", "name", iname.c_str());
      bindings_.pop_back();
      Typed r{Value(), type};
      bool c = false;
      if (instIn) r = connection(instIn, type, frozen, depth + 1, &c);
      if (!c) {
        pugi::xml_node src = instIn ? instIn : defIn;
        const auto v = src ? parseMtlxNumbers(str(src, "value")) : std::nullopt;
        if (frozen && instIn) frozenNames_.push_back(iname);
        if (!v) error(input, fmt::format("interface input '{}' has no value", iname));
        else r = {frozen || !instIn ? mtlxLiteral(*v, type, str(src, "colorspace"))
                                    : valueInput(iname, type, *v, doc_.describe(instIn)),
                  type};
      }
      bindings_.push_back(b);
      return r;
    }
    pugi::xml_node gi = graph.find_child_by_attribute("input", "name", iname.c_str());
    if (!gi) {
      error(input, fmt::format("interface name '{}' is not an input of the node graph", iname));
      return {Value(), type};
    }
    bool c = false;
    Typed r = connection(gi, type, frozen, depth + 1, &c);
    if (c) return r;
    if (frozen) {
      frozenNames_.push_back(iname);
      const auto v = parseMtlxNumbers(str(gi, "value"));
      if (!v) {
        error(gi, fmt::format("interface input '{}' has no value", iname));
        return {Value(), type};
      }
      return {mtlxLiteral(*v, type, str(gi, "colorspace")), type};
    }
    return {interfaceInput(gi, iname, type), type};
  }
  *connected = false;
  return {Value(), type};
}

namespace {

/// A value of MaterialX type `from` as type `to` (convert's rules).
Value convertValue(const Value& v, const std::string& from, const std::string& to) {
  const int a = mtlxComponents(from), b = mtlxComponents(to);
  if (a == b || v.is_null() || a == 0 || b == 0) return v;
  if (a == 1) return swizzle(v, std::string(b, 'x'));
  if (b == 1) return swizzle(v, "x");
  if (b < a) return swizzle(v, std::string("xyzw").substr(0, b));
  if (a == 2 && b == 3) return combine({swizzle(v, "x"), swizzle(v, "y"), 0.0});
  if (a == 2 && b == 4) return combine({swizzle(v, "x"), swizzle(v, "y"), 0.0, 1.0});
  return combine({swizzle(v, "x"), swizzle(v, "y"), swizzle(v, "z"), 1.0});  // 3 -> 4
}

/// A connected value `t` can become `to`: both are value types (float,
/// colour, vector...) or the same type; a value whose type is not one (an
/// unknown type such as "color6") would reach a pin with the wrong size.
bool convertible(const Value& v, const std::string& from, const std::string& to) {
  if (v.is_null() || from == to) return true;
  return mtlxComponents(from) > 0 && mtlxComponents(to) > 0;
}

}  // namespace

MtlxValues::Typed MtlxValues::inputOf(pugi::xml_node node, const std::string& name, const std::string& type,
                                      const std::vector<double>& def, bool frozen, int depth) {
  Typed t = declaredInput(node, name, type, def, frozen, depth);
  // An input declared with another size than its node takes (a vector4
  // `pivot` of place2d) is converted to what the node takes, so that the
  // value nodes built from it combine; a float broadcasts as it is.
  const int have = mtlxComponents(t.type), want = mtlxComponents(type);
  if (t.v.is_null() || have == want || have == 1 || want == 0) return t;
  pugi::xml_node in = node.find_child_by_attribute("input", "name", name.c_str());
  if (have == 0) {
    error(in, fmt::format("input '{}' is a '{}', where its node takes a {}", name, t.type, type));
    return {Value(), type};
  }
  warn(in, fmt::format("input '{}' is declared {}, its node takes a {}: converted", name, t.type, type));
  return {convertValue(t.v, t.type, type), type};
}

MtlxValues::Typed MtlxValues::declaredInput(pugi::xml_node node, const std::string& name, const std::string& type,
                                            const std::vector<double>& def, bool frozen, int depth) {
  pugi::xml_node in = node.find_child_by_attribute("input", "name", name.c_str());
  const std::string itype = in && in.attribute("type") ? str(in, "type") : type;
  if (!in) return {def.empty() ? Value() : mtlxLiteral(def, itype, ""), itype};
  bool connected = false;
  Typed t = connection(in, itype, frozen, depth, &connected);
  if (connected && !convertible(t.v, t.type, itype)) {
    error(in, fmt::format("input '{}' of type '{}' is connected to a value of type '{}' (not a value type it converts "
                          "to)", name, itype, t.type));
    return {Value(), itype};
  }
  if (connected) return {convertValue(t.v, t.type, itype), itype};
  if (in.attribute("value")) {
    const auto v = parseMtlxNumbers(str(in, "value"));
    if (!v) {
      error(in, fmt::format("input '{}': value '{}' is not a {}", name, str(in, "value"), itype));
      return {Value(), itype};
    }
    return {mtlxLiteral(*v, itype, str(in, "colorspace")), itype};
  }
  return {def.empty() ? Value() : mtlxLiteral(def, itype, ""), itype};
}

Value MtlxValues::param(pugi::xml_node shader, const std::string& name, const std::string& type,
                        const std::vector<double>& def, ParamKind kind) {
  pugi::xml_node in = shader.find_child_by_attribute("input", "name", name.c_str());
  if (!in) return mtlxLiteral(def, type, "");
  bool connected = false;
  Typed t = connection(in, type, false, 0, &connected);
  if (connected && !convertible(t.v, t.type, type)) {
    error(in, fmt::format("input '{}' of type '{}' is connected to a value of type '{}' (not a value type it converts "
                          "to)", name, type, t.type));
    return mtlxLiteral(def, type, "");
  }
  if (connected) return convertValue(t.v, t.type, type);
  const auto v = parseMtlxNumbers(str(in, "value"));
  if (!v) {
    if (in.attribute("value")) error(in, fmt::format("input '{}': value '{}' is not a {}", name, str(in, "value"), type));
    return mtlxLiteral(def, type, "");
  }
  const Value lit = mtlxLiteral(*v, type, str(in, "colorspace"));
  if (kind == ParamKind::Switch && (isLiteral(lit, 0) || isLiteral(lit, 1))) return lit;
  return valueInput(name, type, *literalOf(lit), fmt::format("{} input {}", str(shader, "name"), name));
}

std::optional<std::vector<double>> MtlxValues::constant(pugi::xml_node shader, const std::string& name,
                                                        const std::string& type, const std::vector<double>& def) {
  Typed t = inputOf(shader, name, type, def, true, 0);
  // Exactly the type's components (callers index them): a single number
  // broadcasts; any other count (an input declared with another type) is
  // not this constant.
  auto lit = literalOf(t.v);
  const std::size_t n = static_cast<std::size_t>(std::max(0, mtlxComponents(type)));
  if (!lit || n == 0 || lit->size() == n) return lit;
  if (lit->size() == 1) return std::vector<double>(n, (*lit)[0]);
  return std::nullopt;
}

MtlxValues::Typed MtlxValues::nodeValue(pugi::xml_node node, const std::string& output, bool frozen, int depth) {
  if (depth > kMaxDepth) {
    error(node, fmt::format("the graph is deeper than {} nodes", kMaxNodes));
    return {Value(), str(node, "type")};
  }
  const std::string binding = bindings_.empty() ? "" : std::to_string(bindings_.back().instance.hash_value());
  const std::string key = fmt::format("{}|{}|{}|{}", node.hash_value(), output, frozen, binding);
  if (auto it = memo_.find(key); it != memo_.end()) return it->second;
  if (!active_.insert(key).second) {
    error(node, "the node depends on itself (a cycle)");
    return {Value(), str(node, "type")};
  }
  const std::string kind = node.name();
  std::string type = str(node, "type");
  if (type == "multioutput") {
    pugi::xml_node o = node.find_child_by_attribute("output", "name", output.c_str());
    if (o) type = str(o, "type");
  }
  Typed t;
  if (auto impl = implementation(node); impl && !isProcedural(kind)) {
    // A node the document defines itself: its implementation graph.
    auto [n, o] = resolveGraphOutput(impl->graph, output, node);
    if (n) {
      pushBinding(*impl);
      t = nodeValue(n, o, frozen, depth + 1);
      popBinding();
    }
  } else {
    t = compute(node, kind, type, output, frozen, depth);
  }
  active_.erase(key);
  if (!frozen && t.v.is_object()) t.v = w_.node(str(node, "name"), t.v);
  memo_[key] = t;
  return t;
}

Value MtlxValues::textureOf(pugi::xml_node node, const std::string& file, bool srgb, const std::string& wrapU,
                            const std::string& wrapV) {
  const std::string key = file + (srgb ? "|srgb" : "|linear") + "|" + wrapU + "|" + wrapV;
  auto it = textures_.find(key);
  if (it != textures_.end()) return it->second;
  std::string stem = std::filesystem::path(file).stem().string();
  if (stem.empty()) stem = str(node, "name");
  const std::string path = doc_.filePrefix(node) + file;
  const Value t = w_.textureInput(stem, srgb, fmt::format("{}: file '{}'", doc_.describe(node), path), path, wrapU, wrapV);
  textures_[key] = t;
  return t;
}

Value MtlxValues::sampleOf(const Value& texture, const Value& uv) {
  const std::string key = texture.get<std::string>() + "|" + uv.dump();
  auto it = samples_.find(key);
  if (it != samples_.end()) return it->second;
  const Value n = w_.node(texture.get<std::string>().substr(1) + "_sample", textureSample(texture, uv));
  samples_[key] = n;
  return n;
}

/// One node being computed (MtlxValues::compute): the element, its kind, the
/// type and output wanted, and the mode (frozen: constants only, where a
/// varying input gives no value). Each node rule is a member, found by kind
/// in rules(); it reads the node's inputs with in().
struct MtlxValues::Call {
  MtlxValues& self;
  pugi::xml_node node;
  const std::string& kind;
  const std::string& type;
  const std::string& output;
  bool frozen;
  int depth;

  using Rule = Typed (Call::*)() const;
  /// Node kind -> its rule; a kind not in it is unsupported().
  static const std::map<std::string, Rule>& rules();

  Value in(const char* name, const std::string& t, std::vector<double> def) const {
    return self.inputOf(node, name, t, def, frozen, depth + 1).v;
  }
  /// The input at its constant value (interface inputs at their defaults); a
  /// single number broadcasts to the type's components (the folds index them).
  std::optional<std::vector<double>> constantIn(const char* name, const std::string& t, std::vector<double> def) const;
  /// The type the document declares on input `name`, else `fallback`.
  std::string declared(const char* name, const std::string& fallback) const {
    pugi::xml_node i = node.find_child_by_attribute("input", "name", name);
    return i ? str(i, "type") : fallback;
  }
  /// In a frozen evaluation, whether any of the values is not a constant.
  bool varies(std::initializer_list<Value> vs) const {
    if (!frozen) return false;
    for (const auto& v : vs)
      if (!literalOf(v)) return true;
    return false;
  }
  Typed none(const std::string& t) const { return {Value(), t}; }

  // Images (texture inputs sampled at uv arithmetic).
  Typed image() const;
  std::optional<Value> imageTexture() const;
  Value imageUv() const;
  Typed imageOutput(const Value& sample) const;
  // Nodes without a value node: folded at import, else baked (or written out).
  Typed procedural() const;
  Typed fold() const;
  std::optional<std::vector<double>> folded() const;
  Typed hsvToRgbNode() const;
  // MaterialX's hair helpers (mtlx_hair.h): folded, else value nodes, else an error.
  Typed hairHelper() const;
  std::optional<std::vector<double>> hairFolded() const;
  Typed hairRoughnessNode() const;
  std::optional<Typed> melaninNode() const;
  // Nodes with value nodes.
  Typed constant() const;
  Typed convert() const;
  Typed binary() const;
  Typed mix() const;
  Typed clamp() const;
  Typed invert() const;
  Typed unaryMath() const;
  Typed dotproduct() const;
  Typed remap() const;
  Typed luminance() const;
  Typed combineN() const;
  Typed extract() const;
  Typed swizzleNode() const;
  Typed normalmap() const;
  Typed texcoord() const;
  Typed place2d() const;
  Typed geometric() const;
  Typed unsupported() const;
};

namespace {

/// p rotated counter-clockwise by `degrees` about the origin.
Value rotated2(const Value& p, double degrees) {
  const double a = degrees * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
  return combine({sub(mul(swizzle(p, "x"), c), mul(swizzle(p, "y"), s)), add(mul(swizzle(p, "x"), s), mul(swizzle(p, "y"), c))});
}

/// A texture sample as a value of `type` (1 to 4 components).
Value sampleAs(const Value& sample, const std::string& type) {
  const int n = mtlxComponents(type);
  if (n == 1) return outputOf(sample, "r");
  if (n == 2) return swizzle(outputOf(sample, "rgb"), "xy");
  if (n == 3) return outputOf(sample, "rgb");
  return combine({outputOf(sample, "r"), outputOf(sample, "g"), outputOf(sample, "b"), outputOf(sample, "a")});
}

/// A tangent-space normal from a normal map's colour, its xy scaled by `scale`.
Value unpackNormal(const Value& rgb, const Value& scale) {
  Value n = sub(mul(rgb, 2.0), 1.0);
  if (!isLiteral(scale, 1)) n = mul(n, combine({scale, scale, 1.0}));
  return vnormalize(n);
}

}  // namespace

const std::map<std::string, MtlxValues::Call::Rule>& MtlxValues::Call::rules() {
  static const std::map<std::string, Rule> table = [] {
    std::map<std::string, Rule> t = {
        {"image", &Call::image}, {"tiledimage", &Call::image}, {"hextiledimage", &Call::image},
        {"gltf_image", &Call::image}, {"gltf_colorimage", &Call::image}, {"gltf_normalmap", &Call::image},
        {"constant", &Call::constant}, {"dot", &Call::constant}, {"convert", &Call::convert},
        {"add", &Call::binary}, {"subtract", &Call::binary}, {"multiply", &Call::binary},
        {"divide", &Call::binary}, {"min", &Call::binary}, {"max", &Call::binary}, {"power", &Call::binary},
        {"mix", &Call::mix}, {"clamp", &Call::clamp}, {"invert", &Call::invert},
        {"absval", &Call::unaryMath}, {"sqrt", &Call::unaryMath}, {"normalize", &Call::unaryMath},
        {"magnitude", &Call::unaryMath}, {"dotproduct", &Call::dotproduct}, {"remap", &Call::remap},
        {"luminance", &Call::luminance}, {"combine2", &Call::combineN}, {"combine3", &Call::combineN},
        {"combine4", &Call::combineN}, {"extract", &Call::extract}, {"separate2", &Call::extract},
        {"separate3", &Call::extract}, {"separate4", &Call::extract}, {"swizzle", &Call::swizzleNode},
        {"normalmap", &Call::normalmap}, {"texcoord", &Call::texcoord}, {"place2d", &Call::place2d},
        {"position", &Call::geometric}, {"normal", &Call::geometric}, {"tangent", &Call::geometric},
        {"bitangent", &Call::geometric}, {"geomcolor", &Call::geometric},
        {"chiang_hair_roughness", &Call::hairHelper}, {"chiang_hair_absorption_from_color", &Call::hairHelper},
        {"deon_hair_absorption_from_melanin", &Call::hairHelper}};
    for (const char* k : kProceduralKinds) t.emplace(k, &Call::procedural);
    for (const char* k : kFoldableKinds) t.emplace(k, &Call::fold);
    return t;
  }();
  return table;
}

MtlxValues::Typed MtlxValues::compute(pugi::xml_node node, const std::string& kind, const std::string& type,
                                      const std::string& output, bool frozen, int depth) {
  const Call call{*this, node, kind, type, output, frozen, depth};
  const auto& rules = Call::rules();
  const auto rule = rules.find(kind);
  return rule == rules.end() ? call.unsupported() : (call.*(rule->second))();
}

// ---- images ----

MtlxValues::Typed MtlxValues::Call::image() const {
  if (frozen) return none(type);
  const std::optional<Value> tex = imageTexture();
  if (!tex) return none(type);
  return imageOutput(self.sampleOf(*tex, imageUv()));
}

/// The texture input for the node's file (followed through interface names),
/// in its colour space; nullopt (an error) without a file.
std::optional<Value> MtlxValues::Call::imageTexture() const {
  pugi::xml_node fileIn = node.find_child_by_attribute("input", "name", "file");
  // The file may come through an interface name.
  for (int guard = 0; fileIn && fileIn.attribute("interfacename") && guard < 8; ++guard) {
    pugi::xml_node graph = fileIn.parent().parent();
    pugi::xml_node next = graph.find_child_by_attribute("input", "name", str(fileIn, "interfacename").c_str());
    if (!self.bindings_.empty() && self.bindings_.back().graph == graph)
      next = self.bindings_.back().instance.find_child_by_attribute("input", "name", str(fileIn, "interfacename").c_str());
    fileIn = next;
  }
  const std::string file = fileIn ? str(fileIn, "value") : "";
  if (file.empty()) {
    self.error(node, "an image node without a file");
    return std::nullopt;
  }
  const std::string cs = fileIn.attribute("colorspace") ? str(fileIn, "colorspace") : "";
  const bool srgb = cs == "srgb_texture" || cs == "srgb_displayp3";
  if (!cs.empty() && !srgb && cs != "lin_rec709" && cs != "raw" && cs != "none")
    self.warn(node, fmt::format("colour space '{}' of the file is read as linear Rec.709", cs));
  std::string wrap[2] = {"repeat", "repeat"};  // MaterialX's periodic
  for (int axis = 0; axis < 2; ++axis)
    if (auto a = node.find_child_by_attribute("input", "name", axis == 0 ? "uaddressmode" : "vaddressmode")) {
      const std::string m = str(a, "value");
      const char* name = axis == 0 ? "uaddressmode" : "vaddressmode";
      if (m == "clamp" || m == "mirror") {
        wrap[axis] = m;
      } else if (m == "constant") {
        wrap[axis] = "clamp";
        self.warn(node, fmt::format("{} 'constant' (the default colour outside [0, 1]) is read as clamp", name));
      } else if (!m.empty() && m != "periodic") {
        self.warn(node, fmt::format("{} '{}' is not an address mode: read as periodic", name, m));
      }
    }
  return self.textureOf(node, file, srgb && (type != "float"), wrap[0], wrap[1]);
}

/// The texture coordinates: the texcoord input (null: uv0) through the
/// tiling or glTF texture transform.
Value MtlxValues::Call::imageUv() const {
  Value uv = in("texcoord", "vector2", {});
  if (uv.is_null()) uv = Value();  // uv0
  auto uvOr0 = [&]() { return uv.is_null() ? geometry("uv0") : uv; };
  if (kind == "tiledimage" || kind == "hextiledimage") {
    // uv = (texcoord · uvtiling − uvoffset) / realworldimagesize · realworldtilesize (identities skipped).
    auto apply = [](Value x, const Value& by, double identity, Value (*op)(const Value&, const Value&)) {
      return isLiteral(by, identity) ? x : op(x, by);
    };
    Value t = apply(uvOr0(), in(kind == "tiledimage" ? "uvtiling" : "tiling", "vector2", {1, 1}), 1, mul);
    if (kind == "tiledimage") {
      t = apply(t, in("uvoffset", "vector2", {0, 0}), 0, sub);
      t = apply(t, in("realworldimagesize", "vector2", {1, 1}), 1, divide);
      t = apply(t, in("realworldtilesize", "vector2", {1, 1}), 1, mul);
    } else {
      self.warn(node, "hexagonal tiling (random rotation, scale and offset per tile, blended) is not represented: "
                      "sampled as a plain tiled image");
    }
    uv = t == geometry("uv0") ? Value() : t;
  } else if (kind == "gltf_image" || kind == "gltf_colorimage" || kind == "gltf_normalmap") {
    const Value scale = in("scale", "vector2", {1, 1}), offset = in("offset", "vector2", {0, 0});
    const double rotate = literalOf(in("rotate", "float", {0})).value_or(std::vector<double>{0})[0];
    if (!isLiteral(scale, 1) || !isLiteral(offset, 0) || rotate != 0) {
      // KHR_texture_transform as MaterialX's gltf nodes apply it (about the pivot (0, 1)).
      const Value pivot = in("pivot", "vector2", {0, 1});
      Value p = mul(sub(uvOr0(), pivot), scale);
      if (rotate != 0) p = rotated2(p, rotate);
      uv = add(add(p, pivot), offset);
    }
  }
  return uv;
}

/// What the image node gives from its sample: a normal, a glTF colour (times
/// its factors) or alpha, or the sample as the node's type.
MtlxValues::Typed MtlxValues::Call::imageOutput(const Value& sample) const {
  const Value rgb = outputOf(sample, "rgb");
  if (kind == "gltf_normalmap") return {unpackNormal(rgb, in("scale", "float", {1})), "vector3"};
  if (kind == "gltf_colorimage") {
    const Value factor = in("color", "color4", {1, 1, 1, 1});
    const Value geom = in("geomcolor", "color4", {1, 1, 1, 1});
    if (output == "outa") {
      Value a = outputOf(sample, "a");
      a = mul(mul(a, swizzle(factor, "w")), swizzle(geom, "w"));
      return {a, "float"};
    }
    Value c = rgb;
    if (!isLiteral(factor, 1)) c = mul(c, swizzle(factor, "xyz"));
    if (!isLiteral(geom, 1)) c = mul(c, swizzle(geom, "xyz"));
    return {c, "color3"};
  }
  Value v = sampleAs(sample, type);
  if (kind == "gltf_image") {
    const Value factor = in("factor", type, {1, 1, 1, 1});
    if (!isLiteral(factor, 1)) v = mul(v, factor);
  }
  return {v, type};
}

// ---- nodes without a value node ----

MtlxValues::Typed MtlxValues::bake(pugi::xml_node node, const std::string& kind, const std::string& type,
                                   const std::string& why) {
  const Value tex = w_.textureInput(std::string(str(node, "name")) + "_baked", false,
                                    fmt::format("bake of {} ({})", doc_.describe(node), kind));
  warn(node, fmt::format("{}: replaced by the texture input '{}' sampled at uv0 (bake the node into it)", why,
                         tex.get<std::string>().substr(1)));
  return {sampleAs(sampleOf(tex, Value()), type), type};
}

MtlxValues::Typed MtlxValues::Call::procedural() const {
  if (frozen) return none(type);
  return self.bake(node, kind, type, fmt::format("the procedural {} has no value node", kind));
}

std::optional<std::vector<double>> MtlxValues::Call::constantIn(const char* name, const std::string& t,
                                                                std::vector<double> def) const {
  auto lit = literalOf(self.inputOf(node, name, t, def, true, depth + 1).v);
  const std::size_t want = static_cast<std::size_t>(std::max(1, mtlxComponents(t)));
  if (lit && lit->size() == 1 && want > 1) lit = std::vector<double>(want, (*lit)[0]);
  return lit;
}

/// A foldable node: its value at import when its inputs are constants (a
/// warning when that freezes a material input); else hsvtorgb written out,
/// anything else baked.
MtlxValues::Typed MtlxValues::Call::fold() const {
  const std::size_t readsBefore = self.frozenReads();
  const std::optional<std::vector<double>> r = folded();
  if (r && std::all_of(r->begin(), r->end(), [](double v) { return std::isfinite(v); })) {
    if (!frozen && self.frozenReads() > readsBefore)
      self.warn(node, fmt::format("{} has no value node: evaluated at import with the material inputs it reads at "
                                  "their values (changing them at run time does not change this)", kind));
    return {mtlxLiteral(*r, type, ""), type};
  }
  if (frozen) return none(type);
  if (kind == "hsvtorgb") return hsvToRgbNode();
  return self.bake(node, kind, type, fmt::format("{} has no value node and its inputs vary", kind));
}

/// The foldable node's value from its inputs' constants (nullopt when one varies).
std::optional<std::vector<double>> MtlxValues::Call::folded() const {
  static const std::map<std::string, double (*)(double)> kUnary = {
      {"sin", [](double x) { return std::sin(x); }},
      {"cos", [](double x) { return std::cos(x); }},
      {"tan", [](double x) { return std::tan(x); }},
      {"asin", [](double x) { return std::asin(std::clamp(x, -1.0, 1.0)); }},
      {"acos", [](double x) { return std::acos(std::clamp(x, -1.0, 1.0)); }},
      {"floor", [](double x) { return std::floor(x); }},
      {"ceil", [](double x) { return std::ceil(x); }},
      {"round", [](double x) { return std::round(x); }},
      {"fract", [](double x) { return x - std::floor(x); }},
      {"exp", [](double x) { return std::exp(x); }},
      {"ln", [](double x) { return x > 0 ? std::log(x) : 0.0; }},
      {"sign", [](double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; }}};
  const int n = std::max(1, mtlxComponents(type));
  // Component i of a (the last one repeats).
  auto at = [](const std::vector<double>& a, int i) { return a[std::min<std::size_t>(i, a.size() - 1)]; };
  if (auto f = kUnary.find(kind); f != kUnary.end()) {
    auto x = constantIn("in", type, {0});
    if (x)
      for (double& v : *x) v = f->second(v);
    return x;
  }
  if (kind == "rgbtohsv" || kind == "hsvtorgb") {
    auto x = constantIn("in", type, {0, 0, 0});
    if (!x || x->size() < 3) return std::nullopt;  // a colour (a float node type has no hue)
    const auto h = kind == "rgbtohsv" ? rgbToHsv((*x)[0], (*x)[1], (*x)[2]) : hsvToRgb((*x)[0], (*x)[1], (*x)[2]);
    std::vector<double> r(h.begin(), h.end());
    if (n == 4) r.push_back(x->size() > 3 ? (*x)[3] : 1);
    return r;
  }
  if (kind == "modulo" || kind == "atan2") {
    auto a = constantIn("in1", type, {0}), b = constantIn("in2", type, {1.0});
    if (!a || !b) return std::nullopt;
    std::vector<double> r(n);
    for (int i = 0; i < n; ++i) {
      const double x = at(*a, i), y = at(*b, i);
      r[i] = kind == "atan2" ? std::atan2(x, y) : (y == 0 ? 0.0 : x - y * std::floor(x / y));
    }
    return r;
  }
  if (kind == "smoothstep") {
    auto x = constantIn("in", type, {0}), lo = constantIn("low", type, {0}), hi = constantIn("high", type, {1});
    if (!x || !lo || !hi) return std::nullopt;
    std::vector<double> r(n);
    for (int i = 0; i < n; ++i) {
      const double a = at(*lo, i), b = at(*hi, i);
      const double t = b == a ? ((*x)[i] >= b ? 1.0 : 0.0) : std::clamp(((*x)[i] - a) / (b - a), 0.0, 1.0);
      r[i] = t * t * (3 - 2 * t);
    }
    return r;
  }
  if (kind == "ifgreater" || kind == "ifgreatereq" || kind == "ifequal") {
    auto a = constantIn("value1", "float", {1}), b = constantIn("value2", "float", {0});
    auto x = constantIn("in1", type, {0}), y = constantIn("in2", type, {0});
    if (!a || !b || !x || !y) return std::nullopt;
    const bool take = kind == "ifgreater" ? (*a)[0] > (*b)[0] : kind == "ifgreatereq" ? (*a)[0] >= (*b)[0] : (*a)[0] == (*b)[0];
    return take ? *x : *y;
  }
  if (kind == "rotate2d") {
    auto x = constantIn("in", "vector2", {0, 0}), a = constantIn("amount", "float", {0});
    if (!x || !a) return std::nullopt;
    const double t = (*a)[0] * std::numbers::pi / 180, cs = std::cos(t), sn = std::sin(t);
    return std::vector<double>{(*x)[0] * cs - (*x)[1] * sn, (*x)[0] * sn + (*x)[1] * cs};
  }
  return std::nullopt;
}

/// hsvtorgb on varying inputs: rgb = v · vlerp(1, saturate(|x − 6| − 3| − 1), s)
/// with x = 6h + (6, 4, 2): the triangle wave |fract(h + k)·6 − 3| folded with
/// abs, exact for h in [−1/3, 1] (h is clamped there).
MtlxValues::Typed MtlxValues::Call::hsvToRgbNode() const {
  const Value hsv = namedValue(self.w_, std::string(str(node, "name")) + "_hsv",
                               self.inputOf(node, "in", "color3", {0, 0, 0}, false, depth + 1).v);
  const Value h = vclamp(swizzle(hsv, "x"), -1.0 / 3.0, 1.0);
  const Value x = add(mul(swizzle(h, "xxx"), 6.0), literal3(6, 4, 2));
  const Value tri = vabs(sub(vabs(sub(x, 6.0)), 3.0));
  const Value rgb = mul(vlerp(literal3(1, 1, 1), saturate(sub(tri, 1.0)), swizzle(hsv, "y")), swizzle(hsv, "z"));
  self.warn(node, "hsvtorgb: written with abs and clamp (exact for hue in [-1/3, 1]; hue is clamped to it)");
  return {rgb, "color3"};
}

// ---- the hair helpers ----

/// chiang_hair_roughness (one of its three outputs), chiang_hair_absorption_from_color
/// and deon_hair_absorption_from_melanin: their value at import when their
/// inputs are constants (a warning naming the material inputs that freezes);
/// else chiang_hair_roughness's polynomials and the melanin's absorption
/// (linear in the redness once the concentration and the pigment colours are
/// constants) as value nodes; else an error: the rest takes the logarithm of
/// what varies, and no value node computes one.
MtlxValues::Typed MtlxValues::Call::hairHelper() const {
  const bool roughness = kind == "chiang_hair_roughness";
  const std::string t = roughness ? "vector2" : "vector3";
  if (roughness && output != "roughness_R" && output != "roughness_TT" && output != "roughness_TRT") {
    self.error(node, fmt::format("chiang_hair_roughness has no output '{}' (the connection names roughness_R, "
                                 "roughness_TT or roughness_TRT)", output));
    return none(t);
  }
  const std::size_t before = self.frozenReads();
  Typed r = none(t);
  if (auto folded = hairFolded()) {
    for (double& x : *folded) x = tidy(x);
    r = {literal(*folded), t};
  } else if (frozen) {
    return r;
  } else if (roughness) {
    r = hairRoughnessNode();
  } else if (kind == "deon_hair_absorption_from_melanin") {
    if (auto m = melaninNode()) r = *m;
  }
  if (r.v.is_null()) {  // an absorption helper whose logarithm varies
    const bool melanin = kind == "deon_hair_absorption_from_melanin";
    self.error(node, fmt::format("{} varies, and the absorption is its logarithm, which no value node computes (give "
                                 "it a constant value{})",
                                 melanin ? "melanin_concentration or a pigment colour" : "color",
                                 melanin ? "" : ", or connect the node straight to chiang_hair_bsdf's absorption_coefficient"));
    return r;
  }
  if (!frozen && self.frozenReads() > before) {
    std::string names;
    for (const auto& n : self.frozenInputsSince(before)) names += (names.empty() ? "" : ", ") + n;
    self.warn(node, fmt::format("{} is evaluated at import with the material inputs it reads at their values ({}): "
                                "changing them at run time does not change this", kind, names));
  }
  return r;
}

/// The hair helper's value from its inputs' constants (nullopt when one varies).
std::optional<std::vector<double>> MtlxValues::Call::hairFolded() const {
  auto vec = [](const auto& a) { return std::vector<double>(a.begin(), a.end()); };
  auto rgb = [](const std::vector<double>& c) { return hair::Vec3{c[0], c[1], c[2]}; };
  if (kind == "chiang_hair_roughness") {
    const auto l = constantIn("longitudinal", "float", {0.1}), a = constantIn("azimuthal", "float", {0.2});
    const auto tt = constantIn("scale_TT", "float", {0.5}), trt = constantIn("scale_TRT", "float", {2.0});
    if (!l || !a || !tt || !trt) return std::nullopt;
    const hair::LobeRoughness r = hair::chiangHairRoughness((*l)[0], (*a)[0], (*tt)[0], (*trt)[0]);
    return vec(output == "roughness_TT" ? r.tt : output == "roughness_TRT" ? r.trt : r.r);
  }
  if (kind == "chiang_hair_absorption_from_color") {
    const auto c = constantIn("color", "color3", {1, 1, 1}), b = constantIn("azimuthal_roughness", "float", {0.2});
    if (!c || !b) return std::nullopt;
    return vec(hair::absorptionFromColor(rgb(*c), (*b)[0]));
  }
  const auto k = constantIn("melanin_concentration", "float", {0.25}), r = constantIn("melanin_redness", "float", {0.5});
  const auto eu = constantIn("eumelanin_color", "color3", {0.657704, 0.498077, 0.254107});
  const auto ph = constantIn("pheomelanin_color", "color3", {0.829444, 0.67032, 0.349938});
  if (!k || !r || !eu || !ph) return std::nullopt;
  return vec(hair::absorptionFromMelanin((*k)[0], (*r)[0], rgb(*eu), rgb(*ph)));
}

/// chiang_hair_roughness on varying inputs: (v, s) of the output, v = (0.726 l
/// + 0.812 l^2 + 3.7 l^20)^2 (times scale_TT^2 or scale_TRT^2), s = 0.265 a +
/// 1.194 a^2 + 5.372 a^22, l and a clamped to [0.001, 1].
MtlxValues::Typed MtlxValues::Call::hairRoughnessNode() const {
  const std::string name = str(node, "name");
  auto clamped = [&](const char* input, double def) {
    return namedValue(self.w_, name + "_" + input,
                      vclamp(in(input, "float", {def}), hair::kMinRoughness, hair::kMaxRoughness));
  };
  const Value l = clamped("longitudinal", 0.1), a = clamped("azimuthal", 0.2);
  const Value d = namedValue(self.w_, name + "_deviation",
                             add(add(mul(l, 0.726), mul(mul(l, l), 0.812)), mul(vpow(l, 20.0), 3.7)));
  Value v = mul(d, d);
  if (output != "roughness_R") {
    const bool tt = output == "roughness_TT";
    const Value scale = in(tt ? "scale_TT" : "scale_TRT", "float", {tt ? 0.5 : 2.0});
    v = mul(v, mul(scale, scale));
  }
  const Value s = add(add(mul(a, 0.265), mul(mul(a, a), 1.194)), mul(vpow(a, 22.0), 5.372));
  return {combine({v, s}), "vector2"};
}

/// deon_hair_absorption_from_melanin with a varying redness r: max(melanin ·
/// lerp(−ln eumelanin_color, −ln pheomelanin_color, r), 0); nullopt when the
/// concentration or a pigment colour varies.
std::optional<MtlxValues::Typed> MtlxValues::Call::melaninNode() const {
  const auto k = constantIn("melanin_concentration", "float", {0.25});
  const auto eu = constantIn("eumelanin_color", "color3", {0.657704, 0.498077, 0.254107});
  const auto ph = constantIn("pheomelanin_color", "color3", {0.829444, 0.67032, 0.349938});
  if (!k || !eu || !ph) return std::nullopt;
  const hair::Vec3 e{(*eu)[0], (*eu)[1], (*eu)[2]}, p{(*ph)[0], (*ph)[1], (*ph)[2]};
  const double melanin = hair::melaninAmount((*k)[0]);
  const hair::Vec3 allEu = hair::pigmentAbsorption(melanin, e), allPheo = hair::pigmentAbsorption(melanin, p);
  const Value r = in("melanin_redness", "float", {0.5});
  return Typed{vmax(vlerp(literal3(allEu[0], allEu[1], allEu[2]), literal3(allPheo[0], allPheo[1], allPheo[2]), r), 0.0),
               "vector3"};
}

// ---- nodes with value nodes ----

MtlxValues::Typed MtlxValues::Call::constant() const {
  return {in(kind == "constant" ? "value" : "in", type, std::vector<double>(std::max(1, mtlxComponents(type)), 0.0)), type};
}

MtlxValues::Typed MtlxValues::Call::convert() const {
  const std::string from = declared("in", type);
  return {convertValue(in("in", from, {0}), from, type), type};
}

MtlxValues::Typed MtlxValues::Call::binary() const {
  // kind -> (value node op, identity of in2)
  static const std::map<std::string, std::pair<Value (*)(const Value&, const Value&), double>> kBinary = {
      {"add", {add, 0}}, {"subtract", {sub, 0}}, {"multiply", {mul, 1}}, {"divide", {divide, 1}},
      {"min", {vmin, 0}}, {"max", {vmax, 0}}, {"power", {vpow, 1}}};
  const auto& [op, identity] = kBinary.at(kind);
  const Value a = in("in1", type, {0}), c = in("in2", type, {identity});
  if (varies({a, c})) return none(type);
  return {op(a, c), type};
}

MtlxValues::Typed MtlxValues::Call::mix() const {
  const Value fg = in("fg", type, {0}), bg = in("bg", type, {0}), m = in("mix", "float", {0});
  if (varies({fg, bg, m})) return none(type);
  return {vlerp(bg, fg, m), type};
}

MtlxValues::Typed MtlxValues::Call::clamp() const {
  const Value x = in("in", type, {0}), lo = in("low", type, {0}), hi = in("high", type, {1});
  if (varies({x, lo, hi})) return none(type);
  return {vclamp(x, lo, hi), type};
}

MtlxValues::Typed MtlxValues::Call::invert() const {
  const Value x = in("in", type, {0}), amount = in("amount", type, {1});
  if (varies({x, amount})) return none(type);
  return {sub(amount, x), type};
}

MtlxValues::Typed MtlxValues::Call::unaryMath() const {
  const Value x = in("in", declared("in", type), {0});
  if (varies({x})) return none(type);
  if (kind == "absval") return {vabs(x), type};
  if (kind == "sqrt") return {vsqrt(x), type};
  if (kind == "normalize") return {vnormalize(x), type};
  return {vlength(x), "float"};
}

MtlxValues::Typed MtlxValues::Call::dotproduct() const {
  const std::string it = declared("in1", "vector3");
  const Value a = in("in1", it, {0}), b = in("in2", it, {0});
  if (varies({a, b})) return none("float");
  return {vdot(a, b), "float"};
}

MtlxValues::Typed MtlxValues::Call::remap() const {
  const Value x = in("in", type, {0}), il = in("inlow", type, {0}), ih = in("inhigh", type, {1}),
              ol = in("outlow", type, {0}), oh = in("outhigh", type, {1});
  if (varies({x, il, ih, ol, oh})) return none(type);
  return {add(ol, mul(divide(sub(x, il), sub(ih, il)), sub(oh, ol))), type};
}

MtlxValues::Typed MtlxValues::Call::luminance() const {
  const Value x = in("in", type, {0}), k = in("lumacoeffs", "color3", {0.2126, 0.7152, 0.0722});
  if (varies({x, k})) return none(type);
  const Value y = vdot(mtlxComponents(type) == 4 ? swizzle(x, "xyz") : x, k);
  return {mtlxComponents(type) == 4 ? combine({y, y, y, swizzle(x, "w")}) : swizzle(y, "xxx"), type};
}

MtlxValues::Typed MtlxValues::Call::combineN() const {
  const int n = kind.back() - '0';
  std::vector<Value> parts;
  for (int i = 0; i < n; ++i) {
    const std::string name = "in" + std::to_string(i + 1);
    const std::string it = declared(name.c_str(), "float");
    const Value v = in(name.c_str(), it, {0});
    if (mtlxComponents(it) == 1) {
      parts.push_back(v);
    } else {
      for (int k = 0; k < mtlxComponents(it); ++k) parts.push_back(swizzle(v, std::string(1, "xyzw"[k])));
    }
  }
  for (const auto& v : parts)
    if (varies({v})) return none(type);
  if (static_cast<int>(parts.size()) != mtlxComponents(type)) {
    self.error(node, fmt::format("{} builds {} components for a {}", kind, parts.size(), type));
    return none(type);
  }
  return {combine(parts), type};
}

MtlxValues::Typed MtlxValues::Call::extract() const {
  const std::string it = declared("in", "vector3");
  const Value x = in("in", it, {0});
  if (varies({x})) return none("float");
  int index = 0;
  if (kind == "extract") {
    const auto k = literalOf(in("index", "integer", {0}));
    index = k ? static_cast<int>((*k)[0]) : -1;
  } else {
    static const std::string names = "xyzwrgba";
    const std::size_t at = output.size() == 4 ? names.find(output[3]) : std::string::npos;
    index = at == std::string::npos ? -1 : static_cast<int>(at % 4);
  }
  if (index < 0 || index >= mtlxComponents(it)) {
    self.error(node, fmt::format("{}: no channel {} of a {}", kind, kind == "extract" ? std::to_string(index) : output, it));
    return none("float");
  }
  return {swizzle(x, std::string(1, "xyzw"[index])), "float"};
}

MtlxValues::Typed MtlxValues::Call::swizzleNode() const {  // MaterialX 1.38
  const Value x = in("in", declared("in", "color3"), {0});
  pugi::xml_node ch = node.find_child_by_attribute("input", "name", "channels");
  std::string channels = ch ? str(ch, "value") : "";
  if (channels.empty() || channels.find_first_not_of("xyzwrgba") != std::string::npos) {
    self.error(node, fmt::format("swizzle channels '{}' (constant channels are not supported)", channels));
    return none(type);
  }
  if (varies({x})) return none(type);
  return {swizzle(x, channels), type};
}

MtlxValues::Typed MtlxValues::Call::normalmap() const {
  const Value x = in("in", "vector3", {0.5, 0.5, 1});
  const Value s = in("scale", "float", {1});
  if (varies({x, s})) return none("vector3");
  if (auto space = node.find_child_by_attribute("input", "name", "space"); space && str(space, "value") == "object")
    self.warn(node, "an object-space normal map is read as a tangent-space one");
  return {unpackNormal(x, s), "vector3"};
}

MtlxValues::Typed MtlxValues::Call::texcoord() const {
  if (frozen) return none(type);
  const auto k = literalOf(in("index", "integer", {0}));
  int index = k ? static_cast<int>((*k)[0]) : 0;
  if (index > 1) {
    self.warn(node, fmt::format("texcoord index {}: a material reads uv0 and uv1 only; uv1 is used", index));
    index = 1;
  }
  return {convertValue(geometry(index == 0 ? "uv0" : "uv1"), "vector2", type), type};
}

MtlxValues::Typed MtlxValues::Call::place2d() const {
  const Value uv = in("texcoord", "vector2", {});
  const Value pivot = in("pivot", "vector2", {0, 0}), scale = in("scale", "vector2", {1, 1}),
              offset = in("offset", "vector2", {0, 0});
  const auto rotate = literalOf(in("rotate", "float", {0}));
  if (frozen) return none(type);
  if (!rotate) {
    self.error(node, "place2d: a varying rotation is not supported (the rotation must be a constant)");
    return none(type);
  }
  if (auto order = literalOf(in("operationorder", "integer", {0})); order && (*order)[0] != 0)
    self.warn(node, "place2d operationorder TRS is applied as SRT");
  // uv' = R(rotate) · ((uv − pivot) / scale) + pivot − offset, R counter-clockwise in degrees.
  Value p = divide(sub(uv.is_null() ? geometry("uv0") : uv, pivot), scale);
  if ((*rotate)[0] != 0) p = rotated2(namedValue(self.w_, std::string(str(node, "name")) + "_scaled", p), (*rotate)[0]);
  return {sub(add(p, pivot), offset), type};
}

MtlxValues::Typed MtlxValues::Call::geometric() const {
  if (frozen) return none(type);
  const std::string space = str(node.find_child_by_attribute("input", "name", "space"), "value");
  if (kind == "position") {
    if (space != "world") self.warn(node, fmt::format("position in {} space: the world-space position is used", space.empty() ? "object" : space));
    return {geometry("position"), type};
  }
  if (kind == "geomcolor") return {convertValue(geometry("vertex_color"), "vector4", type), type};
  if (kind == "bitangent") return {Json::array({0.0, 1.0, 0.0}), type};
  self.warn(node, fmt::format("the geometric {} is read in tangent space", kind));
  return {geometry(kind), type};
}

MtlxValues::Typed MtlxValues::Call::unsupported() const {
  static const char* const kShading[] = {"surface", "surfacematerial", "standard_surface", "open_pbr_surface",
                                         "gltf_pbr", "UsdPreviewSurface", "disney_principled"};
  if (std::find(std::begin(kShading), std::end(kShading), kind) != std::end(kShading) || type == "BSDF" ||
      type == "EDF" || type == "VDF" || type == "surfaceshader") {
    self.error(node, fmt::format("unsupported node '{}': a shader where a value is expected", kind));
    return none(type);
  }
  self.error(node, fmt::format("unsupported node '{}' (no Substrate value node or import rule for it)", kind));
  return none(type);
}

}  // namespace substratec::import
