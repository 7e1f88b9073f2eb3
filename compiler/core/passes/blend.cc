#include "passes/blend.h"

#include "ir/value_eval.h"
#include "substrate_constants.h"  // runtime_shaders/: SUBSTRATE_COAT_*

namespace substratec {

namespace {

constexpr double kEps = 1e-6;

/// Small expression builder over the DAG: broadcasting binary ops and guards.
class Ex {
 public:
  explicit Ex(ValueDag& d) : d_(d) {}
  ValueId k(double v) { return d_.scalar(v); }
  VType type(ValueId a) const { return d_.node(a).type; }
  VType join(ValueId a, ValueId b) const { return type(a) == VType::Float ? type(b) : type(a); }
  ValueId bc(ValueId a, VType t) { return d_.broadcast(a, t); }
  ValueId bin(Op op, ValueId a, ValueId b) {
    VType r = join(a, b);
    return d_.make(op, r, {bc(a, r), bc(b, r)});
  }
  ValueId add(ValueId a, ValueId b) { return bin(Op::Add, a, b); }
  ValueId sub(ValueId a, ValueId b) { return bin(Op::Subtract, a, b); }
  ValueId mul(ValueId a, ValueId b) { return bin(Op::Multiply, a, b); }
  ValueId max(ValueId a, ValueId b) { return bin(Op::Max, a, b); }
  /// a / max(b, eps): finite for b = 0.
  ValueId safeDiv(ValueId a, ValueId b) { return bin(Op::Divide, a, max(b, k(kEps))); }
  ValueId lerp(ValueId a, ValueId b, ValueId t) {
    VType r = join(a, b);
    return d_.make(Op::Lerp, r, {bc(a, r), bc(b, r), bc(t, r)});
  }
  ValueId sat(ValueId a) { return d_.make(Op::Saturate, type(a), {a}); }
  ValueId min(ValueId a, ValueId b) { return bin(Op::Min, a, b); }
  ValueId sqrt(ValueId a) { return d_.make(Op::Sqrt, type(a), {a}); }
  /// The largest of a colour's channels.
  ValueId max3(ValueId a) {
    if (type(a) == VType::Float) return a;
    auto ch = [&](int i) { return d_.make(Op::Swizzle, VType::Float, {a}, static_cast<std::uint16_t>(i | (1 << 8))); };
    return max(max(ch(0), ch(1)), ch(2));
  }
  ValueId oneMinus(ValueId a) { return d_.make(Op::OneMinus, type(a), {a}); }
  ValueId exp(ValueId a) { return d_.make(Op::Exp, type(a), {a}); }
  ValueId normalize(ValueId a) { return d_.make(Op::Normalize, type(a), {a}); }
  /// Mean of a colour's channels.
  ValueId mean(ValueId a) {
    if (type(a) == VType::Float) return a;
    return d_.make(Op::Dot, VType::Float, {a, d_.splat(VType::Vec3, 1.0 / 3.0)});
  }

