// The Vulkan functions meshcast calls, held in a table of each Context
// instead of global symbols. A global `vkCreateInstance` pointer (volk's way)
// interposes on the loader's own symbol in a program that links both: an
// engine calling Vulkan itself would jump through meshcast's pointer, null
// until loaded (a segfault on its first call). Here nothing named vk* is
// defined: the loader library is opened at run time (or the engine hands its
// vkGetInstanceProcAddr over), instance functions come from
// vkGetInstanceProcAddr and device functions from vkGetDeviceProcAddr, so
// each device's calls go straight to its driver (through the layers asked
// for) and two contexts never share pointers.
//
// VK_NO_PROTOTYPES (set on the gpu target) keeps the loader's prototypes out,
// so a call that bypasses the table does not compile.
#pragma once
#include <vulkan/vulkan.h>

// Answered by the loader without an instance.
#define MESHCAST_VK_GLOBAL_FUNCTIONS(X) \
  X(CreateInstance)                     \
  X(EnumerateInstanceLayerProperties)   \
  X(EnumerateInstanceVersion)

// Instance-level: physical devices and device creation.
#define MESHCAST_VK_INSTANCE_FUNCTIONS(X)    \
  X(DestroyInstance)                         \
  X(EnumeratePhysicalDevices)                \
  X(GetPhysicalDeviceProperties)             \
  X(GetPhysicalDeviceFeatures2)              \
  X(GetPhysicalDeviceMemoryProperties)       \
  X(GetPhysicalDeviceQueueFamilyProperties)  \
  X(CreateDevice)                            \
  X(GetDeviceProcAddr)

// VK_EXT_debug_utils: null unless the instance enabled it (validation).
#define MESHCAST_VK_DEBUG_FUNCTIONS(X) \
  X(CreateDebugUtilsMessengerEXT)      \
  X(DestroyDebugUtilsMessengerEXT)

// Device-level: everything a method records and submits.
#define MESHCAST_VK_DEVICE_FUNCTIONS(X) \
  X(DestroyDevice)                      \
  X(DeviceWaitIdle)                     \
  X(GetDeviceQueue)                     \
  X(QueueSubmit)                        \
  X(CreateCommandPool)                  \
  X(DestroyCommandPool)                 \
  X(AllocateCommandBuffers)             \
  X(FreeCommandBuffers)                 \
  X(BeginCommandBuffer)                 \
  X(EndCommandBuffer)                   \
  X(ResetCommandBuffer)                 \
  X(CreateFence)                        \
  X(DestroyFence)                       \
  X(ResetFences)                        \
  X(GetFenceStatus)                     \
  X(WaitForFences)                      \
  X(CreateBuffer)                       \
  X(DestroyBuffer)                      \
  X(GetBufferMemoryRequirements)        \
  X(AllocateMemory)                     \
  X(FreeMemory)                         \
  X(BindBufferMemory)                   \
  X(MapMemory)                          \
  X(CreateShaderModule)                 \
  X(DestroyShaderModule)                \
  X(CreateDescriptorSetLayout)          \
  X(DestroyDescriptorSetLayout)         \
  X(CreatePipelineLayout)               \
  X(DestroyPipelineLayout)              \
  X(CreateComputePipelines)             \
  X(DestroyPipeline)                    \
  X(CreateDescriptorPool)               \
  X(DestroyDescriptorPool)              \
  X(AllocateDescriptorSets)             \
  X(UpdateDescriptorSets)               \
  X(CreateQueryPool)                    \
  X(DestroyQueryPool)                   \
  X(GetQueryPoolResults)                \
  X(CmdBindPipeline)                    \
  X(CmdBindDescriptorSets)              \
  X(CmdPushConstants)                   \
  X(CmdDispatch)                        \
  X(CmdDispatchIndirect)                \
  X(CmdPipelineBarrier)                 \
  X(CmdCopyBuffer)                      \
  X(CmdFillBuffer)                      \
  X(CmdResetQueryPool)                  \
  X(CmdWriteTimestamp)

namespace meshcast::gpu {

#define MESHCAST_VK_MEMBER(name) PFN_vk##name name = nullptr;
struct VulkanFunctions {
  PFN_vkGetInstanceProcAddr GetInstanceProcAddr = nullptr;
  MESHCAST_VK_GLOBAL_FUNCTIONS(MESHCAST_VK_MEMBER)
  MESHCAST_VK_INSTANCE_FUNCTIONS(MESHCAST_VK_MEMBER)
  MESHCAST_VK_DEBUG_FUNCTIONS(MESHCAST_VK_MEMBER)
  MESHCAST_VK_DEVICE_FUNCTIONS(MESHCAST_VK_MEMBER)
};
#undef MESHCAST_VK_MEMBER

// The loader's vkGetInstanceProcAddr, from libvulkan.so.1 opened once for
// the process (never closed, as a loader may not be); null when there is
// no loader: the CPU path never needs one.
PFN_vkGetInstanceProcAddr loader_get_instance_proc_addr();

// Fill the table's levels in turn. Each throws GpuError naming a function the
// implementation does not offer (the debug ones may stay null).
void load_global_functions(VulkanFunctions& vk, PFN_vkGetInstanceProcAddr get_instance_proc_addr);
void load_instance_functions(VulkanFunctions& vk, VkInstance instance);
void load_device_functions(VulkanFunctions& vk, VkDevice device);

}  // namespace meshcast::gpu
