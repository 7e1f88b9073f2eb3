// substratec runtime shaders: the generic unpacker of the deferred lighting
// pass -- a pixel's closures from its packed words alone (docs/storage.md).
// Common dialect: include substrate_prelude.glsl or .hlsl, substrate_closure.h,
// substrate_common.h and substrate_pack.h first.
#ifndef SUBSTRATE_UNPACK_H
#define SUBSTRATE_UNPACK_H 1

// 1: a pixel may hold the no-closure header of an unlit material (bit 14,
// docs/storage.md, "No closure"): the unpackers read it as nothing to light.
// A scene's lighting whose materials all have closures defines it 0 and
// compiles the test out (scene_emitter.cc).
#ifndef SUBSTRATE_USE_NO_CLOSURE
#define SUBSTRATE_USE_NO_CLOSURE 1
#endif

// The closure feature bits whose basis stores a tangent angle: anisotropy's,
// and a hair's (its fibre) where one may be.
#if SUBSTRATE_USE_HAIR
#define SUBSTRATE_TANGENT_FEATURES (SUBSTRATE_FEATURE_ANISOTROPY | SUBSTRATE_FEATURE_HAIR)
#else
#define SUBSTRATE_TANGENT_FEATURES SUBSTRATE_FEATURE_ANISOTROPY
#endif

// The fields of one closure that follow its header bits, from stream bit
// `pos` (advanced past them), into `c` (initialized by the caller): albedo,
// F0, roughness, then weight, top transmittance, coverage above and the
// feature data its bits announce (docs/storage.md, "Order of fields").
// A feature compiled out (SUBSTRATE_USE_* 0: a lighting pass specialized to a
// scene that never stores it) is skipped, not decoded, so the stream stays
// aligned whatever it holds.
void substrate_unpack_closure_fields(uint words[SUBSTRATE_MAX_WORDS], inout uint pos, uint feats, uint sss, bool isTop,
                                     inout SubstrateClosure c) {
  c.features = feats;
  c.isTop = isTop;
  c.sssType = sss;
  c.coverageAbove = isTop ? 0.0 : 1.0;
  c.diffuseAlbedo = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
  pos += SUBSTRATE_BITS_COLOR;
  // A fibre stores its own field in place of F0. A lighting pass compiled
  // without hair (SUBSTRATE_USE_HAIR 0) meets no hair pixel: the scene's class
  // of a hair material defines it 1 (its field is wider than F0's, so it cannot
  // be skipped without the header bit, which that pass does not read).
#if SUBSTRATE_USE_HAIR
  if ((feats & SUBSTRATE_FEATURE_HAIR) != 0u) {
    c.hair = substrate_dq_hair(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_HAIR));
    pos += SUBSTRATE_BITS_HAIR;
  } else
#endif
#if SUBSTRATE_USE_EYE
  if ((feats & SUBSTRATE_FEATURE_EYE) != 0u) {  // an eye: its iris in place of F0 (0.04, the init's)
    c.irisN = substrate_dq_normal(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_IRIS_NORMAL));
    pos += SUBSTRATE_BITS_IRIS_NORMAL;
    substrate_dq_iris(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_IRIS), c.irisPlaneN, c.iris);
    pos += SUBSTRATE_BITS_IRIS;
  } else
#endif
  {
    c.f0 = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
    pos += SUBSTRATE_BITS_COLOR;
  }
  c.roughness = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_ROUGHNESS), 8u);
  pos += SUBSTRATE_BITS_ROUGHNESS;
  if ((feats & SUBSTRATE_FEATURE_WEIGHT) != 0u) {
    c.weight = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_WEIGHT), 8u);
    pos += SUBSTRATE_BITS_WEIGHT;
  }
  if (!isTop) {
    c.topTransmittance = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
    pos += SUBSTRATE_BITS_COLOR;
  }
  if ((feats & SUBSTRATE_FEATURE_COVERAGE_ABOVE) != 0u) {
    c.coverageAbove = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COVERAGE_ABOVE), 8u);
    pos += SUBSTRATE_BITS_COVERAGE_ABOVE;
  }
  if ((feats & SUBSTRATE_FEATURE_F90) != 0u) {
#if SUBSTRATE_USE_F90
    c.f90 = substrate_dq_color20(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_COLOR));
