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
// A hair closure (runtime_shaders/substrate_hair.h): not one of the 8 header
// feature bits; single-closure header bit 12 (a hair is always alone).
#define SUBSTRATE_FEATURE_HAIR 256u
// An eye closure (runtime_shaders/substrate_eye.h): not a header feature bit
// either; single-closure header bit 13 (an eye is always alone).
#define SUBSTRATE_FEATURE_EYE 512u

// The eye's iris (substrate_eye.h): (1 / pi) times the integral over the
// hemisphere around I of max(I.L, 0) (0.8 + 0.2 (p + 1) (I.L)^p),
// p = 12 - 11 I.L, UE's iris lighting with the caustic on the iris normal, in
// units of a Lambertian's (scipy quad of 2 mu (0.8 + 0.2 (13 - 11 mu)
// mu^(12 - 11 mu)) over [0, 1]); the iris's cosine is divided by it.
#define SUBSTRATE_EYE_CAUSTIC_MEAN 1.0411601538663962

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
// A slab's medium seen through its interface (issue 19, step 12; substrate_bsdf.h,
// "A slab's medium"; scripts/fit_medium_weight.py prints every figure here).
// SPREAD: how far a rough interface pulls the critical cosine toward 0, per
// unit of roughness (the rms of the medium's factor against the random walk,
// 0.031 over roughness 0.05 / 0.45 / 0.8, albedo 0.1 .. 0.9 and six views, is
// smallest there; 0.043 at 0); MEAN_COS: the mean cosine of the medium's
// normalization (0.631 .. 0.667 over the slopes under an index-matched
// boundary), whose image m' = p + (1 - p) MEAN_COS gives the light side's
// mean within 3.1 % (IOR 1 .. 2, any roughness and slope); INVERSE:
// s = (1 - A) / (1 + INVERSE A) inverts van de Hulst's albedo
// A = (1 - s)(1 - 0.139 s) / (1 + 1.17 s) to within 0.0066 in s, 0.1 % in the
// weight (minimax on the weight).
#define SUBSTRATE_MEDIUM_SPREAD 0.35
#define SUBSTRATE_MEDIUM_MEAN_COS 0.645
#define SUBSTRATE_MEDIUM_INVERSE 1.376
// Only a dielectric interface is made relative to the layers above: up to
// F0 0.1 it is; from there it blends back to its own F0, reached at 0.2 (read
// as a conductor, as the ground truth walks conductors). BLEND = 1 / (0.2 - 0.1).
#define SUBSTRATE_COAT_DIELECTRIC_F0 0.1
// The largest F0 substrate_coat_interface reads as the layers' top interface
// (issue 19, step 18): a top that lets light through is a dielectric's
// interface, IOR 2.47 at this F0 (an opaque top lets nothing through, T_N 0,
// whatever this reads). Up to SUBSTRATE_MIX_START, where the runtime still
// reads a closure as all dielectric: read up to 0.25, a smooth top of F0 0.2,
// whose own curve has left chi for Schlick's (substrate_fresnel_share), let
// through more than it does not reflect: 1.0018 of a white furnace at NoV 0.1
// (furnace_test.cc). Beyond it the rest of T_N reads as media, as before.
#define SUBSTRATE_COAT_TOP_F0_MAX 0.18
// What a dielectric interface's microsurface scatters more than once (issue
// 19, step 20): between its facets, and through them and out again, which a
// single-scattering lobe with Turquin's W = 1 + F0 (1 - E) / E (the conductor's
// compensation) leaves out: over a black base it read 5 ... 8 % short of the
// truth at roughness 0.3 ... 0.7, 10 ... 16 % at roughness 1, at every view.
// The lobe (and its albedo) of the curve's share (substrate_fresnel_share: 1 for
// a dielectric, 0 for a conductor) takes 1 + MS r, r the perceptual roughness:
// the least-squares factor over F0 0.04 and 0.08, r 0.2 ... 1 and NoV 1 ... 0.1
// (65,536 walks each; a factor in r alone keeps the lobe reciprocal).
#define SUBSTRATE_DIELECTRIC_MS 0.125
#define SUBSTRATE_COAT_CONDUCTOR_BLEND 10.0
// The diffuse of a slab lies under its dielectric part (issue 19, item 5;
// substrate_closure_dielectric_part). No dielectric reflects more than
// diamond's F0 0.172 (IOR 2.42): a slab whose F0 reaches MIX_START + 1 / MIX_BLEND
// (0.25) in a channel is read as a metalness mix, a conductor beside a
// dielectric, as metalness_to_diffuse_f0 writes it, and its diffuse is
// attenuated by the specular albedo of the dielectric part, of F0
// MIX_DIELECTRIC_F0 (the helper's 0.08 specular at its default 0.5, and
// glTF's), not by the mixed F0's; up to MIX_START (0.18) the slab is all
// dielectric; linear between. Under the layers above (coverageAbove 1) the
// dielectric part is relative to them, as substrate_closure_fresnel_ends
// makes a dielectric: ((sqrt(0.04) - 0.2) / (1 - 0.2 sqrt(0.04)))^2 = 0,
// index-matched; so is its share of the mixed F0 and F90 under them
// (substrate_closure_mix_under, issue 19 step 25).
#define SUBSTRATE_MIX_START 0.18
#define SUBSTRATE_MIX_BLEND 14.285714
#define SUBSTRATE_MIX_DIELECTRIC_F0 0.04
#define SUBSTRATE_MIX_DIELECTRIC_F0_UNDER 0.0
// The Fresnel curve of every interface between its F0 and its F90 (issue 19,
// step 4; substrate_fresnel_weight): chi(c) = t + D(t), t = (1 - c)^5,
// D(t) = (1 - t) s (A + B s), s = sqrt(t): the exact dielectric Fresnel of
// IOR 1.5, the interface the layers above are read as, normalized to [0, 1],
// within 9.7e-4 (a least-squares fit, scripts/fit_fresnel_albedo.py).
//   ROUGH_K, ROUGH_END: the share of a negative D(mean t) that the albedo
//   bound of a lobe gives up, K below roughness END and 0 from there
//   (substrate_fresnel_pull, substrate_fresnel_b; fitted as a bound on the
//   integral: the largest share needed is 0.425, at r 0.225).
#define SUBSTRATE_FRESNEL_CURVE_A 0.18317
#define SUBSTRATE_FRESNEL_CURVE_B -0.39315
#define SUBSTRATE_FRESNEL_ROUGH_K 0.43
// A conductor's curve (issue 19, step 23; substrate_fresnel_curve): the same
// form t + (1 - t) s (a + b s), per channel, with a and b cubics in
// x = sqrt(max(F0, MIN_F0)), a = A0 + x (A1 + x (A2 + x A3)), b likewise: the
// ground truth's conductor (Gulbrandsen 2014 with the edge tint
// 1 - (1 - F0)^2.75, F90 1) within 0.0063 in reflectance from F0 0.02 to
// 0.95 (Schlick's curve, which conductors kept before: 0.040 at F0 0.12, 0.016
// at 0.5). Least squares on the reflectance over 99 F0 and 801 cosines,
// scripts/fit_conductor_fresnel.py. Below MIN_F0 a channel takes the curve of
// MIN_F0 (the cubic's A0 < 0 would take it below 0 near F0 0); a is taken at
// least 0 (it falls to -0.03 above F0 0.7, where D would turn convex in t and
// substrate_fresnel_b no longer bound the lobe's albedo from above).
#define SUBSTRATE_CONDUCTOR_CURVE_A0 -0.31556
#define SUBSTRATE_CONDUCTOR_CURVE_A1 3.84345
#define SUBSTRATE_CONDUCTOR_CURVE_A2 -7.09867
#define SUBSTRATE_CONDUCTOR_CURVE_A3 3.54592
#define SUBSTRATE_CONDUCTOR_CURVE_B0 -0.31076
#define SUBSTRATE_CONDUCTOR_CURVE_B1 -0.09557
#define SUBSTRATE_CONDUCTOR_CURVE_B2 -1.85667
#define SUBSTRATE_CONDUCTOR_CURVE_B3 2.91601
#define SUBSTRATE_CONDUCTOR_CURVE_MIN_F0 0.02
// A low-F0 dielectric's curve (issue 19, step 24; substrate_fresnel_curve):
// the ground truth reads a dielectric's IOR from its F0 and walks its exact
// Fresnel, whose normalized curve rises later toward grazing the closer the
// IOR is to 1 (chi, IOR 1.5's, was 0.069 above it at F0 0.01, 0.186 at
// 0.002). The same form with, per channel, x = min(sqrt(max(F0, MIN_F0)), 0.2):
// a = A + (x - 0.2) (P0 + x (P1 + x P2)), b = B + (x - 0.2) (Q0 + x (Q1 + x Q2)),
// exactly chi from F0 0.04 (chi is within 0.008 of the exact curve up to
// 0.1); within 0.006 in reflectance from F0 0.002 to 0.04, 0.021 at MIN_F0,
// below which a channel takes MIN_F0's curve. Least squares on the
// reflectance over 60 F0 and 801 cosines, scripts/fit_low_f0_fresnel.py.
// Such a curve is more convex in t than chi: a rough lobe's mean of it lies
// above substrate_fresnel_b's bound at pull 0 (by 0.057 in the albedo at F0
// 0.001, roughness 0.45), so its pull is at least
// min(PULL_MAX, PULL_SLOPE (0.2 - x)), 0 at chi's F0: the bound then holds at
// 1,353 lobes of the tables and 13 F0 (the same script).
#define SUBSTRATE_DIELECTRIC_CURVE_P0 -0.22765
#define SUBSTRATE_DIELECTRIC_CURVE_P1 26.36756
#define SUBSTRATE_DIELECTRIC_CURVE_P2 -119.68157
#define SUBSTRATE_DIELECTRIC_CURVE_Q0 7.96407
#define SUBSTRATE_DIELECTRIC_CURVE_Q1 -109.09286
#define SUBSTRATE_DIELECTRIC_CURVE_Q2 386.54276
#define SUBSTRATE_DIELECTRIC_CURVE_MIN_F0 0.001
#define SUBSTRATE_DIELECTRIC_CURVE_X 0.2
#define SUBSTRATE_DIELECTRIC_CURVE_PULL_MAX 0.32
#define SUBSTRATE_DIELECTRIC_CURVE_PULL_SLOPE 6.5
#define SUBSTRATE_FRESNEL_ROUGH_END 0.45
// substrate_closure_coat_diffuse's terms, for k = extraInterfaces 0..3:
//   G_k: 2 int mu g(mu)^(1 + k) dmu, the cosine-weighted mean of the lighting's
//        light-side interface term g (substrate_coat_transmission:
//        1 - chi(mu) since issue 19 step 4; with Schlick's 1 - (1 - mu)^5
//        they were 0.95238 / 0.91991 / 0.89524 / 0.87535);
//   T_k: 0.96^(1 + k), the share of topTransmittance of 1 + k interfaces of
//        IOR 1.5 (1 - F0 of each): T_0 is SubstrateClosure.coatInterface's
//        default, the top's 1 - F0 since issue 19 step 18 (substrate_coat_interface),
//        and the k interfaces under the top take T_(k-1);
//   BEND: T_i^1.13 bounded above by Bernoulli's inequality, T_i (1 - 0.12 (1 - T_i));
//   COVARIANCE: the closure's own interface coupling's covariance with the
//        layers', per unit of mean F90 - mean F0.
// substrate_coat_floor (issue 19, step 9): what a rough top lets through at
// grazing angles, f = SCALE x / (x + HALF), x = max(r - START, 0);
// substrate_coat_mean_share: h(f) = sat(f (A + f (B + C f))).
// scripts/fit_coat_transmission.py.
#define SUBSTRATE_COAT_ROUGH_SCALE 1.094
#define SUBSTRATE_COAT_ROUGH_START 0.1
#define SUBSTRATE_COAT_ROUGH_HALF 0.175
#define SUBSTRATE_COAT_MEAN_A 0.2533
#define SUBSTRATE_COAT_MEAN_B -1.2067
#define SUBSTRATE_COAT_MEAN_C 1.9925
// substrate_coat_aniso_share (issue 19, step 19): the nodes of the two-node
// Gauss-Chebyshev rule in cos 2phi, as cos^2 phi = (1 -+ cos(pi/4)) / 2.
#define SUBSTRATE_COAT_AZIMUTH_C2_0 0.1464466094
#define SUBSTRATE_COAT_AZIMUTH_C2_1 0.8535533906
#define SUBSTRATE_COAT_G_0 0.94642
#define SUBSTRATE_COAT_G_1 0.90734
#define SUBSTRATE_COAT_G_2 0.87632
#define SUBSTRATE_COAT_G_3 0.85053
//   LOBE_<model>_k: G_k assumes a cosine-distributed diffuse lobe; a rough
//        lobe that favours light near the normal, where g is largest, takes
//        more of it, by up to this factor (the largest over 11 roughnesses and
//        7 views of (1 - chi(NoV))^(1 + k) int f g^(1 + k) cos / (G_k int f cos);
//        Chan 2024 with its multiple-scattering lobe at r 1, NoV 1: a white base
//        under an F0-0 coat returned 1.0057 without it, EON 1.0033; issue 19,
//        step 7; scripts/fit_chan2024_energy.py). Lambert: 1.
#define SUBSTRATE_COAT_LOBE_CHAN2024_0 1.0062
#define SUBSTRATE_COAT_LOBE_CHAN2024_1 1.0100
#define SUBSTRATE_COAT_LOBE_CHAN2024_2 1.0129
#define SUBSTRATE_COAT_LOBE_CHAN2024_3 1.0152
#define SUBSTRATE_COAT_LOBE_EON_0 1.0037
#define SUBSTRATE_COAT_LOBE_EON_1 1.0056
#define SUBSTRATE_COAT_LOBE_EON_2 1.0071
#define SUBSTRATE_COAT_LOBE_EON_3 1.0084
#define SUBSTRATE_COAT_T_0 0.96
#define SUBSTRATE_COAT_T_1 0.9216
#define SUBSTRATE_COAT_T_2 0.884736
#define SUBSTRATE_COAT_BEND 0.12
#define SUBSTRATE_COAT_COVARIANCE 0.0145
// substrate_closure_coat_specular (issue 19, step 6): the share R of a
// closure's lobe that the layers' top sends back down by total internal
// reflection, R = P1 a^2 / (a^2 + P2 d^2) + P3 a^2, a the GGX alpha and
// d = mu_i - CRITICAL_COS, mu_i = sqrt(1 - (1 - NoV^2) INV_ETA2) the view's
// cosine inside the layers (IOR 1.5) and CRITICAL_COS = sqrt(1 - INV_ETA2)
// the smallest it can be: least squares on the integral over 33 views and
// 21 roughnesses, rms 0.020, within 0.065 (scripts/fit_coat_tir.py).
#define SUBSTRATE_COAT_TIR_P1 0.5006
#define SUBSTRATE_COAT_TIR_P2 1.34
#define SUBSTRATE_COAT_TIR_P3 0.1584
#define SUBSTRATE_COAT_INV_ETA2 0.4444444444
#define SUBSTRATE_COAT_CRITICAL_COS 0.7453559925
// Under a rough top (issue 19, step 14; substrate_closure_coat_specular):
//   TOP_SPREAD: the share of the top's alpha taken back out of the closure's
//        widened alpha before R is read: the spread a rough top gives a lobe
//        on the way in is mostly undone on the way out, and the TIR fit
//        (above) is for a lobe that spreads below a smooth top;
//   ROUGH_PATH: Q in the lobe's extra path through the media under a rough
//        top, Q f^3 (p(NoV) (1 - NoV)^2 + p(NoL) (1 - NoL)^2), p =
//        substrate_coat_path_length, f = coatFloor: grazing light refracted
//        by tilted facets crosses the media flatter, farther than 1 / mu_t.
// A scan against the Monte Carlo walk (a white mirror and rough conductors,
// roughness 0.05 .. 0.7, under tops of roughness 0.1 .. 1 and transmittance
// 0.7 and 0.4; scripts/scan_tinted_coat.py checks the shipped values).
#define SUBSTRATE_COAT_TOP_SPREAD 0.6
#define SUBSTRATE_COAT_ROUGH_PATH 1.2

