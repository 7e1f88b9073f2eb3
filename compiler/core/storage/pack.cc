#include "storage/pack.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace substratec {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;

double clampDither(double u) {
  if (!(u >= 0)) return 0;  // also NaN
  return std::min(u, std::nextafter(1.0, 0.0));
}

double saturate(double x) {
  if (!(x > 0)) return 0;  // also NaN
  return std::min(x, 1.0);
}

double signNotZero(double x) { return x >= 0 ? 1.0 : -1.0; }

double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Vec3d normalized(const Vec3d& v) {
  double l = std::sqrt(dot(v, v));
  if (!(l > 0)) return {0, 0, 1};
  return {v[0] / l, v[1] / l, v[2] / l};
}

std::uint32_t mask(int bits) { return bits >= 32 ? 0xffffffffu : ((1u << bits) - 1u); }

}  // namespace

// ---- Scalars -----------------------------------------------------------------

std::uint32_t quantizeUnorm(double x, int bits, double dither) {
  const double n = static_cast<double>(mask(bits));
  const double f = std::floor(saturate(x) * n + clampDither(dither));
  return static_cast<std::uint32_t>(std::clamp(f, 0.0, n));
}

double dequantizeUnorm(std::uint32_t code, int bits) {
  return static_cast<double>(code & mask(bits)) / static_cast<double>(mask(bits));
}

std::uint32_t quantizeSnorm(double x, int bits, double dither) {
  const double s = static_cast<double>(mask(bits - 1));
  const double v = x >= -1 ? std::min(x, 1.0) : (x < -1 ? -1.0 : 0.0);  // NaN -> 0
  const double f = std::floor(v * s + s + clampDither(dither));
  return static_cast<std::uint32_t>(std::clamp(f, 0.0, 2 * s));
}

double dequantizeSnorm(std::uint32_t code, int bits) {
  const double s = static_cast<double>(mask(bits - 1));
  return std::clamp(static_cast<double>(code & mask(bits)) / s - 1.0, -1.0, 1.0);
}

std::uint32_t quantizeColor(const Vec3d& c, double dither) {
  const std::uint32_t r = quantizeUnorm(std::sqrt(saturate(c[0])), 7, dither);
  const std::uint32_t g = quantizeUnorm(std::sqrt(saturate(c[1])), 7, dither);
  const std::uint32_t b = quantizeUnorm(std::sqrt(saturate(c[2])), 6, dither);
  return r | (g << 7) | (b << 14);
}

Vec3d dequantizeColor(std::uint32_t code) {
  const double r = dequantizeUnorm(code & 0x7fu, 7);
  const double g = dequantizeUnorm((code >> 7) & 0x7fu, 7);
  const double b = dequantizeUnorm((code >> 14) & 0x3fu, 6);
  return {r * r, g * g, b * b};
}

std::uint32_t quantizeMfp(double mfp, double dither) {
  if (!(mfp > 0)) return 0;  // no medium (also NaN)
  const double t = std::clamp((std::log2(mfp) - packfmt::kMfpLog2Min) / packfmt::kMfpLog2Range, 0.0, 1.0);
  const double f = std::floor(t * 255.0 + clampDither(dither));
  return static_cast<std::uint32_t>(std::clamp(f, 1.0, 255.0));
}

double dequantizeMfp(std::uint32_t code) {
  code &= 0xffu;
  if (code == 0) return 0;
  return std::exp2(static_cast<double>(code) * packfmt::kMfpLog2Range / 255.0 + packfmt::kMfpLog2Min);
}

std::uint32_t quantizeSss(const Vec3d& mfp, double phaseAnisotropy, double dither) {
  return quantizeMfp(mfp[0], dither) | (quantizeMfp(mfp[1], dither) << 8) | (quantizeMfp(mfp[2], dither) << 16) |
         (quantizeSnorm(phaseAnisotropy, 4, dither) << 24);
}

void dequantizeSss(std::uint32_t code, Vec3d& mfp, double& phaseAnisotropy) {
  mfp = {dequantizeMfp(code & 0xffu), dequantizeMfp((code >> 8) & 0xffu), dequantizeMfp((code >> 16) & 0xffu)};
  phaseAnisotropy = dequantizeSnorm((code >> 24) & 0xfu, 4);
}

