// Prefiltered radiance and irradiance cubes of a procedural environment for
// the runtime's split-sum lighting (cubemap.h states the conventions).
#include "preview/cubemap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>

#include "preview/preview_math.h"

namespace substratec::preview {

using namespace detail;  // Vec3 and its operators (not found by ADL on std::array)

namespace {

/// Van der Corput radical inverse in base 2: the second Hammersley coordinate.
double radicalInverse(uint32_t bits) {
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return static_cast<double>(bits) * 2.3283064365386963e-10;  // / 2^32
}

/// Mean of the environment over texel (x, y) of `face` (edge n): k x k
/// samples on a regular grid in (s, t).
Vec3 texelAverage(const Environment& env, int face, int n, int x, int y, int k) {
  Vec3 sum{0.0, 0.0, 0.0};
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) sum = sum + env.radiance(cubeDirection(face, (x + (i + 0.5) / k) / n, (y + (j + 0.5) / k) / n));
  return sum * (1.0 / (k * k));
}

/// The environment averaged over each texel of a cube level of edge n: 4 x 4
/// samples (the radiance varies smoothly), and a grid of spacing a quarter of
/// its radius over texels that may touch a hotspot.
std::vector<float> mirrorLevel(const Environment& env, int n) {
  std::vector<float> out(static_cast<size_t>(6) * n * n * 4);
  const double halfDiagonal = std::atan(std::sqrt(2.0) / n);  // texel centre to corner, at most
  float* p = out.data();
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, p += 4) {
        Vec3 centre = cubeDirection(face, (x + 0.5) / n, (y + 0.5) / n);
        int k = 4;
        for (const Hotspot& h : env.hotspots()) {
          double angle = std::acos(std::clamp(dot(centre, h.direction), -1.0, 1.0));
          if (angle <= h.angularRadius + halfDiagonal)
            k = std::max(k, std::min(256, static_cast<int>(std::ceil(8.0 / (n * h.angularRadius)))));
        }
        Vec3 L = texelAverage(env, face, n, x, y, k);
        p[0] = static_cast<float>(L[0]);
        p[1] = static_cast<float>(L[1]);
        p[2] = static_cast<float>(L[2]);
        p[3] = 1.0f;
      }
  return out;
}

/// `map` with mip 0 set, completed down to 1x1: each texel the solid-angle
/// weighted mean of the (up to) 2x2 texels it covers, i.e. the mean radiance
/// over its area of the sphere (a plain average would favour the small texels
/// near the face corners). The sources of both ways of prefiltering.
void downsampleChain(CubeMap& map) {
  for (int level = 1; map.mipSize(level - 1) > 1; ++level) {
    int n = map.mipSize(level), m = map.mipSize(level - 1);
    std::vector<float> next(static_cast<size_t>(6) * n * n * 4);
    for (int face = 0; face < 6; ++face)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
          double sum[4] = {0.0, 0.0, 0.0, 0.0}, wsum = 0.0;
          for (int sy = 2 * y; sy < std::min(2 * y + 2, m); ++sy)
            for (int sx = 2 * x; sx < std::min(2 * x + 2, m); ++sx) {
              double w = texelSolidAngle(m, sx, sy);
              const float* p = map.texel(level - 1, face, sx, sy);
              for (int c = 0; c < 4; ++c) sum[c] += w * p[c];
              wsum += w;
            }
          for (int c = 0; c < 4; ++c)
            next[((static_cast<size_t>(face) * n + y) * n + x) * 4 + c] = static_cast<float>(sum[c] / wsum);
        }
    map.mips.push_back(std::move(next));
  }
}

/// Direct summation is used while it takes fewer kernel evaluations than this
/// (about 30 ms); importance sampling otherwise.
constexpr double kDirectBudget = 3e7;

/// The texel-averaged environment at edge n with its downsampled chain.
CubeMap sourceCube(const Environment& env, int n) {
  CubeMap src;
  src.size = n;
  src.mips.push_back(mirrorLevel(env, n));
  downsampleChain(src);
  return src;
}

