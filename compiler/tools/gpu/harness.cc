// The Vulkan compute harness on lavapipe (see harness.h): instance/device setup
// with the validation layer, pipelines built from SPIR-V reflection, and
// one-shot dispatches with per-dispatch buffers, images and samplers.
#include "gpu/harness.h"

#include <stdlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <mutex>

#include "gpu/vulkan_loader.h"

namespace substratec::gpu {
namespace {

constexpr const char* kLavapipeIcd = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint32_t kQuietNan = 0x7fc00000u;
constexpr uint32_t kExecutionModelGLCompute = 5;

/// Validation messages, appended by the debug-utils callback (any thread).
struct MessageLog {
  std::mutex mutex;
  std::vector<std::string> messages;
};

/// The VK_EXT_debug_utils callback: records warnings and errors into the MessageLog.
VKAPI_ATTR VkBool32 VKAPI_CALL recordMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT types,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  std::string text = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "ERROR" : "WARNING";
  text += (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)    ? " [validation] "
          : (types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT) ? " [performance] "
                                                                       : " [general] ";
  text += data && data->pMessage ? data->pMessage : "(no message)";
  auto* log = static_cast<MessageLog*>(user);
  std::lock_guard<std::mutex> lock(log->mutex);
  log->messages.push_back(std::move(text));
  return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(MessageLog* log) {
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

/// Sets `*error` to "<call> failed: <VkResult>" unless `result` is VK_SUCCESS.
bool succeeded(VkResult result, const std::string& call, std::string* error) {
  if (result == VK_SUCCESS) return true;
  *error = call + " failed: " + vkResultName(result);
  return false;
}

VkDescriptorType descriptorType(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::UniformBuffer: return VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    case DescriptorKind::StorageBuffer: return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case DescriptorKind::CombinedImageSampler: return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    case DescriptorKind::SampledImage: return VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    case DescriptorKind::StorageImage: return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    case DescriptorKind::Sampler: return VK_DESCRIPTOR_TYPE_SAMPLER;
  }
  return VK_DESCRIPTOR_TYPE_MAX_ENUM;
}

/// "set 0 binding 2 ('tex', CombinedImageSampler)" for error messages.
std::string describe(const DescriptorBinding& b) {
  return "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" + b.name + "', " +
         descriptorKindName(b.kind) + ")";
}

/// Index of the Resource alternative a descriptor kind needs.
size_t resourceIndexFor(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::UniformBuffer:
    case DescriptorKind::StorageBuffer: return 0;
    case DescriptorKind::CombinedImageSampler:
    case DescriptorKind::SampledImage: return 1;
    case DescriptorKind::Sampler: return 2;
    case DescriptorKind::StorageImage: return 3;
  }
  return 0;
}

constexpr const char* kResourceNames[] = {"BufferResource", "ImageResource", "SamplerResource", "StorageImageResource"};

/// The Vulkan objects of one dispatch, destroyed together.
struct DispatchObjects {
  std::vector<VkBuffer> buffers;
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkSampler> samplers;
  std::vector<VkDeviceMemory> memories;
  VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
  VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkQueryPool timestamps = VK_NULL_HANDLE;  // two timestamps around the dispatch, when timed
};

/// An image to fill before the dispatch: from a staging buffer, or cleared.
struct ImageUpload {
  VkImage image;
  uint32_t layers, mipLevels;
  VkImageLayout finalLayout;
  VkBuffer staging = VK_NULL_HANDLE;  // null: clear with `clear`
  std::vector<VkBufferImageCopy> regions{};
  VkClearColorValue clear{};
};

/// A copy from mapped memory back into a resource after the dispatch.
struct Readback {
  std::vector<std::byte>* target;
  const void* mapped;
  size_t size;
  VkImage image = VK_NULL_HANDLE;  // non-null: first copy the image into `buffer`
  VkBuffer buffer = VK_NULL_HANDLE;
  VkBufferImageCopy region{};
};

}  // namespace

struct Context::Impl {
  VulkanFunctions vk;
  Options options;
  std::unique_ptr<MessageLog> log = std::make_unique<MessageLog>();  // the messenger's user data
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory{};
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool commandPool = VK_NULL_HANDLE;
  std::string deviceName, driverInfo;
  double timestampPeriodNs = 1;  // VkPhysicalDeviceLimits::timestampPeriod
  bool shaderFloat16 = false;    // enabled on the device (VkPhysicalDeviceVulkan12Features)
  bool lost = false;  // a fence wait timed out or the device was lost: leak, never wait

