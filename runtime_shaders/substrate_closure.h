// substratec runtime shaders: the closure — what one slab contributes after
// the tree walk, and what the lighting evaluates. Written in the common
// dialect (include substrate_prelude.glsl or .hlsl first).
//
// The generated material function fills closures inline (forward) or packs
// them (base pass); the deferred lighting unpacks them (substrate_pack.h).
// Field meanings and ranges follow docs/storage.md.
#ifndef SUBSTRATE_CLOSURE_H
#define SUBSTRATE_CLOSURE_H 1

#include "substrate_constants.h"  // feature bits, SSS types, layout classes

#ifndef SUBSTRATE_MAX_CLOSURES
#define SUBSTRATE_MAX_CLOSURES 8
#endif

// 1: some closure may be a hair (SUBSTRATE_FEATURE_HAIR, substrate_hair.h);
// 0 leaves its field out of the closure and its code out of the runtime.
#ifndef SUBSTRATE_USE_HAIR
#define SUBSTRATE_USE_HAIR 1
#endif
// 1: some closure may be an eye (SUBSTRATE_FEATURE_EYE, substrate_eye.h);
// 0 leaves its fields out of the closure and its code out of the runtime.
#ifndef SUBSTRATE_USE_EYE
#define SUBSTRATE_USE_EYE 1
#endif
// 1: the material is a single-layer water (substrate_water.h): the lighting
// defines substrate_water_seen.
#ifndef SUBSTRATE_USE_WATER
#define SUBSTRATE_USE_WATER 1
#endif

struct SubstrateClosure {
  float3 diffuseAlbedo;   // post multiple scattering, [0,1]
  float3 f0;              // reflectance at normal incidence, [0,1]
  float3 f90;             // reflectance at grazing (hue only), [0,1]
  float roughness;        // perceptual, shared by diffuse and primary specular, [0,1]
  float anisotropy;       // [-1,1], Kulla-Conty
  float3 N;               // unit normal (world or view space, the caller's choice)
  float3 T;               // unit tangent, orthogonal to N (used when anisotropic)
  float3 sssMfp;          // mean free path in meters (after sss_mfp_scale); 0 = none
  float sssPhaseAnisotropy;
  uint sssType;           // SUBSTRATE_SSS_*
  float secondRoughness;  // haze lobe
  float secondRoughnessWeight;
  float fuzzAmount;
  float3 fuzzColor;
  float fuzzRoughness;
  float glintValue;       // 1 = no glint
  float2 glintUv;
  float4 glintUvDerivatives;  // d(uv)/dx in xy, d(uv)/dy in zw
  uint specularProfile;       // profile index + 1; 0 = none
#if SUBSTRATE_USE_HAIR
  float4 hair;                // a hair closure's (SUBSTRATE_FEATURE_HAIR, substrate_hair.h): azimuthal
                              // roughness, ior, cuticle angle in degrees, scatter
#endif
#if SUBSTRATE_USE_EYE
  float3 irisN;               // an eye closure's (SUBSTRATE_FEATURE_EYE, substrate_eye.h): the iris's normal,
  float3 irisPlaneN;          // the iris plane's normal (the caustic's axis), both unit,
  float2 iris;                // and the iris mask and iris distance, [0,1]
#endif
  float3 emissive;            // forward only (deferred adds it in the base pass)
  float weight;               // mix and coverage weights on the path to the root
  float3 topTransmittance;    // transmittance of the layers above along the normal (1 on top)
  float coverageAbove;        // coverage of the layers above (0 on top)
  uint extraInterfaces;       // interfaces above beyond the first, 0..3 (closure header bits 14-15)
  float coatFloor;            // what the layers' rough top lets through at grazing angles, substrate_coat_floor
                              // of the top-layer roughness (not stored per closure); 0 under a smooth top,
                              // under more than one interface and under a mix of tops
  float coatInterface;        // what the layers' top interface lets through head-on, 1 - its F0
                              // (substrate_coat_interface of the one closure on top; not stored per
                              // closure); 0.96, IOR 1.5's, under a mix of tops
  float2 coatStretch;         // the one stretched closure on top's squared GGX alphas as (ay^2, ax^2 - ay^2)
                              // (substrate_coat_stretch): its floor follows a direction's azimuth
                              // (substrate_coat_floor_along); 0 else
  float3 coatTangent;         // that top's tangent
  float coatShare;            // substrate_coat_mean_share of the floor (its mean over the azimuths under
                              // a stretched top), per pixel like coatFloor; 0 under a smooth top
  uint features;              // SUBSTRATE_FEATURE_* bits
  bool isTop;                 // nothing layered above
  bool coversLayers;          // on top of a pixel where some closure lies under layers (not stored:
                              // set per pixel from the closure headers): its lobe takes no
                              // dielectric multiple scattering (substrate_closure_dielectric_ms)
};

