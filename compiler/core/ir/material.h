// The material IR: settings, inputs, the value DAG and the Substrate tree,
// plus what the analysis passes attach to it (features, bases, culling notes).
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "ir/value.h"

namespace substratec {

std::string_view blendModeName(BlendMode m);

struct Settings {
  int bytesPerPixel = 80;
  int maxClosures = 8;
  bool thinSurface = false;
  double surfaceThickness = 0.0001;
  BlendMode blendMode = BlendMode::Opaque;
};

/// How a texture input's image is addressed outside [0, 1] (`"wrap"`).
enum class Wrap : std::uint8_t { Repeat, Clamp, Mirror };

struct Input {
  std::string name;
  VType type = VType::Float;
  bool isColor = false;
  std::array<double, 4> defaultValue{0, 0, 0, 0};
  std::optional<std::array<double, 4>> min, max;  // per component
  std::string pointer;
  // texture2d only: the image a renderer binds when nobody binds another
  // (`file`, as written: relative to the material file; "" for none), and
  // whether its RGB is sRGB-encoded (`"colorspace": "srgb"`; else linear).
  std::string file;
  bool srgb = false;
  Wrap wrapU = Wrap::Repeat, wrapV = Wrap::Repeat;  // `"wrap"`: one mode, or [u, v]
  bool nearest = false;                            // `"filter": "nearest"` (else linear, trilinear)
  std::string description;  // `description`, as written (an importer's names the source)
};

/// Slab pins, in the format's order. Every pin always has a value (absent
/// pins get their default), so analyses never special-case "missing".
enum class SlabPin : std::uint8_t {
  DiffuseAlbedo, F0, F90, Roughness, Anisotropy, Normal, Tangent, SssMfp, SssMfpScale,
  SssPhaseAnisotropy, Emissive, SecondRoughness, SecondRoughnessWeight, FuzzAmount, FuzzColor,
  FuzzRoughness, GlintValue, GlintUv, Transmittance, BaseColor, AzimuthalRoughness, Ior, CuticleAngle, Scatter,
  Albedo, Extinction, AmbientOcclusion, IrisNormal, IrisPlaneNormal, IrisMask, IrisDistance, Metallic, Specular,
  TopMaterialOpacity, WaterAlbedo, WaterExtinction, WaterPhaseG, ColorScaleBehindWater,
  Count_
};
inline constexpr int kSlabPinCount = static_cast<int>(SlabPin::Count_);

/// The kinds of BSDF leaf (docs/format.md, "BSDF nodes"): the slab; the
/// unlit BSDF, which emits and lets through but reflects nothing, so it is no
/// closure: it stores nothing per pixel and the lighting never sees it; and
/// the hair BSDF, a fibre's far-field scattering (runtime_shaders/substrate_hair.h),
/// one closure that is always the whole material (build_tree); and the
/// volumetric fog cloud, a participating medium a ray-marcher samples per point
/// (runtime_shaders/substrate_fog_cloud.h): no closure, always the whole
/// material, which it makes a volume-domain material (isVolumeMaterial); and
/// the eye BSDF, a slab's cornea interface and sclera with an iris of its own
/// normal and caustic (runtime_shaders/substrate_eye.h): one closure, always
/// the whole material; and the single-layer water, a water surface over the
/// water body behind it (runtime_shaders/substrate_water.h): its surface is
/// one slab closure, its body a forward term that reads what lies behind the
/// water; always the whole material.
enum class BsdfKind : std::uint8_t { Slab, Unlit, Hair, FogCloud, Eye, Water };
/// "slab", "unlit", "hair", "volumetric_fog_cloud", "eye", "single_layer_water": the node kind in materials.
std::string_view bsdfKindName(BsdfKind k);
std::optional<BsdfKind> bsdfKindByName(std::string_view name);
/// Whether a BSDF of kind `k` is a closure the lighting sees (slab, hair, eye); an
/// unlit only emits and lets through, a fog cloud is sampled, not lit as a surface.
bool bsdfIsClosure(BsdfKind k);
/// Whether a BSDF of kind `k` must be the whole material (hair, fog cloud, eye: build_tree).
bool bsdfIsWholeMaterial(BsdfKind k);

/// BsdfKind bits: which kinds of BSDF node take a pin.
inline constexpr std::uint8_t kPinOfSlab = 1, kPinOfUnlit = 2, kPinOfHair = 4, kPinOfFogCloud = 8, kPinOfEye = 16,
                                kPinOfWater = 32;

struct SlabPinInfo {
  std::string_view name;
  VType type;
  bool color;          // a Float broadcasts to grey
  double defaultValue; // for constant defaults (geometry defaults use `geometryDefault`)
  int geometryDefault; // -1 or a GeometryAttr
  double lo, hi;       // legal range of literal values
  std::uint8_t kinds = kPinOfSlab;  // the BSDF kinds that take it (kPinOf*)
};
const SlabPinInfo& slabPinInfo(SlabPin p);
std::optional<SlabPin> slabPinByName(std::string_view name);
/// Whether a BSDF of kind `k` takes pin `p` (an unlit's other pins keep their
/// defaults and nothing reads them).
bool bsdfTakesPin(BsdfKind k, SlabPin p);

std::string_view sssTypeName(SssType t);

/// Opt-in features (bit flags). A feature is *used* when its gate pin is not a
/// constant equal to the neutral default (see passes/features.h).
enum Feature : std::uint16_t {
  kFeatF90 = 1 << 0,
  kFeatAnisotropy = 1 << 1,
  kFeatSss = 1 << 2,      // subsurface medium stored for lighting (bottom slabs)
  kFeatHaze = 1 << 3,     // second roughness lobe
  kFeatFuzz = 1 << 4,
  kFeatGlint = 1 << 5,
  kFeatSpecularProfile = 1 << 6,
  kFeatEmissive = 1 << 7,
  kFeatMedium = 1 << 8,   // a coating slab's medium (MFP): drives transmittance only
  kFeatHair = 1 << 9,     // a hair BSDF's closure: the fibre's lobes, its own field and a tangent
  kFeatEye = 1 << 10,     // an eye BSDF's closure: the iris's normals, mask and distance in place of F0
  kFeatWater = 1 << 11,   // a single-layer water: its body, a forward term (no bytes: its surface is a slab)
};
inline constexpr int kFeatureCount = 12;
/// Features whose lighting reads the closure's tangent, so its basis stores
/// one: anisotropy (the stretched lobe) and hair (the fibre's direction).
inline constexpr std::uint16_t kTangentFeatures = kFeatAnisotropy | kFeatHair;
std::string_view featureName(int bit);  // scene/report names: "f90", "anisotropy", ...

/// Provenance of a slab whose diffuse_albedo and f0 pins are the two outputs
/// of ONE metalness_to_diffuse_f0 node (diffuse = b (1 - m), f0 = 0.08 s (1 - m)
/// + b m): that node's arguments, so the ground truth can walk the
/// conductor/dielectric mix the author meant instead of the folded pins
/// (reference/ground_truth.h). Invisible to generated code and IR dumps. Valid
/// only while the slab's pins are still `diffuse` and `f0` (simplification
/// drops it when it blends them).
struct MetalnessSource {
  ValueId baseColor = kNoValue, metallic = kNoValue, specular = kNoValue;  // Vec3, Float, Float
  ValueId diffuse = kNoValue, f0 = kNoValue;                               // the helper's outputs (the pins)
};

struct Slab {
  BsdfKind kind = BsdfKind::Slab;  // an unlit leaf is no closure (tree_info: not in slabOrder)
  std::string id;       // source node id (with instance suffix when instanced twice)
  std::string pointer;  // JSON pointer of the slab node
  std::array<ValueId, kSlabPinCount> pins{};
  int specularProfileInput = -1;  // input index of the LUT texture, or -1
  SssType sssType = SssType::None;
  bool sssTypeExplicit = false;
  std::uint16_t features = 0;     // filled by the feature pass
  int basis = -1;                 // filled by the shared-bases pass
  std::optional<MetalnessSource> metalness;  // set by build_tree when both pins come from one helper
  // Set only on slabs made by simplification (parameter blending):
  ValueId coverage = kNoValue;    // the slab's own coverage (kNoValue: 1)
  ValueId thickness = kNoValue;   // accumulated layer thickness (kNoValue: none)
  std::string collapsedFrom;      // the operator it replaces ("" for authored slabs)

