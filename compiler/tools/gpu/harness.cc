// The Vulkan compute harness on lavapipe (see harness.h): instance/device setup
// with the validation layer, pipelines built from SPIR-V reflection, and
// one-shot dispatches with per-dispatch buffers, images and samplers.
#include "gpu/harness.h"

#include <stdlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <type_traits>

#include "gpu/harness_internal.h"
#include "gpu/vulkan_loader.h"

namespace substratec::gpu {

using namespace harness_detail;

namespace {

constexpr const char* kLavapipeIcd = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint32_t kExecutionModelGLCompute = 5;

/// The VK_EXT_debug_utils callback: records warnings and errors into the ValidationMessageLog.
VKAPI_ATTR VkBool32 VKAPI_CALL recordMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT types,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  std::string text = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "ERROR" : "WARNING";
  text += (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)    ? " [validation] "
          : (types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT) ? " [performance] "
                                                                       : " [general] ";
  text += data && data->pMessage ? data->pMessage : "(no message)";
  auto* log = static_cast<ValidationMessageLog*>(user);
  std::lock_guard<std::mutex> lock(log->mutex);
  log->messages.push_back(std::move(text));
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(ValidationMessageLog* log) {
  VkDebugUtilsMessengerCreateInfoEXT info{};
  info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = recordMessage;
  info.pUserData = log;
  return info;
}

/// Which Vulkan drivers the loader was pointed at, for "no driver" errors.
std::string driverHint() {
  const char* files = getenv("VK_DRIVER_FILES");
  const char* icds = getenv("VK_ICD_FILENAMES");
  return std::string(" (no usable lavapipe driver; VK_DRIVER_FILES=") + (files ? files : "<unset>") +
         ", VK_ICD_FILENAMES=" + (icds ? icds : "<unset>") + "; Debian: mesa-vulkan-drivers)";
}


/// Every binding of `refl` has a resource of its kind in `resources`, and every resource is used;
/// otherwise false, reporting the first mismatch.
bool resourcesMatch(const ShaderReflection& refl, const Resources& resources, Diagnostics& diags) {
  for (const DescriptorBinding& b : refl.bindings) {
    auto it = resources.find({b.set, b.binding});
    if (it == resources.end()) {
      diags.fail("dispatch: no resource for " + describe(b) + " of entry point '" + refl.entryPoint + "'");
      return false;
    }
    const size_t want = resourceIndexFor(b.kind);
    if (it->second.index() != want) {
      diags.fail("dispatch: " + describe(b) + " needs a " + kResourceNames[want] + ", got a " +
                 kResourceNames[it->second.index()]);
      return false;
    }
  }
  for (const auto& [key, resource] : resources) {
    if (std::none_of(refl.bindings.begin(), refl.bindings.end(), [&key = key](const DescriptorBinding& b) {
          return b.set == key.first && b.binding == key.second;
        })) {
      diags.fail("dispatch: the " + std::string(kResourceNames[resource.index()]) + " for set " +
                 std::to_string(key.first) + " binding " + std::to_string(key.second) +
                 " is not used by entry point '" + refl.entryPoint + "'");
      return false;
    }
  }
  return true;
}

}  // namespace


bool Context::Impl::createInstance(Diagnostics& diags) {
  if (!loadGlobalFunctions(&vk, diags)) return false;
  // Pin the loader to lavapipe unless the caller chose drivers (an empty variable counts as unset: the
  // loader would find no driver at all). Other ICDs (intel, radeon) must never be picked.
  auto unset = [](const char* name) { return !getenv(name) || !*getenv(name); };
  if (unset("VK_DRIVER_FILES") && unset("VK_ICD_FILENAMES")) {
    if (!std::filesystem::exists(kLavapipeIcd)) {
      diags.fail(std::string("lavapipe's ICD file ") + kLavapipeIcd + " is missing (Debian: mesa-vulkan-drivers)");
      return false;
    }
    setenv("VK_DRIVER_FILES", kLavapipeIcd, 1);
  }
  if (!options.shaderCacheDir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.shaderCacheDir, ec);
    setenv("MESA_SHADER_CACHE_DIR", options.shaderCacheDir.c_str(), 1);
  }

