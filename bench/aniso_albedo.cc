// The energy of an anisotropic GGX lobe (issue 19, item 1): how much of the
// light a white conductor (F0 = F90 = 1) with the shipped energy compensation
// returns, per view cosine, over roughness, |anisotropy| and view azimuth;
// and what the compensation from the lobe's exact largest albedo over the view
// azimuths, W = 1 / E_max(NoV, r, |A|), returns (azimuth-free, so it gains
// energy at no azimuth; the shipped W reads E_max from a table since issue 19).
//
// The single-scattering albedo E(NoV, phi) is integrated here independently
// of the reference: Heitz 2018's visible-normal sampling of the anisotropic
// lobe on an n x n stratified grid, weight G2 / G1(V) (height-correlated
// Smith), alphas from substrate_ggx_alpha (r^2 (1 +- A), clamped to
// [1e-3, 1]). The shipped compensation W is the reference's mirror of the
// shader, reference::specularEnergyAniso, so the returned albedo is E W.
// Not a test: `build/bin/aniso_albedo [n]` prints a markdown table
// (docs/accuracy.md, "Anisotropy: what the compensation returns");
// `build/bin/aniso_albedo --case R A` prints one lobe's 1 / W and E per NoV and
// view azimuth (docs/accuracy.md, step 21).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string_view>
#include <vector>

#include "reference/bsdf.h"

