// The CPU mirror of per-pixel packing (docs/storage.md): the encodings of
// every field, a packer that writes exactly the fields of a StorageLayout,
// and a *generic* unpacker that rebuilds the layout from the stream alone,
// the way a deferred lighting pass does (runtime_shaders/substrate_pack.h is
// the shader twin). Values are doubles; bits are manipulated exactly.
//
// Choices the field table of docs/storage.md leaves open:
//  - bit 15 of the material header is 1 for the multi-closure header and 0 for
//    the single-closure header (a COMPLEX/SPECIAL layout with one closure uses
//    the single-closure header, so the class bits cannot tell them apart);
//  - a header's SSS type is non-zero exactly when the closure stores SSS data
//    (the unpacker reads the SSS field from it);
//  - sub-fields are packed in the order the table lists them, each from its
//    least significant bit (e.g. colour: r bits 0-6, g 7-13, b 14-19; SSS:
//    MFP r, g, b then phase; glint: density, uv.x, uv.y, d(u)/dx, d(v)/dx,
//    d(u)/dy, d(v)/dy);
//  - snorm n bits: code = floor(s·x + s + u), s = 2^(n-1) - 1, decode code/s - 1;
//  - the specular profile field holds the atlas index, SubstrateClosure's
//    specularProfile - 1;
//  - every field, normals included, uses the same per-pixel dither u;
//  - the tangent angle is measured in the frame of the normal *as decoded*
//    (the stored normal, or the top-layer normal when elided), so a normal
//    whose quantization crosses z = 0 cannot flip the Duff frame.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "storage/layout.h"
#include "substrate_constants.h"  // runtime_shaders/: the feature bits, SSS types

