// The camera of `substratec render` as its shaders need it: the vertex stage's
// view-projection rows (runtime_shaders/substrate_vertex.vert) and the scene
// lighting's pinhole frame (emit/scene_emitter.h, SubstrateSceneFrame), made
// from one mesh::Camera so that a pixel's view direction is the same ray in
// the forward pass (eye minus position) and in the deferred lighting.
#pragma once
#include <array>

#include "mesh/gltf_mesh.h"

namespace substratec::render {

struct ViewSetup {
  /// Rows of the view-projection matrix (clip = rows · (p, 1)): Vulkan clip
  /// space, y down, depth 0 at `znear` to 1 at `zfar`, the image's aspect.
  std::array<std::array<float, 4>, 4> rows{};
  std::array<double, 3> eye{}, forward{}, right{}, up{};  // right-handed: right = forward x up
  double tanHalfFov = 0;  // vertical
  double znear = 0, zfar = 0;
  /// The unit direction from the eye through the centre of pixel (x, y) of a
  /// width x height image, as the scene lighting computes it (negated: toward the scene).
  std::array<double, 3> ray(int x, int y, int width, int height) const;
  /// The distance from the eye, along ray(x, y, ...), of the point whose depth
  /// buffer value is `depth`; kSkyDistance where nothing was drawn (depth 1).
  double distance(int x, int y, int width, int height, float depth) const;
};

/// How far away the sky is for what lies behind a water (metres): far enough
/// that any water with extinction hides it.
inline constexpr double kSkyDistance = 1e5;

/// The view of `camera` for a width x height image whose geometry lies within
/// [boundsMin, boundsMax]: the far plane just beyond the farthest corner (the
/// camera's own zfar when it is nearer), the near plane the camera's (at least
/// 1e-4 of the far plane, for depth precision).
ViewSetup viewSetup(const mesh::Camera& camera, int width, int height, const std::array<double, 3>& boundsMin,
                    const std::array<double, 3>& boundsMax);

}  // namespace substratec::render