// The shading point as the generated material function sees it.
struct SubstrateGeometry {
  float3 N;            // unit geometric/vertex normal
  float3 T;            // unit tangent (orthogonal to N)
  float3 V;            // unit direction to the eye
  float3 position;     // world space, meters
  float2 uv0;
  float2 uv1;
  float4 vertexColor;
  float4 uvDerivatives;  // d(uv0)/dx in xy, d(uv0)/dy in zw (glints)
  float dither;          // per-pixel value in [0,1) for the centred quantization dither
};

// Which optional parts of the runtime a shader compiles. The generated code
// defines these (0 for features no slab of the material uses: a material pays
// only for what it uses); when undefined, everything is compiled (the generic
// deferred lighting).
#ifndef SUBSTRATE_USE_F90
#define SUBSTRATE_USE_F90 1
#endif
#ifndef SUBSTRATE_USE_ANISOTROPY
#define SUBSTRATE_USE_ANISOTROPY 1
#endif
#ifndef SUBSTRATE_USE_HAZE
#define SUBSTRATE_USE_HAZE 1
#endif
#ifndef SUBSTRATE_USE_FUZZ
#define SUBSTRATE_USE_FUZZ 1
#endif
#ifndef SUBSTRATE_USE_SSS
#define SUBSTRATE_USE_SSS 1
#endif
#ifndef SUBSTRATE_USE_GLINT
#define SUBSTRATE_USE_GLINT 1
#endif
#ifndef SUBSTRATE_USE_SPECULAR_PROFILE
#define SUBSTRATE_USE_SPECULAR_PROFILE 1
#endif
#ifndef SUBSTRATE_USE_EMISSIVE
#define SUBSTRATE_USE_EMISSIVE 1
#endif