/// One sample direction in the frame of the lobe axis (z), its weight and the
/// source lod its pdf calls for (Krivanek & Colbert 2008, with their +1 bias).
struct LobeSample {
  Vec3 local;
  double weight, lod;
};

/// lod = max(0, log2(omegaSample / omegaTexel) / 2 + 1), omegaSample = 1/(N pdf).
double filteredLod(double pdf, int samples, int sourceSize) {
  double omegaTexel = 4.0 * std::numbers::pi / (6.0 * sourceSize * sourceSize);
  double omegaSample = 1.0 / (samples * std::max(pdf, 1e-12));
  return std::max(0.0, 0.5 * std::log2(omegaSample / omegaTexel) + 1.0);
}

/// GGX (alpha) reflection directions about N = V = z: H from the NDF with the
/// Hammersley point (i/N, radicalInverse(i)), L = 2 (z.H) H - z, weight NoL,
/// pdf(L) = D(NoH) NoH / (4 VoH) = D / 4.
std::vector<LobeSample> ggxLobe(double alpha, int samples, int sourceSize) {
  std::vector<LobeSample> lobe;
  double a2 = alpha * alpha;
  for (int i = 0; i < samples; ++i) {
    double phi = 2.0 * std::numbers::pi * i / samples;
    double xi = radicalInverse(static_cast<uint32_t>(i));
    double cosH = std::sqrt((1.0 - xi) / (1.0 + (a2 - 1.0) * xi));
    double sinH = std::sqrt(std::max(0.0, 1.0 - cosH * cosH));
    Vec3 H{sinH * std::cos(phi), sinH * std::sin(phi), cosH};
    Vec3 L = 2.0 * cosH * H - Vec3{0.0, 0.0, 1.0};
    if (L[2] <= 0.0) continue;
    double d = (a2 - 1.0) * cosH * cosH + 1.0;
    double D = a2 / (std::numbers::pi * d * d);
    lobe.push_back({L, L[2], filteredLod(D / 4.0, samples, sourceSize)});
  }
  return lobe;
}

/// One level of edge n by importance sampling: per texel, sum w_k
/// src(frame(L_k), lod_k) / sum w_k over the lobe's samples.
std::vector<float> importanceSampleLevel(const CubeMap& src, int n, const std::vector<LobeSample>& lobe) {
  std::vector<float> out(static_cast<size_t>(6) * n * n * 4);
  float* p = out.data();
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, p += 4) {
        Vec3 N = cubeDirection(face, (x + 0.5) / n, (y + 0.5) / n), T, B;
        detail::orthonormalBasis(N, T, B);
        Vec3 sum{0.0, 0.0, 0.0};
        double wsum = 0.0;
        for (const LobeSample& k : lobe) {
          Vec3 L = T * k.local[0] + B * k.local[1] + N * k.local[2];
          sum = sum + sampleCube(src, L, k.lod) * k.weight;
          wsum += k.weight;
        }
        Vec3 v = sum * (1.0 / wsum);
        p[0] = static_cast<float>(v[0]);
        p[1] = static_cast<float>(v[1]);
        p[2] = static_cast<float>(v[2]);
        p[3] = 1.0f;
      }
  return out;
}

/// A square block of source texels: their solid-angle-weighted centroid
/// direction, the angle from it that covers them all, and their sums.
struct Tile {
  Vec3 dir;
  double radius;
  double w;
  Vec3 wL;
  size_t begin, end;  // its texels in Texels
};

/// The texels of one cube level as directions, solid angles w and w * L,
/// ordered tile by tile (tiles of `tileEdge` x `tileEdge` texels).
struct Texels {
  std::vector<Vec3> dir;
  std::vector<double> w;
  std::vector<Vec3> wL;
  std::vector<Tile> tiles;
};

