// The internals of the Vulkan harness (harness.h) shared by its compute
// dispatches (harness.cc) and its raster passes (raster.cc): the Context's and
// pipelines' Vulkan objects, the per-submission object lists and the helpers
// that bind resources. Nothing outside compiler/tools/gpu includes it.
#pragma once

#include <map>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

#include "gpu/harness.h"
#include "gpu/vulkan_loader.h"

namespace substratec::gpu {

/// Validation messages, appended by the debug-utils callback (any thread);
/// Context::Impl holds one.
struct ValidationMessageLog {
  std::mutex mutex;
  std::vector<std::string> messages;
};

namespace harness_detail {

inline constexpr uint32_t kQuietNan = 0x7fc00000u;

/// Reports `message` as an error; false (for `return fail(...)`).
inline bool fail(Diagnostics& diags, std::string message) {
  diags.fail(std::move(message));
  return false;
}

/// Reports "<call> failed: <VkResult>" unless `result` is VK_SUCCESS.
inline bool succeeded(VkResult result, const std::string& call, Diagnostics& diags) {
  if (result == VK_SUCCESS) return true;
  diags.fail(call + " failed: " + vkResultName(result));
  return false;
}

inline VkDescriptorType descriptorType(DescriptorKind kind) {
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
inline std::string describe(const DescriptorBinding& b) {
  return "set " + std::to_string(b.set) + " binding " + std::to_string(b.binding) + " ('" + b.name + "', " +
         descriptorKindName(b.kind) + ")";
}

/// Index of the Resource alternative a descriptor kind needs.
inline size_t resourceIndexFor(DescriptorKind kind) {
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

inline constexpr const char* kResourceNames[] = {"BufferResource", "ImageResource", "SamplerResource", "StorageImageResource"};

/// The Vulkan objects of one dispatch, destroyed together.
struct DispatchObjects {
  std::vector<VkBuffer> buffers;
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkSampler> samplers;
  std::vector<VkDeviceMemory> memories;
  std::vector<VkRenderPass> renderPasses;    // a raster pass's
  std::vector<VkFramebuffer> framebuffers;   // a raster pass's
  std::vector<VkDescriptorPool> descriptorPools;  // one per descriptor-set group (a dispatch's, a draw's)
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

/// What one dispatch binds, fills and reads back. The info vectors are reserved for every binding up
/// front and never reallocate: the writes point into them.
struct Bindings {
  std::vector<VkDescriptorSet> sets;  // index = set number
  std::vector<VkDescriptorBufferInfo> bufferInfos;
  std::vector<VkDescriptorImageInfo> imageInfos;
  std::vector<VkWriteDescriptorSet> writes;
  std::vector<ImageUpload> uploads;
  std::vector<Readback> readbacks;
};

/// A layout transition of all `mips` and `layers` of a colour image.
inline VkImageMemoryBarrier imageBarrier(VkImage image, uint32_t layers, uint32_t mips, VkImageLayout from, VkImageLayout to,
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
}

}  // namespace harness_detail

struct Context::Impl {
  VulkanFunctions vk;
  Options options;
  std::unique_ptr<ValidationMessageLog> log = std::make_unique<ValidationMessageLog>();  // the messenger's user data
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
  bool fragmentStores = false;   // fragmentStoresAndAtomics, enabled on the device
  bool dualSourceBlend = false;  // dualSrcBlend, enabled on the device
  bool independentBlend = false; // independentBlend, enabled on the device
  bool lost = false;  // a fence wait timed out or the device was lost: leak, never wait
  VkFence lostFence = VK_NULL_HANDLE;  // the fence of the dispatch that timed out (leaked with it)

  ~Impl() {
    if (lost) {  // objects may still be in use by the device; leaking them (and the log) is the only safe choice
      // One more bounded wait (60 s) for the work that timed out: a process
      // that exits while lavapipe's threads still run it crashes in their
      // teardown. Work that never finishes is leaked all the same.
      if (lostFence) (void)vk.vkWaitForFences(device, 1, &lostFence, VK_TRUE, 60'000'000'000ull);
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

  /// Reports the messages recorded since `start` as one error ("the validation layer reported N
  /// message(s) during <during>:", a line each); false if there were any.
  bool noMessagesSince(size_t start, const std::string& during, Diagnostics& diags) {
    std::lock_guard<std::mutex> lock(log->mutex);
    if (log->messages.size() <= start) return true;
    std::string text = "the validation layer reported " + std::to_string(log->messages.size() - start) +
                       " message(s) during " + during + ":";
    for (size_t i = start; i < log->messages.size(); ++i) text += "\n  " + log->messages[i];
    diags.fail(std::move(text));
    return false;
  }

  /// Loads libvulkan, pins lavapipe, creates the instance with the validation layer and the messenger.
  bool createInstance(Diagnostics& diags);
  /// Picks lavapipe, creates the device with one queue for graphics and compute (createLogicalDevice) and
  /// the command pool.
  bool createDevice(Diagnostics& diags);
  /// The device of `physical` with queue family `queueFamily` and the optional features it has
  /// (shaderFloat16; fragmentStoresAndAtomics, dualSrcBlend and independentBlend for raster passes).
  bool createLogicalDevice(Diagnostics& diags);
  /// Allocates memory for `req` (host-visible + coherent and mapped when `hostVisible`), owned by `objs`.
  bool allocate(const VkMemoryRequirements& req, bool hostVisible, harness_detail::DispatchObjects& objs, VkDeviceMemory* out,
                void** mapped, Diagnostics& diags);
  /// Gives `object` (a VkBuffer or VkImage) memory of its own, owned by `objs`: host-visible, coherent
  /// and mapped into `*mapped` when `mapped` is set.
  template <class Object>
  bool bindMemory(Object object, harness_detail::DispatchObjects& objs, void** mapped, Diagnostics& diags) {
    constexpr bool isBuffer = std::is_same_v<Object, VkBuffer>;
    VkMemoryRequirements req;
    if constexpr (isBuffer) vk.vkGetBufferMemoryRequirements(device, object, &req);
    else vk.vkGetImageMemoryRequirements(device, object, &req);
    VkDeviceMemory mem;
    if (!allocate(req, mapped != nullptr, objs, &mem, mapped, diags)) return false;
    if constexpr (isBuffer) return harness_detail::succeeded(vk.vkBindBufferMemory(device, object, mem, 0), "vkBindBufferMemory", diags);
    else return harness_detail::succeeded(vk.vkBindImageMemory(device, object, mem, 0), "vkBindImageMemory", diags);
  }
  /// A host-visible, mapped buffer owned by `objs`.
  bool createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, harness_detail::DispatchObjects& objs, VkBuffer* buffer,
                    void** mapped, Diagnostics& diags);
  /// An optimal-tiling 2D image (cube-compatible when `cube`) with its memory and one view, owned by `objs`.
  bool createImage(VkFormat format, uint32_t width, uint32_t height, uint32_t layers, uint32_t mips, bool cube,
                   VkImageUsageFlags usage, VkImageViewType viewType, harness_detail::DispatchObjects& objs, VkImage* image,
                   VkImageView* view, Diagnostics& diags);
  /// A sampler (filter for min/mag/mips, one address mode for u/v/w, no LOD clamp) owned by `objs`.
  bool createSampler(Filter filter, Address address, Address addressV, harness_detail::DispatchObjects& objs, VkSampler* sampler,
                     Diagnostics& diags);
  /// Destroys everything in `objs` (only once the device no longer uses it).
  void destroy(harness_detail::DispatchObjects& objs);

  // The steps of one dispatch, in order (Context::dispatch runs them; each sets `*why` on failure).
  /// A descriptor pool and one set per layout of `setLayouts` (empty layouts included) into `b.sets`.
  bool allocateSets(const std::vector<VkDescriptorSetLayout>& setLayouts, const ShaderReflection& refl,
                    harness_detail::DispatchObjects& objs, harness_detail::Bindings& b, Diagnostics& diags);
  /// Creates and fills the Vulkan object of every binding and writes the descriptor sets; `*why` names the binding.
  /// A binding found in `shared` (a raster pass's storage images, written by every draw) points at that
  /// image instead, and `resources` holds nothing for it.
  bool bindResources(const ShaderReflection& refl, Resources& resources, harness_detail::DispatchObjects& objs,
                     harness_detail::Bindings& b, Diagnostics& diags,
                     const std::map<std::pair<uint32_t, uint32_t>, VkDescriptorImageInfo>* shared = nullptr);
  /// A uniform or storage buffer: uploaded, NaN-filled or both read back (BufferResource's contract).
  bool bindBuffer(const DescriptorBinding& binding, BufferResource& buf, harness_detail::DispatchObjects& objs, harness_detail::Bindings& b,
                  VkWriteDescriptorSet& w, Diagnostics& diags);
  /// A sampled texture with all its mips staged for upload (and its sampler when combined).
  bool bindImage(const DescriptorBinding& binding, const ImageResource& img, harness_detail::DispatchObjects& objs, harness_detail::Bindings& b,
                 VkWriteDescriptorSet& w, Diagnostics& diags);
  /// A storage image: cleared or staged for upload, and copied out for read-back.
  bool bindStorageImage(const DescriptorBinding& binding, StorageImageResource& si, harness_detail::DispatchObjects& objs, harness_detail::Bindings& b,
                        VkWriteDescriptorSet& w, Diagnostics& diags);
  /// One command buffer: fill images, dispatch (between timestamps when `timed`), copy storage images out,
  /// make everything host-visible.
  bool record(const ComputePipeline::Impl& p, const harness_detail::Bindings& b, const uint32_t groups[3], bool timed,
              harness_detail::DispatchObjects& objs, Diagnostics& diags);
  /// Submits `objs.commandBuffer` and waits for its fence (at most Options::fenceTimeoutNs; after that the
  /// Context is lost).
  bool submitAndWait(harness_detail::DispatchObjects& objs, Diagnostics& diags);
  /// Copies the outputs into their resources, and the dispatch's time into `*dispatchNs` when timed.
  bool readBack(const harness_detail::Bindings& b, harness_detail::DispatchObjects& objs, double* dispatchNs, Diagnostics& diags);
};

struct ComputePipeline::Impl {
  Context::Impl* context = nullptr;
  std::vector<VkDescriptorSetLayout> setLayouts;  // index = set number
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

}  // namespace substratec::gpu
