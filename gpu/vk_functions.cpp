#include "gpu/vk_functions.h"

#include <dlfcn.h>

#include <string>
#include <string_view>

#include "gpu/vulkan.h"

namespace meshcast::gpu {

namespace {

// One table entry from `get` (a vkGet*ProcAddr bound to its handle); a
// required function the implementation lacks is a GpuError naming it.
template <class Pfn, class Get>
void load_one(Pfn& fn, const Get& get, const char* name, bool required) {
  fn = reinterpret_cast<Pfn>(get(name));
  if (!fn && required) throw GpuError(std::string("Vulkan: the implementation does not offer ") + name);
}

}  // namespace

PFN_vkGetInstanceProcAddr loader_get_instance_proc_addr() {
  static PFN_vkGetInstanceProcAddr found = [] {
    void* lib = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!lib) lib = dlopen("libvulkan.so", RTLD_NOW | RTLD_LOCAL);
    return lib ? reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(lib, "vkGetInstanceProcAddr")) : nullptr;
  }();
  return found;
}

void load_global_functions(VulkanFunctions& vk, PFN_vkGetInstanceProcAddr get_instance_proc_addr) {
  vk.GetInstanceProcAddr = get_instance_proc_addr;
  const auto get = [&](const char* name) { return get_instance_proc_addr(VK_NULL_HANDLE, name); };
  // A Vulkan 1.0 loader lacks vkEnumerateInstanceVersion (Context reads
  // that as 1.0 and refuses it); the other two every loader has.
#define MESHCAST_VK_LOAD(name) load_one(vk.name, get, "vk" #name, std::string_view(#name) != "EnumerateInstanceVersion");
  MESHCAST_VK_GLOBAL_FUNCTIONS(MESHCAST_VK_LOAD)
#undef MESHCAST_VK_LOAD
}

void load_instance_functions(VulkanFunctions& vk, VkInstance instance) {
  const auto get = [&](const char* name) { return vk.GetInstanceProcAddr(instance, name); };
#define MESHCAST_VK_LOAD(name) load_one(vk.name, get, "vk" #name, true);
  MESHCAST_VK_INSTANCE_FUNCTIONS(MESHCAST_VK_LOAD)
#undef MESHCAST_VK_LOAD
#define MESHCAST_VK_LOAD(name) load_one(vk.name, get, "vk" #name, false);
  MESHCAST_VK_DEBUG_FUNCTIONS(MESHCAST_VK_LOAD)
#undef MESHCAST_VK_LOAD
}

void load_device_functions(VulkanFunctions& vk, VkDevice device) {
  const auto get = [&](const char* name) { return vk.GetDeviceProcAddr(device, name); };
#define MESHCAST_VK_LOAD(name) load_one(vk.name, get, "vk" #name, true);
  MESHCAST_VK_DEVICE_FUNCTIONS(MESHCAST_VK_LOAD)
#undef MESHCAST_VK_LOAD
}

}  // namespace meshcast::gpu
