#include "sweep/sweep.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <iterator>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pipeline/generate.h"
#include "gpu/sample_run.h"
#include "reference/reference.h"
#include "storage/pack.h"
#include "sweep/precision.h"

namespace substratec::sweep {

namespace {

constexpr int kProbes = 1024;           // shading points of the error measurement
constexpr uint32_t kProbeSeed = 0x5ee9u;

using V3 = std::array<double, 3>;

/// Linear radiance (rgb per probe) of a material through the double reference:
/// direct light + split-sum environment + emissive, as the forward pass sums them.
std::vector<double> radiance(const CompileResult& r, const std::vector<gpu::Sample>& probes, int diffuseModel,
                             std::vector<std::vector<reference::Closure<double>>>* closures) {
  std::vector<double> out;
  out.reserve(probes.size() * 3);
  for (const gpu::Sample& s : probes) {
    auto m = reference::evaluateMaterial<double>(r, s.geometry, {}, gpu::sampleTexture);
    V3 sum{0, 0, 0};
    for (const auto& c : m.closures) {
      const V3 direct = reference::lightClosure<double>(c, s.geometry.V, s.light, s.radiance, diffuseModel);
      const double NoV = c.N[0] * s.geometry.V[0] + c.N[1] * s.geometry.V[1] + c.N[2] * s.geometry.V[2];
      const V3 viewT = reference::viewThroughput<double>(c, NoV, V3{s.geometry.V[0], s.geometry.V[1], s.geometry.V[2]});
      const V3 env = reference::envSplitSum<double>(c, s.geometry.V, s.prefiltered, s.irradiance, diffuseModel);
      for (int k = 0; k < 3; ++k) sum[k] += direct[k] + viewT[k] * (env[k] + c.emissive[k]);
    }
    out.insert(out.end(), sum.begin(), sum.end());
    if (closures) closures->push_back(std::move(m.closures));
  }
  return out;
}

/// The forward shader's SPIR-V instruction count after the performance passes.
bool forwardInstructions(const CompileResult& r, const Options& options, std::size_t* count, Diagnostics& diags) {
  GenerateOptions o;
  o.hlsl = false;
  o.emit.diffuseModel = options.diffuseModel;
  o.emit.precision = options.precision;
  Generated g = generateFiles(r, o);
  validateGenerated(g, {.optimize = true});
  if (!g.valid) {
    diags.fail("internal compiler error: generated code does not validate\n" + g.failure);
    return false;
  }
  for (const EntryReport& e : g.entries)
    if (e.file.ends_with(".forward.frag")) *count = e.optimizedInstructions;
  return true;
}

}  // namespace

bool nsPerInvocation(gpu::Context& ctx, const CompileResult& r, const EmitOptions& emit, const Options& o, double* ns,
                     Diagnostics& diags) {
  std::vector<uint32_t> spirv;
  auto pipeline = gpu::kernelPipeline(ctx, r, Target::Glsl, KernelMode::Throughput, emit, "throughput", &spirv, diags);
  if (!pipeline) return false;
  const int count = (o.pixels + kernel::kLocalSize - 1) / kernel::kLocalSize * kernel::kLocalSize;
  std::vector<double> times;
  for (int run = 0; run <= o.timedRuns; ++run) {  // run 0 warms up (JIT, caches)
    gpu::Resources res =
        gpu::kernelResources(r.material, pipeline->reflection(), spirv, {}, {}, static_cast<std::size_t>(count) * 4);
    double t = 0;
    if (!ctx.dispatch(*pipeline, res, static_cast<uint32_t>(count / kernel::kLocalSize), 1, 1, diags, &t))
      return false;
    if (run > 0) times.push_back(t / count);
  }
  std::sort(times.begin(), times.end());
  *ns = times[times.size() / 2];
  return true;
}

namespace {

/// Median lavapipe time per shading point of the throughput kernel.
bool nsPerPixel(gpu::Context& ctx, const CompileResult& r, const Options& o, double* ns, Diagnostics& diags) {
  EmitOptions emit;
  emit.diffuseModel = o.diffuseModel;  // the model the errors are measured with
  emit.precision = o.precision;
  return nsPerInvocation(ctx, r, emit, o, ns, diags);
}

/// The colour fields a closure stores, by the layout's field names.
std::vector<std::pair<const V3*, std::string>> storedColours(const reference::Closure<double>& c, const StorageLayout& L,
                                                             int k) {
  std::set<std::string> names;
  for (const LayoutField& f : L.fields) names.insert(f.name);
  const std::string pre = fmt::format("closure{}.", k);
  std::vector<std::pair<const V3*, std::string>> out;
  if (names.count(pre + "diffuse_albedo")) out.push_back({&c.diffuseAlbedo, "diffuse_albedo"});
  if (names.count(pre + "f0")) out.push_back({&c.f0, "f0"});
  if (names.count(pre + "f90")) out.push_back({&c.f90, "f90"});
  if (names.count(pre + "top_transmittance")) out.push_back({&c.topTransmittance, "top_transmittance"});
  if (names.count(pre + "fuzz")) out.push_back({&c.fuzzColor, "fuzz"});
  return out;
}

std::array<double, 3> toLab(const std::array<double, 3>& rgb) {
  const double x = 0.4124564 * rgb[0] + 0.3575761 * rgb[1] + 0.1804375 * rgb[2];
  const double y = 0.2126729 * rgb[0] + 0.7151522 * rgb[1] + 0.0721750 * rgb[2];
  const double z = 0.0193339 * rgb[0] + 0.1191920 * rgb[1] + 0.9503041 * rgb[2];
  auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  const double fx = f(x / 0.95047), fy = f(y), fz = f(z / 1.08883);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace

double relMse(const std::vector<double>& x, const std::vector<double>& y) {
  double sum = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sum += (x[i] - y[i]) * (x[i] - y[i]) / (y[i] * y[i] + 0.01);
  return x.empty() ? 0 : sum / static_cast<double>(x.size());
}

double deltaE2000(const std::array<double, 3>& linearA, const std::array<double, 3>& linearB) {
  return deltaE2000Lab(toLab(linearA), toLab(linearB));
}

double deltaE2000Lab(const std::array<double, 3>& lab1, const std::array<double, 3>& lab2) {
  // Sharma, Wu & Dalal 2005, "The CIEDE2000 color-difference formula".
  const auto [L1, a1, b1] = lab1;
  const auto [L2, a2, b2] = lab2;
  const double C1 = std::hypot(a1, b1), C2 = std::hypot(a2, b2), Cbar = 0.5 * (C1 + C2);
  const double G = 0.5 * (1 - std::sqrt(std::pow(Cbar, 7) / (std::pow(Cbar, 7) + std::pow(25.0, 7))));
  const double a1p = (1 + G) * a1, a2p = (1 + G) * a2;
  const double C1p = std::hypot(a1p, b1), C2p = std::hypot(a2p, b2);
  auto hue = [&](double b, double ap) {
    if (b == 0 && ap == 0) return 0.0;
    double h = std::atan2(b, ap) * 180 / std::numbers::pi;
    return h < 0 ? h + 360 : h;
  };
  const double h1p = hue(b1, a1p), h2p = hue(b2, a2p);
  const double dLp = L2 - L1, dCp = C2p - C1p;
  double dhp = 0;
  if (C1p * C2p != 0) {
    dhp = h2p - h1p;
    if (dhp > 180) dhp -= 360;
    if (dhp < -180) dhp += 360;
  }
  const double dHp = 2 * std::sqrt(C1p * C2p) * std::sin(dhp * std::numbers::pi / 360);
  const double Lbarp = 0.5 * (L1 + L2), Cbarp = 0.5 * (C1p + C2p);
  double hbarp = h1p + h2p;
  if (C1p * C2p != 0) {
    if (std::abs(h1p - h2p) <= 180) hbarp *= 0.5;
    else hbarp = h1p + h2p < 360 ? 0.5 * (h1p + h2p + 360) : 0.5 * (h1p + h2p - 360);
  }
  const double rad = std::numbers::pi / 180;
  const double T = 1 - 0.17 * std::cos((hbarp - 30) * rad) + 0.24 * std::cos(2 * hbarp * rad) +
                   0.32 * std::cos((3 * hbarp + 6) * rad) - 0.20 * std::cos((4 * hbarp - 63) * rad);
  const double dTheta = 30 * std::exp(-std::pow((hbarp - 275) / 25, 2));
  const double Rc = 2 * std::sqrt(std::pow(Cbarp, 7) / (std::pow(Cbarp, 7) + std::pow(25.0, 7)));
  const double Sl = 1 + 0.015 * std::pow(Lbarp - 50, 2) / std::sqrt(20 + std::pow(Lbarp - 50, 2));
  const double Sc = 1 + 0.045 * Cbarp, Sh = 1 + 0.015 * Cbarp * T;
  const double Rt = -std::sin(2 * dTheta * rad) * Rc;
  return std::sqrt(std::pow(dLp / Sl, 2) + std::pow(dCp / Sc, 2) + std::pow(dHp / Sh, 2) +
                   Rt * (dCp / Sc) * (dHp / Sh));
}

bool simplificationSteps(const std::string& path, const std::string& text, const CompileOptions& base,
                         std::vector<Step>* steps, CompileResult* full, Diagnostics& diags) {
  auto compile = [&](const CompileOptions& o) -> std::optional<CompileResult> {
    Diagnostics own(path);
    auto r = compileText(path, text, o, own);
    if (!r) diags = std::move(own);  // the last compile that failed is the one reported
    return r;
  };
  auto whole = compile(unsimplifiedOptions(base));
  CompileOptions own = base;
  own.fullSimplification = false;
  auto first = compile(own);
  CompileOptions collapse = base;
  collapse.budgetOverride.reset();
  collapse.maxClosuresOverride.reset();
  collapse.fullSimplification = true;
  auto all = compile(collapse);
  if (!whole || !first || !all) return false;
  *full = *whole;
  // The authored tree first when the material's own settings simplify it.
  if (!first->steps.empty()) steps->push_back({*whole, kAuthoredLabel, whole->after.bytes()});
  std::set<std::pair<int, int>> seen{{first->after.bytes(), static_cast<int>(first->after.closures.size())}};
  steps->push_back({*first, "full budget", first->budgetBytes});
  for (std::size_t i = 0; i < all->steps.size(); ++i) {
    const SimplifyStep& s = all->steps[i];
    if (s.bytesAfter >= first->after.bytes() && s.closuresAfter >= static_cast<int>(first->after.closures.size()))
      continue;  // a step the material's own budget already took
    CompileOptions o = base;
    o.fullSimplification = false;
    o.budgetOverride = std::max(s.bytesAfter, 8);
    o.maxClosuresOverride = std::max(s.closuresAfter, 1);
    Diagnostics ignored(path);
    auto r = compileText(path, text, o, ignored);
    if (!r) continue;  // only full simplification gets there (below the smallest budget)
    if (!seen.insert({r->after.bytes(), static_cast<int>(r->after.closures.size())}).second) continue;
    steps->push_back({*r, fmt::format("step {}", i + 1), *o.budgetOverride});
  }
  if (seen.insert({all->after.bytes(), static_cast<int>(all->after.closures.size())}).second)
    steps->push_back({*all, "full simplification", all->budgetBytes});
  return true;
}

namespace {

/// The accuracy module's options for the sweep's truths.
accuracy::Options accuracyOptions(const Options& o) {
  accuracy::Options a;
  a.samples = o.truthSamples;
  a.evalSamples = o.truthEvalSamples;
  a.threads = o.truthThreads;
  a.diffuseModel = diffuseModelNumber(o.diffuseModel);
  return a;
}

/// Whether `r` has the authored material's closures (so its truth): it took
/// no simplification step and prices the same.
bool sameClosures(const CompileResult& r, const CompileResult& authored) {
  return r.steps.empty() && r.after.bytes() == authored.after.bytes() &&
         r.after.closures.size() == authored.after.closures.size();
}

}  // namespace

bool measure(gpu::Context& ctx, const std::vector<Step>& steps, const CompileResult& full, const Options& o,
             std::vector<Row>* rows, Diagnostics& diags) {
  const std::vector<gpu::Sample> probes = gpu::makeSamples(kProbes, kProbeSeed);
  const std::vector<double> y = radiance(full, probes, diffuseModelNumber(o.diffuseModel), nullptr);
  const accuracy::Options ao = accuracyOptions(o);
  std::optional<accuracy::Truth> authoredTruth;
  if (o.truthSamples > 0) authoredTruth = accuracy::truthOf(full, ao);
  for (const Step& step : steps) {
    const CompileResult& r = step.result;
    Row row;
    row.label = step.label;
    row.budget = step.budget;
    row.bytes = r.after.bytes();
    row.closures = static_cast<int>(r.after.closures.size());
    row.gpuMeasured = row.closures <= packfmt::kMaxClosures;  // else the storage format cannot hold it
    if (row.gpuMeasured) {
      if (!forwardInstructions(r, o, &row.spirvInstructions, diags)) return false;
      if (!nsPerPixel(ctx, r, o, &row.gpuNsPerPixel, diags)) return false;
    }
    if (row.gpuMeasured && o.precision == Precision::Half) {
      BothPrecisions both;
      if (!runBothPrecisions(ctx, r, Target::Glsl, probes, {}, &both, diags)) return false;
      const PrecisionError e = precisionError(both, gpu::resultStride(r));
      row.relMseVsFloat32 = e.relMse;
      row.maxAbsVsFloat32 = e.maxAbs;
    }
    if (authoredTruth) {
      const accuracy::Analytic analytic = accuracy::analyticOf(r, ao);
      row.vsAuthoredTruth = accuracy::compare(analytic, *authoredTruth);
      row.vsOwnTruth = sameClosures(r, full) ? *row.vsAuthoredTruth
                                             : accuracy::compare(analytic, accuracy::truthOf(r, ao));
    }
    std::vector<std::vector<reference::Closure<double>>> closures;
    const std::vector<double> x = radiance(r, probes, diffuseModelNumber(o.diffuseModel), &closures);
    std::vector<double> abs(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      abs[i] = std::abs(x[i] - y[i]);
      row.maxAbs = std::max(row.maxAbs, abs[i]);
    }
    row.relMse = relMse(x, y);
    row.p99Abs = percentile(abs, 0.99);
    // The packed colours: what the storage's quantizer gives back, at each probe's dither.
    double deSum = 0;
    long deCount = 0;
    for (std::size_t p = 0; p < probes.size(); ++p)
      for (std::size_t k = 0; k < closures[p].size(); ++k)
        for (const auto& [colour, name] : storedColours(closures[p][k], r.after, static_cast<int>(k))) {
          Vec3d clamped;
          for (int c = 0; c < 3; ++c) clamped[c] = std::clamp((*colour)[c], 0.0, 1.0);
          const Vec3d decoded = dequantizeColor(quantizeColor(clamped, probes[p].geometry.dither));
          const double de = deltaE2000(*colour, decoded);
          deSum += de;
          ++deCount;
          row.deltaE2000Max = std::max(row.deltaE2000Max, de);
        }
    row.deltaE2000Mean = deCount ? deSum / static_cast<double>(deCount) : 0;
    rows->push_back(row);
  }
  return true;
}

std::optional<std::size_t> cheapestWithin(const std::vector<Row>& rows, double maxError) {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i].gpuMeasured || !(rows[i].relMse <= maxError)) continue;
    if (!best || rows[i].bytes < rows[*best].bytes ||
        (rows[i].bytes == rows[*best].bytes && rows[i].gpuNsPerPixel < rows[*best].gpuNsPerPixel))
      best = i;
  }
  return best;
}

