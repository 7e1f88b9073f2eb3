// Internal to compiler/tools/preview: the few vector helpers the environments and
// the cube-map prefilter share (double precision, std::array based).
#pragma once
#include <array>
#include <cmath>
#include <numbers>

namespace substratec::preview::detail {

using Vec3 = std::array<double, 3>;

inline Vec3 operator+(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 operator-(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 operator*(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline Vec3 operator*(double s, const Vec3& a) { return a * s; }
inline Vec3 mul(const Vec3& a, const Vec3& b) { return {a[0] * b[0], a[1] * b[1], a[2] * b[2]}; }
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
/// a / |a|; +Z for a zero vector.
inline Vec3 normalize(const Vec3& a) {
  double l = length(a);
  return l > 0.0 ? a * (1.0 / l) : Vec3{0.0, 0.0, 1.0};
}
inline double clamp01(double x) { return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x); }
/// Hermite smoothstep of x between e0 and e1 (e0 < e1).
inline double smoothstep(double e0, double e1, double x) {
  double t = clamp01((x - e0) / (e1 - e0));
  return t * t * (3.0 - 2.0 * t);
}
inline Vec3 lerp(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * t; }

/// Orthonormal T, B completing the unit vector n (Duff et al. 2017).
inline void orthonormalBasis(const Vec3& n, Vec3& t, Vec3& b) {
  double sign = std::copysign(1.0, n[2]);
  double a = -1.0 / (sign + n[2]);
  double c = n[0] * n[1] * a;
  t = {1.0 + sign * n[0] * n[0] * a, sign * c, -sign * n[0]};
  b = {c, sign + n[1] * n[1] * a, -n[1]};
}

}  // namespace substratec::preview::detail
