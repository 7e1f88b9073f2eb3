// substratec runtime shaders: the eye BSDF's iris — what an eye closure
// (SUBSTRATE_FEATURE_EYE) changes in a slab's lighting. Common dialect;
// substrate_bsdf.h includes it (include order: prelude -> substrate_closure.h
// -> substrate_common.h -> this).
//
// The model (docs/format.md, "The eye BSDF"): UE's Eye shading model, which
// its Substrate Eye BSDF keeps (ShadingModels.ush, EyeBxDF), on the slab's
// interface and diffuse:
//  - the cornea is the slab's GGX interface: the closure's normal and
//    roughness, F0 0.04 and F90 1 (UE's specular 0.5), with the slab's energy
//    compensation; nothing of it is stored but the roughness;
//  - under it the sclera is the slab's diffuse (the material's diffuse model)
//    with the slab's coupling to the interface along the view and the light;
//  - the iris, where the iris mask is 1, takes in place of the diffuse's
//    cosine the light's cosine to the iris normal times UE's caustic,
//    0.8 + 0.2 (p + 1) max(C.L, 0)^p with p = lerp(12, 1, max(I.L, 0)) and the
//    caustic axis C = normalize(lerp(P, -N, mask * distance)) (P the iris
//    plane's normal: the iris seen as a concave dish behind the cornea),
//    divided by SUBSTRATE_EYE_CAUSTIC_MEAN so that a white iris facing the
//    light with C = I reflects what a white Lambertian does (UE's returns
//    1.0412 times as much). Between, the two lerp by the mask.
// Light reaches the iris through the cornea only: a light below the cornea's
// horizon lights neither (the slab's gate). The iris normal's share of the
// environment: the caustic's mean is the Lambertian's, so the split sum's
// diffuse is the sclera's (substrate_env_split_sum keeps the slab's).
// The CPU mirror is compiler/tools/reference/bsdf.cc (eyeIrisCosine).
#ifndef SUBSTRATE_EYE_H
#define SUBSTRATE_EYE_H 1

#if SUBSTRATE_USE_EYE

// What multiplies albedo / pi for the iris in place of the diffuse's cosine.
float substrate_eye_iris_cosine(SubstrateClosure c, float3 N, float3 L) {
  float mask = saturate(c.iris.x);
  float depth = mask * saturate(c.iris.y);
  float3 axis = substrate_safe_normalize(lerp(c.irisPlaneN, -N, depth), c.irisPlaneN);
  float irisNoL = saturate(dot(c.irisN, L));
  float p = lerp(12.0, 1.0, irisNoL);
  float caustic = 0.8 + 0.2 * (p + 1.0) * pow(saturate(dot(axis, L)), p);
  return irisNoL * caustic * (1.0 / SUBSTRATE_EYE_CAUSTIC_MEAN);
}

// The diffuse of closure c before the light-side coupling: the sclera's
// (`sclera`, the material's diffuse model) lerped by the iris mask toward the
// iris's, albedo / pi times substrate_eye_iris_cosine; `sclera` itself for a
// closure that is no eye.
mfloat3 substrate_eye_diffuse(SubstrateClosure c, mfloat3 sclera, mfloat3 albedo, float3 N, float3 L) {
  if ((c.features & SUBSTRATE_FEATURE_EYE) == 0u) {
    return sclera;
  }
  return mlerp(sclera, albedo * SUBSTRATE_M(SUBSTRATE_INV_PI * substrate_eye_iris_cosine(c, N, L)),
               SUBSTRATE_M(saturate(c.iris.x)));
}

#endif
#endif
