#include "render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "batch/batch.h"
#include "emit/entry_emitter.h"
#include "emit/material_emitter.h"
#include "emit/scene_emitter.h"
#include "gpu/block_layout.h"
#include "gpu/gbuffer.h"
#include "gpu/sample_run.h"
#include "pipeline/generate.h"
#include "preview/render.h"
#include "render/camera.h"
#include "validate/runtime_files.h"

namespace substratec::render {

namespace {

// G-buffer pass attachments: words 0-2, the top-layer word, emissive.
constexpr int kTopLayerAttachment = 3;
constexpr int kEmissiveAttachment = 4;
const std::vector<gpu::AttachmentFormat> kGbufferFormats = {
    gpu::AttachmentFormat::R32Uint, gpu::AttachmentFormat::R32Uint, gpu::AttachmentFormat::R32Uint,
    gpu::AttachmentFormat::R32Uint, gpu::AttachmentFormat::Rgba32Float};
const std::vector<gpu::AttachmentFormat> kColorFormats = {gpu::AttachmentFormat::Rgba32Float};
const std::vector<uint32_t> kVertexComponents(mesh::kVertexComponents.begin(), mesh::kVertexComponents.end());

template <class T>
std::vector<std::byte> bytesOf(const T* data, std::size_t count) {
  std::vector<std::byte> b(count * sizeof(T));
  if (count) std::memcpy(b.data(), data, b.size());
  return b;
}

/// Runs `submit` and adds its host wall time to `*ns`.
template <class F>
bool timed(double* ns, F&& submit) {
  const auto start = std::chrono::steady_clock::now();
  const bool ok = submit();
  *ns += std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count();
  return ok;
}

/// How a material is drawn: into the G-buffer, or forward after the lighting
/// (a single-layer water over what was drawn before it).
enum class DrawKind { Deferred, Masked, Water, Translucent };
DrawKind drawKind(const Material& m) {
  if (isWaterMaterial(m)) return DrawKind::Water;
  if (translucentBlend(m)) return DrawKind::Translucent;
  if (m.settings.blendMode == BlendMode::Masked) return DrawKind::Masked;
  return DrawKind::Deferred;
}

/// Compiles `name` from `files` (memory) as `stage`; reports an internal compiler error on failure.
std::vector<uint32_t> compileShader(const std::string& name, const std::string& text, Target target, ShaderStage stage,
                                    Diagnostics& diags) {
  ShaderSource src;
  src.name = name;
  src.text = text;
  src.language = target == Target::Glsl ? ShaderLanguage::Glsl : ShaderLanguage::Hlsl;
  src.stage = stage;
  for (const RuntimeFile& f : runtimeFiles()) src.memoryFiles.emplace(std::string(f.name), f.text);
  ShaderValidation v = compileAndValidate(src);
  if (!v.ok) {
    diags.fail("internal compiler error: " + name + " does not validate\n" + numberLines(text) + "\n" + v.log);
    return {};
  }
  return std::move(v.spirv);
}

/// The runtime's vertex stage in `target`'s language.
std::vector<uint32_t> vertexStage(Target target, Diagnostics& diags) {
  const std::string file = target == Target::Glsl ? "substrate_vertex.vert" : "substrate_vertex.vs.hlsl";
  for (const RuntimeFile& f : runtimeFiles())
    if (f.name == file) return compileShader(file, std::string(f.text), target, ShaderStage::Vertex, diags);
  diags.fail("internal compiler error: the runtime has no " + file);
  return {};
}

/// glslang's HLSL front end cannot declare a dual-source output (DXC's
/// [[vk::location(0), vk::index(1)]]): the forward entry writes its
/// background throughput to SV_Target1 (emit/syntax.cc). Rewrites that output
/// to location 0, index 1, as DXC would have declared it. False if the
/// module has no output variable at location 1.
bool secondTargetToDualSource(std::vector<uint32_t>& spirv) {
  constexpr uint32_t kOpVariable = 59, kOpDecorate = 71, kLocation = 30, kIndex = 32, kOutput = 3;
  std::vector<uint32_t> outputs;
  for (std::size_t i = 5; i < spirv.size() && (spirv[i] >> 16) > 0; i += spirv[i] >> 16)
    if ((spirv[i] & 0xffffu) == kOpVariable && i + 3 < spirv.size() && spirv[i + 3] == kOutput)
      outputs.push_back(spirv[i + 2]);
  for (std::size_t i = 5; i < spirv.size() && (spirv[i] >> 16) > 0; i += spirv[i] >> 16) {
    if ((spirv[i] & 0xffffu) != kOpDecorate || (spirv[i] >> 16) != 4 || spirv[i + 2] != kLocation ||
        spirv[i + 3] != 1 || std::find(outputs.begin(), outputs.end(), spirv[i + 1]) == outputs.end())
      continue;
    const uint32_t id = spirv[i + 1];
    spirv[i + 3] = 0;
    const uint32_t index[4] = {(4u << 16) | kOpDecorate, id, kIndex, 1};
    spirv.insert(spirv.begin() + static_cast<std::ptrdiff_t>(i + 4), index, index + 4);
    return true;
  }
  return false;
}

/// A material's two fragment entries, compiled for the render.
struct MaterialShaders {
  std::vector<uint32_t> basePass, forward;
};
bool materialShaders(const CompileResult& r, const RenderOptions& o, DrawKind kind, MaterialShaders* out,
                     Diagnostics& diags) {
  GenerateOptions g;
  g.glsl = o.target == Target::Glsl;
  g.hlsl = !g.glsl;
  g.emit.diffuseModel = o.diffuseModel;
  const Generated files = generateFiles(r, g);
  const Syntax& syn = syntaxFor(o.target);
  auto compile = [&](const std::string& file, std::vector<uint32_t>* spirv) {
    ShaderValidation v = compileGeneratedEntry(files, file);
    if (!v.ok) return diags.fail("internal compiler error: " + file + " does not validate\n" + v.log), false;
    *spirv = std::move(v.spirv);
    return true;
  };
  const bool forward = o.forward || kind != DrawKind::Deferred;
  if (forward && !compile(forwardFileName(r.material, syn), &out->forward)) return false;
  if (!forward && !compile(basePassFileName(r.material, syn), &out->basePass)) return false;
  if (kind == DrawKind::Translucent && o.target == Target::Hlsl && !secondTargetToDualSource(out->forward))
    return diags.fail("internal compiler error: " + forwardFileName(r.material, syn) +
                      " has no background-throughput output at location 1"),
           false;
  return true;
}

/// The light, environment and camera every pass shares.
struct Lighting {
  preview::Light light;
  const preview::EnvironmentMaps* maps = nullptr;
  ViewSetup view;
  int width = 0, height = 0;
};

/// SubstrateFrame of the base and forward passes (4 float4, std140 / cbuffer).
gpu::BufferResource materialFrame(const Lighting& l) {
  const float f[16] = {static_cast<float>(l.view.eye[0]), static_cast<float>(l.view.eye[1]),
                       static_cast<float>(l.view.eye[2]), 0,
                       static_cast<float>(l.light.direction[0]), static_cast<float>(l.light.direction[1]),
                       static_cast<float>(l.light.direction[2]), 0,
                       static_cast<float>(l.light.radiance[0]), static_cast<float>(l.light.radiance[1]),
                       static_cast<float>(l.light.radiance[2]), 0,
                       static_cast<float>(l.maps->prefiltered.mipCount()), 0, 0, 0};
  return {bytesOf(f, 16), false, false};
}

/// SubstrateView of the vertex stage: the view-projection rows.
gpu::BufferResource viewBlock(const Lighting& l) {
  float f[16];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) f[r * 4 + c] = l.view.rows[r][c];
  return {bytesOf(f, 16), false, false};
}

/// The scene lighting's frame (gpu/gbuffer.h: SubstrateSceneFrame) for this view and light.
gpu::SceneFrame sceneFrame(const Lighting& l) {
  gpu::SceneFrame f;
  f.width = static_cast<uint32_t>(l.width);
  f.height = static_cast<uint32_t>(l.height);
  f.forward = l.view.forward;
  f.right = l.view.right;
  f.up = l.view.up;
  f.tanHalfFov = l.view.tanHalfFov;
  f.light = l.light.direction;
  f.radiance = l.light.radiance;
  f.envMips = l.maps->prefiltered.mipCount();
  return f;
}

gpu::BufferResource energyTables() {
  const auto lut = energyLutTables();
  return {bytesOf(lut.data(), lut.size()), false, false};
}

/// The resources of a material's draw (every binding its pipeline has but the
/// shared material buffer); `behind` is a water's set 0, binding 6.
gpu::Resources drawResources(const gpu::RasterPipeline& p, const std::vector<uint32_t>& fragment,
                             const SceneMaterial& m, const Lighting& l, const gpu::ImageResource* behind = nullptr) {
  const Material& mat = m.result->material;
  const std::vector<gpu::TextureRole> roles = gpu::textureRoles(mat);
  gpu::Resources res;
  for (const gpu::DescriptorBinding& b : p.reflection().bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    if (b.set == 2 && b.binding == 0) res[key] = viewBlock(l);
    else if (b.set == 0 && b.binding == 0) res[key] = materialFrame(l);
    else if (b.set == 0 && b.binding == 1) res[key] = preview::cubeResource(l.maps->prefiltered);
    else if (b.set == 0 && b.binding == 2) res[key] = preview::cubeResource(l.maps->irradiance);
    else if (b.set == 0 && b.binding == 3)
      res[key] = gpu::SamplerResource{gpu::Filter::Linear, gpu::Address::ClampToEdge, std::nullopt};
    else if (b.set == 0 && b.binding == 5) res[key] = energyTables();
    else if (b.set == 0 && b.binding == 6 && behind) res[key] = *behind;
    else if (b.set == 1 && b.binding == 0)
      res[key] = gpu::BufferResource{gpu::inputBlockBytes(mat, gpu::blockMembers(fragment, 1, 0), {}), false, false};
    else if (b.set == 1) res[key] = preview::materialTexture(mat, roles, m.textures, b);
  }
  return res;
}

/// The pipelines of a render, made once per material and kind.
struct Pipelines {
  std::vector<uint32_t> vertex;
  std::unique_ptr<gpu::RasterPipeline> depthOnly;
  std::map<std::pair<int, int>, std::unique_ptr<gpu::RasterPipeline>> byMaterial;  // (material, pass kind)
};
enum PassKind { kBasePass = 0, kForwardOpaque = 1, kForwardTranslucent = 2 };

gpu::RasterPipeline* pipelineFor(gpu::Context& ctx, Pipelines& ps, int material, PassKind kind,
                                 const SceneMaterial& m, const MaterialShaders& shaders, Diagnostics& diags) {
  auto& slot = ps.byMaterial[{material, kind}];
  if (slot) return slot.get();
  gpu::RasterState s;
  s.vertexComponents = kVertexComponents;
  if (kind == kBasePass) {
    const int words = m.result->after.words();
    s.colors = kGbufferFormats;
    s.depthTest = gpu::DepthTest::Equal;  // the pre-pass wrote the nearest depth: only the visible fragment runs
    s.depthWrite = false;
    s.colorWriteMask = (1u << std::min(words, 3)) - 1u;
    s.colorWriteMask |= 1u << kTopLayerAttachment;
    if (basePassEmissive(m.result->material, m.result->after)) s.colorWriteMask |= 1u << kEmissiveAttachment;
  } else {
    s.colors = kColorFormats;
    s.depthTest = gpu::DepthTest::Less;
    s.depthWrite = kind == kForwardOpaque;
    if (kind == kForwardTranslucent) s.blend = gpu::Blend::DualSource;
  }
  slot = ctx.createRasterPipeline(ps.vertex, kind == kBasePass ? shaders.basePass : shaders.forward, s, diags);
  return slot.get();
}

/// Everything drawn: per primitive its geometry and material, per material its shaders.
struct DrawList {
  std::vector<gpu::Geometry> geometry;  // per primitive
  std::vector<DrawKind> kinds;          // per material
  std::vector<MaterialShaders> shaders;  // per material
};

}  // namespace

