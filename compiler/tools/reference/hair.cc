// Mirrors runtime_shaders/substrate_hair.h (the model and its references are
// described there), statement for statement.
#include "reference/hair.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "reference/common.h"

namespace substratec::reference {

using namespace detail;

namespace {

template <class T> constexpr T kMinVariance = T(2.5e-4);  // SUBSTRATE_HAIR_MIN_VARIANCE
template <class T> constexpr T kMinColor = T(1e-6);       // SUBSTRATE_HAIR_MIN_COLOR
template <class T> constexpr T kKappaTT = T(3.65);        // SUBSTRATE_HAIR_KAPPA_TT
template <class T> constexpr T kKappaTRT = T(17.0);       // SUBSTRATE_HAIR_KAPPA_TRT

// substrate_hair_von_mises
template <class T>
T vonMises(T cosX, T kappa) {
  return std::exp(kappa * (cosX - T(1)) - hairLogI0Scaled(kappa)) / K<T>::twoPi;
}

// substrate_hair_kappa
template <class T>
T kappaOf(T kappa0, T s) {
  return T(1) / (T(1) / kappa0 + T(3.28986813) * s * s);
}

// substrate_hair_pass
template <class T>
V3<T> hairPass(T h, T cosO, T etap, T cosT, T eta, const V3<T>& sigmaA, T& f) {
  T hh = clampT(h, T(-1), T(1));
  f = hairFresnel(cosO * std::sqrt(std::max(T(1) - hh * hh, T(0))), eta);
  T sinGt = hh / etap;
  T cosGt = std::sqrt(std::max(T(1) - sinGt * sinGt, T(0)));
  T len = T(2) * cosGt / std::max(cosT, T(1e-4));
  return {std::exp(-sigmaA[0] * len), std::exp(-sigmaA[1] * len), std::exp(-sigmaA[2] * len)};
}

// substrate_hair_attenuations (the 4-point rule over the width)
constexpr double kWidthH[4] = {0.108847200, 0.495471601, 0.868624138, 0.994058493};
constexpr double kWidthW[4] = {0.271581310, 0.444903730, 0.253777386, 0.029737551};

template <class T>
void attenuations(const Closure<T>& c, T sinO, T cosO, T& aR, V3<T>& aTT, V3<T>& aTRT, V3<T>& a3) {
  T eta = std::max(c.hair[1], T(1));
  V3<T> sigmaA = hairSigmaA(c.diffuseAlbedo, c.hair[0]);
  T sinT = sinO / eta;
  T cosT = std::sqrt(std::max(T(1) - sinT * sinT, T(0)));
  T etap = std::sqrt(std::max(eta * eta - sinO * sinO, T(0))) / std::max(cosO, T(1e-4));
  aR = T(0);
  aTT = aTRT = a3 = splat3(T(0));
  for (int k = 0; k < 4; ++k) {
    const T w = T(kWidthW[k]);
    T f;
    V3<T> t = hairPass(T(kWidthH[k]), cosO, etap, cosT, eta, sigmaA, f);
    aR += w * f;
    for (int i = 0; i < 3; ++i) {
      T tt = (T(1) - f) * (T(1) - f) * t[i];
      T trt = tt * f * t[i];
      aTT[i] += w * tt;
      aTRT[i] += w * trt;
      a3[i] += w * trt * f * t[i] / std::max(T(1) - f * t[i], T(1e-4));
    }
  }
}

// substrate_hair_longitudinal
template <class T>
V4<T> longitudinal(const Closure<T>& c, T sinI, T cosI, T sinO, T cosO) {
  T v = hairVariance(c.roughness);
  T alpha = clampT(c.hair[2], T(-20), T(20)) * (K<T>::pi / T(180));
  T s1 = std::sin(alpha), c1 = std::cos(alpha);
  T s2 = T(2) * c1 * s1, c2 = c1 * c1 - s1 * s1;
  T s4 = T(2) * c2 * s2, c4 = c2 * c2 - s2 * s2;
  T mR = hairMp(cosI, std::abs(cosO * c2 + sinO * s2), sinI, sinO * c2 - cosO * s2, v);
  T mTT = hairMp(cosI, std::abs(cosO * c1 - sinO * s1), sinI, sinO * c1 + cosO * s1, T(0.25) * v);
  T mTRT = hairMp(cosI, std::abs(cosO * c4 - sinO * s4), sinI, sinO * c4 + cosO * s4, T(4) * v);
  T m3 = hairMp(cosI, cosO, sinI, sinO, T(4) * v);
  return {mR, mTT, mTRT, m3};
}

// substrate_hair_dense
template <class T>
T dense(const V3<T>& V, const V3<T>& L, const V3<T>& Tn, T sinI) {
  V3<T> n = safeNormalize(V - dot(V, Tn) * Tn, V);
  T wrapped = saturate((dot(n, L) + T(1)) * T(0.25));
  return lerp(wrapped, T(1) - std::abs(sinI), T(0.33)) / (T(1.33) * K<T>::pi);
}

}  // namespace

template <class T>
T hairVariance(T bm) {
  T b = saturate(bm);
  T b2 = b * b, b4 = b2 * b2;
  T b20 = b4 * b4 * b4 * b4 * b4;
  T x = T(0.726) * b + T(0.812) * b2 + T(3.7) * b20;
  return std::max(x * x, kMinVariance<T>);
}

template <class T>
T hairLogisticScale(T bn) {
  T b = saturate(bn);
  T b2 = b * b;
  T b11 = b2 * b2 * b2 * b2 * b2 * b;
  return T(0.626657) * (T(0.265) * b + T(1.194) * b2 + T(5.372) * b11 * b11);
}

template <class T>
V3<T> hairSigmaA(const V3<T>& color, T bn) {
  T b = saturate(bn);
  T p = T(5.969) - T(0.215) * b + T(2.532) * b * b - T(10.73) * b * b * b + T(5.574) * b * b * b * b +
        T(0.245) * b * b * b * b * b;
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    T l = std::log(clampT(color[i], kMinColor<T>, T(1))) / p;
    r[i] = l * l;
  }
  return r;
}