namespace {
/// Whether the rows carry the half-vs-float32 columns (Options::precision Half).
bool halfColumns(const std::vector<Row>& rows) {
  return std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.relMseVsFloat32.has_value(); });
}
}  // namespace

namespace {

/// A relative error in percent with its sign, or `none`.
std::string percentOr(const std::optional<double>& v, const char* none) {
  return v ? fmt::format("{:+.2f}%", 100 * *v) : std::string(none);
}

/// The worst albedo error and BRDF p95 of a row's comparison, formatted (`none` where absent).
std::pair<std::string, std::string> worstText(const std::optional<accuracy::Comparison>& c, const char* none) {
  if (!c) return {none, none};
  const accuracy::Worst w = accuracy::worstOf(*c);
  return {percentOr(w.relError, none), w.brdfP95 ? fmt::format("{:.2f}%", 100 * *w.brdfP95) : std::string(none)};
}

nlohmann::ordered_json truthJson(const std::optional<accuracy::Comparison>& c) {
  if (!c) return nullptr;
  const accuracy::Worst w = accuracy::worstOf(*c);
  nlohmann::ordered_json j;
  j["worst"] = {{"rel_error", w.relError ? nlohmann::ordered_json(*w.relError) : nlohmann::ordered_json(nullptr)},
                {"rel_error_nov", w.relErrorNoV},
                {"brdf_p95_rel_error", w.brdfP95 ? nlohmann::ordered_json(*w.brdfP95) : nlohmann::ordered_json(nullptr)},
                {"reciprocity_max_ratio", w.reciprocityMaxRatio}};
  const nlohmann::ordered_json full = accuracy::comparisonJson(*c);
  for (auto it = full.begin(); it != full.end(); ++it) j[it.key()] = it.value();
  return j;
}

}  // namespace