  uint32_t count = 0;
  if (!succeeded(vk.vkEnumerateInstanceLayerProperties(&count, nullptr), "vkEnumerateInstanceLayerProperties", diags))
    return false;
  std::vector<VkLayerProperties> layers(count);
  if (!succeeded(vk.vkEnumerateInstanceLayerProperties(&count, layers.data()), "vkEnumerateInstanceLayerProperties",
                 diags))
    return false;
  if (std::none_of(layers.begin(), layers.begin() + count,
                   [](const VkLayerProperties& l) { return std::strcmp(l.layerName, kValidationLayer) == 0; })) {
    diags.fail(std::string("the Vulkan validation layer ") + kValidationLayer +
               " is not installed (Debian: vulkan-validationlayers); GPU results are not trusted without it");
    return false;
  }

  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "substratec";
  app.pEngineName = "substratec-gpu-harness";
  app.apiVersion = VK_API_VERSION_1_2;
  const VkDebugUtilsMessengerCreateInfoEXT debugInfo = messengerInfo(log.get());
  const char* layerNames[] = {kValidationLayer};
  // Synchronization validation too: it checks the harness' own barriers (quiet on every test).
  const char* extensionNames[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  features.pNext = &debugInfo;
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pNext = &features;  // -> debugInfo: problems of vkCreateInstance/vkDestroyInstance are recorded too
  info.pApplicationInfo = &app;
  info.enabledLayerCount = 1;
  info.ppEnabledLayerNames = layerNames;
  info.enabledExtensionCount = 2;
  info.ppEnabledExtensionNames = extensionNames;
  const VkResult created = vk.vkCreateInstance(&info, nullptr, &instance);
  if (created != VK_SUCCESS) {
    diags.fail("vkCreateInstance (with " + std::string(kValidationLayer) + ", VK_EXT_debug_utils, " +
               VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME + ") failed: " + vkResultName(created) +
               (created == VK_ERROR_INCOMPATIBLE_DRIVER ? driverHint() : ""));
    return false;
  }
  if (!loadInstanceFunctions(&vk, instance, diags)) return false;
  return succeeded(vk.vkCreateDebugUtilsMessengerEXT(instance, &debugInfo, nullptr, &messenger),
                   "vkCreateDebugUtilsMessengerEXT", diags);
}

bool Context::Impl::createDevice(Diagnostics& diags) {
  uint32_t count = 0;
  if (const VkResult listed = vk.vkEnumeratePhysicalDevices(instance, &count, nullptr); listed != VK_SUCCESS) {
    diags.fail("vkEnumeratePhysicalDevices failed: " + vkResultName(listed) + driverHint());
    return false;
  }
  std::vector<VkPhysicalDevice> devices(count);
  if (!succeeded(vk.vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices", diags))
    return false;
  std::string seen;
  for (uint32_t i = 0; i < count && !physical; ++i) {
    VkPhysicalDeviceProperties2 props{};
    props.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    vk.vkGetPhysicalDeviceProperties2(devices[i], &props);  // driver properties need a 1.2 device
    seen += std::string(seen.empty() ? "" : ", ") + props.properties.deviceName;
    if (props.properties.apiVersion < VK_API_VERSION_1_2) continue;
    VkPhysicalDeviceDriverProperties driver{};
    driver.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES;
    props.pNext = &driver;
    vk.vkGetPhysicalDeviceProperties2(devices[i], &props);
    if (driver.driverID != VK_DRIVER_ID_MESA_LLVMPIPE) continue;
    physical = devices[i];
    deviceName = props.properties.deviceName;
    driverInfo = driver.driverInfo;
    timestampPeriodNs = props.properties.limits.timestampPeriod;
  }
  if (!physical) {
    diags.fail("no lavapipe (VK_DRIVER_ID_MESA_LLVMPIPE) device among: " +
               (seen.empty() ? std::string("none") : seen) + driverHint());
    return false;
  }
  vk.vkGetPhysicalDeviceMemoryProperties(physical, &memory);

  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
  // One queue for everything: compute dispatches and raster passes (raster.cc).
  constexpr VkQueueFlags kNeed = VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT;
  auto family = std::find_if(families.begin(), families.end(),
                             [](const VkQueueFamilyProperties& f) { return (f.queueFlags & kNeed) == kNeed; });
  if (family == families.end()) {
    diags.fail("lavapipe reports no queue family with both graphics and compute");
    return false;
  }
  queueFamily = static_cast<uint32_t>(family - families.begin());
  if (!createLogicalDevice(diags)) return false;
  if (!loadDeviceFunctions(&vk, device, diags)) return false;
  vk.vkGetDeviceQueue(device, queueFamily, 0, &queue);
  VkCommandPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  poolInfo.queueFamilyIndex = queueFamily;
  return succeeded(vk.vkCreateCommandPool(device, &poolInfo, nullptr, &commandPool), "vkCreateCommandPool", diags);
}

bool Context::Impl::createLogicalDevice(Diagnostics& diags) {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{};
  queueInfo.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  queueInfo.queueFamilyIndex = queueFamily;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;
  // Half-precision arithmetic (`--precision half`: the Float16 capability) when the device has it;
  // nothing else of Vulkan 1.2 is enabled (the shaders keep 16-bit values out of buffers, so no
  // 16-bit storage feature is needed).
  VkPhysicalDeviceVulkan12Features has12{};
  has12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  VkPhysicalDeviceFeatures2 features{};
  features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  features.pNext = &has12;
  vk.vkGetPhysicalDeviceFeatures2(physical, &features);
  shaderFloat16 = has12.shaderFloat16 == VK_TRUE;
  // For raster passes (raster.cc): base passes store material-buffer words
  // from fragment shaders, and translucent forward passes blend with a second
  // colour output (dual-source), and a base pass writes only the attachments
  // it has outputs for (independent blend state). Enabled when the device has them.
  fragmentStores = features.features.fragmentStoresAndAtomics == VK_TRUE;
  dualSourceBlend = features.features.dualSrcBlend == VK_TRUE;
  independentBlend = features.features.independentBlend == VK_TRUE;  // base passes write some attachments only
  VkPhysicalDeviceVulkan12Features enable12{};
  enable12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  enable12.shaderFloat16 = shaderFloat16 ? VK_TRUE : VK_FALSE;
  VkPhysicalDeviceFeatures2 enable{};
  enable.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  enable.pNext = &enable12;
  enable.features.fragmentStoresAndAtomics = fragmentStores ? VK_TRUE : VK_FALSE;
  enable.features.dualSrcBlend = dualSourceBlend ? VK_TRUE : VK_FALSE;
  enable.features.independentBlend = independentBlend ? VK_TRUE : VK_FALSE;
  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.pNext = &enable;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  return succeeded(vk.vkCreateDevice(physical, &info, nullptr, &device), "vkCreateDevice (lavapipe)", diags);
}

bool Context::Impl::allocate(const VkMemoryRequirements& req, bool hostVisible, DispatchObjects& objs,
                             VkDeviceMemory* out, void** mapped, Diagnostics& diags) {
  const VkMemoryPropertyFlags need =
      hostVisible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT : 0;
  uint32_t type = memory.memoryTypeCount;
  for (uint32_t i = 0; i < memory.memoryTypeCount && type == memory.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & need) == need) type = i;
  if (type == memory.memoryTypeCount) {
    diags.fail("no memory type fits (type bits " + std::to_string(req.memoryTypeBits) +
               (hostVisible ? ", host-visible and coherent)" : ")"));
    return false;
  }
  VkMemoryAllocateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  info.allocationSize = req.size;
  info.memoryTypeIndex = type;
  if (!succeeded(vk.vkAllocateMemory(device, &info, nullptr, out), "vkAllocateMemory", diags)) return false;
  objs.memories.push_back(*out);
  return !mapped || succeeded(vk.vkMapMemory(device, *out, 0, VK_WHOLE_SIZE, 0, mapped), "vkMapMemory", diags);
}

bool Context::Impl::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, DispatchObjects& objs, VkBuffer* buffer,
                                 void** mapped, Diagnostics& diags) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (!succeeded(vk.vkCreateBuffer(device, &info, nullptr, buffer), "vkCreateBuffer", diags)) return false;
  objs.buffers.push_back(*buffer);
  return bindMemory(*buffer, objs, mapped, diags);
}

