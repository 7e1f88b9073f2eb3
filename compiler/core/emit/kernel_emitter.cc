#include "emit/kernel_emitter.h"

#include <algorithm>

#include <fmt/format.h>

namespace substratec {

namespace {

using namespace kernel;

/// The preview's specular profiles: each profile input as its own texture
/// (set 1, binding kPreviewProfileBinding + k, named p_<input>; HLSL's sampler
/// ps_<input> 16 above), read by SUBSTRATE_SPECULAR_PROFILE_SAMPLE, which the
/// runtime otherwise leaves at white (an engine binds its profile atlas).
std::string previewProfiles(const Material& m, const StorageLayout& L, const Syntax& syn) {
  const std::vector<int> profiles = specularProfileInputs(m, L);
  if (profiles.empty()) return "";
  std::string s, body;
  for (std::size_t k = 0; k < profiles.size(); ++k) {
    const std::string& name = m.inputs[profiles[k]].name;
    const int binding = kPreviewProfileBinding + static_cast<int>(k);
    s += syn.texture(1, binding, false, "p_" + name) + syn.sampler(1, binding + 16, "ps_" + name);
    body += fmt::format("  if (index == {}u) return SUBSTRATE_TEXTURE_SAMPLE_LEVEL(p_{}, ps_{}, uv, 0.0).rgb;\n", k, name, name);
  }
  s += "float3 substrate_preview_profile(uint index, float2 uv) {\n" + body + "  return SUBSTRATE_SPLAT3(1.0);\n}\n";
  return s + "#define SUBSTRATE_SPECULAR_PROFILE_SAMPLE(index, uv) substrate_preview_profile(index, uv)\n";
}

/// Includes, in the order the entries use: the storage code before the
/// material (compiles its pack function in), the unpacker and lighting after.
std::string includes(const Material& m, const StorageLayout& L, const Syntax& syn, KernelMode mode,
                     Precision precision) {
  std::string s(syn.header);
  s += "#define SUBSTRATE_TEXTURE_LOD0 1  // no implicit derivatives in a compute shader\n";
  // The preview filters its (mipmapped) textures over the pixel's footprint in uv0.
  if (mode == KernelMode::Preview)
    s += "#define SUBSTRATE_SAMPLE(t, s, uv) SUBSTRATE_TEXTURE_SAMPLE_GRAD(t, s, uv, g.uvDerivatives.xy, "
         "g.uvDerivatives.zw)\n";
  s += precisionDefine(precision);
  // The closures lit come straight from <name>_evaluate (unit normals), except
  // in Deferred, which lights what the generic unpacker decoded.
  if (mode != KernelMode::Deferred) s += "#define SUBSTRATE_UNIT_CLOSURE_NORMALS 1  // lit as evaluated: unit normals\n";
  s += fmt::format("#include \"{}\"\n", syn.prelude);
  if (mode == KernelMode::Deferred) {
    s += fmt::format("#define SUBSTRATE_MAX_WORDS {}\n", std::max(32, L.words()));
    s += "#include \"substrate_pack.h\"\n";
  }
  s += fmt::format("#include \"{}{}\"\n", m.name, syn.materialExtension);
  if (mode == KernelMode::Preview) s += previewProfiles(m, L, syn);
  if (mode == KernelMode::Deferred) s += "#include \"substrate_unpack.h\"\n";
  s += "#include \"substrate_energy_lut.h\"\n#include \"substrate_bsdf.h\"\n#include \"substrate_lighting.h\"\n\n";
  return s;
}

/// Writes closure `c` (an expression) at results[base + ...] (kClosure* order).
std::string dumpClosure(const std::string& c, const std::string& base) {
  std::string s;
  auto put3 = [&](int at, const std::string& field) {
    s += fmt::format("  results[{0} + {1}u] = {2}.{3}.x; results[{0} + {4}u] = {2}.{3}.y; results[{0} + {5}u] = {2}.{3}.z;\n",
                     base, at, c, field, at + 1, at + 2);
  };
  auto put = [&](int at, const std::string& value) { s += fmt::format("  results[{} + {}u] = {};\n", base, at, value); };
  put3(kClosureDiffuseAlbedo, "diffuseAlbedo");
  put3(kClosureF0, "f0");
  put3(kClosureF90, "f90");
  put(kClosureRoughness, c + ".roughness");
  put(kClosureAnisotropy, c + ".anisotropy");
  put3(kClosureN, "N");
  put3(kClosureT, "T");
  put3(kClosureSssMfp, "sssMfp");
  put(kClosureSssPhase, c + ".sssPhaseAnisotropy");
  put(kClosureSssType, "float(" + c + ".sssType)");
  put(kClosureSecondRoughness, c + ".secondRoughness");
  put(kClosureSecondRoughnessWeight, c + ".secondRoughnessWeight");
  put(kClosureFuzzAmount, c + ".fuzzAmount");
  put3(kClosureFuzzColor, "fuzzColor");
  put(kClosureFuzzRoughness, c + ".fuzzRoughness");
  put(kClosureGlintValue, c + ".glintValue");
  put(kClosureGlintUv, c + ".glintUv.x");
  put(kClosureGlintUv + 1, c + ".glintUv.y");
  for (int i = 0; i < 4; ++i) put(kClosureGlintUvDerivatives + i, c + ".glintUvDerivatives." + "xyzw"[i]);
  put(kClosureSpecularProfile, "float(" + c + ".specularProfile)");
  put3(kClosureEmissive, "emissive");
  put(kClosureWeight, c + ".weight");
  put3(kClosureTopTransmittance, "topTransmittance");
  put(kClosureCoverageAbove, c + ".coverageAbove");
  put(kClosureFeatures, "float(" + c + ".features)");
  put(kClosureIsTop, c + ".isTop ? 1.0 : 0.0");
  put(kClosureExtraInterfaces, "float(" + c + ".extraInterfaces)");
  put(kClosureCoatFloor, c + ".coatFloor");
  put(kClosureCoatInterface, c + ".coatInterface");
  put(kClosureCoatStretch, c + ".coatStretch.x");
  put(kClosureCoatStretch + 1, c + ".coatStretch.y");
  put3(kClosureCoatTangent, "coatTangent");
  put(kClosureCoatShare, c + ".coatShare");
  s += "#if SUBSTRATE_USE_HAIR\n";  // the field exists only where a hair may be
  for (int i = 0; i < 4; ++i) put(kClosureHair + i, c + ".hair." + "xyzw"[i]);
  s += "#else\n";
  for (int i = 0; i < 4; ++i) put(kClosureHair + i, "0.0");
  s += "#endif\n";
  s += "#if SUBSTRATE_USE_EYE\n";  // the fields exist only where an eye may be
  put3(kClosureIrisN, "irisN");
  put3(kClosureIrisPlaneN, "irisPlaneN");
  for (int i = 0; i < 2; ++i) put(kClosureIris + i, c + ".iris." + "xy"[i]);
  s += "#else\n";
  for (int at = kClosureIrisN; at < kClosureIris + 2; ++at) put(at, "0.0");
  s += "#endif\n";
  put(kClosureCoversLayers, c + ".coversLayers ? 1.0 : 0.0");
  for (int at = kClosureCoversLayers + 1; at < kClosureFloats; ++at) put(at, "0.0");  // padding (none at 69)
  return s;
}

/// With per-sample inputs: binding 8 holds one float4 per non-texture input
/// (material order) per sample; the material's private input globals
/// (EmitOptions::inputsPerInvocation) are set from it.
std::string assignSampleInputs(const Material& m, const Syntax& syn) {
  int count = 0;
  for (const Input& in : m.inputs) count += in.type != VType::Texture;
  std::string s;
  int j = 0;
  for (const Input& in : m.inputs) {
    if (in.type == VType::Texture) continue;
    static const char* swizzle[] = {"", ".x", ".xy", ".xyz", ""};
    s += fmt::format("  {} = sampleInputs[i * {}u + {}u]{};\n", syn.inputAccess(m.name, in.name), count, j++,
                     swizzle[componentCount(in.type)]);
  }
  return s;
}

std::string sampleKernel(const Material& m, const StorageLayout& L, const Syntax& syn, KernelMode mode,
                         const EmitOptions& emit) {
  const bool perSampleInputs = emit.inputsPerInvocation;
  const std::string upper = materialUpper(m);
  const int n = static_cast<int>(L.closures.size());
  std::string s = fmt::format(
      "// Generated by substratec: '{}' over a buffer of shading samples ({}), for tests against the CPU reference.\n"
      "// Layouts: compiler/core/emit/kernel_emitter.h.\n",
      m.name, mode == KernelMode::Forward ? "closures lit inline" : "closures packed, unpacked generically, then lit");
  s += includes(m, L, syn, mode, emit.precision);
  s += syn.storageBuffer(0, 6, Access::Read, "SubstrateSamples", "float4", "samples");
  s += syn.storageBuffer(0, 7, Access::Write, "SubstrateResults", "float", "results");
  if (perSampleInputs) s += syn.storageBuffer(0, 8, Access::Read, "SubstrateSampleInputs", "float4", "sampleInputs");
  s += "\n" + syn.computeMain(kLocalSize, 1) + fmt::format("  uint i = {}.x;\n", syn.computeId(ComputeId::Dispatch));
  if (perSampleInputs) s += assignSampleInputs(m, syn);
  auto sample = [&](int k) { return fmt::format("samples[i * {}u + {}u]", kSampleVec4s, k); };
  s += "  SubstrateGeometry g;\n";
  s += fmt::format("  g.N = normalize({}.xyz);\n", sample(kSampleNormal));
  s += fmt::format("  g.T = substrate_orthogonal_tangent(g.N, {}.xyz);\n", sample(kSampleTangent));
  s += fmt::format("  g.V = {}.xyz;\n", sample(kSampleView));
  s += fmt::format("  g.position = {}.xyz;\n", sample(kSamplePosition));
  s += fmt::format("  g.uv0 = {0}.xy;\n  g.uv1 = {0}.zw;\n", sample(kSampleUv));
  s += fmt::format("  g.vertexColor = {};\n", sample(kSampleColor));
  s += fmt::format("  g.uvDerivatives = {};\n", sample(kSampleUvDerivatives));
  s += fmt::format("  g.dither = {}.w;\n", sample(kSamplePosition));
  s += fmt::format("  float3 L = {}.xyz;\n", sample(kSampleLight));
  s += fmt::format("  float3 radiance = {}.xyz;\n", sample(kSampleRadiance));
  s += fmt::format("  float3 prefiltered = {}.xyz;\n", sample(kSamplePrefiltered));
  s += fmt::format("  float3 irradiance = {}.xyz;\n", sample(kSampleIrradiance));
  s += evaluateCall(m);
  std::string count = fmt::format("uint({}_CLOSURE_COUNT)", upper);
  if (mode == KernelMode::Deferred) {
    // The base pass packs; a deferred pass sees only the words.
    s += fmt::format("  uint packed[{}_WORD_COUNT];\n  uint topLayer;\n", upper);
    s += fmt::format("  {}_pack(closures, g.dither, packed, topLayer);\n", m.name);
    s += "  uint words[SUBSTRATE_MAX_WORDS];\n";
    s += "  for (int w = 0; w < SUBSTRATE_MAX_WORDS; ++w) {\n";
    s += fmt::format("    words[w] = w < {}_WORD_COUNT ? packed[min(w, {}_WORD_COUNT - 1)] : 0u;\n  }}\n", upper, upper);
    s += "  SubstrateClosure unpacked[SUBSTRATE_MAX_CLOSURES];\n";
    s += "  uint count = substrate_unpack_material(words, topLayer, unpacked);\n";
    s += fmt::format("  for (int k = 0; k < {}_CLOSURE_COUNT; ++k) {{\n    closures[k] = unpacked[k];\n  }}\n", upper);
    count = "count";
  }
  const int stride = kResultHeaderFloats + kClosureFloats * n;
  s += fmt::format("  uint base = i * {}u;\n", stride);
  s += "  float3 direct = SUBSTRATE_SPLAT3(0.0);\n  float3 environment = SUBSTRATE_SPLAT3(0.0);\n";
  s += "  float3 emissive = SUBSTRATE_SPLAT3(0.0);\n";
  s += fmt::format("  for (int k = 0; k < {}_CLOSURE_COUNT; ++k) {{\n", upper);
  // A pixel the base pass stored in a smaller layout (dynamic simplification)
  // unpacks to fewer closures: the rest are not lit.
  if (mode == KernelMode::Deferred) s += "    if (uint(k) >= count) continue;\n";
  s += "    if (!substrate_closure_visible(closures[k])) continue;  // dynamic culling: weight 0\n";
  s += "    direct += substrate_light_closure(closures[k], g.V, L, radiance);\n";
  s += "    float3 viewT = substrate_closure_view_throughput(closures[k], dot(closures[k].N, g.V), g.V);\n";
  s += "    environment += viewT * substrate_env_split_sum(closures[k], g.V, prefiltered, irradiance);\n";
  if (mode == KernelMode::Forward && anyEmissive(m, L)) s += "    emissive += viewT * closures[k].emissive;\n";
  s += "  }\n";
  if (mode == KernelMode::Forward && unlitEmission(m)) s += "  emissive += emission;  // the unlit nodes'\n";
  if (mode == KernelMode::Forward && isWaterMaterial(m))
    s += fmt::format("  emissive += substrate_water_seen(closures[0], water, float4(prefiltered, {}), 0.0, g.V, L, "
                     "radiance);  // the water's body\n",
                     dialectLiteral(kWaterSampleDepth));
  s += fmt::format("  results[base + {}u] = float({});\n", kResultCount, count);
  s += fmt::format("  results[base + {}u] = coverage;\n", kResultCoverage);
  s += fmt::format("  results[base + {}u] = {};\n  results[base + 3u] = 0.0;\n", kResultLayoutClass,
                   mode == KernelMode::Deferred ? "float(substrate_layout_class(packed[0]))" : "0.0");
  for (auto [at, v] : {std::pair{kResultTransmittance, "transmittance"}, std::pair{kResultDirect, "direct"},
                       std::pair{kResultEnvironment, "environment"}, std::pair{kResultEmissive, "emissive"}})
    s += fmt::format("  results[base + {0}u] = {1}.x; results[base + {2}u] = {1}.y; results[base + {3}u] = {1}.z; "
                     "results[base + {4}u] = 0.0;\n",
                     at, v, at + 1, at + 2, at + 3);
  for (int k = 0; k < n; ++k) {
    s += fmt::format("  // closure {} ('{}')\n", k, m.slabs[L.closures[k].slab].id);
    s += dumpClosure(fmt::format("closures[{}]", k), fmt::format("base + {}u", kResultHeaderFloats + kClosureFloats * k));
  }
  s += "}\n";
  return s;
}

/// The preview's ray through pixel p and its hit on the unit sphere.
constexpr const char* kPreviewHelpers = R"(// The view ray through pixel p (centre of the pixel) from the camera, looking at the origin.
float3 substrate_preview_ray(float2 p) {
  float2 ndc = (p / preview.viewport.xy) * 2.0 - SUBSTRATE_SPLAT2(1.0);
  float3 forward = normalize(-preview.camera.xyz);
  float3 right = normalize(cross(forward, float3(0.0, 1.0, 0.0)));
  float3 up = cross(right, forward);
  float aspect = preview.viewport.x / preview.viewport.y;
  return normalize(forward + (ndc.x * aspect * preview.camera.w) * right - (ndc.y * preview.camera.w) * up);
}

// Distance along the ray to the unit sphere, or -1.
float substrate_preview_hit(float3 o, float3 d) {
  float b = dot(o, d);
  float c = dot(o, o) - 1.0;
  float disc = b * b - c;
  if (disc < 0.0) return -1.0;
  return -b - sqrt(disc);
}

// Texture coordinates on the sphere: u around (twice), v from pole to pole.
float2 substrate_preview_uv(float3 n) {
  return float2(2.0 * (0.5 + atan2(n.x, n.z) / 6.28318530718), acos(clamp(n.y, -1.0, 1.0)) / 3.14159265359);
}

)";

/// The preview's shading point: the pixel's ray, its hit on the sphere (or
/// the background) and the geometry `g` there.
std::string previewShadingPoint() {
  return R"(  if (float(pixel.x) >= preview.viewport.x || float(pixel.y) >= preview.viewport.y) return;
  uint index = pixel.y * uint(preview.viewport.x) + pixel.x;
  float3 eye = preview.camera.xyz;
  float3 dir = substrate_preview_ray(float2(pixel) + SUBSTRATE_SPLAT2(0.5));
  float3 background = SUBSTRATE_ENV_PREFILTERED(dir, 0.0);
  float t = substrate_preview_hit(eye, dir);
  if (t < 0.0) {
    results[index] = float4(background, 0.0);
    return;
  }
  float3 P = eye + t * dir;
  SubstrateGeometry g;
  g.N = normalize(P);
  g.T = substrate_orthogonal_tangent(g.N, float3(g.N.z, 0.0, -g.N.x));
  g.V = -dir;
  g.position = P;
  g.uv0 = substrate_preview_uv(g.N);
  g.uv1 = g.uv0;
  g.vertexColor = SUBSTRATE_SPLAT4(1.0);
  // uv footprint of one pixel: the neighbours' hits (or none at the silhouette).
  float2 du = SUBSTRATE_SPLAT2(0.0);
  float2 dv = SUBSTRATE_SPLAT2(0.0);
  float3 dx = substrate_preview_ray(float2(pixel) + float2(1.5, 0.5));
  float3 dy = substrate_preview_ray(float2(pixel) + float2(0.5, 1.5));
  float tx = substrate_preview_hit(eye, dx);
  float ty = substrate_preview_hit(eye, dy);
  if (tx > 0.0) du = substrate_preview_uv(normalize(eye + tx * dx)) - g.uv0;
  if (ty > 0.0) dv = substrate_preview_uv(normalize(eye + ty * dy)) - g.uv0;
  du.x = du.x - 2.0 * round(du.x / 2.0);  // across the seam
  dv.x = dv.x - 2.0 * round(dv.x / 2.0);
  g.uvDerivatives = float4(du, dv);
  // Interleaved gradient noise (Jimenez 2014): the per-pixel dither.
  g.dither = frac(52.9829189 * frac(dot(float2(pixel) + SUBSTRATE_SPLAT2(0.5), float2(0.06711056, 0.00583715))));
)";
}