namespace {

double smithLambda(double ax, double ay, double x, double y, double z) {
  return 0.5 * (-1 + std::sqrt(1 + (ax * ax * x * x + ay * ay * y * y) / (z * z)));
}

/// E(mu, phi) of the lobe (ax along the tangent, ay along the bitangent), F = 1.
double albedo(double mu, double phi, double ax, double ay, int n) {
  const double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  const double V[3] = {s * std::cos(phi), s * std::sin(phi), mu};
  double vh[3] = {ax * V[0], ay * V[1], V[2]};
  const double l = std::hypot(vh[0], vh[1], vh[2]);
  for (double& c : vh) c /= l;
  const double lensq = vh[0] * vh[0] + vh[1] * vh[1];
  double t1v[3] = {1, 0, 0};
  if (lensq > 0) t1v[0] = -vh[1] / std::sqrt(lensq), t1v[1] = vh[0] / std::sqrt(lensq);
  const double t2v[3] = {vh[1] * t1v[2] - vh[2] * t1v[1], vh[2] * t1v[0] - vh[0] * t1v[2],
                         vh[0] * t1v[1] - vh[1] * t1v[0]};
  const double lv = smithLambda(ax, ay, V[0], V[1], V[2]);
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double r = std::sqrt((i + 0.5) / n), ph = 2 * std::numbers::pi * (j + 0.5) / n;
      const double t1 = r * std::cos(ph), sv = 0.5 * (1 + vh[2]);
      const double t2 = (1 - sv) * std::sqrt(std::max(0.0, 1 - t1 * t1)) + sv * r * std::sin(ph);
      const double tz = std::sqrt(std::max(0.0, 1 - t1 * t1 - t2 * t2));
      double h[3];
      for (int k = 0; k < 3; ++k) h[k] = t1 * t1v[k] + t2 * t2v[k] + tz * vh[k];
      h[0] *= ax, h[1] *= ay, h[2] = std::max(0.0, h[2]);
      const double hl = std::hypot(h[0], h[1], h[2]);
      if (!(hl > 0)) continue;
      for (double& c : h) c /= hl;
      const double voh = V[0] * h[0] + V[1] * h[1] + V[2] * h[2];
      const double L[3] = {2 * voh * h[0] - V[0], 2 * voh * h[1] - V[1], 2 * voh * h[2] - V[2]};
      if (L[2] <= 0) continue;
      sum += (1 + lv) / (1 + lv + smithLambda(ax, ay, L[0], L[1], L[2]));
    }
  return sum / (double(n) * n);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace substratec::reference;
  if (argc == 4 && std::string_view(argv[1]) == "--case") {
    // One lobe: per NoV, the shipped compensation's 1 / W and E at azimuths 0, 10 .. 90 degrees.
    char* end2 = nullptr;
    char* end3 = nullptr;
    const double rIn = std::strtod(argv[2], &end2), aIn = std::strtod(argv[3], &end3);
    if (*end2 != '\0' || *end3 != '\0' || !(rIn >= 0 && rIn <= 1) || !(std::fabs(aIn) <= 1)) {
      std::fprintf(stderr, "aniso_albedo: --case takes a roughness in [0, 1] and an anisotropy in [-1, 1]\n");
      return 2;
    }
    const double r = rIn, A = std::fabs(aIn);
    const double a = r * r;
    const double ax = std::clamp(a * (1 + A), 1e-3, 1.0), ay = std::clamp(a * (1 - A), 1e-3, 1.0);
    for (double mu : {1.0, 0.8, 0.6, 0.4, 0.2, 0.1}) {
      V3<double> one{1, 1, 1}, specAlbedo;
      double dielectric = 0;
      const FresnelCurve<double> curve = fresnelCurve(one, fresnelShare(1.0), 1.0, 1.0);
      const double w =
          specularEnergyAniso<double>(one, one, curve, V2<double>{1, 1}, one, 0.0, mu, r, A, specAlbedo, dielectric)[0];
      std::printf("NoV %.1f  1/W %.4f  E:", mu, 1 / w);
      for (int k = 0; k < 10; ++k) std::printf(" %.4f", albedo(mu, k * std::numbers::pi / 18, ax, ay, 256));
      std::printf("\n");
    }
    return 0;
  }
  const int n = argc > 1 ? std::clamp(std::atoi(argv[1]), 8, 1024) : 128;
  const double mus[] = {1.0, 0.8, 0.6, 0.4, 0.2, 0.1};
  const double rs[] = {0.1, 0.25, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0};
  const double as[] = {0.1, 0.25, 0.5, 0.75, 1.0};
  constexpr int kPhis = 9;  // 0 .. pi/2: the lobe is symmetric about both axes
  std::printf("Anisotropic GGX, white conductor (F0 = F90 = 1): albedo returned, over r in {0.1 .. 1} (%zu),\n"
              "|A| in {0.1 .. 1} (%zu), %d view azimuths from the tangent to the bitangent; %d x %d points each.\n\n",
              std::size(rs), std::size(as), kPhis, n, n);
  std::printf("| NoV | cases | shipped: min | shipped: mean | E / E_max: min | E / E_max: mean | worst shipped |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|---|\n");
  int total = 0;
  for (double mu : mus) {
    int cases = 0;
    double todayMin = 9, todaySum = 0, maxMin = 9, maxSum = 0;
    double wr = 0, wa = 0, wphi = 0;
    for (double r : rs)
      for (double A : as) {
        const double a = r * r;
        const double ax = std::clamp(a * (1 + A), 1e-3, 1.0), ay = std::clamp(a * (1 - A), 1e-3, 1.0);
        double e[kPhis], eMax = 0;
        for (int k = 0; k < kPhis; ++k) {
          e[k] = albedo(mu, k * std::numbers::pi / (2 * (kPhis - 1)), ax, ay, n);
          eMax = std::max(eMax, e[k]);
        }
        V3<double> one{1, 1, 1}, specAlbedo;
        double dielectric = 0;
        const FresnelCurve<double> curve = fresnelCurve(one, fresnelShare(1.0), 1.0, 1.0);
        const double w = specularEnergyAniso<double>(one, one, curve, V2<double>{1, 1}, one, 0.0, mu, r, A,
                                                     specAlbedo, dielectric)[0];
        for (int k = 0; k < kPhis; ++k) {
          const double today = e[k] * w, ideal = e[k] / eMax;
          if (today < todayMin) todayMin = today, wr = r, wa = A, wphi = k * 90.0 / (kPhis - 1);
          todaySum += today;
          maxMin = std::min(maxMin, ideal);
          maxSum += ideal;
          ++cases;
        }
      }
    total += cases;
    std::printf("| %.1f | %d | %.3f | %.3f | %.3f | %.3f | r %.2f, A %.2f, %.0f deg |\n", mu, cases, todayMin,
                todaySum / cases, maxMin, maxSum / cases, wr, wa, wphi);
  }
  if (total == 0) {
    std::fprintf(stderr, "aniso_albedo: no case measured\n");
    return 1;
  }
  return 0;
}