bool Context::Impl::createImage(VkFormat format, uint32_t width, uint32_t height, uint32_t layers, uint32_t mips,
                                bool cube, VkImageUsageFlags usage, VkImageViewType viewType, DispatchObjects& objs,
                                VkImage* image, VkImageView* view, Diagnostics& diags) {
  VkImageCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  info.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = mips;
  info.arrayLayers = layers;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  if (!succeeded(vk.vkCreateImage(device, &info, nullptr, image), "vkCreateImage", diags)) return false;
  objs.images.push_back(*image);
  if (!bindMemory(*image, objs, nullptr, diags)) return false;
  VkImageViewCreateInfo viewInfo{};
  viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  viewInfo.image = *image;
  viewInfo.viewType = viewType;
  viewInfo.format = format;
  viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mips, 0, layers};
  if (!succeeded(vk.vkCreateImageView(device, &viewInfo, nullptr, view), "vkCreateImageView", diags)) return false;
  objs.views.push_back(*view);
  return true;
}

bool Context::Impl::createSampler(Filter filter, Address address, Address addressV, DispatchObjects& objs,
                                  VkSampler* sampler, Diagnostics& diags) {
  const VkFilter f = filter == Filter::Linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  auto mode = [](Address a) {
    return a == Address::Repeat           ? VK_SAMPLER_ADDRESS_MODE_REPEAT
           : a == Address::MirroredRepeat ? VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT
                                          : VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  };
  const VkSamplerAddressMode a = mode(address);
  VkSamplerCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  info.magFilter = info.minFilter = f;
  info.mipmapMode = filter == Filter::Linear ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = info.addressModeW = a;
  info.addressModeV = mode(addressV);
  info.maxLod = VK_LOD_CLAMP_NONE;
  if (!succeeded(vk.vkCreateSampler(device, &info, nullptr, sampler), "vkCreateSampler", diags)) return false;
  objs.samplers.push_back(*sampler);
  return true;
}