std::uint16_t floatToHalf(double x) {
  if (std::isnan(x)) x = 0;
  x = std::clamp(x, -packfmt::kHalfMax, packfmt::kHalfMax);
  const std::uint32_t f = std::bit_cast<std::uint32_t>(static_cast<float>(x));
  const std::uint32_t sign = (f >> 16) & 0x8000u;
  const std::uint32_t a = f & 0x7fffffffu;
  if (a < 0x38800000u) {  // below 2^-14: a half subnormal (or zero), in units of 2^-24
    const double m = std::nearbyint(static_cast<double>(std::bit_cast<float>(a)) * 16777216.0);
    return static_cast<std::uint16_t>(sign | static_cast<std::uint32_t>(m));  // 1024 is the smallest normal
  }
  const std::uint32_t exponent = (a >> 23) - 127u + 15u;
  const std::uint32_t mantissa = a & 0x7fffffu;
  std::uint32_t h = (exponent << 10) | (mantissa >> 13);
  const std::uint32_t rest = mantissa & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;  // a carry moves into the exponent
  return static_cast<std::uint16_t>(sign | h);
}

double halfToFloat(std::uint16_t h) {
  const double sign = (h & 0x8000u) ? -1.0 : 1.0;
  const int exponent = (h >> 10) & 0x1f;
  const int mantissa = h & 0x3ff;
  if (exponent == 0) return sign * std::ldexp(mantissa, -24);
  if (exponent == 31) return mantissa ? std::nan("") : sign * INFINITY;
  return sign * std::ldexp(1024 + mantissa, exponent - 25);
}

// ---- Directions --------------------------------------------------------------

std::array<double, 2> octProject(const Vec3d& n) {
  const double l1 = std::abs(n[0]) + std::abs(n[1]) + std::abs(n[2]);
  if (!(l1 > 0) || !std::isfinite(l1)) return {0, 0};
  double px = n[0] / l1, py = n[1] / l1;
  if (n[2] < 0) {
    const double ox = (1 - std::abs(py)) * signNotZero(px);
    const double oy = (1 - std::abs(px)) * signNotZero(py);
    px = ox;
    py = oy;
  }
  return {px, py};
}

Vec3d octUnproject(const std::array<double, 2>& p) {
  Vec3d n{p[0], p[1], 1 - std::abs(p[0]) - std::abs(p[1])};
  if (n[2] < 0) {
    const double ox = (1 - std::abs(n[1])) * signNotZero(n[0]);
    const double oy = (1 - std::abs(n[0])) * signNotZero(n[1]);
    n[0] = ox;
    n[1] = oy;
  }
  return normalized(n);
}

std::array<std::uint32_t, 2> octEncodeSnorm(const Vec3d& n, int bits, double dither) {
  const auto p = octProject(n);
  return {quantizeSnorm(p[0], bits, dither), quantizeSnorm(p[1], bits, dither)};
}

Vec3d octDecodeSnorm(const std::array<std::uint32_t, 2>& code, int bits) {
  return octUnproject({dequantizeSnorm(code[0], bits), dequantizeSnorm(code[1], bits)});
}

std::array<std::uint32_t, 2> octEncodeUnorm(const Vec3d& n, int bits, double dither) {
  const auto p = octProject(n);
  return {quantizeUnorm(p[0] * 0.5 + 0.5, bits, dither), quantizeUnorm(p[1] * 0.5 + 0.5, bits, dither)};
}

Vec3d octDecodeUnorm(const std::array<std::uint32_t, 2>& code, int bits) {
  return octUnproject({dequantizeUnorm(code[0], bits) * 2 - 1, dequantizeUnorm(code[1], bits) * 2 - 1});
}

std::uint32_t quantizeNormal(const Vec3d& n, double dither) {
  const auto c = octEncodeSnorm(n, 16, dither);
  return c[0] | (c[1] << 16);
}

Vec3d dequantizeNormal(std::uint32_t code) { return octDecodeSnorm({code & 0xffffu, code >> 16}, 16); }

void orthonormalBasis(const Vec3d& n, Vec3d& t0, Vec3d& b0) {
  const double s = std::copysign(1.0, n[2]);  // -0 counts as negative, like rotationToTangent
  const double a = -1.0 / (s + n[2]);
  const double b = n[0] * n[1] * a;
  t0 = {1 + s * n[0] * n[0] * a, s * b, -s * n[0]};
  b0 = {b, s + n[1] * n[1] * a, -n[1]};
}

std::uint32_t encodeTangentAngle(const Vec3d& tangent, const Vec3d& n, double dither) {
  Vec3d t0, b0;
  orthonormalBasis(n, t0, b0);
  const double y = dot(tangent, b0), x = dot(tangent, t0);
  double angle = (std::isfinite(x) && std::isfinite(y)) ? std::atan2(y, x) : 0.0;
  if (angle < 0) angle += kTwoPi;
  return quantizeUnorm(angle / kTwoPi, bits::kTangentAngle, dither);
}