#endif
    pos += SUBSTRATE_BITS_COLOR;
  }
  if (sss != SUBSTRATE_SSS_NONE) {
#if SUBSTRATE_USE_SSS
    float3 mfp;
    float phase;
    substrate_dq_sss(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_SSS), mfp, phase);
    c.sssMfp = mfp;
    c.sssPhaseAnisotropy = phase;
#else
    c.sssType = SUBSTRATE_SSS_NONE;
#endif
    pos += SUBSTRATE_BITS_SSS;
  }
  if ((feats & SUBSTRATE_FEATURE_HAZE) != 0u) {
#if SUBSTRATE_USE_HAZE
    float r2;
    float w2;
    substrate_dq_haze(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_HAZE), r2, w2);
    c.secondRoughness = r2;
    c.secondRoughnessWeight = w2;
#endif
    pos += SUBSTRATE_BITS_HAZE;
  }
  if ((feats & SUBSTRATE_FEATURE_FUZZ) != 0u) {
#if SUBSTRATE_USE_FUZZ
    float fa;
    float3 fc;
    float fr;
    substrate_dq_fuzz(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_FUZZ), fa, fc, fr);
    c.fuzzAmount = fa;
    c.fuzzColor = fc;
    c.fuzzRoughness = fr;
#endif
    pos += SUBSTRATE_BITS_FUZZ;
  }
  if ((feats & SUBSTRATE_FEATURE_ANISOTROPY) != 0u) {
#if SUBSTRATE_USE_ANISOTROPY
    c.anisotropy = substrate_dq_anisotropy(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_ANISOTROPY));
#endif
    pos += SUBSTRATE_BITS_ANISOTROPY;
  }
  if ((feats & SUBSTRATE_FEATURE_SPECULAR_PROFILE) != 0u) {
#if SUBSTRATE_USE_SPECULAR_PROFILE
    c.specularProfile = substrate_dq_specular_profile(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_SPECULAR_PROFILE));
#endif
    pos += SUBSTRATE_BITS_SPECULAR_PROFILE;
  }
  if ((feats & SUBSTRATE_FEATURE_GLINT) != 0u) {
#if SUBSTRATE_USE_GLINT
    uint density = SUBSTRATE_READ_BITS(words, pos, 8u);
    uint4 rest = uint4(SUBSTRATE_READ_BITS(words, pos + 8u, 32u), SUBSTRATE_READ_BITS(words, pos + 40u, 32u),
                       SUBSTRATE_READ_BITS(words, pos + 72u, 32u), SUBSTRATE_READ_BITS(words, pos + 104u, 32u));
    float gv;
    float2 guv;
    float4 gd;
    substrate_dq_glint(density, rest, gv, guv, gd);
    c.glintValue = gv;
    c.glintUv = guv;
    c.glintUvDerivatives = gd;
#endif
    pos += SUBSTRATE_BITS_GLINT;
  }
}

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
#if SUBSTRATE_USE_NO_CLOSURE
  if (!multi && (header & SUBSTRATE_HEADER_NO_CLOSURE) != 0u) {
    return 0u;  // an unlit pixel: nothing to light
  }
