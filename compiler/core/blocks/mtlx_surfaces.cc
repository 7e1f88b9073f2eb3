#include "blocks/mtlx_surfaces.h"

namespace substratec::blocks {

RoughnessAnisotropy mtlxRoughnessAnisotropy(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                            const std::string& prefix) {
  const Value r = namedValue(w, prefix + "roughness", roughness);
  const Value a = namedValue(w, prefix + "alpha", vmax(mul(r, r), 1e-6));
  const Value aspect = namedValue(w, prefix + "aspect", vsqrt(oneMinus(vmin(anisotropy, 0.98))));
  const Value at = namedValue(w, prefix + "alpha_t", vmin(divide(a, aspect), 1.0));
  const Value ab = namedValue(w, prefix + "alpha_b", mul(a, aspect));
  return fromAlphas(at, ab);
}

RoughnessAnisotropy roughnessPins(const Value& roughness, const Value& anisotropy, NodeWriter& w,
                                  const std::string& prefix, AnisotropyModel model) {
  if (anisotropy.is_null() || isLiteral(anisotropy, 0)) return {roughness, Value()};
  const RoughnessAnisotropy ra = model(roughness, anisotropy, w, prefix);
  return {namedValue(w, (prefix == "specular_" ? "" : prefix) + "anisotropic_roughness", ra.roughness), ra.anisotropy};
}

void mtlxTransmission(SurfaceParams& params, const Value& weight, const char* dispersion, LayeredSurface& s) {
  auto C = [&](const char* name, const char* type, std::vector<double> def) {
    return params.constant(name, type, def).value_or(def);
  };
  s.transmission = weight;
  s.transmittance = params.param("transmission_color", "color3", {1, 1, 1}, ParamKind::Plain);
  params.warn(std::string("transmission: ") + kTransmissionNote);
  if (C("transmission_depth", "float", {0})[0] > 0)
    params.warn("transmission_depth: a surface material does not know the object's thickness; transmission_color "
                "is applied once, as if the light crossed one depth");
  const auto scatter = C("transmission_scatter", "color3", {0, 0, 0});
  if (scatter[0] != 0 || scatter[1] != 0 || scatter[2] != 0)
    params.warn("transmission_scatter: volume scattering inside the transmitting medium is not represented");
  if (C(dispersion, "float", {0})[0] != 0) params.warn(std::string(dispersion) + ": one IOR for every colour; dispersion ignored");
}

}  // namespace substratec::blocks