  ~Impl() {
    if (lost) {  // objects may still be in use by the device; leaking them (and the log) is the only safe choice
      (void)log.release();
      return;
    }
    if (device) {
      vk.vkDeviceWaitIdle(device);
      if (commandPool) vk.vkDestroyCommandPool(device, commandPool, nullptr);
      vk.vkDestroyDevice(device, nullptr);
    }
    if (messenger) vk.vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
    if (instance) vk.vkDestroyInstance(instance, nullptr);
  }

  size_t messageCount() {
    std::lock_guard<std::mutex> lock(log->mutex);
    return log->messages.size();
  }

  /// Appends the messages recorded since `start` to `*out` (after a newline if it is not empty); false if
  /// there were any.
  bool noMessagesSince(size_t start, const std::string& during, std::string* out) {
    std::lock_guard<std::mutex> lock(log->mutex);
    if (log->messages.size() <= start) return true;
    std::string text = "the validation layer reported " + std::to_string(log->messages.size() - start) +
                       " message(s) during " + during + ":";
    for (size_t i = start; i < log->messages.size(); ++i) text += "\n  " + log->messages[i];
    *out = out->empty() ? text : *out + "\n" + text;
    return false;
  }

  /// Loads libvulkan, pins lavapipe, creates the instance with the validation layer and the messenger.
  bool createInstance(std::string* error);
  /// Picks lavapipe, creates the device with one compute queue (and shaderFloat16 when it has it) and the
  /// command pool.
  bool createDevice(std::string* error);
  /// Allocates memory for `req` (host-visible + coherent and mapped when `hostVisible`), owned by `objs`.
  bool allocate(const VkMemoryRequirements& req, bool hostVisible, DispatchObjects& objs, VkDeviceMemory* out,
                void** mapped, std::string* error);
  /// A host-visible, mapped buffer owned by `objs`.
  bool createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, DispatchObjects& objs, VkBuffer* buffer,
                    void** mapped, std::string* error);
  /// An optimal-tiling 2D image (cube-compatible when `cube`) with its memory and one view, owned by `objs`.
  bool createImage(VkFormat format, uint32_t width, uint32_t height, uint32_t layers, uint32_t mips, bool cube,
                   VkImageUsageFlags usage, VkImageViewType viewType, DispatchObjects& objs, VkImage* image,
                   VkImageView* view, std::string* error);
  /// A sampler (filter for min/mag/mips, one address mode for u/v/w, no LOD clamp) owned by `objs`.
  bool createSampler(Filter filter, Address address, DispatchObjects& objs, VkSampler* sampler, std::string* error);
  /// Destroys everything in `objs` (only once the device no longer uses it).
  void destroy(DispatchObjects& objs);
};