// 1: some closure lies under more than one interface (a stack of layers), so
// the lighting raises the interface term to the power 1 + extraInterfaces.
#ifndef SUBSTRATE_USE_EXTRA_INTERFACES
#define SUBSTRATE_USE_EXTRA_INTERFACES 1
#endif
// 1: some closure lies under a layer (coverageAbove may be > 0), so the
// lighting compiles the layers' part: their throughput, the closure's
// interface relative to them, what their underside gives back to the diffuse.
#ifndef SUBSTRATE_USE_LAYERS
#define SUBSTRATE_USE_LAYERS 1
#endif
// 1: some closure under a layer may be a conductor (F0 above 0.1), whose
// lobe the layers' top partly sends back down (substrate_closure_coat_specular):
// the compiler clears it when every closure under a layer has a constant
// dielectric F0, for which the factor is exactly 1.
#ifndef SUBSTRATE_USE_COAT_CONDUCTOR
#define SUBSTRATE_USE_COAT_CONDUCTOR 1
#endif
// 1: some closure may read as a conductor (its largest F0 above 0.1), whose
// Fresnel follows a curve of its own per channel (substrate_fresnel_curve):
// the compiler clears it when every slab's F0 is a constant dielectric one,
// whose curve is chi, the same for every channel (one scalar per light).
#ifndef SUBSTRATE_USE_CONDUCTOR_CURVE
#define SUBSTRATE_USE_CONDUCTOR_CURVE 1
#endif
// 1: some closure may be a dielectric of F0 below 0.04 with no layers under
// or over it, whose Fresnel follows the curve of its own IOR
// (substrate_fresnel_curve; issue 19, step 24): the compiler clears it when
// every slab's F0 is a constant of at least 0.04, or the material has layers,
// whose closures keep chi.
#ifndef SUBSTRATE_USE_LOW_IOR_CURVE
#define SUBSTRATE_USE_LOW_IOR_CURVE 1
#endif
// 1: some closure may lie under an isotropic rough top's floor
// (SubstrateClosure.coatFloor, substrate_coat_floor): the compiler clears it
// when no closure of the material gets one (several closures on top, a
// stretched or hazy top, or every closure under layers under more than one
// interface), where the floor is 0 and the layers' interface term is the
// smooth one exactly.
#ifndef SUBSTRATE_USE_COAT_FLOOR
#define SUBSTRATE_USE_COAT_FLOOR 1
#endif
// 1: some closure may lie under one stretched top (SubstrateClosure.coatStretch,
// issue 19 step 19), whose floor follows a direction's azimuth about the
// top's tangent (substrate_coat_floor_along): the compiler clears it when the
// material has no anisotropic closure on top of others. Either switch compiles
// the floor's term and its share (coatShare); the isotropic floor's own uses
// (a conductor's rough path, substrate_coat_top_alpha) only the first.
#ifndef SUBSTRATE_USE_COAT_ANISO
#define SUBSTRATE_USE_COAT_ANISO 1
#endif
// 1: some closure under a layer may have a wrap lobe, whose light crosses the
// layers at its own cosine (substrate_wrap_light_cosine), or a fuzz, seen at
// the angles refracted into them (substrate_fuzz_under_layers): the compiler
// clears each when no closure under a layer has one. A closure on top meets
// layers of throughput 1 at every cosine and keeps its fuzz's angles.
#ifndef SUBSTRATE_USE_WRAP_UNDER_LAYERS
#define SUBSTRATE_USE_WRAP_UNDER_LAYERS 1
#endif
#ifndef SUBSTRATE_USE_FUZZ_UNDER_LAYERS
#define SUBSTRATE_USE_FUZZ_UNDER_LAYERS 1
#endif
// 1: a closure's diffuse lies under its dielectric part, and a conductor-like
// F0 is read as a metalness mix (substrate_closure_dielectric_part): the
// compiler sets it for materials with a metalness_to_diffuse_f0 slab; 0
// compiles the diffuse under the whole interface (1 - E_spec), as before.
#ifndef SUBSTRATE_USE_METALNESS_MIX
#define SUBSTRATE_USE_METALNESS_MIX 1
#endif
// 1: every closure the shader lights has a unit N (the generated material
// function guarantees it for a unit g.N: its normals go through
// substrate_tangent_to_world, which normalizes, or are g.N itself), so
// substrate_closure_normal returns N as is instead of re-normalizing it at every
// use. The forward entries and the kernels that light evaluated closures define
// it; the default (0) suits closures of any origin (deferred, unpacked).
#ifndef SUBSTRATE_UNIT_CLOSURE_NORMALS
#define SUBSTRATE_UNIT_CLOSURE_NORMALS 0
#endif
// Diffuse model: 0 Lambert, 1 Chan 2018, 2 Chan 2024, 3 EON (Portsmouth 2025).
#ifndef SUBSTRATE_DIFFUSE_MODEL
#define SUBSTRATE_DIFFUSE_MODEL SUBSTRATE_DIFFUSE_MODEL_DEFAULT
#endif