Vec3d decodeTangentAngle(std::uint32_t code, const Vec3d& n) {
  Vec3d t0, b0;
  orthonormalBasis(n, t0, b0);
  const double angle = dequantizeUnorm(code, bits::kTangentAngle) * kTwoPi;
  const double c = std::cos(angle), s = std::sin(angle);
  return normalized({c * t0[0] + s * b0[0], c * t0[1] + s * b0[1], c * t0[2] + s * b0[2]});
}

std::uint32_t packTopLayer(const TopLayerValues& top, double dither) {
  const auto c = octEncodeUnorm(top.normal, 12, dither);
  return c[0] | (c[1] << 12) | (quantizeUnorm(top.roughness, 8, dither) << 24);
}

TopLayerValues unpackTopLayer(std::uint32_t word) {
  TopLayerValues t;
  t.normal = octDecodeUnorm({word & 0xfffu, (word >> 12) & 0xfffu}, 12);
  t.roughness = dequantizeUnorm(word >> 24, 8);
  return t;
}

// ---- Bit stream --------------------------------------------------------------

std::uint32_t readBits(const std::uint32_t* words, std::size_t count, std::size_t offset, int bits) {
  if (bits < 0 || bits > 32) throw std::out_of_range("readBits: width must be 0..32");
  if (bits == 0) return 0;
  if (offset + static_cast<std::size_t>(bits) > count * 32) throw std::out_of_range("readBits: past the stream");
  const std::size_t w = offset / 32;
  const unsigned s = static_cast<unsigned>(offset % 32);
  std::uint64_t v = words[w] >> s;
  if (s + static_cast<unsigned>(bits) > 32) v |= static_cast<std::uint64_t>(words[w + 1]) << (32 - s);
  return static_cast<std::uint32_t>(v) & mask(bits);
}

void writeBits(std::vector<std::uint32_t>& words, std::size_t offset, int bits, std::uint32_t value) {
  if (bits < 0 || bits > 32) throw std::out_of_range("writeBits: width must be 0..32");
  if (bits == 0) return;
  if (offset + static_cast<std::size_t>(bits) > words.size() * 32) throw std::out_of_range("writeBits: past the stream");
  const std::uint64_t v = static_cast<std::uint64_t>(value & mask(bits)) << (offset % 32);
  const std::size_t w = offset / 32;
  words[w] |= static_cast<std::uint32_t>(v);
  if ((offset % 32) + static_cast<std::size_t>(bits) > 32) words[w + 1] |= static_cast<std::uint32_t>(v >> 32);
}

// ---- Materials ---------------------------------------------------------------

std::uint32_t quantizeHair(const std::array<double, 4>& h, double dither) {
  return quantizeUnorm(h[0], 8, dither) | (quantizeUnorm((h[1] - 1.0) / 2.0, 8, dither) << 8) |
         (quantizeSnorm(h[2] / 20.0, 8, dither) << 16) | (quantizeUnorm(h[3], 8, dither) << 24);
}

std::array<double, 4> dequantizeHair(std::uint32_t code) {
  return {dequantizeUnorm(code & 0xffu, 8), 1.0 + 2.0 * dequantizeUnorm((code >> 8) & 0xffu, 8),
          20.0 * dequantizeSnorm((code >> 16) & 0xffu, 8), dequantizeUnorm(code >> 24, 8)};
}

std::uint32_t quantizeIris(const Vec3d& planeNormal, const std::array<double, 2>& iris, double dither) {
  const auto o = octEncodeUnorm(planeNormal, 8, dither);
  return o[0] | (o[1] << 8) | (quantizeUnorm(iris[0], 8, dither) << 16) | (quantizeUnorm(iris[1], 8, dither) << 24);
}

void dequantizeIris(std::uint32_t code, Vec3d& planeNormal, std::array<double, 2>& iris) {
  planeNormal = octDecodeUnorm({code & 0xffu, (code >> 8) & 0xffu}, 8);
  iris = {dequantizeUnorm((code >> 16) & 0xffu, 8), dequantizeUnorm(code >> 24, 8)};
}

