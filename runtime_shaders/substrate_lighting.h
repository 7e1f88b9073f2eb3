// substratec runtime shaders: lighting of closures — throughputs of the layers
// above, the deferred light loop, split-sum environment lighting and
// translucency. Common dialect; include order: prelude -> substrate_closure.h
// -> substrate_common.h -> substrate_energy_lut.h -> substrate_bsdf.h -> this.
// Formulas and references: README.md.
#ifndef SUBSTRATE_LIGHTING_H
#define SUBSTRATE_LIGHTING_H 1

// SUBSTRATE_DIFFUSE_MEAN_COS: substrate_constants.h. The layers' throughput
// along a direction (substrate_closure_above_throughput) is in substrate_bsdf.h.

// Dynamic culling: false when the closure's weight is 0 (or not a number) at
// this pixel, so the lighting skips it (its contribution would be 0).
bool substrate_closure_visible(SubstrateClosure c) {
  return c.weight > 0.0;
}

// Along the view: c.weight * substrate_closure_above_throughput(c, NoV, V) (the
// weight clamped to half's range in half precision). V: the view direction
// (its azimuth about a stretched top matters, substrate_coat_floor_along).
mfloat3 substrate_closure_view_throughput(SubstrateClosure c, float NoV, float3 V) {
  return SUBSTRATE_M_CLAMPED(max(c.weight, 0.0)) * substrate_closure_above_throughput(c, NoV, V);
}

// Along the light, given what the layers above let through along the view
// (viewCrossing = substrate_closure_layers_crossing(c, NoV, V)) and along the
// light (lightCrossing, at the light's cosine and direction; the azimuths'
// mean, substrate_coat_mean_direction, for light with no one direction):
// lerp(1, lightCrossing, substrate_cover_given_view(coverageAbove, viewCrossing)),
// the layers met only where the view met them (substrate_bsdf.h, issue 19,
// step 22). The closure's weight is counted once, in the view throughput; the
// product of the two is (1 - C) + C t_V t_L. Exactly 1 on top (C = 0), where
// the crossings need not be taken.
mfloat3 substrate_closure_light_throughput(SubstrateClosure c, float3 viewCrossing, float3 lightCrossing) {
  return SUBSTRATE_M3(lerp(SUBSTRATE_SPLAT3(1.0), lightCrossing,
                           substrate_cover_given_view(saturate(c.coverageAbove), viewCrossing)));
}

// One closure lit by one light of radiance `radiance` (the light's radiance
// times its solid angle / attenuation, i.e. what multiplies BSDF * NoL):
// max(weight, 0) ((1 - C) + C t_V t_L) * BSDF * NoL * radiance, t_V and t_L
// what the layers above let through along the view and the light
// (substrate_closure_layers_crossing; a wrap lobe's light crosses them at its
// own cosine, substrate_wrap_light_cosine), C their coverage: a path meets
// them on both sides or on neither (issue 19, step 22), which is the view
// throughput times the light's given the view's. Emissive is not added here
// (the base pass adds it once). A closure whose weight is 0 at this pixel (a
// mix or a coverage that hides it) is skipped: nothing is evaluated.
float3 substrate_light_closure(SubstrateClosure c, float3 V, float3 L, float3 radiance) {
  if (!substrate_closure_visible(c)) {
    return SUBSTRATE_SPLAT3(0.0);
  }
  float3 N = substrate_closure_normal(c);
  float3 f = substrate_eval_closure(c, V, L);
  mfloat3 throughput = SUBSTRATE_MSPLAT3(SUBSTRATE_M_CLAMPED(max(c.weight, 0.0)));
#if SUBSTRATE_USE_LAYERS
  float cover = saturate(c.coverageAbove);
  if (cover > 0.0) {
    float3 pair = substrate_closure_layers_crossing(c, dot(N, V), V) *
                  substrate_closure_layers_crossing(c, substrate_wrap_light_cosine(c, dot(N, L)), L);
    throughput *= SUBSTRATE_M3(lerp(SUBSTRATE_SPLAT3(1.0), pair, cover));
  }
#endif
  return SUBSTRATE_F3(throughput) * f * radiance;
}