void Context::Impl::destroy(DispatchObjects& objs) {
  if (objs.fence) vk.vkDestroyFence(device, objs.fence, nullptr);
  if (objs.timestamps) vk.vkDestroyQueryPool(device, objs.timestamps, nullptr);
  if (objs.commandBuffer) vk.vkFreeCommandBuffers(device, commandPool, 1, &objs.commandBuffer);
  for (VkFramebuffer f : objs.framebuffers) vk.vkDestroyFramebuffer(device, f, nullptr);
  for (VkRenderPass r : objs.renderPasses) vk.vkDestroyRenderPass(device, r, nullptr);
  for (VkDescriptorPool pool : objs.descriptorPools) vk.vkDestroyDescriptorPool(device, pool, nullptr);
  for (VkSampler s : objs.samplers) vk.vkDestroySampler(device, s, nullptr);
  for (VkImageView v : objs.views) vk.vkDestroyImageView(device, v, nullptr);
  for (VkImage i : objs.images) vk.vkDestroyImage(device, i, nullptr);
  for (VkBuffer b : objs.buffers) vk.vkDestroyBuffer(device, b, nullptr);
  for (VkDeviceMemory m : objs.memories) vk.vkFreeMemory(device, m, nullptr);
  objs = DispatchObjects{};
}

ComputePipeline::ComputePipeline(ShaderReflection reflection, std::unique_ptr<Impl> impl)
    : reflection_(std::move(reflection)), impl_(std::move(impl)) {}

ComputePipeline::~ComputePipeline() {
  Context::Impl* ctx = impl_->context;
  if (!ctx || ctx->lost) return;
  const VulkanFunctions& vk = ctx->vk;
  if (impl_->pipeline) vk.vkDestroyPipeline(ctx->device, impl_->pipeline, nullptr);
  if (impl_->layout) vk.vkDestroyPipelineLayout(ctx->device, impl_->layout, nullptr);
  for (VkDescriptorSetLayout l : impl_->setLayouts)
    if (l) vk.vkDestroyDescriptorSetLayout(ctx->device, l, nullptr);
}

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;

std::unique_ptr<Context> Context::create(const Options& options, Diagnostics& diags) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  Diagnostics setup(diags.file());
  if (!impl->createInstance(setup) || !impl->createDevice(setup) || !impl->noMessagesSince(0, "device setup", setup)) {
    diags.fail("GPU harness: " + setup.errorMessages());
    return nullptr;
  }
  return std::unique_ptr<Context>(new Context(std::move(impl)));
}

std::string Context::deviceName() const { return impl_->deviceName; }
std::string Context::driverInfo() const { return impl_->driverInfo; }
bool Context::shaderFloat16() const { return impl_->shaderFloat16; }

std::vector<std::string> Context::takeMessages() {
  std::lock_guard<std::mutex> lock(impl_->log->mutex);
  return std::exchange(impl_->log->messages, {});
}

