#include "emit/material_emitter.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <map>
#include <optional>
#include <set>

#include <fmt/format.h>

#include "ir/dump.h"
#include "substrate_constants.h"  // runtime_shaders/: SUBSTRATE_FEATURE_* bits

namespace substratec {

std::string materialUpper(const Material& m) {
  std::string s = m.name;
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

const char* precisionName(Precision p) { return p == Precision::Half ? "half" : "float"; }

std::string precisionDefine(Precision p) {
  return p == Precision::Half ? "#define SUBSTRATE_PRECISION_HALF 1  // colours, weights, throughputs in float16\n" : "";
}

std::string useDefines(std::uint16_t features) {
  std::string s;
  auto use = [&](const char* macro, std::uint16_t bit) {
    s += fmt::format("#define {} {}\n", macro, (features & bit) ? 1 : 0);
  };
  use("SUBSTRATE_USE_F90", kFeatF90);
  use("SUBSTRATE_USE_ANISOTROPY", kFeatAnisotropy);
  use("SUBSTRATE_USE_HAZE", kFeatHaze);
  use("SUBSTRATE_USE_FUZZ", kFeatFuzz);
  use("SUBSTRATE_USE_SSS", kFeatSss);
  use("SUBSTRATE_USE_GLINT", kFeatGlint);
  use("SUBSTRATE_USE_SPECULAR_PROFILE", kFeatSpecularProfile);
  use("SUBSTRATE_USE_EMISSIVE", kFeatEmissive);
  use("SUBSTRATE_USE_HAIR", kFeatHair);
  use("SUBSTRATE_USE_EYE", kFeatEye);
  use("SUBSTRATE_USE_WATER", kFeatWater);
  return s;
}

/// Whether some closure of `layout` lies under a layer (not ClosureLayout::isTop).
bool hasLayers(const StorageLayout& layout) {
  return std::any_of(layout.closures.begin(), layout.closures.end(), [](const ClosureLayout& c) { return !c.isTop; });
}

std::string extraInterfacesDefine(const StorageLayout& layout) {
  const bool any = std::any_of(layout.closures.begin(), layout.closures.end(),
                               [](const ClosureLayout& c) { return c.extraInterfaces > 0; });
  return fmt::format("#define SUBSTRATE_USE_EXTRA_INTERFACES {}\n#define SUBSTRATE_USE_LAYERS {}\n", any ? 1 : 0,
                     hasLayers(layout) ? 1 : 0);
}

/// The channels of value `v` when it is a constant (one for a float, three for a
/// colour); nothing when it is absent or not a constant.
std::optional<std::vector<double>> constantChannels(const Material& m, ValueId v) {
  if (v == kNoValue || !m.values.isConst(v)) return std::nullopt;
  const auto& k = m.values.node(v).c;
  const int channels = m.values.node(v).type == VType::Float ? 1 : 3;
  return std::vector<double>(k.begin(), k.begin() + channels);
}

/// Whether value `v` may exceed `limit` in some channel: it is not a
/// constant whose every channel is at most `limit` (NaN counts as above).
bool mayExceed(const Material& m, ValueId v, double limit) {
  const auto k = constantChannels(m, v);
  return !k || std::any_of(k->begin(), k->end(), [&](double x) { return !(x <= limit); });
}

/// Whether slab `slab` may read as a conductor in the runtime: its F0 is not
/// a constant whose largest channel is at most SUBSTRATE_COAT_DIELECTRIC_F0
/// (where substrate_fresnel_share is exactly 1).
bool mayReadAsConductor(const Material& m, int slab) {
  return mayExceed(m, m.slabs[slab].pin(SlabPin::F0), SUBSTRATE_COAT_DIELECTRIC_F0);
}

/// Whether slab `slab` may be what the ground truth walks as a conductor,
/// whose Fresnel curve the runtime follows (substrate_closure_fresnel_ends):
/// it may read as one, has no medium (a transmitting slab is a dielectric
/// there) and its diffuse albedo is not a constant above 0, unless it is a
/// metalness mix.
bool mayWalkAsConductor(const Material& m, int slab) {
  const Slab& s = m.slabs[slab];
  if (!mayReadAsConductor(m, slab) || (s.features & (kFeatMedium | kFeatSss))) return false;
  if (s.metalness) return true;
  const ValueId albedo = s.pin(SlabPin::DiffuseAlbedo);
  // An albedo that is not constant, or a constant 0 in every channel.
  return albedo == kNoValue || !m.values.isConst(albedo) || !mayExceed(m, albedo, 0.0);
}

/// Whether the largest channel of value `v` may fall below `limit`: it is not
/// a constant with a channel of at least `limit` (NaN counts as below).
bool largestMayFallBelow(const Material& m, ValueId v, double limit) {
  const auto k = constantChannels(m, v);
  return !k || std::any_of(k->begin(), k->end(), [](double x) { return std::isnan(x); }) ||
         std::none_of(k->begin(), k->end(), [&](double x) { return x >= limit; });
}

bool usesConductorCurve(const Material& m, const StorageLayout& layout) {
  for (const ClosureLayout& c : layout.closures)
    if (c.slab < 0 || mayWalkAsConductor(m, c.slab)) return true;
  return false;
}

bool usesLowIorCurve(const Material& m, const StorageLayout& layout) {
  // Chi from F0 SUBSTRATE_DIELECTRIC_CURVE_X^2 = 0.04 on (a relative 1e-6 below it, so that a
  // constant 0.04 folds to chi whatever the rounding).
  constexpr double kChiF0 = SUBSTRATE_DIELECTRIC_CURVE_X * SUBSTRATE_DIELECTRIC_CURVE_X * (1 - 1e-6);
  if (hasLayers(layout)) return false;
  for (const ClosureLayout& c : layout.closures)
    if (c.slab < 0 || largestMayFallBelow(m, m.slabs[c.slab].pin(SlabPin::F0), kChiF0)) return true;
  return false;
}

/// SUBSTRATE_USE_COAT_CONDUCTOR: 1 when some closure under a layer may read
/// as a conductor (mayReadAsConductor): substrate_closure_coat_specular
/// returns exactly 1 for the others, so a material whose closures under
/// layers are all dielectrics compiles none of it.
/// SUBSTRATE_USE_CONDUCTOR_CURVE: usesConductorCurve; the others' Fresnel
/// curve is chi or Schlick's, the same in every channel, one scalar per
/// light (substrate_fresnel).
/// SUBSTRATE_USE_LOW_IOR_CURVE: usesLowIorCurve; the others' dielectric
/// curve is chi, whose coefficients are constants.
std::string conductorDefines(const Material& m, const StorageLayout& layout) {
  bool underLayers = false;
  for (const ClosureLayout& c : layout.closures)
    underLayers = underLayers || (c.slab >= 0 && !c.isTop && mayReadAsConductor(m, c.slab));
  return fmt::format(
      "#define SUBSTRATE_USE_COAT_CONDUCTOR {}\n#define SUBSTRATE_USE_CONDUCTOR_CURVE {}\n"
      "#define SUBSTRATE_USE_LOW_IOR_CURVE {}\n",
      underLayers ? 1 : 0, usesConductorCurve(m, layout) ? 1 : 0, usesLowIorCurve(m, layout) ? 1 : 0);
}

/// SUBSTRATE_USE_WRAP_UNDER_LAYERS and SUBSTRATE_USE_FUZZ_UNDER_LAYERS: 1 when
/// some closure under a layer has a wrap lobe (its light crosses the layers at
/// its own cosine, substrate_wrap_light_cosine) or a fuzz (seen at the
/// refracted angles, substrate_fuzz_under_layers). A closure on top meets
/// layers of throughput 1 at every cosine and keeps its fuzz's angles, so a
/// material with neither under a layer compiles none of it.
std::string underLayersDefines(const Material& m, const StorageLayout& layout) {
  bool wrap = false, fuzz = false;
  for (const ClosureLayout& c : layout.closures) {
    if (c.isTop || c.slab < 0) continue;
    const Slab& slab = m.slabs[c.slab];
    wrap = wrap || slab.sssType == SssType::Wrap;
    fuzz = fuzz || (slab.features & kFeatFuzz) != 0;
  }
  return fmt::format("#define SUBSTRATE_USE_WRAP_UNDER_LAYERS {}\n#define SUBSTRATE_USE_FUZZ_UNDER_LAYERS {}\n",
                     wrap ? 1 : 0, fuzz ? 1 : 0);
}

/// The index of the one closure on top, or -1 when there are several (a mix
/// of tops: no one interface above the others).
int oneTopClosure(const StorageLayout& layout) {
  const auto isTop = [](const ClosureLayout& c) { return c.isTop; };
  if (std::count_if(layout.closures.begin(), layout.closures.end(), isTop) != 1) return -1;
  return static_cast<int>(std::find_if(layout.closures.begin(), layout.closures.end(), isTop) - layout.closures.begin());
}

/// The one closure on top when it is one stretched GGX lobe (anisotropy, no
/// haze), whose floor follows a direction's azimuth (SubstrateClosure.coatStretch); else -1.
int stretchedTopClosure(const Material& m, const StorageLayout& layout) {
  const int top = oneTopClosure(layout);
  if (top < 0) return -1;
  const std::uint16_t f = m.slabs[layout.closures[static_cast<std::size_t>(top)].slab].features;
  return (f & (kFeatAnisotropy | kFeatHaze)) == kFeatAnisotropy ? top : -1;
}

/// The closures that read the layers' rough top (SubstrateClosure.coatFloor,
/// or coatStretch under a stretched top): when one closure, one GGX lobe
/// (isotropic or stretched, not hazy), is on top, those under that one
/// interface (extraInterfaces 0); else none. None either when every closure is
/// on top, or when an isotropic top's roughness is a constant up to
/// SUBSTRATE_COAT_ROUGH_START, whose floor is 0 (a clear coat of roughness 0.05).
std::vector<std::size_t> coatFloorClosures(const Material& m, const StorageLayout& layout) {
  const int top = oneTopClosure(layout);
  if (top < 0) return {};  // no one roughness
  const Slab& slab = m.slabs[layout.closures[static_cast<std::size_t>(top)].slab];
  if (slab.features & kFeatHaze) return {};  // two lobes
  const ValueId r = slab.pin(SlabPin::Roughness);
  if (!(slab.features & kFeatAnisotropy) && r != kNoValue && m.values.isConst(r) &&
      m.values.node(r).c[0] <= SUBSTRATE_COAT_ROUGH_START)
    return {};
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < layout.closures.size(); ++i)
    if (!layout.closures[i].isTop && layout.closures[i].extraInterfaces == 0) out.push_back(i);
  return out;
}

/// SUBSTRATE_USE_COAT_FLOOR: 1 when some closure reads the rough top's floor
/// (coatFloorClosures); the others' floor is 0, for which the layers'
/// interface term is the smooth one exactly, so a material with none compiles
/// none of it.
/// Under a stretched top (stretchedTopClosure) SUBSTRATE_USE_COAT_ANISO is 1
/// instead: the floor follows a direction's azimuth, and the isotropic floor's
/// own terms (coatFloor stays 0) compile out.
std::string coatFloorDefine(const Material& m, const StorageLayout& layout) {
  const bool any = !coatFloorClosures(m, layout).empty();
  const bool stretched = any && stretchedTopClosure(m, layout) >= 0;
  return fmt::format("#define SUBSTRATE_USE_COAT_FLOOR {}\n#define SUBSTRATE_USE_COAT_ANISO {}\n",
                     any && !stretched ? 1 : 0, stretched ? 1 : 0);
}

std::vector<int> specularProfileInputs(const Material& m, const StorageLayout& layout) {
  std::vector<int> inputs;
  for (const ClosureLayout& c : layout.closures) {
    const int input = m.slabs[c.slab].specularProfileInput;
    if (input >= 0 && std::find(inputs.begin(), inputs.end(), input) == inputs.end()) inputs.push_back(input);
  }
  return inputs;
}

bool translucentBlend(const Material& m) {
  return m.settings.blendMode == BlendMode::TranslucentGrey || m.settings.blendMode == BlendMode::TranslucentColored ||
         m.settings.blendMode == BlendMode::ColoredTransmittanceOnly;
}

bool anyEmissive(const Material& m, const StorageLayout& L) {
  for (const auto& c : L.closures)
    if (m.slabs[c.slab].features & kFeatEmissive) return true;
  return false;
}

bool basePassEmissive(const Material& m, const StorageLayout& L) { return anyEmissive(m, L) || unlitEmission(m); }

std::string backgroundThroughput(const Material& m) {
  if (m.settings.blendMode == BlendMode::TranslucentGrey)
    return "SUBSTRATE_SPLAT3(1.0 - coverage + coverage * dot(transmittance, SUBSTRATE_SPLAT3(1.0 / 3.0)))";
  return "SUBSTRATE_SPLAT3(1.0 - coverage) + coverage * transmittance";
}

std::string lightClosureCode(const std::string& c, const std::string& view, const std::string& indent) {
  return fmt::format(
      "{0}color += substrate_light_closure({1}, {2}, L, frame.lightRadiance.rgb);\n"
      "{0}color += substrate_closure_view_throughput({1}, dot({1}.N, {2}), {2}) *\n"
      "{0}         substrate_env_split_sum({1}, {2},\n"
      "{0}                                 SUBSTRATE_ENV_PREFILTERED(substrate_reflection_dir({1}, {2}),\n"
      "{0}                                                           substrate_env_mip(substrate_env_roughness({1}), "
      "frame.envParams.x)),\n"
      "{0}                                 SUBSTRATE_ENV_IRRADIANCE({1}.N));\n",
      indent, c, view);
}

bool unlitEmission(const Material& m) {
  if (m.root < 0) return false;
  for (int n : analyzeTree(m).preorder) {
    const TreeNode& node = m.nodes[n];
    if (isUnlitLeaf(m, node) && (m.slabs[node.slab].features & kFeatEmissive)) return true;
  }
  return false;
}

std::string closureArraySize(const Material& m) {
  return m.root >= 0 && analyzeTree(m).slabOrder.empty() ? "1" : materialUpper(m) + "_CLOSURE_COUNT";
}

std::string evaluateCall(const Material& m) {
  const bool emission = unlitEmission(m);
  return fmt::format(
      "  SubstrateClosure closures[{}];\n  float coverage;\n  float3 transmittance;\n{}"
      "  {}_evaluate(g, closures, coverage, transmittance{});\n",
      closureArraySize(m), std::string(emission ? "  float3 emission;\n" : "") +
                               (isWaterMaterial(m) ? "  SubstrateWater water;\n" : ""),
      m.name, std::string(emission ? ", emission" : "") + (isWaterMaterial(m) ? ", water" : ""));
}

namespace {

class Emitter {
 public:
  Emitter(const Material& m, const TreeInfo& t, const StorageLayout& L, const Syntax& s, const EmitOptions& o)
      : m_(m), t_(t), L_(L), syn_(s), opt_(o) {}