struct ComputePipeline::Impl {
  Context::Impl* context = nullptr;
  std::vector<VkDescriptorSetLayout> setLayouts;  // index = set number
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

bool Context::Impl::createInstance(std::string* error) {
  if (!loadGlobalFunctions(&vk, error)) return false;
  // Pin the loader to lavapipe unless the caller chose drivers (an empty variable counts as unset: the
  // loader would find no driver at all). Other ICDs (intel, radeon) must never be picked.
  auto unset = [](const char* name) { return !getenv(name) || !*getenv(name); };
  if (unset("VK_DRIVER_FILES") && unset("VK_ICD_FILENAMES")) {
    if (!std::filesystem::exists(kLavapipeIcd)) {
      *error = std::string("lavapipe's ICD file ") + kLavapipeIcd + " is missing (Debian: mesa-vulkan-drivers)";
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
  if (!succeeded(vk.vkEnumerateInstanceLayerProperties(&count, nullptr), "vkEnumerateInstanceLayerProperties", error))
    return false;
  std::vector<VkLayerProperties> layers(count);
  if (!succeeded(vk.vkEnumerateInstanceLayerProperties(&count, layers.data()), "vkEnumerateInstanceLayerProperties",
                 error))
    return false;
  if (std::none_of(layers.begin(), layers.begin() + count,
                   [](const VkLayerProperties& l) { return std::strcmp(l.layerName, kValidationLayer) == 0; })) {
    *error = std::string("the Vulkan validation layer ") + kValidationLayer +
             " is not installed (Debian: vulkan-validationlayers); GPU results are not trusted without it";
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
  if (!succeeded(created, "vkCreateInstance (with " + std::string(kValidationLayer) + ", VK_EXT_debug_utils, " +
                              VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME + ")",
                 error)) {
    if (created == VK_ERROR_INCOMPATIBLE_DRIVER) *error += driverHint();
    return false;
  }
  if (!loadInstanceFunctions(&vk, instance, error)) return false;
  return succeeded(vk.vkCreateDebugUtilsMessengerEXT(instance, &debugInfo, nullptr, &messenger),
                   "vkCreateDebugUtilsMessengerEXT", error);
}

bool Context::Impl::createDevice(std::string* error) {
  uint32_t count = 0;
  if (!succeeded(vk.vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices", error)) {
    *error += driverHint();
    return false;
  }
  std::vector<VkPhysicalDevice> devices(count);
  if (!succeeded(vk.vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices", error))
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
    *error = "no lavapipe (VK_DRIVER_ID_MESA_LLVMPIPE) device among: " + (seen.empty() ? std::string("none") : seen) +
             driverHint();
    return false;
  }
  vk.vkGetPhysicalDeviceMemoryProperties(physical, &memory);

  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vk.vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
  auto family = std::find_if(families.begin(), families.end(),
                             [](const VkQueueFamilyProperties& f) { return f.queueFlags & VK_QUEUE_COMPUTE_BIT; });
  if (family == families.end()) {
    *error = "lavapipe reports no compute queue family";
    return false;
  }
  queueFamily = static_cast<uint32_t>(family - families.begin());
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
  VkPhysicalDeviceVulkan12Features enable12{};
  enable12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  enable12.shaderFloat16 = shaderFloat16 ? VK_TRUE : VK_FALSE;
  VkDeviceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  info.pNext = &enable12;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  if (!succeeded(vk.vkCreateDevice(physical, &info, nullptr, &device), "vkCreateDevice (lavapipe)", error)) return false;
  if (!loadDeviceFunctions(&vk, device, error)) return false;
  vk.vkGetDeviceQueue(device, queueFamily, 0, &queue);
  VkCommandPoolCreateInfo poolInfo{};
  poolInfo.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  poolInfo.queueFamilyIndex = queueFamily;
  return succeeded(vk.vkCreateCommandPool(device, &poolInfo, nullptr, &commandPool), "vkCreateCommandPool", error);
}

bool Context::Impl::allocate(const VkMemoryRequirements& req, bool hostVisible, DispatchObjects& objs,
                             VkDeviceMemory* out, void** mapped, std::string* error) {
  const VkMemoryPropertyFlags need =
      hostVisible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT : 0;
  uint32_t type = memory.memoryTypeCount;
  for (uint32_t i = 0; i < memory.memoryTypeCount && type == memory.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & need) == need) type = i;
  if (type == memory.memoryTypeCount) {
    *error = "no memory type fits (type bits " + std::to_string(req.memoryTypeBits) +
             (hostVisible ? ", host-visible and coherent)" : ")");
    return false;
  }
  VkMemoryAllocateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  info.allocationSize = req.size;
  info.memoryTypeIndex = type;
  if (!succeeded(vk.vkAllocateMemory(device, &info, nullptr, out), "vkAllocateMemory", error)) return false;
  objs.memories.push_back(*out);
  return !mapped || succeeded(vk.vkMapMemory(device, *out, 0, VK_WHOLE_SIZE, 0, mapped), "vkMapMemory", error);
}

bool Context::Impl::createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, DispatchObjects& objs, VkBuffer* buffer,
                                 void** mapped, std::string* error) {
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  if (!succeeded(vk.vkCreateBuffer(device, &info, nullptr, buffer), "vkCreateBuffer", error)) return false;
  objs.buffers.push_back(*buffer);
  VkMemoryRequirements req;
  vk.vkGetBufferMemoryRequirements(device, *buffer, &req);
  VkDeviceMemory mem;
  return allocate(req, true, objs, &mem, mapped, error) &&
         succeeded(vk.vkBindBufferMemory(device, *buffer, mem, 0), "vkBindBufferMemory", error);
}

bool Context::Impl::createImage(VkFormat format, uint32_t width, uint32_t height, uint32_t layers, uint32_t mips,
                                bool cube, VkImageUsageFlags usage, VkImageViewType viewType, DispatchObjects& objs,
                                VkImage* image, VkImageView* view, std::string* error) {
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
  if (!succeeded(vk.vkCreateImage(device, &info, nullptr, image), "vkCreateImage", error)) return false;
  objs.images.push_back(*image);
  VkMemoryRequirements req;
  vk.vkGetImageMemoryRequirements(device, *image, &req);
  VkDeviceMemory mem;
  if (!allocate(req, false, objs, &mem, nullptr, error) ||
      !succeeded(vk.vkBindImageMemory(device, *image, mem, 0), "vkBindImageMemory", error))
    return false;
  VkImageViewCreateInfo viewInfo{};
  viewInfo.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  viewInfo.image = *image;
  viewInfo.viewType = viewType;
  viewInfo.format = format;
  viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mips, 0, layers};
  if (!succeeded(vk.vkCreateImageView(device, &viewInfo, nullptr, view), "vkCreateImageView", error)) return false;
  objs.views.push_back(*view);
  return true;
}

bool Context::Impl::createSampler(Filter filter, Address address, DispatchObjects& objs, VkSampler* sampler,
                                  std::string* error) {
  const VkFilter f = filter == Filter::Linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  const VkSamplerAddressMode a =
      address == Address::Repeat ? VK_SAMPLER_ADDRESS_MODE_REPEAT : VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  VkSamplerCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  info.magFilter = info.minFilter = f;
  info.mipmapMode = filter == Filter::Linear ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = info.addressModeV = info.addressModeW = a;
  info.maxLod = VK_LOD_CLAMP_NONE;
  if (!succeeded(vk.vkCreateSampler(device, &info, nullptr, sampler), "vkCreateSampler", error)) return false;
  objs.samplers.push_back(*sampler);
  return true;
}

void Context::Impl::destroy(DispatchObjects& objs) {
  if (objs.fence) vk.vkDestroyFence(device, objs.fence, nullptr);
  if (objs.timestamps) vk.vkDestroyQueryPool(device, objs.timestamps, nullptr);
  if (objs.commandBuffer) vk.vkFreeCommandBuffers(device, commandPool, 1, &objs.commandBuffer);
  if (objs.descriptorPool) vk.vkDestroyDescriptorPool(device, objs.descriptorPool, nullptr);
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

std::unique_ptr<Context> Context::create(const Options& options, std::string* error) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  std::string why;
  if (!impl->createInstance(&why) || !impl->createDevice(&why) || !impl->noMessagesSince(0, "device setup", &why)) {
    *error = "GPU harness: " + why;
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

std::unique_ptr<ComputePipeline> Context::createPipeline(const std::vector<uint32_t>& spirv, std::string* error) {
  Impl& c = *impl_;
  const VulkanFunctions& vk = c.vk;
  if (c.lost) {
    *error = "GPU harness: the Context is unusable after an earlier timeout or device loss";
    return nullptr;
  }
  ShaderReflection reflection;
  if (!reflectSpirv(spirv, &reflection, error)) return nullptr;
  if (reflection.executionModel != kExecutionModelGLCompute) {
    *error = "createPipeline: entry point '" + reflection.entryPoint + "' is not a GLCompute entry point";
    return nullptr;
  }
  for (const DescriptorBinding& b : reflection.bindings) {
    if (b.count != 1) {
      *error = "createPipeline: descriptor arrays are not supported (" + describe(b) + ")";
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
                   "vkCreateDescriptorSetLayout (set " + std::to_string(set) + ")", error))
      return nullptr;
  }
  VkPipelineLayoutCreateInfo layoutInfo{};
  layoutInfo.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  layoutInfo.setLayoutCount = setCount;
  layoutInfo.pSetLayouts = p.setLayouts.data();
  if (!succeeded(vk.vkCreatePipelineLayout(c.device, &layoutInfo, nullptr, &p.layout), "vkCreatePipelineLayout", error))
    return nullptr;

  VkShaderModuleCreateInfo moduleInfo{};
  moduleInfo.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  moduleInfo.codeSize = spirv.size() * sizeof(uint32_t);
  moduleInfo.pCode = spirv.data();
  VkShaderModule module = VK_NULL_HANDLE;
  if (!succeeded(vk.vkCreateShaderModule(c.device, &moduleInfo, nullptr, &module), "vkCreateShaderModule", error))
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
  if (!succeeded(r, "vkCreateComputePipelines", error)) return nullptr;
  std::string messages;
  if (!c.noMessagesSince(start, "createPipeline", &messages)) {
    *error = messages;
    return nullptr;
  }
  return pipeline;
}

bool Context::dispatch(const ComputePipeline& pipeline, Resources& resources, uint32_t groupsX, uint32_t groupsY,
                       uint32_t groupsZ, std::string* error, double* dispatchNs) {
  Impl& c = *impl_;
  const VulkanFunctions& vk = c.vk;
  const ShaderReflection& refl = pipeline.reflection();
  const ComputePipeline::Impl& p = *pipeline.impl_;
  if (c.lost || p.context != &c) {
    *error = c.lost ? "dispatch: the Context is unusable after an earlier timeout or device loss"
                    : "dispatch: the pipeline belongs to another Context";
    return false;
  }
  // Every binding gets a resource of its kind, and every resource is used.
  for (const DescriptorBinding& b : refl.bindings) {
    auto it = resources.find({b.set, b.binding});
    if (it == resources.end()) {
      *error = "dispatch: no resource for " + describe(b) + " of entry point '" + refl.entryPoint + "'";
      return false;
    }
    const size_t want = resourceIndexFor(b.kind);
    if (it->second.index() != want) {
      *error = "dispatch: " + describe(b) + " needs a " + kResourceNames[want] + ", got a " +
               kResourceNames[it->second.index()];
      return false;
    }
  }
  for (const auto& [key, resource] : resources) {
    if (std::none_of(refl.bindings.begin(), refl.bindings.end(), [&key = key](const DescriptorBinding& b) {
          return b.set == key.first && b.binding == key.second;
        })) {
      *error = "dispatch: the " + std::string(kResourceNames[resource.index()]) + " for set " + std::to_string(key.first) +
               " binding " + std::to_string(key.second) + " is not used by entry point '" + refl.entryPoint + "'";
      return false;
    }
  }

  const size_t start = c.messageCount();
  DispatchObjects objs;
  std::string why;
  const bool ran = [&]() -> bool {
    // Descriptor pool and one set per layout (empty layouts included).
    std::vector<VkDescriptorSet> sets(p.setLayouts.size(), VK_NULL_HANDLE);
    if (!sets.empty()) {
      std::map<VkDescriptorType, uint32_t> typeCounts;
      for (const DescriptorBinding& b : refl.bindings) ++typeCounts[descriptorType(b.kind)];
      std::vector<VkDescriptorPoolSize> sizes;
      for (const auto& [type, count] : typeCounts) sizes.push_back({type, count});
      VkDescriptorPoolCreateInfo poolInfo{};
      poolInfo.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
      poolInfo.maxSets = static_cast<uint32_t>(sets.size());
      poolInfo.poolSizeCount = static_cast<uint32_t>(sizes.size());
      poolInfo.pPoolSizes = sizes.data();
      if (!succeeded(vk.vkCreateDescriptorPool(c.device, &poolInfo, nullptr, &objs.descriptorPool),
                     "vkCreateDescriptorPool", &why))
        return false;
      VkDescriptorSetAllocateInfo alloc{};
      alloc.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
      alloc.descriptorPool = objs.descriptorPool;
      alloc.descriptorSetCount = static_cast<uint32_t>(sets.size());
      alloc.pSetLayouts = p.setLayouts.data();
      if (!succeeded(vk.vkAllocateDescriptorSets(c.device, &alloc, sets.data()), "vkAllocateDescriptorSets", &why))
        return false;
    }

    // Resources and descriptor writes (the info vectors never reallocate: pointers into them stay valid).
    std::vector<VkDescriptorBufferInfo> bufferInfos;
    std::vector<VkDescriptorImageInfo> imageInfos;
    bufferInfos.reserve(refl.bindings.size());
    imageInfos.reserve(refl.bindings.size());
    std::vector<VkWriteDescriptorSet> writes;
    std::vector<ImageUpload> uploads;
    std::vector<Readback> readbacks;
    for (const DescriptorBinding& b : refl.bindings) {
      Resource& resource = resources.at({b.set, b.binding});
      const std::string where = describe(b) + ": ";
      auto fail = [&](const std::string& what) { return why = where + what, false; };
      VkWriteDescriptorSet w{};
      w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      w.dstSet = sets[b.set];
      w.dstBinding = b.binding;
      w.descriptorCount = 1;
      w.descriptorType = descriptorType(b.kind);
      if (auto* buf = std::get_if<BufferResource>(&resource)) {
        if (buf->data.empty()) return fail("BufferResource::data is empty (it gives the buffer's size)");
        VkBuffer buffer;
        void* mapped;
        const VkBufferUsageFlags usage = b.kind == DescriptorKind::UniformBuffer ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT
                                                                                  : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        if (!c.createBuffer(buf->data.size(), usage, objs, &buffer, &mapped, &why)) return fail(why);
        if (buf->output && buf->initialized) {
          std::memcpy(mapped, buf->data.data(), buf->data.size());
          readbacks.push_back({&buf->data, mapped, buf->data.size()});
        } else if (buf->output) {
          auto* bytes = static_cast<unsigned char*>(mapped);
          for (size_t i = 0; i < buf->data.size(); ++i) bytes[i] = static_cast<unsigned char>(kQuietNan >> (8 * (i % 4)));
          readbacks.push_back({&buf->data, mapped, buf->data.size()});
        } else {
          std::memcpy(mapped, buf->data.data(), buf->data.size());
        }
        bufferInfos.push_back({buffer, 0, VK_WHOLE_SIZE});
        w.pBufferInfo = &bufferInfos.back();
      } else if (auto* img = std::get_if<ImageResource>(&resource)) {
        const bool cube = b.dim == ImageDim::Cube;
        if (img->width == 0 || img->height == 0 || img->layers == 0 || img->mips.empty())
          return fail("ImageResource needs a non-zero size, layers and at least one mip level");
        if (cube && (b.arrayed || img->layers != 6 || img->width != img->height))
          return fail("a cube map needs layers == 6, width == height (cube arrays are not supported)");
        if (!cube && (b.dim != ImageDim::Dim2D || (!b.arrayed && img->layers != 1)))
          return fail("only 2D, 2D array and cube images are supported (a non-arrayed 2D image has one layer)");
        const uint32_t levels = static_cast<uint32_t>(img->mips.size());
        if (levels > 32 || (std::max(img->width, img->height) >> (levels - 1)) == 0)
          return fail("too many mip levels (" + std::to_string(levels) + ") for the image size");
        ImageUpload up{VK_NULL_HANDLE, img->layers, levels, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
        size_t totalFloats = 0;
        for (uint32_t l = 0; l < levels; ++l) {
          const uint32_t w = std::max(1u, img->width >> l), h = std::max(1u, img->height >> l);
          if (img->mips[l].size() != size_t{w} * h * img->layers * 4)
            return fail("mip " + std::to_string(l) + " has " + std::to_string(img->mips[l].size()) + " floats, expected " +
                        std::to_string(size_t{w} * h * img->layers * 4) + " (" + std::to_string(w) + "x" +
                        std::to_string(h) + "x" + std::to_string(img->layers) + " RGBA)");
          VkBufferImageCopy region{};
          region.bufferOffset = totalFloats * sizeof(float);
          region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, l, 0, img->layers};
          region.imageExtent = {w, h, 1};
          up.regions.push_back(region);
          totalFloats += img->mips[l].size();
        }
        void* mapped;
        VkImageView view;
        if (!c.createBuffer(totalFloats * sizeof(float), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, objs, &up.staging, &mapped,
                            &why) ||
            !c.createImage(VK_FORMAT_R32G32B32A32_SFLOAT, img->width, img->height, img->layers, levels, cube,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                           cube ? VK_IMAGE_VIEW_TYPE_CUBE : b.arrayed ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D,
                           objs, &up.image, &view, &why))
          return fail(why);
        for (uint32_t l = 0; l < levels; ++l)
          std::memcpy(static_cast<char*>(mapped) + up.regions[l].bufferOffset, img->mips[l].data(),
                      img->mips[l].size() * sizeof(float));
        uploads.push_back(std::move(up));
        VkSampler sampler = VK_NULL_HANDLE;
        if (b.kind == DescriptorKind::CombinedImageSampler &&
            !c.createSampler(img->filter, img->address, objs, &sampler, &why))
          return fail(why);
        imageInfos.push_back({sampler, view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
        w.pImageInfo = &imageInfos.back();
      } else if (auto* smp = std::get_if<SamplerResource>(&resource)) {
        VkSampler sampler;
        if (!c.createSampler(smp->filter, smp->address, objs, &sampler, &why)) return fail(why);
        imageInfos.push_back({sampler, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED});
        w.pImageInfo = &imageInfos.back();
      } else {
        auto& si = std::get<StorageImageResource>(resource);
        if (si.width == 0 || si.height == 0 || si.layers == 0) return fail("StorageImageResource needs a non-zero size");
        if (b.dim != ImageDim::Dim2D || (!b.arrayed && si.layers != 1))
          return fail("only 2D and 2D array storage images are supported (a non-arrayed one has one layer)");
        const bool uint = si.format == StorageFormat::R32Uint;
        const size_t texel = uint ? 4 : 16;
        ImageUpload up{VK_NULL_HANDLE, si.layers, 1, VK_IMAGE_LAYOUT_GENERAL};
        for (int i = 0; i < 4; ++i) up.clear.uint32[i] = uint ? 0xffffffffu : kQuietNan;  // NaN bits for float
        Readback rb{&si.data, nullptr, size_t{si.width} * si.height * si.layers * texel};
        VkImageView view;
        void* mapped;
        if (!c.createImage(uint ? VK_FORMAT_R32_UINT : VK_FORMAT_R32G32B32A32_SFLOAT, si.width, si.height, si.layers, 1,
                           false,
                           VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                           b.arrayed ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D, objs, &up.image, &view, &why) ||
            !c.createBuffer(rb.size, VK_BUFFER_USAGE_TRANSFER_DST_BIT, objs, &rb.buffer, &mapped, &why))
          return fail(why);
        if (si.upload) {  // the image's contents come from `data`, through a staging buffer
          if (si.data.size() != rb.size)
            return fail("StorageImageResource::data has " + std::to_string(si.data.size()) + " bytes, expected " +
                        std::to_string(rb.size));
          void* staged;
          if (!c.createBuffer(rb.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, objs, &up.staging, &staged, &why))
            return fail(why);
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
        uploads.push_back(std::move(up));
        readbacks.push_back(rb);
        imageInfos.push_back({VK_NULL_HANDLE, view, VK_IMAGE_LAYOUT_GENERAL});
        w.pImageInfo = &imageInfos.back();
      }
      writes.push_back(w);
    }
    if (!writes.empty())
      vk.vkUpdateDescriptorSets(c.device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);

    // One command buffer: fill images, dispatch, copy storage images out, make everything host-visible.
    VkCommandBufferAllocateInfo cbInfo{};
    cbInfo.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbInfo.commandPool = c.commandPool;
    cbInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbInfo.commandBufferCount = 1;
    if (!succeeded(vk.vkAllocateCommandBuffers(c.device, &cbInfo, &objs.commandBuffer), "vkAllocateCommandBuffers", &why))
      return false;
    const VkCommandBuffer cmd = objs.commandBuffer;
    VkCommandBufferBeginInfo begin{};
    begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    if (!succeeded(vk.vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer", &why)) return false;
    auto transition = [](VkImage image, uint32_t layers, uint32_t mips, VkImageLayout from, VkImageLayout to,
                         VkAccessFlags srcAccess, VkAccessFlags dstAccess) {
      VkImageMemoryBarrier barrier{};
      barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
      barrier.srcAccessMask = srcAccess;
      barrier.dstAccessMask = dstAccess;
      barrier.oldLayout = from;
      barrier.newLayout = to;
      barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      barrier.image = image;
      barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, mips, 0, layers};
      return barrier;
    };
    auto barriers = [&](VkPipelineStageFlags src, VkPipelineStageFlags dst, const std::vector<VkImageMemoryBarrier>& b) {
      if (!b.empty()) vk.vkCmdPipelineBarrier(cmd, src, dst, 0, 0, nullptr, 0, nullptr, static_cast<uint32_t>(b.size()), b.data());
    };
    std::vector<VkImageMemoryBarrier> before, after, out;
    for (const ImageUpload& up : uploads) {
      before.push_back(transition(up.image, up.layers, up.mipLevels, VK_IMAGE_LAYOUT_UNDEFINED,
                                  VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT));
      after.push_back(transition(up.image, up.layers, up.mipLevels, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, up.finalLayout,
                                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT));
    }
    barriers(VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, before);
    for (const ImageUpload& up : uploads) {
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
    if (!sets.empty())
      vk.vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, static_cast<uint32_t>(sets.size()),
                                 sets.data(), 0, nullptr);
    if (dispatchNs) {
      VkQueryPoolCreateInfo q{};
      q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
      q.queryType = VK_QUERY_TYPE_TIMESTAMP;
      q.queryCount = 2;
      if (!succeeded(vk.vkCreateQueryPool(c.device, &q, nullptr, &objs.timestamps), "vkCreateQueryPool", &why))
        return false;
      vk.vkCmdResetQueryPool(cmd, objs.timestamps, 0, 2);
      vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, objs.timestamps, 0);
    }
    vk.vkCmdDispatch(cmd, groupsX, groupsY, groupsZ);
    if (dispatchNs) vk.vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, objs.timestamps, 1);
    for (const Readback& rb : readbacks)
      if (rb.image)
        out.push_back(transition(rb.image, rb.region.imageSubresource.layerCount, 1, VK_IMAGE_LAYOUT_GENERAL,
                                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_ACCESS_SHADER_WRITE_BIT,
                                 VK_ACCESS_TRANSFER_READ_BIT));
    barriers(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, out);
    for (const Readback& rb : readbacks)
      if (rb.image)
        vk.vkCmdCopyImageToBuffer(cmd, rb.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, rb.buffer, 1, &rb.region);
    VkMemoryBarrier toHost{};
    toHost.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    toHost.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vk.vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                            VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr, 0, nullptr);
    if (!succeeded(vk.vkEndCommandBuffer(cmd), "vkEndCommandBuffer", &why)) return false;

    // Submit, wait (bounded), read back.
    VkFenceCreateInfo fenceInfo{};
    fenceInfo.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    if (!succeeded(vk.vkCreateFence(c.device, &fenceInfo, nullptr, &objs.fence), "vkCreateFence", &why)) return false;
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    if (!succeeded(vk.vkQueueSubmit(c.queue, 1, &submit, objs.fence), "vkQueueSubmit", &why)) return false;
    const VkResult waited = vk.vkWaitForFences(c.device, 1, &objs.fence, VK_TRUE, c.options.fenceTimeoutNs);
    if (waited != VK_SUCCESS) {
      c.lost = true;  // the work may still be running: its objects are leaked, the Context is done
      why = waited == VK_TIMEOUT ? "vkWaitForFences timed out after " + std::to_string(c.options.fenceTimeoutNs / 1000000) +
                                       " ms (the Context is unusable now)"
                                 : "vkWaitForFences failed: " + vkResultName(waited);
      return false;
    }
    for (const Readback& rb : readbacks) {
      rb.target->resize(rb.size);
      std::memcpy(rb.target->data(), rb.mapped, rb.size);
    }
    if (dispatchNs) {
      uint64_t t[2] = {0, 0};
      if (!succeeded(vk.vkGetQueryPoolResults(c.device, objs.timestamps, 0, 2, sizeof t, t, sizeof(uint64_t),
                                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
                     "vkGetQueryPoolResults", &why))
        return false;
      *dispatchNs = static_cast<double>(t[1] - t[0]) * c.timestampPeriodNs;
    }
    return true;
  }();
  if (!c.lost) c.destroy(objs);
  std::string message = ran ? std::string() : "dispatch: " + why;
  const bool quiet = c.noMessagesSince(start, "dispatch of entry point '" + refl.entryPoint + "'", &message);
  if (!ran || !quiet) *error = message;
  return ran && quiet;
}

}  // namespace substratec::gpu