// substrate_diffuse_chan2024's multiple-scattering lobe (issue 19, step 7):
// K1(mu) = int VoH^2 / (NoH + 0.025) cos / pi over the light hemisphere ~
// (P0 + P1 mu + P2 mu^2 + P3 mu^3) / (mu + C), minimax within 5.4e-4 over mu in
// [0, 1] then shifted up by that, so it never lies below K1 (the lobe never
// returns more than Chan 2024 loses); M = int K1 2 mu dmu of the fit
// (scripts/fit_chan2024_energy.py).
#define SUBSTRATE_CHAN24_K1_P0 0.301627
#define SUBSTRATE_CHAN24_K1_P1 0.817761
#define SUBSTRATE_CHAN24_K1_P2 -0.105938
#define SUBSTRATE_CHAN24_K1_P3 0.068682
#define SUBSTRATE_CHAN24_K1_C 0.220
#define SUBSTRATE_CHAN24_K1_MEAN 0.942430

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

// The cosine-weighted hemispherical mean of min(E_fuzz(mu, r), 1) (issue 19,
// step 16; substrate_fuzz_mean_albedo): a quartic in the fuzz roughness r,
// 0.0006 + 0.1835 r + 0.0960 r^2 + 0.4185 r^3 - 0.3972 r^4, fitted to the
// table's quadrature at 401 roughnesses and shifted down so that it is nowhere
// above it (at most 0.005 below at 1,001 roughnesses;
// ReferenceEnergy.TheFuzzAlbedoMomentsBoundTheTables).
#define SUBSTRATE_FUZZ_MEAN_0 0.000614
#define SUBSTRATE_FUZZ_MEAN_1 0.183517
#define SUBSTRATE_FUZZ_MEAN_2 0.095986
#define SUBSTRATE_FUZZ_MEAN_3 0.418528
#define SUBSTRATE_FUZZ_MEAN_4 -0.397177