  std::string run();
  /// A volume's material file: `<name>_sample(g)`, the fog cloud's pins at one
  /// sample point (isVolumeMaterial; docs/codegen.md, "Volumes").
  std::string runVolume();

 private:
  // --- values
  std::string expr(ValueId v);                 // an expression for v (inline or a variable)
  std::string varName(ValueId v) const;
  std::string opExpr(const ValueNode& n);
  void need(ValueId v);                        // marks v and its arguments as used
  void emitValues();
  bool nonZero(ValueId v) const;  // a constant without a 0, or max(c, x) with a positive constant c
  std::string vec3(double x, double y, double z) const {
    return fmt::format("float3({}, {}, {})", dialectLiteral(x), dialectLiteral(y), dialectLiteral(z));
  }

  // --- tree
  void collectNeeded();
  void collectTextures();  // the texture inputs the needed values sample (after need())
  void emitResources();
  void emitTree();
  std::string operatorCall(const TreeNode& node, const std::string& prefix, const std::string& c,
                           const std::string& t);  // substrate_op_* of a binary operator (emitTree)
  void emitClosures();
  void emitCoatFloor();
  void emitCoversLayers();
  void emitCoatInterface();
  std::string pathWeight(int node, const std::string& id, std::vector<std::pair<int, int>>& layers);
  std::string walkUp(const ClosureLayout& cl, int node, const std::string& id);
  void emitEmission();
  void emitNoClosureSlot();
  int firstUnlit() const;  // the first unlit leaf in pre-order, or -1
  void emitHairClosure(const std::string& c, const Slab& s);  // closure c of hair s
  void emitEyeClosure(const std::string& c, const Slab& s);   // closure c of eye s
  void emitWaterBody();                                         // `water`: a water material's body
  unsigned emitFeaturePins(const std::string& c, const Slab& s);  // returns the feature bits
  std::string nodeName(int n) const { return m_.nodes[n].id; }
  int verticalOfTop(int node) const;  // the vertical whose top layer holds `node` (TreeInfo::layerVertical), or -1
  bool knownOpaque(int node) const;   // a slab with the constant MFP 0 and a positive constant thickness: T = 0
  bool underOperatorTop(int node) const;  // in (or is) an operator that is the top of a vertical
  bool fuzzAboveAny() const;              // the top layer of a vertical holds fuzz (fuzzyLayer)

