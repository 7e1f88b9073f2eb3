// The per-pixel storage layout of a material (docs/storage.md is its
// specification): which fields are stored, in which order, with how many
// bits and which encoding. Pricing (bytes per pixel, closures, layout class)
// is derived from it, and code generation packs exactly these fields.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "ir/material.h"
#include "ir/tree_info.h"

namespace substratec {

/// The GBuffer classes (docs/storage.md, "Layout classes"), and VOLUME: a
/// volume-domain material's froxel payload (a fog cloud's sample, no GBuffer).
enum class LayoutClass { Simple, Single, Complex, Special, Volume };
std::string_view layoutClassName(LayoutClass c);  // "SIMPLE", ...

/// Field widths in bits (docs/storage.md, "Field table").
namespace bits {
inline constexpr int kHeader = 16;          // material header
inline constexpr int kClosureHeader = 16;   // per closure, when there are several
inline constexpr int kColor = 20;           // 7/7/6 after a sqrt curve
inline constexpr int kRoughness = 8;
inline constexpr int kGreyWeight = 8;
inline constexpr int kCoverageAbove = 8;
inline constexpr int kSss = 28;             // 3 x 8-bit log2 MFP + 4-bit phase anisotropy
inline constexpr int kHaze = 16;            // second roughness 8 + weight 8
inline constexpr int kFuzz = 32;            // amount 6 + color 20 + roughness 6
inline constexpr int kAnisotropy = 8;
inline constexpr int kSpecularProfile = 8;
inline constexpr int kHair = 32;            // a hair closure's, in place of F0: 4 x 8 bits
inline constexpr int kIrisNormal = 32;      // an eye closure's, in place of F0 with kIris: octahedral 2 x 16
inline constexpr int kIris = 32;            // iris plane normal octahedral 2 x 8 + mask 8 + distance 8
inline constexpr int kGlint = 136;          // density 8 + uv 2 x fp32 + uv derivatives 4 x fp16
inline constexpr int kNormal = 32;          // octahedral 2 x 16
inline constexpr int kTangentAngle = 14;
inline constexpr int kTopLayerBytes = 4;    // octahedral normal 2 x 12 + roughness 8
// A volume's froxel payload (runtime_shaders/substrate_fog_cloud.h), 3 words:
inline constexpr int kFogAlbedo = 24;       // unorm8 x 3
inline constexpr int kFogOcclusion = 8;     // unorm8
inline constexpr int kRgb9e5 = 32;          // extinction, emissive: shared-exponent RGB
}  // namespace bits

struct LayoutField {
  std::string name;      // e.g. "closure1.f0", "basis0.tangent_angle", "header"
  int bits = 0;
  std::string encoding;  // e.g. "unorm7/7/6 sqrt", "log2 unorm8 x3 + snorm4"
  int closure = -1;      // closure index, or -1
  int basis = -1;        // basis index, or -1
  std::uint16_t feature = 0;  // the kFeat* bit whose data the field holds (0: a field every closure has)
};

struct ClosureLayout {
  int slab = -1;          // Material::slabs index
  int basis = -1;
  bool isTop = true;
  bool storesWeight = false;         // grey mix/coverage weight (not statically 1)
  bool storesCoverageAbove = false;  // below a layer whose coverage is not statically 1
  int extraInterfaces = 0;  // interfaces above beyond the first, up to 3 (storedExtraInterfaces; closure header)
  std::uint16_t storedFeatures = 0;
};

struct StorageLayout {
  LayoutClass layoutClass = LayoutClass::Simple;
  std::vector<ClosureLayout> closures;
  int basisCount = 0;
  bool basis0NormalElided = false;
  std::vector<LayoutField> fields;  // in stream order (the top-layer word is separate)
  int totalBits = 0;

  int words() const { return (totalBits + 31) / 32; }
  /// Bytes per pixel, including the 4 bytes of top-layer data; a VOLUME
  /// layout's bytes per froxel (it has no surface, so no top layer).
  int bytes() const { return words() * 4 + (layoutClass == LayoutClass::Volume ? 0 : bits::kTopLayerBytes); }
};

/// Features whose data lives in a closure (emissive and medium cost no bytes).
inline constexpr std::uint16_t kStoredFeatureMask =
    kFeatF90 | kFeatAnisotropy | kFeatSss | kFeatHaze | kFeatFuzz | kFeatGlint | kFeatSpecularProfile | kFeatHair |
    kFeatEye;

StorageLayout computeLayout(const Material& m, const TreeInfo& info);

/// Dynamic simplification (docs/scenes.md): the closures of layout `L` that
/// can be the only one left at a pixel, with nothing it stores in use — the
/// base pass then packs the pixel in the SIMPLE layout. Closure k qualifies
/// when every other closure stores a weight that is not a constant (it can be
/// 0), its own weight can be 1, nothing covers it or its coverage above is
/// stored (it can be 0), and each feature it stores has a pin that is not a
/// constant and a neutral value the lighting treats as the feature off: F90
/// 1, anisotropy 0, an MFP of 0 (not under wrap lighting, which replaces the
/// diffuse model even without a medium), haze weight 0, fuzz amount 0, glint
/// value 1. A specular profile is a static choice: never. Empty for a SIMPLE
/// layout.
std::vector<int> runtimeSimpleClosures(const Material& m, const StorageLayout& L);

/// The SIMPLE layout of closure `k` of `L` alone (header, albedo, F0,
/// roughness: 64 bits), which the base pass packs when runtimeSimpleClosures
/// says it may.
StorageLayout simpleLayoutOf(const StorageLayout& L, int k);

}  // namespace substratec
