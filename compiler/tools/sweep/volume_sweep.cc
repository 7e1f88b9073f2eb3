#include "sweep/volume_sweep.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "emit/kernel_emitter.h"

namespace substratec::sweep {

bool measureVolume(gpu::Context& ctx, const CompileResult& r, const Options& o, std::vector<VolumeRow>* rows,
                   Diagnostics& diags) {
  const accuracy::FogReport error = accuracy::fogAccuracy(r.material, r.after.bytes());
  for (const accuracy::FogRow& e : error.rows) {
    VolumeRow row;
    row.steps = e.steps;
    row.error = e;
    EmitOptions emit;
    emit.volumeSteps = e.steps;
    if (!nsPerInvocation(ctx, r, emit, o, &row.gpuNsPerRay, diags)) return false;
    rows->push_back(row);
  }
  return true;
}

std::string formatVolumeTable(const std::string& material, const std::vector<VolumeRow>& rows) {
  std::string s = fmt::format(
      "{}: a volume; cost per ray through the cube of half side {} m (lavapipe) against the march's error "
      "(`accuracy`: a 4096-step march)\n",
      material, kernel::kVolumeCostExtent);
  s += fmt::format("{:>6}  {:>10}  {:>14}  {:>14}  {:>20}\n", "steps", "ns/ray", "median rel err", "max rel err",
                   "max rel err (12 B)");
  for (const VolumeRow& r : rows)
    s += fmt::format("{:>6}  {:>10.1f}  {:>14.3e}  {:>14.3e}  {:>20.3e}\n", r.steps, r.gpuNsPerRay, r.error.medianError,
                     r.error.maxError, r.error.payloadMaxError);
  return s;
}

std::string formatVolumeJson(const std::string& material, const std::vector<VolumeRow>& rows) {
  nlohmann::ordered_json j;
  j["material"] = material;
  j["domain"] = "volume";
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const VolumeRow& r : rows)
    a.push_back({{"steps", r.steps},
                 {"gpu_ns_per_ray", r.gpuNsPerRay},
                 {"median_rel_error", r.error.medianError},
                 {"max_rel_error", r.error.maxError},
                 {"payload_max_rel_error", r.error.payloadMaxError}});
  j["rows"] = a;
  return j.dump(2) + "\n";
}

std::string plotVolumeSvg(const std::string& material, const std::vector<VolumeRow>& rows) {
  Plot plot{material, "lavapipe ns per ray", "max rel error vs a 4096-step march", {}};
  for (const VolumeRow& r : rows) plot.points.push_back({fmt::format("{} steps", r.steps), r.gpuNsPerRay, r.error.maxError});
  return plotSvg(plot);
}

}  // namespace substratec::sweep
