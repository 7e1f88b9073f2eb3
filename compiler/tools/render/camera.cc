#include "render/camera.h"

#include <algorithm>
#include <cmath>

namespace substratec::render {

namespace {

using V3 = std::array<double, 3>;
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
/// `v` normalized, or `fallback` when it has no length (or is not finite).
V3 unitOr(const V3& v, const V3& fallback) {
  const double l = std::sqrt(dot(v, v));
  if (!(l > 1e-12) || !std::isfinite(l)) return fallback;
  return {v[0] / l, v[1] / l, v[2] / l};
}

}  // namespace

std::array<double, 3> ViewSetup::ray(int x, int y, int width, int height) const {
  const double ndcX = (x + 0.5) / width * 2 - 1, ndcY = (y + 0.5) / height * 2 - 1;
  const double aspect = static_cast<double>(width) / height;
  V3 d;
  for (int c = 0; c < 3; ++c) d[c] = forward[c] + ndcX * aspect * tanHalfFov * right[c] - ndcY * tanHalfFov * up[c];
  return unitOr(d, forward);
}

double ViewSetup::distance(int x, int y, int width, int height, float depth) const {
  if (!(depth < 1.0f)) return kSkyDistance;
  // depth = A + B / z_view (viewSetup's third row over its fourth).
  const double A = zfar / (zfar - znear), B = -zfar * znear / (zfar - znear);
  const double z = B / (static_cast<double>(depth) - A);
  const double cosine = dot(ray(x, y, width, height), forward);
  return std::clamp(z / std::max(cosine, 1e-6), 0.0, kSkyDistance);
}

ViewSetup viewSetup(const mesh::Camera& camera, int width, int height, const std::array<double, 3>& boundsMin,
                    const std::array<double, 3>& boundsMax) {
  ViewSetup v;
  v.eye = camera.position;
  v.forward = unitOr(camera.forward, {0, 0, -1});
  v.right = unitOr(cross(v.forward, camera.up), std::abs(v.forward[1]) < 0.9 ? unitOr(cross(v.forward, {0, 1, 0}), {1, 0, 0})
                                                                             : V3{1, 0, 0});
  v.up = cross(v.right, v.forward);
  v.tanHalfFov = std::tan(0.5 * std::clamp(camera.yfov, 1e-3, 3.1));
  // The far plane: the farthest corner of the bounds along the view, with a margin.
  double far = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const V3 p{corner & 1 ? boundsMax[0] : boundsMin[0], corner & 2 ? boundsMax[1] : boundsMin[1],
               corner & 4 ? boundsMax[2] : boundsMin[2]};
    far = std::max(far, dot({p[0] - v.eye[0], p[1] - v.eye[1], p[2] - v.eye[2]}, v.forward));
  }
  far = std::max(far * 1.01, 1e-3);
  if (camera.zfar > 0) far = std::min(far, camera.zfar);
  v.zfar = far;
  v.znear = std::clamp(camera.znear, far * 1e-4, far * 0.5);
  const double aspect = static_cast<double>(width) / height;
  // clip.x = x_view / (aspect tan), clip.y = -y_view / tan (Vulkan: y down),
  // clip.z = A z_view + B with depth 0 at near and 1 at far, clip.w = z_view.
  const double A = v.zfar / (v.zfar - v.znear), B = -v.zfar * v.znear / (v.zfar - v.znear);
  auto row = [&](const V3& axis, double scale, double offset) {
    return std::array<float, 4>{static_cast<float>(axis[0] * scale), static_cast<float>(axis[1] * scale),
                                static_cast<float>(axis[2] * scale),
                                static_cast<float>(-dot(axis, v.eye) * scale + offset)};
  };
  v.rows[0] = row(v.right, 1 / (aspect * v.tanHalfFov), 0);
  v.rows[1] = row(v.up, -1 / v.tanHalfFov, 0);
  v.rows[2] = row(v.forward, A, B);
  v.rows[3] = row(v.forward, 1, 0);
  return v;
}

}  // namespace substratec::render