std::uint32_t closureHeaderFeatures(const ClosureLayout& c) {
  std::uint32_t f = 0;
  if (c.storedFeatures & kFeatF90) f |= kClosureF90;
  if (c.storedFeatures & kFeatAnisotropy) f |= kClosureAnisotropy;
  if (c.storedFeatures & kFeatHaze) f |= kClosureHaze;
  if (c.storedFeatures & kFeatFuzz) f |= kClosureFuzz;
  if (c.storedFeatures & kFeatGlint) f |= kClosureGlint;
  if (c.storedFeatures & kFeatSpecularProfile) f |= kClosureSpecularProfile;
  if (c.storesWeight) f |= kClosureWeight;
  if (c.storesCoverageAbove) f |= kClosureCoverageAbove;
  if (c.storedFeatures & kFeatHair) f |= kClosureHair;  // beyond the 8 header bits: single-closure header bit 12
  if (c.storedFeatures & kFeatEye) f |= kClosureEye;    // and bit 13
  return f;
}

namespace {

std::uint16_t featuresFromHeader(std::uint32_t f, std::uint32_t sssType) {
  std::uint16_t s = 0;
  if (f & kClosureHair) s |= kFeatHair;
  if (f & kClosureEye) s |= kFeatEye;
  if (f & kClosureF90) s |= kFeatF90;
  if (f & kClosureAnisotropy) s |= kFeatAnisotropy;
  if (f & kClosureHaze) s |= kFeatHaze;
  if (f & kClosureFuzz) s |= kFeatFuzz;
  if (f & kClosureGlint) s |= kFeatGlint;
  if (f & kClosureSpecularProfile) s |= kFeatSpecularProfile;
  if (sssType != kSssTypeNone) s |= kFeatSss;
  return s;
}

std::uint32_t headerSssType(const ClosureLayout& c, const ClosureValues& v) {
  if (!(c.storedFeatures & kFeatSss)) return kSssTypeNone;
  return (v.sssType >= 1 && v.sssType <= 3) ? v.sssType : kSssTypeDiffusion;
}

std::uint32_t classBits(LayoutClass c) { return static_cast<std::uint32_t>(c); }

std::string_view fieldSuffix(const std::string& name) {
  const auto dot = name.find('.');
  return dot == std::string::npos ? std::string_view(name) : std::string_view(name).substr(dot + 1);
}

void expectBits(const LayoutField& f, int bits) {
  if (f.bits != bits)
    throw std::invalid_argument(fmt::format("packMaterial: field '{}' has {} bits, the format says {}", f.name, f.bits, bits));
}

/// The glint field (136 bits) as five parts: density (8), uv.x, uv.y, then two
/// words of two halves (d(u)/dx | d(v)/dx << 16, d(u)/dy | d(v)/dy << 16).
void writeGlint(std::vector<std::uint32_t>& w, std::size_t& pos, const ClosureValues& v, double dither) {
  auto put = [&](int n, std::uint32_t x) { writeBits(w, pos, n, x); pos += static_cast<std::size_t>(n); };
  put(8, quantizeUnorm(v.glintValue, 8, dither));
  put(32, std::bit_cast<std::uint32_t>(static_cast<float>(v.glintUv[0])));
  put(32, std::bit_cast<std::uint32_t>(static_cast<float>(v.glintUv[1])));
  const auto& d = v.glintUvDerivatives;
  put(32, floatToHalf(d[0]) | (static_cast<std::uint32_t>(floatToHalf(d[1])) << 16));
  put(32, floatToHalf(d[2]) | (static_cast<std::uint32_t>(floatToHalf(d[3])) << 16));
}

/// Throws std::invalid_argument unless the layout and the values can be packed.
void checkPackArguments(const StorageLayout& layout, const std::vector<ClosureValues>& closures,
                        const std::vector<BasisValues>& bases) {
  const int count = static_cast<int>(layout.closures.size());
  if (count < 0 || count > packfmt::kMaxClosures)
    throw std::invalid_argument(fmt::format("packMaterial: {} closures (the format holds 0 to 8)", count));
  if (static_cast<int>(closures.size()) != count)
    throw std::invalid_argument("packMaterial: one ClosureValues per layout closure");
  if (count == 0) {  // an unlit material: the header alone
    if (layout.basisCount != 0) throw std::invalid_argument("packMaterial: no closure, so no basis");
    return;
  }
  const bool multi = count > 1;
  if (layout.basisCount < 1 || layout.basisCount > packfmt::kMaxBases)
    throw std::invalid_argument(fmt::format("packMaterial: {} bases (the format holds 1 to 8)", layout.basisCount));
  if (!multi && (layout.basisCount != 1 || layout.closures[0].basis != 0))
    throw std::invalid_argument("packMaterial: a single closure must use basis 0, the only basis");
  if (!multi && layout.closures[0].extraInterfaces != 0)
    throw std::invalid_argument("packMaterial: a single closure is on top (its header holds no extra interfaces)");
  if (static_cast<int>(bases.size()) < layout.basisCount)
    throw std::invalid_argument("packMaterial: fewer BasisValues than layout bases");
  for (const auto& c : layout.closures)
    if (c.basis < 0 || c.basis >= layout.basisCount) throw std::invalid_argument("packMaterial: closure basis out of range");
}

/// A closure field of plain bits: its name (after "closureN."), width and encoding.
struct PackedClosureField {
  std::string_view name;
  int bits;
  std::uint32_t (*encode)(const ClosureValues& v, double dither);
};

const PackedClosureField kPackedClosureFields[] = {
    {"diffuse_albedo", bits::kColor, [](const ClosureValues& v, double d) { return quantizeColor(v.diffuseAlbedo, d); }},
    {"f0", bits::kColor, [](const ClosureValues& v, double d) { return quantizeColor(v.f0, d); }},
    {"hair", bits::kHair, [](const ClosureValues& v, double d) { return quantizeHair(v.hair, d); }},
    {"iris_normal", bits::kIrisNormal, [](const ClosureValues& v, double d) { return quantizeNormal(v.irisN, d); }},
    {"iris", bits::kIris, [](const ClosureValues& v, double d) { return quantizeIris(v.irisPlaneN, v.iris, d); }},
    {"roughness", bits::kRoughness, [](const ClosureValues& v, double d) { return quantizeUnorm(v.roughness, 8, d); }},
    {"weight", bits::kGreyWeight, [](const ClosureValues& v, double d) { return quantizeUnorm(v.weight, 8, d); }},
    {"top_transmittance", bits::kColor,
     [](const ClosureValues& v, double d) { return quantizeColor(v.topTransmittance, d); }},
    {"coverage_above", bits::kCoverageAbove,
     [](const ClosureValues& v, double d) { return quantizeUnorm(v.coverageAbove, 8, d); }},
    {"f90", bits::kColor, [](const ClosureValues& v, double d) { return quantizeColor(v.f90, d); }},
    {"sss", bits::kSss, [](const ClosureValues& v, double d) { return quantizeSss(v.sssMfp, v.sssPhaseAnisotropy, d); }},
    {"haze", bits::kHaze,
     [](const ClosureValues& v, double d) {
       return quantizeUnorm(v.secondRoughness, 8, d) | (quantizeUnorm(v.secondRoughnessWeight, 8, d) << 8);
     }},
    {"fuzz", bits::kFuzz,
     [](const ClosureValues& v, double d) {
       return quantizeUnorm(v.fuzzAmount, 6, d) | (quantizeColor(v.fuzzColor, d) << 6) |
              (quantizeUnorm(v.fuzzRoughness, 6, d) << 26);
     }},
    {"anisotropy", bits::kAnisotropy, [](const ClosureValues& v, double d) { return quantizeSnorm(v.anisotropy, 8, d); }},
    {"specular_profile", bits::kSpecularProfile,
     [](const ClosureValues& v, double) {
       return v.specularProfile == 0 ? 0u : std::min<std::uint32_t>(v.specularProfile - 1, 255u);
     }},
};

/// The plain closure field `f` names (its width checked); throws for an unknown one.
const PackedClosureField& packedClosureField(const LayoutField& f) {
  const std::string_view what = fieldSuffix(f.name);
  for (const PackedClosureField& pf : kPackedClosureFields)
    if (pf.name == what) {
      expectBits(f, pf.bits);
      return pf;
    }
  throw std::invalid_argument(fmt::format("packMaterial: unknown field '{}'", f.name));
}

/// A closure's header (several closures): basis, top, features, SSS type, extra interfaces.
template <class Put>
void putClosureHeader(const LayoutField& f, const ClosureLayout& c, const ClosureValues& v, Put& put) {
  expectBits(f, bits::kClosureHeader);
  if (c.extraInterfaces < 0 || c.extraInterfaces > kMaxStoredExtraInterfaces)
    throw std::invalid_argument(fmt::format("packMaterial: closure {} has {} extra interfaces (0 to 3)",
                                            f.closure, c.extraInterfaces));
  std::uint32_t h = static_cast<std::uint32_t>(c.basis) | (c.isTop ? 8u : 0u);
  h |= (closureHeaderFeatures(c) & 0xffu) << 4;
  h |= headerSssType(c, v) << 12;
  h |= static_cast<std::uint32_t>(c.extraInterfaces) << 14;
  put(bits::kClosureHeader, h);
}

}  // namespace

