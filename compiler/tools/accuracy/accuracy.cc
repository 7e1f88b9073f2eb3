// The accuracy metric (accuracy.h; docs/accuracy.md, "The accuracy metric"):
// the analytic model's figures (reference::envIntegrated, lightClosure) and the
// Monte Carlo truth's (reference::groundTruthAlbedo, groundTruthEstimate) at the
// views of kNoV, and their comparison. Every evaluation is independent and has
// its own seed (splitmix64 of the options' seed and its index), so the threads
// only change the order in which they are computed, never a bit of a result.
#include "accuracy/accuracy.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <numbers>
#include <thread>
#include <type_traits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "reference/hair.h"
#include "reference/hair_truth.h"
#include "util/random.h"

namespace substratec::accuracy {

namespace {

/// Runs task(i) for i in [0, n) on `threads` threads (0: the machine's); each
/// task writes only its own slot of the caller's results.
void parallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& task) {
  std::size_t workers = threads > 0 ? static_cast<std::size_t>(threads)
                                    : std::max(1u, std::thread::hardware_concurrency());
  workers = std::min(workers, n);
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) task(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < workers; ++t)
    pool.emplace_back([&] {
      for (std::size_t i = next++; i < n; i = next++) task(i);
    });
  for (auto& th : pool) th.join();
}

/// The seed of evaluation `index` (its own splitmix64 stream of `seed`).
std::uint32_t seedOf(std::uint32_t seed, std::uint64_t index) {
  std::uint64_t s = (static_cast<std::uint64_t>(seed) << 32) ^ (index * 0xD1B54A32D192ED03ull);
  return static_cast<std::uint32_t>(splitmix64(s) >> 32);
}

