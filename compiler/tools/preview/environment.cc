// The procedural environments of `substratec preview` (environment.h). Every
// term is a smooth, bounded function of the direction, so the radiance is
// finite and non-negative everywhere, the sun's centre included.
#include "preview/environment.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>

#include "image/radiance.h"
#include "preview/preview_math.h"

namespace substratec::preview {

using namespace detail;  // Vec3 and its operators (not found by ADL on std::array)

namespace {

// Linear-sRGB colours of black bodies, normalised to luminance 1 (Planck's
// law through the CIE 1931 observer, Wyman et al. 2013 fit).
constexpr Vec3 kTungsten3200{1.6665, 0.8701, 0.3245};
constexpr Vec3 kDaylight5600{1.1299, 0.9736, 0.8798};
constexpr Vec3 kShade7500{0.9741, 0.9901, 1.1751};

// A soft box: a rectangle on the plane at distance 1 along `centre`, with
// half-extents (halfU, halfV) along the horizontal axis u and the axis v
// completing it, edges blurred over +-`soft` (same units), of radiance
// `luminance * colour`.
struct SoftBox {
  Vec3 centre, u, v, radiance;
  double halfU, halfV, soft;

  SoftBox(const Vec3& towards, double hu, double hv, double softness, const Vec3& colour, double luminance)
      : centre(detail::normalize(towards)), radiance(colour * luminance), halfU(hu), halfV(hv), soft(softness) {
    u = detail::normalize(detail::cross(Vec3{0.0, 1.0, 0.0}, centre));
    v = detail::cross(centre, u);
  }

  /// Coverage in [0, 1] of direction d by the box (0 behind it).
  double coverage(const Vec3& d) const {
    double c = detail::dot(d, centre);
    if (c <= 1e-3) return 0.0;
    double x = std::abs(detail::dot(d, u)) / c;
    double y = std::abs(detail::dot(d, v)) / c;
    return (1.0 - detail::smoothstep(halfU - soft, halfU + soft, x)) *
           (1.0 - detail::smoothstep(halfV - soft, halfV + soft, y));
  }
};

// "studio": a dark grey room lit by three large soft boxes — a warm key
// (3200 K, front left, above), a cool fill (7500 K, right, low) and a daylight
// strip (5600 K, above, behind) — over a floor that bounces their light.
Vec3 studioRadiance(const Vec3& d) {
  static const SoftBox kBoxes[] = {
      SoftBox({-0.55, 0.45, 0.70}, 0.45, 0.35, 0.08, kTungsten3200, 12.0),
      SoftBox({0.85, 0.10, 0.45}, 0.30, 0.50, 0.08, kShade7500, 5.0),
      SoftBox({0.15, 0.75, -0.65}, 0.60, 0.12, 0.05, kDaylight5600, 16.0),
  };
  // Walls: dark grey, a little brighter toward the ceiling.
  double y = d[1];
  Vec3 wall = Vec3{1.0, 1.0, 1.0} * (0.03 + 0.015 * detail::clamp01(y));
  // Floor: a warm grey lit from above, brightest straight down, fading into the
  // walls toward the horizon.
  Vec3 floor = Vec3{1.0, 0.95, 0.88} * (0.12 + 0.06 * detail::clamp01(-y));
  Vec3 L = detail::lerp(wall, floor, detail::smoothstep(0.0, 0.25, -y));
  for (const SoftBox& b : kBoxes) {
    double k = b.coverage(d);
    if (k > 0.0) L = detail::lerp(L, b.radiance, k);
  }
  return L;
}

// "sky": sun 30 degrees high, 40 degrees left of +Z toward -X.
const Vec3 kSunDirection = [] {
  double el = 30.0 * std::numbers::pi / 180.0, az = 40.0 * std::numbers::pi / 180.0;
  return detail::normalize(Vec3{-std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)});
}();
constexpr double kSunAngularRadius = 0.25 * std::numbers::pi / 180.0;  // a 0.5 degree disc
constexpr double kSunRadiance = 2.0e3;
constexpr Vec3 kSunColour{1.20, 0.96, 0.75};  // about 4800 K, luminance ~1

// Zenith blue over horizon haze (exponential in the height of the direction),
// a sun disc with limb darkening, an aureole around it, and a dark ground that
// fades into the haze at the horizon.
Vec3 skyRadiance(const Vec3& d) {
  constexpr Vec3 kZenith{0.10, 0.24, 0.62};
  constexpr Vec3 kHaze{0.85, 0.90, 0.98};
  constexpr Vec3 kGround{0.10, 0.09, 0.075};
  double y = d[1];
  Vec3 sky = detail::lerp(kZenith, kHaze, std::exp(-std::max(y, 0.0) / 0.2));
  if (y < 0.0) return detail::lerp(sky, kGround, detail::smoothstep(0.0, 0.15, -y));
  double cosAngle = std::min(std::max(detail::dot(d, kSunDirection), -1.0), 1.0);
  double angle = std::acos(cosAngle);
  // Aureole (forward scattering by the haze), only above the horizon.
  double glow = 6.0 * std::exp(-angle / 0.05) + 0.4 * std::exp(-angle / 0.4);
  Vec3 L = sky + kSunColour * (glow * detail::smoothstep(0.0, 0.05, y));
  if (angle < kSunAngularRadius * 1.05) {
    double rho = std::min(angle / kSunAngularRadius, 1.0);
    double limb = 1.0 - 0.5 * (1.0 - std::sqrt(1.0 - rho * rho));  // centre 1, edge 0.5
    double edge = 1.0 - detail::smoothstep(0.95, 1.05, angle / kSunAngularRadius);
    L = L + kSunColour * (kSunRadiance * limb * edge);
  }
  return L;
}

Vec3 whiteRadiance(const Vec3&) { return {1.0, 1.0, 1.0}; }

/// `img` box-averaged by integer factors until it is at most
/// kMaxLatLongWidth wide (and its height at most half that): the cube maps
/// sample the environment every 0.006 rad or so, which then still visits
/// every texel, so a sun smaller than a texel keeps its energy.
image::RgbF reduceLatLong(image::RgbF img) {
  const std::uint32_t fx = (img.width + kMaxLatLongWidth - 1) / kMaxLatLongWidth;
  const std::uint32_t fy = (img.height + kMaxLatLongWidth / 2 - 1) / (kMaxLatLongWidth / 2);
  const std::uint32_t f = std::max(fx, fy);
  if (f <= 1) return img;
  image::RgbF out;
  out.width = std::max<std::uint32_t>(1, img.width / f);
  out.height = std::max<std::uint32_t>(1, img.height / f);
  out.rgb.assign(std::size_t{out.width} * out.height * 3, 0.0f);
  for (std::uint32_t y = 0; y < out.height; ++y)
    for (std::uint32_t x = 0; x < out.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double sum = 0;
        std::uint32_t n = 0;
        for (std::uint32_t sy = y * f; sy < std::min(img.height, (y + 1) * f); ++sy)
          for (std::uint32_t sx = x * f; sx < std::min(img.width, (x + 1) * f); ++sx, ++n)
            sum += img.rgb[(std::size_t{sy} * img.width + sx) * 3 + c];
        out.rgb[(std::size_t{y} * out.width + x) * 3 + c] = static_cast<float>(sum / std::max<std::uint32_t>(n, 1));
      }
  return out;
}

}  // namespace