/// The preview's lighting of the closures into `color`, composited over the
/// environment seen through the sphere as the blend mode says.
std::string previewLighting(const Material& m, const StorageLayout& L) {
  std::string s = evaluateCall(m);
  s += fmt::format(R"(  float3 color = SUBSTRATE_SPLAT3(0.0);
  for (int k = 0; k < {0}_CLOSURE_COUNT; ++k) {{
    if (!substrate_closure_visible(closures[k])) continue;  // dynamic culling: weight 0
    for (int l = 0; l < {1}; ++l) {{
      color += substrate_light_closure(closures[k], g.V, preview.lightDirection[l].xyz, preview.lightRadiance[l].rgb);
    }}
    float3 viewT = substrate_closure_view_throughput(closures[k], dot(closures[k].N, g.V), g.V);
    float3 pre = SUBSTRATE_ENV_PREFILTERED(substrate_reflection_dir(closures[k], g.V),
                                           substrate_env_mip(substrate_env_roughness(closures[k]), preview.viewport.z));
    color += viewT * substrate_env_split_sum(closures[k], g.V, pre, SUBSTRATE_ENV_IRRADIANCE(closures[k].N));
)",
                   materialUpper(m), kPreviewLights);
  if (anyEmissive(m, L)) s += "    color += viewT * closures[k].emissive;\n";
  s += "  }\n";
  if (unlitEmission(m)) s += "  color += emission;  // the unlit nodes'\n";
  // A ball of water: behind its surface the environment along the view (not
  // refracted), through the sphere's chord 2 N.V (substrate_water_seen).
  if (isWaterMaterial(m))
    s += "  color += substrate_water_seen(closures[0], water, float4(SUBSTRATE_ENV_PREFILTERED(-g.V, 0.0), "
         "2.0 * max(dot(g.N, g.V), 0.0)), 0.0, g.V, preview.lightDirection[0].xyz, preview.lightRadiance[0].rgb);\n";
  switch (m.settings.blendMode) {
    case BlendMode::Masked:
      s += "  if (coverage < 0.5) color = background;\n";
      break;
    case BlendMode::AlphaHoldout:
      s += "  color = background * (1.0 - coverage);\n";
      break;
    default:
      if (translucentBlend(m)) {
        if (m.settings.blendMode == BlendMode::ColoredTransmittanceOnly) s += "  color = SUBSTRATE_SPLAT3(0.0);\n";
        s += fmt::format("  color += background * ({});\n", backgroundThroughput(m));
      } else {
        s += "  color = lerp(background, color, coverage);\n";
      }
  }
  return s + "  results[index] = float4(color, 1.0);\n}\n";
}

std::string previewKernel(const Material& m, const StorageLayout& L, const Syntax& syn, Precision precision) {
  std::string s = fmt::format(
      "// Generated by substratec: '{}' on a unit sphere, {} lights and a split-sum environment (substratec preview).\n"
      "// Layouts: compiler/core/emit/kernel_emitter.h.\n",
      m.name, kPreviewLights);
  s += includes(m, L, syn, KernelMode::Preview, precision);
  std::string lights;
  for (const char* l : {"lightDirection", "lightRadiance"}) lights += fmt::format("  float4 {}[{}];\n", l, kPreviewLights);
  s += syn.uniformBlock(0, 0, "SubstratePreview", "preview", "  float4 camera;\n  float4 viewport;\n" + lights);
  s += environmentResources(syn);
  s += syn.storageBuffer(0, 7, Access::Write, "SubstrateResults", "float4", "results") + "\n";
  s += kPreviewHelpers;
  s += syn.computeMain(8, 8) + fmt::format("  uint2 pixel = {}.xy;\n", syn.computeId(ComputeId::Dispatch));
  return s + previewShadingPoint() + previewLighting(m, L);
}

/// Where the ray o + t d, t >= 0, is inside the cube [-e, e]^3 (a volume's preview and cost kernels).
constexpr const char* kVolumeBox = R"(// Where the ray o + t d, t >= 0, is inside the cube [-e, e]^3: (t in, t out), empty when out <= in.
float2 substrate_preview_box(float3 o, float3 d, float e) {
  float3 inv = SUBSTRATE_SPLAT3(1.0) / max(abs(d), SUBSTRATE_SPLAT3(1e-20));
  float3 sgn = float3(d.x < 0.0 ? -1.0 : 1.0, d.y < 0.0 ? -1.0 : 1.0, d.z < 0.0 ? -1.0 : 1.0);
  float3 a = (SUBSTRATE_SPLAT3(-e) - o) * sgn * inv;
  float3 b = (SUBSTRATE_SPLAT3(e) - o) * sgn * inv;
  float3 lo = min(a, b);
  float3 hi = max(a, b);
  return float2(max(max(max(lo.x, lo.y), lo.z), 0.0), min(min(hi.x, hi.y), hi.z));
}

)";

