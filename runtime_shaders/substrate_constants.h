// substratec runtime shaders: the numbers the compiler shares with the
// shaders, as plain #defines (no dialect: this header is also compiled as C++
// by the compiler, which takes these values from here and nowhere else).
// substrate_closure.h includes it; include it directly only from C++. The
// #ifndef ones may be overridden by defining them before substrate_closure.h.
#ifndef SUBSTRATE_CONSTANTS_H
#define SUBSTRATE_CONSTANTS_H 1

// Feature bits of a closure, the same bits as the closure header's feature
// field in docs/storage.md.
#define SUBSTRATE_FEATURE_F90 1u
#define SUBSTRATE_FEATURE_ANISOTROPY 2u
#define SUBSTRATE_FEATURE_HAZE 4u
#define SUBSTRATE_FEATURE_FUZZ 8u
#define SUBSTRATE_FEATURE_GLINT 16u
#define SUBSTRATE_FEATURE_SPECULAR_PROFILE 32u
#define SUBSTRATE_FEATURE_WEIGHT 64u
#define SUBSTRATE_FEATURE_COVERAGE_ABOVE 128u

#define SUBSTRATE_SSS_NONE 0u
#define SUBSTRATE_SSS_WRAP 1u
#define SUBSTRATE_SSS_DIFFUSION 2u
#define SUBSTRATE_SSS_SIMPLE_VOLUME 3u

// Layout classes (material header bits 0-1).
#define SUBSTRATE_LAYOUT_SIMPLE 0u
#define SUBSTRATE_LAYOUT_SINGLE 1u
#define SUBSTRATE_LAYOUT_COMPLEX 2u
#define SUBSTRATE_LAYOUT_SPECIAL 3u

// Diffuse model: 0 Lambert, 1 Chan 2018, 2 Chan 2024, 3 EON (Portsmouth 2025);
// the default when the includer defines none.
#define SUBSTRATE_DIFFUSE_MODEL_DEFAULT 2

// What one more interface above lets through, folded into a transmittance
// along the normal (substrate_extra_interfaces in substrate_tree.h explains
// the bound): Q^n for the n interfaces past the ones the lighting counts.
#define SUBSTRATE_EXTRA_INTERFACE 0.91

// The layers above a closure are read as one dielectric interface of IOR 1.5
// (F0 0.04) over their media (issue 19, step 2; runtime_shaders/README.md,
// "Closures under layers"): the closure's own interface is relative to it
// (substrate_closure_fresnel_ends), light crosses the media along the
// refracted direction (substrate_coat_path_length), and the diffuse gets back
// what the interface's underside reflects down (substrate_closure_coat_diffuse).
//   SQRT_F0: sqrt(F0) of the interface above, (1.5 - 1) / (1.5 + 1);
//   TRAP: 1.5^2 * 0.59634, the IOR squared times the interface's hemispherical
//         reflectance seen from inside (total internal reflection included).
#define SUBSTRATE_COAT_SQRT_F0 0.2
#define SUBSTRATE_COAT_TRAP 1.34177

// The tree walk's guard against a division by a coverage of 0 (substrate_tree.h).
#define SUBSTRATE_TREE_EPSILON 1e-6

// Shading normals that face away from the eye by less than this (in NoV) are
// shaded as grazing (NoV = 1e-4); beyond it the closure returns 0.
#ifndef SUBSTRATE_NOV_BIAS
#define SUBSTRATE_NOV_BIAS 1e-3
#endif

// SSS wrap: per-channel wrap amount w = mfp / (mfp + SCALE) (meters).
#ifndef SUBSTRATE_SSS_WRAP_MFP_SCALE
#define SUBSTRATE_SSS_WRAP_MFP_SCALE 0.005
#endif

// Glints: microfacet density per unit uv area is 2^lerp(MIN, MAX, glintValue);
// the reflection cone half-angle (radians) is CONE_ANGLE.
#ifndef SUBSTRATE_GLINT_LOG2_DENSITY_MIN
#define SUBSTRATE_GLINT_LOG2_DENSITY_MIN 8.0
#endif
#ifndef SUBSTRATE_GLINT_LOG2_DENSITY_MAX
#define SUBSTRATE_GLINT_LOG2_DENSITY_MAX 40.0
#endif
#ifndef SUBSTRATE_GLINT_CONE_ANGLE
#define SUBSTRATE_GLINT_CONE_ANGLE 0.05
#endif

// The cosine at which the transmittance of the layers above is evaluated for
// light arriving from the whole hemisphere (irradiance): the mean of 1/mu under
// the cosine-weighted hemisphere is 2, so T^(1/0.5) is exact to first order in
// the optical depth.
#ifndef SUBSTRATE_DIFFUSE_MEAN_COS
#define SUBSTRATE_DIFFUSE_MEAN_COS 0.5
#endif

#endif
