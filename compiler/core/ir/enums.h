// The names of the compiler's enumerations, one table per enum (X-macros, as
// tools/gpu/vulkan_loader.h lists its entry points): each list gives the
// enumerators in order with their spelling in materials, reports and on the
// command line. The enums, their name functions, the parsers and the
// "expected one of ..." lists of the diagnostics all derive from these lists,
// so a value is added or renamed in one place.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "substrate_constants.h"  // runtime_shaders/: SUBSTRATE_DIFFUSE_MODEL_DEFAULT

/// settings.blend_mode
#define SUBSTRATEC_BLEND_MODES(X)                                                                  \
  X(Opaque, "opaque") X(Masked, "masked") X(TranslucentGrey, "translucent_grey")                    \
  X(TranslucentColored, "translucent_colored") X(ColoredTransmittanceOnly, "colored_transmittance_only") \
  X(AlphaHoldout, "alpha_holdout")
/// a slab's sss_type (the values are SUBSTRATE_SSS_*)
#define SUBSTRATEC_SSS_TYPES(X) \
  X(None, "none") X(Wrap, "wrap") X(Diffusion, "diffusion") X(SimpleVolume, "simple_volume")
/// a geometry node's attribute
#define SUBSTRATEC_GEOMETRY_ATTRS(X)                                                   \
  X(Normal, "normal") X(Tangent, "tangent") X(Uv0, "uv0") X(Uv1, "uv1")                \
  X(VertexColor, "vertex_color") X(Position, "position") X(View, "view")
/// the Substrate tree's operators (reports and dumps)
#define SUBSTRATEC_TREE_OPS(X)                                                                     \
  X(Slab, "SLAB") X(Horizontal, "HORIZONTAL") X(Vertical, "VERTICAL") X(Add, "ADD")                \
  X(CoverageWeight, "WEIGHT") X(Select, "SELECT")
/// --diffuse (the values are the SUBSTRATE_DIFFUSE_MODEL numbers: 0 Lambert,
/// 1 Chan 2018, 2 Chan 2024, 3 EON, Portsmouth 2025)
#define SUBSTRATEC_DIFFUSE_MODELS(X) X(Lambert, "lambert") X(Chan2018, "chan2018") X(Chan2024, "chan2024") X(Eon, "eon")

#define SUBSTRATEC_ENUMERATOR(e, name) e,

namespace substratec {

enum class BlendMode : std::uint8_t { SUBSTRATEC_BLEND_MODES(SUBSTRATEC_ENUMERATOR) };
enum class SssType : std::uint8_t { SUBSTRATEC_SSS_TYPES(SUBSTRATEC_ENUMERATOR) };
enum class GeometryAttr : std::uint16_t { SUBSTRATEC_GEOMETRY_ATTRS(SUBSTRATEC_ENUMERATOR) };
enum class TreeOp : std::uint8_t { SUBSTRATEC_TREE_OPS(SUBSTRATEC_ENUMERATOR) };
enum class DiffuseModel : std::uint8_t { SUBSTRATEC_DIFFUSE_MODELS(SUBSTRATEC_ENUMERATOR) };

/// The diffuse model a shader uses when none is chosen (the runtime's default).
inline constexpr DiffuseModel kDefaultDiffuseModel = static_cast<DiffuseModel>(SUBSTRATE_DIFFUSE_MODEL_DEFAULT);
/// The SUBSTRATE_DIFFUSE_MODEL number of a model (what the reference takes too).
constexpr int diffuseModelNumber(DiffuseModel m) { return static_cast<int>(m); }

/// One enumerator and its name.
template <class E>
struct EnumName {
  E value;
  std::string_view name;
};

inline constexpr EnumName<BlendMode> kBlendModeNames[] = {
#define SUBSTRATEC_X(e, n) {BlendMode::e, n},
    SUBSTRATEC_BLEND_MODES(SUBSTRATEC_X)
#undef SUBSTRATEC_X
};
inline constexpr EnumName<SssType> kSssTypeNames[] = {
#define SUBSTRATEC_X(e, n) {SssType::e, n},
    SUBSTRATEC_SSS_TYPES(SUBSTRATEC_X)
#undef SUBSTRATEC_X
};
inline constexpr EnumName<GeometryAttr> kGeometryAttrNames[] = {
#define SUBSTRATEC_X(e, n) {GeometryAttr::e, n},
    SUBSTRATEC_GEOMETRY_ATTRS(SUBSTRATEC_X)
#undef SUBSTRATEC_X
};
inline constexpr EnumName<TreeOp> kTreeOpNames[] = {
#define SUBSTRATEC_X(e, n) {TreeOp::e, n},
    SUBSTRATEC_TREE_OPS(SUBSTRATEC_X)
#undef SUBSTRATEC_X
};
inline constexpr EnumName<DiffuseModel> kDiffuseModelNames[] = {
#define SUBSTRATEC_X(e, n) {DiffuseModel::e, n},
    SUBSTRATEC_DIFFUSE_MODELS(SUBSTRATEC_X)
#undef SUBSTRATEC_X
};

/// The name of `e` in `table`, or `fallback` for a value outside it.
template <class E, std::size_t N>
constexpr std::string_view enumName(const EnumName<E> (&table)[N], E e, std::string_view fallback) {
  for (const EnumName<E>& x : table)
    if (x.value == e) return x.name;
  return fallback;
}

/// The enumerator named `name` in `table`, if any.
template <class E, std::size_t N>
constexpr std::optional<E> enumByName(const EnumName<E> (&table)[N], std::string_view name) {
  for (const EnumName<E>& x : table)
    if (x.name == name) return x.value;
  return std::nullopt;
}

/// The names of `table` in order (a CLI's choices).
template <class E, std::size_t N>
std::vector<std::string> enumNames(const EnumName<E> (&table)[N]) {
  std::vector<std::string> names;
  for (const EnumName<E>& x : table) names.emplace_back(x.name);
  return names;
}

/// The names of `table` in order, comma separated ("a, b, c"): the list of an
/// "expected one of ..." diagnostic.
template <class E, std::size_t N>
std::string enumNameList(const EnumName<E> (&table)[N]) {
  std::string s;
  for (const EnumName<E>& x : table) s += (s.empty() ? "" : ", ") + std::string(x.name);
  return s;
}

/// The --diffuse names and their parser (an unknown name is std::nullopt).
inline std::vector<std::string> diffuseModelNames() { return enumNames(kDiffuseModelNames); }
inline std::optional<DiffuseModel> parseDiffuseModel(std::string_view name) {
  return enumByName(kDiffuseModelNames, name);
}
constexpr std::string_view diffuseModelName(DiffuseModel m) { return enumName(kDiffuseModelNames, m, "?"); }

}  // namespace substratec
