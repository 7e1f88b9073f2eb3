// The layering approximation against the Monte Carlo ground truth: for every
// material given, the directional albedo over NoV of the analytic model (the
// runtime's closures, CPU reference in double) and of the random walk through
// the same tree's stacks (reference/random_walk.h), in the walk's two albedo
// conventions. Prints a markdown table per material; bench/accuracy.sh writes
// it to docs/accuracy/layering.md.
//
//   layering_truth [--samples N] [--diffuse 0..3] FILE...   (diffuse: Lambert, Chan 2018, Chan 2024, EON)
//
// Analytic: sum over closures of viewThroughput(NoV) * the integral over the
// sphere of lightThroughput * BSDF * cos (reference::envIntegrated under a
// uniform white environment, importance-sampled: converged to well under 0.1 %),
// of reference::layeringOnly of each closure (anisotropy, haze, fuzz, glints and
// specular profiles are not modelled by the walk). Walk: sum over
// groundTruthTerms of weight * layeredAlbedo, maxDepth 1024. Both at the
// geometric normal, inputs at their defaults, textures as value_eval's constant
// sample, the default diffuse model (Chan 2024) unless --diffuse.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "pipeline/pipeline.h"
#include "reference/ground_truth.h"
#include "reference/reference.h"

namespace {

using namespace substratec;
using V = reference::V3<double>;

double luminance(const V& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

V analyticAlbedo(const CompileResult& r, const reference::Geometry& g, int samples, int diffuseModel) {
  const auto m = reference::evaluateMaterial<double>(r, g, {}, {});
  V sum{0, 0, 0};
  std::uint32_t seed = 7;
  for (const auto& full : m.closures) {
    const reference::Closure<double> c = reference::layeringOnly(full);
    const double NoV = c.N[0] * g.V[0] + c.N[1] * g.V[1] + c.N[2] * g.V[2];
    const V t = reference::viewThroughput<double>(c, NoV);
    const V e = reference::envIntegrated(
        c, g.V, [](const V&) { return V{1, 1, 1}; }, diffuseModel, samples, seed++);
    for (int k = 0; k < 3; ++k) sum[k] += t[k] * e[k];
  }
  return sum;
}

V walkAlbedo(const CompileResult& r, const reference::Geometry& g, const reference::WalkOptions& o) {
  V sum{0, 0, 0};
  const V wo{g.V[0], g.V[1], g.V[2]};  // the geometric frame is the local frame here (N = z, T = x)
  const auto terms = reference::groundTruthTerms(r, g, {});
  for (std::size_t i = 0; i < terms.size(); ++i) {
    reference::WalkOptions oi = o;
    oi.seed = o.seed + static_cast<std::uint32_t>(i) * 0x9E3779B9u;
    const V a = reference::layeredAlbedo(terms[i].stack, wo, oi);
    for (int k = 0; k < 3; ++k) sum[k] += terms[i].weight * a[k];
  }
  return sum;
}

}  // namespace

int main(int argc, char** argv) {
  int samples = 16384;
  int diffuseModel = reference::kDiffuseChan2024;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--samples" && i + 1 < argc) samples = std::stoi(argv[++i]);
    else if (a == "--diffuse" && i + 1 < argc) diffuseModel = std::stoi(argv[++i]);
    else files.push_back(a);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: layering_truth [--samples N] [--diffuse 0..3] FILE...\n");
    return 2;
  }
  const double nov[] = {1.0, 0.8, 0.6, 0.4, 0.2, 0.1};
  for (const std::string& path : files) {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CompileOptions o;
    o.budgetOverride = 1024;
    o.maxClosuresOverride = 8;
    Diagnostics diags(path);
    auto r = compileText(path, text, o, diags);
    if (!r) {
      std::fprintf(stderr, "%s", diags.formatAll().c_str());
      return 1;
    }
    std::string out = fmt::format("## {}\n\n| NoV | analytic | walk (analytic's conventions) | error | walk (default conventions) | error |\n|---:|---:|---:|---:|---:|---:|\n", r->material.name);
    for (double mu : nov) {
      reference::Geometry g;
      g.V = {std::sqrt(1 - mu * mu), 0, mu};
      const double a = luminance(analyticAlbedo(*r, g, samples, diffuseModel));
      reference::WalkOptions matched;
      matched.samples = samples;
      matched.maxDepth = 1024;
      matched.albedoSeenThroughInterface = true;
      matched.absoluteIor = true;
      reference::WalkOptions plain = matched;
      plain.albedoSeenThroughInterface = false;
      plain.absoluteIor = false;
      const double w1 = luminance(walkAlbedo(*r, g, matched));
      const double w2 = luminance(walkAlbedo(*r, g, plain));
      auto rel = [&](double w) { return w > 1e-9 ? fmt::format("{:+.1f} %", 100 * (a / w - 1)) : std::string("—"); };
      out += fmt::format("| {:.1f} | {:.4f} | {:.4f} | {} | {:.4f} | {} |\n", mu, a, w1, rel(w1), w2, rel(w2));
    }
    std::printf("%s\n", out.c_str());
    std::fflush(stdout);
  }
  return 0;
}