double dot3(const Rgb& a, const Rgb& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

Rgb add(const Rgb& a, const Rgb& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

/// The shipping model's closures at geometry g, with the features the truth
/// never walks (reference::groundTruthExcluded) at their mean, as the truth
/// walks them: a glint at density 1 (glintFactor's expectation is 1: the plain
/// lobe) and no specular profile (tint 1). Compared at one shading point, a
/// glint is its noise at that point (mostly 0 without uv derivatives), which
/// is not an error of the model.
std::vector<reference::Closure<double>> comparableClosures(const CompileResult& r, const reference::Geometry& g) {
  auto closures = reference::evaluateMaterial<double>(r, g, {}, {}).closures;
  for (auto& c : closures) {
    c.features &= ~(reference::kFeatureGlint | reference::kFeatureSpecularProfile);
    c.glintValue = 1;
    c.specularProfile = 0;
    c.hair[3] = 0;  // a hair's truth is one fibre: the dense-hair blend is not part of it
  }
  return closures;
}

/// The analytic directional albedo at geometry g: sum over closures of
/// viewThroughput(N.V) * envIntegrated (white environment), closure i
/// integrated with its own seed.
Rgb analyticAlbedo(const CompileResult& r, const reference::Geometry& g, const Options& o, std::uint64_t salt) {
  const auto closures = comparableClosures(r, g);
  const Rgb V{g.V[0], g.V[1], g.V[2]};
  Rgb sum{0, 0, 0};
  for (std::size_t i = 0; i < closures.size(); ++i) {
    const reference::Closure<double>& c = closures[i];
    const Rgb t = reference::viewThroughput<double>(c, dot3(c.N, V), V);
    const Rgb e = (c.features & reference::kFeatureHair)  // a fibre scatters all around: the sphere
                      ? reference::hairAlbedoIntegrated(c, V)
                      : reference::envIntegrated(c, V, [](const Rgb&) { return Rgb{1, 1, 1}; }, o.diffuseModel,
                                                 o.envSamples, seedOf(o.seed, salt * 64 + i));
    for (int k = 0; k < 3; ++k) sum[k] += t[k] * e[k];
  }
  return sum;
}

/// Sum over the closures of lightClosure(c, V, L, 1): f * cos of the shipping model.
Rgb analyticFCos(const std::vector<reference::Closure<double>>& closures, const Rgb& V, const Rgb& L, int diffuseModel) {
  Rgb sum{0, 0, 0};
  for (const auto& c : closures) sum = add(sum, reference::lightClosure<double>(c, V, L, Rgb{1, 1, 1}, diffuseModel));
  return sum;
}

/// The BRDF f (luminance) of the closures: each closure's lightClosure divided
/// by the cosine it applied (its own normal's N.L); 0 where that is not positive.
double analyticF(const std::vector<reference::Closure<double>>& closures, const Rgb& V, const Rgb& L, int diffuseModel) {
  double f = 0;
  for (const auto& c : closures) {
    const double NoL = dot3(c.N, L);
    if (NoL > 1e-6) f += luminance(reference::lightClosure<double>(c, V, L, Rgb{1, 1, 1}, diffuseModel)) / NoL;
  }
  return f;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  const double x = p * static_cast<double>(v.size() - 1);
  const std::size_t i = static_cast<std::size_t>(x);
  if (i + 1 >= v.size()) return v.back();
  return v[i] + (x - static_cast<double>(i)) * (v[i + 1] - v[i]);  // linear between closest ranks
}

/// A truth albedo (or a BRDF grid whose largest f cos is) at or below this
/// is black: no relative error is read from it. A conductor of F0 0 reflects
/// 1e-67 head-on in the walk (rounding), and an error relative to that read
/// 3e63 (glTF AnisotropyDiscTest's black text); 1e-9 is far below what a
/// half-float G-buffer or a display can show.
constexpr double kBlackAlbedo = 1e-9;

std::optional<double> relative(double a, double t) {
  if (!(t > kBlackAlbedo)) return std::nullopt;
  return a / t - 1;
}

}  // namespace

double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

std::vector<Rgb> lightGrid(const Options& options) {
  std::vector<Rgb> grid;
  for (double mu : options.gridNoL)
    for (int j = 0; j < options.gridAzimuths; ++j) {
      const double phi = 2 * std::numbers::pi * j / options.gridAzimuths;
      const double s = std::sqrt(std::max(0.0, 1 - mu * mu));
      grid.push_back({s * std::cos(phi), s * std::sin(phi), mu});
    }
  return grid;
}

reference::Geometry viewGeometry(double nov) {
  reference::Geometry g;
  g.V = {std::sqrt(std::max(0.0, 1 - nov * nov)), 0, nov};
  return g;
}

reference::WalkOptions walkOptions(int samples, std::uint32_t seed) {
  reference::WalkOptions o;
  o.samples = samples;
  o.maxDepth = 1024;
  o.albedoSeenThroughInterface = true;
  o.absoluteIor = true;
  o.seed = seed;
  return o;
}

/// The hair closure of `r` when a hair BSDF is the whole material (else nullopt).
std::optional<reference::Closure<double>> hairClosureOf(const CompileResult& r, const reference::Geometry& g) {
  const auto closures = comparableClosures(r, g);
  if (closures.size() != 1 || !(closures[0].features & reference::kFeatureHair)) return std::nullopt;
  return closures[0];
}

/// A hair's truth (reference/hair_truth.h): pbrt-v4's HairBxDF at the
/// closure's parameters (its absorption from the base colour as the runtime
/// takes it, clamped alike), integrated over the fibre's width, by quadrature
/// (exact figures: no standard error). The furnace is the same white fibre.
Truth hairTruthOf(const CompileResult& authored, const Options& options) {
  const std::vector<Rgb> grid = lightGrid(options);
  Truth truth;
  truth.brdfThreshold = options.brdfThreshold;
  truth.rows.resize(kNoV.size());
  parallelFor(kNoV.size(), options.threads, [&](std::size_t v) {
    const reference::Geometry g = viewGeometry(kNoV[v]);
    const reference::Closure<double> c = *hairClosureOf(authored, g);
    const Rgb V{g.V[0], g.V[1], g.V[2]};
    const double tl = std::sqrt(dot3(c.T_, c.T_));
    const Rgb T{c.T_[0] / tl, c.T_[1] / tl, c.T_[2] / tl};  // unit (the walk's is already)
    reference::HairParams p;
    Rgb color;
    for (int k = 0; k < 3; ++k) color[k] = std::clamp(c.diffuseAlbedo[k], 1e-6, 1.0);
    p.betaM = c.roughness;
    p.betaN = c.hair[0];
    p.eta = std::max(c.hair[1], 1.0 + 1e-6);
    p.alphaDeg = c.hair[2];
    p.sigmaA = reference::hairSigmaAFromColor(color, p.betaN);
    const double sinO = std::clamp(dot3(V, T), -1.0, 1.0);
    TruthRow& row = truth.rows[v];
    row.nov = kNoV[v];
    row.albedo.value = reference::chiangAlbedo(p, sinO);
    reference::HairParams white = p;
    white.sigmaA = {0, 0, 0};
    row.furnace = reference::Estimate{reference::chiangAlbedo(white, sinO), {0, 0, 0}, 1};
    for (const Rgb& L : grid) row.grid.push_back({reference::chiangFarField(p, V, L, T), {0, 0, 0}, 1});
  });
  return truth;
}

Truth truthOf(const CompileResult& authored, const Options& options) {
  if (hairClosureOf(authored, viewGeometry(1))) return hairTruthOf(authored, options);
  const std::vector<Rgb> grid = lightGrid(options);
  const std::size_t perView = grid.size() + 2;  // albedo, furnace, the grid
  const CompileResult furnace = reference::furnaceMaterial(authored);
  Truth truth;
  truth.samples = options.samples;
  truth.evalSamples = options.evalSamples;
  truth.brdfThreshold = options.brdfThreshold;
  truth.excluded = reference::groundTruthExcluded(authored);
  truth.rows.resize(kNoV.size());
  for (std::size_t v = 0; v < kNoV.size(); ++v) {
    truth.rows[v].nov = kNoV[v];
    truth.rows[v].grid.resize(grid.size());
    truth.rows[v].furnace = reference::Estimate{};
  }
  parallelFor(kNoV.size() * perView, options.threads, [&](std::size_t i) {
    const std::size_t v = i / perView, k = i % perView;
    const reference::Geometry g = viewGeometry(kNoV[v]);
    TruthRow& row = truth.rows[v];
    if (k == 0)
      row.albedo = reference::groundTruthAlbedo(authored, g, {}, walkOptions(options.samples, seedOf(options.seed, i)));
    else if (k == 1)
      row.furnace = reference::groundTruthAlbedo(furnace, g, {}, walkOptions(options.samples, seedOf(options.seed, i)));
    else
      row.grid[k - 2] = reference::groundTruthEstimate(authored, g, grid[k - 2], {},
                                                       walkOptions(options.evalSamples, seedOf(options.seed, i)));
  });
  return truth;
}

Analytic analyticOf(const CompileResult& compiled, const Options& options) {
  const std::vector<Rgb> grid = lightGrid(options);
  const CompileResult furnace = reference::furnaceMaterial(compiled);
  Analytic a;
  a.rows.resize(kNoV.size());
  parallelFor(kNoV.size(), options.threads, [&](std::size_t v) {
    AnalyticRow& row = a.rows[v];
    row.nov = kNoV[v];
    const reference::Geometry g = viewGeometry(kNoV[v]);
    const Rgb V{g.V[0], g.V[1], g.V[2]};
    row.albedo = analyticAlbedo(compiled, g, options, 2 * v);
    row.furnace = analyticAlbedo(furnace, g, options, 2 * v + 1);
    const auto closures = comparableClosures(compiled, g);
    row.grid.reserve(grid.size());
    double maxLum = 0;
    for (const Rgb& L : grid) {
      row.grid.push_back(analyticFCos(closures, V, L, options.diffuseModel));
      maxLum = std::max(maxLum, luminance(row.grid.back()));
    }
    // Reciprocity: f(v, l) against f(l, v), the material evaluated seen from l.
    for (std::size_t j = 0; j < grid.size(); ++j) {
      reference::Geometry swapped = g;
      swapped.V = grid[j];
      const auto seenFromL = comparableClosures(compiled, swapped);
      const double fcosBack = luminance(analyticFCos(seenFromL, grid[j], V, options.diffuseModel));
      if (!(luminance(row.grid[j]) > options.brdfThreshold * maxLum) || !(fcosBack > options.brdfThreshold * maxLum))
        continue;
      const double f = analyticF(closures, V, grid[j], options.diffuseModel);
      const double back = analyticF(seenFromL, grid[j], V, options.diffuseModel);
      if (!(f > 0) || !(back > 0)) continue;
      row.reciprocityMaxRatio = std::max({row.reciprocityMaxRatio, f / back, back / f});
      ++row.reciprocityPairs;
    }
  });
  return a;
}

/// One NoV's comparison (the brdf fields over the grid points where the truth
/// is significant).
ComparisonRow compareRow(const AnalyticRow& a, const TruthRow& t, double threshold) {
  ComparisonRow row;
  row.nov = t.nov;
  row.analytic = a.albedo;
  row.truth = t.albedo.value;
  row.truthStderr = t.albedo.standardError;
  row.truthWalks = t.albedo.samples;
  row.relError = relative(luminance(a.albedo), luminance(t.albedo.value));
  for (int k = 0; k < 3; ++k) row.channelRelError[k] = relative(a.albedo[k], t.albedo.value[k]);
  double maxLum = 0;
  for (const auto& e : t.grid) maxLum = std::max(maxLum, luminance(e.value));
  std::vector<double> errors;
  for (std::size_t j = 0; j < t.grid.size() && j < a.grid.size(); ++j) {
    const double lt = luminance(t.grid[j].value);
    if (maxLum > kBlackAlbedo && lt > threshold * maxLum) errors.push_back(std::abs(luminance(a.grid[j]) / lt - 1));
  }
  row.brdfTotal = static_cast<int>(t.grid.size());
  row.brdfCounted = static_cast<int>(errors.size());
  if (!errors.empty()) {
    row.brdfMedianRelError = percentile(errors, 0.5);
    row.brdfP95RelError = percentile(errors, 0.95);
  }
  row.reciprocityMaxRatio = a.reciprocityMaxRatio;
  row.reciprocityPairs = a.reciprocityPairs;
  row.furnaceAnalytic = a.furnace;
  if (t.furnace) {
    row.furnaceTruth = t.furnace->value;
    row.furnaceTruthStderr = t.furnace->standardError;
  }
  return row;
}

Comparison compare(const Analytic& analytic, const Truth& truth) {
  Comparison c;
  c.excluded = truth.excluded;
  c.truthSamples = truth.samples;
  c.truthEvalSamples = truth.evalSamples;
  int black = 0;
  for (std::size_t v = 0; v < truth.rows.size() && v < analytic.rows.size(); ++v) {
    c.rows.push_back(compareRow(analytic.rows[v], truth.rows[v], truth.brdfThreshold));
    const ComparisonRow& row = c.rows.back();
    if (!row.relError) {
      ++black;
      c.problems.push_back(
          fmt::format("the truth's albedo is 0 (at most {:g}) at NoV {}: no relative error", kBlackAlbedo, row.nov));
    } else if (!row.brdfMedianRelError) {
      c.problems.push_back(fmt::format("the truth's f * cos is 0 over the whole grid at NoV {}: no BRDF error", row.nov));
    }
  }
  if (c.rows.empty()) c.problems.push_back("no view compared");
  else if (black == static_cast<int>(c.rows.size()))
    c.problems.insert(c.problems.begin(), "the truth is black at every NoV: nothing to compare");
  return c;
}

}  // namespace substratec::accuracy

