// The CPU mirror of runtime_shaders/substrate_fog_cloud.h (the volumetric fog
// cloud BSDF: its sample's sanitizing, the 12-byte froxel payload with its
// RGB9E5 words, Hillaire 2015's analytic step and the Henyey-Greenstein
// phase), in double, one function per shader function with the same guards
// and constants; plus a ray-marcher over a medium given as a function of
// position (marchFogCloud), what a volume pass does with the shader's step.
// The model, the payload's layout and the guards are described in the shader.
#pragma once
#include <array>
#include <cstdint>
#include <functional>

namespace substratec::reference {

inline constexpr double kFogMaxExtinction = 65408.0;  // SUBSTRATE_FOG_MAX_EXTINCTION: RGB9E5's largest value
inline constexpr double kFogMaxStep = 1e9;            // SUBSTRATE_FOG_MAX_STEP (m)
inline constexpr double kFogThinStep = 1e-2;          // SUBSTRATE_FOG_THIN_STEP (optical depth)
inline constexpr int kFogMaxMarchSteps = 1 << 20;     // marchFogCloud's bound on its step count

/// SubstrateFogCloudSample.
struct FogCloudSample {
  std::array<double, 3> albedo{}, extinction{}, emissive{};  // extinction 1/m; emissive radiance per metre
  double ambientOcclusion = 1;
};

/// substrate_fog_cloud_make: albedo and ao saturated, extinction and emissive
/// clamped to [0, 65408]; NaN gives 0, +Inf the maximum.
FogCloudSample fogCloudMake(std::array<double, 3> albedo, std::array<double, 3> extinction,
                            std::array<double, 3> emissive, double ambientOcclusion);
/// substrate_rgb9e5_encode: r bits 0-8, g 9-17, b 18-26, exponent 27-31 (bias 15).
std::uint32_t rgb9e5Encode(std::array<double, 3> color);
/// substrate_rgb9e5_decode.
std::array<double, 3> rgb9e5Decode(std::uint32_t word);
/// substrate_fog_cloud_pack: {albedo unorm8 x3 + ao unorm8, extinction RGB9E5, emissive RGB9E5}.
std::array<std::uint32_t, 3> fogCloudPack(const FogCloudSample& s);
/// substrate_fog_cloud_unpack.
FogCloudSample fogCloudUnpack(std::array<std::uint32_t, 3> words);
/// substrate_fog_cloud_step: one step of length ds with the sample's coefficients constant.
void fogCloudStep(const FogCloudSample& s, double ds, std::array<double, 3> inScattered,
                  std::array<double, 3> ambient, std::array<double, 3>& radiance, std::array<double, 3>& throughput);
/// substrate_fog_hg_phase: Henyey-Greenstein, 1 / (4 pi) at g = 0; g clamped to [-0.99, 0.99].
double hgPhase(double cosTheta, double g);

struct FogMarch {
  std::array<double, 3> radiance{}, throughput{1, 1, 1};
};

/// Marches [0, length] from `origin` along `direction` (taken as given: a unit
/// vector for `length` in metres) in `steps` equal steps (clamped to [1, 2^20]),
/// each with fogCloudStep and the medium sampled at the step's midpoint;
/// inScattered and ambient the same at every step. Starts from radiance 0,
/// throughput 1.
FogMarch marchFogCloud(const std::function<FogCloudSample(const std::array<double, 3>& position)>& medium,
                       std::array<double, 3> origin, std::array<double, 3> direction, double length, int steps,
                       std::array<double, 3> inScattered, std::array<double, 3> ambient);

}  // namespace substratec::reference
