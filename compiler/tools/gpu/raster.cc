// Raster passes on lavapipe (harness.h): graphics pipelines of a vertex and a
// fragment stage built from SPIR-V reflection, and one-shot render passes that
// draw indexed triangles into colour and depth attachments (cleared or loaded
// from the host), with per-draw descriptor sets and storage images shared by
// every draw of the pass, all read back afterwards.
#include <algorithm>
#include <cstring>
#include <map>
#include <set>

#include "gpu/harness.h"
#include "gpu/harness_internal.h"

namespace substratec::gpu {

using namespace harness_detail;

namespace {

constexpr uint32_t kExecutionModelVertex = 0;
constexpr uint32_t kExecutionModelFragment = 4;
constexpr uint32_t kMaxPassSide = 16384;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

VkFormat vkFormat(AttachmentFormat f) {
  return f == AttachmentFormat::R32Uint ? VK_FORMAT_R32_UINT : VK_FORMAT_R32G32B32A32_SFLOAT;
}
VkImageAspectFlags aspectOf(bool depth) {
  return depth ? VkImageAspectFlags{VK_IMAGE_ASPECT_DEPTH_BIT} : VkImageAspectFlags{VK_IMAGE_ASPECT_COLOR_BIT};
}
size_t texelBytes(AttachmentFormat f) { return f == AttachmentFormat::R32Uint ? 4 : 16; }

VkCompareOp compareOp(DepthTest t) {
  switch (t) {
    case DepthTest::Off: return VK_COMPARE_OP_ALWAYS;
    case DepthTest::Less: return VK_COMPARE_OP_LESS;
    case DepthTest::LessOrEqual: return VK_COMPARE_OP_LESS_OR_EQUAL;
    case DepthTest::Equal: return VK_COMPARE_OP_EQUAL;
  }
  return VK_COMPARE_OP_ALWAYS;
}

/// The two stages' bindings merged into one list (sorted), each binding's stages in `stages`.
/// False, reporting it, when the stages declare one binding as different kinds.
bool mergeBindings(const ShaderReflection& vertex, const ShaderReflection* fragment, ShaderReflection* merged,
                   std::map<std::pair<uint32_t, uint32_t>, VkShaderStageFlags>* stages, Diagnostics& diags) {
  std::map<std::pair<uint32_t, uint32_t>, DescriptorBinding> all;
  auto add = [&](const ShaderReflection& r, VkShaderStageFlags stage) {
    for (const DescriptorBinding& b : r.bindings) {
      const auto key = std::make_pair(b.set, b.binding);
      auto [it, inserted] = all.emplace(key, b);
      if (!inserted && it->second.kind != b.kind)
        return fail(diags, "createRasterPipeline: the stages disagree on " + describe(b) + " (the other stage: " +
                               describe(it->second) + ")");
      (*stages)[key] |= stage;
    }
    return true;
  };
  if (!add(vertex, VK_SHADER_STAGE_VERTEX_BIT)) return false;
  if (fragment && !add(*fragment, VK_SHADER_STAGE_FRAGMENT_BIT)) return false;
  merged->entryPoint = fragment ? vertex.entryPoint + "+" + fragment->entryPoint : vertex.entryPoint;
  merged->executionModel = kExecutionModelVertex;
  for (auto& [key, b] : all) merged->bindings.push_back(b);
  return true;
}

/// A render pass for `colors` and a depth attachment: each attachment cleared or loaded
/// (`loaded`: colours, then depth), left in TRANSFER_SRC_OPTIMAL for read-back.
VkRenderPass makeRenderPass(const VulkanFunctions& vk, VkDevice device, const std::vector<AttachmentFormat>& colors,
                            const std::vector<bool>& loaded, Diagnostics& diags) {
  std::vector<VkAttachmentDescription> attachments;
  std::vector<VkAttachmentReference> colorRefs;
  for (size_t i = 0; i <= colors.size(); ++i) {
    const bool depth = i == colors.size();
    VkAttachmentDescription a{};
    a.format = depth ? kDepthFormat : vkFormat(colors[i]);
    a.samples = VK_SAMPLE_COUNT_1_BIT;
    a.loadOp = loaded[i] ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR;
    a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    const VkImageLayout inPass =
        depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    a.initialLayout = loaded[i] ? inPass : VK_IMAGE_LAYOUT_UNDEFINED;
    a.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    attachments.push_back(a);
    if (!depth) colorRefs.push_back({static_cast<uint32_t>(i), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
  }
  const VkAttachmentReference depthRef{static_cast<uint32_t>(colors.size()),
                                       VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = static_cast<uint32_t>(colorRefs.size());
  subpass.pColorAttachments = colorRefs.data();
  subpass.pDepthStencilAttachment = &depthRef;
  // Uploads (transfers) before the pass; read-back copies after it.
  constexpr VkPipelineStageFlags kAttachmentStages = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                                                     VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                                     VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  constexpr VkAccessFlags kAttachmentAccess =
      VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  VkSubpassDependency deps[2]{};
  deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
  deps[0].dstSubpass = 0;
  deps[0].srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[0].dstStageMask = kAttachmentStages;
  deps[0].srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  deps[0].dstAccessMask = kAttachmentAccess;
  deps[1].srcSubpass = 0;
  deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
  deps[1].srcStageMask = kAttachmentStages;
  deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  VkRenderPassCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
  info.attachmentCount = static_cast<uint32_t>(attachments.size());
  info.pAttachments = attachments.data();
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = deps;
  VkRenderPass pass = VK_NULL_HANDLE;
  if (!succeeded(vk.vkCreateRenderPass(device, &info, nullptr, &pass), "vkCreateRenderPass", diags))
    return VK_NULL_HANDLE;
  return pass;
}

VkShaderModule makeModule(const VulkanFunctions& vk, VkDevice device, const std::vector<uint32_t>& spirv,
                          Diagnostics& diags) {
  VkShaderModuleCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  info.codeSize = spirv.size() * sizeof(uint32_t);
  info.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  if (!succeeded(vk.vkCreateShaderModule(device, &info, nullptr, &module), "vkCreateShaderModule", diags))
    return VK_NULL_HANDLE;
  return module;
}

}  // namespace

struct RasterPipeline::Impl {
  Context::Impl* context = nullptr;
  std::vector<VkDescriptorSetLayout> setLayouts;  // index = set number
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkRenderPass renderPass = VK_NULL_HANDLE;  // a compatible one, for creation
  VkPipeline pipeline = VK_NULL_HANDLE;
};

RasterPipeline::RasterPipeline(ShaderReflection reflection, RasterState state, std::unique_ptr<Impl> impl)
    : reflection_(std::move(reflection)), state_(std::move(state)), impl_(std::move(impl)) {}

RasterPipeline::~RasterPipeline() {
  Context::Impl* ctx = impl_->context;
  if (!ctx || ctx->lost) return;
  const VulkanFunctions& vk = ctx->vk;
  if (impl_->pipeline) vk.vkDestroyPipeline(ctx->device, impl_->pipeline, nullptr);
  if (impl_->renderPass) vk.vkDestroyRenderPass(ctx->device, impl_->renderPass, nullptr);
  if (impl_->layout) vk.vkDestroyPipelineLayout(ctx->device, impl_->layout, nullptr);
  for (VkDescriptorSetLayout l : impl_->setLayouts)
    if (l) vk.vkDestroyDescriptorSetLayout(ctx->device, l, nullptr);
}

namespace {

/// The fixed-function part of a graphics pipeline, filled from a RasterState.
struct FixedFunction {
  std::vector<VkVertexInputAttributeDescription> attributes;
  VkVertexInputBindingDescription binding{};
  VkPipelineVertexInputStateCreateInfo vertexInput{};
  VkPipelineInputAssemblyStateCreateInfo assembly{};
  VkPipelineViewportStateCreateInfo viewport{};
  VkPipelineRasterizationStateCreateInfo raster{};
  VkPipelineMultisampleStateCreateInfo multisample{};
  VkPipelineDepthStencilStateCreateInfo depth{};
  std::vector<VkPipelineColorBlendAttachmentState> blends;
  VkPipelineColorBlendStateCreateInfo blend{};
  VkDynamicState dynamicStates[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
  VkPipelineDynamicStateCreateInfo dynamic{};

  explicit FixedFunction(const RasterState& s) {
    uint32_t offset = 0;
    for (uint32_t loc = 0; loc < s.vertexComponents.size(); ++loc) {
      static constexpr VkFormat kFormats[5] = {VK_FORMAT_UNDEFINED, VK_FORMAT_R32_SFLOAT, VK_FORMAT_R32G32_SFLOAT,
                                               VK_FORMAT_R32G32B32_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT};
      attributes.push_back({loc, 0, kFormats[s.vertexComponents[loc]], offset});
      offset += s.vertexComponents[loc] * static_cast<uint32_t>(sizeof(float));
    }
    binding = {0, offset, VK_VERTEX_INPUT_RATE_VERTEX};
    vertexInput.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    vertexInput.vertexBindingDescriptionCount = 1;
    vertexInput.pVertexBindingDescriptions = &binding;
    vertexInput.vertexAttributeDescriptionCount = static_cast<uint32_t>(attributes.size());
    vertexInput.pVertexAttributeDescriptions = attributes.data();
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = viewport.scissorCount = 1;
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;  // glTF's double-sided and single-sided materials alike
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = s.depthTest != DepthTest::Off;
    depth.depthWriteEnable = s.depthWrite;
    depth.depthCompareOp = compareOp(s.depthTest);
    for (size_t i = 0; i < s.colors.size(); ++i) {
      VkPipelineColorBlendAttachmentState a{};
      a.colorWriteMask = (s.colorWriteMask >> i) & 1u ? (VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                                          VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT)
                                                       : 0;
      if (i == 0 && s.blend == Blend::DualSource) {
        a.blendEnable = VK_TRUE;
        a.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
        a.dstColorBlendFactor = VK_BLEND_FACTOR_SRC1_COLOR;
        a.colorBlendOp = VK_BLEND_OP_ADD;
        a.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO;
        a.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        a.alphaBlendOp = VK_BLEND_OP_ADD;
      }
      blends.push_back(a);
    }
    blend.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blend.attachmentCount = static_cast<uint32_t>(blends.size());
    blend.pAttachments = blends.data();
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;
  }
};

/// What a RasterState asks of the device and of itself; "" when it is fine.
std::string stateProblem(const RasterState& s, const ShaderReflection* fragment, bool fragmentStores,
                         bool dualSource, bool independentBlend) {
  if (s.vertexComponents.empty() || s.vertexComponents.size() > 16) return "1 to 16 vertex inputs are needed";
  for (uint32_t c : s.vertexComponents)
    if (c < 1 || c > 4) return "a vertex input has " + std::to_string(c) + " components (1 to 4)";
  if (s.colors.size() > 8) return "more than 8 colour attachments";
  if (s.blend == Blend::DualSource && !dualSource) return "dual-source blending needs dualSrcBlend, which the device lacks";
  if (s.blend == Blend::DualSource && s.colors.empty()) return "dual-source blending needs a colour attachment";
  const uint32_t all = s.colors.size() >= 32 ? ~0u : (1u << s.colors.size()) - 1u;
  const bool uniform = (s.colorWriteMask & all) == 0 || (s.colorWriteMask & all) == all;
  if (!independentBlend && (!uniform || (s.blend != Blend::None && s.colors.size() > 1)))
    return "attachments written or blended differently need independentBlend, which the device lacks";
  if (fragment && !fragmentStores &&
      std::any_of(fragment->bindings.begin(), fragment->bindings.end(),
                  [](const DescriptorBinding& b) { return b.kind == DescriptorKind::StorageImage; }))
    return "the fragment stage stores to an image, which needs fragmentStoresAndAtomics (the device lacks it)";
  return "";
}

/// The descriptor set layouts (one per set number up to the highest, empty ones included) and the
/// pipeline layout of `merged`, each binding visible to the stages that use it.
bool createLayouts(const VulkanFunctions& vk, VkDevice device, const ShaderReflection& merged,
                   const std::map<std::pair<uint32_t, uint32_t>, VkShaderStageFlags>& stages,
                   std::vector<VkDescriptorSetLayout>* setLayouts, VkPipelineLayout* layout, Diagnostics& diags) {
  const uint32_t setCount = merged.bindings.empty() ? 0 : merged.bindings.back().set + 1;
  setLayouts->assign(setCount, VK_NULL_HANDLE);
  for (uint32_t set = 0; set < setCount; ++set) {
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (const DescriptorBinding& b : merged.bindings)
      if (b.set == set)
        bindings.push_back({b.binding, descriptorType(b.kind), 1, stages.at({b.set, b.binding}), nullptr});
    VkDescriptorSetLayoutCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    info.bindingCount = static_cast<uint32_t>(bindings.size());
    info.pBindings = bindings.data();
    if (!succeeded(vk.vkCreateDescriptorSetLayout(device, &info, nullptr, &(*setLayouts)[set]),
                   "vkCreateDescriptorSetLayout (set " + std::to_string(set) + ")", diags))
      return false;
  }
  VkPipelineLayoutCreateInfo layoutInfo{};
  layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layoutInfo.setLayoutCount = setCount;
  layoutInfo.pSetLayouts = setLayouts->data();
  if (!succeeded(vk.vkCreatePipelineLayout(device, &layoutInfo, nullptr, layout), "vkCreatePipelineLayout", diags))
    return false;
  return true;
}

/// The graphics pipeline of the two stages (the fragment stage may be empty) and `state` on `layout`,
/// for render passes compatible with `renderPass`.
bool buildPipeline(const VulkanFunctions& vk, VkDevice device, const std::vector<uint32_t>& vertex,
                   const std::vector<uint32_t>& fragment, const std::string& vertexEntry,
                   const std::string& fragmentEntry, const RasterState& state, VkPipelineLayout layout,
                   VkRenderPass renderPass, VkPipeline* pipeline, Diagnostics& diags) {
  VkShaderModule modules[2] = {makeModule(vk, device, vertex, diags),
                               !fragment.empty() ? makeModule(vk, device, fragment, diags) : VK_NULL_HANDLE};
  VkPipelineShaderStageCreateInfo stageInfo[2]{};
  for (int i = 0; i < 2; ++i) {
    stageInfo[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stageInfo[i].stage = i == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
    stageInfo[i].module = modules[i];
    stageInfo[i].pName = i == 0 ? vertexEntry.c_str() : fragmentEntry.c_str();
  }
  const FixedFunction ff(state);
  VkGraphicsPipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
  info.stageCount = !fragment.empty() ? 2 : 1;
  info.pStages = stageInfo;
  info.pVertexInputState = &ff.vertexInput;
  info.pInputAssemblyState = &ff.assembly;
  info.pViewportState = &ff.viewport;
  info.pRasterizationState = &ff.raster;
  info.pMultisampleState = &ff.multisample;
  info.pDepthStencilState = &ff.depth;
  info.pColorBlendState = &ff.blend;
  info.pDynamicState = &ff.dynamic;
  info.layout = layout;
  info.renderPass = renderPass;
  VkResult r = VK_ERROR_INITIALIZATION_FAILED;
  if (modules[0] && (!!fragment.empty() || modules[1]))
    r = vk.vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, pipeline);
  for (VkShaderModule m : modules)
    if (m) vk.vkDestroyShaderModule(device, m, nullptr);
  return succeeded(r, "vkCreateGraphicsPipelines", diags);
}

}  // namespace

std::unique_ptr<RasterPipeline> Context::createRasterPipeline(const std::vector<uint32_t>& vertex,
                                                              const std::vector<uint32_t>& fragment,
                                                              const RasterState& state, Diagnostics& diags) {
  Impl& c = *impl_;
  const VulkanFunctions& vk = c.vk;
  if (c.lost) return fail(diags, "GPU harness: the Context is unusable after an earlier timeout or device loss"), nullptr;
  ShaderReflection vr, fr;
  if (!reflectSpirv(vertex, &vr, diags)) return nullptr;
  if (vr.executionModel != kExecutionModelVertex)
    return fail(diags, "createRasterPipeline: entry point '" + vr.entryPoint + "' is not a Vertex entry point"), nullptr;
  const bool hasFragment = !fragment.empty();
  if (hasFragment) {
    if (!reflectSpirv(fragment, &fr, diags)) return nullptr;
    if (fr.executionModel != kExecutionModelFragment)
      return fail(diags, "createRasterPipeline: entry point '" + fr.entryPoint + "' is not a Fragment entry point"),
             nullptr;
  }
  if (const std::string why = stateProblem(state, hasFragment ? &fr : nullptr, c.fragmentStores, c.dualSourceBlend,
                                              c.independentBlend);
      !why.empty())
    return fail(diags, "createRasterPipeline: " + why), nullptr;
  ShaderReflection merged;
  std::map<std::pair<uint32_t, uint32_t>, VkShaderStageFlags> stages;
  if (!mergeBindings(vr, hasFragment ? &fr : nullptr, &merged, &stages, diags)) return nullptr;
  for (const DescriptorBinding& b : merged.bindings)
    if (b.count != 1) return fail(diags, "createRasterPipeline: descriptor arrays are not supported (" + describe(b) + ")"), nullptr;

  const size_t start = c.messageCount();
  auto impl = std::make_unique<RasterPipeline::Impl>();
  impl->context = &c;
  std::unique_ptr<RasterPipeline> pipeline(new RasterPipeline(merged, state, std::move(impl)));
  RasterPipeline::Impl& p = *pipeline->impl_;
  if (!createLayouts(vk, c.device, merged, stages, &p.setLayouts, &p.layout, diags)) return nullptr;
  p.renderPass = makeRenderPass(vk, c.device, state.colors, std::vector<bool>(state.colors.size() + 1, false), diags);
  if (!p.renderPass) return nullptr;

  if (!buildPipeline(vk, c.device, vertex, fragment, vr.entryPoint, fr.entryPoint, state, p.layout, p.renderPass,
                     &p.pipeline, diags))
    return nullptr;
  if (!c.noMessagesSince(start, "createRasterPipeline", diags)) return nullptr;
  return pipeline;
}

namespace {

/// The checks of a pass that need no Vulkan object; "" when it is fine.
std::string passProblem(const RasterPass& pass, const std::vector<Draw>& draws) {
  if (pass.width == 0 || pass.height == 0 || pass.width > kMaxPassSide || pass.height > kMaxPassSide)
    return "the pass is " + std::to_string(pass.width) + "x" + std::to_string(pass.height) + " (1 to " +
           std::to_string(kMaxPassSide) + " a side)";
  const size_t texels = size_t{pass.width} * pass.height;
  for (size_t i = 0; i < pass.colors.size(); ++i)
    if (!pass.colors[i].initial.empty() && pass.colors[i].initial.size() != texels * texelBytes(pass.colors[i].format))
      return "colour attachment " + std::to_string(i) + " has " + std::to_string(pass.colors[i].initial.size()) +
             " initial bytes, expected " + std::to_string(texels * texelBytes(pass.colors[i].format));
  if (!pass.depthInitial.empty() && pass.depthInitial.size() != texels)
    return "the depth attachment has " + std::to_string(pass.depthInitial.size()) + " initial values, expected " +
           std::to_string(texels);
  for (const auto& [key, r] : pass.shared)
    if (!std::holds_alternative<StorageImageResource>(r))
      return "a shared resource (set " + std::to_string(key.first) + " binding " + std::to_string(key.second) +
             ") is not a StorageImageResource";
  for (size_t d = 0; d < draws.size(); ++d) {
    const std::string at = "draw " + std::to_string(d) + ": ";
    if (!draws[d].pipeline || !draws[d].geometry) return at + "no pipeline or no geometry";
    const RasterState& s = draws[d].pipeline->state();
    std::vector<AttachmentFormat> formats;
    for (const ColorAttachment& a : pass.colors) formats.push_back(a.format);
    if (s.colors != formats) return at + "its pipeline was made for other colour attachments";
    const Geometry& g = *draws[d].geometry;
    uint32_t stride = 0;
    for (uint32_t c : s.vertexComponents) stride += c;
    if (g.vertices.empty() || g.vertices.size() % stride != 0)
      return at + "its geometry has " + std::to_string(g.vertices.size()) + " floats, not a multiple of the " +
             std::to_string(stride) + " a vertex has";
    const size_t vertexCount = g.vertices.size() / stride;
    if (g.indices.empty() || g.indices.size() % 3 != 0)
      return at + std::to_string(g.indices.size()) + " indices are not whole triangles";
    if (*std::max_element(g.indices.begin(), g.indices.end()) >= vertexCount)
      return at + "an index is out of range (" + std::to_string(vertexCount) + " vertices)";
  }
  return "";
}

/// Every binding of `refl` has a resource of its kind in `resources` or in `shared`, and every resource
/// is used; otherwise false, reporting the first mismatch.
bool drawResourcesMatch(const ShaderReflection& refl, const Resources& resources, const Resources& shared,
                        const std::string& at, Diagnostics& diags) {
  for (const DescriptorBinding& b : refl.bindings) {
    const auto key = std::make_pair(b.set, b.binding);
    const Resource* r = nullptr;
    if (auto it = resources.find(key); it != resources.end()) r = &it->second;
    else if (auto s = shared.find(key); s != shared.end()) r = &s->second;
    if (!r) return fail(diags, at + "no resource for " + describe(b));
    if (r->index() != resourceIndexFor(b.kind))
      return fail(diags, at + describe(b) + " needs a " + kResourceNames[resourceIndexFor(b.kind)] + ", got a " +
                             kResourceNames[r->index()]);
  }
  for (const auto& [key, r] : resources)
    if (std::none_of(refl.bindings.begin(), refl.bindings.end(), [&k = key](const DescriptorBinding& b) {
          return b.set == k.first && b.binding == k.second;
        }))
      return fail(diags, at + "the " + std::string(kResourceNames[r.index()]) + " for set " + std::to_string(key.first) +
                             " binding " + std::to_string(key.second) + " is not used by its pipeline");
  return true;
}

}  // namespace

/// An attachment image of a pass and where its contents go.
struct PassAttachment {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkBuffer staging = VK_NULL_HANDLE;   // the initial contents, when loaded
  VkBuffer readback = VK_NULL_HANDLE;  // mapped at `mapped`
  void* mapped = nullptr;
  size_t bytes = 0;
  bool depth = false;
  bool loaded = false;
};

/// One raster pass's Vulkan work (Context::render runs the steps in order).
struct RasterRecorder {
  Context::Impl& c;
  RasterPass& pass;
  std::vector<Draw>& draws;
  DispatchObjects objs;
  Bindings passBindings;                  // the shared storage images
  std::vector<Bindings> drawBindings;     // per draw
  std::vector<PassAttachment> attachments;  // colours, then depth
  std::map<const Geometry*, std::pair<VkBuffer, VkBuffer>> geometry;  // vertex, index buffers
  std::map<std::pair<uint32_t, uint32_t>, VkDescriptorImageInfo> shared;

  bool createAttachments(Diagnostics& diags);
  bool bindShared(Diagnostics& diags);
  bool bindDraws(Diagnostics& diags);
  bool uploadGeometry(Diagnostics& diags);
  /// One command buffer: fills, the pass's draws (between timestamps when `timed`), read-back copies.
  bool record(bool timed, Diagnostics& diags);
  /// The render pass (clears or loads as the attachments say) and its framebuffer.
  bool makeTarget(VkRenderPass* renderPass, VkFramebuffer* framebuffer, Diagnostics& diags);
  /// Textures, shared storage images and loaded attachments filled, then handed to the pass.
  void recordFills(VkCommandBuffer cmd);
  /// The render pass and every draw in it.
  bool recordDraws(VkCommandBuffer cmd, VkRenderPass renderPass, VkFramebuffer framebuffer, bool timed,
                   Diagnostics& diags);
  /// Copies of the attachments and shared storage images into mapped buffers, made visible to the host.
  void recordReadBacks(VkCommandBuffer cmd);
  void readBack();
};

bool RasterRecorder::createAttachments(Diagnostics& diags) {
  const size_t texels = size_t{pass.width} * pass.height;
  for (size_t i = 0; i <= pass.colors.size(); ++i) {
    PassAttachment a;
    a.depth = i == pass.colors.size();
    const VkFormat format = a.depth ? kDepthFormat : vkFormat(pass.colors[i].format);
    a.bytes = texels * (a.depth ? sizeof(float) : texelBytes(pass.colors[i].format));
    a.loaded = a.depth ? !pass.depthInitial.empty() : !pass.colors[i].initial.empty();
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {pass.width, pass.height, 1};
    info.mipLevels = info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = (a.depth ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT) |
                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (!succeeded(c.vk.vkCreateImage(c.device, &info, nullptr, &a.image), "vkCreateImage (attachment)", diags))
      return false;
    objs.images.push_back(a.image);
    if (!c.bindMemory(a.image, objs, nullptr, diags)) return false;
    VkImageViewCreateInfo view{};
    view.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    view.image = a.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspectOf(a.depth), 0, 1,
                             0, 1};
    if (!succeeded(c.vk.vkCreateImageView(c.device, &view, nullptr, &a.view), "vkCreateImageView", diags)) return false;
    objs.views.push_back(a.view);
    if (!c.createBuffer(a.bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, objs, &a.readback, &a.mapped, diags)) return false;
    if (a.loaded) {
      void* staged;
      if (!c.createBuffer(a.bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, objs, &a.staging, &staged, diags)) return false;
      std::memcpy(staged, a.depth ? static_cast<const void*>(pass.depthInitial.data()) : pass.colors[i].initial.data(),
                  a.bytes);
    }
    attachments.push_back(a);
  }
  return true;
}

bool RasterRecorder::bindShared(Diagnostics& diags) {
  passBindings.imageInfos.reserve(pass.shared.size());
  for (auto& [key, resource] : pass.shared) {
    const DescriptorBinding* binding = nullptr;
    for (const Draw& d : draws)
      for (const DescriptorBinding& b : d.pipeline->reflection().bindings)
        if (!binding && b.set == key.first && b.binding == key.second) binding = &b;
    if (!binding)
      return fail(diags, "the shared StorageImageResource for set " + std::to_string(key.first) + " binding " +
                             std::to_string(key.second) + " is used by no draw");
    VkWriteDescriptorSet unused{};
    Diagnostics failure(diags.file());
    if (!c.bindStorageImage(*binding, std::get<StorageImageResource>(resource), objs, passBindings, unused, failure))
      return fail(diags, describe(*binding) + " (shared): " + failure.errorMessages());
    shared[key] = passBindings.imageInfos.back();
  }
  return true;
}

bool RasterRecorder::bindDraws(Diagnostics& diags) {
  drawBindings.resize(draws.size());
  for (size_t d = 0; d < draws.size(); ++d) {
    const RasterPipeline& p = *draws[d].pipeline;
    const std::string at = "draw " + std::to_string(d) + ": ";
    if (!drawResourcesMatch(p.reflection(), draws[d].resources, pass.shared, at, diags)) return false;
    Diagnostics failure(diags.file());
    if (!c.allocateSets(p.impl_->setLayouts, p.reflection(), objs, drawBindings[d], failure) ||
        !c.bindResources(p.reflection(), draws[d].resources, objs, drawBindings[d], failure, &shared))
      return fail(diags, at + failure.errorMessages());
  }
  return true;
}

bool RasterRecorder::uploadGeometry(Diagnostics& diags) {
  for (const Draw& d : draws) {
    if (geometry.count(d.geometry)) continue;
    const Geometry& g = *d.geometry;
    VkBuffer vb, ib;
    void *vm, *im;
    if (!c.createBuffer(g.vertices.size() * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, objs, &vb, &vm, diags) ||
        !c.createBuffer(g.indices.size() * sizeof(uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT, objs, &ib, &im, diags))
      return false;
    std::memcpy(vm, g.vertices.data(), g.vertices.size() * sizeof(float));
    std::memcpy(im, g.indices.data(), g.indices.size() * sizeof(uint32_t));
    geometry[d.geometry] = {vb, ib};
  }
  return true;
}

bool RasterRecorder::record(bool timed, Diagnostics& diags) {
  const VulkanFunctions& vk = c.vk;
  VkRenderPass renderPass;
  VkFramebuffer framebuffer;
  if (!makeTarget(&renderPass, &framebuffer, diags)) return false;
  VkCommandBufferAllocateInfo cbInfo{};
  cbInfo.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cbInfo.commandPool = c.commandPool;
  cbInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbInfo.commandBufferCount = 1;
  if (!succeeded(vk.vkAllocateCommandBuffers(c.device, &cbInfo, &objs.commandBuffer), "vkAllocateCommandBuffers", diags))
    return false;
  const VkCommandBuffer cmd = objs.commandBuffer;
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (!succeeded(vk.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer", diags)) return false;

  recordFills(cmd);
  if (!recordDraws(cmd, renderPass, framebuffer, timed, diags)) return false;
  recordReadBacks(cmd);
  return succeeded(vk.vkEndCommandBuffer(cmd), "vkEndCommandBuffer", diags);
}

bool RasterRecorder::makeTarget(VkRenderPass* renderPass, VkFramebuffer* framebuffer, Diagnostics& diags) {
  const VulkanFunctions& vk = c.vk;
  std::vector<bool> loaded;
  for (const PassAttachment& a : attachments) loaded.push_back(a.loaded);
  std::vector<AttachmentFormat> formats;
  for (const ColorAttachment& a : pass.colors) formats.push_back(a.format);
  *renderPass = makeRenderPass(vk, c.device, formats, loaded, diags);
  if (!*renderPass) return false;
  objs.renderPasses.push_back(*renderPass);
  std::vector<VkImageView> views;
  for (const PassAttachment& a : attachments) views.push_back(a.view);
  VkFramebufferCreateInfo fb{};
  fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
  fb.renderPass = *renderPass;
  fb.attachmentCount = static_cast<uint32_t>(views.size());
  fb.pAttachments = views.data();
  fb.width = pass.width;
  fb.height = pass.height;
  fb.layers = 1;
  if (!succeeded(vk.vkCreateFramebuffer(c.device, &fb, nullptr, framebuffer), "vkCreateFramebuffer", diags))
    return false;
  objs.framebuffers.push_back(*framebuffer);
  return true;
}

void RasterRecorder::recordFills(VkCommandBuffer cmd) {
  const VulkanFunctions& vk = c.vk;
  // Fill textures, shared storage images and loaded attachments, then hand them to the pass.
  std::vector<const ImageUpload*> uploads;
  for (const ImageUpload& up : passBindings.uploads) uploads.push_back(&up);
  for (const Bindings& b : drawBindings)
    for (const ImageUpload& up : b.uploads) uploads.push_back(&up);
  std::vector<VkImageMemoryBarrier> before, after;
  for (const ImageUpload* up : uploads) {
    before.push_back(imageBarrier(up->image, up->layers, up->mipLevels, VK_IMAGE_LAYOUT_UNDEFINED,
                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT));
    after.push_back(imageBarrier(up->image, up->layers, up->mipLevels, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                 up->finalLayout, VK_ACCESS_TRANSFER_WRITE_BIT,
                                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT));
  }
  for (const PassAttachment& a : attachments) {
    if (!a.loaded) continue;
    VkImageMemoryBarrier toDst = imageBarrier(a.image, 1, 1, VK_IMAGE_LAYOUT_UNDEFINED,
                                              VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkImageMemoryBarrier toPass =
        imageBarrier(a.image, 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     a.depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                     VK_ACCESS_TRANSFER_WRITE_BIT,
                     a.depth ? VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT
                             : VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    if (a.depth) toDst.subresourceRange.aspectMask = toPass.subresourceRange.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
    before.push_back(toDst);
    after.push_back(toPass);
  }
  if (!before.empty())
    vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                            nullptr, static_cast<uint32_t>(before.size()), before.data());
  for (const ImageUpload* up : uploads) {
    if (up->staging) {
      vk.vkCmdCopyBufferToImage(cmd, up->staging, up->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                static_cast<uint32_t>(up->regions.size()), up->regions.data());
    } else {
      const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, up->layers};
      vk.vkCmdClearColorImage(cmd, up->image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &up->clear, 1, &range);
    }
  }
  for (const PassAttachment& a : attachments) {
    if (!a.loaded) continue;
    VkBufferImageCopy region{};
    region.imageSubresource = {aspectOf(a.depth), 0,
                               0, 1};
    region.imageExtent = {pass.width, pass.height, 1};
    vk.vkCmdCopyBufferToImage(cmd, a.staging, a.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  if (!after.empty())
    vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                            VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT |
                                VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                            0, 0, nullptr, 0, nullptr, static_cast<uint32_t>(after.size()), after.data());

}

bool RasterRecorder::recordDraws(VkCommandBuffer cmd, VkRenderPass renderPass, VkFramebuffer framebuffer, bool timed,
                                 Diagnostics& diags) {
  const VulkanFunctions& vk = c.vk;
  if (timed) {
    VkQueryPoolCreateInfo q{};
    q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    q.queryType = VK_QUERY_TYPE_TIMESTAMP;
    q.queryCount = 2;
    if (!succeeded(vk.vkCreateQueryPool(c.device, &q, nullptr, &objs.timestamps), "vkCreateQueryPool", diags))
      return false;
    vk.vkCmdResetQueryPool(cmd, objs.timestamps, 0, 2);
    vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, objs.timestamps, 0);
  }
  std::vector<VkClearValue> clears;
  for (const ColorAttachment& a : pass.colors) {
    VkClearValue v{};
    std::memcpy(v.color.uint32, a.clear.data(), sizeof v.color.uint32);
    clears.push_back(v);
  }
  VkClearValue depthClear{};
  depthClear.depthStencil = {pass.depthClear, 0};
  clears.push_back(depthClear);
  VkRenderPassBeginInfo rp{};
  rp.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  rp.renderPass = renderPass;
  rp.framebuffer = framebuffer;
  rp.renderArea = {{0, 0}, {pass.width, pass.height}};
  rp.clearValueCount = static_cast<uint32_t>(clears.size());
  rp.pClearValues = clears.data();
  vk.vkCmdBeginRenderPass(cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0, 0, static_cast<float>(pass.width), static_cast<float>(pass.height), 0, 1};
  const VkRect2D scissor{{0, 0}, {pass.width, pass.height}};
  for (size_t d = 0; d < draws.size(); ++d) {
    const RasterPipeline::Impl& p = *draws[d].pipeline->impl_;
    vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline);
    const std::vector<VkDescriptorSet>& sets = drawBindings[d].sets;
    if (!sets.empty())
      vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout, 0, static_cast<uint32_t>(sets.size()),
                                 sets.data(), 0, nullptr);
    const auto [vb, ib] = geometry.at(draws[d].geometry);
    const VkDeviceSize offset = 0;
    vk.vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
    vk.vkCmdBindIndexBuffer(cmd, ib, 0, VK_INDEX_TYPE_UINT32);
    vk.vkCmdSetViewport(cmd, 0, 1, &viewport);
    vk.vkCmdSetScissor(cmd, 0, 1, &scissor);
    vk.vkCmdDrawIndexed(cmd, static_cast<uint32_t>(draws[d].geometry->indices.size()), 1, 0, 0, 0);
  }
  vk.vkCmdEndRenderPass(cmd);
  if (timed) vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, objs.timestamps, 1);

  return true;
}

void RasterRecorder::recordReadBacks(VkCommandBuffer cmd) {
  const VulkanFunctions& vk = c.vk;
  // Read back: the attachments (left in TRANSFER_SRC by the pass) and the shared storage images.
  std::vector<VkImageMemoryBarrier> out;
  for (const Readback& rb : passBindings.readbacks)
    out.push_back(imageBarrier(rb.image, rb.region.imageSubresource.layerCount, 1, VK_IMAGE_LAYOUT_GENERAL,
                               VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
                               VK_ACCESS_TRANSFER_READ_BIT));
  if (!out.empty())
    vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                            0, nullptr, static_cast<uint32_t>(out.size()), out.data());
  for (const Readback& rb : passBindings.readbacks)
    vk.vkCmdCopyImageToBuffer(cmd, rb.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, rb.buffer, 1, &rb.region);
  for (const PassAttachment& a : attachments) {
    VkBufferImageCopy region{};
    region.imageSubresource = {aspectOf(a.depth), 0,
                               0, 1};
    region.imageExtent = {pass.width, pass.height, 1};
    vk.vkCmdCopyImageToBuffer(cmd, a.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, a.readback, 1, &region);
  }
  VkMemoryBarrier toHost{};
  toHost.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr,
                          0, nullptr);
}

void RasterRecorder::readBack() {
  for (const Readback& rb : passBindings.readbacks) {
    rb.target->resize(rb.size);
    std::memcpy(rb.target->data(), rb.mapped, rb.size);
  }
  for (size_t i = 0; i < attachments.size(); ++i) {
    const PassAttachment& a = attachments[i];
    if (a.depth) {
      pass.depth.resize(a.bytes / sizeof(float));
      std::memcpy(pass.depth.data(), a.mapped, a.bytes);
    } else {
      pass.colors[i].data.resize(a.bytes);
      std::memcpy(pass.colors[i].data.data(), a.mapped, a.bytes);
    }
  }
}

bool Context::render(RasterPass& pass, std::vector<Draw>& draws, Diagnostics& diags, double* passNs) {
  Impl& c = *impl_;
  if (c.lost) return fail(diags, "render: the Context is unusable after an earlier timeout or device loss");
  for (const Draw& d : draws)
    if (d.pipeline && d.pipeline->impl_->context != &c) return fail(diags, "render: a pipeline belongs to another Context");
  if (const std::string why = passProblem(pass, draws); !why.empty()) return fail(diags, "render: " + why);
  const size_t start = c.messageCount();
  RasterRecorder rec{c, pass, draws, {}, {}, {}, {}, {}, {}};
  Diagnostics failure(diags.file());
  const bool ran = rec.createAttachments(failure) && rec.bindShared(failure) && rec.bindDraws(failure) &&
                   rec.uploadGeometry(failure) && rec.record(passNs != nullptr, failure) &&
                   c.submitAndWait(rec.objs, failure);
  bool timedOk = true;
  if (ran) {
    rec.readBack();
    if (passNs) {
      uint64_t t[2] = {0, 0};
      timedOk = succeeded(c.vk.vkGetQueryPoolResults(c.device, rec.objs.timestamps, 0, 2, sizeof t, t, sizeof(uint64_t),
                                                     VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                          "vkGetQueryPoolResults", failure);
      *passNs = static_cast<double>(t[1] - t[0]) * c.timestampPeriodNs;
    }
  }
  if (!c.lost) c.destroy(rec.objs);
  if (!ran || !timedOk) diags.fail("render: " + failure.errorMessages());
  const bool quiet = c.noMessagesSince(start, "a raster pass", diags);
  return ran && timedOk && quiet;
}

}  // namespace substratec::gpu