namespace substratec::accuracy {

namespace {

nlohmann::ordered_json rgbJson(const Rgb& c) { return nlohmann::ordered_json::array({c[0], c[1], c[2]}); }

template <class T>
nlohmann::ordered_json orNull(const std::optional<T>& v) {
  if (!v) return nullptr;
  if constexpr (std::is_same_v<T, Rgb>) return rgbJson(*v);
  else return *v;
}

nlohmann::ordered_json rowJson(const ComparisonRow& r) {
  nlohmann::ordered_json channels = nlohmann::ordered_json::array();
  for (const auto& e : r.channelRelError) channels.push_back(orNull(e));
  return {{"nov", r.nov},
          {"analytic", rgbJson(r.analytic)},
          {"truth", rgbJson(r.truth)},
          {"truth_stderr", rgbJson(r.truthStderr)},
          {"truth_walks", r.truthWalks},
          {"rel_error", orNull(r.relError)},
          {"rel_error_rgb", channels},
          {"brdf_median_rel_error", orNull(r.brdfMedianRelError)},
          {"brdf_p95_rel_error", orNull(r.brdfP95RelError)},
          {"brdf_points", {{"counted", r.brdfCounted}, {"total", r.brdfTotal}}},
          {"reciprocity_max_ratio", r.reciprocityMaxRatio},
          {"reciprocity_pairs", r.reciprocityPairs},
          {"furnace_analytic", orNull(r.furnaceAnalytic)},
          {"furnace_truth", orNull(r.furnaceTruth)},
          {"furnace_truth_stderr", orNull(r.furnaceTruthStderr)}};
}

/// A relative error in percent ("—" when there is none); `sign`: with its sign.
std::string percent(const std::optional<double>& v, bool sign) {
  if (!v) return "—";
  return sign ? fmt::format("{:+.2f} %", 100 * *v) : fmt::format("{:.2f} %", 100 * *v);
}

std::string comparisonTable(const Comparison& c) {
  std::string out = fmt::format("{:>4}  {:<22}  {:<22}  {:<22}  {:>9}  {:>9}  {:>9}  {:>7}  {:>6}  {:>7}  {:>7}\n",
                                "nov", "analytic", "truth", "± stderr", "rel_err", "brdf_med", "brdf_p95", "points",
                                "recip", "furn_a", "furn_t");
  auto rgb = [](const Rgb& v) { return fmt::format("{:.4f} {:.4f} {:.4f}", v[0], v[1], v[2]); };
  auto lum = [](const std::optional<Rgb>& v) { return v ? fmt::format("{:.4f}", luminance(*v)) : std::string("—"); };
  for (const auto& r : c.rows)
    out += fmt::format("{:>4.1f}  {:<22}  {:<22}  {:<22}  {:>9}  {:>9}  {:>9}  {:>7}  {:>6.3f}  {:>7}  {:>7}\n", r.nov,
                       rgb(r.analytic), rgb(r.truth), rgb(r.truthStderr), percent(r.relError, true),
                       percent(r.brdfMedianRelError, false), percent(r.brdfP95RelError, false),
                       fmt::format("{}/{}", r.brdfCounted, r.brdfTotal), r.reciprocityMaxRatio,
                       lum(r.furnaceAnalytic), lum(r.furnaceTruth));
  std::string excluded;
  for (const auto& e : c.excluded) excluded += (excluded.empty() ? "" : ", ") + e;
  out += "excluded: " + (excluded.empty() ? std::string("none") : excluded) + "\n";
  for (const auto& p : c.problems) out += "problem: " + p + "\n";
  return out;
}

}  // namespace

nlohmann::ordered_json comparisonJson(const Comparison& c) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (const auto& r : c.rows) rows.push_back(rowJson(r));
  return {{"rows", rows}, {"excluded", c.excluded}, {"problems", c.problems}};
}