// The deferred light loop over the unpacked closures of a pixel. The optional
// lobes branch on each closure's feature bits inside substrate_eval_closure,
// so pixels without a feature never run its code; closures of weight 0 are
// skipped (substrate_light_closure).
float3 substrate_light_closures(SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES], uint count, float3 V, float3 L,
                                float3 radiance) {
  float3 sum = SUBSTRATE_SPLAT3(0.0);
  uint n = min(count, uint(SUBSTRATE_MAX_CLOSURES));
  for (uint i = 0u; i < n; ++i) {
    sum += substrate_light_closure(closures[i], V, L, radiance);
  }
  return sum;
}

// What a closure's interface reflects at cosine NoV (its directional albedo,
// E_spec = (F0 (E - B) + F90 B) W): the primary lobe's, lerped toward the haze
// lobe's by the haze weight, from the closure's Fresnel ends f0, f90 and the
// curve between them (substrate_closure_fresnel_ends). The environment and the translucency both
// remove it from what reaches the diffuse or passes through. `dielectric`: the
// same for the closure's dielectric part of ends fd (substrate_closure_dielectric_part,
// for substrate_diffuse_transmission).
mfloat3 substrate_closure_specular_albedo_of(SubstrateClosure c, mfloat3 f0, mfloat3 f90, SubstrateFresnelCurve curve,
                                             float2 fd, float NoV, out float dielectric) {
  mfloat3 f0w = substrate_closure_compensated_f0(c, f0, fd);
  mfloat3 specAlbedo;
  float msRate = substrate_closure_dielectric_ms(c);
  substrate_specular_energy(f0, f90, curve, fd, f0w, msRate, NoV, saturate(c.roughness), specAlbedo, dielectric);
#if SUBSTRATE_USE_HAZE
  if ((c.features & SUBSTRATE_FEATURE_HAZE) != 0u && c.secondRoughnessWeight > 0.0) {
    mfloat3 specAlbedo2;
    float dielectric2;
    substrate_specular_energy(f0, f90, curve, fd, f0w, msRate, NoV, saturate(c.secondRoughness), specAlbedo2,
                              dielectric2);
    specAlbedo = mlerp(specAlbedo, specAlbedo2, SUBSTRATE_M(saturate(c.secondRoughnessWeight)));
    dielectric = lerp(dielectric, dielectric2, saturate(c.secondRoughnessWeight));
  }
#endif
  return specAlbedo;
}

// The same from the closure's own Fresnel ends (substrate_closure_fresnel_ends).
mfloat3 substrate_closure_specular_albedo(SubstrateClosure c, float NoV) {
  mfloat3 f0;
  mfloat3 f90;
  SubstrateFresnelCurve curve;
  substrate_closure_fresnel_ends(c, f0, f90, curve);
  float dielectric;
  return substrate_closure_specular_albedo_of(c, f0, f90, curve, SUBSTRATE_SPLAT2(1.0), NoV, dielectric);
}

// ---------------------------------------------------------------------------
// Environment lighting (split sum, Karis 2013).

// Roughness of the prefiltered fetch: the primary roughness, lerped toward the
// haze roughness by the haze weight when the closure has haze.
float substrate_env_roughness(SubstrateClosure c) {
  float r = saturate(c.roughness);
#if SUBSTRATE_USE_HAZE
  if ((c.features & SUBSTRATE_FEATURE_HAZE) != 0u) {
    r = lerp(r, saturate(c.secondRoughness), saturate(c.secondRoughnessWeight));
  }
#endif
  return r;
}