// An upper bound of the standard deviation of min(E_fuzz(mu, r), 1) over the
// cosine-weighted hemisphere (substrate_fuzz_albedo_deviation; issue 19, step
// 16): min(0.06 + 0.4 r, 0.134). The largest is 0.1337 near r = 0.86 (0.059 at
// r = 0, 0.096 at 0.1, 0.127 at 1; midpoint rule with 4,000 points at 1,001
// roughnesses; ReferenceEnergy.TheFuzzAlbedoMomentsBoundTheTables). With
// substrate_diffuse_light_coupling_deviation, the most the diffuse's light
// coupling and the fuzz's light term can covary.
#define SUBSTRATE_FUZZ_DEVIATION_0 0.06
#define SUBSTRATE_FUZZ_DEVIATION_SLOPE 0.4
#define SUBSTRATE_FUZZ_DEVIATION_MAX 0.134

// What the diffuse models add to the mean of the fuzz pair's light term
// (substrate_fuzz_pair_margin; issue 19, step 16), a + b r at the slab's
// roughness r: Chan 2018 (its smooth term), Chan 2024 and EON (their
// retro-reflection) weigh light near the normal more than Lambert's cosine at
// some views, so the light-weighted mean of the pair's light term can exceed
// its cosine-weighted bound. The most it did, over a grid of 21 roughnesses,
// 20 view cosines, 20 fuzz roughnesses and F0 / F90 of 0 / 1 and 0 / 0 (160 x
// 48 light directions each), as a share of the model's own albedo: Chan 2018
// 0.0142 at r = 0 falling to 0.0083 at 1; Chan 2024 0.0000 at r = 0.1, 0.0041
// at 0.35, 0.0088 at 1; EON 0.0010 at 0.5, 0.0038 at 1 (bounded above at every
// roughness; ReferenceEnergy.TheFuzzPairMarginsCoverEachDiffuseModelsLightWeighting).
// Lambert's is 0: its light weighting is the cosine the bound assumes.
#define SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2018_0 0.016
#define SUBSTRATE_FUZZ_PAIR_MARGIN_CHAN2024_1 0.0125
#define SUBSTRATE_FUZZ_PAIR_MARGIN_EON_1 0.0045

#endif