  ValueId pin(SlabPin p) const { return pins[static_cast<int>(p)]; }
  ValueId& pin(SlabPin p) { return pins[static_cast<int>(p)]; }
};

std::string_view treeOpName(TreeOp op);

/// One node of the Substrate tree. Operands: Horizontal (left = background,
/// right = foreground, a = mix), Vertical (left = top, right = base,
/// a = thickness), Add (left, right), CoverageWeight (left, a = weight),
/// Select (left = a, right = b, a = value, b = threshold).
struct TreeNode {
  TreeOp op = TreeOp::Slab;
  int left = -1, right = -1;
  ValueId a = kNoValue, b = kNoValue;
  int slab = -1;        // index into Material::slabs (Slab nodes)
  std::string id;       // source node id (instance-suffixed), for names and reports
  std::string pointer;  // JSON pointer of the source node
};

/// Tree node `n` is an unlit leaf (a Slab of BsdfKind::Unlit: no closure).
bool isUnlitLeaf(const struct Material& m, const TreeNode& n);
/// Tree node `n` is a hair leaf (a Slab of BsdfKind::Hair).
bool isHairLeaf(const struct Material& m, const TreeNode& n);
/// Tree node `n` is a leaf of BSDF kind `k`.
/// The material is a single-layer water (its root is one; build_tree keeps it
/// the whole material): <name>_evaluate also returns its body (SubstrateWater).
bool isWaterMaterial(const struct Material& m);
bool isLeafOfKind(const struct Material& m, const TreeNode& n, BsdfKind k);
/// The material is a volume (its root is a volumetric fog cloud: build_tree
/// keeps one alone at the root): no surface, no closure, no GBuffer; it is
/// evaluated per sample point (`<name>_sample`) into a froxel payload
/// (docs/storage.md, "Volumetric fog cloud").
bool isVolumeMaterial(const struct Material& m);

/// The name of tree node `n` in reports and dumps: its operator's
/// (treeOpName), "UNLIT" for an unlit leaf, "HAIR" for a hair leaf,
/// "FOG_CLOUD" for a volumetric fog cloud.
std::string_view nodeOpName(const struct Material& m, const TreeNode& n);

struct Basis {
  ValueId normal = kNoValue;
  ValueId tangent = kNoValue;  // kNoValue when every slab on it is isotropic
  std::vector<int> slabs;
};

struct CullNote {
  std::string what;  // node id
  std::string why;
};

struct Material {
  std::string file;  // as given (for diagnostics)
  std::string name;
  Settings settings;
  std::vector<Input> inputs;
  ValueDag values;
  std::vector<Slab> slabs;
  std::vector<TreeNode> nodes;  // arena; unreachable entries are ignored after culling
  int root = -1;
  std::vector<Basis> bases;
  std::vector<CullNote> culled;
  /// A slab's pins come from a metalness_to_diffuse_f0 node (Slab::metalness,
  /// set by build_tree, kept through simplification): the runtime reads
  /// conductor-like F0 as a metalness mix whose diffuse lies under its
  /// dielectric part (SUBSTRATE_USE_METALNESS_MIX; blend's diffuse energy the same).
  bool metalnessMix = false;
  /// Readable names for DAG nodes that are named value nodes (or their
  /// outputs) in the source: generated code uses them as variable names.
  std::unordered_map<ValueId, std::string> valueNames;

  int inputIndex(std::string_view name) const;
};

/// Rendering of a value for dumps: constants, input names, op trees (bounded).
std::string renderValue(const Material& m, ValueId v, int budget = 5);

/// Slab indices in tree pre-order (left before right): the BSDF order used by
/// reports, storage and generated code.
std::vector<int> slabsInTreeOrder(const Material& m);

}  // namespace substratec
