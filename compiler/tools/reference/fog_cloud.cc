// Mirrors runtime_shaders/substrate_fog_cloud.h, statement for statement, in
// double (the shader's bit tricks on floats become ilogb and ldexp: the same
// exact integer logic).
#include "reference/fog_cloud.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace substratec::reference {

namespace {

constexpr double kFltMax = 3.0e38;  // SUBSTRATE_FLT_MAX

using D3 = std::array<double, 3>;

// substrate_fog_clamp: [0, hi], NaN -> 0.
double fogClamp(double x, double hi) { return x > 0.0 ? std::min(x, hi) : 0.0; }

D3 fogClamp3(const D3& v, double hi) { return {fogClamp(v[0], hi), fogClamp(v[1], hi), fogClamp(v[2], hi)}; }

// substrate_fog_round: nearest, ties up (x >= 0).
double fogRound(double x) {
  const double r = std::floor(x);
  return x - r >= 0.5 ? r + 1.0 : r;
}

// substrate_fog_unorm8
std::uint32_t fogUnorm8(double x) { return static_cast<std::uint32_t>(fogRound(fogClamp(x, 1.0) * 255.0)); }

// substrate_fog_step_channel
void stepChannel(double sigma, double ds, double& factor, double& absorbed, double& transmittance) {
  const double tau = sigma * ds;
  transmittance = std::exp(-tau);
  if (tau < kFogThinStep) {
    const double series = 1.0 - tau * (0.5 - tau * (1.0 / 6.0));  // (1 - e^-tau) / tau to third order
    factor = ds * series;
    absorbed = tau * series;
  } else {
    absorbed = 1.0 - transmittance;
    factor = absorbed / sigma;
  }
}

}  // namespace

FogCloudSample fogCloudMake(D3 albedo, D3 extinction, D3 emissive, double ambientOcclusion) {
  FogCloudSample s;
  s.albedo = fogClamp3(albedo, 1.0);
  s.extinction = fogClamp3(extinction, kFogMaxExtinction);
  s.emissive = fogClamp3(emissive, kFogMaxExtinction);
  s.ambientOcclusion = fogClamp(ambientOcclusion, 1.0);
  return s;
}

std::uint32_t rgb9e5Encode(D3 color) {
  const D3 c = fogClamp3(color, kFogMaxExtinction);
  const double m = std::max(c[0], std::max(c[1], c[2]));
  // floor(log2(m)) (the shader reads it from the float's exponent bits; 0 reads -127).
  const int log2m = m > 0.0 ? std::ilogb(m) : -127;
  int e = std::max(log2m, -16) + 16;
  if (fogRound(m * std::ldexp(1.0, 24 - e)) >= 512.0) ++e;
  const double inv = std::ldexp(1.0, 24 - e);
  const auto r = static_cast<std::uint32_t>(fogRound(c[0] * inv));
  const auto g = static_cast<std::uint32_t>(fogRound(c[1] * inv));
  const auto b = static_cast<std::uint32_t>(fogRound(c[2] * inv));
  return r | (g << 9) | (b << 18) | (static_cast<std::uint32_t>(e) << 27);
}

D3 rgb9e5Decode(std::uint32_t w) {
  const double unit = std::ldexp(1.0, static_cast<int>(w >> 27) - 24);
  return {double(w & 0x1ffu) * unit, double((w >> 9) & 0x1ffu) * unit, double((w >> 18) & 0x1ffu) * unit};
}

std::array<std::uint32_t, 3> fogCloudPack(const FogCloudSample& s) {
  return {fogUnorm8(s.albedo[0]) | (fogUnorm8(s.albedo[1]) << 8) | (fogUnorm8(s.albedo[2]) << 16) |
              (fogUnorm8(s.ambientOcclusion) << 24),
          rgb9e5Encode(s.extinction), rgb9e5Encode(s.emissive)};
}

FogCloudSample fogCloudUnpack(std::array<std::uint32_t, 3> w) {
  FogCloudSample s;
  s.albedo = {double(w[0] & 0xffu) / 255.0, double((w[0] >> 8) & 0xffu) / 255.0, double((w[0] >> 16) & 0xffu) / 255.0};
  s.ambientOcclusion = double(w[0] >> 24) / 255.0;
  s.extinction = rgb9e5Decode(w[1]);
  s.emissive = rgb9e5Decode(w[2]);
  return s;
}

void fogCloudStep(const FogCloudSample& s, double ds, D3 inScattered, D3 ambient, D3& radiance, D3& throughput) {
  const double d = fogClamp(ds, kFogMaxStep);
  const D3 sigma = fogClamp3(s.extinction, kFogMaxExtinction);
  const D3 albedo = fogClamp3(s.albedo, 1.0);
  const D3 emissive = fogClamp3(s.emissive, kFogMaxExtinction);
  const double ao = fogClamp(s.ambientOcclusion, 1.0);
  for (int i = 0; i < 3; ++i) {
    const double light = fogClamp(inScattered[i] + ambient[i] * ao, kFltMax);
    double factor = 0, absorbed = 0, transmittance = 1;
    stepChannel(sigma[i], d, factor, absorbed, transmittance);
    const double added = albedo[i] * light * absorbed + emissive[i] * factor;
    const double t = fogClamp(throughput[i], kFltMax);
    radiance[i] = fogClamp(fogClamp(radiance[i], kFltMax) + t * added, kFltMax);
    throughput[i] = t * transmittance;
  }
}

double hgPhase(double cosTheta, double g) {
  const double k = g > -0.99 ? std::min(g, 0.99) : (g <= -0.99 ? -0.99 : 0.0);
  const double c = cosTheta > -1.0 ? std::min(cosTheta, 1.0) : (cosTheta <= -1.0 ? -1.0 : 1.0);
  const double d = std::max(1.0 + k * k - 2.0 * k * c, 1e-6);
  return (1.0 - k * k) / (4.0 * std::numbers::pi * d * std::sqrt(d));
}

FogMarch marchFogCloud(const std::function<FogCloudSample(const D3& position)>& medium, D3 origin, D3 direction,
                       double length, int steps, D3 inScattered, D3 ambient) {
  const int n = std::clamp(steps, 1, kFogMaxMarchSteps);
  const double ds = length / n;
  FogMarch m;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) * ds;
    const D3 p = {origin[0] + direction[0] * t, origin[1] + direction[1] * t, origin[2] + direction[2] * t};
    fogCloudStep(medium(p), ds, inScattered, ambient, m.radiance, m.throughput);
  }
  return m;
}

}  // namespace substratec::reference