std::vector<std::uint32_t> packMaterial(const StorageLayout& layout, const std::vector<ClosureValues>& closures,
                                        const std::vector<BasisValues>& bases, double dither) {
  checkPackArguments(layout, closures, bases);
  const int count = static_cast<int>(layout.closures.size());
  const bool multi = count > 1;

  // The normal of each basis as the unpacker will see it (tangent angles are
  // measured in its frame).
  auto decodedNormal = [&](int b) -> Vec3d {
    const bool elided = !multi || (b == 0 && layout.basis0NormalElided);
    if (elided) return unpackTopLayer(packTopLayer({bases[0].normal, 0.0}, dither)).normal;
    return dequantizeNormal(quantizeNormal(bases[b].normal, dither));
  };

  std::vector<std::uint32_t> words(static_cast<std::size_t>(layout.words()), 0u);
  std::size_t pos = 0;
  auto put = [&](int n, std::uint32_t x) { writeBits(words, pos, n, x); pos += static_cast<std::size_t>(n); };

  for (const LayoutField& f : layout.fields) {
    const std::string_view what = fieldSuffix(f.name);
    if (f.closure < 0 && f.basis < 0) {
      if (what != "header") throw std::invalid_argument(fmt::format("packMaterial: unknown field '{}'", f.name));
      expectBits(f, bits::kHeader);
      std::uint32_t h = classBits(layout.layoutClass);
      if (count == 0) {
        h |= packfmt::kNoClosureHeaderBit;  // an unlit material: nothing to light
      } else if (multi) {
        h |= static_cast<std::uint32_t>(count - 1) << 2;
        h |= static_cast<std::uint32_t>(layout.basisCount) << 5;
        h |= packfmt::kMultiClosureHeaderBit;
      } else {
        h |= (closureHeaderFeatures(layout.closures[0]) & 0x7fu) << 2;
        h |= headerSssType(layout.closures[0], closures[0]) << 10;
        if (layout.closures[0].storedFeatures & kFeatHair) h |= packfmt::kHairHeaderBit;
        if (layout.closures[0].storedFeatures & kFeatEye) h |= packfmt::kEyeHeaderBit;
      }
      put(16, h);
      continue;
    }
    if (f.closure >= 0) {
      if (f.closure >= count) throw std::invalid_argument(fmt::format("packMaterial: field '{}' names no closure", f.name));
      const ClosureLayout& c = layout.closures[f.closure];
      const ClosureValues& v = closures[f.closure];
      if (what == "header") putClosureHeader(f, c, v, put);
      else if (what == "glint") {
        expectBits(f, bits::kGlint);
        writeGlint(words, pos, v, dither);
      } else {
        const PackedClosureField& pf = packedClosureField(f);
        put(pf.bits, pf.encode(v, dither));
      }
      continue;
    }
    if (f.basis >= layout.basisCount) throw std::invalid_argument(fmt::format("packMaterial: field '{}' names no basis", f.name));
    if (what == "normal") {
      expectBits(f, bits::kNormal);
      put(32, quantizeNormal(bases[f.basis].normal, dither));
    } else if (what == "tangent_angle") {
      expectBits(f, bits::kTangentAngle);
      put(14, encodeTangentAngle(bases[f.basis].tangent, decodedNormal(f.basis), dither));
    } else {
      throw std::invalid_argument(fmt::format("packMaterial: unknown field '{}'", f.name));
    }
  }
  if (static_cast<int>(pos) != layout.totalBits)
    throw std::invalid_argument(fmt::format("packMaterial: wrote {} bits, the layout totals {}", pos, layout.totalBits));
  return words;
}

