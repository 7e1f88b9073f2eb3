// `substratec accuracy` for a volume (a volumetric fog cloud, isVolumeMaterial):
// a volume has no BRDF; what a renderer cheapens is the march. Rays cross a
// cube around the origin; each is marched with N equal steps (the runtime's
// step, reference/fog_cloud.h, in double) and compared with the same ray
// marched with kTruthSteps steps (converged: the step is exact for a constant
// medium and second-order for a varying one). The "payload" column marches N
// steps through samples stored in the 12-byte froxel payload and decoded
// (quantization's own error, on top of the steps'). Speed against error: the
// cost of a march is its step count.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "ir/material.h"

namespace substratec::accuracy {

struct FogOptions {
  double extent = 2.0;        // the cube's half side (m), centred at the origin
  int rays = 64;              // through the cube, Fibonacci directions, each through a point near the centre
  std::vector<int> steps = {4, 8, 16, 32, 64, 128};
  int truthSteps = 4096;
  double light = 1.0;         // in-scattered radiance (light x phase x visibility), grey
  double ambient = 0.5;       // ambient radiance, grey (times the sample's ambient occlusion)
};

struct FogRow {
  int steps = 0;
  double medianError = 0, maxError = 0;  // relative radiance error (luminance) against the truth
  double maxThroughputError = 0;         // absolute, luminance
  double payloadMaxError = 0;            // the same march through decoded froxel samples
};

struct FogReport {
  std::string material;
  int bytesPerFroxel = 0;
  int rays = 0;          // rays compared (those whose truth radiance is not 0)
  double extent = 0;
  int truthSteps = 0;
  std::vector<FogRow> rows;
};

/// Marches `m` (a volume) as FogOptions says; every pin evaluated in double at
/// each sample point with the inputs at their defaults.
FogReport fogAccuracy(const Material& m, int bytesPerFroxel, const FogOptions& options = {});
std::string formatFogTable(const FogReport& r);
nlohmann::ordered_json fogJson(const FogReport& r);

}  // namespace substratec::accuracy