std::unique_ptr<ComputePipeline> Context::createPipeline(const std::vector<uint32_t>& spirv, Diagnostics& diags) {
  Impl& c = *impl_;
  const VulkanFunctions& vk = c.vk;
  if (c.lost) {
    diags.fail("GPU harness: the Context is unusable after an earlier timeout or device loss");
    return nullptr;
  }
  ShaderReflection reflection;
  if (!reflectSpirv(spirv, &reflection, diags)) return nullptr;
  if (reflection.executionModel != kExecutionModelGLCompute) {
    diags.fail("createPipeline: entry point '" + reflection.entryPoint + "' is not a GLCompute entry point");
    return nullptr;
  }
  for (const DescriptorBinding& b : reflection.bindings) {
    if (b.count != 1) {
      diags.fail("createPipeline: descriptor arrays are not supported (" + describe(b) + ")");
      return nullptr;
    }
  }
  const size_t start = c.messageCount();
  auto impl = std::make_unique<ComputePipeline::Impl>();
  impl->context = &c;
  std::unique_ptr<ComputePipeline> pipeline(new ComputePipeline(reflection, std::move(impl)));
  ComputePipeline::Impl& p = *pipeline->impl_;

  const uint32_t setCount = reflection.bindings.empty() ? 0 : reflection.bindings.back().set + 1;
  p.setLayouts.assign(setCount, VK_NULL_HANDLE);
  for (uint32_t set = 0; set < setCount; ++set) {
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    for (const DescriptorBinding& b : reflection.bindings)
      if (b.set == set) bindings.push_back({b.binding, descriptorType(b.kind), 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    VkDescriptorSetLayoutCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    info.bindingCount = static_cast<uint32_t>(bindings.size());
    info.pBindings = bindings.data();
    if (!succeeded(vk.vkCreateDescriptorSetLayout(c.device, &info, nullptr, &p.setLayouts[set]),
                   "vkCreateDescriptorSetLayout (set " + std::to_string(set) + ")", diags))
      return nullptr;
  }
  VkPipelineLayoutCreateInfo layoutInfo{};
  layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layoutInfo.setLayoutCount = setCount;
  layoutInfo.pSetLayouts = p.setLayouts.data();
  if (!succeeded(vk.vkCreatePipelineLayout(c.device, &layoutInfo, nullptr, &p.layout), "vkCreatePipelineLayout", diags))
    return nullptr;

  VkShaderModuleCreateInfo moduleInfo{};
  moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  moduleInfo.codeSize = spirv.size() * sizeof(uint32_t);
  moduleInfo.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  if (!succeeded(vk.vkCreateShaderModule(c.device, &moduleInfo, nullptr, &module), "vkCreateShaderModule", diags))
    return nullptr;
  VkComputePipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = reflection.entryPoint.c_str();
  info.layout = p.layout;
  const VkResult r = vk.vkCreateComputePipelines(c.device, VK_NULL_HANDLE, 1, &info, nullptr, &p.pipeline);
  vk.vkDestroyShaderModule(c.device, module, nullptr);
  if (!succeeded(r, "vkCreateComputePipelines", diags)) return nullptr;
  if (!c.noMessagesSince(start, "createPipeline", diags)) return nullptr;
  return pipeline;
}

bool Context::Impl::allocateSets(const std::vector<VkDescriptorSetLayout>& setLayouts, const ShaderReflection& refl,
                                 DispatchObjects& objs, Bindings& b, Diagnostics& diags) {
  b.sets.assign(setLayouts.size(), VK_NULL_HANDLE);
  if (b.sets.empty()) return true;
  std::map<VkDescriptorType, uint32_t> typeCounts;
  for (const DescriptorBinding& binding : refl.bindings) ++typeCounts[descriptorType(binding.kind)];
  std::vector<VkDescriptorPoolSize> sizes;
  for (const auto& [type, count] : typeCounts) sizes.push_back({type, count});
  VkDescriptorPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  poolInfo.maxSets = static_cast<uint32_t>(b.sets.size());
  poolInfo.poolSizeCount = static_cast<uint32_t>(sizes.size());
  poolInfo.pPoolSizes = sizes.data();
  VkDescriptorPool pool;
  if (!succeeded(vk.vkCreateDescriptorPool(device, &poolInfo, nullptr, &pool), "vkCreateDescriptorPool", diags))
    return false;
  objs.descriptorPools.push_back(pool);
  VkDescriptorSetAllocateInfo alloc{};
  alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  alloc.descriptorPool = pool;
  alloc.descriptorSetCount = static_cast<uint32_t>(b.sets.size());
  alloc.pSetLayouts = setLayouts.data();
  return succeeded(vk.vkAllocateDescriptorSets(device, &alloc, b.sets.data()), "vkAllocateDescriptorSets", diags);
}

bool Context::Impl::bindResources(const ShaderReflection& refl, Resources& resources, DispatchObjects& objs,
                                  Bindings& b, Diagnostics& diags,
                                  const std::map<std::pair<uint32_t, uint32_t>, VkDescriptorImageInfo>* shared) {
  b.bufferInfos.reserve(refl.bindings.size());
  b.imageInfos.reserve(refl.bindings.size());
  for (const DescriptorBinding& binding : refl.bindings) {
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = b.sets[binding.set];
    w.dstBinding = binding.binding;
    w.descriptorCount = 1;
    w.descriptorType = descriptorType(binding.kind);
    if (shared) {
      if (auto it = shared->find({binding.set, binding.binding}); it != shared->end()) {
        w.pImageInfo = &it->second;
        b.writes.push_back(w);
        continue;
      }
    }
    Resource& resource = resources.at({binding.set, binding.binding});
    Diagnostics failure(diags.file());  // the binding's failure, reported below naming the binding
    bool bound = true;
    if (auto* buf = std::get_if<BufferResource>(&resource)) {
      bound = bindBuffer(binding, *buf, objs, b, w, failure);
    } else if (auto* img = std::get_if<ImageResource>(&resource)) {
      bound = bindImage(binding, *img, objs, b, w, failure);
    } else if (auto* smp = std::get_if<SamplerResource>(&resource)) {
      VkSampler sampler;
      bound = createSampler(smp->filter, smp->address, smp->addressV.value_or(smp->address), objs, &sampler, failure);
      if (bound) {
        b.imageInfos.push_back({sampler, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED});
        w.pImageInfo = &b.imageInfos.back();
      }
    } else {
      bound = bindStorageImage(binding, std::get<StorageImageResource>(resource), objs, b, w, failure);
    }
    if (!bound) {
      diags.fail(describe(binding) + ": " + failure.errorMessages());
      return false;
    }
    b.writes.push_back(w);
  }
  if (!b.writes.empty())
    vk.vkUpdateDescriptorSets(device, static_cast<uint32_t>(b.writes.size()), b.writes.data(), 0, nullptr);
  return true;
}

bool Context::Impl::bindBuffer(const DescriptorBinding& binding, BufferResource& buf, DispatchObjects& objs,
                               Bindings& b, VkWriteDescriptorSet& w, Diagnostics& diags) {
  if (buf.data.empty()) return fail(diags, "BufferResource::data is empty (it gives the buffer's size)");
  VkBuffer buffer;
  void* mapped;
  const VkBufferUsageFlags usage = binding.kind == DescriptorKind::UniformBuffer ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
                                                                                : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  if (!createBuffer(buf.data.size(), usage, objs, &buffer, &mapped, diags)) return false;
  if (buf.output && buf.initialized) {
    std::memcpy(mapped, buf.data.data(), buf.data.size());
    b.readbacks.push_back({&buf.data, mapped, buf.data.size()});
  } else if (buf.output) {
    auto* bytes = static_cast<unsigned char*>(mapped);
    for (size_t i = 0; i < buf.data.size(); ++i) bytes[i] = static_cast<unsigned char>(kQuietNan >> (8 * (i % 4)));
    b.readbacks.push_back({&buf.data, mapped, buf.data.size()});
  } else {
    std::memcpy(mapped, buf.data.data(), buf.data.size());
  }
  b.bufferInfos.push_back({buffer, 0, VK_WHOLE_SIZE});
  w.pBufferInfo = &b.bufferInfos.back();
  return true;
}

bool Context::Impl::bindImage(const DescriptorBinding& binding, const ImageResource& img, DispatchObjects& objs,
                              Bindings& b, VkWriteDescriptorSet& w, Diagnostics& diags) {
  const bool cube = binding.dim == ImageDim::Cube;
  if (img.width == 0 || img.height == 0 || img.layers == 0 || img.mips.empty())
    return fail(diags, "ImageResource needs a non-zero size, layers and at least one mip level");
  if (cube && (binding.arrayed || img.layers != 6 || img.width != img.height))
    return fail(diags, "a cube map needs layers == 6, width == height (cube arrays are not supported)");
  if (!cube && (binding.dim != ImageDim::Dim2D || (!binding.arrayed && img.layers != 1)))
    return fail(diags, "only 2D, 2D array and cube images are supported (a non-arrayed 2D image has one layer)");
  const uint32_t levels = static_cast<uint32_t>(img.mips.size());
  if (levels > 32 || (std::max(img.width, img.height) >> (levels - 1)) == 0)
    return fail(diags, "too many mip levels (" + std::to_string(levels) + ") for the image size");
  ImageUpload up{VK_NULL_HANDLE, img.layers, levels, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  size_t totalFloats = 0;
  for (uint32_t l = 0; l < levels; ++l) {
    const uint32_t width = std::max(1u, img.width >> l), height = std::max(1u, img.height >> l);
    const size_t want = size_t{width} * height * img.layers * 4;
    if (img.mips[l].size() != want)
      return fail(diags, "mip " + std::to_string(l) + " has " + std::to_string(img.mips[l].size()) +
                             " floats, expected " + std::to_string(want) + " (" + std::to_string(width) + "x" +
                             std::to_string(height) + "x" + std::to_string(img.layers) + " RGBA)");
    VkBufferImageCopy region{};
    region.bufferOffset = totalFloats * sizeof(float);
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, img.layers};
    region.imageExtent = {width, height, 1};
    up.regions.push_back(region);
    totalFloats += img.mips[l].size();
  }
  void* mapped;
  VkImageView view;
  const VkImageViewType viewType =
      cube ? VK_IMAGE_VIEW_TYPE_CUBE : binding.arrayed ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  if (!createBuffer(totalFloats * sizeof(float), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, objs, &up.staging, &mapped, diags) ||
      !createImage(VK_FORMAT_R32G32B32A32_SFLOAT, img.width, img.height, img.layers, levels, cube,
                   VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, viewType, objs, &up.image, &view, diags))
    return false;
  for (uint32_t l = 0; l < levels; ++l)
    std::memcpy(static_cast<char*>(mapped) + up.regions[l].bufferOffset, img.mips[l].data(),
                img.mips[l].size() * sizeof(float));
  b.uploads.push_back(std::move(up));
  VkSampler sampler = VK_NULL_HANDLE;
  if (binding.kind == DescriptorKind::CombinedImageSampler &&
      !createSampler(img.filter, img.address, img.addressV.value_or(img.address), objs, &sampler, diags))
    return false;
  b.imageInfos.push_back({sampler, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
  w.pImageInfo = &b.imageInfos.back();
  return true;
}

bool Context::Impl::bindStorageImage(const DescriptorBinding& binding, StorageImageResource& si, DispatchObjects& objs,
                                     Bindings& b, VkWriteDescriptorSet& w, Diagnostics& diags) {
  if (si.width == 0 || si.height == 0 || si.layers == 0)
    return fail(diags, "StorageImageResource needs a non-zero size");
  if (binding.dim != ImageDim::Dim2D || (!binding.arrayed && si.layers != 1))
    return fail(diags, "only 2D and 2D array storage images are supported (a non-arrayed one has one layer)");
  const bool uint = si.format == StorageFormat::R32Uint;
  const size_t texel = uint ? 4 : 16;
  ImageUpload up{VK_NULL_HANDLE, si.layers, 1, VK_IMAGE_LAYOUT_GENERAL};
  for (int i = 0; i < 4; ++i) up.clear.uint32[i] = uint ? 0xffffffffu : kQuietNan;  // NaN bits for float
  Readback rb{&si.data, nullptr, size_t{si.width} * si.height * si.layers * texel};
  VkImageView view;
  void* mapped;
  const VkImageViewType viewType = binding.arrayed ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D;
  if (!createImage(uint ? VK_FORMAT_R32_UINT : VK_FORMAT_R32G32B32A32_SFLOAT, si.width, si.height, si.layers, 1, false,
                   VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                   viewType, objs, &up.image, &view, diags) ||
      !createBuffer(rb.size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, objs, &rb.buffer, &mapped, diags))
    return false;
  if (si.upload) {  // the image's contents come from `data`, through a staging buffer
    if (si.data.size() != rb.size)
      return fail(diags, "StorageImageResource::data has " + std::to_string(si.data.size()) +
                             " bytes, expected " + std::to_string(rb.size));
    void* staged;
    if (!createBuffer(rb.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, objs, &up.staging, &staged, diags)) return false;
    std::memcpy(staged, si.data.data(), rb.size);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, si.layers};
    region.imageExtent = {si.width, si.height, 1};
    up.regions.push_back(region);
  }
  rb.mapped = mapped;
  rb.image = up.image;
  rb.region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, si.layers};
  rb.region.imageExtent = {si.width, si.height, 1};
  b.uploads.push_back(std::move(up));
  b.readbacks.push_back(rb);
  b.imageInfos.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL});
  w.pImageInfo = &b.imageInfos.back();
  return true;
}

