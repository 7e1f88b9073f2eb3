#include "accuracy/fog_accuracy.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "accuracy/accuracy.h"
#include "ir/value_eval.h"
#include "reference/fog_cloud.h"

namespace substratec::accuracy {

namespace {

using D3 = std::array<double, 3>;

/// The fog cloud's pins at `p`, sanitized as substrate_fog_cloud_make does.
reference::FogCloudSample sampleAt(const Material& m, const D3& p) {
  const Slab& fog = m.slabs[m.nodes[m.root].slab];
  EvalPoint at;
  at.position = p;
  ValueId last = 0;
  for (SlabPin pin : {SlabPin::Albedo, SlabPin::Extinction, SlabPin::Emissive, SlabPin::AmbientOcclusion})
    last = std::max(last, fog.pin(pin));
  const auto values = evaluateDag(m, at, last);
  auto v3 = [&](SlabPin pin) {
    const auto& v = values[fog.pin(pin)];
    return D3{v[0], v[1], v[2]};
  };
  return reference::fogCloudMake(v3(SlabPin::Albedo), v3(SlabPin::Extinction), v3(SlabPin::Emissive),
                                 values[fog.pin(SlabPin::AmbientOcclusion)][0]);
}

struct Ray {
  D3 origin, direction;
  double length;
};

/// Ray k of n: a Fibonacci direction, through a point within a tenth of the
/// extent of the centre, from where it enters the cube to where it leaves.
Ray rayOf(int k, int n, double extent) {
  const double golden = 2.399963229728653;  // pi (3 - sqrt 5)
  const double z = 1.0 - (2.0 * k + 1.0) / n, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = golden * k;
  const D3 d{r * std::cos(phi), r * std::sin(phi), z};
  const D3 through{0.1 * extent * std::sin(1.7 * k), 0.1 * extent * std::cos(2.3 * k), 0.1 * extent * std::sin(0.9 * k)};
  double t0 = -1e300, t1 = 1e300;  // slab test against [-extent, extent]^3
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) continue;
    double u = (-extent - through[a]) / d[a], v = (extent - through[a]) / d[a];
    t0 = std::max(t0, std::min(u, v));
    t1 = std::min(t1, std::max(u, v));
  }
  return {{through[0] + t0 * d[0], through[1] + t0 * d[1], through[2] + t0 * d[2]}, d, std::max(0.0, t1 - t0)};
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

FogReport fogAccuracy(const Material& m, int bytesPerFroxel, const FogOptions& o) {
  FogReport rep;
  rep.material = m.name;
  rep.bytesPerFroxel = bytesPerFroxel;
  rep.extent = o.extent;
  rep.truthSteps = o.truthSteps;
  const D3 light{o.light, o.light, o.light}, ambient{o.ambient, o.ambient, o.ambient};
  auto exact = [&](const D3& p) { return sampleAt(m, p); };
  auto stored = [&](const D3& p) { return reference::fogCloudUnpack(reference::fogCloudPack(sampleAt(m, p))); };
  std::vector<Ray> rays;
  std::vector<reference::FogMarch> truth;
  for (int k = 0; k < o.rays; ++k) {
    const Ray ray = rayOf(k, o.rays, o.extent);
    const auto t = reference::marchFogCloud(exact, ray.origin, ray.direction, ray.length, o.truthSteps, light, ambient);
    if (luminance(t.radiance) <= 0) continue;  // nothing to compare against: relative errors need a denominator
    rays.push_back(ray);
    truth.push_back(t);
  }
  rep.rays = static_cast<int>(rays.size());
  for (int n : o.steps) {
    FogRow row;
    row.steps = n;
    std::vector<double> errors;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Ray& ray = rays[i];
      const auto a = reference::marchFogCloud(exact, ray.origin, ray.direction, ray.length, n, light, ambient);
      const auto q = reference::marchFogCloud(stored, ray.origin, ray.direction, ray.length, n, light, ambient);
      const double ref = luminance(truth[i].radiance);
      errors.push_back(std::abs(luminance(a.radiance) - ref) / ref);
      row.maxThroughputError = std::max(row.maxThroughputError, std::abs(luminance(a.throughput) - luminance(truth[i].throughput)));
      row.payloadMaxError = std::max(row.payloadMaxError, std::abs(luminance(q.radiance) - ref) / ref);
    }
    row.medianError = median(errors);
    row.maxError = errors.empty() ? 0 : *std::max_element(errors.begin(), errors.end());
    rep.rows.push_back(row);
  }
  return rep;
}

std::string formatFogTable(const FogReport& r) {
  std::string s = fmt::format(
      "{}: a volume (volumetric fog cloud), {} bytes per froxel; {} rays across the cube of half side {} m, "
      "radiance against a {}-step march\n",
      r.material, r.bytesPerFroxel, r.rays, r.extent, r.truthSteps);
  s += fmt::format("{:>6}  {:>14}  {:>14}  {:>18}  {:>20}\n", "steps", "median rel err", "max rel err",
                   "max throughput err", "max rel err (12 B)");
  for (const FogRow& row : r.rows)
    s += fmt::format("{:>6}  {:>14.3e}  {:>14.3e}  {:>18.3e}  {:>20.3e}\n", row.steps, row.medianError, row.maxError,
                     row.maxThroughputError, row.payloadMaxError);
  return s;
}

nlohmann::ordered_json fogJson(const FogReport& r) {
  nlohmann::ordered_json j;
  j["material"] = r.material;
  j["domain"] = "volume";
  j["bytes_per_froxel"] = r.bytesPerFroxel;
  j["rays"] = r.rays;
  j["extent"] = r.extent;
  j["truth_steps"] = r.truthSteps;
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const FogRow& row : r.rows)
    rows.push_back({{"steps", row.steps},
                    {"median_rel_error", row.medianError},
                    {"max_rel_error", row.maxError},
                    {"max_throughput_error", row.maxThroughputError},
                    {"payload_max_rel_error", row.payloadMaxError}});
  j["rows"] = rows;
  return j;
}

}  // namespace substratec::accuracy