/// A volume's preview: the cube kVolumePreviewExtent around the origin marched
/// from the preview's camera in kVolumePreviewSteps steps of the runtime's
/// step, each sample lit by the key light through the medium (its
/// transmittance toward the light marched in kVolumePreviewShadowSteps
/// steps), an isotropic phase, and the environment's mean irradiance as
/// ambient; over the environment behind. Same resources as the sphere's.
constexpr const char* kVolumePreviewBody = R"(  if (float(pixel.x) >= preview.viewport.x || float(pixel.y) >= preview.viewport.y) return;
  uint index = pixel.y * uint(preview.viewport.x) + pixel.x;
  float3 eye = preview.camera.xyz;
  float3 dir = substrate_preview_ray(float2(pixel) + SUBSTRATE_SPLAT2(0.5));
  float3 background = SUBSTRATE_ENV_PREFILTERED(dir, 0.0);
  float2 span = substrate_preview_box(eye, dir, VOLUME_PREVIEW_EXTENT);
  if (span.y <= span.x) {
    results[index] = float4(background, 0.0);
    return;
  }
  float3 L = preview.lightDirection[0].xyz;
  // Isotropic scattering of the environment: its mean radiance over the sphere.
  float3 ambient = (SUBSTRATE_ENV_IRRADIANCE(float3(0.0, 1.0, 0.0)) + SUBSTRATE_ENV_IRRADIANCE(float3(0.0, -1.0, 0.0))) *
                   (0.5 * SUBSTRATE_INV_PI);
  float ds = (span.y - span.x) / float(VOLUME_PREVIEW_STEPS);
  float3 radiance = SUBSTRATE_SPLAT3(0.0);
  float3 throughput = SUBSTRATE_SPLAT3(1.0);
  for (int k = 0; k < VOLUME_PREVIEW_STEPS; ++k) {
    SubstrateFogCloudSample s = substrate_preview_medium(eye + (span.x + (float(k) + 0.5) * ds) * dir, -dir);
    // What reaches the sample from the light: the medium's transmittance toward it.
    float2 toLight = substrate_preview_box(eye + (span.x + (float(k) + 0.5) * ds) * dir, L, VOLUME_PREVIEW_EXTENT);
    float dl = max(toLight.y, 0.0) / float(VOLUME_PREVIEW_SHADOW_STEPS);
    float3 depth = SUBSTRATE_SPLAT3(0.0);
    for (int j = 0; j < VOLUME_PREVIEW_SHADOW_STEPS; ++j) {
      float3 p = eye + (span.x + (float(k) + 0.5) * ds) * dir + ((float(j) + 0.5) * dl) * L;
      depth += substrate_preview_medium(p, -dir).extinction * dl;
    }
    float3 inScattered = preview.lightRadiance[0].rgb * exp(-depth) * substrate_fog_hg_phase(dot(L, dir), 0.0);
    substrate_fog_cloud_step(s, ds, inScattered, ambient, radiance, throughput);
  }
  results[index] = float4(radiance + throughput * background, 1.0 - dot(throughput, SUBSTRATE_SPLAT3(1.0 / 3.0)));
}
)";

