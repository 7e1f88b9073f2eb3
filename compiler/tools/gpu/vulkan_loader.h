// Run-time loading of the Vulkan loader (libvulkan.so.1) for the GPU harness:
// nothing links libvulkan, so the substratec CLI starts without it and only a
// GPU command pays for (and depends on) Vulkan. Every entry point the harness
// calls lives in one function-pointer table, filled in three steps: global
// functions after dlopen, instance functions after vkCreateInstance, device
// functions after vkCreateDevice.
#pragma once

#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#include <vulkan/vulkan.h>

#include <string>

#include "diag/diagnostics.h"

namespace substratec::gpu {

// X-macro lists of the entry points used, by the level they are loaded at.
#define SUBSTRATEC_VK_GLOBAL_FUNCTIONS(X) \
  X(vkCreateInstance)                     \
  X(vkEnumerateInstanceLayerProperties)   \
  X(vkEnumerateInstanceExtensionProperties)

#define SUBSTRATEC_VK_INSTANCE_FUNCTIONS(X)  \
  X(vkDestroyInstance)                       \
  X(vkEnumeratePhysicalDevices)              \
  X(vkGetPhysicalDeviceProperties2)          \
  X(vkGetPhysicalDeviceFeatures2)            \
  X(vkGetPhysicalDeviceQueueFamilyProperties) \
  X(vkGetPhysicalDeviceMemoryProperties)     \
  X(vkCreateDevice)                          \
  X(vkGetDeviceProcAddr)                     \
  X(vkCreateDebugUtilsMessengerEXT)          \
  X(vkDestroyDebugUtilsMessengerEXT)

#define SUBSTRATEC_VK_DEVICE_FUNCTIONS(X) \
  X(vkDestroyDevice)                      \
  X(vkDeviceWaitIdle)                     \
  X(vkGetDeviceQueue)                     \
  X(vkQueueSubmit)                        \
  X(vkCreateCommandPool)                  \
  X(vkDestroyCommandPool)                 \
  X(vkAllocateCommandBuffers)             \
  X(vkFreeCommandBuffers)                 \
  X(vkBeginCommandBuffer)                 \
  X(vkEndCommandBuffer)                   \
  X(vkCreateFence)                        \
  X(vkDestroyFence)                       \
  X(vkWaitForFences)                      \
  X(vkCreateBuffer)                       \
  X(vkDestroyBuffer)                      \
  X(vkGetBufferMemoryRequirements)        \
  X(vkBindBufferMemory)                   \
  X(vkCreateImage)                        \
  X(vkDestroyImage)                       \
  X(vkGetImageMemoryRequirements)         \
  X(vkBindImageMemory)                    \
  X(vkCreateImageView)                    \
  X(vkDestroyImageView)                   \
  X(vkCreateSampler)                      \
  X(vkDestroySampler)                     \
  X(vkAllocateMemory)                     \
  X(vkFreeMemory)                         \
  X(vkMapMemory)                          \
  X(vkCreateShaderModule)                 \
  X(vkDestroyShaderModule)                \
  X(vkCreateDescriptorSetLayout)          \
  X(vkDestroyDescriptorSetLayout)         \
  X(vkCreatePipelineLayout)               \
  X(vkDestroyPipelineLayout)              \
  X(vkCreateComputePipelines)             \
  X(vkDestroyPipeline)                    \
  X(vkCreateDescriptorPool)               \
  X(vkDestroyDescriptorPool)              \
  X(vkAllocateDescriptorSets)             \
  X(vkUpdateDescriptorSets)               \
  X(vkCmdPipelineBarrier)                 \
  X(vkCmdCopyBufferToImage)               \
  X(vkCmdCopyImageToBuffer)               \
  X(vkCmdClearColorImage)                 \
  X(vkCmdBindPipeline)                    \
  X(vkCmdBindDescriptorSets)              \
  X(vkCmdDispatch)                        \
  X(vkCreateQueryPool)                    \
  X(vkDestroyQueryPool)                   \
  X(vkCmdResetQueryPool)                  \
  X(vkCmdWriteTimestamp)                  \
  X(vkGetQueryPoolResults)               \
  X(vkCreateGraphicsPipelines)            \
  X(vkCreateRenderPass)                   \
  X(vkDestroyRenderPass)                  \
  X(vkCreateFramebuffer)                  \
  X(vkDestroyFramebuffer)                 \
  X(vkCmdBeginRenderPass)                 \
  X(vkCmdEndRenderPass)                   \
  X(vkCmdBindVertexBuffers)               \
  X(vkCmdBindIndexBuffer)                 \
  X(vkCmdSetViewport)                     \
  X(vkCmdSetScissor)                      \
  X(vkCmdDrawIndexed)

/// The function-pointer table; a null member means "not loaded yet".
struct VulkanFunctions {
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
#define SUBSTRATEC_VK_MEMBER(name) PFN_##name name = nullptr;
  SUBSTRATEC_VK_GLOBAL_FUNCTIONS(SUBSTRATEC_VK_MEMBER)
  SUBSTRATEC_VK_INSTANCE_FUNCTIONS(SUBSTRATEC_VK_MEMBER)
  SUBSTRATEC_VK_DEVICE_FUNCTIONS(SUBSTRATEC_VK_MEMBER)
#undef SUBSTRATEC_VK_MEMBER
};

/// dlopens libvulkan.so.1 (once per process; never closed) and loads vkGetInstanceProcAddr and the
/// global functions. False, reporting what is missing.
bool loadGlobalFunctions(VulkanFunctions* fns, Diagnostics& diags);

/// Loads the instance-level functions (including VK_EXT_debug_utils') through vkGetInstanceProcAddr;
/// false, reporting the first one missing.
bool loadInstanceFunctions(VulkanFunctions* fns, VkInstance instance, Diagnostics& diags);

/// Loads the device-level functions through vkGetDeviceProcAddr; false, reporting the first one missing.
bool loadDeviceFunctions(VulkanFunctions* fns, VkDevice device, Diagnostics& diags);

/// The enumerator's name of a VkResult ("VK_ERROR_DEVICE_LOST"), or "VkResult(<n>)".
std::string vkResultName(VkResult result);

}  // namespace substratec::gpu