bool isEnvironmentFile(const std::string& name) {
  if (name.size() < 5) return false;
  std::string ext = name.substr(name.size() - 4);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".hdr";
}

std::array<double, 2> latLongCoordinates(const std::array<double, 3>& d) {
  const double u = std::atan2(d[0], -d[2]) / (2 * std::numbers::pi) + 0.5;
  const double v = std::acos(std::clamp(d[1], -1.0, 1.0)) / std::numbers::pi;
  return {u, v};
}

Environment latLongEnvironment(const std::string& name, image::RgbF img) {
  auto map = std::make_shared<const image::RgbF>(reduceLatLong(std::move(img)));
  return Environment(name, [map](const Vec3& d) -> Vec3 {
    // Bilinear between texel centres: repeating around the horizon, clamped at the poles.
    const auto [u, v] = latLongCoordinates(d);
    const double w = map->width, h = map->height;
    const double x = u * w - 0.5, y = std::clamp(v * h - 0.5, 0.0, h - 1);
    const double x0 = std::floor(x), y0 = std::floor(y), tx = x - x0, ty = y - y0;
    auto at = [&](double xx, double yy, int c) {
      const auto ix = static_cast<std::size_t>((static_cast<long long>(xx) % map->width + map->width) % map->width);
      const auto iy = static_cast<std::size_t>(std::min(yy, h - 1));
      return static_cast<double>(map->rgb[(iy * map->width + ix) * 3 + c]);
    };
    Vec3 L{};
    for (int c = 0; c < 3; ++c)
      L[c] = (at(x0, y0, c) * (1 - tx) + at(x0 + 1, y0, c) * tx) * (1 - ty) +
             (at(x0, y0 + 1, c) * (1 - tx) + at(x0 + 1, y0 + 1, c) * tx) * ty;
    return L;
  });
}

std::vector<std::string> environmentNames() { return {"studio", "sky", "white"}; }

Environment makeEnvironment(const std::string& name) {
  if (name == "studio") return Environment(name, studioRadiance);
  if (name == "sky") return Environment(name, skyRadiance, {{kSunDirection, kSunAngularRadius * 1.05}});
  if (name == "white") return Environment(name, whiteRadiance);
  if (isEnvironmentFile(name)) {
    image::RgbF img;
    std::string why;
    if (!image::loadRadiance(name, &img, &why)) throw std::runtime_error(name + ": " + why);
    return latLongEnvironment(name, std::move(img));
  }
  std::string known;
  for (const std::string& n : environmentNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown environment '" + name + "' (known: " + known + ")");
}

std::array<double, 3> skySunDirection() { return kSunDirection; }
double skySunAngularRadius() { return kSunAngularRadius; }

}  // namespace substratec::preview