Texels gatherTexels(const CubeMap& map, int level, int tileEdge) {
  Texels t;
  const int n = map.mipSize(level);
  const double halfDiagonal = std::atan(std::sqrt(2.0) / n);
  for (int face = 0; face < 6; ++face)
    for (int ty = 0; ty < n; ty += tileEdge)
      for (int tx = 0; tx < n; tx += tileEdge) {
        Tile tile{{0.0, 0.0, 0.0}, 0.0, 0.0, {0.0, 0.0, 0.0}, t.dir.size(), 0};
        for (int y = ty; y < std::min(ty + tileEdge, n); ++y)
          for (int x = tx; x < std::min(tx + tileEdge, n); ++x) {
            const float* p = map.texel(level, face, x, y);
            double w = texelSolidAngle(n, x, y);
            Vec3 d = cubeDirection(face, (x + 0.5) / n, (y + 0.5) / n);
            t.dir.push_back(d);
            t.w.push_back(w);
            t.wL.push_back(Vec3{p[0], p[1], p[2]} * w);
            tile.dir = tile.dir + d * w;
            tile.w += w;
            tile.wL = tile.wL + t.wL.back();
          }
        tile.end = t.dir.size();
        tile.dir = detail::normalize(tile.dir);
        for (size_t i = tile.begin; i < tile.end; ++i)
          tile.radius = std::max(tile.radius, std::acos(std::clamp(dot(tile.dir, t.dir[i]), -1.0, 1.0)));
        tile.radius += halfDiagonal;
        t.tiles.push_back(tile);
      }
  return t;
}

/// A rotation-invariant kernel of c = N.L (zero for c <= 0), up to a constant.
struct Kernel {
  double a2 = -1.0;  // GGX alpha^2; < 0: the cosine kernel
  /// cosine: c. GGX for N = V: D(NoH) NoL / 4 with NoH^2 = (1 + c) / 2, i.e.
  /// c / ((a2 - 1) (1 + c) / 2 + 1)^2 times a constant.
  double operator()(double c) const {
    if (a2 < 0.0) return c;
    double d = (a2 - 1.0) * 0.5 * (1.0 + c) + 1.0;
    return c / (d * d);
  }
};

/// One level of edge n by direct summation over the source texels:
/// scale * sum K(N.w_i) w_i L_i / sum K(N.w_i) w_i (normalised, so a constant
/// environment stays exactly constant). Tiles lying wholly beyond `nearAngle`
/// from N, where the kernel is small and smooth, count as one texel at their
/// centroid (a two-level Barnes-Hut sum); nearAngle >= pi sums every texel.
std::vector<float> convolveDirect(const Texels& src, int n, Kernel kernel, double scale, double nearAngle) {
  // Per tile, the cosines of (pi/2 + radius) and (nearAngle + radius): the
  // tile is wholly below the horizon of N, or wholly beyond nearAngle, when
  // N . centroid is below them.
  std::vector<double> belowCos, farCos;
  for (const Tile& tile : src.tiles) {
    belowCos.push_back(tile.radius >= std::numbers::pi / 2 ? -2.0 : -std::sin(tile.radius));
    farCos.push_back(nearAngle + tile.radius >= std::numbers::pi ? -2.0 : std::cos(nearAngle + tile.radius));
  }
  std::vector<float> out(static_cast<size_t>(6) * n * n * 4);
  float* p = out.data();
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, p += 4) {
        Vec3 N = cubeDirection(face, (x + 0.5) / n, (y + 0.5) / n);
        Vec3 sum{0.0, 0.0, 0.0};
        double wsum = 0.0;
        for (size_t t = 0; t < src.tiles.size(); ++t) {
          const Tile& tile = src.tiles[t];
          double c = dot(N, tile.dir);
          if (c <= belowCos[t]) continue;  // wholly below the horizon
          if (c < farCos[t]) {
            if (c <= 0.0) continue;
            double k = kernel(c);
            sum = sum + tile.wL * k;
            wsum += tile.w * k;
            continue;
          }
          for (size_t i = tile.begin; i < tile.end; ++i) {
            double ci = dot(N, src.dir[i]);
            if (ci <= 0.0) continue;
            double k = kernel(ci);
            sum = sum + src.wL[i] * k;
            wsum += src.w[i] * k;
          }
        }
        Vec3 v = sum * (wsum > 0.0 ? scale / wsum : 0.0);
        p[0] = static_cast<float>(v[0]);
        p[1] = static_cast<float>(v[1]);
        p[2] = static_cast<float>(v[2]);
        p[3] = 1.0f;
      }
  return out;
}

