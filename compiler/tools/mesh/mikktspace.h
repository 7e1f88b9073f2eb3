// Per-vertex tangents for an indexed triangle list, MikkTSpace-style, not
// bit-identical to the reference implementation (Debian packages none; this
// is our own): each triangle's tangent and bitangent from its UV derivatives,
// projected onto the plane of each corner's normal, normalized and summed per
// vertex weighted by the corner's angle; the vertex tangent is the sum
// Gram-Schmidt orthogonalized against the normal, and w the sign that makes
// glTF's bitangent = cross(normal, tangent.xyz) * w point along the summed
// bitangent. Unlike the reference, vertices are never split (a vertex shared
// by triangles of mirrored UVs gets one averaged tangent). A vertex whose
// triangles all have degenerate UVs (zero area in UV space), or whose sum
// cancels, gets a unit vector orthogonal to its normal and w = 1. Never NaN
// or Inf: non-finite inputs are treated as degenerate.
//
// Also the small vector helpers the mesh floor shares (inline here, so that
// the floor's unity build sees one definition).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace substratec::mesh {

namespace vec {

using Vec3 = std::array<double, 3>;

/// a + b.
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
/// a - b.
inline Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
/// a * s.
inline Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
/// The dot product.
inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
/// The cross product a x b.
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// The Euclidean length.
inline double length(const Vec3& a) { return std::sqrt(dot(a, a)); }
/// True when every component is finite.
inline bool finite(const Vec3& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }
/// `a` scaled to unit length, or `fallback` when it is zero, tiny or not finite.
inline Vec3 normalizeOr(const Vec3& a, const Vec3& fallback) {
  const double l = length(a);
  if (!std::isfinite(l) || l < 1e-30) return fallback;
  const Vec3 u = scale(a, 1.0 / l);
  return finite(u) ? u : fallback;
}
/// A unit vector orthogonal to the unit vector `n` (+X for n = +Z; deterministic).
inline Vec3 anyPerpendicular(const Vec3& n) {
  const Vec3 axis = std::fabs(n[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalizeOr(sub(axis, scale(n, dot(n, axis))), Vec3{0, 0, 1});
}
/// `t` Gram-Schmidt orthogonalized against the unit vector `n` and normalized,
/// or anyPerpendicular(n) when nothing is left of it.
inline Vec3 orthonormalTo(const Vec3& t, const Vec3& n) {
  const Vec3 r = sub(t, scale(n, dot(n, t)));
  const double l = length(r);
  if (!std::isfinite(l) || l < 1e-12 * std::max(1.0, length(t))) return anyPerpendicular(n);
  return normalizeOr(r, anyPerpendicular(n));
}

}  // namespace vec

/// Writes the tangent (xyz unit, orthogonal to the normal; w = +-1) of every
/// vertex of `vertices` (kVertexFloats floats each, gltf_mesh.h's layout: the
/// position, normal and TEXCOORD_0 are read) from the triangles `indices`
/// (three per triangle; a triangle with an index out of range is ignored). A
/// vertex no triangle uses gets the fallback tangent. The normals are read as
/// unit vectors (a zero one is taken as +Z).
void generateTangents(std::vector<float>& vertices, const std::vector<uint32_t>& indices);

}  // namespace substratec::mesh
