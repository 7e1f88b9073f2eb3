#include "ir/helper_math.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>

namespace substratec::helpers {
namespace {


/// Clamp that never returns NaN: NaN goes to `lo`, +-inf to the nearest bound.
double clampSafe(double x, double lo, double hi) { return x > lo ? (x < hi ? x : hi) : lo; }

double dot3(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/// Normalizes v; a zero or non-finite vector gives `fallback`. Scales by the
/// largest component first so that tiny (1e-300) and huge (1e300) vectors
/// normalize instead of under/overflowing in the squared length.
Vec3 normalizeOr(const Vec3& v, const Vec3& fallback) {
  for (double c : v)
    if (!std::isfinite(c)) return fallback;
  const double m = std::max({std::fabs(v[0]), std::fabs(v[1]), std::fabs(v[2])});
  if (!(m > 0.0)) return fallback;
  Vec3 s{v[0] / m, v[1] / m, v[2] / m};
  const double len = std::sqrt(dot3(s, s));  // in [1, sqrt(3)]
  return {s[0] / len, s[1] / len, s[2] / len};
}

// ---------------------------------------------------------------------------
// Haze (Barla et al. 2018), see the header.

constexpr double kHazeExtent = 3.0;  // alpha_h = (1 + L) alpha_c

// ---------------------------------------------------------------------------
// Transmittance to MFP.

constexpr double kMfpTransparent = 1e9;            // metres; "no extinction"
constexpr double kDefaultSurfaceThickness = 1e-4;  // metres; format default

// ---------------------------------------------------------------------------
// Thin film (Belcour & Barla 2017).

constexpr double kFilmIorMax = 5.0;
constexpr double kFilmThicknessMax = 1e-3;  // metres
constexpr double kBaseF0Max = 0.9999;       // keeps the base IOR finite
constexpr double kR123Max = 0.9999;         // keeps 1 / (1 - R12 R23) finite
constexpr int kAiryOrders = 2;

/// Belcour & Barla's fit of the CIE 1931 colour matching functions by
/// Gaussians in the optical-path-difference (Fourier) domain: the spectral
/// integral of cos(2 pi OPD / lambda + shift) against x, y, z. `opd` in metres.
/// Normalized so that Y(0, 0) ~ 1.
Vec3 xyzSensitivity(double opd, double shift) {
  // pos is a wavenumber (1 / wavelength, m^-1): pos * phase = 2 pi OPD / lambda.
  const double phase = 2.0 * std::numbers::pi * opd;
  struct Lobe {
    double val, pos, var;
  };
  // x, y, z main lobes, then the second (blue) lobe of x.
  static constexpr Lobe kLobes[4] = {{5.4856e-13, 1.6810e+06, 4.3278e+09},
                                     {4.4201e-13, 1.7953e+06, 9.3046e+09},
                                     {5.2481e-13, 2.2084e+06, 6.6121e+09},
                                     {9.7470e-14, 2.2399e+06, 4.5282e+09}};
  auto lobe = [&](const Lobe& l) {
    const double g = std::exp(-phase * phase * l.var);  // phase is bounded: no overflow
    if (g == 0.0) return 0.0;
    return l.val * std::sqrt(2.0 * std::numbers::pi * l.var) * std::cos(l.pos * phase + shift) * g;
  };
  constexpr double kNorm = 1.0685e-7;
  return {(lobe(kLobes[0]) + lobe(kLobes[3])) / kNorm, lobe(kLobes[1]) / kNorm, lobe(kLobes[2]) / kNorm};
}

/// CIE XYZ to linear Rec.709 (D65), one row per RGB channel.
constexpr double kXyzToRgb[3][3] = {{3.2404542, -1.5371385, -0.4985314},
                                    {-0.9692660, 1.8760108, 0.0415560},
                                    {0.0556434, -0.2040259, 1.0572252}};

double xyzToRgbChannel(const Vec3& xyz, int c) {
  return kXyzToRgb[c][0] * xyz[0] + kXyzToRgb[c][1] * xyz[1] + kXyzToRgb[c][2] * xyz[2];
}

/// Sensitivity of RGB channel c to an interference term of path difference
/// `opd` and phase shift `shift`, white-balanced: at opd = 0 it is exactly
/// cos(shift) (the fit integrates against illuminant E, whose Rec.709 colour
/// is not grey; dividing by it makes a zero-thickness film colourless).
double rgbSensitivity(double opd, double shift, int c) {
  static const Vec3 kWhite = [] {
    const Vec3 xyz = xyzSensitivity(0.0, 0.0);
    return Vec3{xyzToRgbChannel(xyz, 0), xyzToRgbChannel(xyz, 1), xyzToRgbChannel(xyz, 2)};
  }();
  return xyzToRgbChannel(xyzSensitivity(opd, shift), c) / kWhite[c];
}

/// Unpolarized Fresnel reflectance of a smooth dielectric interface, relative
/// IOR eta = n_transmitted / n_incident, cosine of incidence c in [0, 1]
/// (Walter et al. 2007 form). Total internal reflection gives 1.
double fresnelDielectric(double eta, double c) {
  if (eta == 1.0) return 0.0;  // no interface (also avoids 0/0 at c = 0)
  const double g2 = eta * eta - 1.0 + c * c;
  if (g2 <= 0.0) return 1.0;  // total internal reflection (or its edge)
  const double g = std::sqrt(g2);
  const double a = (g - c) / (g + c);                          // g + c > 0 here
  const double b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);  // 1 - c^2 + c g > 0 here
  return clampSafe(0.5 * a * a * (1.0 + b * b), 0.0, 1.0);
}

/// The air / film part of the stack, shared by the three channels.
struct FilmInterface {
  double R12, T121, cosTheta2, eta2;
};

/// Airy reflectance of air / film / base (Belcour & Barla 2017, the series
/// truncated after kAiryOrders terms) for RGB channel c at path difference `opd`.
double airyReflectance(const FilmInterface& film, double baseF0, double baseF90, double opd, int c) {
  // Base IOR from its F0 (dielectric approximation of the base, as in the
  // real-time form of the paper: no conductor phase).
  const double sF0 = std::sqrt(clampSafe(baseF0, 0.0, kBaseF0Max));
  const double eta3 = (1.0 + sF0) / (1.0 - sF0);
  // Film -> base interface: exact dielectric Fresnel, its grazing value moved
  // from 1 to the base's F90 with Schlick's weight (F90 = 1 leaves it exact).
  const double x = 1.0 - film.cosTheta2, x5 = x * x * x * x * x;
  const double R23 =
      clampSafe(fresnelDielectric(eta3 / film.eta2, film.cosTheta2) + (baseF90 - 1.0) * x5, 0.0, 1.0);
  // Phase: air -> film reflects with no shift (eta2 >= 1), so film -> air
  // (phi21) shifts by pi; film -> base shifts by pi if the base is less dense.
  const double phi = std::numbers::pi + (eta3 < film.eta2 ? std::numbers::pi : 0.0);
  // Compound terms.
  const double R123 = clampSafe(film.R12 * R23, 0.0, kR123Max);
  const double r123 = std::sqrt(R123);
  const double Rs = film.T121 * film.T121 * R23 / (1.0 - R123);
  double I = film.R12 + Rs;  // m = 0
  double Cm = Rs - film.T121;
  for (int m = 1; m <= kAiryOrders; ++m) {
    Cm *= r123;
    I += 2.0 * Cm * rgbSensitivity(m * opd, m * phi, c);
  }
  return std::max(I, 0.0);  // out-of-gamut terms can go negative
}

}  // namespace

DiffuseF0 metalnessToDiffuseF0(const Vec3& base_color, double metallic, double specular) {
  const double m = clampSafe(metallic, 0.0, 1.0);
  const double dielectricF0 = 0.08 * clampSafe(specular, 0.0, 1.0);
  DiffuseF0 r{};
  for (int c = 0; c < 3; ++c) {
    const double b = clampSafe(base_color[c], 0.0, 1.0);
    r.diffuse_albedo[c] = b * (1.0 - m);
    r.f0[c] = dielectricF0 * (1.0 - m) + b * m;
  }
  return r;
}

double iorToF0(double ior) {
  const double n = clampSafe(ior, 0.0, DBL_MAX);  // DBL_MAX + 1 == DBL_MAX: finite
  const double r = (n - 1.0) / (n + 1.0);         // in [-1, 1]
  return r * r;
}

SecondRoughness hazinessToSecondRoughness(double roughness, double haziness) {
  const double r = clampSafe(roughness, 0.0, 1.0);
  const double h = clampSafe(haziness, 0.0, 1.0);
  const double alphaC = r * r;
  const double alphaH = std::min(1.0, (1.0 + kHazeExtent) * alphaC);
  const double ratio = alphaH > 0.0 ? alphaC / alphaH : 1.0 / (1.0 + kHazeExtent);
  const double p = ratio * ratio;  // in [1/16, 1]
  SecondRoughness out{};
  out.second_roughness = std::sqrt(alphaH);
  out.second_roughness_weight = h / (h + p * (1.0 - h));  // denominator >= min(h, p) > 0 unless h = 0
  return out;
}

Mfp transmittanceToMfp(const Vec3& transmittance, double thickness) {
  const double t = thickness > 0.0 ? std::min(thickness, DBL_MAX) : kDefaultSurfaceThickness;
  Mfp out{};
  out.thickness = t;
  for (int c = 0; c < 3; ++c) {
    const double T = clampSafe(transmittance[c], 0.0, 1.0);
    if (T <= 0.0) {
      out.mfp[c] = 0.0;  // opaque
    } else if (T >= 1.0) {
      out.mfp[c] = kMfpTransparent;
    } else {
      // ln(T) in [ln(DBL_TRUE_MIN), -1.1e-16]: finite and negative. t / -ln(T)
      // may overflow to +inf for huge t; the cap brings it back.
      out.mfp[c] = std::min(-t / std::log(T), kMfpTransparent);
    }
  }
  return out;
}

F0F90 thinFilm(double NoV, const Vec3& f0, const Vec3& f90, double film_thickness_m, double ior) {
  if (!(film_thickness_m > 0.0)) return {f0, f90};  // no film: identity, bit for bit
  const double d = std::min(film_thickness_m, kFilmThicknessMax);
  const double cosTheta1 = clampSafe(NoV, 0.0, 1.0);

  FilmInterface film{};
  film.eta2 = clampSafe(ior, 1.0, kFilmIorMax);
  // Snell (air -> film); eta2 >= 1, so no total internal reflection.
  const double sin2Theta2 = (1.0 - cosTheta1 * cosTheta1) / (film.eta2 * film.eta2);
  film.cosTheta2 = std::sqrt(std::max(0.0, 1.0 - sin2Theta2));
  // Air -> film interface.
  film.R12 = fresnelDielectric(film.eta2, cosTheta1);
  film.T121 = 1.0 - film.R12;
  // Optical path difference of one round trip in the film.
  const double opd = 2.0 * film.eta2 * d * film.cosTheta2;

  F0F90 out{{}, f90};
  for (int c = 0; c < 3; ++c) {
    const double baseF0 = clampSafe(f0[c], 0.0, 1.0);
    const double baseF90 = clampSafe(f90[c], 0.0, 1.0);
    const double withFilm = airyReflectance(film, baseF0, baseF90, opd, c);
    const double zeroFilm = airyReflectance(film, baseF0, baseF90, 0.0, c);
    out.f0[c] = clampSafe(baseF0 + (withFilm - zeroFilm), 0.0, 1.0);
  }
  return out;
}

Vec3 rotationToTangent(double angle, const Vec3& normal) {
  const Vec3 n = normalizeOr(normal, {0.0, 0.0, 1.0});
  // Duff et al. 2017: branchless, stable at both poles (copysign keeps
  // s + n.z away from 0, including for n.z = -0).
  const double s = std::copysign(1.0, n[2]);
  const double a = -1.0 / (s + n[2]);
  const double b = n[0] * n[1] * a;
  const Vec3 b1{1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]};
  const Vec3 b2{b, s + n[1] * n[1] * a, -n[1]};
  const double theta = std::isfinite(angle) ? angle : 0.0;
  const double c = std::cos(theta), sn = std::sin(theta);
  Vec3 t{c * b1[0] + sn * b2[0], c * b1[1] + sn * b2[1], c * b1[2] + sn * b2[2]};
  // The basis is orthonormal to rounding; one Gram-Schmidt step and a
  // renormalization make "unit and orthogonal" hold to ~1e-16.
  const double k = dot3(t, n);
  t = {t[0] - k * n[0], t[1] - k * n[1], t[2] - k * n[2]};
  return normalizeOr(t, b1);
}

double viewDependentCoverage(double coverage, double NoV) {
  const double c = clampSafe(coverage, 0.0, 1.0);
  const double mu = clampSafe(NoV, 1e-4, 1.0);
  if (mu >= 1.0 || c <= 0.0 || c >= 1.0) return c;
  // 1 - (1 - c)^(1/mu), without cancellation for small c.
  return clampSafe(-std::expm1(std::log1p(-c) / mu), c, 1.0);
}

}  // namespace substratec::helpers
