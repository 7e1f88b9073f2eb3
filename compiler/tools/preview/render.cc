#include "preview/render.h"

#include <cmath>
#include <cstring>
#include <map>
#include <mutex>

#include <fmt/format.h>

#include "pipeline/generate.h"
#include "emit/kernel_emitter.h"
#include "gpu/block_layout.h"
#include "gpu/sample_run.h"
#include "preview/cubemap.h"
#include "preview/environment.h"
#include "validate/runtime_files.h"

namespace substratec::preview {

namespace {

using namespace kernel;

template <class T>
std::vector<std::byte> bytesOf(const std::vector<T>& v) {
  std::vector<std::byte> b(v.size() * sizeof(T));
  std::memcpy(b.data(), v.data(), b.size());
  return b;
}

std::array<double, 3> unit(std::array<double, 3> v) {
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / l, v[1] / l, v[2] / l};
}
/// The preview's light, render's: a warm key from the upper left (the unit
/// direction toward the light, +Y up, the camera on +Z). The preview had a
/// cool fill from the right and a rim from behind too, until it was made to
/// light as `render` does (issue 20, part 4).
const Light kLights[kPreviewLights] = {
    {unit({-0.6, 0.7, 0.6}), {2.6, 2.4, 2.1}},
};

}  // namespace

const EnvironmentMaps& environmentMaps(const std::string& name) {
  static std::mutex mutex;
  static std::map<std::string, EnvironmentMaps> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = cache.find(name);
  if (it == cache.end()) {
    const Environment env = makeEnvironment(name);
    it = cache.emplace(name, EnvironmentMaps{prefilterRadiance(env), irradianceMap(env)}).first;
  }
  return it->second;
}

gpu::ImageResource cubeResource(const CubeMap& map) {
  gpu::ImageResource img;
  img.width = img.height = static_cast<uint32_t>(map.size);
  img.layers = 6;
  img.mips = map.mips;
  img.filter = gpu::Filter::Linear;
  img.address = gpu::Address::ClampToEdge;
  return img;
}

Light previewLight(const std::string& environment, int l) {
  Light light = kLights[l];
  // The furnace has no lights; an image environment is the whole lighting.
  if (environment == "white" || isEnvironmentFile(environment)) light.radiance = {0, 0, 0};
  return light;
}

gpu::Resource materialTexture(const Material& m, const std::vector<gpu::TextureRole>& roles,
                              const BoundTextures* textures, const gpu::DescriptorBinding& b) {
  const bool profile = b.binding >= kPreviewProfileBinding;
  const int input = profile ? -1 : gpu::inputOfResource(m, b.name);
  if (b.kind == gpu::DescriptorKind::Sampler) {  // HLSL's: the input's wrap and filter
    if (input < 0) return gpu::SamplerResource{gpu::Filter::Linear, gpu::Address::ClampToEdge, std::nullopt};
    const Input& in = m.inputs[input];
    return gpu::SamplerResource{in.nearest ? gpu::Filter::Nearest : gpu::Filter::Linear, addressOf(in.wrapU),
                                addressOf(in.wrapV)};
  }
  const std::string name = profile ? (b.name.rfind("p_", 0) == 0 ? b.name.substr(2) : b.name)
                                   : (input >= 0 ? m.inputs[input].name : "");
  const gpu::ImageResource* image = nullptr;
  if (textures)
    if (auto it = textures->images.find(name); it != textures->images.end()) image = &it->second;
  if (profile) {
    gpu::ImageResource lut = image ? *image : defaultSpecularProfile();
    lut.address = gpu::Address::ClampToEdge;
    return lut;
  }
  return image ? *image : solidTexture(gpu::neutralTexel(input >= 0 ? roles[input] : gpu::TextureRole::Colour));
}

std::array<double, 3> calibrationGains(const std::string& environment, int lights,
                                       const std::array<double, 3>& toCamera) {
  std::array<double, 3> e = sampleCube(environmentMaps(environment).irradiance, toCamera, 0.0);
  for (int l = 0; l < std::min(lights, kPreviewLights); ++l) {
    const Light light = previewLight(environment, l);
    const double cosine = std::max(0.0, light.direction[0] * toCamera[0] + light.direction[1] * toCamera[1] +
                                            light.direction[2] * toCamera[2]);
    for (int c = 0; c < 3; ++c) e[c] += cosine * light.radiance[c];
  }
  return {M_PI / std::max(e[0], 1e-9), M_PI / std::max(e[1], 1e-9), M_PI / std::max(e[2], 1e-9)};
}