namespace substratec {

using Vec3d = std::array<double, 3>;

/// Feature bits as stored in the headers: SUBSTRATE_FEATURE_* of
/// runtime_shaders/substrate_constants.h. SSS is not a bit: the header's SSS
/// type is non-zero exactly when SSS data is stored.
enum ClosureFeatureBit : std::uint32_t {
  kClosureF90 = SUBSTRATE_FEATURE_F90,
  kClosureAnisotropy = SUBSTRATE_FEATURE_ANISOTROPY,
  kClosureHaze = SUBSTRATE_FEATURE_HAZE,
  kClosureFuzz = SUBSTRATE_FEATURE_FUZZ,
  kClosureGlint = SUBSTRATE_FEATURE_GLINT,
  kClosureSpecularProfile = SUBSTRATE_FEATURE_SPECULAR_PROFILE,
  kClosureWeight = SUBSTRATE_FEATURE_WEIGHT,
  kClosureCoverageAbove = SUBSTRATE_FEATURE_COVERAGE_ABOVE,
  kClosureHair = SUBSTRATE_FEATURE_HAIR,  // not a header feature bit: single-closure header bit 12
  kClosureEye = SUBSTRATE_FEATURE_EYE,    // nor this: single-closure header bit 13
};

/// SSS types as stored (SUBSTRATE_SSS_*; the values of SssType).
inline constexpr std::uint32_t kSssTypeNone = SUBSTRATE_SSS_NONE, kSssTypeWrap = SUBSTRATE_SSS_WRAP,
                               kSssTypeDiffusion = SUBSTRATE_SSS_DIFFUSION,
                               kSssTypeSimpleVolume = SUBSTRATE_SSS_SIMPLE_VOLUME;

namespace packfmt {
inline constexpr std::uint32_t kMultiClosureHeaderBit = 1u << 15;  // material header bit 15
inline constexpr std::uint32_t kNoClosureHeaderBit = 1u << 14;  // single-closure header bit 14: an unlit pixel
inline constexpr std::uint32_t kHairHeaderBit = 1u << 12;  // single-closure header bit 12: a hair closure
inline constexpr std::uint32_t kEyeHeaderBit = 1u << 13;   // single-closure header bit 13: an eye closure
inline constexpr int kMaxClosures = 8;     // closure count - 1 is 3 bits
inline constexpr int kMaxBases = 8;        // basis id is 3 bits
inline constexpr double kMfpLog2Min = -24.0;
inline constexpr double kMfpLog2Range = 32.0;  // log2 MFP in [-24, 8]
inline constexpr double kHalfMax = 65504.0;
}  // namespace packfmt

/// One closure's values, mirroring struct SubstrateClosure. Its normal and
/// tangent are those of its basis (BasisValues). Defaults are the neutral
/// values of substrate_closure_init.
struct ClosureValues {
  Vec3d diffuseAlbedo{0.18, 0.18, 0.18};
  Vec3d f0{0.04, 0.04, 0.04};
  Vec3d f90{1, 1, 1};
  double roughness = 0.5;
  double anisotropy = 0;
  /// A hair closure's (SubstrateClosure.hair): azimuthal roughness, ior,
  /// cuticle angle in degrees, scatter; stored in place of f0.
  std::array<double, 4> hair{0.5, 1.55, 2.0, 0.0};
  /// An eye closure's (SubstrateClosure.irisN, .irisPlaneN, .iris): the iris's
  /// normal, its plane's normal (unit, world space like the bases'), and the
  /// iris mask and distance; stored in place of f0 (whose 0.04 is fixed).
  Vec3d irisN{0, 0, 1};
  Vec3d irisPlaneN{0, 0, 1};
  std::array<double, 2> iris{0, 0};
  Vec3d sssMfp{0, 0, 0};  // meters, after sss_mfp_scale; 0 = no medium
  double sssPhaseAnisotropy = 0;
  std::uint32_t sssType = kSssTypeNone;
  double secondRoughness = 0.5;
  double secondRoughnessWeight = 0;
  double fuzzAmount = 0;
  Vec3d fuzzColor{0, 0, 0};
  double fuzzRoughness = 0.5;
  double glintValue = 1;  // glint density; 1 = no glint
  std::array<double, 2> glintUv{0, 0};
  std::array<double, 4> glintUvDerivatives{0, 0, 0, 0};  // d(uv)/dx in 0-1, d(uv)/dy in 2-3
  std::uint32_t specularProfile = 0;  // profile index + 1; 0 = none
  Vec3d emissive{0, 0, 0};            // never stored (added in the base pass)
  double weight = 1;
  Vec3d topTransmittance{1, 1, 1};
  double coverageAbove = 0;  // 0 on top; 1 when below layers of static coverage 1
  std::uint32_t features = 0;  // kClosure* bits (set by the unpacker; ignored by the packer)
  std::uint32_t extraInterfaces = 0;  // closure header bits 14-15 (set by the unpacker; the packer reads the layout)
  bool isTop = true;           // set by the unpacker; the packer reads the layout
  int basis = 0;               // set by the unpacker; the packer reads the layout
};

struct BasisValues {
  Vec3d normal{0, 0, 1};   // unit
  Vec3d tangent{1, 0, 0};  // unit, orthogonal to normal (used when a closure is anisotropic)
};

struct TopLayerValues {
  Vec3d normal{0, 0, 1};
  double roughness = 0.5;
};

// ---- Scalar encodings (x·(2^n - 1) + dither, floored and clamped) ----------
// `dither` is the per-pixel u in [0, 1); NaN inputs encode as 0.

std::uint32_t quantizeUnorm(double x, int bits, double dither);
double dequantizeUnorm(std::uint32_t code, int bits);
/// snorm over [-1, 1]: code = floor(s·x + s + u) in [0, 2s], s = 2^(bits-1) - 1.
std::uint32_t quantizeSnorm(double x, int bits, double dither);
double dequantizeSnorm(std::uint32_t code, int bits);

/// Hair (32 bits): azimuthal roughness unorm8 (bits 0-7), (ior - 1) / 2
/// unorm8 (8-15), cuticle angle / 20 degrees snorm8 (16-23), scatter unorm8 (24-31).
std::uint32_t quantizeHair(const std::array<double, 4>& hair, double dither);
std::array<double, 4> dequantizeHair(std::uint32_t code);

/// Iris (32 bits): the iris plane's normal octahedral 2 x unorm8 (x bits 0-7,
/// y 8-15), iris mask unorm8 (16-23), iris distance unorm8 (24-31). The iris
/// normal is a field of its own, as a basis normal (quantizeNormal).
std::uint32_t quantizeIris(const Vec3d& planeNormal, const std::array<double, 2>& iris, double dither);
void dequantizeIris(std::uint32_t code, Vec3d& planeNormal, std::array<double, 2>& iris);

/// Colour (20 bits): sqrt(saturate(c)) as unorm 7/7/6, r in bits 0-6, g 7-13, b 14-19.
std::uint32_t quantizeColor(const Vec3d& c, double dither);
Vec3d dequantizeColor(std::uint32_t code);

/// One MFP channel (8 bits): 0 for mfp <= 0 (no medium), else
/// clamp(floor(255·(log2(mfp) + 24)/32 + u), 1, 255).
std::uint32_t quantizeMfp(double mfp, double dither);
double dequantizeMfp(std::uint32_t code);
/// SSS (28 bits): MFP r, g, b (8 each, bits 0-23) then phase anisotropy snorm4 (bits 24-27).
std::uint32_t quantizeSss(const Vec3d& mfp, double phaseAnisotropy, double dither);
void dequantizeSss(std::uint32_t code, Vec3d& mfp, double& phaseAnisotropy);

/// IEEE half, round to nearest even, clamped to ±65504 (NaN -> 0).
std::uint16_t floatToHalf(double x);
double halfToFloat(std::uint16_t h);

// ---- Directions --------------------------------------------------------------

/// Octahedral projection to [-1, 1]^2 and back (the inverse normalizes).
std::array<double, 2> octProject(const Vec3d& n);
Vec3d octUnproject(const std::array<double, 2>& p);
/// Octahedral codes: snorm (basis normals) or unorm of (p + 1)/2 (top-layer word).
std::array<std::uint32_t, 2> octEncodeSnorm(const Vec3d& n, int bits, double dither);
Vec3d octDecodeSnorm(const std::array<std::uint32_t, 2>& code, int bits);
std::array<std::uint32_t, 2> octEncodeUnorm(const Vec3d& n, int bits, double dither);
Vec3d octDecodeUnorm(const std::array<std::uint32_t, 2>& code, int bits);

/// Basis normal (32 bits): octahedral x snorm16 in bits 0-15, y in bits 16-31.
std::uint32_t quantizeNormal(const Vec3d& n, double dither);
Vec3d dequantizeNormal(std::uint32_t code);

/// The canonical frame of a unit normal (Duff et al. 2017; the frame of the
/// runtime's substrate_orthonormal_basis and of the compiler's
/// rotationToTangent): s = copysign(1, z) (-0 counts as negative), a = -1/(s + z),
/// b = x·y·a, T0 = (1 + s·x²·a, s·b, -s·x), B0 = (b, s + y²·a, -y).
void orthonormalBasis(const Vec3d& n, Vec3d& t0, Vec3d& b0);
/// Tangent angle (14 bits): unorm14 of atan2(T·B0, T·T0)/2π in [0, 1), in the
/// frame of `n`; pass the normal as the unpacker will decode it.
std::uint32_t encodeTangentAngle(const Vec3d& tangent, const Vec3d& n, double dither);
Vec3d decodeTangentAngle(std::uint32_t code, const Vec3d& n);

/// Top-layer word: octahedral normal 2 x unorm12 (x bits 0-11, y 12-23), roughness unorm8 (24-31).
std::uint32_t packTopLayer(const TopLayerValues& top, double dither);
TopLayerValues unpackTopLayer(std::uint32_t word);

// ---- Bit stream --------------------------------------------------------------

/// Reads `bits` (0..32) bits at stream bit `offset` (little-endian stream; may
/// straddle two words). Throws std::out_of_range past `count` words.
std::uint32_t readBits(const std::uint32_t* words, std::size_t count, std::size_t offset, int bits);
/// ORs `value` (masked to `bits`) into the stream at `offset` (words must be large enough).
void writeBits(std::vector<std::uint32_t>& words, std::size_t offset, int bits, std::uint32_t value);

// ---- Materials ---------------------------------------------------------------

/// Header feature bits of a closure of a layout (kClosure*, with the weight and
/// coverage-above flags).
std::uint32_t closureHeaderFeatures(const ClosureLayout& c);

/// Packs one pixel: exactly the fields of `layout.fields`, in order, into
/// layout.words() words. The structure (features, flags, basis, is-top) comes
/// from the layout; `closures` (one per layout closure) and `bases` (at least
/// layout.basisCount) supply the values. A closure storing SSS writes its
/// values' sssType (Diffusion when that is None). When basis 0's normal is
/// elided, pack the top-layer word from bases[0].normal with the same dither:
/// the tangent angle is encoded in the frame of that decoded normal.
/// Throws std::invalid_argument on a layout the format cannot express
/// (more than 8 closures or bases, mismatched sizes, unknown fields).
std::vector<std::uint32_t> packMaterial(const StorageLayout& layout, const std::vector<ClosureValues>& closures,
                                        const std::vector<BasisValues>& bases, double dither);

/// Dynamic simplification as the generated pack function decides it
/// (storage/layout.h, runtimeSimpleClosures): the closure of `layout` left
/// alone at this pixel with nothing it stores in use (every other weight
/// <= 0, its own weight >= 1 when stored, coverage above <= 0 when stored,
/// F90 >= 1, anisotropy 0, MFP <= 0, haze weight and fuzz amount <= 0, glint
/// value >= 1), whose SIMPLE layout (simpleLayoutOf) the base pass then
/// packs; nullopt to pack `layout` itself.
std::optional<int> runtimeSimpleClosure(const Material& m, const StorageLayout& layout,
                                        const std::vector<ClosureValues>& closures);

struct UnpackedMaterial {
  LayoutClass cls = LayoutClass::Simple;
  std::vector<ClosureValues> closures;  // unstored fields hold their neutral values
  std::vector<BasisValues> bases;       // decoded normal and tangent (the canonical T0 if not stored)
  TopLayerValues topLayer;
  /// The layout read back from the headers: class, closures (basis, isTop,
  /// flags, storedFeatures in Feature bits; slab = -1), basis count, normal
  /// elision, and the field list (names and bits as computeLayout makes them,
  /// encodings left empty), totalBits.
  StorageLayout layout;
};

/// Generic unpacking from the stream alone (the header, then the closure
/// headers, decide every field). For a single closure, and for basis 0 when
/// every top closure uses it, the normal is the top-layer word's.
/// Throws std::runtime_error on a malformed stream (too short, bad ids).
UnpackedMaterial unpackMaterial(const std::uint32_t* words, std::size_t count, std::uint32_t topLayer);

}  // namespace substratec
