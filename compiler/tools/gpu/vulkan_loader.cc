// dlopen-based loading of the Vulkan loader and its entry points (see vulkan_loader.h).
#include "gpu/vulkan_loader.h"

#include <dlfcn.h>

#include <mutex>

namespace substratec::gpu {
namespace {

constexpr const char* kLibraryName = "libvulkan.so.1";

/// The process-wide libvulkan handle and its vkGetInstanceProcAddr; the library stays loaded for the
/// process' lifetime (unloading it under a live ICD/LLVM is asking for trouble at exit).
struct Library {
  void* handle = nullptr;
  PFN_vkGetInstanceProcAddr getInstanceProcAddr = nullptr;
  std::string error;
};

const Library& library() {
  static Library lib;
  static std::once_flag once;
  std::call_once(once, [] {
    lib.handle = dlopen(kLibraryName, RTLD_NOW | RTLD_LOCAL);
    if (!lib.handle) {
      const char* why = dlerror();
      lib.error = std::string("cannot load ") + kLibraryName + " (install the Vulkan loader, Debian: libvulkan1): " +
                  (why ? why : "unknown dlopen error");
      return;
    }
    lib.getInstanceProcAddr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(lib.handle, "vkGetInstanceProcAddr"));
    if (!lib.getInstanceProcAddr) lib.error = std::string(kLibraryName) + " has no symbol vkGetInstanceProcAddr";
  });
  return lib;
}

/// Resolves one entry point through `get` (vkGetInstanceProcAddr or vkGetDeviceProcAddr on a handle);
/// false, reporting "<how>, \"<name>\") returned NULL", when the driver does not have it.
template <class Fn, class Get>
bool resolve(Fn* slot, const char* name, Get get, const char* how, Diagnostics& diags) {
  *slot = reinterpret_cast<Fn>(get(name));
  if (*slot) return true;
  diags.fail(std::string(how) + ", \"" + name + "\") returned NULL");
  return false;
}

}  // namespace

// Each loader resolves its X-macro list of functions through a local `get`, labelled `how`.
#define SUBSTRATEC_VK_LOAD(name) \
  if (!resolve(&fns->name, #name, get, how, diags)) return false;

bool loadGlobalFunctions(VulkanFunctions* fns, Diagnostics& diags) {
  const Library& lib = library();
  if (!lib.getInstanceProcAddr) {
    diags.fail(lib.error);
    return false;
  }
  fns->vkGetInstanceProcAddr = lib.getInstanceProcAddr;
  auto get = [fns](const char* name) { return fns->vkGetInstanceProcAddr(VK_NULL_HANDLE, name); };
  const char* how = "vkGetInstanceProcAddr(NULL";
  SUBSTRATEC_VK_GLOBAL_FUNCTIONS(SUBSTRATEC_VK_LOAD)
  return true;
}

bool loadInstanceFunctions(VulkanFunctions* fns, VkInstance instance, Diagnostics& diags) {
  auto get = [fns, instance](const char* name) { return fns->vkGetInstanceProcAddr(instance, name); };
  const char* how = "vkGetInstanceProcAddr(instance";
  SUBSTRATEC_VK_INSTANCE_FUNCTIONS(SUBSTRATEC_VK_LOAD)
  return true;
}

bool loadDeviceFunctions(VulkanFunctions* fns, VkDevice device, Diagnostics& diags) {
  auto get = [fns, device](const char* name) { return fns->vkGetDeviceProcAddr(device, name); };
  const char* how = "vkGetDeviceProcAddr(device";
  SUBSTRATEC_VK_DEVICE_FUNCTIONS(SUBSTRATEC_VK_LOAD)
  return true;
}

#undef SUBSTRATEC_VK_LOAD

std::string vkResultName(VkResult result) {
  switch (result) {
#define SUBSTRATEC_VK_CASE(r) \
  case r: return #r;
    SUBSTRATEC_VK_CASE(VK_SUCCESS)
    SUBSTRATEC_VK_CASE(VK_NOT_READY)
    SUBSTRATEC_VK_CASE(VK_TIMEOUT)
    SUBSTRATEC_VK_CASE(VK_EVENT_SET)
    SUBSTRATEC_VK_CASE(VK_EVENT_RESET)
    SUBSTRATEC_VK_CASE(VK_INCOMPLETE)
    SUBSTRATEC_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SUBSTRATEC_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SUBSTRATEC_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SUBSTRATEC_VK_CASE(VK_ERROR_DEVICE_LOST)
    SUBSTRATEC_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SUBSTRATEC_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SUBSTRATEC_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SUBSTRATEC_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SUBSTRATEC_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SUBSTRATEC_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SUBSTRATEC_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SUBSTRATEC_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
    SUBSTRATEC_VK_CASE(VK_ERROR_UNKNOWN)
    SUBSTRATEC_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
    SUBSTRATEC_VK_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    SUBSTRATEC_VK_CASE(VK_ERROR_FRAGMENTATION)
    SUBSTRATEC_VK_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    SUBSTRATEC_VK_CASE(VK_PIPELINE_COMPILE_REQUIRED)
    SUBSTRATEC_VK_CASE(VK_ERROR_INVALID_SHADER_NV)
    SUBSTRATEC_VK_CASE(VK_ERROR_VALIDATION_FAILED_EXT)
#undef SUBSTRATEC_VK_CASE
    default: break;
  }
  return "VkResult(" + std::to_string(static_cast<int>(result)) + ")";
}

}  // namespace substratec::gpu