Worst worstOf(const Comparison& c) {
  Worst w;
  for (const ComparisonRow& r : c.rows) {
    if (r.relError && (!w.relError || std::abs(*r.relError) > std::abs(*w.relError))) {
      w.relError = r.relError;
      w.relErrorNoV = r.nov;
    }
    if (r.brdfP95RelError) w.brdfP95 = std::max(w.brdfP95.value_or(0.0), *r.brdfP95RelError);
    w.reciprocityMaxRatio = std::max(w.reciprocityMaxRatio, r.reciprocityMaxRatio);
  }
  return w;
}

std::string formatJson(const Report& report) {
  nlohmann::ordered_json nol = nlohmann::ordered_json::array();
  for (double mu : report.options.gridNoL) nol.push_back(mu);
  nlohmann::ordered_json j = {
      {"material", report.material},
      {"bytes", report.bytes},
      {"closures", report.closures},
      {"truth_samples", report.vsAuthored.truthSamples},
      {"truth_eval_samples", report.vsAuthored.truthEvalSamples},
      {"brdf_threshold", report.options.brdfThreshold},
      {"grid", {{"nol", nol}, {"azimuths", report.options.gridAzimuths}}},
      {"diffuse_model", report.options.diffuseModel},
  };
  const nlohmann::ordered_json authored = comparisonJson(report.vsAuthored);
  for (auto it = authored.begin(); it != authored.end(); ++it) j[it.key()] = it.value();
  j["truth_compiled"] = report.vsCompiled ? comparisonJson(*report.vsCompiled) : nlohmann::ordered_json(nullptr);
  return j.dump(2) + "\n";
}

std::string formatTable(const Report& report) {
  std::string out = fmt::format(
      "accuracy of {} (as compiled: {} B, {} closures; truth: {} walks per albedo, {} per grid point; BRDF grid {} "
      "directions, counted where the truth exceeds {:g} of its max)\n",
      report.material, report.bytes, report.closures, report.vsAuthored.truthSamples,
      report.vsAuthored.truthEvalSamples, report.options.gridNoL.size() * report.options.gridAzimuths,
      report.options.brdfThreshold);
  out += "-- against the truth of the authored material\n" + comparisonTable(report.vsAuthored);
  if (report.vsCompiled) out += "-- against the truth of the compiled closures\n" + comparisonTable(*report.vsCompiled);
  return out;
}

}  // namespace substratec::accuracy