// Direction to fetch the prefiltered environment at: the mirror direction
// R = 2 (N.V) N - V moved toward N for rough lobes (dominant direction,
// Lagarde & de Rousiers 2014: lerp(N, R, (1 - a)(sqrt(1 - a) + a)), a = r^2).
// Anisotropic closures first bend N toward V within the plane orthogonal to
// the axis the facets tilt about (B for A > 0, T for A < 0), by |A| sat(5 r)
// (the bent-normal approximation of the stretched lobe).
float3 substrate_reflection_dir(SubstrateClosure c, float3 V) {
  float3 N = substrate_closure_normal(c);
  float r = substrate_env_roughness(c);
#if SUBSTRATE_USE_ANISOTROPY
  if ((c.features & SUBSTRATE_FEATURE_ANISOTROPY) != 0u && c.anisotropy != 0.0) {
    float3 T;
    float3 B;
    substrate_closure_frame(c, N, T, B);
    float A = clamp(c.anisotropy, -1.0, 1.0);
    // A > 0 (ax > ay): the facets tilt mostly along T, i.e. about B, so the
    // normal is bent toward V within the plane orthogonal to B (and vice versa).
    float3 axis = B;
    if (A < 0.0) {
      axis = T;
    }
    float3 side = cross(axis, V);
    float3 bentN = substrate_safe_normalize(cross(side, axis), N);
    N = substrate_safe_normalize(lerp(N, bentN, abs(A) * saturate(5.0 * r)), N);
  }
#endif
  float NoV = dot(N, V);
  float3 R = 2.0 * NoV * N - V;
  float a = r * r;
  float k = (1.0 - a) * (sqrt(1.0 - a) + a);
  return substrate_safe_normalize(lerp(N, R, k), N);
}

// Mip of a prefiltered cube of `mipCount` levels prefiltered with perceptual
// roughness r_i = i / (mipCount - 1) at mip i: r (mipCount - 1).
float substrate_env_mip(float roughness, float mipCount) {
  return saturate(roughness) * max(mipCount - 1.0, 0.0);
}