std::vector<std::string> cellColumns() {
  return {"spirv_instr", "ns/pixel", "rel_mse", "max_abs", "p99_abs", "dE00_avg", "dE00_max", "alb_vs_gt", "p95_vs_gt",
          "alb_vs_own"};
}

std::vector<std::string> cells(const Row& r) {
  const auto [albTruth, p95Truth] = worstText(r.vsAuthoredTruth, "-");
  const auto [albOwn, p95Own] = worstText(r.vsOwnTruth, "-");
  return {r.gpuMeasured ? std::to_string(r.spirvInstructions) : "-",
          r.gpuMeasured ? fmt::format("{:.1f}", r.gpuNsPerPixel) : "-",
          fmt::format("{:.3e}", r.relMse),
          fmt::format("{:.3e}", r.maxAbs),
          fmt::format("{:.3e}", r.p99Abs),
          fmt::format("{:.3f}", r.deltaE2000Mean),
          fmt::format("{:.3f}", r.deltaE2000Max),
          albTruth,
          p95Truth,
          albOwn};
}

std::string formatTable(const std::string& material, const std::vector<Row>& rows) {
  const bool half = halfColumns(rows);
  std::string s = fmt::format("----- SWEEP - {}{} -----\n", material, half ? " (half precision)" : "");
  s += fmt::format("{:<20} {:>6} {:>5} {:>8} {:>11} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} {:>10} {:>10} {:>10}",
                   "row", "budget", "bytes", "closures", "spirv_instr", "ns/pixel", "rel_mse", "max_abs", "p99_abs",
                   "dE00_avg", "dE00_max", "alb_vs_gt", "p95_vs_gt", "alb_vs_own");
  s += half ? fmt::format(" {:>10} {:>10}\n", "mse_vs_f32", "abs_vs_f32") : "\n";
  for (const Row& r : rows) {
    const std::vector<std::string> c = cells(r);
    s += fmt::format("{:<20} {:>6} {:>5} {:>8} {:>11} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} {:>10} {:>10} {:>10}",
                     r.label, r.budget, r.bytes, r.closures, c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8], c[9]);
    s += half ? fmt::format(" {:>10.3e} {:>10.3e}\n", r.relMseVsFloat32.value_or(0), r.maxAbsVsFloat32.value_or(0))
              : "\n";
  }
  if (std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.vsAuthoredTruth.has_value(); }))
    s += "alb_vs_gt / p95_vs_gt: the worst directional-albedo error over NoV and the worst BRDF p95 against the truth "
         "of the authored material; alb_vs_own: against the truth of the row's own closures (docs/accuracy.md)\n";
  if (std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.gpuMeasured; }))
    s += fmt::format("-: the authored tree holds more than {} closures, which the storage format cannot pack\n",
                     packfmt::kMaxClosures);
  return s;
}

