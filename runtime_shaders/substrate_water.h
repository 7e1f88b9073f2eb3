// substratec runtime shaders: the single-layer water's body — what a pixel of
// water shows of the water behind its surface and of the light the water
// scatters toward the eye. Common dialect; a water material's file includes it
// (after substrate_closure.h and substrate_common.h); substrate_lighting.h
// defines substrate_water_seen on it (SUBSTRATE_USE_WATER).
//
// The model (docs/format.md, "The single-layer water"; UE's Single Layer Water,
// whose Substrate BSDF keeps it): the surface is one slab closure, lit like any
// (the water's interface, F0 = 0.08 specular, and the top material that covers
// `opacity` of it); under the uncovered share the water body between the
// surface and what lies behind it, `distance` metres along the view (refraction
// ignored, as UE's), holds
//   behind x colour scale x T + albedo x (1 - T) x phase x light,  T = exp(-extinction distance),
// the background seen through the water and the directional light scattered
// once toward the eye on the way (the light unattenuated inside the water and
// the phase at the angle between the light's and the view's directions, both
// unrefracted: UE's approximation; no ambient in-scattering). That radiance
// crosses the interface along the view (1 - its directional albedo at NoV) and
// the light crosses it once going in (1 - at NoL).
//
// The background is the host's: what the scene shows behind the water surface
// and its distance from the eye, rendered before the water (UE's "scene colour
// and depth without single-layer water"). The forward pass adds what
// substrate_water_seen returns to its colour, the base pass to its emissive
// target (docs/codegen.md, "Single-layer water"). The CPU mirror is
// compiler/tools/reference/water.cc.
#ifndef SUBSTRATE_WATER_H
#define SUBSTRATE_WATER_H 1

#include "substrate_fog_cloud.h"  // substrate_fog_hg_phase

// The water body of a single-layer water material (<name>_evaluate's `water`).
struct SubstrateWater {
  float3 albedo;       // single-scattering albedo, [0,1]
  float3 extinction;   // 1/m (UE's pin is 1/cm: x 100)
  float phaseG;        // Henyey-Greenstein anisotropy, [-1,1]
  float3 scaleBehind;  // colour scale of what is seen behind the water, >= 0
  float opacity;       // the top material's opacity: the share of the surface that hides the water, [0,1]
  float f0;            // the water surface's F0, 0.08 specular
};

void substrate_water_init(out SubstrateWater w) {
  w.albedo = SUBSTRATE_SPLAT3(0.0);
  w.extinction = SUBSTRATE_SPLAT3(0.0);
  w.phaseG = 0.0;
  w.scaleBehind = SUBSTRATE_SPLAT3(1.0);
  w.opacity = 0.0;
  w.f0 = 0.04;
}

// x when it is a number in (0, hi], hi above, 0 for NaN and x <= 0.
float3 substrate_water_clamp3(float3 x, float hi) {
  return float3(x.x > 0.0 ? min(x.x, hi) : 0.0, x.y > 0.0 ? min(x.y, hi) : 0.0, x.z > 0.0 ? min(x.z, hi) : 0.0);
}

// The body's radiance toward the eye just under the surface: `background`
// through `distance` metres of water (NaN or <= 0: none), plus `light`
// scattered once at the phase angle of cosine `cosPhase` on the way.
float3 substrate_water_body(SubstrateWater w, float3 background, float distance, float cosPhase, float3 light) {
  float d = distance > 0.0 ? min(distance, SUBSTRATE_FLT_MAX) : 0.0;
  float3 tau = min(substrate_water_clamp3(w.extinction, SUBSTRATE_FLT_MAX) * d, SUBSTRATE_SPLAT3(88.0));
  float3 t = exp(-tau);
  float3 behind = substrate_water_clamp3(background, SUBSTRATE_FLT_MAX) * substrate_water_clamp3(w.scaleBehind, 65504.0);
  float phase = substrate_fog_hg_phase(cosPhase, w.phaseG);
  return substrate_water_clamp3(behind * t + saturate(w.albedo) * (SUBSTRATE_SPLAT3(1.0) - t) *
                                    substrate_water_clamp3(light, SUBSTRATE_FLT_MAX) * phase,
                                SUBSTRATE_FLT_MAX);
}

#endif