// Split-sum environment lighting of one closure (Karis 2013), the light-side
// throughput of the layers above included, the view-side one NOT: the caller
// multiplies by substrate_closure_view_throughput(c, NoV), as for emissive.
//   prefilteredRadiance: the prefiltered cube at substrate_reflection_dir(c, V)
//                        and mip substrate_env_mip(roughness, mipCount) (the
//                        closure's roughness, or substrate_env_roughness(c) to
//                        account for haze);
//   irradiance:          E = integral of L cos over the hemisphere around N
//                        (W/m^2; a Lambertian albedo a reflects a E / pi).
// Specular: E_spec = (F0 (E - B) + F90 B) W from the same tables as the direct
// lighting (haze: lerped by weight), under layers times what their top sends
// back down (substrate_closure_coat_specular at NoV = NoL), tinted by the
// specular profile at (NoV, NoV); diffuse: albedo T E / pi,
// T = substrate_diffuse_transmission (every diffuse model, wrap included,
// uses albedo as its hemispherical albedo); fuzz: amount colour
// min(E_fuzz, 1) E / pi on top, the rest attenuated by (1 - amount min(E_fuzz, 1))
// at NoV (the direct light's light-side term, E_fuzz(NoL), is not applied here:
// the environment has no single light direction), the diffuse on top also by
// the mean of the direct light's pair of crossings
// (substrate_fuzz_diffuse_pair_mean: what a darker base absorbs of what the
// fuzz sends back down).
// The layers above are crossed at NoV by the specular (its light comes from
// the mirror direction) and at SUBSTRATE_DIFFUSE_MEAN_COS by the diffuse and fuzz.
float3 substrate_env_split_sum(SubstrateClosure c, float3 V, float3 prefilteredRadiance, float3 irradiance) {
#if SUBSTRATE_USE_HAIR
  if ((c.features & SUBSTRATE_FEATURE_HAIR) != 0u) {
    return substrate_hair_env(c, V, irradiance);  // a fibre's albedo times the mean radiance
  }
#endif
  float3 N = substrate_closure_normal(c);
  float NoVraw = dot(N, V);
  if (!(NoVraw > -SUBSTRATE_NOV_BIAS)) {
    return SUBSTRATE_SPLAT3(0.0);
  }
  float NoV = clamp(NoVraw, SUBSTRATE_MIN_COS, 1.0);
  mfloat3 f0;
  mfloat3 f90;
  SubstrateFresnelCurve curve;
  substrate_closure_fresnel_ends(c, f0, f90, curve);
  float2 fd = substrate_closure_dielectric_part(c, f0, f90);
  float dielectric;
  mfloat3 specAlbedo = substrate_closure_specular_albedo_of(c, f0, f90, curve, fd, NoV, dielectric);
  // Radiance (HDR) is float; the weights that multiply it are mfloat. Under
  // layers: what their top sends back down (the light from the mirror
  // direction, at NoV).
  float3 spec = SUBSTRATE_F3(specAlbedo) *
                substrate_closure_coat_specular(c, f0, f90, fd, curve.share, NoV, NoV, substrate_env_roughness(c)) *
                max(prefilteredRadiance, SUBSTRATE_SPLAT3(0.0));
#if SUBSTRATE_USE_SPECULAR_PROFILE
  if ((c.features & SUBSTRATE_FEATURE_SPECULAR_PROFILE) != 0u && c.specularProfile > 0u) {
    spec *= SUBSTRATE_SPECULAR_PROFILE_SAMPLE(c.specularProfile - 1u, float2(NoV, NoV));
  }
#endif
  float3 irr = max(irradiance, SUBSTRATE_SPLAT3(0.0)) * SUBSTRATE_INV_PI;
  mfloat3 albedo = SUBSTRATE_M3(saturate(c.diffuseAlbedo));
  float2 ends = substrate_diffuse_interface(f0, f90, fd);
  float3 diffuse = SUBSTRATE_F3(albedo * substrate_diffuse_transmission(albedo, specAlbedo, dielectric)) *
                   substrate_closure_coat_diffuse(c, ends) * irr;
#if SUBSTRATE_USE_SSS
  // A slab's medium: its view dependence (substrate_bsdf.h, "A slab's medium";
  // the light's side averages to 1 over the hemisphere; no branch, as there).
  {
    float p;
    float3 s2 = substrate_closure_medium(c, SUBSTRATE_F3(albedo), saturate(c.roughness), p);
    diffuse *= (SUBSTRATE_SPLAT3(1.0) + s2 * SUBSTRATE_MEDIUM_MEAN_COS) / (SUBSTRATE_SPLAT3(1.0) + s2 * (p + (1.0 - p) * NoV));
  }
#endif
  // The mirror direction's azimuth is the view's (cos^2 alike); the diffuse's light has
  // none: the azimuths' mean (substrate_coat_mean_direction).
  // The light meets the layers only where the view met them (substrate_closure_light_throughput).
  mfloat3 specLight = SUBSTRATE_MSPLAT3(1.0);
  mfloat3 diffuseLight = SUBSTRATE_MSPLAT3(1.0);
#if SUBSTRATE_USE_LAYERS
  if (saturate(c.coverageAbove) > 0.0) {
    float3 viewCrossing = substrate_closure_layers_crossing(c, NoV, V);
    specLight = substrate_closure_light_throughput(c, viewCrossing, viewCrossing);
    diffuseLight = substrate_closure_light_throughput(
        c, viewCrossing,
        substrate_closure_layers_crossing(c, SUBSTRATE_DIFFUSE_MEAN_COS,
                                          substrate_coat_mean_direction(c, SUBSTRATE_DIFFUSE_MEAN_COS)));
  }
#endif
  float3 result = spec * SUBSTRATE_F3(specLight) + diffuse * SUBSTRATE_F3(diffuseLight);
#if SUBSTRATE_USE_FUZZ
  if ((c.features & SUBSTRATE_FEATURE_FUZZ) != 0u) {
    float amount = saturate(c.fuzzAmount);
    float eFuzz = min(substrate_fuzz_albedo(substrate_fuzz_cosine(c, NoV), c.fuzzRoughness), 1.0);
    // The diffuse on top: the direct light's pair of crossings averaged over
    // the hemisphere (not under layers, nor for the wrap lobe, as there).
    float cover = 0.0;
#if SUBSTRATE_USE_LAYERS
    cover = saturate(c.coverageAbove);
#endif
#if SUBSTRATE_USE_SSS
    cover = c.sssType == SUBSTRATE_SSS_WRAP ? 1.0 : cover;
#endif
    float3 pairMean = lerp(substrate_fuzz_diffuse_pair_mean(c, amount, SUBSTRATE_F3(albedo)), SUBSTRATE_SPLAT3(1.0), cover);
    result = (spec * SUBSTRATE_F3(specLight) + diffuse * SUBSTRATE_F3(diffuseLight) * pairMean) * (1.0 - amount * eFuzz) +
             saturate(c.fuzzColor) * (amount * eFuzz) * irr * SUBSTRATE_F3(diffuseLight);
  }
#endif
  return result;
}

