#include "emit/entry_emitter.h"

#include <fmt/format.h>

namespace substratec {

namespace {

/// Shared prologue: includes. The material file includes the runtime it needs;
/// the base pass includes substrate_pack.h before it, which compiles the
/// material's pack function in (the forward pass does not pack).
std::string includes(const Material& m, const Syntax& syn, bool lighting, Precision precision = Precision::Float) {
  std::string s(syn.header);
  // The forward pass lights the closures <name>_evaluate returns: their normals are unit.
  if (lighting) s += "#define SUBSTRATE_UNIT_CLOSURE_NORMALS 1  // lit as evaluated: unit normals\n";
  s += precisionDefine(precision);
  s += fmt::format("#include \"{}\"\n", syn.prelude);
  if (!lighting) s += "#include \"substrate_pack.h\"\n";
  s += fmt::format("#include \"{}{}\"\n", m.name, syn.materialExtension);
  // A water's base pass lights its body (substrate_water_seen) as the forward pass does.
  if (lighting || isWaterMaterial(m))
    s += "#include \"substrate_energy_lut.h\"\n#include \"substrate_bsdf.h\"\n#include \"substrate_lighting.h\"\n";
  return s;
}

/// The interpolants of the stock vertex stage (both entry kinds).
const std::vector<StageVar>& interpolants() {
  static const std::vector<StageVar> v = {{0, "float3", "worldPosition", "POSITION0"}, {1, "float3", "normal", "NORMAL0"},
                                          {2, "float4", "tangent", "TANGENT0"},        {3, "float2", "uv0", "TEXCOORD0"},
                                          {4, "float2", "uv1", "TEXCOORD1"},           {5, "float4", "color", "COLOR0"}};
  return v;
}

/// The frame block (set 0, binding 0), with `environment` the split-sum
/// environment, `more` (an image the pass stores to: early fragment tests) and
/// `reads` (resources it only reads), then the stage interface with `outputs`,
/// up to main's brace.
std::string resourcesAndMain(const Syntax& syn, bool environment, const std::vector<StageVar>& outputs,
                             const std::string& more = "", const std::string& reads = "") {
  std::string s = syn.uniformBlock(0, 0, "SubstrateFrame", "frame",
                                   "  float4 cameraPosition;  // xyz: world position of the eye\n"
                                   "  float4 lightDirection;  // xyz: unit vector toward the light\n"
                                   "  float4 lightRadiance;   // rgb\n"
                                   "  float4 envParams;       // x: mip count of the prefiltered environment\n");
  if (environment) s += environmentResources(syn);
  // A pass that stores to an image (the base pass's material buffer) tests
  // depth first: a hidden fragment must not store its words over the visible one's.
  s += reads + more + "\n" + syn.fragmentInterface(interpolants(), outputs) + "\n" +
       (more.empty() ? "" : syn.earlyFragmentTests()) + syn.fragmentMain();
  return s;
}

/// Fills SubstrateGeometry `g` from the interpolants, evaluates the material
/// into `closures`, `coverage` and `transmittance` (both entry kinds).
std::string geometryAndEvaluate(const Material& m, const Syntax& syn) {
  auto in = [&](const char* n) { return syn.input(n); };
  std::string s = "  SubstrateGeometry g;\n";
  s += fmt::format("  g.N = normalize({});\n", in("normal"));
  s += fmt::format("  g.T = substrate_orthogonal_tangent(g.N, {}.xyz);\n", in("tangent"));
  s += fmt::format("  g.V = normalize(frame.cameraPosition.xyz - {});\n", in("worldPosition"));
  s += fmt::format("  g.position = {};\n", in("worldPosition"));
  s += fmt::format("  g.uv0 = {};\n  g.uv1 = {};\n", in("uv0"), in("uv1"));
  s += fmt::format("  g.vertexColor = {};\n", in("color"));
  s += fmt::format("  g.uvDerivatives = float4(ddx({0}), ddy({0}));\n", in("uv0"));
  s += "  // Interleaved gradient noise (Jimenez 2014): the per-pixel dither.\n";
  s += fmt::format("  g.dither = frac(52.9829189 * frac(dot({}.xy, float2(0.06711056, 0.00583715))));\n", syn.fragCoord());
  return s + evaluateCall(m);
}

/// The forward pass's lighting of the closures into `color`: one closure
/// inline, several in one loop (the lighting code exists once in the shader).
std::string forwardLighting(const Material& m, const StorageLayout& L) {
  const bool loop = L.closures.size() > 1;
  const std::string cl = loop ? "closures[k]" : "closures[0]";
  if (L.closures.empty())  // an unlit material: nothing to light
    return "  float3 color = SUBSTRATE_SPLAT3(0.0);\n" +
           std::string(unlitEmission(m) ? "  color += emission;  // the unlit nodes'\n" : "");
  // A closure whose weight is 0 at this pixel is skipped (dynamic culling);
  // a lone closure of static weight 1 needs no test.
  const bool test = loop || L.closures[0].storesWeight;
  std::string s = "  float3 L = frame.lightDirection.xyz;\n  float3 color = SUBSTRATE_SPLAT3(0.0);\n";
  if (loop) {
    s += fmt::format("  for (uint k = 0u; k < uint({}_CLOSURE_COUNT); ++k) {{\n", materialUpper(m));
    s += "    if (!substrate_closure_visible(closures[k])) continue;  // weight 0 here: nothing to light\n";
  } else {
    s += fmt::format("  // closure 0 ('{}')\n", m.slabs[L.closures[0].slab].id);
    if (test) s += "  if (substrate_closure_visible(closures[0])) {  // weight 0 here: nothing to light\n";
  }
  const std::string in = test ? "    " : "  ";
  s += lightClosureCode(cl, "g.V", in);
  if (anyEmissive(m, L))
    s += fmt::format("{0}color += substrate_closure_view_throughput({1}, dot({1}.N, g.V), g.V) * {1}.emissive;\n", in, cl);
  if (test) s += "  }\n";
  if (unlitEmission(m)) s += "  color += emission;  // the unlit nodes'\n";
  return s;
}

/// A single-layer water's body (substrate_water_seen), added by the forward
/// pass to its colour and by the base pass to its emissive target: what lies
/// behind the water is the host's texture at set 0, binding 6 (rgb: the scene's
/// colour behind the water; a: its distance from the eye in metres), read at
/// the pixel; the frame's light scatters in the water.
std::string waterResources(const Syntax& syn) {
  return "// set 0, binding 6: what lies behind the water (rgb colour, a distance from the eye, metres).\n" +
         syn.texture(0, 6, false, "substrate_water_behind");
}
std::string waterBody(const Syntax& syn) {
  return fmt::format(
      "  float3 water_seen = substrate_water_seen(closures[0], water, {}, length(frame.cameraPosition.xyz - g.position), "
      "g.V, frame.lightDirection.xyz, frame.lightRadiance.rgb);  // the water's body\n",
      syn.texelFetch("substrate_water_behind", syn.fragCoord() + ".xy"));
}

}  // namespace

std::string forwardFileName(const Material& m, const Syntax& syn) {
  return m.name + ".forward" + std::string(syn.fragmentExtension);
}
std::string basePassFileName(const Material& m, const Syntax& syn) {
  return m.name + ".basepass" + std::string(syn.fragmentExtension);
}

std::string volumeFileName(const Material& m, const Syntax& syn) {
  return m.name + ".volume" + std::string(syn.computeExtension);
}

std::string emitVolumeEntry(const Material& m, const StorageLayout& L, const Syntax& syn) {
  std::string s = fmt::format("// Generated by substratec: the froxel pass of volume '{}' ({} words a froxel).\n", m.name,
                              L.words());
  s += std::string(syn.header) + "#define SUBSTRATE_TEXTURE_LOD0 1  // no implicit derivatives in a compute shader\n";
  s += fmt::format("#include \"{}\"\n#include \"{}{}\"\n\n", syn.prelude, m.name, syn.materialExtension);
  s += syn.uniformBlock(0, 0, "SubstrateVolumeGrid", "grid",
                        "  float4 origin;    // xyz: world position of the grid's corner (metres)\n"
                        "  float4 cellSize;  // xyz: one froxel's extent (metres)\n"
                        "  uint4 counts;     // xyz: froxels along each axis\n");
  s += syn.storageBuffer(0, 1, Access::Write, "SubstrateFroxels", "uint", "froxels");
  s += "\n" + syn.computeMain(kVolumeLocalSize, 1);
  // One slice of the grid a row of groups (x: the froxels of slice y, x fastest): a dispatch of
  // ceil(n.x n.y / 64) x n.z groups, within Vulkan's 65,535 groups a dimension for 4M froxels a slice.
  s += fmt::format("  uint i = {0}.x;\n  uint z = {0}.y;\n", syn.computeId(ComputeId::Dispatch));
  s += "  uint3 n = grid.counts.xyz;\n";
  s += "  if (i >= n.x * n.y || z >= n.z) return;\n";
  s += "  uint3 cell = uint3(i % n.x, i / n.x, z);\n";
  s += "  float3 unit = (float3(cell) + SUBSTRATE_SPLAT3(0.5)) / float3(n);  // the froxel's centre in [0, 1]^3\n";
  s += "  SubstrateGeometry g;\n";
  s += "  g.position = grid.origin.xyz + (float3(cell) + SUBSTRATE_SPLAT3(0.5)) * grid.cellSize.xyz;\n";
  s += "  g.N = float3(0.0, 0.0, 1.0);\n  g.T = float3(1.0, 0.0, 0.0);\n  g.V = float3(0.0, 0.0, 1.0);\n";
  s += "  g.uv0 = unit.xy;\n  g.uv1 = float2(unit.z, 0.0);\n";
  s += "  g.vertexColor = SUBSTRATE_SPLAT4(1.0);\n  g.uvDerivatives = SUBSTRATE_SPLAT4(0.0);\n  g.dither = 0.5;\n";
  s += fmt::format("  uint words[{}_WORD_COUNT];\n  {}_pack({}_sample(g), words);\n", materialUpper(m), m.name, m.name);
  s += fmt::format("  for (uint w = 0u; w < {0}_WORD_COUNT; ++w) {{\n    froxels[(z * n.x * n.y + i) * uint({0}_WORD_COUNT) + w] = words[w];\n  }}\n",
                   materialUpper(m));
  s += "}\n";
  return s;
}

std::string emitForwardEntry(const Material& m, const StorageLayout& L, const Syntax& syn, Precision precision) {
  const bool dual = translucentBlend(m);
  std::string s = fmt::format("// Generated by substratec: the forward pass of '{}' ({} closure(s), lit inline, no packing).\n",
                              m.name, L.closures.size());
  std::vector<StageVar> outputs = {{0, "float4", "color"}};
  if (dual) outputs.push_back({0, "float4", "transmittance", "", "dual-source: the background multiplier", 1});
  s += includes(m, syn, true, precision) + "\n" +
       resourcesAndMain(syn, true, outputs, "", isWaterMaterial(m) ? waterResources(syn) : "");
  s += geometryAndEvaluate(m, syn);
  s += forwardLighting(m, L);
  if (isWaterMaterial(m)) s += waterBody(syn) + "  color += water_seen;\n";
  std::string color = "color";
  if (m.settings.blendMode == BlendMode::AlphaHoldout) color = "SUBSTRATE_SPLAT3(0.0)";
  if (m.settings.blendMode == BlendMode::Masked) s += "  if (coverage < 0.5) discard;\n";
  if (m.settings.blendMode == BlendMode::ColoredTransmittanceOnly) color = "SUBSTRATE_SPLAT3(0.0)";
  s += fmt::format("  {} = float4({}, coverage);\n", syn.output("color"), color);
  if (dual) s += fmt::format("  {} = float4({}, 1.0);\n", syn.output("transmittance"), backgroundThroughput(m));
  return s + syn.fragmentEnd();
}

std::string emitBasePassEntry(const Material& m, const StorageLayout& L, const Syntax& syn) {
  const std::string upper = materialUpper(m);
  const int words = L.words();
  const int rts = std::min(words, 3);
  const bool emissive = basePassEmissive(m, L) || isWaterMaterial(m);
  std::string s = fmt::format(
      "// Generated by substratec: the base pass of '{}' — {} packed words ({} to render targets, {} to the "
      "material buffer) and the top-layer word.\n",
      m.name, words, rts, words - rts);
  std::vector<StageVar> outputs;
  for (int k = 0; k < rts; ++k) outputs.push_back({k, "uint", fmt::format("word{}", k)});
  outputs.push_back({3, "uint", "topLayer"});
  if (emissive) outputs.push_back({4, "float4", "emissive"});
  const std::string buffer = words > 3 ? syn.storageImage(0, 4, Access::Write, ImageKind::UintArray, "materialBuffer") : "";
  s += includes(m, syn, false) + "\n" +
       resourcesAndMain(syn, false, outputs, buffer, isWaterMaterial(m) ? waterResources(syn) : "");
  s += geometryAndEvaluate(m, syn);
  s += fmt::format("  uint words[{}_WORD_COUNT];\n  uint topLayer;\n", upper);
  s += fmt::format("  {}_pack(closures, g.dither, words, topLayer);\n", m.name);
  for (int k = 0; k < rts; ++k) s += fmt::format("  {} = words[{}];\n", syn.output(fmt::format("word{}", k)), k);
  s += fmt::format("  {} = topLayer;\n", syn.output("topLayer"));
  for (int k = 3; k < words; ++k)
    s += fmt::format("  SUBSTRATE_IMAGE_STORE_LAYER(materialBuffer, uint2({}.xy), {}u, words[{}]);\n", syn.fragCoord(),
                     k - 3, k);
  if (emissive) {
    std::string sum = "SUBSTRATE_SPLAT3(0.0)";
    for (std::size_t c = 0; c < L.closures.size(); ++c)
      if (m.slabs[L.closures[c].slab].features & kFeatEmissive)
        sum += fmt::format(" + closures[{0}].weight * closures[{0}].emissive", c);  // the light-independent part
    if (unlitEmission(m)) sum += " + emission";  // the unlit nodes'
    if (isWaterMaterial(m)) {
      s += waterBody(syn);
      sum += " + water_seen";
    }
    s += fmt::format("  {} = float4({}, 1.0);\n", syn.output("emissive"), sum);
  }
  return s + syn.fragmentEnd();
}

}  // namespace substratec

