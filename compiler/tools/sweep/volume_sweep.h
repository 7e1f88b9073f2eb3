// `substratec sweep` of a volume (a volumetric fog cloud, isVolumeMaterial):
// nothing simplifies a volume, so what a renderer trades is its march. For
// each step count of accuracy::FogOptions: the lavapipe time per ray of the
// volume's cost kernel (KernelMode::Throughput with that many steps,
// kernel_emitter.h) against the march's error (accuracy/fog_accuracy.h: the
// same cube, against a 4,096-step march, and through the 12-byte payload).
#pragma once
#include <string>
#include <vector>

#include "accuracy/fog_accuracy.h"
#include "gpu/harness.h"
#include "pipeline/pipeline.h"
#include "sweep/sweep.h"

namespace substratec::sweep {

struct VolumeRow {
  int steps = 0;
  double gpuNsPerRay = 0;  // median of the timed dispatches (Options::pixels rays each)
  accuracy::FogRow error;  // the march's error at this step count
};

/// Times and measures every step count. False, with errors reported, on a failure.
bool measureVolume(gpu::Context& gpu, const CompileResult& r, const Options& options, std::vector<VolumeRow>* rows,
                   Diagnostics& diags);

/// Outputs: a text table and `{"material", "domain": "volume", "rows": [...]}`.
std::string formatVolumeTable(const std::string& material, const std::vector<VolumeRow>& rows);
std::string formatVolumeJson(const std::string& material, const std::vector<VolumeRow>& rows);

/// The SVG plot of the march's largest relative error (log scale) against
/// lavapipe ns per ray, one point per step count (sweep.h's Plot).
std::string plotVolumeSvg(const std::string& material, const std::vector<VolumeRow>& rows);

}  // namespace substratec::sweep