/// Bilinear fetch of `level` at (face, s, t), texel indices clamped to the face.
Vec3 bilinear(const CubeMap& map, int level, const CubeCoord& c) {
  int n = map.mipSize(level);
  double u = c.s * n - 0.5, v = c.t * n - 0.5;
  double fu = std::floor(u), fv = std::floor(v);
  double ax = u - fu, ay = v - fv;
  int x0 = std::clamp(static_cast<int>(fu), 0, n - 1), x1 = std::clamp(static_cast<int>(fu) + 1, 0, n - 1);
  int y0 = std::clamp(static_cast<int>(fv), 0, n - 1), y1 = std::clamp(static_cast<int>(fv) + 1, 0, n - 1);
  const float* a = map.texel(level, c.face, x0, y0);
  const float* b = map.texel(level, c.face, x1, y0);
  const float* d = map.texel(level, c.face, x0, y1);
  const float* e = map.texel(level, c.face, x1, y1);
  Vec3 r;
  for (int i = 0; i < 3; ++i)
    r[i] = (1.0 - ay) * ((1.0 - ax) * a[i] + ax * b[i]) + ay * ((1.0 - ax) * d[i] + ax * e[i]);
  return r;
}

}  // namespace

std::array<double, 3> cubeDirection(int face, double s, double t) {
  double sc = 2.0 * s - 1.0, tc = 2.0 * t - 1.0;
  switch (face) {
    case 0: return detail::normalize({1.0, -tc, -sc});
    case 1: return detail::normalize({-1.0, -tc, sc});
    case 2: return detail::normalize({sc, 1.0, tc});
    case 3: return detail::normalize({sc, -1.0, -tc});
    case 4: return detail::normalize({sc, -tc, 1.0});
    case 5: return detail::normalize({-sc, -tc, -1.0});
    default: throw std::invalid_argument("cube face " + std::to_string(face) + " is not in 0..5");
  }
}

CubeCoord cubeCoord(const std::array<double, 3>& r) {
  double ax = std::abs(r[0]), ay = std::abs(r[1]), az = std::abs(r[2]);
  int face;
  double sc, tc, m;
  if (ax >= ay && ax >= az) {
    face = r[0] >= 0.0 ? 0 : 1;
    sc = r[0] >= 0.0 ? -r[2] : r[2];
    tc = -r[1];
    m = ax;
  } else if (ay >= az) {
    face = r[1] >= 0.0 ? 2 : 3;
    sc = r[0];
    tc = r[1] >= 0.0 ? r[2] : -r[2];
    m = ay;
  } else {
    face = r[2] >= 0.0 ? 4 : 5;
    sc = r[2] >= 0.0 ? r[0] : -r[0];
    tc = -r[1];
    m = az;
  }
  return {face, 0.5 * (sc / m + 1.0), 0.5 * (tc / m + 1.0)};
}

double texelSolidAngle(int n, int x, int y) {
  // The area on the unit sphere of [0, X] x [0, Y] of the face plane z = 1.
  auto area = [](double X, double Y) { return std::atan2(X * Y, std::sqrt(X * X + Y * Y + 1.0)); };
  double x0 = 2.0 * x / n - 1.0, x1 = 2.0 * (x + 1) / n - 1.0;
  double y0 = 2.0 * y / n - 1.0, y1 = 2.0 * (y + 1) / n - 1.0;
  return area(x0, y0) - area(x0, y1) - area(x1, y0) + area(x1, y1);
}

double mipRoughness(int level, int mipCount) {
  return mipCount > 1 ? static_cast<double>(level) / (mipCount - 1) : 0.0;
}

