// substratec runtime shaders: the generic unpacker of the deferred lighting
// pass -- a pixel's closures from its packed words alone (docs/storage.md).
// Common dialect: include substrate_prelude.glsl or .hlsl, substrate_closure.h,
// substrate_common.h and substrate_pack.h first.
#ifndef SUBSTRATE_UNPACK_H
#define SUBSTRATE_UNPACK_H 1

// Reads a pixel's closures from the stream alone (docs/storage.md, "Order of
// fields"): the header gives the closure and basis counts (one closure and
// one basis for a single-closure header), each closure header its basis, is-top,
// feature bits and SSS type. A basis stores a tangent angle when one of its
// closures is anisotropic; a lone closure's normal, and basis 0's when every
// top closure uses it, is the top-layer normal. Unstored fields keep the
// neutral values of substrate_closure_init (coverage above is 1 below layers
// of static coverage 1); closures past the count are neutral. Returns the
// closure count.
uint substrate_unpack_material(uint words[SUBSTRATE_MAX_WORDS], uint topLayer,
                               out SubstrateClosure closures[SUBSTRATE_MAX_CLOSURES]) {
  for (int k = 0; k < SUBSTRATE_MAX_CLOSURES; ++k) {
    substrate_closure_init(closures[k]);
  }
  uint header = words[0] & 0xffffu;
  bool multi = (header & SUBSTRATE_HEADER_MULTI) != 0u;
  uint count = 1u;
  uint basisCount = 1u;
  if (multi) {
    count = min(((header >> 2u) & 7u) + 1u, uint(SUBSTRATE_MAX_CLOSURES));
    basisCount = clamp((header >> 5u) & 15u, 1u, uint(SUBSTRATE_MAX_BASES));
  }
  uint pos = SUBSTRATE_BITS_HEADER;

  uint closureBasis[SUBSTRATE_MAX_CLOSURES];
  bool basisAniso[SUBSTRATE_MAX_BASES];
  for (int b = 0; b < SUBSTRATE_MAX_BASES; ++b) {
    basisAniso[b] = false;
  }
  bool topShare = true;
  for (int i = 0; i < SUBSTRATE_MAX_CLOSURES; ++i) {
    closureBasis[i] = 0u;
    if (uint(i) < count) {
      uint basis = 0u;
      bool isTop = true;
      uint feats = (header >> 2u) & 0x7fu;
      uint sss = (header >> 10u) & 3u;
      if (multi) {
        uint h = SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_CLOSURE_HEADER);
        pos += SUBSTRATE_BITS_CLOSURE_HEADER;
        basis = min(h & 7u, basisCount - 1u);
        isTop = ((h >> 3u) & 1u) != 0u;
        feats = (h >> 4u) & 0xffu;
        sss = (h >> 12u) & 3u;
      }
      closureBasis[i] = basis;
      if (isTop && basis != 0u) {
        topShare = false;
      }
      if ((feats & SUBSTRATE_FEATURE_ANISOTROPY) != 0u) {
        basisAniso[basis] = true;
      }
      closures[i].features = feats;
      closures[i].isTop = isTop;
      closures[i].sssType = sss;
      closures[i].coverageAbove = isTop ? 0.0 : 1.0;

      closures[i].diffuseAlbedo = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
      pos += SUBSTRATE_BITS_COLOR;
      closures[i].f0 = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
      pos += SUBSTRATE_BITS_COLOR;
      closures[i].roughness = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_ROUGHNESS), 8u);
      pos += SUBSTRATE_BITS_ROUGHNESS;
      if ((feats & SUBSTRATE_FEATURE_WEIGHT) != 0u) {
        closures[i].weight = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_WEIGHT), 8u);
        pos += SUBSTRATE_BITS_WEIGHT;
      }
      if (!isTop) {
        closures[i].topTransmittance = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
        pos += SUBSTRATE_BITS_COLOR;
      }
      if ((feats & SUBSTRATE_FEATURE_COVERAGE_ABOVE) != 0u) {
        closures[i].coverageAbove =
            substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COVERAGE_ABOVE), 8u);
        pos += SUBSTRATE_BITS_COVERAGE_ABOVE;
      }
      if ((feats & SUBSTRATE_FEATURE_F90) != 0u) {
        closures[i].f90 = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
        pos += SUBSTRATE_BITS_COLOR;
      }
      if (sss != SUBSTRATE_SSS_NONE) {
        float3 mfp;
        float phase;
        substrate_dq_sss(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_SSS), mfp, phase);
        closures[i].sssMfp = mfp;
        closures[i].sssPhaseAnisotropy = phase;
        pos += SUBSTRATE_BITS_SSS;
      }
      if ((feats & SUBSTRATE_FEATURE_HAZE) != 0u) {
        float r2;
        float w2;
        substrate_dq_haze(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_HAZE), r2, w2);
        closures[i].secondRoughness = r2;
        closures[i].secondRoughnessWeight = w2;
        pos += SUBSTRATE_BITS_HAZE;
      }
      if ((feats & SUBSTRATE_FEATURE_FUZZ) != 0u) {
        float fa;
        float3 fc;
        float fr;
        substrate_dq_fuzz(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_FUZZ), fa, fc, fr);
        closures[i].fuzzAmount = fa;
        closures[i].fuzzColor = fc;
        closures[i].fuzzRoughness = fr;
        pos += SUBSTRATE_BITS_FUZZ;
      }
      if ((feats & SUBSTRATE_FEATURE_ANISOTROPY) != 0u) {
        closures[i].anisotropy = substrate_dq_anisotropy(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_ANISOTROPY));
        pos += SUBSTRATE_BITS_ANISOTROPY;
      }
      if ((feats & SUBSTRATE_FEATURE_SPECULAR_PROFILE) != 0u) {
        closures[i].specularProfile =
            substrate_dq_specular_profile(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_SPECULAR_PROFILE));
        pos += SUBSTRATE_BITS_SPECULAR_PROFILE;
      }
      if ((feats & SUBSTRATE_FEATURE_GLINT) != 0u) {
        uint density = SUBSTRATE_READ_BITS(words, pos, 8u);
        uint4 rest = uint4(SUBSTRATE_READ_BITS(words, pos + 8u, 32u), SUBSTRATE_READ_BITS(words, pos + 40u, 32u),
                           SUBSTRATE_READ_BITS(words, pos + 72u, 32u), SUBSTRATE_READ_BITS(words, pos + 104u, 32u));
        float gv;
        float2 guv;
        float4 gd;
        substrate_dq_glint(density, rest, gv, guv, gd);
        closures[i].glintValue = gv;
        closures[i].glintUv = guv;
        closures[i].glintUvDerivatives = gd;
        pos += SUBSTRATE_BITS_GLINT;
      }
    }
  }

  float3 topN;
  float topRoughness;
  substrate_dq_top_layer(topLayer, topN, topRoughness);
  float3 basisN[SUBSTRATE_MAX_BASES];
  float3 basisT[SUBSTRATE_MAX_BASES];
  for (int b = 0; b < SUBSTRATE_MAX_BASES; ++b) {
    float3 n = topN;
    if (uint(b) < basisCount) {
      bool elided = !multi || (b == 0 && topShare);
      if (!elided) {
        n = substrate_dq_normal(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_NORMAL));
        pos += SUBSTRATE_BITS_NORMAL;
      }
    }
    float3 t0;
    float3 b0;
    substrate_pack_frame(n, t0, b0);
    if (uint(b) < basisCount && basisAniso[b]) {
      t0 = substrate_tangent_angle_decode(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_TANGENT_ANGLE), n);
      pos += SUBSTRATE_BITS_TANGENT_ANGLE;
    }
    basisN[b] = n;
    basisT[b] = t0;
  }
  for (int j = 0; j < SUBSTRATE_MAX_CLOSURES; ++j) {
    if (uint(j) < count) {
      closures[j].N = basisN[closureBasis[j]];
      closures[j].T = basisT[closureBasis[j]];
    }
  }
  return count;
}

#endif
