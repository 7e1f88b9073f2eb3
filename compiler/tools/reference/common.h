// Mirrors runtime_shaders/substrate_common.h (constants and guarded primitives)
// and the dialect's intrinsics (saturate, lerp, normalize, ...), templated on the
// scalar type, plus the small vector algebra the rest of the reference uses.
// Every constant is written as T(...) so that the float instantiation never
// computes in double. Internal to compiler/tools/reference/.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "ir/value_eval.h"
#include "reference/reference.h"

namespace substratec::reference::detail {

// ---------------------------------------------------------------------------
// Vector algebra on std::array (component-wise, as the shading languages).

template <class T, std::size_t n>
std::array<T, n> operator+(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] + b[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator-(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] - b[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator-(const std::array<T, n>& a) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = -a[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator*(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] * b[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator/(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] / b[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator*(const std::array<T, n>& a, T s) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] * s;
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator*(T s, const std::array<T, n>& a) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = s * a[i];
  return r;
}
template <class T, std::size_t n>
std::array<T, n> operator/(const std::array<T, n>& a, T s) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = a[i] / s;
  return r;
}

template <class T>
V3<T> splat3(T x) {
  return {x, x, x};
}
template <class T>
T dot(const V3<T>& a, const V3<T>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
template <class T>
V3<T> cross(const V3<T>& a, const V3<T>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
template <class T>
T length(const V3<T>& a) {
  return std::sqrt(dot(a, a));
}
template <class T>
V3<T> normalize(const V3<T>& a) {
  return a / length(a);
}
template <class T, std::size_t n>
std::array<T, n> vmax(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = std::max(a[i], b[i]);
  return r;
}
template <class T, std::size_t n>
std::array<T, n> vmin(const std::array<T, n>& a, const std::array<T, n>& b) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = std::min(a[i], b[i]);
  return r;
}
template <class T, std::size_t n>
std::array<T, n> vabs(const std::array<T, n>& a) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = std::fabs(a[i]);
  return r;
}
template <class To, class From, std::size_t n>
std::array<To, n> cast(const std::array<From, n>& a) {
  std::array<To, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = static_cast<To>(a[i]);
  return r;
}

// ---------------------------------------------------------------------------
// Intrinsics of the dialect.

template <class T>
T clampT(T x, T lo, T hi) {
  return std::min(std::max(x, lo), hi);  // GLSL clamp = min(max(x, lo), hi)
}
template <class T>
T saturate(T x) {
  return clampT(x, T(0), T(1));
}
template <class T, std::size_t n>
std::array<T, n> saturate(const std::array<T, n>& a) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = saturate(a[i]);
  return r;
}
template <class T, std::size_t n>
std::array<T, n> vclamp(const std::array<T, n>& a, T lo, T hi) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = clampT(a[i], lo, hi);
  return r;
}
// GLSL mix(x, y, a) = x (1 - a) + y a (exact at a = 0 and a = 1).
template <class T>
T lerp(T x, T y, T a) {
  return x * (T(1) - a) + y * a;
}
template <class T, std::size_t n>
std::array<T, n> lerp(const std::array<T, n>& x, const std::array<T, n>& y, T a) {
  std::array<T, n> r;
  for (std::size_t i = 0; i < n; ++i) r[i] = lerp(x[i], y[i], a);
  return r;
}
template <class T>
bool finite3(const V3<T>& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// ---------------------------------------------------------------------------
// substrate_common.h

template <class T>
struct K {
  static constexpr T pi = T(3.14159265358979);      // SUBSTRATE_PI
  static constexpr T twoPi = T(6.28318530717959);   // SUBSTRATE_TWO_PI
  static constexpr T invPi = T(0.318309886183791);  // SUBSTRATE_INV_PI
  static constexpr T minCos = T(1e-4);              // SUBSTRATE_MIN_COS
  static constexpr T minTransmittance = T(1e-30);   // SUBSTRATE_MIN_TRANSMITTANCE
  static constexpr T minMfp = T(1e-30);             // SUBSTRATE_MIN_MFP
  static constexpr T fltMax = T(3.0e38);            // SUBSTRATE_FLT_MAX
};

// substrate_pow: base clamped at 0, 0^y = 0 for y != 0, 0^0 = 1, clamped to 3e38.
template <class T>
T substratePow(T x, T y) {
  T b = std::max(x, T(0));
  T r = std::pow(b > T(0) ? b : T(1), y);
  if (b > T(0)) return std::min(r, K<T>::fltMax);
  return y == T(0) ? T(1) : T(0);
}

// substrate_pow5: saturate(x)^5.
template <class T>
T pow5(T x) {
  T t = saturate(x);
  T t2 = t * t;
  return t2 * t2 * t;
}

// The mean of the three channels (substrate_diffuse_interface's dot with 1/3).
template <class T>
T mean3(const V3<T>& v) {
  return (v[0] + v[1] + v[2]) / T(3);
}

template <class T>
T max3(const V3<T>& v) {
  return std::max(v[0], std::max(v[1], v[2]));
}

// substrate_safe_normalize: v / max|v_i| first; `fallback` when max|v_i| <= 1e-30,
// not finite, or > 3e38 (a NaN fails both comparisons).
template <class T>
V3<T> safeNormalize(const V3<T>& v, const V3<T>& fallback) {
  T m = max3(vabs(v));
  if (m > T(1e-30) && m <= K<T>::fltMax) {
    V3<T> u = v / m;
    return u * (T(1) / std::sqrt(dot(u, u)));  // u * rsqrt(dot(u, u))
  }
  return fallback;
}

// v / |v|, or `fallback` when |v|² is not positive and finite (the walks'
// normalization; no GLSL counterpart).
template <class T>
V3<T> unitOr(const V3<T>& v, const V3<T>& fallback) {
  T l2 = dot(v, v);
  if (!(l2 > T(0)) || !std::isfinite(l2)) return fallback;
  return v / std::sqrt(l2);
}

// substrate_orthonormal_basis (Duff et al. 2017), s from the sign bit of N.z.
template <class T>
void orthonormalBasis(const V3<T>& N, V3<T>& Tn, V3<T>& Bn) {
  T s = std::signbit(N[2]) ? T(-1) : T(1);
  T a = T(-1) / (s + N[2]);
  T b = N[0] * N[1] * a;
  Tn = {T(1) + s * N[0] * N[0] * a, s * b, -s * N[0]};
  Bn = {b, s + N[1] * N[1] * a, -N[1]};
}

// substrate_transmittance: exp(-min(max(d, 0) / max(mfp, 1e-30), 1e30)).
template <class T>
V3<T> transmittance(const V3<T>& mfp, T d) {
  T dd = std::max(d, T(0));
  V3<T> r;
  for (int i = 0; i < 3; ++i) r[i] = std::exp(-std::min(dd / std::max(mfp[i], K<T>::minMfp), T(1e30)));
  return r;
}

// substrate_layer_scattering (substrate_tree.h): albedo * (1 - sat(T)^2).
template <class T>
V3<T> layerScattering(const V3<T>& albedo, const V3<T>& t) {
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    const T tc = clampT(t[i], T(0), T(1));
    r[i] = albedo[i] * (T(1) - tc * tc);
  }
  return r;
}

// substrate_transmittance_at_cosine: exp(log(clamp(T, 1e-30, 1)) / max(mu, 1e-4)).
template <class T>
V3<T> transmittanceAtCosine(const V3<T>& normalTransmittance, T mu) {
  V3<T> r;
  for (int i = 0; i < 3; ++i)
    r[i] = std::exp(std::log(clampT(normalTransmittance[i], K<T>::minTransmittance, T(1))) /
                    std::max(mu, K<T>::minCos));
  return r;
}

// substrate_pcg3d (Jarzynski & Olano 2020), 32-bit unsigned arithmetic.
inline std::array<std::uint32_t, 3> pcg3d(std::array<std::uint32_t, 3> v) {
  for (auto& x : v) x = x * 1664525u + 1013904223u;
  v[0] += v[1] * v[2];
  v[1] += v[2] * v[0];
  v[2] += v[0] * v[1];
  v[0] ^= v[0] >> 16u;
  v[1] ^= v[1] >> 16u;
  v[2] ^= v[2] >> 16u;
  v[0] += v[1] * v[2];
  v[1] += v[2] * v[0];
  v[2] += v[0] * v[1];
  return v;
}

// substrate_hash_to_unit: ((h >> 8) + 1) / 2^24, in (0, 1].
template <class T>
T hashToUnit(std::uint32_t h) {
  return (static_cast<T>(h >> 8u) + T(1)) * (T(1) / T(16777216));
}

// ---------------------------------------------------------------------------
// The value DAG's evaluation point.

/// The point evaluateDag sees at `g`, as the generated code does: tangent
/// space (normal (0,0,1), tangent (1,0,0), view = ts_view = (V.T, V.(N x T),
/// V.N), not renormalized), g's position, uvs and vertex colour; `tex` (when
/// set) samples the textures. Inputs at their defaults.
inline EvalPoint tangentSpacePoint(const Geometry& g, const TextureFn& tex) {
  EvalPoint p;
  p.normal = {0, 0, 1};
  p.tangent = {1, 0, 0};
  const V3<double> B = cross(g.N, g.T);
  p.view = {dot(g.V, g.T), dot(g.V, B), dot(g.V, g.N)};
  p.position = g.position;
  p.uv0 = g.uv0;
  p.uv1 = g.uv1;
  p.vertexColor = g.vertexColor;
  if (tex) p.sampler = tex;
  return p;
}

}  // namespace substratec::reference::detail