std::string volumePreviewKernel(const Material& m, const Syntax& syn) {
  std::string s = fmt::format(
      "// Generated by substratec: volume '{}' in a cube of half side {}, marched in {} steps (substratec preview).\n"
      "// Layouts: compiler/core/emit/kernel_emitter.h.\n",
      m.name, dialectLiteral(kVolumePreviewExtent), kVolumePreviewSteps);
  s += std::string(syn.header) + "#define SUBSTRATE_TEXTURE_LOD0 1  // no implicit derivatives in a compute shader\n";
  s += fmt::format("#include \"{}\"\n#include \"{}{}\"\n", syn.prelude, m.name, syn.materialExtension);
  s += fmt::format("#define VOLUME_PREVIEW_EXTENT {}\n#define VOLUME_PREVIEW_STEPS {}\n#define VOLUME_PREVIEW_SHADOW_STEPS {}\n\n",
                   dialectLiteral(kVolumePreviewExtent), kVolumePreviewSteps, kVolumePreviewShadowSteps);
  std::string lights;
  for (const char* l : {"lightDirection", "lightRadiance"}) lights += fmt::format("  float4 {}[{}];\n", l, kPreviewLights);
  s += syn.uniformBlock(0, 0, "SubstratePreview", "preview", "  float4 camera;\n  float4 viewport;\n" + lights);
  s += environmentResources(syn);
  s += syn.storageBuffer(0, 7, Access::Write, "SubstrateResults", "float4", "results") + "\n";
  s += kPreviewHelpers;
  s += kVolumeBox;
  s += fmt::format(R"(// The medium at p, seen along -toEye.
SubstrateFogCloudSample substrate_preview_medium(float3 p, float3 toEye) {{
  SubstrateGeometry g;
  g.position = p;
  g.N = float3(0.0, 0.0, 1.0);
  g.T = float3(1.0, 0.0, 0.0);
  g.V = toEye;
  g.uv0 = (p.xy / VOLUME_PREVIEW_EXTENT) * 0.5 + SUBSTRATE_SPLAT2(0.5);
  g.uv1 = float2(p.z / VOLUME_PREVIEW_EXTENT * 0.5 + 0.5, 0.0);
  g.vertexColor = SUBSTRATE_SPLAT4(1.0);
  g.uvDerivatives = SUBSTRATE_SPLAT4(0.0);
  g.dither = 0.5;
  return {}_sample(g);
}}

)",
                   m.name);
  s += syn.computeMain(8, 8) + fmt::format("  uint2 pixel = {}.xy;\n", syn.computeId(ComputeId::Dispatch));
  return s + kVolumePreviewBody;
}