std::optional<int> runtimeSimpleClosure(const Material& m, const StorageLayout& layout,
                                        const std::vector<ClosureValues>& closures) {
  for (int k : runtimeSimpleClosures(m, layout)) {
    const ClosureLayout& c = layout.closures[k];
    const ClosureValues& v = closures.at(k);
    bool plain = true;
    for (std::size_t j = 0; j < closures.size(); ++j)
      if (static_cast<int>(j) != k && closures[j].weight > 0) plain = false;
    if (c.storesWeight && !(v.weight >= 1)) plain = false;
    if (c.storesCoverageAbove && v.coverageAbove > 0) plain = false;
    const std::uint16_t f = c.storedFeatures;
    if ((f & kFeatF90) && !(std::min({v.f90[0], v.f90[1], v.f90[2]}) >= 1)) plain = false;
    if ((f & kFeatAnisotropy) && v.anisotropy != 0) plain = false;
    if ((f & kFeatSss) && std::max({v.sssMfp[0], v.sssMfp[1], v.sssMfp[2]}) > 0) plain = false;
    if ((f & kFeatHaze) && v.secondRoughnessWeight > 0) plain = false;
    if ((f & kFeatFuzz) && v.fuzzAmount > 0) plain = false;
    if ((f & kFeatGlint) && !(v.glintValue >= 1)) plain = false;
    if (plain) return k;
  }
  return std::nullopt;
}