// Every field set to its neutral value (no feature, weight 1, on top).
void substrate_closure_init(out SubstrateClosure c) {
  c.diffuseAlbedo = SUBSTRATE_SPLAT3(0.18);
  c.f0 = SUBSTRATE_SPLAT3(0.04);
  c.f90 = SUBSTRATE_SPLAT3(1.0);
  c.roughness = 0.5;
  c.anisotropy = 0.0;
  c.N = float3(0.0, 0.0, 1.0);
  c.T = float3(1.0, 0.0, 0.0);
  c.sssMfp = SUBSTRATE_SPLAT3(0.0);
  c.sssPhaseAnisotropy = 0.0;
  c.sssType = SUBSTRATE_SSS_NONE;
  c.secondRoughness = 0.5;
  c.secondRoughnessWeight = 0.0;
  c.fuzzAmount = 0.0;
  c.fuzzColor = SUBSTRATE_SPLAT3(0.0);
  c.fuzzRoughness = 0.5;
  c.glintValue = 1.0;
  c.glintUv = SUBSTRATE_SPLAT2(0.0);
  c.glintUvDerivatives = SUBSTRATE_SPLAT4(0.0);
  c.specularProfile = 0u;
#if SUBSTRATE_USE_HAIR
  c.hair = float4(0.5, 1.55, 2.0, 0.0);
#endif
#if SUBSTRATE_USE_EYE
  c.irisN = float3(0.0, 0.0, 1.0);
  c.irisPlaneN = float3(0.0, 0.0, 1.0);
  c.iris = SUBSTRATE_SPLAT2(0.0);
#endif
  c.emissive = SUBSTRATE_SPLAT3(0.0);
  c.weight = 1.0;
  c.topTransmittance = SUBSTRATE_SPLAT3(1.0);
  c.coverageAbove = 0.0;
  c.extraInterfaces = 0u;
  c.coatFloor = 0.0;
  c.coatInterface = SUBSTRATE_COAT_T_0;
  c.coatStretch = SUBSTRATE_SPLAT2(0.0);
  c.coatTangent = float3(1.0, 0.0, 0.0);
  c.coatShare = 0.0;
  c.features = 0u;
  c.isTop = true;
  c.coversLayers = false;
}

// What the rough top of the layers above a closure lets through at grazing
// angles, per unit of their T_N (issue 19, step 9; substrate_coat_transmission
// in substrate_bsdf.h): f(r) = 1.094 x / (x + 0.175), x = max(r - 0.1, 0), r
// the pixel's top-layer roughness (the top-layer word's, so that the forward
// and the deferred lighting agree). 0 up to r 0.1, 0.91 at r 1. Computed once
// per pixel: the material function and the unpacker store it in
// SubstrateClosure.coatFloor of each closure under one interface (extra
// interfaces 0) when one closure is on top and its lobe is one isotropic GGX
// lobe, so that r is that interface's own roughness; else 0 (the smooth term:
// an inner interface may be smoother than the top, a mix of tops has no one
// roughness, and a stretched or hazy top reflects more at grazing angles than
// one lobe of roughness r: anisotropy -1 read 1.19 of a white furnace). Under
// one stretched top the floor follows a direction's azimuth instead
// (SubstrateClosure.coatStretch, substrate_coat_floor_projected; step 19).
float substrate_coat_floor(float topRoughness) {
  float x = max(topRoughness - SUBSTRATE_COAT_ROUGH_START, 0.0);
  return SUBSTRATE_COAT_ROUGH_SCALE * x / (x + SUBSTRATE_COAT_ROUGH_HALF);
}

// The share of the way from G_k to 1 that a rough top moves the mean of the
// layers' interface term (substrate_coat_transmission, issue 19 step 9):
// h(f) = sat(f (0.2533 + f (-1.2067 + 1.9925 f))), f the floor. The
// cosine-weighted mean of the term to the power 1 + k is at most G_k + (1 -
// G_k) h(f) for k = 0..3 (h is fitted above the largest of the four shares,
// within 0.017 of it; scripts/fit_coat_transmission.py), so the diffuse's
// normalization (substrate_closure_coat_diffuse) never gains energy; h(0) =
// 0: a smooth top keeps G_k. Set per pixel in SubstrateClosure.coatShare.
float substrate_coat_mean_share(float coatFloor) {
  return saturate(coatFloor * (SUBSTRATE_COAT_MEAN_A + coatFloor * (SUBSTRATE_COAT_MEAN_B + SUBSTRATE_COAT_MEAN_C * coatFloor)));
}

// Smallest GGX alpha (Kulla-Conty clamp; scripts/gen_energy_lut.py uses the same).
SUBSTRATE_CONST float SUBSTRATE_MIN_ALPHA = 1e-3;

// (ax, ay) from perceptual roughness r and anisotropy A (Kulla & Conty 2017):
// a = r^2, ax = a (1 + A), ay = a (1 - A), each clamped to [1e-3, 1].
float2 substrate_ggx_alpha(float roughness, float anisotropy) {
  float r = saturate(roughness);
  float a = r * r;
  float A = clamp(anisotropy, -1.0, 1.0);
  return clamp(float2(a * (1.0 + A), a * (1.0 - A)), SUBSTRATE_SPLAT2(SUBSTRATE_MIN_ALPHA), SUBSTRATE_SPLAT2(1.0));
}