/// A volume's cost kernel: one ray an invocation, made up from its index (a
/// hash: from a sphere of radius 3 x the extent toward a point near the
/// centre), through the cube kVolumeCostExtent marched in `steps` steps of
/// `<name>_sample` and the runtime's step (a constant light and ambient):
/// results[i] = (radiance, mean throughput). What `sweep` times per ray.
std::string volumeThroughputKernel(const Material& m, const Syntax& syn, int steps) {
  std::string s = fmt::format(
      "// Generated by substratec: the cost of volume '{}' per ray, {} steps through a cube of half side {}.\n", m.name,
      steps, dialectLiteral(kVolumeCostExtent));
  s += std::string(syn.header) + "#define SUBSTRATE_TEXTURE_LOD0 1  // no implicit derivatives in a compute shader\n";
  s += fmt::format("#include \"{}\"\n#include \"{}{}\"\n", syn.prelude, m.name, syn.materialExtension);
  s += fmt::format("#define VOLUME_EXTENT {}\n#define VOLUME_STEPS {}\n\n", dialectLiteral(kVolumeCostExtent),
                   std::clamp(steps, 1, kMaxVolumeSteps));
  s += syn.storageBuffer(0, 7, Access::Write, "SubstrateResults", "float4", "results") + "\n";
  s += kVolumeBox;
  s += syn.computeMain(kLocalSize, 1) + fmt::format("  uint i = {}.x;\n", syn.computeId(ComputeId::Dispatch));
  s += fmt::format(R"(  uint3 h = substrate_pcg3d(uint3(i, i * 7919u + 17u, 0x5eedu));
  uint3 k = substrate_pcg3d(h);
  float z = substrate_hash_to_unit(h.x) * 2.0 - 1.0;
  float phi = 6.28318530718 * substrate_hash_to_unit(h.y);
  float3 from = (3.0 * VOLUME_EXTENT) * float3(sqrt(max(0.0, 1.0 - z * z)) * cos(phi), sqrt(max(0.0, 1.0 - z * z)) * sin(phi), z);
  float3 toward = (0.1 * VOLUME_EXTENT) * (float3(substrate_hash_to_unit(k.x), substrate_hash_to_unit(k.y),
                                                   substrate_hash_to_unit(k.z)) * 2.0 - SUBSTRATE_SPLAT3(1.0));
  float3 dir = normalize(toward - from);
  float2 span = substrate_preview_box(from, dir, VOLUME_EXTENT);
  float ds = max(span.y - span.x, 0.0) / float(VOLUME_STEPS);
  float3 radiance = SUBSTRATE_SPLAT3(0.0);
  float3 throughput = SUBSTRATE_SPLAT3(1.0);
  SubstrateGeometry g;
  g.N = float3(0.0, 0.0, 1.0);
  g.T = float3(1.0, 0.0, 0.0);
  g.V = -dir;
  g.uv0 = SUBSTRATE_SPLAT2(0.5);
  g.uv1 = SUBSTRATE_SPLAT2(0.5);
  g.vertexColor = SUBSTRATE_SPLAT4(1.0);
  g.uvDerivatives = SUBSTRATE_SPLAT4(0.0);
  g.dither = 0.5;
  for (int n = 0; n < VOLUME_STEPS; ++n) {{
    g.position = from + (span.x + (float(n) + 0.5) * ds) * dir;
    substrate_fog_cloud_step({}_sample(g), ds, SUBSTRATE_SPLAT3(1.0), SUBSTRATE_SPLAT3(0.5), radiance, throughput);
  }}
  results[i] = float4(radiance, dot(throughput, SUBSTRATE_SPLAT3(1.0 / 3.0)));
}}
)",
                   m.name);
  return s;
}