namespace {

/// The cursor of unpackMaterial over the stream: each field read is recorded
/// in the layout it rebuilds.
struct FieldReader {
  const std::uint32_t* words;
  std::size_t count;
  StorageLayout& L;
  std::size_t pos = 0;

  /// Records a field of `n` bits at the cursor and returns its start.
  std::size_t take(std::string name, int n, int closure = -1, int basis = -1) {
    if (pos + static_cast<std::size_t>(n) > count * 32)
      throw std::runtime_error(fmt::format("unpackMaterial: field '{}' runs past the {} words of the stream", name, count));
    const std::size_t start = pos;
    pos += static_cast<std::size_t>(n);
    L.fields.push_back({std::move(name), n, std::string(), closure, basis});
    L.totalBits += n;
    return start;
  }
  std::uint32_t field(std::string name, int n, int closure = -1, int basis = -1) {
    return readBits(words, count, take(std::move(name), n, closure, basis), n);
  }
};

/// Closure i's layout from its header (several closures) or the material header (one).
ClosureLayout unpackClosureHeader(FieldReader& r, int i, std::uint32_t header, bool multi, int basisCount,
                                  std::uint32_t& feats, std::uint32_t& sss) {
  ClosureLayout c;
  if (multi) {
    const std::uint32_t h = r.field(fmt::format("closure{}.", i) + "header", bits::kClosureHeader, i);
    c.basis = static_cast<int>(h & 7u);
    c.isTop = (h >> 3) & 1u;
    feats = (h >> 4) & 0xffu;
    sss = (h >> 12) & 3u;
    c.extraInterfaces = static_cast<int>((h >> 14) & 3u);
    if (c.basis >= basisCount)
      throw std::runtime_error(fmt::format("unpackMaterial: closure {} uses basis {} of {}", i, c.basis, basisCount));
  } else {
    c.basis = 0;
    c.isTop = true;
    feats = (header >> 2) & 0x7fu;
    sss = (header >> 10) & 3u;
    if (header & packfmt::kHairHeaderBit) feats |= kClosureHair;
    if (header & packfmt::kEyeHeaderBit) feats |= kClosureEye;
  }
  c.storesWeight = feats & kClosureWeight;
  c.storesCoverageAbove = feats & kClosureCoverageAbove;
  c.storedFeatures = featuresFromHeader(feats, sss);
  return c;
}

/// The glint field (writeGlint's parts) starting at bit `start`.
void unpackGlint(const std::uint32_t* words, std::size_t count, std::size_t start, ClosureValues& v) {
  auto part = [&](std::size_t off, int n) { return readBits(words, count, start + off, n); };
  v.glintValue = dequantizeUnorm(part(0, 8), 8);
  v.glintUv = {std::bit_cast<float>(part(8, 32)), std::bit_cast<float>(part(40, 32))};
  const std::uint32_t dx = part(72, 32), dy = part(104, 32);
  v.glintUvDerivatives = {halfToFloat(static_cast<std::uint16_t>(dx & 0xffffu)),
                          halfToFloat(static_cast<std::uint16_t>(dx >> 16)),
                          halfToFloat(static_cast<std::uint16_t>(dy & 0xffffu)),
                          halfToFloat(static_cast<std::uint16_t>(dy >> 16))};
}

/// Closure i's values: its header, then each field its features store.
void unpackClosure(FieldReader& r, int i, std::uint32_t header, bool multi, int basisCount, UnpackedMaterial& out) {
  const std::string p = fmt::format("closure{}.", i);
  std::uint32_t feats = 0, sss = 0;
  const ClosureLayout c = unpackClosureHeader(r, i, header, multi, basisCount, feats, sss);
  ClosureValues v;
  v.features = feats;
  v.isTop = c.isTop;
  v.basis = c.basis;
  v.sssType = sss;
  v.extraInterfaces = static_cast<std::uint32_t>(c.extraInterfaces);
  if (!c.isTop) v.coverageAbove = 1;  // below layers of static coverage 1 unless stored

  v.diffuseAlbedo = dequantizeColor(r.field(p + "diffuse_albedo", bits::kColor, i));
  if (feats & kClosureHair) {
    v.hair = dequantizeHair(r.field(p + "hair", bits::kHair, i));
  } else if (feats & kClosureEye) {
    v.irisN = dequantizeNormal(r.field(p + "iris_normal", bits::kIrisNormal, i));
    dequantizeIris(r.field(p + "iris", bits::kIris, i), v.irisPlaneN, v.iris);
  } else {
    v.f0 = dequantizeColor(r.field(p + "f0", bits::kColor, i));
  }
  v.roughness = dequantizeUnorm(r.field(p + "roughness", bits::kRoughness, i), 8);
  if (c.storesWeight) v.weight = dequantizeUnorm(r.field(p + "weight", bits::kGreyWeight, i), 8);
  if (!c.isTop) v.topTransmittance = dequantizeColor(r.field(p + "top_transmittance", bits::kColor, i));
  if (c.storesCoverageAbove) v.coverageAbove = dequantizeUnorm(r.field(p + "coverage_above", bits::kCoverageAbove, i), 8);
  if (feats & kClosureF90) v.f90 = dequantizeColor(r.field(p + "f90", bits::kColor, i));
  if (sss != kSssTypeNone) dequantizeSss(r.field(p + "sss", bits::kSss, i), v.sssMfp, v.sssPhaseAnisotropy);
  if (feats & kClosureHaze) {
    const std::uint32_t h = r.field(p + "haze", bits::kHaze, i);
    v.secondRoughness = dequantizeUnorm(h & 0xffu, 8);
    v.secondRoughnessWeight = dequantizeUnorm(h >> 8, 8);
  }
  if (feats & kClosureFuzz) {
    const std::uint32_t z = r.field(p + "fuzz", bits::kFuzz, i);
    v.fuzzAmount = dequantizeUnorm(z & 0x3fu, 6);
    v.fuzzColor = dequantizeColor((z >> 6) & 0xfffffu);
    v.fuzzRoughness = dequantizeUnorm(z >> 26, 6);
  }
  if (feats & kClosureAnisotropy) v.anisotropy = dequantizeSnorm(r.field(p + "anisotropy", bits::kAnisotropy, i), 8);
  if (feats & kClosureSpecularProfile)
    v.specularProfile = r.field(p + "specular_profile", bits::kSpecularProfile, i) + 1;
  if (feats & kClosureGlint) unpackGlint(r.words, r.count, r.take(p + "glint", bits::kGlint, i), v);
  r.L.closures.push_back(c);
  out.closures.push_back(v);
}

}  // namespace

