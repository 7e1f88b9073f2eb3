// substratec runtime shaders: the statistical operators of the Substrate tree
// walk (SIGGRAPH 2023 course, bonus slides), used by the generated material
// functions, which call them in a fully unrolled order. Common dialect.
//
// Each subtree carries a coverage C (probability of presence) and a
// transmittance T (along the normal), assuming uncorrelated coverage.
#ifndef SUBSTRATE_TREE_H
#define SUBSTRATE_TREE_H 1

#include "substrate_constants.h"  // SUBSTRATE_EXTRA_INTERFACE, SUBSTRATE_TREE_EPSILON

// Horizontal mix toward the foreground by w:
//   C = (1-w)Cb + w Cf,  T = ((1-w)Cb Tb + w Cf Tf) / max(eps, C).
void substrate_op_horizontal(float cb, float3 tb, float cf, float3 tf, float w, out float c, out float3 t) {
  c = (1.0 - w) * cb + w * cf;
  t = ((1.0 - w) * cb * tb + w * cf * tf) / max(SUBSTRATE_TREE_EPSILON, c);
}

// Vertical layering:
//   C = Ct + Cb(1-Ct),  T = Tt Ct(1-Cb) + Tb Cb(1-Ct) + Tt Tb Ct Cb.
void substrate_op_vertical(float ct, float3 tt, float cb, float3 tb, out float c, out float3 t) {
  c = ct + cb * (1.0 - ct);
  t = tt * (ct * (1.0 - cb)) + tb * (cb * (1.0 - ct)) + tt * tb * (ct * cb);
}

// Add: C = sat(Ca + Cb), T coverage-weighted.
void substrate_op_add(float ca, float3 ta, float cb, float3 tb, out float c, out float3 t) {
  c = saturate(ca + cb);
  t = (ca * ta + cb * tb) / max(SUBSTRATE_TREE_EPSILON, ca + cb);
}

// One more layer above a slab on its walk to the root: the layers above are
// kept as one (coverage, transmittance) pair whose throughput at normal
// incidence, 1 - C + C T, is the product of the layers' throughputs.
void substrate_layer_above(inout float c, inout float3 t, float cLayer, float3 tLayer) {
  float3 through = (SUBSTRATE_SPLAT3(1.0 - c) + c * t) * (SUBSTRATE_SPLAT3(1.0 - cLayer) + cLayer * tLayer);
  float cNew = 1.0 - (1.0 - c) * (1.0 - cLayer);
  t = saturate((through - SUBSTRATE_SPLAT3(1.0 - cNew)) / max(SUBSTRATE_TREE_EPSILON, cNew));
  c = cNew;
}

// What one more interface above lets through, folded into a transmittance
// along the normal. The lighting (substrate_closure_above_throughput) applies
// the angular part of 1 + k interfaces, (1 - (1 - mu)^5)^(1 + k), with k the
// closure's extraInterfaces = min(n - 1, 3) for a closure under n interfaces;
// it must receive no more than the n-th power, or every interface of a stack
// of clear coats reflects its share and still passes everything on (three
// white transparent slabs returned 1.08 of the light at NoV 0.1, six 1.38).
// The interfaces beyond the fourth are folded in here: Q is the largest q
// with q^(1/mu) <= 1 - (1 - mu)^5 for every mu in (0, 1] (0.9139, at
// mu ~ 0.1), rounded down; the emitter multiplies the layer of each interface
// past the first 1 + k on the way down by Q, so T^(1/mu) carries
// (Q^(n-1-k))^(1/mu) <= (1 - (1 - mu)^5)^(n-1-k) at every cosine.
// With coverage the bound holds too: the pair (C, T) of substrate_layer_above
// never lets through more than the product of the layers (Jensen: x^(1/mu) is
// convex), and each covered path crosses at most the interfaces counted.
// Since issue 19 (step 2) the media are crossed along the cosine refracted
// into the layers (substrate_coat_path_length: at most 1.342 times the thickness), so Q^(n-1-k) no
// longer bounds those interfaces at grazing; it need not: a closure's own
// interface is now relative to the layers above (substrate_closure_fresnel_ends),
// so a stack of coats of one IOR has one interface, the top's, and Q only
// darkens. Furnace.RandomStacksOfTwoToEightSlabsNeverGainEnergy and
// Furnace.StacksOfWhiteTransparentSlabsAtEveryDepth hold every depth to 1.001.
// Q is SUBSTRATE_EXTRA_INTERFACE (substrate_constants.h, via substrate_closure.h).
float substrate_extra_interfaces(float n) {
  return pow(SUBSTRATE_EXTRA_INTERFACE, n);
}

// The diffuse albedo a slab layered on top of another scatters back: its
// medium returns a(1 - T^2) (light crossing it down and up again, T the
// transmittance along the normal) and lets T^2 reach the base and come back.
// A coat that lets light through cannot also scatter all of it back: a
// white coat of thickness 0 (T = 1) over a white base would otherwise return
// twice the light it receives. An opaque layer (T = 0) keeps its albedo.
float3 substrate_layer_scattering(float3 albedo, float3 t) {
  float3 tc = saturate(t);
  return albedo * (SUBSTRATE_SPLAT3(1.0) - tc * tc);
}

#endif