/// The cost kernel: one shading point per invocation, made up from its index
/// (a hash), so that nothing but the material and the lighting is measured.
std::string throughputKernel(const Material& m, const StorageLayout& L, const Syntax& syn, Precision precision) {
  const std::string upper = materialUpper(m);
  std::string s = fmt::format(
      "// Generated by substratec: the cost of '{}' per shading point (one light and a split-sum environment).\n",
      m.name);
  s += includes(m, L, syn, KernelMode::Throughput, precision);
  s += syn.storageBuffer(0, 7, Access::Write, "SubstrateResults", "float4", "results") + "\n";
  // A water pays for its body too: what lies behind it is a constant grey
  // kWaterSampleDepth behind the surface (the forward pass reads a texture).
  const std::string waterBody =
      isWaterMaterial(m)
          ? fmt::format("  color += substrate_water_seen(closures[0], water, float4(SUBSTRATE_SPLAT3(0.5), {}), 0.0, "
                        "g.V, L, SUBSTRATE_SPLAT3(1.0));  // the water's body\n",
                        dialectLiteral(kWaterSampleDepth))
          : "";
  s += syn.computeMain(kLocalSize, 1) + fmt::format("  uint i = {}.x;\n", syn.computeId(ComputeId::Dispatch));
  s += fmt::format(R"(  uint3 h = substrate_pcg3d(uint3(i, i * 7919u + 17u, 0x5eedu));
  uint3 k = substrate_pcg3d(h);
  float z = substrate_hash_to_unit(h.x) * 2.0 - 1.0;
  float phi = 6.28318530718 * substrate_hash_to_unit(h.y);
  float rxy = sqrt(max(0.0, 1.0 - z * z));
  SubstrateGeometry g;
  g.N = float3(rxy * cos(phi), rxy * sin(phi), z);
  g.T = substrate_orthogonal_tangent(g.N, float3(1.0, 0.0, 0.0));
  float3 B = cross(g.N, g.T);
  float cv = 0.05 + 0.95 * substrate_hash_to_unit(h.z);
  float av = 6.28318530718 * substrate_hash_to_unit(k.x);
  g.V = cv * g.N + sqrt(1.0 - cv * cv) * (cos(av) * g.T + sin(av) * B);
  float cl = substrate_hash_to_unit(k.y);
  float al = 6.28318530718 * substrate_hash_to_unit(k.z);
  float3 L = cl * g.N + sqrt(1.0 - cl * cl) * (cos(al) * g.T + sin(al) * B);
  g.position = g.N;
  g.uv0 = float2(substrate_hash_to_unit(h.x ^ k.y), substrate_hash_to_unit(h.y ^ k.z));
  g.uv1 = g.uv0;
  g.vertexColor = SUBSTRATE_SPLAT4(1.0);
  g.uvDerivatives = float4(1e-3, 0.0, 0.0, 1e-3);
  g.dither = substrate_hash_to_unit(k.x ^ h.z);
{1}  float3 color = SUBSTRATE_SPLAT3(0.0);
  for (int c = 0; c < {0}_CLOSURE_COUNT; ++c) {{
    if (!substrate_closure_visible(closures[c])) continue;  // dynamic culling: weight 0
    color += substrate_light_closure(closures[c], g.V, L, SUBSTRATE_SPLAT3(1.0));
    color += substrate_closure_view_throughput(closures[c], dot(closures[c].N, g.V), g.V) *
             substrate_env_split_sum(closures[c], g.V, SUBSTRATE_SPLAT3(0.5), SUBSTRATE_SPLAT3(1.5));
  }}
{2}  results[i] = float4(color, coverage);
}}
)",
                   upper, evaluateCall(m), waterBody);
  return s;
}

}  // namespace

std::string emitKernel(const Material& m, const StorageLayout& layout, const Syntax& syn, KernelMode mode,
                       const EmitOptions& emit) {
  if (mode == KernelMode::Preview)
    return isVolumeMaterial(m) ? volumePreviewKernel(m, syn) : previewKernel(m, layout, syn, emit.precision);
  if (mode == KernelMode::Throughput)
    return isVolumeMaterial(m) ? volumeThroughputKernel(m, syn, emit.volumeSteps)
                               : throughputKernel(m, layout, syn, emit.precision);
  return sampleKernel(m, layout, syn, mode, emit);
}

std::string kernelFileName(const Material& m, const Syntax& syn, KernelMode mode) {
  const char* what = mode == KernelMode::Forward    ? "forward_samples"
                     : mode == KernelMode::Deferred ? "deferred_samples"
                     : mode == KernelMode::Preview  ? "preview"
                                                    : "throughput";
  return fmt::format("{}.{}{}", m.name, what, syn.computeExtension);
}

}  // namespace substratec