// SubstrateClosure.coatStretch of a stretched top of roughness r and
// anisotropy A: its squared GGX alphas (substrate_ggx_alpha) as (ay^2, ax^2 -
// ay^2), so that the projected one at any azimuth is one multiply-add away.
float2 substrate_coat_stretch(float roughness, float anisotropy) {
  float2 a = substrate_ggx_alpha(roughness, anisotropy);
  return float2(a.y * a.y, a.x * a.x - a.y * a.y);
}

// The floor under a stretched top (coatStretch s) along a direction whose
// azimuth phi about the top's tangent has cos^2 phi = c2 in [0, 1] (issue 19,
// step 19): substrate_coat_floor of the roughness the lobe projects on that
// azimuth, r_o = (ax^2 c2 + ay^2 (1 - c2))^(1/4) = (s.x + s.y c2)^(1/4) (the
// projected alpha of an anisotropic GGX, Heitz 2014, under which its masking
// is an isotropic lobe's). A stretched top is rough along one azimuth and
// smooth along the other: read as smooth everywhere (a floor of 0, before
// step 19), a white base under glTF CoatParameterSweep's coat of anisotropy 1
// returned 0.47 of a white furnace at NoV 0.1 (-53 % against the truth).
// 0 for s = 0 (no stretched top).
float substrate_coat_floor_projected(float2 stretch, float c2) {
  return substrate_coat_floor(sqrt(sqrt(stretch.x + stretch.y * c2)));
}

// SubstrateClosure.coatShare under a stretched top: h of the projected floor
// (substrate_coat_floor_projected) averaged over the azimuths, by Gauss-Chebyshev
// in cos 2phi at two nodes (c2 = (1 -+ cos(pi/4)) / 2): a bound of the term's
// mean as h is of each azimuth's (their mean is the term's), within the fit's
// margin (Furnace.AWhiteBaseUnderAStretchedClearCoatIsLitThroughItsRoughAxis).
float substrate_coat_aniso_share(float2 stretch) {
  return (substrate_coat_mean_share(substrate_coat_floor_projected(stretch, SUBSTRATE_COAT_AZIMUTH_C2_0)) +
          substrate_coat_mean_share(substrate_coat_floor_projected(stretch, SUBSTRATE_COAT_AZIMUTH_C2_1))) *
         0.5;
}

// What the layers' top interface lets through head-on, for the closures under
// it (SubstrateClosure.coatInterface; issue 19, step 18): 1 - F0 of the one
// closure on top, F0 its channels' mean clamped to [0, SUBSTRATE_COAT_TOP_F0_MAX]
// (a dielectric's; the layers' term reads the rest of topTransmittance as
// their media). Set per pixel, like coatFloor, by the material function and
// the unpacker (the top closure is in the pixel: nothing more is stored).
// With 0.96, IOR 1.5's, for every top, a clear coat of F0 0.06 (IOR 1.65)
// left T_N 0.94, read as media of transmittance 0.98 whose trapped light the
// diffuse lost: a white Lambertian under it returned 0.88 of a white furnace
// head-on, 0.70 under a coat of IOR 2 (glTF CoatParameterSweep, OpenPBR's
// default coat IOR 1.6).
float substrate_coat_interface(float3 topF0) {
  return 1.0 - clamp(dot(topF0, SUBSTRATE_SPLAT3(1.0 / 3.0)), 0.0, SUBSTRATE_COAT_TOP_F0_MAX);
}

// The top's GGX alpha r^2 back from a floor f > 0, r = START + HALF f /
// (SCALE - f) (the inverse of substrate_coat_floor, f < SCALE); 0 for f = 0:
// no one rough top (issue 19, step 14: substrate_closure_coat_specular).
float substrate_coat_top_alpha(float coatFloor) {
  float f = clamp(coatFloor, 0.0, 0.99 * SUBSTRATE_COAT_ROUGH_SCALE);
  float r = SUBSTRATE_COAT_ROUGH_START + SUBSTRATE_COAT_ROUGH_HALF * f / (SUBSTRATE_COAT_ROUGH_SCALE - f);
  return f > 0.0 ? r * r : 0.0;
}

#endif