template <class T>
T hairLogI0Scaled(T x) {
  if (x <= T(3.75)) {
    T t = x / T(3.75);
    T t2 = t * t;
    T i0 = T(1) + t2 * (T(3.5156229) + t2 * (T(3.0899424) + t2 * (T(1.2067492) +
                 t2 * (T(0.2659732) + t2 * (T(0.0360768) + t2 * T(0.0045813))))));
    return std::log(i0) - x;
  }
  T u = T(3.75) / x;
  T p = T(0.39894228) + u * (T(0.01328592) + u * (T(0.00225319) + u * (T(-0.00157565) + u * (T(0.00916281) +
        u * (T(-0.02057706) + u * (T(0.02635537) + u * (T(-0.01647633) + u * T(0.00392377))))))));
  return std::log(p) - T(0.5) * std::log(x);
}

template <class T>
T hairMp(T cosI, T cosO, T sinI, T sinO, T v) {
  T a = cosI * cosO / v;
  T e = (cosI * cosO - sinI * sinO - T(1)) / v + hairLogI0Scaled(a) - std::log(v * (T(1) - std::exp(T(-2) / v)));
  return std::exp(std::min(e, T(80)));
}

template <class T>
T hairFresnel(T c, T eta) {
  T ci = saturate(c);
  if (!(ci > T(1e-7))) return T(1);
  T ct = std::sqrt(std::max(T(1) - (T(1) - ci * ci) / (eta * eta), T(0)));
  T rs = (ci - eta * ct) / (ci + eta * ct);
  T rp = (eta * ci - ct) / (eta * ci + ct);
  return saturate(T(0.5) * (rs * rs + rp * rp));
}

template <class T>
V3<T> hairEval(const Closure<T>& c, const V3<T>& V, const V3<T>& L) {
  V3<T> Tn = safeNormalize(c.T_, V3<T>{T(1), T(0), T(0)});
  T sinO = clampT(dot(V, Tn), T(-1), T(1)), sinI = clampT(dot(L, Tn), T(-1), T(1));
  T cosO = std::sqrt(std::max(T(1) - sinO * sinO, T(0))), cosI = std::sqrt(std::max(T(1) - sinI * sinI, T(0)));
  V3<T> lp = L - sinI * Tn, vp = V - sinO * Tn;
  T cosPhi = clampT(dot(lp, vp) / std::sqrt(std::max(dot(lp, lp) * dot(vp, vp), T(1e-12))), T(-1), T(1));
  T cosHalfPhi = std::sqrt(saturate(T(0.5) + T(0.5) * cosPhi));
  T eta = std::max(c.hair[1], T(1));
  T aR = hairFresnel(cosO * cosHalfPhi, eta);  // Marschner's far-field R
  T aMeanR;
  V3<T> aTT, aTRT, a3;
  attenuations(c, sinO, cosO, aMeanR, aTT, aTRT, a3);
  V4<T> m = longitudinal(c, sinI, cosI, sinO, cosO);
  T s = hairLogisticScale(c.hair[0]);
  T nTT = vonMises(-cosPhi, kappaOf(kKappaTT<T>, s));
  T nTRT = vonMises(cosPhi, kappaOf(kKappaTRT<T>, s));
  V3<T> lobes = splat3(m[0] * aR * T(0.25) * cosHalfPhi) + (m[1] * nTT) * aTT + (m[2] * nTRT) * aTRT +
                (m[3] / K<T>::twoPi) * a3;
  T w = saturate(c.hair[3]);
  T d = dense(V, L, Tn, sinI);
  V3<T> r;
  for (int i = 0; i < 3; ++i) r[i] = std::max(lerp(lobes[i], saturate(c.diffuseAlbedo[i]) * d, w), T(0));
  return r;
}

