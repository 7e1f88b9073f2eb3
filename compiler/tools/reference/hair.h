// The CPU mirror of runtime_shaders/substrate_hair.h: a hair closure's lobes
// per light (hairEval, what substrate_eval_closure returns for it) and under an
// environment (hairEnv), one function per shader function, templated on the
// scalar type (float and double). The truth they are measured against is
// reference/hair_truth.h (pbrt-v4's HairBxDF integrated over the fibre's width).
#pragma once
#include "reference/reference.h"

namespace substratec::reference {

template <class T> T hairVariance(T betaM);                        // substrate_hair_variance
template <class T> T hairLogisticScale(T betaN);                   // substrate_hair_logistic_scale
template <class T> V3<T> hairSigmaA(const V3<T>& color, T betaN);  // substrate_hair_sigma_a
template <class T> T hairLogI0Scaled(T x);                         // substrate_hair_log_i0_scaled
template <class T> T hairMp(T cosI, T cosO, T sinI, T sinO, T v);  // substrate_hair_mp
template <class T> T hairFresnel(T c, T eta);                      // substrate_hair_fresnel
/// substrate_hair_eval: S(V, L), what multiplies a light's radiance.
template <class T> V3<T> hairEval(const Closure<T>& c, const V3<T>& V, const V3<T>& L);
/// substrate_hair_env: the albedo times irradiance / pi.
template <class T> V3<T> hairEnv(const Closure<T>& c, const V3<T>& V, const V3<T>& irradiance);

/// The albedo of a hair closure seen from V: hairEval integrated over the
/// sphere of light directions by a product Gauss-Legendre rule in theta_i
/// (weight cos theta_i; panels a quarter of the TT lobe's width apart, 8 to
/// 256) and phi (the far field is even in phi: [0, pi], 16 panels), 4 points
/// a panel. What the white furnace measures (stability, accuracy).
V3<double> hairAlbedoIntegrated(const Closure<double>& c, const V3<double>& V);

}  // namespace substratec::reference