std::array<double, 3> renderCalibrationGains(const std::string& environment,
                                             const std::array<double, 3>& towardCamera) {
  return preview::calibrationGains(environment, 1, towardCamera);  // the key light alone
}

namespace {

/// The state one render carries between its passes.
struct Frame {
  gpu::Context& ctx;
  const mesh::Scene& scene;
  const std::vector<SceneMaterial>& materials;
  const std::vector<int>& primitiveMaterial;
  const RenderOptions& o;
  Lighting lighting;
  DrawList list;
  Pipelines pipelines;
  std::vector<float> color;  // RGBA32F, the opaque result, then composited
  std::vector<float> depth;
  std::optional<gpu::ImageResource> waterBehind;  // while the waters are drawn
  RenderStats stats;

  bool prepare(Diagnostics& diags);
  bool gbufferPass(std::vector<gpu::ColorAttachment>* gbuffer, std::vector<std::byte>* materialBuffer,
                   int slices, Diagnostics& diags);
  bool lightTiles(const std::vector<gpu::ColorAttachment>& gbuffer, const std::vector<std::byte>& materialBuffer,
                  int slices, Diagnostics& diags);
  bool deferred(Diagnostics& diags);
  bool forwardOpaque(Diagnostics& diags);
  void composite(const std::vector<gpu::ColorAttachment>* gbuffer);
  bool forwardAfter(Diagnostics& diags);
  bool drawOver(const std::vector<int>& opaque, std::vector<int> translucent, Diagnostics& diags);
  gpu::ImageResource behindTheWater() const;
  std::vector<int> primitivesOf(std::initializer_list<DrawKind> kinds) const;
};

bool Frame::prepare(Diagnostics& diags) {
  pipelines.vertex = vertexStage(o.target, diags);
  if (pipelines.vertex.empty()) return false;
  for (const SceneMaterial& m : materials) {
    list.kinds.push_back(drawKind(m.result->material));
    list.shaders.emplace_back();
  }
  std::vector<bool> used(materials.size(), false);
  for (int mi : primitiveMaterial) used[mi] = true;
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (used[i] && !materialShaders(*materials[i].result, o, list.kinds[i], &list.shaders[i], diags)) return false;
  for (const mesh::Primitive& p : scene.primitives) list.geometry.push_back({p.vertices, p.indices});
  return true;
}

std::vector<int> Frame::primitivesOf(std::initializer_list<DrawKind> kinds) const {
  std::vector<int> out;
  for (std::size_t i = 0; i < scene.primitives.size(); ++i)
    if (std::find(kinds.begin(), kinds.end(), list.kinds[primitiveMaterial[i]]) != kinds.end())
      out.push_back(static_cast<int>(i));
  return out;
}

bool Frame::gbufferPass(std::vector<gpu::ColorAttachment>* gbuffer, std::vector<std::byte>* materialBuffer, int slices,
                        Diagnostics& diags) {
  gpu::RasterState depthState;
  depthState.vertexComponents = kVertexComponents;
  depthState.colors = kGbufferFormats;
  depthState.colorWriteMask = 0;
  pipelines.depthOnly = ctx.createRasterPipeline(pipelines.vertex, {}, depthState, diags);
  if (!pipelines.depthOnly) return false;
  gpu::RasterPass pass;
  pass.width = static_cast<uint32_t>(lighting.width);
  pass.height = static_cast<uint32_t>(lighting.height);
  for (gpu::AttachmentFormat f : kGbufferFormats) pass.colors.push_back({f, {0, 0, 0, 0}, {}, {}});
  if (slices > 0)
    pass.shared[{0, 4}] = gpu::StorageImageResource{pass.width, pass.height, static_cast<uint32_t>(slices),
                                                    gpu::StorageFormat::R32Uint, {}, false};
  const std::vector<int> opaque = primitivesOf({DrawKind::Deferred});
  std::vector<gpu::Draw> draws;
  for (int p : opaque) {
    gpu::Draw d{pipelines.depthOnly.get(), &list.geometry[p], {}};
    d.resources[{2, 0}] = viewBlock(lighting);
    draws.push_back(std::move(d));
  }
  for (int p : opaque) {
    const int mi = primitiveMaterial[p];
    gpu::RasterPipeline* pipe =
        pipelineFor(ctx, pipelines, mi, kBasePass, materials[mi], list.shaders[mi], diags);
    if (!pipe) return false;
    gpu::Resources res = drawResources(*pipe, list.shaders[mi].basePass, materials[mi], lighting);
    draws.push_back({pipe, &list.geometry[p], std::move(res)});
  }
  stats.draws += static_cast<int>(opaque.size());
  if (!timed(&stats.opaqueWallNs, [&] { return ctx.render(pass, draws, diags, &stats.opaqueNs); })) return false;
  *gbuffer = std::move(pass.colors);
  depth = std::move(pass.depth);
  if (slices > 0) *materialBuffer = std::move(std::get<gpu::StorageImageResource>(pass.shared.at({0, 4})).data);
  return true;
}

/// The resources of one class's lighting dispatch, by its reflection.
gpu::Resources lightingResources(const gpu::ComputePipeline& p, const Lighting& l,
                                 const gpu::StorageImageResource& gbufferImage,
                                 const gpu::StorageImageResource* materialImage, const gpu::TileLists& lists) {
  gpu::Resources res;
  for (const gpu::DescriptorBinding& b : p.reflection().bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    switch (b.binding) {
      case 0: res[key] = gpu::sceneFrameBlock(sceneFrame(l)); break;
      case 1: res[key] = preview::cubeResource(l.maps->prefiltered); break;
      case 2: res[key] = preview::cubeResource(l.maps->irradiance); break;
      case 3: res[key] = gpu::SamplerResource{gpu::Filter::Linear, gpu::Address::ClampToEdge, std::nullopt}; break;
      case 4: if (materialImage) res[key] = *materialImage; break;
      case 5: res[key] = energyTables(); break;
      case 6: res[key] = gbufferImage; break;
      case 7: res[key] = gpu::BufferResource{bytesOf(lists.raw.data(), lists.raw.size()), false, false}; break;
      case 8:
        res[key] = gpu::StorageImageResource{static_cast<uint32_t>(l.width), static_cast<uint32_t>(l.height), 1,
                                             gpu::StorageFormat::R32G32B32A32Sfloat, {}, false};
        break;
      default: break;  // anything else stays unbound: the harness names it
    }
  }
  return res;
}

bool Frame::lightTiles(const std::vector<gpu::ColorAttachment>& gbuffer, const std::vector<std::byte>& materialBuffer,
                       int slices, Diagnostics& diags) {
  std::vector<SceneMaterialShape> shapes;
  std::vector<bool> drawn(materials.size(), false);
  for (int p : primitivesOf({DrawKind::Deferred})) drawn[primitiveMaterial[p]] = true;
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (drawn[i]) shapes.push_back(summarize(*materials[i].result).shape());
  const SceneShape shape = sceneShape("render", shapes, o.diffuseModel);
  const Syntax& syn = syntaxFor(o.target);
  const uint32_t W = static_cast<uint32_t>(lighting.width), H = static_cast<uint32_t>(lighting.height);
  gpu::StorageImageResource gbufferImage{W, H, 4, gpu::StorageFormat::R32Uint, {}, true};
  for (int k = 0; k < 4; ++k) gbufferImage.data.insert(gbufferImage.data.end(), gbuffer[k].data.begin(), gbuffer[k].data.end());
  std::optional<gpu::StorageImageResource> materialImage;
  if (slices > 0)
    materialImage = gpu::StorageImageResource{W, H, static_cast<uint32_t>(slices), gpu::StorageFormat::R32Uint,
                                              materialBuffer, true};
  auto computePipeline = [&](const std::string& name, const std::string& text) {
    const std::vector<uint32_t> spirv = compileShader(name, text, o.target, ShaderStage::Compute, diags);
    return spirv.empty() ? nullptr : ctx.createPipeline(spirv, diags);
  };
  auto classifier = computePipeline(tileClassificationFileName(shape, syn), emitTileClassification(shape, syn));
  const gpu::SceneFrame frame = sceneFrame(lighting);
  gpu::TileLists tiles;
  if (!classifier || !timed(&stats.classifyWallNs, [&] {
        return gpu::classifyTiles(ctx, *classifier, frame, gbufferImage, &tiles, diags, &stats.classifyNs);
      }))
    return false;
  color.assign(std::size_t{W} * H * 4, 0.0f);
  for (const SceneLightingClass& k : shape.classes) {
    const auto& list = tiles.tiles[static_cast<int>(k.cls)];  // tile ids: ty * tilesX + tx
    stats.tiles[static_cast<int>(k.cls)] = list.size();
    if (list.empty()) continue;
    auto light = computePipeline(sceneLightingFileName(shape, k.cls, syn), emitSceneLighting(shape, k, syn));
    if (!light) return false;
    gpu::Resources res =
        lightingResources(*light, lighting, gbufferImage, materialImage ? &*materialImage : nullptr, tiles);
    double ns = 0;
    if (!timed(&stats.lightingWallNs,
               [&] { return ctx.dispatch(*light, res, static_cast<uint32_t>(list.size()), 1, 1, diags, &ns); }))
      return false;
    stats.lightingNs += ns;
    const auto& lit = std::get<gpu::StorageImageResource>(res.at({0, 8})).data;
    for (uint32_t tile : list) {  // copy this class's tiles out of its target
      const uint32_t x0 = (tile % frame.tilesX()) * kSceneTileSize, y0 = (tile / frame.tilesX()) * kSceneTileSize;
      for (uint32_t y = y0; y < std::min(H, y0 + kSceneTileSize); ++y)
        for (uint32_t x = x0; x < std::min(W, x0 + kSceneTileSize); ++x)
          std::memcpy(&color[(std::size_t{y} * W + x) * 4], lit.data() + (std::size_t{y} * W + x) * 16, 16);
    }
  }
  return true;
}

bool Frame::deferred(Diagnostics& diags) {
  if (primitivesOf({DrawKind::Deferred}).empty()) {  // nothing for the G-buffer: the sky, then forward draws
    color.assign(static_cast<std::size_t>(lighting.width) * lighting.height * 4, 0.0f);
    depth.assign(static_cast<std::size_t>(lighting.width) * lighting.height, 1.0f);
    composite(nullptr);
    return true;
  }
  int slices = 0;
  std::vector<bool> drawn(materials.size(), false);
  for (int p : primitivesOf({DrawKind::Deferred})) drawn[primitiveMaterial[p]] = true;
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (drawn[i]) slices = std::max(slices, materials[i].result->after.words() - 3);
  std::vector<gpu::ColorAttachment> gbuffer;
  std::vector<std::byte> materialBuffer;
  if (!gbufferPass(&gbuffer, &materialBuffer, slices, diags)) return false;
  if (!lightTiles(gbuffer, materialBuffer, slices, diags)) return false;
  composite(&gbuffer);
  return true;
}

bool Frame::forwardOpaque(Diagnostics& diags) {
  gpu::RasterPass pass;
  pass.width = static_cast<uint32_t>(lighting.width);
  pass.height = static_cast<uint32_t>(lighting.height);
  pass.colors.push_back({gpu::AttachmentFormat::Rgba32Float, {0, 0, 0, 0}, {}, {}});
  std::vector<gpu::Draw> draws;
  for (int p : primitivesOf({DrawKind::Deferred, DrawKind::Masked})) {
    const int mi = primitiveMaterial[p];
    gpu::RasterPipeline* pipe = pipelineFor(ctx, pipelines, mi, kForwardOpaque, materials[mi], list.shaders[mi], diags);
    if (!pipe) return false;
    draws.push_back({pipe, &list.geometry[p], drawResources(*pipe, list.shaders[mi].forward, materials[mi], lighting)});
  }
  stats.draws += static_cast<int>(draws.size());
  if (!draws.empty() &&
      !timed(&stats.opaqueWallNs, [&] { return ctx.render(pass, draws, diags, &stats.opaqueNs); }))
    return false;
  const std::size_t texels = std::size_t{pass.width} * pass.height;
  color.assign(texels * 4, 0.0f);
  depth.assign(texels, 1.0f);
  if (!draws.empty()) {
    std::memcpy(color.data(), pass.colors[0].data.data(), color.size() * sizeof(float));
    depth = std::move(pass.depth);
  }
  composite(nullptr);
  return true;
}

void Frame::composite(const std::vector<gpu::ColorAttachment>* gbuffer) {
  const preview::Environment env = preview::makeEnvironment(o.environment);
  const float* emissive =
      gbuffer ? reinterpret_cast<const float*>((*gbuffer)[kEmissiveAttachment].data.data()) : nullptr;
  for (int y = 0; y < lighting.height; ++y)
    for (int x = 0; x < lighting.width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * lighting.width + x;
      float* c = &color[i * 4];
      if (depth[i] < 1.0f) {
        for (int ch = 0; ch < 3 && emissive; ++ch) c[ch] += emissive[i * 4 + ch];
        ++stats.coveredPixels;
      } else {
        const auto sky = env.radiance(lighting.view.ray(x, y, lighting.width, lighting.height));
        for (int ch = 0; ch < 3; ++ch) c[ch] = static_cast<float>(sky[ch]);
      }
      c[3] = 1.0f;
    }
}

/// Draws over the frame so far: masked (and water) primitives first, opaque,
/// then `translucent` back to front, blended.
bool Frame::drawOver(const std::vector<int>& opaque, std::vector<int> translucent, Diagnostics& diags) {
  if (opaque.empty() && translucent.empty()) return true;
  auto distance = [&](int p) {  // of the primitive's bounds centre from the eye
    double d = 0;
    for (int c = 0; c < 3; ++c) {
      const double m = 0.5 * (scene.primitives[p].boundsMin[c] + scene.primitives[p].boundsMax[c]) - lighting.view.eye[c];
      d += m * m;
    }
    return d;
  };
  std::stable_sort(translucent.begin(), translucent.end(), [&](int a, int b) { return distance(a) > distance(b); });
  gpu::RasterPass pass;
  pass.width = static_cast<uint32_t>(lighting.width);
  pass.height = static_cast<uint32_t>(lighting.height);
  pass.colors.push_back({gpu::AttachmentFormat::Rgba32Float, {}, bytesOf(color.data(), color.size()), {}});
  pass.depthInitial = depth;
  std::vector<gpu::Draw> draws;
  translucent.insert(translucent.begin(), opaque.begin(), opaque.end());  // opaque first, then back to front
  for (std::size_t i = 0; i < translucent.size(); ++i) {
    const int p = translucent[i], mi = primitiveMaterial[p];
    const PassKind kind = i < opaque.size() ? kForwardOpaque : kForwardTranslucent;
    gpu::RasterPipeline* pipe = pipelineFor(ctx, pipelines, mi, kind, materials[mi], list.shaders[mi], diags);
    if (!pipe) return false;
    const gpu::ImageResource* behind = list.kinds[mi] == DrawKind::Water && waterBehind ? &*waterBehind : nullptr;
    draws.push_back(
        {pipe, &list.geometry[p], drawResources(*pipe, list.shaders[mi].forward, materials[mi], lighting, behind)});
  }
  stats.draws += static_cast<int>(draws.size());
  if (!timed(&stats.forwardWallNs, [&] { return ctx.render(pass, draws, diags, &stats.forwardNs); })) return false;
  std::memcpy(color.data(), pass.colors[0].data.data(), color.size() * sizeof(float));
  depth = std::move(pass.depth);
  for (std::size_t i = 3; i < color.size(); i += 4) color[i] = 1.0f;
  return true;
}

/// What lies behind the water (set 0, binding 6; docs/codegen.md, "Single-layer
/// water"): the frame drawn so far, rgb its colour and a its distance from the
/// eye along the pixel's ray (from the depth buffer; kSkyDistance where nothing
/// was drawn).
gpu::ImageResource Frame::behindTheWater() const {
  const int W = lighting.width, H = lighting.height;
  gpu::ImageResource image;
  image.width = static_cast<uint32_t>(W);
  image.height = static_cast<uint32_t>(H);
  image.mips.emplace_back(color);
  std::vector<float>& texels = image.mips[0];
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      texels[i * 4 + 3] = static_cast<float>(lighting.view.distance(x, y, W, H, depth[i]));
    }
  return image;
}

