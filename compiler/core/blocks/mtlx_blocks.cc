// MaterialX's Standard Surface, OpenPBR and Disney principled as building
// blocks (standard_surface, open_pbr_surface, disney_principled): the pins
// are the parameters the model's unit reads, under their MaterialX names,
// and the expansion is that unit run on the pins (BlockParams).
#include <algorithm>
#include <map>

#include "blocks/blocks.h"
#include "blocks/mtlx_surfaces.h"

namespace substratec::blocks {

namespace {

/// Gives every parameter as a varying value ("$<name>", true for given) and
/// records what the unit asks for, in the order it asks.
class Probe final : public SurfaceParams {
 public:
  Value param(const std::string& name, const std::string& type, const std::vector<double>& def,
              ParamKind kind) override {
    record(name, type, def, kind).constantOnly = false;
    return Value("$" + name);
  }
  std::optional<std::vector<double>> constant(const std::string& name, const std::string& type,
                                              const std::vector<double>& def) override {
    record(name, type, def, ParamKind::Plain);
    return std::nullopt;
  }
  /// Every parameter is given; one the unit only asks about (a connected
  /// tangent it warns of) is a pin too, a direction read as a constant.
  bool given(const std::string& name) const override {
    asked.push_back(name);
    return true;
  }
  void warn(const std::string&) override {}
  /// The parameters, those only asked about last.
  std::vector<ModelParam> all() {
    for (const std::string& name : asked)
      if (std::none_of(params.begin(), params.end(), [&](const ModelParam& p) { return p.name == name; }))
        params.push_back({name, "vector3", {0, 0, 1}, ParamKind::Plain, true});
    return std::move(params);
  }
  std::vector<ModelParam> params;
  mutable std::vector<std::string> asked;

 private:
  ModelParam& record(const std::string& name, const std::string& type, const std::vector<double>& def, ParamKind kind) {
    for (ModelParam& p : params)
      if (p.name == name) {
        if (kind == ParamKind::Switch) p.kind = kind;
        return p;
      }
    params.push_back({name, type, def, kind, true});
    return params.back();
  }
};

/// The components of a literal JSON value for a parameter of `type`: a
/// single number broadcasts, true and false are 1 and 0.
std::optional<std::vector<double>> componentsOf(const Json& v, const std::string& type) {
  if (v.is_boolean()) return std::vector<double>{v.get<bool>() ? 1.0 : 0.0};
  auto lit = literalOf(v);
  const std::size_t n = type == "color3" || type == "vector3" ? 3 : type == "vector2" ? 2 : 1;
  if (lit && lit->size() == 1 && n > 1) return std::vector<double>(n, (*lit)[0]);
  return lit && lit->size() == n ? lit : std::nullopt;
}

BlockPin::Kind pinKindOf(const std::string& type) {
  if (type == "color3") return BlockPin::Kind::Color;
  if (type == "vector3") return BlockPin::Kind::Vec3;
  if (type == "vector2") return BlockPin::Kind::Vec2;
  if (type == "boolean") return BlockPin::Kind::Flag;
  return BlockPin::Kind::Float;
}

BuildingBlock modelBlock(const char* kind, Value (*expand)(const Json&, BlockContext&)) {
  BlockSignature sig{kind, {}};
  for (const ModelParam& p : blockModelParams(kind)) sig.pins.push_back({p.name.c_str(), pinKindOf(p.type)});
  return {sig, expand};
}

template <SurfaceUnit unit>
Value expandModel(const Json& block, BlockContext& c) {
  BlockParams params(block, c.document, c.warnings);
  return layeredSurfaceNodes(unit(params, c.w), c.w);
}

}  // namespace

SurfaceUnit blockModelUnit(const std::string& kind) {
  if (kind == "standard_surface") return standardSurface;
  if (kind == "open_pbr_surface") return openPbrSurface;
  if (kind == "disney_principled") return disneyPrincipled;
  return nullptr;
}

const std::vector<ModelParam>& blockModelParams(const std::string& kind) {
  static const std::map<std::string, std::vector<ModelParam>> all = [] {
    std::map<std::string, std::vector<ModelParam>> m;
    for (const char* k : {"standard_surface", "open_pbr_surface", "disney_principled"}) {
      Probe probe;
      DiscardingNodeWriter scratch;
      blockModelUnit(k)(probe, scratch);
      m[k] = probe.all();
    }
    return m;
  }();
  static const std::vector<ModelParam> none;
  auto it = all.find(kind);
  return it == all.end() ? none : it->second;
}

Json blockModelBlock(const std::string& kind, SurfaceParams& params) {
  Json block = {{"kind", kind}};
  for (const ModelParam& p : blockModelParams(kind)) {
    if (!params.given(p.name)) continue;
    if (!p.constantOnly) {
      block[p.name] = params.param(p.name, p.type, p.def, p.kind);
    } else {
      const std::vector<double> c = params.constant(p.name, p.type, p.def).value_or(p.def);
      block[p.name] = p.type == "boolean" ? Json(c[0] != 0) : literal(c);
    }
  }
  return block;
}

Value BlockParams::param(const std::string& name, const std::string&, const std::vector<double>& def, ParamKind) {
  auto it = block_.find(name);
  return it == block_.end() ? literal(def) : *it;
}

std::optional<std::vector<double>> BlockParams::constant(const std::string& name, const std::string& type,
                                                         const std::vector<double>& def) {
  auto it = block_.find(name);
  if (it == block_.end()) return def;
  if (it->is_string() && !it->get_ref<const std::string&>().empty() && it->get_ref<const std::string&>()[0] == '$') {
    // An input: read at its value, as MaterialX's import reads a shader's input.
    const auto inputs = document_.find("inputs");
    if (inputs == document_.end() || !inputs->is_object()) return std::nullopt;
    const auto input = inputs->find(it->get_ref<const std::string&>().substr(1));
    if (input == inputs->end() || !input->is_object() || !input->contains("default")) return std::nullopt;
    return componentsOf((*input)["default"], type);
  }
  return componentsOf(*it, type);
}

BuildingBlock standardSurfaceBlock() { return modelBlock("standard_surface", expandModel<standardSurface>); }
BuildingBlock openPbrSurfaceBlock() { return modelBlock("open_pbr_surface", expandModel<openPbrSurface>); }
BuildingBlock disneyPrincipledBlock() { return modelBlock("disney_principled", expandModel<disneyPrincipled>); }

}  // namespace substratec::blocks