#endif
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
  uint tops = 0u;
  bool topPlainLobe = true;  // the top closure's lobe is one isotropic GGX lobe
  bool topStretched = false;  // one anisotropic GGX lobe (no haze)
  uint topIndex = 0u;
  float coatInterface = SUBSTRATE_COAT_T_0;  // the top closure's substrate_coat_interface
  for (int i = 0; i < SUBSTRATE_MAX_CLOSURES; ++i) {
    closureBasis[i] = 0u;
    if (uint(i) < count) {
      uint basis = 0u;
      bool isTop = true;
      uint feats = (header >> 2u) & 0x7fu;
#if SUBSTRATE_USE_HAIR
      feats |= (header & SUBSTRATE_HEADER_HAIR) != 0u ? SUBSTRATE_FEATURE_HAIR : 0u;  // a hair is always alone
#endif
#if SUBSTRATE_USE_EYE
      feats |= (header & SUBSTRATE_HEADER_EYE) != 0u ? SUBSTRATE_FEATURE_EYE : 0u;  // so is an eye
#endif
      uint sss = (header >> 10u) & 3u;
      if (multi) {
        uint h = SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_CLOSURE_HEADER);
        pos += SUBSTRATE_BITS_CLOSURE_HEADER;
        basis = min(h & 7u, basisCount - 1u);
        isTop = ((h >> 3u) & 1u) != 0u;
        feats = (h >> 4u) & 0xffu;
        sss = (h >> 12u) & 3u;
#if SUBSTRATE_USE_EXTRA_INTERFACES
        closures[i].extraInterfaces = (h >> 14u) & 3u;
#endif
      }
      closureBasis[i] = basis;
      if (isTop && basis != 0u) {
        topShare = false;
      }
      if (isTop) {
        tops += 1u;
        topPlainLobe = (feats & (SUBSTRATE_FEATURE_ANISOTROPY | SUBSTRATE_FEATURE_HAZE)) == 0u;
        topStretched = (feats & (SUBSTRATE_FEATURE_ANISOTROPY | SUBSTRATE_FEATURE_HAZE)) == SUBSTRATE_FEATURE_ANISOTROPY;
        topIndex = uint(i);
      }
      if ((feats & SUBSTRATE_TANGENT_FEATURES) != 0u) {
        basisAniso[basis] = true;  // a stored tangent angle: an anisotropic lobe's, a fibre's
      }
      substrate_unpack_closure_fields(words, pos, feats, sss, isTop, closures[i]);
      if (isTop) {
        coatInterface = substrate_coat_interface(closures[i].f0);
      }
    }
  }

  float3 topN;
  float topRoughness;
  substrate_dq_top_layer(topLayer, topN, topRoughness);
  // The top-layer roughness is the top's own when one closure is on top; a
  // closure under that one interface alone reads its floor (substrate_coat_floor),
  // and the mean share of it (substrate_coat_mean_share).
  float coatFloor = tops == 1u && topPlainLobe ? substrate_coat_floor(topRoughness) : 0.0;
  float coatShare = substrate_coat_mean_share(coatFloor);
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
    substrate_orthonormal_basis(n, t0, b0);
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
      closures[j].coatFloor = closures[j].isTop || closures[j].extraInterfaces != 0u ? 0.0 : coatFloor;
      closures[j].coatInterface = !closures[j].isTop && tops == 1u ? coatInterface : SUBSTRATE_COAT_T_0;
      closures[j].coatShare = closures[j].isTop || closures[j].extraInterfaces != 0u ? 0.0 : coatShare;
      closures[j].coversLayers = closures[j].isTop && tops < count;  // substrate_closure_dielectric_ms
    }
  }
#if SUBSTRATE_USE_COAT_ANISO
  // One stretched top: its floor follows a direction's azimuth (substrate_coat_floor_along),
  // from its own unpacked roughness, anisotropy and tangent.
  if (tops == 1u && topStretched) {
    float topR = closures[0].roughness;
    float topA = closures[0].anisotropy;
    float3 topT = closures[0].T;
    for (int k = 1; k < SUBSTRATE_MAX_CLOSURES; ++k) {
      if (uint(k) == topIndex) {
        topR = closures[k].roughness;
        topA = closures[k].anisotropy;
        topT = closures[k].T;
      }
    }
    float2 stretch = substrate_coat_stretch(topR, topA);
    float share = substrate_coat_aniso_share(stretch);
    for (int j = 0; j < SUBSTRATE_MAX_CLOSURES; ++j) {
      if (uint(j) < count && !closures[j].isTop && closures[j].extraInterfaces == 0u) {
        closures[j].coatStretch = stretch;
        closures[j].coatTangent = topT;
        closures[j].coatShare = share;
      }
    }
  }
