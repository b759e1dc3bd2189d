// An engine that calls Vulkan itself and links meshcast's host layer beside
// it: this program links the Vulkan loader and calls it directly (its own
// instance, device, a buffer) before, between and after Casters on the CPU
// and Vulkan backends, and hands one Caster its own device and queue. A
// library that defined vk* symbols of its own would replace the loader's
// here, and the first direct call would jump through a null pointer.
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cmath>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/caster.h"
#include "check/generate.h"

namespace meshcast::testing {
namespace {

// The engine's side: plain loader calls, no meshcast.
struct Engine {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  bool int64_atomics = false;

  Engine() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "engine";
    app.apiVersion = VK_API_VERSION_1_2;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS) return;
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    for (VkPhysicalDevice d : devices) {
      VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
      VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
      vkGetPhysicalDeviceFeatures2(d, &f2);
      uint32_t families = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
      std::vector<VkQueueFamilyProperties> qf(families);
      vkGetPhysicalDeviceQueueFamilyProperties(d, &families, qf.data());
      for (uint32_t i = 0; i < families && !physical; ++i)
        if ((qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && f2.features.shaderInt64 && f2.features.shaderFloat64)
          physical = d, family = i, int64_atomics = f12.shaderBufferInt64Atomics;
    }
    if (!physical) return;
    VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    e12.shaderBufferInt64Atomics = int64_atomics;
    VkPhysicalDeviceFeatures2 e2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &e12};
    e2.features.shaderInt64 = e2.features.shaderFloat64 = VK_TRUE;
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family, qci.queueCount = 1, qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &e2};
    dci.queueCreateInfoCount = 1, dci.pQueueCreateInfos = &qci;
    if (vkCreateDevice(physical, &dci, nullptr, &device) != VK_SUCCESS) return;
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~Engine() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }

  // Some of the engine's own work: a buffer made and dropped, the device idle.
  void work() const {
    ASSERT_TRUE(device) << "no Vulkan device with compute, shaderInt64 and shaderFloat64";
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = 4096, bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer buffer = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateBuffer(device, &bci, nullptr, &buffer), VK_SUCCESS);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    EXPECT_GE(req.size, 4096u);
    vkDestroyBuffer(device, buffer, nullptr);
    EXPECT_EQ(vkDeviceWaitIdle(device), VK_SUCCESS);
    uint32_t n = 0;
    EXPECT_EQ(vkEnumeratePhysicalDevices(instance, &n, nullptr), VK_SUCCESS);
    EXPECT_GT(n, 0u);
  }
};

// A sphere cast through its centre from around it: every ray hits.
void cast_and_check(host::Caster& caster, const std::vector<Ray>& rays, const char* what) {
  std::vector<Hit> now(rays.size()), later(rays.size());
  caster.trace_now(rays, now);
  caster.wait(caster.submit(rays), later);
  for (size_t i = 0; i < rays.size(); ++i) {
    ASSERT_NE(now[i].triangle, MC_NO_HIT) << what << ", ray " << i;
    ASSERT_EQ(later[i].triangle, now[i].triangle) << what << ", ray " << i;
    ASSERT_NEAR(later[i].t, now[i].t, 1e-5f * now[i].t) << what << ", ray " << i;
  }
}

TEST(EngineVulkan, LoaderCallsKeepWorkingBesideCastersOnBothBackends) {
  Engine engine;
  engine.work();
  const Mesh sphere = make_sphere(16, 32, 1, {0, 0, 0});
  const std::vector<uint8_t> blob = build_blob(sphere, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "sphere");
  std::vector<Ray> rays;
  for (int i = 0; i < 256; ++i) {
    const float a = 0.0245f * float(i), b = 0.011f * float(i);
    const float o[3] = {3 * std::cos(a) * std::cos(b), 3 * std::sin(a) * std::cos(b), 3 * std::sin(b)};
    rays.push_back({{o[0], o[1], o[2]}, {-o[0], -o[1], -o[2]}, INFINITY});
  }

  for (host::Backend backend : {host::Backend::Cpu, host::Backend::Vulkan}) {
    host::CasterOptions options;
    options.backend = backend;
    host::Caster caster(blob, "sphere", options);
    if (backend == host::Backend::Vulkan) {
      ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    }
    engine.work();
    cast_and_check(caster, rays, host::backend_name(backend));
    engine.work();
  }
  engine.work();

  // The engine's own device and queue, handed over.
  host::CasterOptions options;
  options.backend = host::Backend::Vulkan;
  options.engine_vulkan = {engine.instance, engine.physical, engine.device, engine.queue, engine.family,
                           reinterpret_cast<void*>(&vkGetInstanceProcAddr)};
  {
    host::Caster caster(blob, "sphere", options);
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    cast_and_check(caster, rays, "the engine's device");
    engine.work();
  }
  // The caster left the engine's device alive and usable.
  engine.work();
}

}  // namespace
}  // namespace meshcast::testing