gpu::ComputePipeline* PipelineCache::get(gpu::Context& gpu, const std::vector<uint32_t>& spirv, Diagnostics& diags) {
  auto it = pipelines_.find(spirv);
  if (it != pipelines_.end()) return it->second.get();
  auto pipeline = gpu.createPipeline(spirv, diags);
  if (!pipeline) return nullptr;
  return pipelines_.emplace(spirv, std::move(pipeline)).first->second.get();
}

bool renderSphere(gpu::Context& ctx, const CompileResult& r, const RenderOptions& o, Image* out, Diagnostics& diags) {
  EmitOptions emit;
  emit.diffuseModel = o.diffuseModel;
  emit.precision = o.precision;
  if (!gpu::canRun(ctx, o.precision, diags)) return false;
  ShaderValidation v = compileKernel(r, o.target, KernelMode::Preview, emit);
  if (!v.ok) {
    diags.fail("internal compiler error: the preview kernel does not validate\n" + v.log);
    return false;
  }
  std::unique_ptr<gpu::ComputePipeline> own;
  gpu::ComputePipeline* pipeline = nullptr;
  if (o.pipelines) {
    pipeline = o.pipelines->get(ctx, v.spirv, diags);
  } else {
    own = ctx.createPipeline(v.spirv, diags);
    pipeline = own.get();
  }
  if (!pipeline) return false;
  const EnvironmentMaps& maps = environmentMaps(o.environment);

  // Preview parameters (kernel_emitter.h): camera, viewport, lights.
  std::vector<float> params(kPreviewParamVec4s * 4, 0.0f);
  const double tanHalfFov = std::tan(0.5 * 30.0 * M_PI / 180.0);
  const float camera[4] = {0.0f, 0.0f, 4.2f, static_cast<float>(tanHalfFov)};
  const float viewport[4] = {static_cast<float>(o.size), static_cast<float>(o.size),
                             static_cast<float>(maps.prefiltered.mipCount()), static_cast<float>(o.exposure)};
  std::memcpy(&params[0], camera, sizeof camera);
  std::memcpy(&params[4], viewport, sizeof viewport);
  for (int l = 0; l < kPreviewLights; ++l)
    for (int c = 0; c < 3; ++c) {
      const Light light = previewLight(o.environment, l);
      params[(2 + l) * 4 + c] = static_cast<float>(light.direction[c]);
      params[(2 + kPreviewLights + l) * 4 + c] = static_cast<float>(light.radiance[c]);
    }

  const std::vector<gpu::TextureRole> roles = gpu::textureRoles(r.material);  // for unbound textures
  gpu::Resources res;
  for (const gpu::DescriptorBinding& b : pipeline->reflection().bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    if (b.set == 0 && b.binding == 0) {
      res[key] = gpu::BufferResource{bytesOf(params), false};
    } else if (b.set == 0 && b.binding == 1) {
      res[key] = cubeResource(maps.prefiltered);
    } else if (b.set == 0 && b.binding == 2) {
      res[key] = cubeResource(maps.irradiance);
    } else if (b.set == 0 && b.binding == 3) {
      res[key] = gpu::SamplerResource{gpu::Filter::Linear, gpu::Address::ClampToEdge, std::nullopt};
    } else if (b.set == 0 && b.binding == 5) {
      auto lut = energyLutTables();
      res[key] = gpu::BufferResource{bytesOf(std::vector<float>(lut.begin(), lut.end())), false};
    } else if (b.set == 0 && b.binding == 7) {
      gpu::BufferResource buf;
      buf.data.resize(static_cast<std::size_t>(o.size) * o.size * 4 * sizeof(float));
      buf.output = true;
      res[key] = buf;
    } else if (b.set == 1 && b.binding == 0) {
      res[key] = gpu::BufferResource{gpu::inputBlockBytes(r.material, gpu::blockMembers(v.spirv, 1, 0), {}), false};
    } else if (b.set == 1) {
      res[key] = materialTexture(r.material, roles, o.textures, b);
    }
  }
  const uint32_t groups = static_cast<uint32_t>((o.size + 7) / 8);
  if (!ctx.dispatch(*pipeline, res, groups, groups, 1, diags)) return false;
  const auto& buf = std::get<gpu::BufferResource>(res.at({0, 7}));
  *out = Image(o.size, o.size);
  std::memcpy(out->rgba.data(), buf.data.data(), out->rgba.size() * sizeof(float));
  return true;
}

}  // namespace substratec::preview