  void line(const std::string& s) { out_ += (s.empty() ? "" : indent_ + s) + "\n"; }
  /// A slab's or an eye's subsurface scattering into closure c.
  void emitSssPins(const std::string& c, const Slab& s) {
    line(fmt::format("{}.sssMfp = {};", c, mfpOf(s)));
    line(fmt::format("{}.sssPhaseAnisotropy = {};", c, expr(s.pin(SlabPin::SssPhaseAnisotropy))));
    line(fmt::format("{}.sssType = {}u;", c, static_cast<unsigned>(s.sssType)));
  }
  /// mfp · sss_mfp_scale, without the multiplication when the scale is 1.
  std::string mfpOf(const Slab& s) {
    ValueId scale = s.pin(SlabPin::SssMfpScale);
    if (m_.values.isConstEqual(scale, 1.0)) return expr(s.pin(SlabPin::SssMfp));
    return fmt::format("{} * {}", expr(s.pin(SlabPin::SssMfp)), expr(scale));
  }

  const Material& m_;
  const TreeInfo& t_;
  const StorageLayout& L_;
  const Syntax& syn_;
  const EmitOptions& opt_;
  std::string out_, indent_;
  std::vector<bool> needed_;
  std::set<int> textures_;  // texture input indices sampled
  std::map<int, int> profileIndex_;  // input index -> profile index
};

std::string Emitter::varName(ValueId v) const {
  auto it = m_.valueNames.find(v);
  if (it != m_.valueNames.end()) return "n_" + it->second;
  return fmt::format("v{}", v);
}

void Emitter::need(ValueId root) {
  std::vector<ValueId> stack{root};
  while (!stack.empty()) {
    ValueId v = stack.back();
    stack.pop_back();
    if (needed_[v]) continue;
    needed_[v] = true;
    const ValueNode& n = m_.values.node(v);
    for (int i = 0; i < n.argCount; ++i) stack.push_back(n.args[i]);
  }
}

std::string Emitter::expr(ValueId v) {
  const ValueNode& n = m_.values.node(v);
  switch (n.op) {
    case Op::Const: {
      int k = componentCount(n.type);
      if (k == 1) return dialectLiteral(n.c[0]);
      std::string args;
      for (int i = 0; i < k; ++i) args += (i ? ", " : "") + dialectLiteral(n.c[i]);
      return dialectType(n.type) + "(" + args + ")";
    }
    case Op::Input: return syn_.inputAccess(m_.name, m_.inputs[n.attr].name);
    case Op::Geometry:
      switch (static_cast<GeometryAttr>(n.attr)) {
        case GeometryAttr::Normal: return vec3(0, 0, 1);   // tangent space (the format's convention)
        case GeometryAttr::Tangent: return vec3(1, 0, 0);
        case GeometryAttr::View: return "ts_view";
        case GeometryAttr::Uv0: return "g.uv0";
        case GeometryAttr::Uv1: return "g.uv1";
        case GeometryAttr::VertexColor: return "g.vertexColor";
        case GeometryAttr::Position: return "g.position";
      }
      return "g.N";
    default: return varName(v);
  }
}

bool Emitter::nonZero(ValueId v) const {
  const ValueNode& n = m_.values.node(v);
  auto positiveConst = [&](ValueId c) {
    const ValueNode& k = m_.values.node(c);
    if (k.op != Op::Const) return false;
    for (int i = 0; i < std::max(1, componentCount(k.type)); ++i)
      if (!(k.c[i] > 0)) return false;
    return true;
  };
  if (n.op == Op::Const) {
    for (int i = 0; i < std::max(1, componentCount(n.type)); ++i)
      if (n.c[i] == 0 || !std::isfinite(n.c[i])) return false;
    return true;
  }
  // max(c, x) with c > 0 in every component is at least c (a NaN x gives c or NaN, never 0).
  return n.op == Op::Max && n.argCount == 2 && (positiveConst(n.args[0]) || positiveConst(n.args[1]));
}

std::string Emitter::opExpr(const ValueNode& n) {
  auto a = [&](int i) { return expr(n.args[i]); };
  auto call = [&](const char* f) {
    std::string s = std::string(f) + "(";
    for (int i = 0; i < n.argCount; ++i) s += (i ? ", " : "") + a(i);
    return s + ")";
  };
  switch (n.op) {
    case Op::Add: return fmt::format("({} + {})", a(0), a(1));
    case Op::Subtract: return fmt::format("({} - {})", a(0), a(1));
    case Op::Multiply: return fmt::format("({} * {})", a(0), a(1));
    case Op::Divide:
      // A divisor that cannot be 0 needs no guard, only the overflow clamp:
      // inline (two instructions), not a call. A shader inlines every call,
      // and SPIRV-Tools' inliner is quadratic in the calls of one function:
      // the blending of a wide tree divides by max(1e-6, w) thousands of times.
      if (nonZero(n.args[1]))
        return fmt::format("clamp({} / {}, -SUBSTRATE_VALUES_FLT_MAX, SUBSTRATE_VALUES_FLT_MAX)", a(0), a(1));
      return call("substrate_safe_div");
    case Op::Min: return call("min");
    case Op::Max: return call("max");
    case Op::Lerp: return call("lerp");
    case Op::Clamp: return call("clamp");
    case Op::Saturate: return call("saturate");
    case Op::OneMinus: return fmt::format("(1.0 - {})", a(0));
    case Op::Abs: return call("abs");
    case Op::Sqrt: return call("substrate_value_sqrt");
    case Op::Normalize: return call("substrate_value_normalize");
    case Op::Length: return call("length");
    case Op::Pow: return call("substrate_value_pow");
    case Op::Dot: return call("dot");
    case Op::Step: return call("step");
    case Op::Exp: return call("substrate_value_exp");
    case Op::Swizzle: {
      std::string sw;
      for (int i = 0; i < componentCount(n.type); ++i) sw += "xyzw"[(n.attr >> (2 * i)) & 3];
      return a(0) + "." + sw;
    }
    case Op::Combine: {
      std::string args;
      for (int i = 0; i < n.argCount; ++i) args += (i ? ", " : "") + a(i);
      return dialectType(n.type) + "(" + args + ")";
    }
    case Op::Sample: return fmt::format("SUBSTRATE_SAMPLE(t_{0}, s_{0}, {1})", m_.inputs[n.attr].name, a(0));
    case Op::MetalnessToDiffuseF0:
      return n.attr == 0 ? call("substrate_metalness_to_diffuse") : call("substrate_metalness_to_f0");
    case Op::IorToF0: return call("substrate_ior_to_f0");
    case Op::HazinessToSecondRoughness:
      return n.attr == 0 ? call("substrate_haziness_second_roughness") : call("substrate_haziness_weight");
    case Op::TransmittanceToMfp:
      return n.attr == 0 ? call("substrate_transmittance_to_mfp") : call("substrate_transmittance_to_mfp_thickness");
    case Op::ThinFilm: {
      std::string s = call(n.attr == 0 ? "substrate_thin_film_f0" : "substrate_thin_film_f90");
      return s.substr(0, s.size() - 1) + ", ts_view)";
    }
    case Op::RotationToTangent: return call("substrate_rotation_to_tangent");
    case Op::ViewDependentCoverage: {
      std::string s = call("substrate_view_dependent_coverage");
      return s.substr(0, s.size() - 1) + ", ts_view)";
    }
    default: return "0.0";
  }
}

int Emitter::verticalOfTop(int node) const { return t_.layerVertical[node]; }

bool Emitter::underOperatorTop(int node) const {
  for (int x = node, p = t_.parent[node]; p >= 0; x = p, p = t_.parent[p])
    if (m_.nodes[p].op == TreeOp::Vertical && m_.nodes[p].left == x && m_.nodes[x].op != TreeOp::Slab) return true;
  return false;
}

bool Emitter::fuzzAboveAny() const {
  for (int n : t_.preorder)
    if (m_.nodes[n].op == TreeOp::Vertical && fuzzyLayer(t_, m_.nodes[n].left)) return true;
  return false;
}

bool Emitter::knownOpaque(int node) const {
  const Slab& s = m_.slabs[m_.nodes[node].slab];
  const int v = verticalOfTop(node);
  const double d = m_.settings.surfaceThickness;
  return m_.values.isConstEqual(s.pin(SlabPin::SssMfp), 0.0) &&
         (v < 0 ? d > 0 : m_.values.isConst(m_.nodes[v].a) && m_.values.node(m_.nodes[v].a).c[0] > 0);
}

/// Marks every value the generated function computes: operator values, the
/// slabs' media, and for each closure only the pins its features use.
void Emitter::collectNeeded() {
  needed_.assign(m_.values.size(), false);
  for (int n : t_.preorder) {
    const TreeNode& node = m_.nodes[n];
    if (node.a != kNoValue) need(node.a);
    if (node.b != kNoValue) need(node.b);
  }
  for (const ClosureLayout& c : L_.closures) {
    const Slab& s = m_.slabs[c.slab];
    for (SlabPin p : {SlabPin::DiffuseAlbedo, SlabPin::F0, SlabPin::Roughness, SlabPin::Normal, SlabPin::SssMfp,
                      SlabPin::SssMfpScale})
      need(s.pin(p));
    if (s.coverage != kNoValue) need(s.coverage);
    const std::uint16_t f = s.features;
    if (f & kFeatF90) need(s.pin(SlabPin::F90));
    if (f & kFeatAnisotropy) {
      need(s.pin(SlabPin::Anisotropy));
      need(s.pin(SlabPin::Tangent));
    }
    if (f & kFeatSss) need(s.pin(SlabPin::SssPhaseAnisotropy));
    if (f & kFeatHaze) {
      need(s.pin(SlabPin::SecondRoughness));
      need(s.pin(SlabPin::SecondRoughnessWeight));
    }
    if (f & kFeatFuzz) {
      need(s.pin(SlabPin::FuzzAmount));
      need(s.pin(SlabPin::FuzzColor));
      need(s.pin(SlabPin::FuzzRoughness));
    }
    if (f & kFeatGlint) {
      need(s.pin(SlabPin::GlintValue));
      need(s.pin(SlabPin::GlintUv));
    }
    if (f & kFeatEmissive) need(s.pin(SlabPin::Emissive));
    if (f & kFeatHair)  // emitHairClosure's pins
      for (SlabPin p : {SlabPin::BaseColor, SlabPin::Tangent, SlabPin::AzimuthalRoughness, SlabPin::Ior,
                        SlabPin::CuticleAngle, SlabPin::Scatter})
        need(s.pin(p));
    if (f & kFeatWater)  // emitWaterBody's pins
      for (SlabPin p : {SlabPin::Specular, SlabPin::TopMaterialOpacity, SlabPin::WaterAlbedo,
                        SlabPin::WaterExtinction, SlabPin::WaterPhaseG, SlabPin::ColorScaleBehindWater})
        need(s.pin(p));
    if (f & kFeatEye)  // emitEyeClosure's pins
      for (SlabPin p : {SlabPin::DiffuseAlbedo, SlabPin::Roughness, SlabPin::IrisNormal, SlabPin::IrisPlaneNormal,
                        SlabPin::IrisMask, SlabPin::IrisDistance})
        need(s.pin(p));
  }
  for (int n : t_.preorder) {  // unlit leaves: what they let through and emit
    const TreeNode& node = m_.nodes[n];
    if (!isUnlitLeaf(m_, node)) continue;
    const Slab& s = m_.slabs[node.slab];
    need(s.pin(SlabPin::Transmittance));
    if (s.coverage != kNoValue) need(s.coverage);
    if (s.features & kFeatEmissive) need(s.pin(SlabPin::Emissive));
    if (L_.closures.empty()) need(s.pin(SlabPin::Normal));  // the no-closure slot's (emitNoClosureSlot)
  }
  const std::vector<int> profiles = specularProfileInputs(m_, L_);
  for (std::size_t k = 0; k < profiles.size(); ++k) profileIndex_[profiles[k]] = static_cast<int>(k);
  collectTextures();
}

void Emitter::collectTextures() {
  for (ValueId v = 0; v < m_.values.size(); ++v)
    if (needed_[v] && m_.values.node(v).op == Op::Sample) textures_.insert(m_.values.node(v).attr);
}

void Emitter::emitResources() {
  std::vector<std::pair<VType, std::string>> uniforms;
  for (const auto& in : m_.inputs)
    if (in.type != VType::Texture) uniforms.emplace_back(in.type, in.name);
  if (opt_.inputsPerInvocation && !uniforms.empty())
    line("// Material inputs: private globals, set by the kernel for each shading point; textures from binding 1.");
  else
    line("// Material inputs: descriptor set 1, binding 0 (std140); textures from binding 1.");
  if (!uniforms.empty()) out_ += syn_.materialInputs(m_.name, uniforms, opt_.inputsPerInvocation);
  int binding = 1;
  for (std::size_t i = 0; i < m_.inputs.size(); ++i) {
    if (m_.inputs[i].type != VType::Texture || !textures_.count(static_cast<int>(i))) continue;
    const std::string& n = m_.inputs[i].name;
    out_ += syn_.texture(1, binding, false, "t_" + n) + syn_.sampler(1, binding + 16, "s_" + n);
    ++binding;
  }
  if (!textures_.empty()) {
    line("#ifndef SUBSTRATE_SAMPLE");
    line("#ifdef SUBSTRATE_TEXTURE_LOD0  // compute shaders have no implicit derivatives");
    line("#define SUBSTRATE_SAMPLE(t, s, uv) SUBSTRATE_TEXTURE_SAMPLE_LEVEL(t, s, uv, 0.0)");
    line("#else");
    line("#define SUBSTRATE_SAMPLE(t, s, uv) SUBSTRATE_TEXTURE_SAMPLE(t, s, uv)");
    line("#endif");
    line("#endif");
  }
}

void Emitter::emitValues() {
  bool any = false;
  for (ValueId v = 0; v < m_.values.size(); ++v) {
    if (!needed_[v]) continue;
    const ValueNode& n = m_.values.node(v);
    if (n.op == Op::Const || n.op == Op::Input || n.op == Op::Geometry) continue;
    if (!any) line("// Values (the value DAG, in dependency order)");
    any = true;
    line(fmt::format("{} {} = {};", dialectType(n.type), varName(v), opExpr(n)));
  }
}

void Emitter::emitTree() {
  line("// Tree: coverage C and transmittance T (along the normal) of every node.");
  for (int n : t_.preorder) {
    const TreeNode& node = m_.nodes[n];
    if (node.op != TreeOp::Slab) continue;
    const Slab& s = m_.slabs[node.slab];
    std::string c = s.coverage == kNoValue ? "1.0" : expr(s.coverage);
    if (s.kind == BsdfKind::Unlit) {  // no closure: it covers, lets through its transmittance, emits (emitEmission)
      line(fmt::format("// unlit '{}' (Id={})", node.id, t_.reportId[n]));
      line(fmt::format("float C_{} = {};", node.id, c));
      line(fmt::format("float3 T_{} = {};", node.id, expr(s.pin(SlabPin::Transmittance))));
      continue;
    }
    int v = verticalOfTop(n);
    std::string t;
    double d = m_.settings.surfaceThickness;
    if (knownOpaque(n))
      t = vec3(0, 0, 0);  // no medium: opaque matter
    else
      t = fmt::format("substrate_transmittance({}, {})", mfpOf(s), v >= 0 ? expr(m_.nodes[v].a) : dialectLiteral(d));
    line(fmt::format("// slab '{}' (Id={}, BSDF {}){}", node.id, t_.reportId[n], t_.bsdfId[node.slab],
                     v >= 0 ? fmt::format(", in the top layer of vertical '{}'", m_.nodes[v].id) : ""));
    line(fmt::format("float C_{} = {};", node.id, c));
    line(fmt::format("float3 T_{} = {};", node.id, t));
    if (t_.layerVertical[n] >= 0 && fuzzyLayer(t_, n))  // what its fuzz lets through to the layers under it
      line(fmt::format("float FT_{} = substrate_fuzz_transmission({}, {}, "
                       "dot(substrate_tangent_to_world({}, g.N, g.T), g.V));",
                       node.id, expr(s.pin(SlabPin::FuzzAmount)), expr(s.pin(SlabPin::FuzzRoughness)),
                       expr(s.pin(SlabPin::Normal))));
    if (underOperatorTop(n))  // what it lets through, its interface included (TI: see emitClosures)
      line(fmt::format("float3 TI_{0} = T_{0} * (1.0 - {1});", node.id, expr(s.pin(SlabPin::F0))));
  }
  // Operators bottom-up: by distance from leaves, then tree id.
  for (int n : t_.bottomUpOperators) {
    const TreeNode& node = m_.nodes[n];
    const std::string id = node.id, l = nodeName(node.left);
    const bool weight = node.op == TreeOp::CoverageWeight;  // unary: C = weight * C_a, the rest passes through
    line(fmt::format("// {} '{}' (Id={}, DistanceFromLeaves={})", treeOpName(node.op), id, t_.reportId[n],
                     t_.distanceFromLeaves[n]));
    line(fmt::format("float C_{0}; float3 T_{0};", id));
    line(weight ? fmt::format("C_{0} = {1} * C_{2}; T_{0} = T_{2};", id, expr(node.a), l)
                : operatorCall(node, "T_", "C_" + id, "T_" + id));
    if (t_.layerVertical[n] >= 0 && fuzzyLayer(t_, n)) {
      // The same operator on what the children's fuzz lets through (1 for a
      // child without fuzz), for the closures under the layer (walkUp).
      line(fmt::format("float FT_{};", id));
      line(weight ? fmt::format("FT_{} = FT_{};", id, l)
                  : fmt::format("{{ float c; float3 f; {} FT_{} = f.x; }}", operatorCall(node, "FT_", "c", "f"), id));
    }
    if (!underOperatorTop(n)) continue;
    // The same operator on what the children let through with their interfaces.
    line(fmt::format("float3 TI_{};", id));
    line(weight ? fmt::format("TI_{} = TI_{};", id, l)
                : fmt::format("{{ float c; {} }}", operatorCall(node, "TI_", "c", "TI_" + id)));
  }
}

/// The call of binary operator `node`'s substrate_op_* on its children's
/// coverages C_ and their values named `prefix` (T_, TI_: float3; FT_: a float
/// splat to float3, 1 for a child without fuzz), into `c` and `t`.
std::string Emitter::operatorCall(const TreeNode& node, const std::string& prefix, const std::string& c,
                                  const std::string& t) {
  auto value = [&](int x) {
    if (prefix != "FT_") return prefix + nodeName(x);
    return fmt::format("SUBSTRATE_SPLAT3({})", fuzzyLayer(t_, x) ? "FT_" + nodeName(x) : std::string("1.0"));
  };
  const std::string l = nodeName(node.left), r = nodeName(node.right), tl = value(node.left), tr = value(node.right);
  switch (node.op) {
    case TreeOp::Horizontal:
      return fmt::format("substrate_op_horizontal(C_{}, {}, C_{}, {}, {}, {}, {});", l, tl, r, tr, expr(node.a), c, t);
    case TreeOp::Select:
      return fmt::format("substrate_op_horizontal(C_{}, {}, C_{}, {}, 1.0 - step({}, {}), {}, {});", l, tl, r, tr,
                         expr(node.a), expr(node.b), c, t);
    case TreeOp::Vertical: return fmt::format("substrate_op_vertical(C_{}, {}, C_{}, {}, {}, {});", l, tl, r, tr, c, t);
    case TreeOp::Add: return fmt::format("substrate_op_add(C_{}, {}, C_{}, {}, {}, {});", l, tl, r, tr, c, t);
    default: return "";  // slabs and coverage weights: the caller's
  }
}

/// The walk from BSDF leaf `node` (id `id`) up to the root: its mix/coverage
/// weight (an expression, "" for 1); `layers` gets (vertical, its top) for
/// each vertical whose base holds it, bottom-up.
std::string Emitter::pathWeight(int node, const std::string& id, std::vector<std::pair<int, int>>& layers) {
  const Slab& s = m_.slabs[m_.nodes[node].slab];
  std::string weight = s.coverage == kNoValue ? "" : fmt::format("C_{}", id);
  for (int x = node, p = t_.parent[node]; p >= 0; x = p, p = t_.parent[p]) {
    const TreeNode& op = m_.nodes[p];
    std::string f;
    switch (op.op) {
      case TreeOp::Horizontal: f = op.right == x ? expr(op.a) : fmt::format("(1.0 - {})", expr(op.a)); break;
      case TreeOp::CoverageWeight: f = expr(op.a); break;
      case TreeOp::Select:
        f = op.right == x ? fmt::format("(1.0 - step({}, {}))", expr(op.a), expr(op.b))
                          : fmt::format("step({}, {})", expr(op.a), expr(op.b));
        break;
      case TreeOp::Vertical:
        if (op.right != x) break;
        layers.emplace_back(p, op.left);
        // What its fuzz lets through: FT where the layer covers, 1 elsewhere.
        if (fuzzyLayer(t_, op.left))
          f = t_.unitCoverage[op.left] ? fmt::format("FT_{}", m_.nodes[op.left].id)
                                       : fmt::format("lerp(1.0, FT_{0}, C_{0})", m_.nodes[op.left].id);
        break;
      default: break;
    }
    if (!f.empty()) weight += (weight.empty() ? "" : " * ") + f;
  }
  return weight;
}

/// The walk from closure `cl`'s slab (tree node `node`, id `id`) up to the
/// root: returns its mix/coverage weight (an expression, "" for 1) and, for a
/// closure under layers, emits what the layers above do to it (ca_, ta_, va_).
std::string Emitter::walkUp(const ClosureLayout& cl, int node, const std::string& id) {
  std::vector<std::pair<int, int>> layers;  // (vertical, its top) for each vertical above, bottom-up
  const std::string weight = pathWeight(node, id, layers);
  if (!cl.isTop) {
    line(fmt::format("float ca_{0} = 0.0; float3 ta_{0} = {1}; float va_{0} = 0.0;", id, vec3(1, 1, 1)));
    // From the root down. The top's interfaces transmit 1 - F0 at normal
    // incidence: a slab's inline, an operator's (a partial coat, a mix of
    // coats) through TI. The lighting applies the angular part of the first
    // 1 + extraInterfaces interfaces on the way down (at most 4); every
    // further one is folded in here as substrate_extra_interfaces
    // (substrate_tree.h).
    int lit = 1 + cl.extraInterfaces;
    for (auto it = layers.rbegin(); it != layers.rend(); ++it) {
      const TreeNode& top = m_.nodes[it->second];
      std::string tTop = fmt::format("TI_{}", top.id);
      if (top.op == TreeOp::Slab)
        tTop = fmt::format("T_{} * (1.0 - {})", top.id, expr(m_.slabs[top.slab].pin(SlabPin::F0)));
      const int extra = foldedInterfaces(t_.interfaces[it->second], lit);
      if (extra > 0) tTop = fmt::format("{} * substrate_extra_interfaces({})", tTop, dialectLiteral(extra));
      if (top.op == TreeOp::Slab)
        line(fmt::format("va_{0} += C_{1} * substrate_roughness_to_variance({2});", id, top.id,
                         expr(m_.slabs[top.slab].pin(SlabPin::Roughness))));
      line(fmt::format("substrate_layer_above(ca_{0}, ta_{0}, C_{1}, {2});  // under '{1}' (vertical '{3}')", id,
                       top.id, tTop, m_.nodes[it->first].id));
    }
  }
  return weight;
}

void Emitter::emitClosures() {
  for (std::size_t i = 0; i < L_.closures.size(); ++i) {
    const ClosureLayout& cl = L_.closures[i];
    const Slab& s = m_.slabs[cl.slab];
    const int node = t_.slabNode[cl.slab];
    const std::string c = fmt::format("closures[{}]", i), id = m_.nodes[node].id;
    line("");
    line(fmt::format("// Closure {}: slab '{}' (BSDF {}, LayerDepth {}, {}){}", i, id, i, t_.layerDepth[node],
                     cl.isTop ? "top layer" : "under a layer",
                     s.collapsedFrom.empty() ? "" : fmt::format(" (a blended {})", s.collapsedFrom)));
    const std::string weight = walkUp(cl, node, id);
    line(fmt::format("substrate_closure_init({});", c));
    if (s.kind == BsdfKind::Hair) {  // always the whole material: no weight, nothing above
      emitHairClosure(c, s);
      continue;
    }
    if (s.kind == BsdfKind::Eye) {  // always the whole material too
      emitEyeClosure(c, s);
      continue;
    }
    const ValueId albedo = s.pin(SlabPin::DiffuseAlbedo);
    if (verticalOfTop(node) >= 0 && !knownOpaque(node) && !m_.values.isConstEqual(albedo, 0.0))
      // A layer scatters back only what it does not let through (substrate_tree.h).
      line(fmt::format("{}.diffuseAlbedo = substrate_layer_scattering({}, T_{});", c, expr(albedo), id));
    else
      line(fmt::format("{}.diffuseAlbedo = {};", c, expr(albedo)));
    line(fmt::format("{}.f0 = {};", c, expr(s.pin(SlabPin::F0))));
    std::string rough = expr(s.pin(SlabPin::Roughness));
    if (!cl.isTop)  // a rough layer above widens the lobes below (Belcour 2018)
      rough = fmt::format("substrate_variance_to_roughness(substrate_roughness_to_variance({}) + va_{})", rough, id);
    line(fmt::format("{}.roughness = {};", c, rough));
    line(fmt::format("{}.N = substrate_tangent_to_world({}, g.N, g.T);", c, expr(s.pin(SlabPin::Normal))));
    unsigned bits = emitFeaturePins(c, s);
    if (cl.storesWeight) bits |= SUBSTRATE_FEATURE_WEIGHT;
    if (cl.storesCoverageAbove) bits |= SUBSTRATE_FEATURE_COVERAGE_ABOVE;
    if (!weight.empty()) line(fmt::format("{}.weight = {};", c, weight));
    if (!cl.isTop) {
      line(fmt::format("{}.topTransmittance = ta_{};", c, id));
      line(fmt::format("{}.coverageAbove = ca_{};", c, id));
      if (cl.extraInterfaces > 0)  // the lighting's interface term to the power 1 + this
        line(fmt::format("{}.extraInterfaces = {}u;", c, cl.extraInterfaces));
      line(fmt::format("{}.isTop = false;", c));
    }
    line(fmt::format("{}.features = {}u;", c, bits));
  }
}

/// The pins of slab s's features into closure c (emitClosures); returns
/// their SUBSTRATE_FEATURE_* bits.
unsigned Emitter::emitFeaturePins(const std::string& c, const Slab& s) {
  unsigned bits = 0;
  const std::uint16_t f = s.features;
  if (f & kFeatF90) {
    bits |= SUBSTRATE_FEATURE_F90;
    line(fmt::format("{}.f90 = {};", c, expr(s.pin(SlabPin::F90))));
  }
  if (f & kFeatAnisotropy) {
    bits |= SUBSTRATE_FEATURE_ANISOTROPY;
    line(fmt::format("{}.anisotropy = {};", c, expr(s.pin(SlabPin::Anisotropy))));
    line(fmt::format("{0}.T = substrate_orthogonal_tangent({0}.N, substrate_tangent_to_world({1}, g.N, g.T));", c,
                     expr(s.pin(SlabPin::Tangent))));
  }
  if (f & kFeatSss) {
    emitSssPins(c, s);
  }
  if (f & kFeatHaze) {
    bits |= SUBSTRATE_FEATURE_HAZE;
    line(fmt::format("{}.secondRoughness = {};", c, expr(s.pin(SlabPin::SecondRoughness))));
    line(fmt::format("{}.secondRoughnessWeight = {};", c, expr(s.pin(SlabPin::SecondRoughnessWeight))));
  }
  if (f & kFeatFuzz) {
    bits |= SUBSTRATE_FEATURE_FUZZ;
    line(fmt::format("{}.fuzzAmount = {};", c, expr(s.pin(SlabPin::FuzzAmount))));
    line(fmt::format("{}.fuzzColor = {};", c, expr(s.pin(SlabPin::FuzzColor))));
    line(fmt::format("{}.fuzzRoughness = {};", c, expr(s.pin(SlabPin::FuzzRoughness))));
  }
  if (f & kFeatGlint) {
    bits |= SUBSTRATE_FEATURE_GLINT;
    line(fmt::format("{}.glintValue = {};", c, expr(s.pin(SlabPin::GlintValue))));
    line(fmt::format("{}.glintUv = {};", c, expr(s.pin(SlabPin::GlintUv))));
    line(fmt::format("{}.glintUvDerivatives = g.uvDerivatives;", c));
  }
  if (f & kFeatSpecularProfile) {
    bits |= SUBSTRATE_FEATURE_SPECULAR_PROFILE;
    line(fmt::format("{}.specularProfile = {}u;  // ${}", c, profileIndex_[s.specularProfileInput] + 1,
                     m_.inputs[s.specularProfileInput].name));
  }
  if (f & kFeatEmissive) line(fmt::format("{}.emissive = {};", c, expr(s.pin(SlabPin::Emissive))));
  return bits;
}

/// A hair closure (runtime_shaders/substrate_hair.h): the base colour in
/// diffuseAlbedo, the longitudinal roughness in roughness, the fibre in T
/// (orthogonal to the normal, as the stored tangent angle is), the rest in hair.
void Emitter::emitHairClosure(const std::string& c, const Slab& s) {
  line(fmt::format("{}.diffuseAlbedo = {};", c, expr(s.pin(SlabPin::BaseColor))));
  line(fmt::format("{}.roughness = {};", c, expr(s.pin(SlabPin::Roughness))));
  line(fmt::format("{}.N = substrate_tangent_to_world({}, g.N, g.T);", c, expr(s.pin(SlabPin::Normal))));
  line(fmt::format("{0}.T = substrate_orthogonal_tangent({0}.N, substrate_tangent_to_world({1}, g.N, g.T));", c,
                   expr(s.pin(SlabPin::Tangent))));
  line(fmt::format("{}.hair = float4({}, {}, {}, {});", c, expr(s.pin(SlabPin::AzimuthalRoughness)),
                   expr(s.pin(SlabPin::Ior)), expr(s.pin(SlabPin::CuticleAngle)), expr(s.pin(SlabPin::Scatter))));
  if (s.features & kFeatEmissive) line(fmt::format("{}.emissive = {};", c, expr(s.pin(SlabPin::Emissive))));
  line(fmt::format("{}.features = {}u;", c, SUBSTRATE_FEATURE_HAIR));
}

/// An eye closure (runtime_shaders/substrate_eye.h): the cornea's normal and
/// roughness, F0 0.04 (substrate_closure_init's), the sclera's and iris's
/// colour in diffuseAlbedo, the iris's normals in world space and its mask
/// and distance in iris.
void Emitter::emitEyeClosure(const std::string& c, const Slab& s) {
  line(fmt::format("{}.diffuseAlbedo = {};", c, expr(s.pin(SlabPin::DiffuseAlbedo))));
  line(fmt::format("{}.roughness = {};", c, expr(s.pin(SlabPin::Roughness))));
  line(fmt::format("{}.N = substrate_tangent_to_world({}, g.N, g.T);", c, expr(s.pin(SlabPin::Normal))));
  line(fmt::format("{}.irisN = substrate_tangent_to_world({}, g.N, g.T);", c, expr(s.pin(SlabPin::IrisNormal))));
  line(fmt::format("{}.irisPlaneN = substrate_tangent_to_world({}, g.N, g.T);", c,
                   expr(s.pin(SlabPin::IrisPlaneNormal))));
  line(fmt::format("{}.iris = float2({}, {});", c, expr(s.pin(SlabPin::IrisMask)), expr(s.pin(SlabPin::IrisDistance))));
  if (s.features & kFeatEmissive) line(fmt::format("{}.emissive = {};", c, expr(s.pin(SlabPin::Emissive))));
  if (s.features & kFeatSss) emitSssPins(c, s);  // the sclera's subsurface scattering
  line(fmt::format("{}.features = {}u;", c, SUBSTRATE_FEATURE_EYE));
}

/// A single-layer water's body (runtime_shaders/substrate_water.h) into
/// `water`; its surface is closure 0, the slab build_tree lowered it to.
void Emitter::emitWaterBody() {
  if (!isWaterMaterial(m_)) return;
  const Slab& s = m_.slabs[m_.nodes[m_.root].slab];
  line("");
  line(fmt::format("// The water body of '{}' (substrate_water_seen lights it).", s.id));
  line("substrate_water_init(water);");
  line(fmt::format("water.albedo = {};", expr(s.pin(SlabPin::WaterAlbedo))));
  line(fmt::format("water.extinction = {};", expr(s.pin(SlabPin::WaterExtinction))));
  line(fmt::format("water.phaseG = {};", expr(s.pin(SlabPin::WaterPhaseG))));
  line(fmt::format("water.scaleBehind = {};", expr(s.pin(SlabPin::ColorScaleBehindWater))));
  line(fmt::format("water.opacity = saturate({});", expr(s.pin(SlabPin::TopMaterialOpacity))));
  line(fmt::format("water.f0 = 0.08 * saturate({});", expr(s.pin(SlabPin::Specular))));
}

int Emitter::firstUnlit() const {
  for (int n : t_.preorder)
    if (isUnlitLeaf(m_, m_.nodes[n])) return n;
  return -1;
}

/// A material with no closure (only unlit leaves): its one slot
/// (closureArraySize) is neutral with weight 0, so nothing lights it, and
/// holds what the top-layer word stores: the first unlit's normal and a
/// roughness of 1.
void Emitter::emitNoClosureSlot() {
  if (!L_.closures.empty()) return;
  const int n = firstUnlit();
  line("");
  line("// No closure (an unlit material): one neutral slot of weight 0, for the top-layer word.");
  line("substrate_closure_init(closures[0]);");
  line("closures[0].weight = 0.0;");
  line("closures[0].roughness = 1.0;");
  line(fmt::format("closures[0].N = substrate_tangent_to_world({}, g.N, g.T);",
                   expr(m_.slabs[m_.nodes[n].slab].pin(SlabPin::Normal))));
}

/// `emission`: what the unlit leaves emit, each weighted by the mixes and
/// coverage weights on its way to the root (unlitEmission; an unlit is never
/// under a layer, build_tree).
void Emitter::emitEmission() {
  if (!unlitEmission(m_)) return;
  line("");
  line("// What the unlit nodes emit toward the viewer (light-independent).");
  std::string sum;
  for (int n : t_.preorder) {
    const TreeNode& node = m_.nodes[n];
    if (!isUnlitLeaf(m_, node) || !(m_.slabs[node.slab].features & kFeatEmissive)) continue;
    const Slab& s = m_.slabs[node.slab];
    std::vector<std::pair<int, int>> layers;
    const std::string weight = pathWeight(n, node.id, layers);
    const std::string e = expr(s.pin(SlabPin::Emissive));
    sum += (sum.empty() ? "" : " + ") + (weight.empty() ? e : fmt::format("({}) * {}", weight, e));
  }
  line(fmt::format("emission = {};", sum));
}

/// What the layers' top lets through at grazing angles, for every closure
/// under one interface when one closure, one GGX lobe, is on top (coatFloorClosures;
/// the others keep 0, substrate_closure_init), as the deferred unpacker derives it:
/// under an isotropic top, substrate_coat_floor of the pixel's top-layer
/// roughness (the top-layer word's, so that the forward pass lights as the
/// deferred one does) and its mean share; under a stretched top, its GGX
/// alphas and tangent (the floor follows a direction's azimuth,
/// substrate_coat_floor_along) and the azimuths' mean share.
/// SubstrateClosure.coversLayers of every closure on top when some closure lies
/// under layers, as the deferred unpacker derives it from the closure headers:
/// such a top's lobe takes no dielectric multiple scattering, which the layers'
/// interface term under it does not take away (substrate_closure_dielectric_ms).
void Emitter::emitCoversLayers() {
  if (!hasLayers(L_)) return;
  for (std::size_t i = 0; i < L_.closures.size(); ++i)
    if (L_.closures[i].isTop) line(fmt::format("closures[{}].coversLayers = true;", i));
}

void Emitter::emitCoatFloor() {
  const std::vector<std::size_t> under = coatFloorClosures(m_, L_);
  if (under.empty()) return;
  if (const int top = stretchedTopClosure(m_, L_); top >= 0) {
    line(fmt::format("float2 coatStretch = substrate_coat_stretch(closures[{0}].roughness, closures[{0}].anisotropy);"
                     "  // of the stretched top",
                     top));
    line("float coatShare = substrate_coat_aniso_share(coatStretch);");
    for (std::size_t i : under) {
      line(fmt::format("closures[{}].coatStretch = coatStretch;", i));
      line(fmt::format("closures[{}].coatTangent = closures[{}].T;", i, top));
      line(fmt::format("closures[{}].coatShare = coatShare;", i));
    }
    return;
  }
  line(fmt::format("float coatFloor = substrate_coat_floor({});  // of the top-layer roughness",
                   topRoughnessExpr(L_, "closures")));
  line("float coatShare = substrate_coat_mean_share(coatFloor);");
  for (std::size_t i : under) {
    line(fmt::format("closures[{}].coatFloor = coatFloor;", i));
    line(fmt::format("closures[{}].coatShare = coatShare;", i));
  }
}

/// What the layers' top interface lets through head-on (substrate_coat_interface
/// of the one closure on top's F0, as the deferred unpacker derives it from the
/// unpacked top closure), for every closure under it when one closure is on
/// top; the others keep 0.96 (substrate_closure_init). Nothing when no closure
/// lies under layers.
void Emitter::emitCoatInterface() {
  const int top = oneTopClosure(L_);
  if (top < 0 || L_.closures.size() == 1) return;  // a mix of tops, or nothing under the top
  line(fmt::format("float coatInterface = substrate_coat_interface(closures[{}].f0);  // of the top closure", top));
  for (std::size_t i = 0; i < L_.closures.size(); ++i)
    if (!L_.closures[i].isTop) line(fmt::format("closures[{}].coatInterface = coatInterface;", i));
}

std::string Emitter::runVolume() {
  const std::string upper = materialUpper(m_);
  const Slab& fog = m_.slabs[m_.nodes[m_.root].slab];
  needed_.assign(m_.values.size(), false);
  for (SlabPin p : {SlabPin::Albedo, SlabPin::Extinction, SlabPin::Emissive, SlabPin::AmbientOcclusion}) need(fog.pin(p));
  collectTextures();
  out_ += fmt::format("// Generated by substratec from {}: do not edit.\n", opt_.sourceName);
  out_ += fmt::format("// Material '{}': a volume (volumetric fog cloud '{}'), no closure, {} layout, {} bytes per froxel "
                      "({} words).\n",
                      m_.name, fog.id, layoutClassName(L_.layoutClass), L_.bytes(), L_.words());
  out_ += fmt::format("#ifndef SUBSTRATE_MATERIAL_{0}\n#define SUBSTRATE_MATERIAL_{0} 1\n\n", upper);
  line(fmt::format("#define {}_WORD_COUNT {}", upper, L_.words()));
  line("#include \"substrate_closure.h\"");
  line("#include \"substrate_common.h\"");
  line("#include \"substrate_values.h\"");
  line("#include \"substrate_fog_cloud.h\"");
  line("");
  emitResources();
  line("");
  line("// Samples the medium at one point of the volume (g.position, world space, metres): a ray-marcher calls it");
  line("// at every step, a froxel pass at every froxel. Values are sanitized: finite, in the pins' ranges.");
  line(fmt::format("SubstrateFogCloudSample {}_sample(SubstrateGeometry g) {{", m_.name));
  indent_ = "  ";
  line("float3 ts_view = float3(dot(g.V, g.T), dot(g.V, cross(g.N, g.T)), dot(g.V, g.N));  // the view direction in "
       "tangent space");
  emitValues();
  line(fmt::format("return substrate_fog_cloud_make({}, {}, {}, {});", expr(fog.pin(SlabPin::Albedo)),
                   expr(fog.pin(SlabPin::Extinction)), expr(fog.pin(SlabPin::Emissive)),
                   expr(fog.pin(SlabPin::AmbientOcclusion))));
  indent_ = "";
  line("}");
  line("");
  out_ += fmt::format("#endif  // SUBSTRATE_MATERIAL_{}\n", upper);
  return out_;
}

std::string Emitter::run() {
  if (isVolumeMaterial(m_)) return runVolume();
  const std::string upper = materialUpper(m_);
  collectNeeded();
  std::uint16_t all = 0;
  for (int s : t_.slabOrder) all |= m_.slabs[s].features;
  out_ += fmt::format("// Generated by substratec from {}: do not edit.\n", opt_.sourceName);
  out_ += fmt::format("// Material '{}': {} closure(s), {} layout, {} bytes per pixel ({} words + 4 top-layer bytes).\n",
                      m_.name, L_.closures.size(), layoutClassName(L_.layoutClass), L_.bytes(), L_.words());
  out_ += fmt::format("// Features: {}.\n", all ? featureList(all) : "none");
  out_ += fmt::format("#ifndef SUBSTRATE_MATERIAL_{0}\n#define SUBSTRATE_MATERIAL_{0} 1\n\n", upper);
  line("// What this material uses: the runtime compiles nothing else.");
  out_ += useDefines(all);
  out_ += extraInterfacesDefine(L_);
  out_ += conductorDefines(m_, L_);
  out_ += coatFloorDefine(m_, L_);
  out_ += underLayersDefines(m_, L_);
  line(fmt::format("#define SUBSTRATE_USE_METALNESS_MIX {}", m_.metalnessMix ? 1 : 0));
  line(fmt::format("#define SUBSTRATE_DIFFUSE_MODEL {}", diffuseModelNumber(opt_.diffuseModel)));
  line(fmt::format("#define {}_CLOSURE_COUNT {}", upper, L_.closures.size()));
  line(fmt::format("#define {}_WORD_COUNT {}", upper, L_.words()));
  line("#include \"substrate_closure.h\"");
  line("#include \"substrate_common.h\"");
  line("#include \"substrate_values.h\"");
  line("#include \"substrate_tree.h\"");
  if (isWaterMaterial(m_)) line("#include \"substrate_water.h\"  // SubstrateWater, its body");
  // A fuzzy layer's transmission reads the fuzz albedo table (substrate_fuzz_transmission).
  if (fuzzAboveAny()) line("#include \"substrate_energy_lut.h\"");
  line("");
  emitResources();
  line("");
  line(fmt::format("// Evaluates the material at one shading point into its closures (fully unrolled)."));
  line(fmt::format("void {0}_evaluate(SubstrateGeometry g, out SubstrateClosure closures[{1}], "
                   "out float coverage, out float3 transmittance{2}{3}) {{",
                   m_.name, closureArraySize(m_), unlitEmission(m_) ? ", out float3 emission" : "",
                   isWaterMaterial(m_) ? ", out SubstrateWater water" : ""));
  indent_ = "  ";
  line("float3 ts_view = float3(dot(g.V, g.T), dot(g.V, cross(g.N, g.T)), dot(g.V, g.N));  // the view direction in "
       "tangent space");
  emitValues();
  emitTree();
  emitClosures();
  emitWaterBody();
  emitCoatFloor();
  emitCoatInterface();
  emitCoversLayers();
  emitNoClosureSlot();
  emitEmission();
  line("");
  line(fmt::format("coverage = C_{};", m_.nodes[m_.root].id));
  line(fmt::format("transmittance = T_{};", m_.nodes[m_.root].id));
  indent_ = "";
  line("}");
  line("");
  out_ += fmt::format("#endif  // SUBSTRATE_MATERIAL_{}\n", upper);
  return out_;
}

}  // namespace

std::string topRoughnessExpr(const StorageLayout& layout, const std::string& arr) {
  std::vector<std::size_t> tops;
  for (std::size_t i = 0; i < layout.closures.size(); ++i)
    if (layout.closures[i].isTop) tops.push_back(i);
  if (tops.size() == 1) return fmt::format("saturate({}[{}].roughness)", arr, tops[0]);  // its weight cancels
  if (tops.empty()) return fmt::format("saturate({}[0].roughness)", arr);  // no closure: the neutral slot's
  std::string rsum, wsum;
  for (std::size_t i : tops) {
    const std::string c = fmt::format("{}[{}]", arr, i);
    rsum += (rsum.empty() ? "" : " + ") + fmt::format("{0}.weight * {0}.roughness", c);
    wsum += (wsum.empty() ? "" : " + ") + fmt::format("{}.weight", c);
  }
  return fmt::format("saturate(({}) / max({}, 1e-6))", rsum, wsum);
}

std::string emitMaterial(const Material& m, const TreeInfo& t, const StorageLayout& layout, const Syntax& syn,
                         const EmitOptions& options) {
  return Emitter(m, t, layout, syn, options).run();
}

}  // namespace substratec
