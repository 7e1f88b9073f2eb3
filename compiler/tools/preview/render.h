// `substratec preview`: a compiled material on a unit sphere, rendered on
// lavapipe by the generated preview kernel (emit/kernel_emitter.h) under three
// lights and a procedural split-sum environment (preview/environment.h,
// preview/cubemap.h), tone-mapped and written as an 8-bit sRGB PNG; and the
// contact sheet of a material at each step of its simplification.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "emit/material_emitter.h"
#include "emit/syntax.h"
#include "gpu/harness.h"
#include "gpu/sample_run.h"
#include "pipeline/pipeline.h"
#include "preview/cubemap.h"
#include "preview/image.h"
#include "preview/textures.h"

namespace substratec::preview {

/// Preview pipelines by their SPIR-V, so that rendering many materials in one
/// context builds each distinct kernel once (materials that differ only in
/// their inputs' values, compiled under one name, share a kernel).
class PipelineCache {
 public:
  /// The pipeline of `spirv`, built on first use. Null, with errors reported, on failure.
  gpu::ComputePipeline* get(gpu::Context& gpu, const std::vector<uint32_t>& spirv, Diagnostics& diags);

 private:
  std::map<std::vector<uint32_t>, std::unique_ptr<gpu::ComputePipeline>> pipelines_;
};

/// A light of the preview (and of `render`): a unit direction toward it and its radiance.
struct Light {
  std::array<double, 3> direction, radiance;
};

/// The lights of `environment`, l < kPreviewLights (emit/kernel_emitter.h):
/// one, a warm key from the upper left, which `render` lights with too; under
/// "white", a furnace, it is black (the radiance 1 alone), and under an image
/// environment (isEnvironmentFile) too: the image is the whole lighting.
Light previewLight(const std::string& environment, int l);

/// The split-sum cube maps of an environment, built once per name in a
/// process (a sweep renders many tiles under the same light).
struct EnvironmentMaps {
  CubeMap prefiltered, irradiance;
};
const EnvironmentMaps& environmentMaps(const std::string& name);
/// A cube map as a sampled texture (linear, clamped).
gpu::ImageResource cubeResource(const CubeMap& map);

/// A set-1 texture or sampler binding of a material's shaders (the preview
/// kernel, the base and forward passes): a texture input's bound image or its
/// neutral texel by role (repeated), a specular profile p_<input>'s image or
/// the default profile (clamped), and HLSL's samplers by the input's wrap and filter.
gpu::Resource materialTexture(const Material& m, const std::vector<gpu::TextureRole>& roles,
                              const BoundTextures* textures, const gpu::DescriptorBinding& b);

struct RenderOptions {
  int size = 256;                            // pixels, square
  std::string environment = "studio";        // preview/environment.h
  Target target = Target::Glsl;              // which generated language runs
  DiffuseModel diffuseModel = kDefaultDiffuseModel;  // SUBSTRATE_DIFFUSE_MODEL
  Precision precision = Precision::Float;    // of the runtime's lighting (needs shaderFloat16 for Half)
  double exposure = 0;                       // stops, for the tone map
  PipelineCache* pipelines = nullptr;        // reuse pipelines across calls (null: build one per call)
  /// The material's textures by input name (bindTextures); an input it does
  /// not hold (or every input, when null) gets its neutral texel.
  const BoundTextures* textures = nullptr;
};

/// The gains (exposure and white balance, per channel) that calibrate a render
/// under `environment`: π / E_c for the irradiance E on a normal facing the
/// camera (the environment's, plus its lights' at their cosines), so that a
/// white Lambertian at the sphere's centre reflects radiance (1, 1, 1) and a
/// Lambertian of albedo a reflects a, which the tone curve (tonemap) keeps
/// below 0.76. (1, 1, 1) for "white" (radiance 1 everywhere, no lights).
/// `lights` and `towardCamera` generalize it: the first `lights` preview
/// lights (`render` has the key light alone) and the normal that faces the camera.
std::array<double, 3> calibrationGains(const std::string& environment, int lights = kernel::kPreviewLights,
                                       const std::array<double, 3>& towardCamera = {0, 0, 1});

/// Renders `r` (linear HDR, background = the environment). False, with errors
/// reported, on a kernel that does not validate (a compiler bug) or a failed dispatch.
bool renderSphere(gpu::Context& gpu, const CompileResult& r, const RenderOptions& options, Image* out,
                  Diagnostics& diags);

}  // namespace substratec::preview