std::string formatJson(const std::string& material, const std::vector<Row>& rows) {
  nlohmann::ordered_json j;
  j["material"] = material;
  if (halfColumns(rows)) j["precision"] = "half";
  j["rows"] = nlohmann::ordered_json::array();
  for (const Row& r : rows) {
    nlohmann::ordered_json row;
    row["label"] = r.label;
    row["budget"] = r.budget;
    row["bytes"] = r.bytes;
    row["closures"] = r.closures;
    row["spirv_instructions"] = r.gpuMeasured ? nlohmann::ordered_json(r.spirvInstructions) : nullptr;
    row["gpu_ns_per_pixel"] = r.gpuMeasured ? nlohmann::ordered_json(r.gpuNsPerPixel) : nullptr;
    row["rel_mse"] = r.relMse;
    row["max_abs"] = r.maxAbs;
    row["p99_abs"] = r.p99Abs;
    row["delta_e2000"] = {{"mean", r.deltaE2000Mean}, {"max", r.deltaE2000Max}};
    row["vs_authored_truth"] = truthJson(r.vsAuthoredTruth);
    row["vs_own_truth"] = truthJson(r.vsOwnTruth);
    if (r.relMseVsFloat32) row["rel_mse_vs_float32"] = *r.relMseVsFloat32;
    if (r.maxAbsVsFloat32) row["max_abs_vs_float32"] = *r.maxAbsVsFloat32;
    j["rows"].push_back(row);
  }
  return j.dump(2) + "\n";
}

