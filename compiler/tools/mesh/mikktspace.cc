#include "mesh/mikktspace.h"

#include <cstddef>

#include "mesh/gltf_mesh.h"

namespace substratec::mesh {

namespace {

using vec::Vec3;

/// Three floats of vertex `v` at `offset` in the kVertexFloats layout, as doubles.
Vec3 vertexVec3(const std::vector<float>& vs, std::size_t v, int offset) {
  const float* f = vs.data() + v * kVertexFloats + offset;
  return {f[0], f[1], f[2]};
}

/// One triangle's dP/du and dP/dv (the tangent and bitangent before any
/// normalization) from its positions `p` and TEXCOORD_0 `uv`; false when the
/// triangle has no area in UV space (or an input is not finite).
bool uvDerivatives(const Vec3 p[3], const double uv[3][2], Vec3& t, Vec3& b) {
  const Vec3 e1 = vec::sub(p[1], p[0]), e2 = vec::sub(p[2], p[0]);
  const double s1 = uv[1][0] - uv[0][0], t1 = uv[1][1] - uv[0][1];
  const double s2 = uv[2][0] - uv[0][0], t2 = uv[2][1] - uv[0][1];
  const double area2 = s1 * t2 - s2 * t1;  // twice the signed area in UV space
  if (!std::isfinite(area2) || !(std::fabs(area2) > 1e-30)) return false;
  t = vec::scale(vec::sub(vec::scale(e1, t2), vec::scale(e2, t1)), 1.0 / area2);
  b = vec::scale(vec::sub(vec::scale(e2, s1), vec::scale(e1, s2)), 1.0 / area2);
  return vec::finite(t) && vec::finite(b);
}

/// The angle of triangle `p` at corner `c` (0 when an edge there has no length).
double cornerAngle(const Vec3 p[3], int c) {
  const Vec3 zero{0, 0, 0};
  const Vec3 a = vec::normalizeOr(vec::sub(p[(c + 1) % 3], p[c]), zero);
  const Vec3 b = vec::normalizeOr(vec::sub(p[(c + 2) % 3], p[c]), zero);
  if (vec::dot(a, a) == 0 || vec::dot(b, b) == 0) return 0;
  return std::acos(std::clamp(vec::dot(a, b), -1.0, 1.0));
}

/// The sums of one vertex's corner tangents and bitangents, angle-weighted.
struct TangentSum {
  Vec3 t{0, 0, 0}, b{0, 0, 0};
};

/// The unit normal of vertex `v` (+Z when it has none usable).
Vec3 unitNormal(const std::vector<float>& vs, std::size_t v) {
  return vec::normalizeOr(vertexVec3(vs, v, kNormalOffset), Vec3{0, 0, 1});
}

/// Adds triangle `tri`'s tangent frame to its three corners' sums.
void accumulateTriangle(const std::vector<float>& vs, const std::array<std::size_t, 3>& tri,
                        std::vector<TangentSum>& sums) {
  Vec3 p[3];
  double uv[3][2];
  for (int c = 0; c < 3; ++c) {
    p[c] = vertexVec3(vs, tri[c], kPositionOffset);
    uv[c][0] = vs[tri[c] * kVertexFloats + kUv0Offset];
    uv[c][1] = vs[tri[c] * kVertexFloats + kUv0Offset + 1];
  }
  Vec3 t, b;
  if (!uvDerivatives(p, uv, t, b)) return;
  const Vec3 zero{0, 0, 0};
  for (int c = 0; c < 3; ++c) {
    const double w = cornerAngle(p, c);
    if (!(w > 0)) continue;
    const Vec3 n = unitNormal(vs, tri[c]);
    const Vec3 tp = vec::normalizeOr(vec::sub(t, vec::scale(n, vec::dot(n, t))), zero);
    const Vec3 bp = vec::normalizeOr(vec::sub(b, vec::scale(n, vec::dot(n, b))), zero);
    sums[tri[c]].t = vec::add(sums[tri[c]].t, vec::scale(tp, w));
    sums[tri[c]].b = vec::add(sums[tri[c]].b, vec::scale(bp, w));
  }
}

/// Writes vertex `v`'s tangent from its sums: orthonormal to the normal, w the
/// bitangent's sign; the fallback (any perpendicular, w = 1) when the sum is nothing.
void writeTangent(std::vector<float>& vs, std::size_t v, const TangentSum& sum) {
  const Vec3 n = unitNormal(vs, v);
  Vec3 t = vec::anyPerpendicular(n);
  double w = 1;
  const double l = vec::length(sum.t);
  if (std::isfinite(l) && l > 1e-12) {
    t = vec::orthonormalTo(sum.t, n);
    w = vec::dot(vec::cross(n, t), sum.b) < 0 ? -1.0 : 1.0;
  }
  float* out = vs.data() + v * kVertexFloats + kTangentOffset;
  for (int i = 0; i < 3; ++i) out[i] = static_cast<float>(t[i]);
  out[3] = static_cast<float>(w);
}

}  // namespace

void generateTangents(std::vector<float>& vertices, const std::vector<uint32_t>& indices) {
  const std::size_t count = vertices.size() / kVertexFloats;
  std::vector<TangentSum> sums(count);
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const std::array<std::size_t, 3> tri = {indices[i], indices[i + 1], indices[i + 2]};
    if (tri[0] >= count || tri[1] >= count || tri[2] >= count) continue;
    accumulateTriangle(vertices, tri, sums);
  }
  for (std::size_t v = 0; v < count; ++v) writeTangent(vertices, v, sums[v]);
}

}  // namespace substratec::mesh