UnpackedMaterial unpackMaterial(const std::uint32_t* words, std::size_t count, std::uint32_t topLayer) {
  UnpackedMaterial out;
  StorageLayout& L = out.layout;
  FieldReader r{words, count, L};

  out.topLayer = unpackTopLayer(topLayer);
  const std::uint32_t header = r.field("header", bits::kHeader);
  out.cls = static_cast<LayoutClass>(header & 3u);
  L.layoutClass = out.cls;
  const bool multi = (header & packfmt::kMultiClosureHeaderBit) != 0;
  int closureCount = 1;
  int basisCount = 1;
  if (!multi && (header & packfmt::kNoClosureHeaderBit)) return out;  // an unlit pixel: no closure, no basis
  if (multi) {
    closureCount = static_cast<int>((header >> 2) & 7u) + 1;
    basisCount = static_cast<int>((header >> 5) & 15u);
    if (basisCount < 1 || basisCount > packfmt::kMaxBases)
      throw std::runtime_error(fmt::format("unpackMaterial: basis count {} (1 to 8)", basisCount));
  }
  L.basisCount = basisCount;
  for (int i = 0; i < closureCount; ++i) unpackClosure(r, i, header, multi, basisCount, out);

  bool topShare = true;
  for (const auto& c : L.closures)
    if (c.isTop && c.basis != 0) topShare = false;
  L.basis0NormalElided = topShare;
  for (int b = 0; b < basisCount; ++b) {
    const std::string p = fmt::format("basis{}.", b);
    bool anisotropic = false;
    for (const auto& c : L.closures)
      if (c.basis == b && (c.storedFeatures & kTangentFeatures)) anisotropic = true;
    const bool elided = !multi || (b == 0 && topShare);
    BasisValues bv;
    bv.normal = elided ? out.topLayer.normal : dequantizeNormal(r.field(p + "normal", bits::kNormal, -1, b));
    Vec3d b0;
    orthonormalBasis(bv.normal, bv.tangent, b0);
    if (anisotropic) bv.tangent = decodeTangentAngle(r.field(p + "tangent_angle", bits::kTangentAngle, -1, b), bv.normal);
    out.bases.push_back(bv);
  }
  return out;
}

}  // namespace substratec