std::string formatCsv(const std::vector<Row>& rows) {
  const bool half = halfColumns(rows);
  std::string s =
      "label,budget,bytes,closures,spirv_instructions,gpu_ns_per_pixel,rel_mse,max_abs,p99_abs,delta_e2000_mean,"
      "delta_e2000_max,albedo_rel_error_vs_truth,brdf_p95_vs_truth,albedo_rel_error_vs_own_truth,brdf_p95_vs_own_truth";
  s += half ? ",rel_mse_vs_float32,max_abs_vs_float32\n" : "\n";
  auto worst = [](const std::optional<accuracy::Comparison>& c) -> std::pair<std::string, std::string> {
    if (!c) return {"", ""};
    const accuracy::Worst w = accuracy::worstOf(*c);
    return {w.relError ? fmt::format("{:.6e}", *w.relError) : "", w.brdfP95 ? fmt::format("{:.6e}", *w.brdfP95) : ""};
  };
  for (const Row& r : rows) {
    const auto [albTruth, p95Truth] = worst(r.vsAuthoredTruth);
    const auto [albOwn, p95Own] = worst(r.vsOwnTruth);
    s += fmt::format("{},{},{},{},{},{},{:.6e},{:.6e},{:.6e},{:.4f},{:.4f},{},{},{},{}", r.label, r.budget, r.bytes,
                     r.closures, r.gpuMeasured ? std::to_string(r.spirvInstructions) : "",
                     r.gpuMeasured ? fmt::format("{:.3f}", r.gpuNsPerPixel) : "", r.relMse, r.maxAbs, r.p99Abs,
                     r.deltaE2000Mean, r.deltaE2000Max, albTruth, p95Truth, albOwn, p95Own);
    s += half ? fmt::format(",{:.6e},{:.6e}\n", r.relMseVsFloat32.value_or(0), r.maxAbsVsFloat32.value_or(0)) : "\n";
  }
  return s;
}