/// After the opaque frame: masked primitives (the deferred path's base pass
/// keeps no coverage), then the single-layer waters over everything opaque
/// (they read it: UE's scene colour and depth without the water), then the
/// translucent ones back to front. Without a water, one pass.
bool Frame::forwardAfter(Diagnostics& diags) {
  std::vector<int> masked = o.forward ? std::vector<int>{} : primitivesOf({DrawKind::Masked});
  const std::vector<int> water = primitivesOf({DrawKind::Water});
  if (!water.empty()) {
    if (!drawOver(masked, {}, diags)) return false;
    masked.clear();
    waterBehind = behindTheWater();
    const bool drawn = drawOver(water, {}, diags);
    waterBehind.reset();
    if (!drawn) return false;
  }
  return drawOver(masked, primitivesOf({DrawKind::Translucent}), diags);
}

}  // namespace

bool renderScene(gpu::Context& ctx, const mesh::Scene& scene, const std::vector<SceneMaterial>& materials,
                 const std::vector<int>& primitiveMaterial, const mesh::Camera& camera, const RenderOptions& o,
                 RenderResult* out, Diagnostics& diags) {
  if (primitiveMaterial.size() != scene.primitives.size())
    return diags.fail("render: one material index per primitive is needed"), false;
  for (int mi : primitiveMaterial)
    if (mi < 0 || static_cast<std::size_t>(mi) >= materials.size() || !materials[mi].result)
      return diags.fail("render: a primitive's material index is out of range"), false;
  if (o.width < 1 || o.height < 1) return diags.fail("render: the image needs a size"), false;
  Frame f{ctx, scene, materials, primitiveMaterial, o, {}, {}, {}, {}, {}, {}, {}};
  f.lighting.light = preview::previewLight(o.environment, 0);
  f.lighting.maps = &preview::environmentMaps(o.environment);
  f.lighting.view = viewSetup(camera, o.width, o.height, scene.boundsMin, scene.boundsMax);
  f.lighting.width = o.width;
  f.lighting.height = o.height;
  if (!f.prepare(diags)) return false;
  if (!(o.forward ? f.forwardOpaque(diags) : f.deferred(diags))) return false;
  if (!f.forwardAfter(diags)) return false;
  out->hdr = preview::Image(o.width, o.height);
  out->hdr.rgba = std::move(f.color);
  out->depth = std::move(f.depth);
  out->stats = f.stats;
  return true;
}

}  // namespace substratec::render