bool Context::Impl::record(const ComputePipeline::Impl& p, const Bindings& b, const uint32_t groups[3], bool timed,
                           DispatchObjects& objs, Diagnostics& diags) {
  VkCommandBufferAllocateInfo cbInfo{};
  cbInfo.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cbInfo.commandPool = commandPool;
  cbInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbInfo.commandBufferCount = 1;
  if (!succeeded(vk.vkAllocateCommandBuffers(device, &cbInfo, &objs.commandBuffer), "vkAllocateCommandBuffers", diags))
    return false;
  const VkCommandBuffer cmd = objs.commandBuffer;
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (!succeeded(vk.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer", diags)) return false;
  auto barriers = [&](VkPipelineStageFlags src, VkPipelineStageFlags dst,
                      const std::vector<VkImageMemoryBarrier>& list) {
    if (!list.empty())
      vk.vkCmdPipelineBarrier(cmd, src, dst, 0, 0, nullptr, 0, nullptr, static_cast<uint32_t>(list.size()),
                              list.data());
  };
  std::vector<VkImageMemoryBarrier> before, after, out;
  for (const ImageUpload& up : b.uploads) {
    before.push_back(imageBarrier(up.image, up.layers, up.mipLevels, VK_IMAGE_LAYOUT_UNDEFINED,
                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT));
    after.push_back(imageBarrier(up.image, up.layers, up.mipLevels, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                 up.finalLayout, VK_ACCESS_TRANSFER_WRITE_BIT,
                                 VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT));
  }
  barriers(VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, before);
  for (const ImageUpload& up : b.uploads) {
    if (up.staging) {
      vk.vkCmdCopyBufferToImage(cmd, up.staging, up.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                static_cast<uint32_t>(up.regions.size()), up.regions.data());
    } else {
      const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, up.layers};
      vk.vkCmdClearColorImage(cmd, up.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &up.clear, 1, &range);
    }
  }
  barriers(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, after);
  vk.vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
  if (!b.sets.empty())
    vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, static_cast<uint32_t>(b.sets.size()),
                               b.sets.data(), 0, nullptr);
  if (timed) {
    VkQueryPoolCreateInfo q{};
    q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    q.queryType = VK_QUERY_TYPE_TIMESTAMP;
    q.queryCount = 2;
    if (!succeeded(vk.vkCreateQueryPool(device, &q, nullptr, &objs.timestamps), "vkCreateQueryPool", diags)) return false;
    vk.vkCmdResetQueryPool(cmd, objs.timestamps, 0, 2);
    vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, objs.timestamps, 0);
  }
  vk.vkCmdDispatch(cmd, groups[0], groups[1], groups[2]);
  if (timed) vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, objs.timestamps, 1);
  for (const Readback& rb : b.readbacks)
    if (rb.image)
      out.push_back(imageBarrier(rb.image, rb.region.imageSubresource.layerCount, 1, VK_IMAGE_LAYOUT_GENERAL,
                                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
                                 VK_ACCESS_TRANSFER_READ_BIT));
  barriers(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, out);
  for (const Readback& rb : b.readbacks)
    if (rb.image)
      vk.vkCmdCopyImageToBuffer(cmd, rb.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, rb.buffer, 1, &rb.region);
  VkMemoryBarrier toHost{};
  toHost.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  toHost.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                          VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0, nullptr);
  return succeeded(vk.vkEndCommandBuffer(cmd), "vkEndCommandBuffer", diags);
}