#endif
  return count;
}

// A pixel whose material header is a single-closure one (bit 15 clear:
// SIMPLE and SINGLE layouts, and COMPLEX or SPECIAL ones with one closure),
// without the loops of substrate_unpack_material: its one closure, normal
// from the top-layer word, tangent from the stored angle when anisotropic.
void substrate_unpack_single_closure(uint words[SUBSTRATE_MAX_WORDS], uint topLayer, out SubstrateClosure c) {
  substrate_closure_init(c);
  uint header = words[0] & 0xffffu;
  uint feats = (header >> 2u) & 0x7fu;
#if SUBSTRATE_USE_HAIR
  feats |= (header & SUBSTRATE_HEADER_HAIR) != 0u ? SUBSTRATE_FEATURE_HAIR : 0u;
#endif
#if SUBSTRATE_USE_EYE
  feats |= (header & SUBSTRATE_HEADER_EYE) != 0u ? SUBSTRATE_FEATURE_EYE : 0u;
#endif
  uint pos = SUBSTRATE_BITS_HEADER;
  substrate_unpack_closure_fields(words, pos, feats, (header >> 10u) & 3u, true, c);
#if SUBSTRATE_USE_NO_CLOSURE
  if ((header & SUBSTRATE_HEADER_NO_CLOSURE) != 0u) {
    c.weight = 0.0;  // an unlit pixel: its closure is not lit (substrate_closure_visible)
  }
#endif
  float topRoughness;
  substrate_dq_top_layer(topLayer, c.N, topRoughness);
  float3 b0;
  substrate_orthonormal_basis(c.N, c.T, b0);
#if SUBSTRATE_USE_ANISOTROPY || SUBSTRATE_USE_HAIR
  if ((feats & SUBSTRATE_TANGENT_FEATURES) != 0u) {  // a stretched lobe's, a fibre's
    c.T = substrate_tangent_angle_decode(SUBSTRATE_READ_BITS(words, pos, SUBSTRATE_BITS_TANGENT_ANGLE), c.N);
  }
#endif
}

// A pixel in the SIMPLE layout (class bits 0): the header is known, so the
// three fields are read at their fixed offsets (16, 36, 56); the normal is the
// top-layer word's. Only for pixels known to be SIMPLE (a SIMPLE tile), which
// include unlit pixels (no closure: weight 0).
void substrate_unpack_simple(uint words[SUBSTRATE_MAX_WORDS], uint topLayer, out SubstrateClosure c) {
  substrate_closure_init(c);
  c.diffuseAlbedo = substrate_dq_color20(SUBSTRATE_READ_BITS(words, 16u, SUBSTRATE_BITS_COLOR));
  c.f0 = substrate_dq_color20(SUBSTRATE_READ_BITS(words, 36u, SUBSTRATE_BITS_COLOR));
  c.roughness = substrate_dq_unorm(SUBSTRATE_READ_BITS(words, 56u, SUBSTRATE_BITS_ROUGHNESS), 8u);
#if SUBSTRATE_USE_NO_CLOSURE
  // An unlit pixel (header bit 14) is SIMPLE too: weight 0, so it is not lit.
  c.weight = (words[0] & SUBSTRATE_HEADER_NO_CLOSURE) != 0u ? 0.0 : 1.0;
#endif
  float topRoughness;
  substrate_dq_top_layer(topLayer, c.N, topRoughness);
}

#endif
