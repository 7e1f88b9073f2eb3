// `substratec accuracy`: the shipping model against the Monte Carlo truth, in
// one metric (docs/accuracy.md, "The accuracy metric"). For views in the x-z
// plane at NoV in kNoV (around the geometric normal, inputs at their defaults,
// textures as value_eval's constant sample):
// - directional albedo: the analytic model's (sum over closures of
//   viewThroughput(NoV) * envIntegrated under a white environment) against the
//   truth's (reference::groundTruthAlbedo), relative error in Rec. 709
//   luminance and per channel, no floor;
// - BRDF: f * cos on a fixed grid of light directions (reference::lightClosure
//   against reference::groundTruthEstimate), median and 95th percentile of the
//   luminance relative error over the points where the truth exceeds a stated
//   fraction of its maximum over the grid;
// - reciprocity of the analytic model: max over the grid of max(r, 1/r),
//   r = f(v, l) / f(l, v), where both are significant;
// - white furnace: the same on reference::furnaceMaterial (albedos 1, no
//   absorption), whose truth is 1.
// A glint and a specular profile, which the truth does not walk, are compared
// at their mean on both sides (the analytic closures with glint density 1 and
// no profile).
// Split in truth / analytic / compare so that a caller (the sweep) walks a
// truth once and compares several analytic models with it.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "pipeline/pipeline.h"
#include "reference/ground_truth.h"
#include "reference/random_walk.h"
#include "reference/reference.h"

namespace substratec::accuracy {

using Rgb = reference::V3<double>;

/// The views of every comparison: NoV, the view in the x-z plane.
inline constexpr std::array<double, 6> kNoV{1, 0.8, 0.6, 0.4, 0.2, 0.1};

struct Options {
  /// Walks per truth albedo (per NoV and channel group); also of the furnace.
  int samples = 32768;
  /// Walks per truth f * cos grid point (per channel group).
  int evalSamples = 2048;
  /// Importance samples per strategy of envIntegrated (the analytic albedo).
  int envSamples = 4096;
  /// The light grid: every NoL of gridNoL at gridAzimuths azimuths
  /// phi_j = 2 pi j / gridAzimuths (phi 0: the view's side; pi: the mirror side).
  /// No NoL of the grid is one of kNoV: no grid point is a view's exact mirror
  /// direction, where a smooth lobe's peak would set the max of the threshold.
  std::vector<double> gridNoL{0.95, 0.85, 0.7, 0.5, 0.3, 0.15};
  int gridAzimuths = 8;
  /// A grid point counts in the BRDF error when lum(truth) > brdfThreshold *
  /// the grid's max lum(truth) (at that NoV); reciprocity counts a pair when
  /// both of its values exceed it (of the analytic grid's max).
  double brdfThreshold = 0.01;
  int diffuseModel = diffuseModelNumber(kDefaultDiffuseModel);
  std::uint32_t seed = 1;
  /// Threads over the independent evaluations (0: the machine's). Every
  /// evaluation has its own seed: the results do not depend on it.
  int threads = 0;
};

/// The light directions of the grid (world space, z the geometric normal).
std::vector<Rgb> lightGrid(const Options& options);

/// The geometry of view NoV: N = z, T = x, V = (sqrt(1 - NoV^2), 0, NoV).
reference::Geometry viewGeometry(double nov);

/// The walk's options: the analytic model's conventions
/// (albedoSeenThroughInterface, absoluteIor), maxDepth 1024, `samples` walks.
reference::WalkOptions walkOptions(int samples, std::uint32_t seed);

struct TruthRow {
  double nov = 1;
  reference::Estimate albedo;                // directional albedo
  std::vector<reference::Estimate> grid;     // f * cos at lightGrid's directions
  std::optional<reference::Estimate> furnace;  // directional albedo of furnaceMaterial
};

struct Truth {
  std::vector<TruthRow> rows;          // one per kNoV
  std::vector<std::string> excluded;   // reference::groundTruthExcluded
  int samples = 0, evalSamples = 0;    // walks per figure (per channel group)
  double brdfThreshold = 0.01;         // Options::brdfThreshold it was made with
};

/// The truth of `authored` (compile it without simplification: a budget and
/// closure count large enough): the Monte Carlo figures at every kNoV.
Truth truthOf(const CompileResult& authored, const Options& options);

struct AnalyticRow {
  double nov = 1;
  Rgb albedo{0, 0, 0};               // sum of viewThroughput * envIntegrated (white environment)
  std::vector<Rgb> grid;             // sum of lightClosure (radiance 1) at lightGrid's directions
  double reciprocityMaxRatio = 1;    // max over significant pairs of max(r, 1/r); 1 when none
  int reciprocityPairs = 0;          // pairs counted
  std::optional<Rgb> furnace;        // the albedo of furnaceMaterial
};

struct Analytic {
  std::vector<AnalyticRow> rows;  // one per kNoV
};

/// The shipping model (every feature: the runtime's closures on the CPU in
/// double) of `compiled`.
Analytic analyticOf(const CompileResult& compiled, const Options& options);

struct ComparisonRow {
  double nov = 1;
  Rgb analytic{0, 0, 0}, truth{0, 0, 0}, truthStderr{0, 0, 0};
  long truthWalks = 0;
  /// lum(analytic) / lum(truth) - 1 (Rec. 709); empty when lum(truth) is 0.
  std::optional<double> relError;
  std::array<std::optional<double>, 3> channelRelError;  // per channel, empty where truth is 0
  /// Of |lum(analytic f) / lum(truth f) - 1| over the significant grid points;
  /// empty when none is (a black truth).
  std::optional<double> brdfMedianRelError, brdfP95RelError;
  int brdfCounted = 0, brdfTotal = 0;
  double reciprocityMaxRatio = 1;
  int reciprocityPairs = 0;
  std::optional<Rgb> furnaceAnalytic, furnaceTruth, furnaceTruthStderr;
};

struct Comparison {
  std::vector<ComparisonRow> rows;
  std::vector<std::string> excluded;
  int truthSamples = 0, truthEvalSamples = 0;
  /// What makes the comparison empty or meaningless ("the truth is black at
  /// every NoV", ...): a caller must not read an empty problem list as a pass
  /// otherwise. Empty when every row has a relative error.
  std::vector<std::string> problems;
};

Comparison compare(const Analytic& analytic, const Truth& truth);

/// The worst figures of a comparison over its views: the largest |rel_error|
/// (with its sign, and its NoV), the largest BRDF p95 and the largest
/// reciprocity ratio; empty optionals where no view has the figure.
struct Worst {
  std::optional<double> relError;
  double relErrorNoV = 0;
  std::optional<double> brdfP95;
  double reciprocityMaxRatio = 1;
};
Worst worstOf(const Comparison& c);

/// One comparison as JSON: {"rows": [...], "excluded": [...], "problems": [...]}
/// (docs/accuracy.md: every key of a row).
nlohmann::ordered_json comparisonJson(const Comparison& c);

/// Rec. 709 luminance.
double luminance(const Rgb& c);

/// What the command prints about one material: the comparison with the truth
/// of the authored material and, when the compiled material differs from it,
/// with the truth of the compiled closures (like for like).
struct Report {
  std::string material;
  int bytes = 0, closures = 0;  // of the material as compiled
  Options options;
  Comparison vsAuthored;
  std::optional<Comparison> vsCompiled;
};

/// The report as JSON (docs/accuracy.md, "The accuracy metric": every key).
std::string formatJson(const Report& report);
/// The report as a table, one row per NoV.
std::string formatTable(const Report& report);

}  // namespace substratec::accuracy
