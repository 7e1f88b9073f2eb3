// Procedural HDR environments for `substratec preview`: analytic radiance
// functions of a world-space direction (+Y up), so that nothing has to be
// downloaded or shipped. "studio" (the default): soft boxes in a dark room;
// "sky": a clear sky with a sun; "white": radiance 1 everywhere (furnace).
#pragma once
#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

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

/// The names makeEnvironment accepts, default first.
std::vector<std::string> environmentNames();

/// The environment called `name`; throws std::invalid_argument naming the
/// known environments for any other name.
Environment makeEnvironment(const std::string& name);

/// Unit direction toward the sun of the "sky" environment, and the angular
/// radius of its disc in radians (tests keep away from it).
std::array<double, 3> skySunDirection();
double skySunAngularRadius();

}  // namespace substratec::preview
