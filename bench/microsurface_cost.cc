// The microsurface walk's cost and energy (issue 18; compiler/tools/reference/
// microsurface.h). Not a test: prints, in Release,
//   - ns per sampleMicrosurface and per evalMicrosurface call (alpha 0.5,
//     dielectric eta 1.5 and a Gulbrandsen conductor (r 0.9, g 0.6, grey),
//     over view cosines; process CPU time);
//   - the energy lost to kMaxMicrosurfaceOrder (1 - mean weight of a white
//     conductor, F = 1, and of a dielectric in importance mode, whose weights
//     are all 1) with its standard error;
//   - the table of E_ss (maxOrder 1) and E_ms (all orders) of a white GGX
//     conductor.
// Usage: microsurface_cost [samples per figure, default 1000000]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>

#include "reference/microsurface.h"

namespace {

using namespace substratec;
using namespace substratec::reference;
using D3 = V3<double>;

D3 viewDir(double mu) { return {std::sqrt(std::max(0.0, 1 - mu * mu)), 0, mu}; }

Microsurface conductor(double a, int maxOrder) {
  Microsurface m;
  m.kind = Microsurface::Kind::Conductor;
  m.alphaX = m.alphaY = a;
  m.n = {0, 0, 0};  // F = 1 exactly
  m.k = {1, 1, 1};
  m.maxOrder = maxOrder;
  return m;
}

/// Mean weight (channel 0) and its standard error; `ns` per call.
void albedo(const Microsurface& m, double mu, int n, double& mean, double& err, double& ns) {
  SplitMix64 rng{1};
  double s = 0, s2 = 0;
  std::clock_t t0 = std::clock();  // CPU time: the machine is shared
  for (int i = 0; i < n; ++i) {
    MicrosurfaceSample out;
    double w = sampleMicrosurface(m, viewDir(mu), Transport::Importance, rng, out) ? out.weight[0] : 0;
    s += w;
    s2 += w * w;
  }
  ns = 1e9 * double(std::clock() - t0) / CLOCKS_PER_SEC / n;
  mean = s / n;
  err = std::sqrt(std::max(0.0, s2 / n - mean * mean) / (n - 1));
}

double evalNs(const Microsurface& m, double mu, int n) {
  SplitMix64 rng{2};
  double sink = 0;
  std::clock_t t0 = std::clock();  // CPU time: the machine is shared
  for (int i = 0; i < n; ++i) {
    double z = 2 * rng.uniform() - 1, phi = 6.283185307179586 * rng.uniform(), r = std::sqrt(1 - z * z);
    sink += evalMicrosurface(m, viewDir(mu), {r * std::cos(phi), r * std::sin(phi), z}, Transport::Radiance, rng)[0];
  }
  double ns = 1e9 * double(std::clock() - t0) / CLOCKS_PER_SEC / n;
  if (!std::isfinite(sink)) std::printf("non-finite eval sum\n");
  return ns;
}

}  // namespace

int main(int argc, char** argv) {
  int n = argc > 1 ? std::atoi(argv[1]) : 1000000;
  double r, g;
  conductorIor(0.9, 0.6, r, g);
  Microsurface gold = conductor(0.5, 0);
  gold.n = {r, r, r};
  gold.k = {g, g, g};
  Microsurface glass;
  glass.alphaX = glass.alphaY = 0.5;
  glass.eta = 1.5;
  std::printf("cost, alpha 0.5 (ns per call; eval towards uniform directions of the sphere)\n");
  std::printf("%-10s %6s %12s %12s\n", "surface", "mu", "sample_ns", "eval_ns");
  const Microsurface* ms[] = {&gold, &glass};
  const char* names[] = {"conductor", "dielectric"};
  for (int i = 0; i < 2; ++i)
    for (double mu : {1.0, 0.5, 0.1, -0.5}) {
      if (i == 0 && mu < 0) continue;
      double mean, err, ns;
      albedo(*ms[i], mu, n, mean, err, ns);
      std::printf("%-10s %6.2f %12.1f %12.1f\n", names[i], mu, ns, evalNs(*ms[i], mu, n));
    }
  std::printf("\nwhite GGX conductor: E_ss (maxOrder 1), E_ms (all orders), lost = 1 - E_ms (kMaxMicrosurfaceOrder %d)\n",
              kMaxMicrosurfaceOrder);
  std::printf("%6s %6s %10s %10s %10s %10s\n", "alpha", "mu", "E_ss", "E_ms", "lost", "stderr");
  for (double a : {0.1, 0.2, 0.5, 0.75, 1.0})
    for (double mu : {1.0, 0.5, 0.2, 0.1}) {
      double ess, ems, e1, e2, ns;
      albedo(conductor(a, 1), mu, n, ess, e1, ns);
      albedo(conductor(a, 0), mu, n, ems, e2, ns);
      std::printf("%6.2f %6.2f %10.5f %10.5f %10.2e %10.1e\n", a, mu, ess, ems, 1 - ems, e1);
    }
  std::printf("\ndielectric (importance mode, weights 1): lost = 1 - (R + T)\n");
  std::printf("%6s %6s %6s %10s\n", "eta", "alpha", "mu", "lost");
  for (double eta : {1.5, 1 / 1.5})
    for (double a : {0.5, 1.0})
      for (double mu : {1.0, 0.1, -0.5}) {
        Microsurface d;
        d.alphaX = d.alphaY = a;
        d.eta = eta;
        double mean, err, ns;
        albedo(d, mu, n, mean, err, ns);
        std::printf("%6.3f %6.2f %6.2f %10.2e\n", eta, a, mu, 1 - mean);
      }
  return 0;
}