bool Context::Impl::submitAndWait(DispatchObjects& objs, Diagnostics& diags) {
  VkFenceCreateInfo fenceInfo{};
  fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  if (!succeeded(vk.vkCreateFence(device, &fenceInfo, nullptr, &objs.fence), "vkCreateFence", diags)) return false;
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &objs.commandBuffer;
  if (!succeeded(vk.vkQueueSubmit(queue, 1, &submit, objs.fence), "vkQueueSubmit", diags)) return false;
  const VkResult waited = vk.vkWaitForFences(device, 1, &objs.fence, VK_TRUE, options.fenceTimeoutNs);
  if (waited == VK_SUCCESS) return true;
  lost = true;  // the work may still be running: its objects are leaked, the Context is done
  lostFence = objs.fence;
  return fail(diags, waited == VK_TIMEOUT ? "vkWaitForFences timed out after " +
                                               std::to_string(options.fenceTimeoutNs / 1000000) +
                                               " ms (the Context is unusable now)"
                                         : "vkWaitForFences failed: " + vkResultName(waited));
}

bool Context::Impl::readBack(const Bindings& b, DispatchObjects& objs, double* dispatchNs, Diagnostics& diags) {
  for (const Readback& rb : b.readbacks) {
    rb.target->resize(rb.size);
    std::memcpy(rb.target->data(), rb.mapped, rb.size);
  }
  if (!dispatchNs) return true;
  uint64_t t[2] = {0, 0};
  if (!succeeded(vk.vkGetQueryPoolResults(device, objs.timestamps, 0, 2, sizeof t, t, sizeof(uint64_t),
                                          VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                 "vkGetQueryPoolResults", diags))
    return false;
  *dispatchNs = static_cast<double>(t[1] - t[0]) * timestampPeriodNs;
  return true;
}

bool Context::dispatch(const ComputePipeline& pipeline, Resources& resources, uint32_t groupsX, uint32_t groupsY,
                       uint32_t groupsZ, Diagnostics& diags, double* dispatchNs) {
  Impl& c = *impl_;
  const ShaderReflection& refl = pipeline.reflection();
  const ComputePipeline::Impl& p = *pipeline.impl_;
  if (c.lost || p.context != &c) {
    diags.fail(c.lost ? "dispatch: the Context is unusable after an earlier timeout or device loss"
                      : "dispatch: the pipeline belongs to another Context");
    return false;
  }
  if (!resourcesMatch(refl, resources, diags)) return false;
  const size_t start = c.messageCount();
  DispatchObjects objs;
  Bindings bindings;
  const uint32_t groups[3] = {groupsX, groupsY, groupsZ};
  Diagnostics failure(diags.file());  // the failed step's, reported below as the dispatch's
  const bool ran = c.allocateSets(p.setLayouts, refl, objs, bindings, failure) &&
                   c.bindResources(refl, resources, objs, bindings, failure) &&
                   c.record(p, bindings, groups, dispatchNs != nullptr, objs, failure) &&
                   c.submitAndWait(objs, failure) && c.readBack(bindings, objs, dispatchNs, failure);
  if (!c.lost) c.destroy(objs);
  if (!ran) diags.fail("dispatch: " + failure.errorMessages());
  const bool quiet = c.noMessagesSince(start, "dispatch of entry point '" + refl.entryPoint + "'", diags);
  return ran && quiet;
}

}  // namespace substratec::gpu