 private:
  ValueDag& d_;
};

/// Evaluates a (scalar) weight at the inputs' defaults: used only for the
/// discrete choices a blend cannot express as an expression.
double typicalValue(const Material& m, ValueId v) { return evaluateValue(m, v)[0]; }

ValueId pin(const Slab& s, SlabPin p) { return s.pin(p); }

ValueId thicknessOf(Material& m, const Slab& s) { return s.thickness == kNoValue ? m.values.scalar(0) : s.thickness; }

/// Hemispherical average of the Schlick Fresnel: F0 + (F90 - F0)/21.
ValueId fresnelAverage(Material& m, const Slab& s) {
  Ex e(m.values);
  return e.add(pin(s, SlabPin::F0), e.mul(e.sub(pin(s, SlabPin::F90), pin(s, SlabPin::F0)), e.k(1.0 / 21.0)));
}

/// The slab's diffuse with its fuzz folded in: lerp(d, fuzz colour, k·amount).
ValueId foldedDiffuse(Material& m, const Slab& s) {
  Ex e(m.values);
  return e.lerp(pin(s, SlabPin::DiffuseAlbedo), pin(s, SlabPin::FuzzColor),
                e.mul(pin(s, SlabPin::FuzzAmount), e.k(kFuzzAlbedo)));
}

/// The same for the interface the diffuse lies under, the slab's dielectric
/// part, as the runtime reads it (substrate_closure_dielectric_part): from
/// F0 0.25 a metalness mix whose diffuse lies under a dielectric of F0
/// SUBSTRATE_MIX_DIELECTRIC_F0 and F90 1; up to 0.18 its own; linear between.
/// Only in a material the runtime reads so (Material::metalnessMix).
ValueId dielectricFresnelAverage(Material& m, const Slab& s) {
  if (!m.metalnessMix) return fresnelAverage(m, s);
  Ex e(m.values);
  ValueId fmax = e.max3(e.sat(pin(s, SlabPin::F0)));
  ValueId t = e.sat(e.mul(e.sub(fmax, e.k(SUBSTRATE_MIX_START)), e.k(SUBSTRATE_MIX_BLEND)));
  ValueId f0 = e.min(pin(s, SlabPin::F0), e.lerp(fmax, e.k(SUBSTRATE_MIX_DIELECTRIC_F0), t));
  ValueId f90 = e.lerp(pin(s, SlabPin::F90), e.k(1.0), t);
  return e.add(f0, e.mul(e.sub(f90, f0), e.k(1.0 / 21.0)));
}

/// The part of the directional albedo that is not specular: (1 - F_d)·folded
/// diffuse, within what the interface leaves, 1 - F (substrate_diffuse_transmission).
ValueId diffuseEnergy(Material& m, const Slab& s) {
  Ex e(m.values);
  return e.min(e.mul(e.oneMinus(dielectricFresnelAverage(m, s)), foldedDiffuse(m, s)),
               e.oneMinus(fresnelAverage(m, s)));
}

/// Sets r's diffuse albedo so that (1 - F_d,r)·folded diffuse equals `target`:
/// the blended slab returns exactly the blended energy (a plain lerp of the
/// diffuse would not, since (1-F)·d is bilinear in the blended parameters).
/// Where the target exceeds 1 - F_r the runtime keeps the bound.
void setDiffuseEnergy(Material& m, Slab& r, ValueId target) {
  Ex e(m.values);
  ValueId folded = e.safeDiv(target, e.oneMinus(dielectricFresnelAverage(m, r)));
  ValueId fuzz = e.mul(pin(r, SlabPin::FuzzAmount), e.k(kFuzzAlbedo));
  ValueId d = e.safeDiv(e.sub(folded, e.mul(fuzz, pin(r, SlabPin::FuzzColor))), e.oneMinus(fuzz));
  r.pin(SlabPin::DiffuseAlbedo) = e.sat(d);
}

/// The plain-lerp baseline (BlendRule::PlainLerp): every pin (the fuzz colour
/// and the diffuse included, as they are) and the thickness lerped by t,
/// normals and tangents renormalized; coverage and features are the caller's.
Slab plainLerpSlabs(Material& m, const Slab& a, const Slab& b, ValueId t) {
  Ex e(m.values);
  Slab r = a;
  for (int p = 0; p < kSlabPinCount; ++p) {
    SlabPin sp = static_cast<SlabPin>(p);
    ValueId v = e.lerp(pin(a, sp), pin(b, sp), t);
    if (sp == SlabPin::Normal || sp == SlabPin::Tangent) v = e.normalize(v);
    r.pin(sp) = v;
  }
  if (a.thickness != kNoValue || b.thickness != kNoValue)
    r.thickness = e.lerp(thicknessOf(m, a), thicknessOf(m, b), t);
  else
    r.thickness = kNoValue;
  return r;
}

/// Lerps every blendable pin of two slabs by t (normals/tangents renormalized):
/// the plain lerp, then the fuzz colour and the diffuse energy-preserving.
Slab lerpSlabs(Material& m, const Slab& a, const Slab& b, ValueId t) {
  Slab r = plainLerpSlabs(m, a, b, t);
  Ex e(m.values);
  // Fuzz colour premultiplied by the amount, so amount·colour blends linearly.
  r.pin(SlabPin::FuzzColor) = e.safeDiv(
      e.lerp(e.mul(pin(a, SlabPin::FuzzAmount), pin(a, SlabPin::FuzzColor)),
             e.mul(pin(b, SlabPin::FuzzAmount), pin(b, SlabPin::FuzzColor)), t),
      pin(r, SlabPin::FuzzAmount));
  setDiffuseEnergy(m, r, e.lerp(diffuseEnergy(m, a), diffuseEnergy(m, b), t));
  return r;
}

/// Discrete properties (specular profile, SSS type, glint uv) from the side
/// that dominates: `bWins` picks b when both sides have the property.
void takeDiscrete(Slab& r, const Slab& a, const Slab& b, bool bWins) {
  auto pick = [&](bool aHas, bool bHas) { return aHas == bHas ? bWins : bHas; };
  r.specularProfileInput =
      pick(a.specularProfileInput >= 0, b.specularProfileInput >= 0) ? b.specularProfileInput : a.specularProfileInput;
  bool aSss = a.features & kFeatSss, bSss = b.features & kFeatSss;
  const Slab& sss = pick(aSss, bSss) ? b : a;
  r.sssType = sss.sssType;
  r.sssTypeExplicit = sss.sssTypeExplicit;
  bool aGlint = a.features & kFeatGlint, bGlint = b.features & kFeatGlint;
  r.pin(SlabPin::GlintUv) = pick(aGlint, bGlint) ? b.pin(SlabPin::GlintUv) : a.pin(SlabPin::GlintUv);
}

}  // namespace

Slab interfaceUnderLayers(Material& m, const Slab& in, ValueId& scale) {
  Ex e(m.values);
  Slab s = in;
  ValueId f = e.max3(e.sat(pin(in, SlabPin::F0)));
  ValueId root = e.sqrt(f);
  ValueId r = e.bin(Op::Divide, e.sub(root, e.k(SUBSTRATE_COAT_SQRT_F0)),
                    e.oneMinus(e.mul(root, e.k(SUBSTRATE_COAT_SQRT_F0))));
  ValueId rel = e.min(f, e.mul(r, r));
  rel = e.lerp(rel, f, e.sat(e.mul(e.sub(f, e.k(SUBSTRATE_COAT_DIELECTRIC_F0)), e.k(SUBSTRATE_COAT_CONDUCTOR_BLEND))));
  scale = e.bin(Op::Divide, rel, e.max(f, e.k(1e-4)));
  s.pin(SlabPin::F0) = e.mul(pin(in, SlabPin::F0), scale);
  s.pin(SlabPin::F90) = e.mul(pin(in, SlabPin::F90), scale);
  return s;
}

ValueId coverageOf(Material& m, const Slab& s) { return s.coverage == kNoValue ? m.values.scalar(1) : s.coverage; }

Slab foldToSingleInterface(Material& m, const Slab& s) {
  Ex e(m.values);
  Slab r = s;
  r.pin(SlabPin::Roughness) =
      e.lerp(pin(s, SlabPin::Roughness), pin(s, SlabPin::SecondRoughness), pin(s, SlabPin::SecondRoughnessWeight));
  r.pin(SlabPin::SecondRoughnessWeight) = m.values.scalar(0);
  r.pin(SlabPin::DiffuseAlbedo) = e.lerp(pin(s, SlabPin::DiffuseAlbedo), pin(s, SlabPin::FuzzColor),
                                         e.mul(pin(s, SlabPin::FuzzAmount), e.k(kFuzzAlbedo)));
  r.pin(SlabPin::FuzzAmount) = m.values.scalar(0);
  return r;
}

Slab blendHorizontal(Material& m, const Slab& bg, const Slab& fg, ValueId w, BlendRule rule) {
  Ex e(m.values);
  ValueId cb = coverageOf(m, bg), cf = coverageOf(m, fg);
  if (rule == BlendRule::PlainLerp) {
    Slab r = plainLerpSlabs(m, bg, fg, w);
    takeDiscrete(r, bg, fg, typicalValue(m, w) > 0.5);
    r.coverage = e.lerp(cb, cf, w);
    r.features = bg.features | fg.features;
    return r;
  }
  ValueId num = e.mul(cf, w);
  ValueId mix = e.safeDiv(num, e.add(num, e.mul(cb, e.oneMinus(w))));
  Slab r = lerpSlabs(m, bg, fg, mix);
  takeDiscrete(r, bg, fg, typicalValue(m, w) > 0.5);
  r.coverage = e.lerp(cb, cf, w);
  r.features = bg.features | fg.features;
  return r;
}

Slab blendSelect(Material& m, const Slab& a, const Slab& b, ValueId value, ValueId threshold, BlendRule rule) {
  // a when value <= threshold: the weight of b is 1 - step(value, threshold).
  ValueId pickA = m.values.make(Op::Step, VType::Float, {value, threshold});
  return blendHorizontal(m, a, b, m.values.make(Op::OneMinus, VType::Float, {pickA}), rule);
}

Slab blendCoverageWeight(Material& m, const Slab& a, ValueId weight) {
  Ex e(m.values);
  Slab r = a;
  r.coverage = e.mul(coverageOf(m, a), weight);
  return r;
}

Slab blendAdd(Material& m, const Slab& a, const Slab& b, BlendRule rule) {
  Ex e(m.values);
  ValueId ca = coverageOf(m, a), cb = coverageOf(m, b);
  ValueId c = e.sat(e.add(ca, cb));
  ValueId t = e.safeDiv(cb, e.add(ca, cb));
  if (rule == BlendRule::PlainLerp) {
    Slab r = plainLerpSlabs(m, a, b, t);
    takeDiscrete(r, a, b, typicalValue(m, t) > 0.5);
    r.coverage = c;
    r.features = a.features | b.features;
    return r;
  }
  Slab r = lerpSlabs(m, a, b, t);
  // Colours add: the summed contribution Ca·Xa + Cb·Xb, re-expressed per unit
  // of the new coverage and saturated.
  auto added = [&](ValueId xa, ValueId xb) { return e.sat(e.safeDiv(e.add(e.mul(ca, xa), e.mul(cb, xb)), c)); };
  r.pin(SlabPin::F0) = added(pin(a, SlabPin::F0), pin(b, SlabPin::F0));
  // The diffuse part adds too: the energy of both, per unit of the new
  // coverage, minus what the (added) specular now takes.
  ValueId albedoA = e.add(fresnelAverage(m, a), diffuseEnergy(m, a));
  ValueId albedoB = e.add(fresnelAverage(m, b), diffuseEnergy(m, b));
  setDiffuseEnergy(m, r, e.max(e.sub(added(albedoA, albedoB), fresnelAverage(m, r)), e.k(0)));
  r.pin(SlabPin::Emissive) = e.safeDiv(e.add(e.mul(ca, pin(a, SlabPin::Emissive)), e.mul(cb, pin(b, SlabPin::Emissive))), c);
  takeDiscrete(r, a, b, typicalValue(m, t) > 0.5);
  r.coverage = c;
  r.features = a.features | b.features;
  return r;
}

Slab blendVertical(Material& m, const Slab& topIn, const Slab& baseIn, ValueId d, BlendRule rule) {
  Ex e(m.values);
  if (rule == BlendRule::PlainLerp) {
    ValueId ctop = coverageOf(m, topIn), cbase = coverageOf(m, baseIn);
    Slab r = plainLerpSlabs(m, baseIn, topIn, ctop);
    takeDiscrete(r, baseIn, topIn, true);
    r.thickness = e.add(d, thicknessOf(m, baseIn));
    r.coverage = e.sub(e.add(ctop, cbase), e.mul(ctop, cbase));
    r.features = topIn.features | baseIn.features;
    return r;
  }
  const Slab top = foldToSingleInterface(m, topIn);
  const Slab base1 = foldToSingleInterface(m, baseIn);  // the base as seen under the top
  ValueId ct = coverageOf(m, topIn), cb = coverageOf(m, baseIn);

  // Transmittance of the top's medium along the normal, and both ways.
  ValueId mfp = e.mul(pin(top, SlabPin::SssMfp), pin(top, SlabPin::SssMfpScale));
  ValueId tn = e.exp(e.sub(e.k(0), e.bin(Op::Divide, e.bc(d, VType::Vec3), e.max(mfp, e.k(1e-30)))));
  ValueId tn2 = e.mul(tn, tn);
  ValueId tn2cb = e.mul(tn2, cb);

  // Region "top present": one interface, the top's (F0, F90, roughness,
  // normal), over the base seen through the top's medium. The
  // base's specular lobe is not the top's: putting its reflectance into the
  // top's (sharper) lobe makes highlights the full stack does not have, so
  // the whole albedo of the base goes into the diffuse below.
  Slab t = base1;
  for (SlabPin p : {SlabPin::F0, SlabPin::F90, SlabPin::Roughness, SlabPin::Normal}) t.pin(p) = pin(top, p);
  t.pin(SlabPin::Anisotropy) = e.k(0);
  // The base's interface as the runtime reads it under the top (relative to
  // it: a dielectric base of the top's IOR has none left).
  ValueId relScale;
  const Slab baseUnder = interfaceUnderLayers(m, base1, relScale);
  // Glints (flakes under a clear coat) stay unless the top hides the base or
  // the base's interface vanishes under it: the glint value is lerped toward
  // the top's by k = 1 - mean(T_n^2 C_B)(1 - mean F0_T) mean(F0_rel / F0_B).
  ValueId k = e.oneMinus(
      e.mul(e.mul(e.mean(tn2cb), e.oneMinus(e.mean(pin(top, SlabPin::F0)))), e.mean(relScale)));
  t.pin(SlabPin::GlintValue) = e.lerp(pin(base1, SlabPin::GlintValue), pin(top, SlabPin::GlintValue), k);
  // Energy of the stack: the top's interface reflects F_T; what it transmits
  // meets the medium, which returns its volumetric albedo a_T(1 - T_n^2), and
  // reaches the base, whose whole albedo (specular included: its lobe is not
  // the top's) comes back as diffuse through the top twice at the diffuse mean
  // cosine 0.5 (T_n^2 each way, as the runtime's layer throughput T^(1/mu)).
  // The base's diffuse also gets back what the top's underside reflects down,
  // as the runtime's substrate_closure_coat_diffuse: times
  // (1 - F_T) / ((1 - F_T) + TRAP A_B (1 - T_n^4)), 1 under a clear top.
  // The diffuse makes the single interface return exactly that.
  ValueId ft = fresnelAverage(m, top);
  ValueId tn4 = e.mul(tn2, tn2);
  ValueId trap = e.safeDiv(e.oneMinus(ft), e.add(e.oneMinus(ft), e.mul(e.mul(e.k(SUBSTRATE_COAT_TRAP),
                                                                              foldedDiffuse(m, baseUnder)),
                                                                        e.oneMinus(tn4))));
  ValueId albedoBase = e.add(fresnelAverage(m, baseUnder), e.mul(diffuseEnergy(m, baseUnder), trap));
  ValueId stack = e.add(ft, e.mul(e.oneMinus(ft), e.add(e.mul(pin(top, SlabPin::DiffuseAlbedo), e.oneMinus(tn2)),
                                                         e.mul(e.mul(tn2cb, tn2), albedoBase))));
  setDiffuseEnergy(m, t, e.max(e.sub(stack, fresnelAverage(m, t)), e.k(0)));
  t.pin(SlabPin::Emissive) = e.add(pin(top, SlabPin::Emissive), e.mul(e.mul(tn, cb), pin(base1, SlabPin::Emissive)));

  // Coverage-weighted: C = Ct + Cb(1-Ct); the top region weighs Ct/C.
  ValueId c = e.sub(e.add(ct, cb), e.mul(ct, cb));
  ValueId wt = e.safeDiv(ct, c);
  Slab r = lerpSlabs(m, baseIn, t, wt);
  // The medium below is the base's; the top's was consumed into the colours.
  for (SlabPin p : {SlabPin::SssMfp, SlabPin::SssMfpScale, SlabPin::SssPhaseAnisotropy, SlabPin::Tangent,
                    SlabPin::SecondRoughness, SlabPin::FuzzColor, SlabPin::FuzzRoughness})
    r.pin(p) = pin(baseIn, p);
  r.sssType = baseIn.sssType;
  r.sssTypeExplicit = baseIn.sssTypeExplicit;
  bool topGlint = topIn.features & kFeatGlint;
  r.pin(SlabPin::GlintUv) = topGlint ? pin(topIn, SlabPin::GlintUv) : pin(baseIn, SlabPin::GlintUv);
  r.specularProfileInput = topIn.specularProfileInput >= 0 ? topIn.specularProfileInput : baseIn.specularProfileInput;
  r.thickness = e.add(d, thicknessOf(m, baseIn));
  r.coverage = c;
  r.features = (topIn.features | baseIn.features) & ~kFeatAnisotropy;
  return r;
}

}  // namespace substratec
