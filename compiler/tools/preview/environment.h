// Procedural HDR environments for `substratec preview`: analytic radiance
// functions of a world-space direction (+Y up), so that nothing has to be
// downloaded or shipped. "studio" (the default): soft boxes in a dark room;
// "sky": a clear sky with a sun; "white": radiance 1 everywhere (furnace).
// Or an image: a Radiance HDR file in the lat-long layout (--env FILE.hdr).
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "image/radiance.h"

namespace substratec::preview {

/// The environment `substratec preview` uses without --env.
inline constexpr const char* kDefaultEnvironment = "studio";

/// A feature smaller than a cube texel (a sun): texels near it are
/// integrated with many more samples so that its energy is kept.
struct Hotspot {
  std::array<double, 3> direction;  // unit
  double angularRadius;             // radians, of the region to refine
};

/// An analytic environment: linear HDR radiance (finite, >= 0) per direction.
class Environment {
 public:
  using RadianceFn = std::function<std::array<double, 3>(const std::array<double, 3>&)>;
  Environment(std::string name, RadianceFn fn, std::vector<Hotspot> hotspots = {})
      : name_(std::move(name)), fn_(std::move(fn)), hotspots_(std::move(hotspots)) {}

  const std::string& name() const { return name_; }
  /// Radiance arriving from world-space unit direction `unitDir` (+Y up),
  /// linear Rec.709 primaries.
  std::array<double, 3> radiance(const std::array<double, 3>& unitDir) const { return fn_(unitDir); }
  /// Its features smaller than a texel (everything else varies smoothly).
  const std::vector<Hotspot>& hotspots() const { return hotspots_; }

 private:
  std::string name_;
  RadianceFn fn_;
  std::vector<Hotspot> hotspots_;
};

/// The names of the procedural environments, default first.
std::vector<std::string> environmentNames();

/// True for an environment given as a file rather than a name: a path that
/// ends in ".hdr" (any case).
bool isEnvironmentFile(const std::string& name);

/// The environment called `name`, or (isEnvironmentFile) read from that
/// Radiance file; throws std::invalid_argument naming the known environments
/// for any other name, std::runtime_error ("PATH: why") for a file that
/// cannot be read or decoded.
Environment makeEnvironment(const std::string& name);

/// Lat-long images wider than this are box-averaged down to it first.
inline constexpr std::uint32_t kMaxLatLongWidth = 512;

/// The (u, v) in [0, 1] of direction `d` in a lat-long image, MaterialX's
/// convention (its viewer's and shaders' mx_latlong_projection): v = 0 is
/// straight up (+Y, the image's top row), v = 1 straight down; u = 0.5 is
/// -Z (looking away from a camera on +Z), u grows toward +X.
std::array<double, 2> latLongCoordinates(const std::array<double, 3>& d);

/// The environment of a lat-long radiance image (linear, finite, >= 0),
/// sampled bilinearly between texel centres (repeating in u, clamped in v).
Environment latLongEnvironment(const std::string& name, image::RgbF img);

/// Unit direction toward the sun of the "sky" environment, and the angular
/// radius of its disc in radians (tests keep away from it).
std::array<double, 3> skySunDirection();
double skySunAngularRadius();

}  // namespace substratec::preview
