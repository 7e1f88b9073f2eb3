#include "reference/gltf_brdf.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>

#include "reference/reference.h"

namespace substratec::reference {

namespace {

constexpr double kMinAlpha = 1e-3;

double dot(const Rgb& a, const Rgb& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Rgb normalized(const Rgb& a) {
  const double l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}

/// Trowbridge-Reitz (GGX) with alpha = a, and the height-correlated Smith
/// visibility V = G / (4 NoL NoV) (specification B.3.2).
double ggxD(double a, double NoH) {
  const double a2 = a * a, d = NoH * NoH * (a2 - 1) + 1;
  return a2 / (std::numbers::pi * d * d);
}
double smithV(double a, double NoV, double NoL) {
  const double a2 = a * a;
  const double gv = NoL * std::sqrt(NoV * NoV * (1 - a2) + a2), gl = NoV * std::sqrt(NoL * NoL * (1 - a2) + a2);
  return gv + gl > 0 ? 0.5 / (gv + gl) : 0;
}

/// KHR_materials_anisotropy: alpha_t along t, alpha_b along b.
double ggxDAniso(double at, double ab, double ToH, double BoH, double NoH) {
  const double a2 = at * ab;
  const Rgb f{ab * ToH, at * BoH, a2 * NoH};
  const double w2 = a2 / dot(f, f);
  return a2 * w2 * w2 / std::numbers::pi;
}
double smithVAniso(double at, double ab, double ToV, double BoV, double NoV, double ToL, double BoL, double NoL) {
  const double gv = NoL * std::sqrt(at * ToV * at * ToV + ab * BoV * ab * BoV + NoV * NoV);
  const double gl = NoV * std::sqrt(at * ToL * at * ToL + ab * BoL * ab * BoL + NoL * NoL);
  return gv + gl > 0 ? 0.5 / (gv + gl) : 0;
}

/// KHR_materials_sheen: the Charlie distribution and the Estevez-Kulla visibility.
double charlieD(double r, double NoH) {
  const double a = std::max(r * r, 1e-12), inv = 1 / a;
  const double sin2 = std::max(1 - NoH * NoH, 0.0);
  return (2 + inv) * std::pow(sin2, 0.5 * inv) / (2 * std::numbers::pi);
}
double sheenLambdaFit(double x, double a) {
  const double t = (1 - a) * (1 - a);
  auto mix = [t](double p, double q) { return p + (q - p) * t; };
  const double A = mix(21.5473, 25.3245), B = mix(3.82987, 3.32435), C = mix(0.19823, 0.16801),
               D = mix(-1.97760, -1.27393), E = mix(-4.32054, -4.85967);
  return A / (1 + B * std::pow(x, C)) + D * x + E;
}
double sheenLambda(double mu, double a) {
  return mu < 0.5 ? std::exp(sheenLambdaFit(mu, a)) : std::exp(2 * sheenLambdaFit(0.5, a) - sheenLambdaFit(1 - mu, a));
}
double sheenV(double r, double NoV, double NoL) {
  const double a = std::max(r, 1e-6) * std::max(r, 1e-6);
  const double v = 1 / ((1 + sheenLambda(NoV, a) + sheenLambda(NoL, a)) * 4 * NoV * NoL);
  return std::clamp(v, 0.0, 1.0);
}

double schlick(double f0, double x) { return f0 + (1 - f0) * std::pow(1 - x, 5); }
double max3(const Rgb& c) { return std::max({c[0], c[1], c[2]}); }

}  // namespace

double gltfSheenAlbedo(double mu, double r) {
  static std::mutex mutex;
  static std::map<std::pair<double, double>, double> cache;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (auto it = cache.find({mu, r}); it != cache.end()) return it->second;
  }
  // E(mu) = integral over the hemisphere of D V NoL (white sheen), midpoint rule
  // in (cos theta_l, phi_l): dOmega = d(cos) d(phi).
  const Rgb V{std::sqrt(std::max(1 - mu * mu, 0.0)), 0, mu};
  const int nt = 256, np = 128;
  double e = 0;
  for (int i = 0; i < nt; ++i) {
    const double NoL = (i + 0.5) / nt, s = std::sqrt(1 - NoL * NoL);
    for (int j = 0; j < np; ++j) {
      const double phi = std::numbers::pi * (j + 0.5) / np;  // symmetric in phi: half the circle, twice
      const Rgb L{s * std::cos(phi), s * std::sin(phi), NoL};
      const Rgb H = normalized({V[0] + L[0], V[1] + L[1], V[2] + L[2]});
      e += charlieD(r, H[2]) * sheenV(r, mu, NoL) * NoL;
    }
  }
  e *= (1.0 / nt) * (2 * std::numbers::pi / (2 * np)) * 2;
  std::lock_guard<std::mutex> lock(mutex);
  cache[{mu, r}] = e;
  return e;
}

Rgb gltfReflectance(const GltfMaterial& m, const Rgb& V, const Rgb& L) {
  const double NoV = V[2], NoL = L[2];
  if (NoV <= 0 || NoL <= 0 || m.unlit) return {0, 0, 0};
  const Rgb H = normalized({V[0] + L[0], V[1] + L[1], V[2] + L[2]});
  const double NoH = H[2], VoH = std::fabs(dot(V, H));
  // alpha = roughness², kept >= 1e-3 (Substrate's GGX floor): at 0 the
  // specification's lobe is a delta, with no value to compare at a probe.
  const double alpha = std::max(m.roughness * m.roughness, kMinAlpha);

  // specular_brdf: V·D, isotropic or along the rotated tangent.
  double vd;
  if (m.anisotropyStrength > 0) {
    const double c = std::cos(m.anisotropyRotation), s = std::sin(m.anisotropyRotation);
    const Rgb t{c, s, 0}, b{-s, c, 0};
    const double at = alpha + (1 - alpha) * m.anisotropyStrength * m.anisotropyStrength, ab = alpha;
    vd = ggxDAniso(at, ab, dot(t, H), dot(b, H), NoH) *
         smithVAniso(at, ab, dot(t, V), dot(b, V), NoV, dot(t, L), dot(b, L), NoL);
  } else {
    vd = ggxD(alpha, NoH) * smithV(alpha, NoV, NoL);
  }
  // Dielectric: fresnel_mix(specularColor, ior, specular, base = diffuse, layer = specular_brdf);
  // the diffuse keeps what transmission and diffuse transmission leave (their BTDFs are 0 here).
  const double f0ior = std::pow((1 - m.ior) / (1 + m.ior), 2);
  Rgb fr;
  for (int k = 0; k < 3; ++k) fr[k] = schlick(std::min(f0ior * m.specularColor[k], 1.0), VoH);
  const double diffuseScale = (1 - m.transmission) * (1 - m.diffuseTransmission) * (1 - m.specular * max3(fr));
  Rgb f;
  for (int k = 0; k < 3; ++k) {
    const double dielectric = diffuseScale * m.baseColor[k] / std::numbers::pi + m.specular * fr[k] * vd;
    const double metal = schlick(m.baseColor[k], VoH) * vd;
    f[k] = dielectric + (metal - dielectric) * m.metallic;
  }
  // Sheen over the base.
  if (max3(m.sheenColor) > 0) {
    const double sheen = charlieD(m.sheenRoughness, NoH) * sheenV(m.sheenRoughness, NoV, NoL);
    const double scale = std::min(1 - max3(m.sheenColor) * gltfSheenAlbedo(NoV, m.sheenRoughness),
                                  1 - max3(m.sheenColor) * gltfSheenAlbedo(NoL, m.sheenRoughness));
    for (int k = 0; k < 3; ++k) f[k] = m.sheenColor[k] * sheen + f[k] * scale;
  }
  // Clearcoat on top: fresnel_coat(N, 1.5, clearcoat, base, layer) = mix(base, layer, clearcoat · Fc(NoV)).
  if (m.clearcoat > 0) {
    const double ac = std::max(m.clearcoatRoughness * m.clearcoatRoughness, kMinAlpha);
    const double layer = ggxD(ac, NoH) * smithV(ac, NoV, NoL);
    const double w = m.clearcoat * schlick(0.04, NoV);
    for (int k = 0; k < 3; ++k) f[k] = f[k] * (1 - w) + layer * w;
  }
  return {f[0] * NoL * m.coverage, f[1] * NoL * m.coverage, f[2] * NoL * m.coverage};
}

std::optional<GltfMaterial> gltfMaterialOf(const nlohmann::ordered_json& j, std::string* why) {
  if (j.dump().find("Texture\"") != std::string::npos) {
    *why = "textured";
    return std::nullopt;
  }
  GltfMaterial m;
  auto num = [](const nlohmann::ordered_json& o, const char* k, double d) {
    return o.contains(k) && o[k].is_number() ? o[k].get<double>() : d;
  };
  auto rgb = [](const nlohmann::ordered_json& o, const char* k, Rgb d) {
    if (!o.contains(k) || !o[k].is_array() || o[k].size() < 3) return d;
    return Rgb{o[k][0].get<double>(), o[k][1].get<double>(), o[k][2].get<double>()};
  };
  const auto pbr = j.value("pbrMetallicRoughness", nlohmann::ordered_json::object());
  m.baseColor = rgb(pbr, "baseColorFactor", {1, 1, 1});
  m.metallic = num(pbr, "metallicFactor", 1);
  m.roughness = num(pbr, "roughnessFactor", 1);
  const double alpha = pbr.contains("baseColorFactor") && pbr["baseColorFactor"].is_array() && pbr["baseColorFactor"].size() == 4
                           ? pbr["baseColorFactor"][3].get<double>()
                           : 1.0;
  const std::string mode = j.value("alphaMode", std::string("OPAQUE"));
  if (mode == "BLEND") m.coverage = alpha;
  if (mode == "MASK") m.coverage = alpha >= num(j, "alphaCutoff", 0.5) ? 1 : 0;
  const auto ext = j.value("extensions", nlohmann::ordered_json::object());
  for (const auto& [name, e] : ext.items()) {
    if (name == "KHR_materials_ior") {
      m.ior = num(e, "ior", 1.5);
    } else if (name == "KHR_materials_specular") {
      m.specular = num(e, "specularFactor", 1);
      m.specularColor = rgb(e, "specularColorFactor", {1, 1, 1});
    } else if (name == "KHR_materials_clearcoat") {
      m.clearcoat = num(e, "clearcoatFactor", 0);
      m.clearcoatRoughness = num(e, "clearcoatRoughnessFactor", 0);
    } else if (name == "KHR_materials_sheen") {
      m.sheenColor = rgb(e, "sheenColorFactor", {0, 0, 0});
      m.sheenRoughness = num(e, "sheenRoughnessFactor", 0);
    } else if (name == "KHR_materials_anisotropy") {
      m.anisotropyStrength = num(e, "anisotropyStrength", 0);
      m.anisotropyRotation = num(e, "anisotropyRotation", 0);
    } else if (name == "KHR_materials_transmission") {
      m.transmission = num(e, "transmissionFactor", 0);
    } else if (name == "KHR_materials_diffuse_transmission") {
      m.diffuseTransmission = num(e, "diffuseTransmissionFactor", 0);
    } else if (name == "KHR_materials_unlit") {
      m.unlit = true;
    } else if (name == "KHR_materials_volume" || name == "KHR_materials_dispersion" ||
               name == "KHR_materials_emissive_strength" || name == "KHR_materials_diffuse_roughness") {
      // No effect on reflection (volume, dispersion), not reflection (emission), or a
      // draft the glTF 2.0 model does not have (diffuse roughness: Lambert stays).
    } else {
      *why = name + " (not in the glTF 2.0 model)";
      return std::nullopt;
    }
  }
  return m;
}

const std::vector<Rgb>& gltfProbeDirections() {
  static const std::vector<Rgb> dirs = [] {
    std::vector<Rgb> d;
    const int n = 24;
    const double golden = (std::sqrt(5.0) - 1) / 2;
    for (int i = 0; i < n; ++i) {
      const double z = 0.1 + 0.9 * (i + 0.5) / n;  // cos theta in [0.1, 1]: above the surface, not grazing
      const double s = std::sqrt(1 - z * z), phi = 2 * std::numbers::pi * golden * i;
      d.push_back({s * std::cos(phi), s * std::sin(phi), z});
    }
    return d;
  }();
  return dirs;
}

GltfComparison compareWithGltf(const CompileResult& r, const GltfMaterial& m, int diffuseModel) {
  double sum = 0, sx = 0, sy = 0;
  std::size_t count = 0;
  for (const Rgb& V : gltfProbeDirections()) {
    Geometry g;
    g.N = {0, 0, 1};
    g.T = {1, 0, 0};
    g.V = V;
    const MaterialResult<double> mr = evaluateMaterial<double>(r, g, {}, {});
    for (const Rgb& L : gltfProbeDirections()) {
      Rgb x{0, 0, 0};
      for (const Closure<double>& c : mr.closures) {
        const V3<double> l = lightClosure(c, V, L, {1.0, 1.0, 1.0}, diffuseModel);
        for (int k = 0; k < 3; ++k) x[k] += l[k];
      }
      const Rgb y = gltfReflectance(m, V, L);
      for (int k = 0; k < 3; ++k) {
        sum += (x[k] - y[k]) * (x[k] - y[k]) / (y[k] * y[k] + 0.01);
        sx += x[k];
        sy += y[k];
        ++count;
      }
    }
  }
  return {count ? sum / count : 0, sy > 0 ? sx / sy : 0};
}

}  // namespace substratec::reference