namespace substratec {

namespace {

/// Header feature bits of a closure (SUBSTRATE_FEATURE_*, docs/storage.md).
unsigned featureBits(const ClosureLayout& c) {
  unsigned b = 0;
  if (c.storedFeatures & kFeatF90) b |= 1;
  if (c.storedFeatures & kFeatAnisotropy) b |= 2;
  if (c.storedFeatures & kFeatHaze) b |= 4;
  if (c.storedFeatures & kFeatFuzz) b |= 8;
  if (c.storedFeatures & kFeatGlint) b |= 16;
  if (c.storedFeatures & kFeatSpecularProfile) b |= 32;
  if (c.storesWeight) b |= 64;
  if (c.storesCoverageAbove) b |= 128;
  return b;
}

/// The code that quantizes a basis field `f` (its `field` is "normal" or
/// "tangent_angle"): from the first closure of its basis, the tangent from the
/// first with anisotropy.
std::string packedBasisFieldCode(const StorageLayout& L, const LayoutField& f, const std::string& field,
                                 const std::vector<int>& closureIndex) {
  const bool multi = L.closures.size() > 1;
  auto closure = [&](int i) { return fmt::format("closures[{}]", closureIndex[i]); };
  int first = 0;
  for (std::size_t i = 0; i < L.closures.size(); ++i)
    if (L.closures[i].basis == f.basis) {
      first = static_cast<int>(i);
      break;
    }
  const std::string n = closure(first) + ".N";
  if (field == "normal") return fmt::format("substrate_q_normal({}, dither)", n);
  // tangent_angle, in the frame of the normal as the unpacker decodes it
  bool elided = !multi || (f.basis == 0 && L.basis0NormalElided);
  std::string stored = elided ? "substrate_top_layer_normal_as_stored(topN, dither)"
                              : fmt::format("substrate_normal_as_stored({}, dither)", n);
  int aniso = first;
  for (std::size_t i = 0; i < L.closures.size(); ++i)
    if (L.closures[i].basis == f.basis && (L.closures[i].storedFeatures & kTangentFeatures)) {
      aniso = static_cast<int>(i);
      break;
    }
  return fmt::format("substrate_tangent_angle_encode({}.T, {}, dither)", closure(aniso), stored);
}

/// The statements that pack every field of `L`, at static bit offsets, from
/// `closures[closureIndex[i]]` for the layout's closure i. `topN` is the
/// top-layer normal already computed (for a tangent angle in its frame).
std::string packFields(const Material& m, const StorageLayout& L, const std::vector<int>& closureIndex,
                       const std::string& indent) {
  const bool multi = L.closures.size() > 1;
  std::string s;
  int offset = 0;
  auto put = [&](const std::string& code, int bits) {
    int w = offset / 32, sh = offset % 32;
    s += fmt::format("{}{{ uint q = {};\n{}  words[{}] |= q << {}u;", indent, code, indent, w, sh);
    if (sh + bits > 32) s += fmt::format("\n{}  words[{}] |= q >> {}u;", indent, w + 1, 32 - sh);
    s += " }\n";
    offset += bits;
  };
  // The SSS type tells the unpacker an SSS field follows: non-zero only when one is stored.
  auto sssCode = [&](const ClosureLayout& c) {
    return (c.storedFeatures & kFeatSss) ? static_cast<unsigned>(m.slabs[c.slab].sssType) : 0u;
  };
  auto closure = [&](int i) { return fmt::format("closures[{}]", closureIndex[i]); };
  const int cls = static_cast<int>(L.layoutClass);
  for (const LayoutField& f : L.fields) {
    const std::string c = f.closure >= 0 ? closure(f.closure) : "";
    const std::string field = f.name.substr(f.name.find('.') + 1);
    s += fmt::format("{}// {} ({} bits at {})\n", indent, f.name, f.bits, offset);
    if (f.name == "header" && L.closures.empty()) {
      put("substrate_material_header_unlit()", f.bits);  // no closure: an unlit material
    } else if (f.name == "header") {
      const ClosureLayout& c0 = L.closures[0];
      put(multi ? fmt::format("substrate_material_header_multi({}u, {}u, {}u)", cls, L.closures.size(), L.basisCount)
                : fmt::format("substrate_material_header_single({}u, {}u, {}u){}", cls, featureBits(c0), sssCode(c0),
                              (c0.storedFeatures & kFeatHair)  ? " | SUBSTRATE_HEADER_HAIR"
                              : (c0.storedFeatures & kFeatEye) ? " | SUBSTRATE_HEADER_EYE"
                                                               : ""),
          f.bits);
    } else if (field == "header") {
      const ClosureLayout& cl = L.closures[f.closure];
      put(fmt::format("substrate_closure_header({}u, {}, {}u, {}u, {}u)", cl.basis, cl.isTop ? "true" : "false",
                      featureBits(cl), sssCode(cl), cl.extraInterfaces),
          f.bits);
    } else if (field == "diffuse_albedo" || field == "f0" || field == "f90" || field == "top_transmittance") {
      const char* member = field == "diffuse_albedo" ? "diffuseAlbedo" : field == "f0" ? "f0"
                           : field == "f90"          ? "f90"
                                                     : "topTransmittance";
      put(fmt::format("substrate_q_color20({}.{}, dither)", c, member), f.bits);
    } else if (field == "roughness" || field == "weight" || field == "coverage_above") {
      const char* member = field == "roughness" ? "roughness" : field == "weight" ? "weight" : "coverageAbove";
      put(fmt::format("substrate_q_unorm({}.{}, 8u, dither)", c, member), f.bits);
    } else if (field == "sss") {
      put(fmt::format("substrate_q_sss({0}.sssMfp, {0}.sssPhaseAnisotropy, dither)", c), f.bits);
    } else if (field == "haze") {
      put(fmt::format("substrate_q_haze({0}.secondRoughness, {0}.secondRoughnessWeight, dither)", c), f.bits);
    } else if (field == "fuzz") {
      put(fmt::format("substrate_q_fuzz({0}.fuzzAmount, {0}.fuzzColor, {0}.fuzzRoughness, dither)", c), f.bits);
    } else if (field == "hair") {
      put(fmt::format("substrate_q_hair({}.hair, dither)", c), f.bits);
    } else if (field == "iris_normal") {
      put(fmt::format("substrate_q_normal({}.irisN, dither)", c), f.bits);
    } else if (field == "iris") {
      put(fmt::format("substrate_q_iris({0}.irisPlaneN, {0}.iris, dither)", c), f.bits);
    } else if (field == "anisotropy") {
      put(fmt::format("substrate_q_anisotropy({}.anisotropy, dither)", c), f.bits);
    } else if (field == "specular_profile") {
      put(fmt::format("substrate_q_specular_profile({}.specularProfile)", c), f.bits);
    } else if (field == "glint") {
      const int k = closureIndex[f.closure];
      s += fmt::format("{}uint4 glint{} = uint4(0u, 0u, 0u, 0u);\n", indent, k);
      put(fmt::format("substrate_q_glint({0}.glintValue, {0}.glintUv, {0}.glintUvDerivatives, dither, glint{1})", c, k), 8);
      for (const char* part : {"x", "y", "z", "w"}) put(fmt::format("glint{}.{}", k, part), 32);
    } else if (f.basis >= 0) {
      put(packedBasisFieldCode(L, f, field, closureIndex), f.bits);
    }
  }
  return s;
}

/// The run-time test that closure `k` is alone at this pixel with nothing it
/// stores in use (storage/layout.h, runtimeSimpleClosures).
std::string aloneAndPlain(const Material& m, const StorageLayout& L, int k) {
  std::vector<std::string> terms;
  const std::string c = fmt::format("closures[{}]", k);
  for (int j = 0; j < static_cast<int>(L.closures.size()); ++j)
    if (j != k) terms.push_back(fmt::format("!(closures[{}].weight > 0.0)", j));
  const ClosureLayout& cl = L.closures[k];
  if (cl.storesWeight) terms.push_back(c + ".weight >= 1.0");
  if (cl.storesCoverageAbove) terms.push_back(fmt::format("!({}.coverageAbove > 0.0)", c));
  const std::uint16_t f = cl.storedFeatures;
  if (f & kFeatF90) terms.push_back(fmt::format("min(min({0}.f90.x, {0}.f90.y), {0}.f90.z) >= 1.0", c));
  if (f & kFeatAnisotropy) terms.push_back(c + ".anisotropy == 0.0");
  if (f & kFeatSss) terms.push_back(fmt::format("!(substrate_max3({}.sssMfp) > 0.0)", c));
  if (f & kFeatHaze) terms.push_back(fmt::format("!({}.secondRoughnessWeight > 0.0)", c));
  if (f & kFeatFuzz) terms.push_back(fmt::format("!({}.fuzzAmount > 0.0)", c));
  if (f & kFeatGlint) terms.push_back(c + ".glintValue >= 1.0");
  (void)m;
  std::string s;
  for (const std::string& t : terms) s += (s.empty() ? "" : " && ") + t;
  return s.empty() ? "true" : s;
}

}  // namespace

std::string emitPackFunction(const Material& m, const StorageLayout& L, const Syntax&, bool dynamicSimplification) {
  const std::string upper = materialUpper(m);
  if (isVolumeMaterial(m))  // the froxel payload's layout is the runtime's, the same for every volume
    return fmt::format("// Packs a sample into the froxel payload of docs/storage.md (\"Volumetric fog cloud\").\n"
                       "void {0}_pack(SubstrateFogCloudSample s, out uint words[{1}_WORD_COUNT]) {{\n"
                       "  substrate_fog_cloud_pack(s, words);\n}}\n",
                       m.name, upper);
  std::string s;
  s += "// Packs the closures into the uint stream of docs/storage.md (static bit offsets, centred dither).\n";
  s += "// Compiled when substrate_pack.h is included before this file (the base pass does).\n";
  s += "#ifdef SUBSTRATE_PACK_H\n";
  s += fmt::format("void {0}_pack(SubstrateClosure closures[{2}], float dither, out uint words[{1}_WORD_COUNT], "
                   "out uint topLayer) {{\n",
                   m.name, upper, closureArraySize(m));
  for (int w = 0; w < L.words(); ++w) s += fmt::format("  words[{}] = 0u;\n", w);
  // Dynamic simplification: a pixel where one closure is left, with nothing
  // it stores in use, is stored in the SIMPLE layout (docs/scenes.md).
  for (int k : dynamicSimplification ? runtimeSimpleClosures(m, L) : std::vector<int>{}) {
    s += fmt::format("  // Dynamic simplification: closure {} ('{}') alone and plain at this pixel -> the SIMPLE layout.\n",
                     k, m.slabs[L.closures[k].slab].id);
    s += fmt::format("  if ({}) {{\n", aloneAndPlain(m, L, k));
    s += fmt::format("    topLayer = substrate_q_top_layer(closures[{0}].N, saturate(closures[{0}].roughness), dither);\n", k);
    s += packFields(m, simpleLayoutOf(L, k), {k}, "    ");
    s += "    return;\n  }\n";
  }
  // Top-layer word: the top closures' normal and roughness, coverage-weighted.
  std::string nsum;
  for (std::size_t i = 0; i < L.closures.size(); ++i) {
    if (!L.closures[i].isTop) continue;
    nsum += (nsum.empty() ? "" : " + ") + fmt::format("closures[{0}].weight * closures[{0}].N", i);
  }
  if (nsum.empty())  // no closure (an unlit material): the neutral slot's normal
    s += "  float3 topN = closures[0].N;\n";
  else
    s += fmt::format("  float3 topN = substrate_safe_normalize({}, closures[0].N);\n", nsum);
  s += fmt::format("  float topRoughness = {};\n", topRoughnessExpr(L, "closures"));
  s += "  topLayer = substrate_q_top_layer(topN, topRoughness, dither);\n";
  std::vector<int> identity(L.closures.size());
  for (std::size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<int>(i);
  s += packFields(m, L, identity, "  ");
  s += "}\n#endif\n";
  return s;
}

}  // namespace substratec
