// Cube maps for the runtime's split-sum environment lighting
// (runtime_shaders/substrate_lighting.h, compiler/core/emit/entry_emitter.cc):
//  * envPrefiltered: mip i holds the environment prefiltered with GGX of
//    perceptual roughness r_i = i / (mipCount - 1) (alpha = r_i^2), the
//    inverse of substrate_env_mip(r, mipCount) = r (mipCount - 1); mip 0 is
//    the mirror; frame.envParams.x must be mipCount.
//  * envIrradiance: E(n) = integral of L(w) max(n.w, 0) dw (W/m^2, NOT / pi:
//    substrate_env_split_sum divides by pi), sampled at lod 0.
// Face/texel conventions (Vulkan spec "Cube map face selection", = GL's):
// faces +X -X +Y -Y +Z -Z (array layers 0..5); a direction r with major axis
// component m selects the face and (sc, tc):
//   +X: (-rz, -ry)  -X: (+rz, -ry)  +Y: (+rx, +rz)  -Y: (+rx, -rz)
//   +Z: (+rx, -ry)  -Z: (-rx, -ry);   s = (sc/|m| + 1)/2, t = (tc/|m| + 1)/2.
// Texel (x, y) of a face of edge n covers s in [x, x+1]/n, t in [y, y+1]/n and
// stands for its centre ((x + .5)/n, (y + .5)/n); rows (y) are stored top
// (t = 0) first, x fastest — the layout vkCmdCopyBufferToImage expects.
#pragma once
#include <array>
#include <vector>

#include "preview/environment.h"

namespace substratec::preview {

/// Defaults of `substratec preview`.
inline constexpr int kDefaultPrefilterSize = 64;
inline constexpr int kDefaultPrefilterMips = 6;
inline constexpr int kDefaultPrefilterSamples = 128;
inline constexpr int kDefaultIrradianceSize = 16;
inline constexpr int kDefaultIrradianceSource = 32;

/// A cube map with a mip chain: mips[level] = 6 faces x mipSize(level)^2
/// texels x RGBA32F (alpha 1), face-major, then rows, then texels.
struct CubeMap {
  int size = 0;  // edge of mip 0 in texels
  std::vector<std::vector<float>> mips;

  int mipCount() const { return static_cast<int>(mips.size()); }
  /// Edge of mip `level`: max(1, size >> level), as Vulkan sizes mips.
  int mipSize(int level) const { return size >> level > 0 ? size >> level : 1; }
  /// The RGBA of texel (x, y) of `face` at `level`.
  const float* texel(int level, int face, int x, int y) const {
    int n = mipSize(level);
    return mips[level].data() + ((static_cast<size_t>(face) * n + y) * n + x) * 4;
  }
};

/// A face and its (s, t) in [0, 1]^2.
struct CubeCoord {
  int face = 0;
  double s = 0.5, t = 0.5;
};

/// Unit direction of (s, t) on `face` (the conventions above).
std::array<double, 3> cubeDirection(int face, double s, double t);
/// The face and (s, t) a direction (need not be unit, must be non-zero)
/// selects; ties between axes go to X, then Y. Inverse of cubeDirection.
CubeCoord cubeCoord(const std::array<double, 3>& dir);
/// Solid angle of texel (x, y) of a face of edge n (they sum to 4 pi).
double texelSolidAngle(int n, int x, int y);

/// Perceptual roughness mip `level` of a `mipCount`-level prefiltered cube
/// stands for: level / (mipCount - 1) (0 when mipCount is 1).
double mipRoughness(int level, int mipCount);

/// The prefiltered radiance cube. Mip 0 (roughness 0, the mirror) is the
/// environment averaged over each texel (4 x 4 samples; a fine grid over
/// texels near Environment::hotspots(), so the sun keeps its energy). Mip i
/// > 0 is the split-sum prefilter (Karis 2013, N = V = R) at roughness r =
/// mipRoughness(i), alpha = max(r^2, 1e-3): the normalised convolution
///   sum_j K(N.w_j) w_j L_j / sum_j K(N.w_j) w_j,  K = D_GGX(NoH) NoL / 4
/// (the pdf of L under GGX importance sampling times the NoL weight), summed
/// directly over the solid-angle-weighted downsampled mip 0 at a resolution
/// fine enough for the lobe, tiles of 8 x 8 texels standing for their texels
/// where the kernel is small (beyond 2 atan(7 alpha)). When that would take
/// more than ~3e7 kernel evaluations (large baseSize) a level falls back to
/// importance sampling: `samplesPerTexel` GGX half vectors of a Hammersley
/// set, weighted by NoL, fetched at the lod of their pdf (filtered importance
/// sampling, Krivanek & Colbert 2008). Deterministic. Throws
/// std::invalid_argument unless baseSize >= 1, 1 <= mipCount <=
/// floor(log2 baseSize) + 1 and samplesPerTexel >= 1.
CubeMap prefilterRadiance(const Environment& env, int baseSize = kDefaultPrefilterSize,
                          int mipCount = kDefaultPrefilterMips, int samplesPerTexel = kDefaultPrefilterSamples);

/// The irradiance cube (one mip of edge `size`): E(n) = integral of L(w)
/// max(n.w, 0) dw as pi * sum_j max(n.w_j, 0) w_j L_j / sum_j max(n.w_j, 0)
/// w_j over every texel of the environment averaged into a cube of edge
/// `sourceSize` (exact for a constant environment: white gives pi). Throws
/// std::invalid_argument unless size >= 1 and sourceSize >= 1.
CubeMap irradianceMap(const Environment& env, int size = kDefaultIrradianceSize,
                      int sourceSize = kDefaultIrradianceSource);

/// Trilinear fetch of `map` along `dir` at fractional mip `lod` (clamped to
/// the chain): bilinear within the selected face, edges clamped.
std::array<double, 3> sampleCube(const CubeMap& map, const std::array<double, 3>& dir, double lod);

/// Solid-angle-weighted mean radiance of mip `level` (the integral over the
/// sphere / 4 pi).
std::array<double, 3> meanRadiance(const CubeMap& map, int level);

}  // namespace substratec::preview