template <class T>
V3<T> hairEnv(const Closure<T>& c, const V3<T>& V, const V3<T>& irradiance) {
  V3<T> Tn = safeNormalize(c.T_, V3<T>{T(1), T(0), T(0)});
  T sinO = clampT(dot(V, Tn), T(-1), T(1));
  T cosO = std::sqrt(std::max(T(1) - sinO * sinO, T(0)));
  T aR;
  V3<T> aTT, aTRT, a3;
  attenuations(c, sinO, cosO, aR, aTT, aTRT, a3);
  V3<T> r;
  for (int i = 0; i < 3; ++i) {
    T albedo = lerp(aR + aTT[i] + aTRT[i] + a3[i], saturate(c.diffuseAlbedo[i]), saturate(c.hair[3]));
    r[i] = albedo * std::max(irradiance[i], T(0)) * K<T>::invPi;
  }
  return r;
}

V3<double> hairAlbedoIntegrated(const Closure<double>& c, const V3<double>& V) {
  constexpr double x4[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  constexpr double w4[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  const V3<double> Tn = safeNormalize(c.T_, V3<double>{1, 0, 0});
  // Two directions across the fibre: the view's projection (any when V is along T).
  V3<double> a = safeNormalize(V - dot(V, Tn) * Tn, std::abs(Tn[2]) < 0.9 ? V3<double>{0, 0, 1} : V3<double>{1, 0, 0});
  a = safeNormalize(a - dot(a, Tn) * Tn, V3<double>{0, 1, 0});
  const V3<double> b = cross(Tn, a);
  const double sigma = 0.5 * std::sqrt(hairVariance(c.roughness));  // the TT lobe's width
  const int thetaPanels = std::clamp(static_cast<int>(std::ceil(std::numbers::pi / (0.25 * sigma * 4))), 8, 256);
  constexpr int kPhiPanels = 16;
  V3<double> sum{0, 0, 0};
  for (int i = 0; i < thetaPanels; ++i)
    for (int p = 0; p < 4; ++p) {
      const double ht = std::numbers::pi / thetaPanels;
      const double theta = -std::numbers::pi / 2 + ht * (i + 0.5 + 0.5 * x4[p]);
      const double wt = 0.5 * ht * w4[p] * std::cos(theta);
      for (int j = 0; j < kPhiPanels; ++j)
        for (int q = 0; q < 4; ++q) {
          const double hp = std::numbers::pi / kPhiPanels;
          const double phi = hp * (j + 0.5 + 0.5 * x4[q]);
          const double wp = 2 * 0.5 * hp * w4[q];  // phi and -phi
          const V3<double> L = std::sin(theta) * Tn + std::cos(theta) * (std::cos(phi) * a + std::sin(phi) * b);
          sum = sum + (wt * wp) * hairEval(c, V, L);
        }
    }
  return sum;
}

#define SUBSTRATEC_HAIR_INSTANTIATE(T)                                                         \
  template T hairVariance<T>(T);                                                               \
  template T hairLogisticScale<T>(T);                                                          \
  template V3<T> hairSigmaA<T>(const V3<T>&, T);                                               \
  template T hairLogI0Scaled<T>(T);                                                            \
  template T hairMp<T>(T, T, T, T, T);                                                         \
  template T hairFresnel<T>(T, T);                                                             \
  template V3<T> hairEval<T>(const Closure<T>&, const V3<T>&, const V3<T>&);                   \
  template V3<T> hairEnv<T>(const Closure<T>&, const V3<T>&, const V3<T>&);
SUBSTRATEC_HAIR_INSTANTIATE(float)
SUBSTRATEC_HAIR_INSTANTIATE(double)
#undef SUBSTRATEC_HAIR_INSTANTIATE

}  // namespace substratec::reference