// ---------------------------------------------------------------------------
// Translucency (dual-source blending).

// coverage:      saturate(c.weight), the share of the pixel this closure covers;
// transmittance: what the covered part lets through from behind, per channel:
//                substrate_closure_above_throughput(c, NoV, V) (the layers above, along V)
//                * (1 - E_spec(NoV)) (reflected by the interface)
//                * (1 - fuzzAmount min(E_fuzz, 1)) (caught by the fuzz).
// The caller blends dst = colour + dst * ((1 - coverage) + coverage * transmittance)
// (dual-source: src1 = that factor) and multiplies `transmittance` by the
// slab's own medium, substrate_transmittance(mfp, thickness / max(NoV, 1e-4)),
// which the closure does not carry.
void substrate_translucency(SubstrateClosure c, float NoV, float3 V, out float coverage, out float3 transmittance) {
  coverage = saturate(c.weight);
#if SUBSTRATE_USE_HAIR
  if ((c.features & SUBSTRATE_FEATURE_HAIR) != 0u) {
    transmittance = SUBSTRATE_SPLAT3(0.0);  // a fibre covers what it covers (its TT lobe is lit, not blended)
    return;
  }
#endif
  float mu = clamp(NoV, SUBSTRATE_MIN_COS, 1.0);
  mfloat3 specAlbedo = substrate_closure_specular_albedo(c, mu);
  transmittance = SUBSTRATE_F3(substrate_closure_above_throughput(c, mu, V) * (SUBSTRATE_MSPLAT3(1.0) - specAlbedo));
#if SUBSTRATE_USE_FUZZ
  if ((c.features & SUBSTRATE_FEATURE_FUZZ) != 0u) {
    transmittance *= 1.0 - saturate(c.fuzzAmount) * min(substrate_fuzz_albedo(substrate_fuzz_cosine(c, mu), c.fuzzRoughness), 1.0);
  }
#endif
}

// ---------------------------------------------------------------------------
// Single-layer water (substrate_water.h): what the surface lets through of its body.

#if SUBSTRATE_USE_WATER
#include "substrate_water.h"

// What a pixel of water shows of its body: the uncovered share of surface c
// (1 - opacity) times what the water's interface lets through along the view,
// of the body lit by `lightRadiance` from L through the interface.
// `behind`: rgb what lies behind the water, a its distance from the eye;
// `surfaceDistance`: the surface's.
float3 substrate_water_seen(SubstrateClosure c, SubstrateWater w, float4 behind, float surfaceDistance, float3 V,
                            float3 L, float3 lightRadiance) {
  float3 N = substrate_closure_normal(c);
  float NoVraw = dot(N, V);
  if (!(NoVraw > -SUBSTRATE_NOV_BIAS)) {
    return SUBSTRATE_SPLAT3(0.0);  // seen from below the surface: not this model's
  }
  SubstrateClosure s = c;  // the bare water interface
  s.f0 = SUBSTRATE_SPLAT3(saturate(w.f0));
  s.f90 = SUBSTRATE_SPLAT3(1.0);
  s.features = 0u;
  float NoV = clamp(NoVraw, SUBSTRATE_MIN_COS, 1.0);
  float NoL = dot(N, L);
  float3 through = SUBSTRATE_SPLAT3(1.0) - SUBSTRATE_F3(substrate_closure_specular_albedo(s, NoV));
  float3 lightIn = NoL > 0.0 ? lightRadiance * (SUBSTRATE_SPLAT3(1.0) - SUBSTRATE_F3(substrate_closure_specular_albedo(s, NoL)))
                             : SUBSTRATE_SPLAT3(0.0);
  float3 body = substrate_water_body(w, behind.rgb, behind.a - surfaceDistance, dot(-L, V), lightIn);
  return (1.0 - saturate(w.opacity)) * through * body;
}
#endif

#endif