CubeMap prefilterRadiance(const Environment& env, int baseSize, int mipCount, int samplesPerTexel) {
  int maxMips = 1;
  while ((baseSize >> maxMips) > 0) ++maxMips;
  if (baseSize < 1 || mipCount < 1 || mipCount > maxMips || samplesPerTexel < 1)
    throw std::invalid_argument("prefilterRadiance: need baseSize >= 1, 1 <= mipCount <= " + std::to_string(maxMips) +
                                " and samplesPerTexel >= 1 (got " + std::to_string(baseSize) + ", " +
                                std::to_string(mipCount) + ", " + std::to_string(samplesPerTexel) + ")");
  CubeMap src = sourceCube(env, baseSize);
  CubeMap out;
  out.size = baseSize;
  out.mips.push_back(src.mips[0]);
  for (int level = 1; level < mipCount; ++level) {
    double r = mipRoughness(level, mipCount);
    double alpha = std::max(r * r, 1e-3);  // SUBSTRATE_MIN_ALPHA
    int n = out.mipSize(level);
    // Source texels of at most ~1/3 of the lobe's half-width at half maximum
    // (~1.2 alpha), or the finest there are; beyond nearAngle (2 atan(7 alpha):
    // about 2 % of the GGX lobe's weight lies further out) tiles of 8 x 8
    // texels stand for their texels.
    int sourceLevel = 0;
    double needed = std::max(16.0, std::numbers::pi / (1.2 * alpha));
    for (int j = src.mipCount() - 1; j >= 0; --j)
      if (src.mipSize(j) >= needed) {
        sourceLevel = j;
        break;
      }
    double nearAngle = 2.0 * std::atan(7.0 * alpha);
    if (nearAngle > std::numbers::pi / 3) nearAngle = std::numbers::pi;  // broad lobes: every texel
    double m = src.mipSize(sourceLevel), tiles = 6.0 * std::ceil(m / 8) * std::ceil(m / 8);
    double nearShare = nearAngle >= std::numbers::pi ? 1.0 : 0.5 * (1.0 - std::cos(std::min(std::numbers::pi, nearAngle + 0.25)));
    double cost = 6.0 * n * n * (tiles + nearShare * 6.0 * m * m);
    if (cost <= kDirectBudget)
      out.mips.push_back(convolveDirect(gatherTexels(src, sourceLevel, 8), n, Kernel{alpha * alpha}, 1.0, nearAngle));
    else
      out.mips.push_back(importanceSampleLevel(src, n, ggxLobe(alpha, samplesPerTexel, baseSize)));
  }
  return out;
}

CubeMap irradianceMap(const Environment& env, int size, int sourceSize) {
  if (size < 1 || sourceSize < 1)
    throw std::invalid_argument("irradianceMap: need size >= 1 and sourceSize >= 1 (got " + std::to_string(size) +
                                ", " + std::to_string(sourceSize) + ")");
  CubeMap src = sourceCube(env, sourceSize);
  CubeMap out;
  out.size = size;
  // E = integral of L cos = pi * (the cosine-weighted mean of L).
  out.mips.push_back(convolveDirect(gatherTexels(src, 0, 8), size, Kernel{}, std::numbers::pi, std::numbers::pi));
  return out;
}

std::array<double, 3> sampleCube(const CubeMap& map, const std::array<double, 3>& dir, double lod) {
  CubeCoord c = cubeCoord(dir);
  double l = std::clamp(lod, 0.0, static_cast<double>(map.mipCount() - 1));
  int l0 = static_cast<int>(l);
  double f = l - l0;
  Vec3 a = bilinear(map, l0, c);
  if (f <= 0.0 || l0 + 1 >= map.mipCount()) return a;
  return detail::lerp(a, bilinear(map, l0 + 1, c), f);
}

std::array<double, 3> meanRadiance(const CubeMap& map, int level) {
  int n = map.mipSize(level);
  Vec3 sum{0.0, 0.0, 0.0};
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const float* p = map.texel(level, face, x, y);
        sum = sum + Vec3{p[0], p[1], p[2]} * texelSolidAngle(n, x, y);
      }
  return sum * (1.0 / (4.0 * std::numbers::pi));
}

}  // namespace substratec::preview
