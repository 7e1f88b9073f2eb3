// Rough interfaces with multiple scattering: the microsurface random walk of
// Heitz, Hanika, d'Eon and Dachsbacher 2016 ("Multiple-scattering microfacet
// BSDFs with the Smith model"), for GGX (Trowbridge-Reitz) slopes, possibly
// anisotropic, and the uniform height distribution. A ray meets the
// microsurface, bounces between microfacets (reflection, refraction, total
// internal reflection) and leaves: the BSDF it defines conserves energy (a
// white conductor and a dielectric reflect + transmit all the light) at every
// roughness, where the single-scattering microfacet BSDF loses the energy of
// the inter-facet bounces (E_ss(mu) < 1).
//
// The random walk of the layered reference (random_walk.h) uses it at every
// rough interface: `sample` for the walk's own bounces, `eval` (an unbiased
// stochastic estimate, one microsurface walk with next-event estimation at each
// of its vertices) for the connections, `pdf` (a proxy density) for the
// multiple-importance weights (any positive function used the same way by both
// strategies keeps MIS unbiased).
//
// Frame: local, z the interface's normal, x its tangent (alphaX along it).
// Directions point away from the surface: `wo` is where the light arrives from
// (or the walk came from), `wi` where it leaves to. A dielectric is seen from
// either side (wo.z < 0: from below, the eta of that side is 1 / eta); a
// conductor from above only.
#pragma once
#include <cstdint>

#include "reference/reference.h"
#include "util/random.h"

namespace substratec::reference {

/// What a transmitted path carries across a dielectric (pbrt's TransportMode):
/// radiance is scaled by 1 / eta^2 on refraction, importance is not.
enum class Transport { Radiance, Importance };

struct Microsurface {
  enum class Kind { Conductor, Dielectric };
  Kind kind = Kind::Dielectric;
  double alphaX = 0.25, alphaY = 0.25;  // GGX roughness along x (the tangent) and y; clamped to >= 1e-3
  double eta = 1.5;                     // Dielectric: IOR below (z < 0) over IOR above (z > 0)
  V3<double> n{1, 1, 1}, k{0, 0, 0};    // Conductor: complex IOR per channel, relative to the medium above
  /// Scattering orders on the microsurface: 0 = all (the default: bounded by
  /// kMaxMicrosurfaceOrder), 1 = single scattering (the classic microfacet BSDF).
  int maxOrder = 0;
};

/// The bound on microsurface bounces of one walk (the energy of longer walks,
/// lost, is measured in microsurface_test.cc).
inline constexpr int kMaxMicrosurfaceOrder = 256;

/// One exit of the microsurface walk.
struct MicrosurfaceSample {
  V3<double> wi{0, 0, 1};         // the exit direction (unit)
  V3<double> weight{1, 1, 1};     // f |cos wi| / pdf of the whole walk, per channel
  bool reflected = true;          // left on the side it arrived from
};

/// Samples the exit of a walk that arrives along -wo. False: no exit (the
/// walk exceeded the order bound, or a degenerate direction).
bool sampleMicrosurface(const Microsurface& m, const V3<double>& wo, Transport mode, SplitMix64& rng,
                        MicrosurfaceSample& s);

/// An unbiased stochastic estimate of f(wo, wi) |cos wi|, per channel (one
/// microsurface walk, next-event estimation towards wi at each vertex).
V3<double> evalMicrosurface(const Microsurface& m, const V3<double>& wo, const V3<double>& wi, Transport mode,
                            SplitMix64& rng);

/// A positive proxy of the density with which sampleMicrosurface returns wi
/// (the single-scattering density of visible normals plus a smooth floor for
/// the multiple orders), for MIS weights only.
double pdfMicrosurface(const Microsurface& m, const V3<double>& wo, const V3<double>& wi);

/// Gulbrandsen 2014 ("Artist friendly metallic Fresnel"): the complex IOR
/// (n, k) of a conductor of normal reflectivity r and edge tint g, both in
/// [0, 1] (clamped to [0, 0.9999]).
void conductorIor(double r, double g, double& n, double& k);

/// Exact Fresnel reflectance of a conductor of complex IOR n + ik for cos(theta_i) in [0, 1].
double fresnelConductor(double cosThetaI, double n, double k);

}  // namespace substratec::reference