namespace {

/// Code points of UTF-8 text (continuation bytes are not counted).
std::size_t codePoints(std::string_view text) {
  std::size_t n = 0;
  for (unsigned char c : text) n += (c & 0xC0) != 0x80;
  return n;
}

/// `text` with XML's five special characters escaped.
std::string xmlEscaped(std::string_view text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

/// At most `maxPoints` code points of `text`, the last one an ellipsis when cut.
std::string truncatedTo(std::string_view text, std::size_t maxPoints) {
  if (codePoints(text) <= maxPoints) return std::string(text);
  std::string out;
  std::size_t points = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if ((c & 0xC0) != 0x80 && ++points == maxPoints) break;
    out += text[i];
  }
  return out + "\u2026";
}

}  // namespace

double plotTextWidth(std::string_view text, double fontSize) {
  return kPlotGlyphWidth * fontSize * static_cast<double>(codePoints(text));
}

std::string plotSvg(const Plot& plot) {
  // Error (log10, floored at 1e-8: the full budget may be exact) against cost.
  // Every text is placed from its estimated
  // extent (plotTextWidth; a glyph rises a font size above its baseline and
  // descends a quarter of one below it) so that it
  // stays inside the canvas: labels of points near the right edge end left of
  // their point, and a title longer than the canvas is cut with an ellipsis.
  constexpr double W = kPlotWidth, H = kPlotHeight, L = 70, R = 20, T = 40, B = 50;
  constexpr double kFont = 11, kTitleFont = 14, kPad = 2;
  double xMin = 1e300, xMax = -1e300, yMin = 1e300, yMax = -1e300;
  // Non-finite or huge values are pinned to the axes' ends rather than
  // stretching them (or making every coordinate NaN).
  auto ly = [](double e) { return std::isnan(e) ? 8.0 : std::clamp(std::log10(std::max(e, 1e-8)), -8.0, 8.0); };
  auto lx = [](double ns) { return std::isfinite(ns) ? std::clamp(ns, 0.0, 1e12) : 1e12; };
  for (const PlotPoint& p : plot.points) {
    xMin = std::min(xMin, lx(p.cost));
    xMax = std::max(xMax, lx(p.cost));
    yMin = std::min(yMin, ly(p.error));
    yMax = std::max(yMax, ly(p.error));
  }
  if (plot.points.empty()) xMin = xMax = yMin = yMax = 0;
  if (xMax - xMin < 1e-9) xMax = xMin + 1;
  yMin = std::floor(yMin);
  yMax = std::max(std::ceil(yMax), yMin + 1);
  auto px = [&](double x) { return L + (lx(x) - xMin) / (xMax - xMin) * (W - L - R); };
  auto py = [&](double y) { return T + (yMax - y) / (yMax - yMin) * (H - T - B); };
  // A text at (x, y) with `anchor`, moved inside the canvas from its extent.
  auto text = [&](double x, double y, const std::string& content, double font, const char* anchor,
                  const std::string& extra = "") {
    const double w = plotTextWidth(content, font);
    const double shift = std::string_view(anchor) == "middle" ? w / 2 : std::string_view(anchor) == "end" ? w : 0;
    x = std::clamp(x - shift, kPad, std::max(kPad, W - kPad - w)) + shift;
    y = std::clamp(y, font + kPad, H - kPad - 0.25 * font);  // ascent above the baseline, descent below
    const std::string anchorAttr =
        std::string_view(anchor) == "start" ? "" : fmt::format(" text-anchor=\"{}\"", anchor);
    const std::string fontAttr = font == kFont ? "" : fmt::format(" font-size=\"{}\"", font);
    return fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\"{}{}{}>{}</text>\n", x, y, fontAttr, anchorAttr, extra,
                       xmlEscaped(content));
  };
  std::string s = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"sans-serif\" font-size=\"{2}\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
      W, H, kFont);
  const std::string suffix = ": error against cost";
  const auto titlePoints = static_cast<std::size_t>((W - 2 * kPad) / (kPlotGlyphWidth * kTitleFont));
  const std::size_t suffixPoints = codePoints(suffix);
  s += text(L, 20, truncatedTo(plot.title, titlePoints > suffixPoints + 1 ? titlePoints - suffixPoints : 1) + suffix,
            kTitleFont, "start");
  s += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"black\"/>\n", L, H - B, W - R);
  s += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"black\"/>\n", L, T, H - B);
  s += text((L + W - R) / 2, H - 12, plot.costAxis, kFont, "middle");
  // Rotated by -90 degrees about its anchor: its extent runs up and down from
  // (16, middle), its glyphs' height to the left of x = 16.
  s += fmt::format("<text x=\"16\" y=\"{0}\" transform=\"rotate(-90 16 {0})\" text-anchor=\"middle\">{1} (log10)</text>\n",
                   (T + H - B) / 2, xmlEscaped(plot.errorAxis));
  for (int e = static_cast<int>(yMin); e <= static_cast<int>(yMax); ++e)
    s += text(L - 6, py(e) + 4, fmt::format("1e{}", e), kFont, "end");
  for (int k = 0; k <= 4; ++k) {
    const double x = xMin + (xMax - xMin) * k / 4;
    s += text(L + (W - L - R) * k / 4, H - B + 16, fmt::format("{:.0f}", x), kFont, "middle");
  }
  for (const PlotPoint& p : plot.points) {
    const double x = px(p.cost), y = py(ly(p.error));
    s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"4\" fill=\"#c0392b\"/>\n", x, y);
    // Right of the point when it fits, else left of it.
    const bool fitsRight = x + 6 + plotTextWidth(p.label, kFont) <= W - kPad;
    s += fitsRight ? text(x + 6, y - 6, p.label, kFont, "start") : text(x - 6, y - 6, p.label, kFont, "end");
  }
  s += "</svg>\n";
  return s;
}

std::string plotSvg(const std::string& material, const std::vector<Row>& rows) {
  Plot plot{material, "lavapipe ns per shading point", "rel_mse vs the authored tree", {}};
  for (const Row& r : rows)  // a row without code has no time: not plotted
    if (r.gpuMeasured)
      plot.points.push_back(
          {fmt::format("{} ({} B, {} cl)", r.label, r.bytes, r.closures), r.gpuNsPerPixel, r.relMse});
  return plotSvg(plot);
}

}  // namespace substratec::sweep
