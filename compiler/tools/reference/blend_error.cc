#include "reference/blend_error.h"

#include <cmath>
#include <numbers>

#include "reference/reference.h"

namespace substratec::reference {

namespace {

using D3 = std::array<double, 3>;

constexpr int kPoints = 64;
constexpr int kDiffuseModel = diffuseModelNumber(kDefaultDiffuseModel);

D3 cross3(const D3& a, const D3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
D3 unit(const D3& a) {
  double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / l, a[1] / l, a[2] / l};
}

/// Unit direction at cos(theta) = mu and azimuth phi in the frame (T, B, N).
D3 inFrame(const D3& T, const D3& B, const D3& N, double mu, double phi) {
  double s = std::sqrt(1 - mu * mu);
  D3 d;
  for (int k = 0; k < 3; ++k) d[k] = s * std::cos(phi) * T[k] + s * std::sin(phi) * B[k] + mu * N[k];
  return unit(d);
}

// Views and lights in the tangent frame: above the horizon, near-normal to grazing.
constexpr std::array<double, 4> kViewCos{0.95, 0.7, 0.4, 0.15}, kViewPhi{0.3, 2.0, 3.7, 5.2};
constexpr std::array<double, 4> kLightCos{0.9, 0.6, 0.35, 0.12}, kLightPhi{3.5, 0.9, 5.6, 2.4};

}  // namespace

std::array<double, 4> blendProbeTexture(int inputIndex, double u, double v) {
  const double i = inputIndex;
  // r, g in [0.25, 0.75] and b in [0.75, 0.95]: read as a tangent-space normal
  // map, a plausible one (tilts up to ~35 degrees, never below the surface).
  return {0.5 + 0.25 * std::sin(2 * std::numbers::pi * 1.3 * u + i), 0.5 + 0.25 * std::cos(2 * std::numbers::pi * 0.9 * v + 0.5 * i),
          0.85 + 0.1 * std::sin(3 * (u + v) + 2 * i), 0.5 + 0.4 * std::sin(2 * (u - v) + 3 * i)};
}

std::vector<double> blendProbeRadiance(const CompileResult& r) {
  std::vector<double> out;
  out.reserve(kPoints * kViewCos.size() * kLightCos.size() * 3);
  const TextureFn tex = blendProbeTexture;
  const double golden = (std::sqrt(5.0) - 1) / 2;
  for (int i = 0; i < kPoints; ++i) {
    // Fibonacci sphere: normals all around.
    const double z = 1 - (2 * i + 1) / double(kPoints);
    const double rho = std::sqrt(1 - z * z), phi = 2 * std::numbers::pi * golden * i;
    Geometry g;
    g.N = {rho * std::cos(phi), rho * std::sin(phi), z};
    const D3 helper = std::fabs(g.N[2]) < 0.9 ? D3{0, 0, 1} : D3{1, 0, 0};
    g.T = unit(cross3(helper, g.N));
    const D3 B = cross3(g.N, g.T);
    g.position = g.N;
    g.uv0 = {(i + 0.5) / kPoints, std::fmod(i * golden, 1.0)};
    g.uv1 = {g.uv0[1], g.uv0[0]};
    for (std::size_t v = 0; v < kViewCos.size(); ++v) {
      g.V = inFrame(g.T, B, g.N, kViewCos[v], kViewPhi[v] + 0.1 * i);
      const MaterialResult<double> m = evaluateMaterial<double>(r, g, {}, tex);
      const V3<double> V = g.V;
      // The view's environment and emission, shared by its four light probes.
      V3<double> ambient{0, 0, 0};
      for (const Closure<double>& c : m.closures) {
        const double NoV = c.N[0] * V[0] + c.N[1] * V[1] + c.N[2] * V[2];
        const V3<double> vt = viewThroughput(c, NoV, V);
        const V3<double> env = envSplitSum(c, V, {0.5, 0.5, 0.5}, {0.5 * std::numbers::pi, 0.5 * std::numbers::pi, 0.5 * std::numbers::pi}, kDiffuseModel);
        for (int k = 0; k < 3; ++k) ambient[k] += vt[k] * (env[k] + c.emissive[k]);
      }
      for (std::size_t l = 0; l < kLightCos.size(); ++l) {
        const V3<double> L = inFrame(g.T, B, g.N, kLightCos[l], kLightPhi[l] - 0.07 * i);
        V3<double> rad = ambient;
        for (const Closure<double>& c : m.closures) {
          const V3<double> d = lightClosure(c, V, L, {1.0, 1.0, 1.0}, kDiffuseModel);
          for (int k = 0; k < 3; ++k) rad[k] += d[k];
        }
        out.insert(out.end(), rad.begin(), rad.end());
      }
    }
  }
  return out;
}

double relativeMse(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size() || x.empty()) return NAN;
  double sum = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sum += (x[i] - y[i]) * (x[i] - y[i]) / (y[i] * y[i] + 0.01);
  return sum / static_cast<double>(x.size());
}

namespace {

CompileOptions optionsFor(const BlendBudget& b, BlendRule rule) {
  CompileOptions o;
  o.blendRule = rule;
  if (b.full) {
    o.fullSimplification = true;
  } else {
    o.budgetOverride = b.bytes;
    o.maxClosuresOverride = b.closures;
  }
  return o;
}

}  // namespace

std::optional<std::vector<BlendBudget>> simplificationBudgets(const std::string& text, BlendRule rule,
                                                              Diagnostics& diags) {
  auto listed = compileText(diags.file(), text, optionsFor({0, 0, true}, rule), diags);
  if (!listed) return std::nullopt;
  std::vector<BlendBudget> out;
  std::size_t reached = 0;
  for (std::size_t k = 0; k < listed->steps.size(); ++k) {
    const bool last = k + 1 == listed->steps.size();
    BlendBudget b{listed->steps[k].bytesAfter, listed->steps[k].closuresAfter, last};
    std::size_t n = listed->steps.size();
    if (!last) {
      auto r = compileText(diags.file(), text, optionsFor(b, rule), diags);
      if (!r) return std::nullopt;
      n = r->steps.size();
    }
    if (n == reached) continue;  // reached together with the previous budget
    reached = n;
    out.push_back(b);
  }
  return out;
}

std::optional<std::vector<BlendStepError>> measureBlendError(const std::string& text,
                                                             const std::vector<BlendBudget>& budgets, BlendRule rule,
                                                             Diagnostics& diags) {
  std::vector<BlendStepError> out;
  if (budgets.empty()) return out;
  // The reference: the material without any simplification (a budget nothing exceeds).
  const CompileOptions none = unsimplifiedOptions({});
  auto unsimplified = compileText(diags.file(), text, none, diags);
  if (!unsimplified) return std::nullopt;
  const std::vector<double> y = blendProbeRadiance(*unsimplified);
  for (const BlendBudget& b : budgets) {
    auto r = compileText(diags.file(), text, optionsFor(b, rule), diags);
    if (!r) return std::nullopt;
    BlendStepError e;
    e.step = static_cast<int>(r->steps.size());
    if (!r->steps.empty()) {
      const SimplifyStep& last = r->steps.back();
      e.action = last.action + " " + (last.action == "collapse" ? last.kind + " " : std::string()) + last.node;
    }
    e.full = b.full;
    e.bytes = r->after.bytes();
    e.closures = static_cast<int>(r->after.closures.size());
    e.relMse = relativeMse(blendProbeRadiance(*r), y);
    out.push_back(e);
  }
  return out;
}

}  // namespace substratec::reference
