// An engine that calls Vulkan itself and links meshcast's host layer beside
// it: this program links the Vulkan loader and calls it directly (its own
// instance, device, a buffer) before, between and after Casters on the CPU
// and Vulkan backends, and hands one Caster its own device and queue. A
// library that defined vk* symbols of its own would replace the loader's
// here, and the first direct call would jump through a null pointer.
#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <cmath>
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "meshcast/caster.h"
#include "meshcast/errors.h"
#include "check/generate.h"

namespace meshcast::testing {
namespace {

// What an engine asks of Vulkan: its instance's version, and which of the
// features meshcast uses it enables on its device (those the device offers).
struct EngineSetup {
  uint32_t api_version = VK_API_VERSION_1_2;
  bool float64 = true;
  bool int64_atomics = true;
};

// The engine's side: plain loader calls, no meshcast.
struct Engine {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  EngineSetup setup;
  // The features the device was created with, as the engine hands them over.
  VkPhysicalDeviceVulkan12Features enabled12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 enabled{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};

  explicit Engine(EngineSetup wanted = {}) : setup(wanted) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "engine";
    app.apiVersion = setup.api_version;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS) return;
    // A Vulkan 1.0 engine queries and enables features the 1.0 way.
    const bool v12 = setup.api_version >= VK_API_VERSION_1_2;
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    bool int64_atomics = false;
    for (VkPhysicalDevice d : devices) {
      VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
      VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
      if (v12) vkGetPhysicalDeviceFeatures2(d, &f2);
      else vkGetPhysicalDeviceFeatures(d, &f2.features);
      uint32_t families = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(d, &families, nullptr);
      std::vector<VkQueueFamilyProperties> qf(families);
      vkGetPhysicalDeviceQueueFamilyProperties(d, &families, qf.data());
      for (uint32_t i = 0; i < families && !physical; ++i)
        if ((qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && f2.features.shaderInt64 && f2.features.shaderFloat64)
          physical = d, family = i, int64_atomics = f12.shaderBufferInt64Atomics;
    }
    if (!physical) return;
    enabled12.shaderBufferInt64Atomics = setup.int64_atomics && int64_atomics;
    enabled.pNext = v12 ? &enabled12 : nullptr;
    enabled.features.shaderInt64 = VK_TRUE;
    enabled.features.shaderFloat64 = setup.float64;
    float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family, qci.queueCount = 1, qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, v12 ? &enabled : nullptr};
    if (!v12) dci.pEnabledFeatures = &enabled.features;
    dci.queueCreateInfoCount = 1, dci.pQueueCreateInfos = &qci;
    if (vkCreateDevice(physical, &dci, nullptr, &device) != VK_SUCCESS) return;
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  Engine(const Engine&) = delete;  // `enabled` points into itself
  Engine& operator=(const Engine&) = delete;
  ~Engine() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }

  // What the engine hands a caster: its objects, the version it created
  // its instance for and the features it created its device with.
  host::VulkanObjects objects() const {
    host::VulkanObjects o{instance, physical, device, queue, family, reinterpret_cast<void*>(&vkGetInstanceProcAddr)};
    o.instance_api_version = setup.api_version;
    o.enabled_features = &enabled;
    return o;
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

// The sphere these tests cast at, in `layout`, and rays through its
// centre from around it: every ray hits.
std::vector<uint8_t> sphere_blob(const char* layout) {
  return build_blob(make_sphere(16, 32, 1, {0, 0, 0}), parse_layout(layout), "sphere");
}

std::vector<Ray> sphere_rays() {
  std::vector<Ray> rays;
  for (int i = 0; i < 256; ++i) {
    const float a = 0.0245f * float(i), b = 0.011f * float(i);
    const float o[3] = {3 * std::cos(a) * std::cos(b), 3 * std::sin(a) * std::cos(b), 3 * std::sin(b)};
    rays.push_back({{o[0], o[1], o[2]}, {-o[0], -o[1], -o[2]}, INFINITY});
  }
  return rays;
}

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
  const std::vector<uint8_t> blob = sphere_blob("QuadTreeHalfFloat/Indexed8BitPackSOA4");
  const std::vector<Ray> rays = sphere_rays();

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
  options.engine_vulkan = engine.objects();
  {
    host::Caster caster(blob, "sphere", options);
    ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
    cast_and_check(caster, rays, "the engine's device");
    engine.work();
  }
  // The caster left the engine's device alive and usable.
  engine.work();
}

// The UsageError a Vulkan caster on `options` throws as it is made ("" when
// it is made).
std::string refusal(const host::CasterOptions& options) {
  const std::vector<uint8_t> blob = sphere_blob("QuadTreeHalfFloat/Indexed8BitPackSOA4");
  try {
    host::Caster caster(blob, "sphere", options);
  } catch (const UsageError& e) {
    return e.what();
  }
  return "";
}

host::CasterOptions on(const Engine& engine) {
  host::CasterOptions options;
  options.backend = host::Backend::Vulkan;
  options.engine_vulkan = engine.objects();
  return options;
}

// An instance created for Vulkan 1.0 offers none of what the shaders
// (SPIR-V for Vulkan 1.2) and the feature query (1.1) need, whatever its
// device offers: refused at the door, naming the version stated.
TEST(EngineVulkan, AnInstanceOfVulkan10IsRefusedNamingTheVersion) {
  Engine engine({VK_API_VERSION_1_0});
  engine.work();
  const std::string why = refusal(on(engine));
  EXPECT_NE(why.find("created for Vulkan 1.0 (instance_api_version)"), std::string::npos) << why;
  EXPECT_NE(why.find("Vulkan 1.2 or later"), std::string::npos) << why;
  engine.work();
}

// Vulkan cannot be asked which version an instance was made for, nor which
// features a device was made with: left unstated, each is refused by name.
TEST(EngineVulkan, AnUnstatedVersionOrFeatureSetIsRefused) {
  Engine engine;
  host::CasterOptions options = on(engine);
  options.engine_vulkan.instance_api_version = 0;
  std::string why = refusal(options);
  EXPECT_NE(why.find("instance_api_version is 0 (not stated)"), std::string::npos) << why;
  options = on(engine);
  options.engine_vulkan.enabled_features = nullptr;
  why = refusal(options);
  EXPECT_NE(why.find("enabled_features is null (not stated)"), std::string::npos) << why;
  // A VkPhysicalDeviceFeatures (the Vulkan 1.0 struct) where the chain's
  // root belongs: its first word is no sType of VkPhysicalDeviceFeatures2.
  VkPhysicalDeviceFeatures2 plain{};
  plain.sType = VkStructureType(VK_TRUE);  // a VkPhysicalDeviceFeatures' robustBufferAccess
  options.engine_vulkan.enabled_features = &plain;
  why = refusal(options);
  EXPECT_NE(why.find("not VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2"), std::string::npos) << why;
  engine.work();
}

// A device that every method's shaders need a feature of (doubles) and
// that was created without it is refused, naming the feature, although
// the physical device offers it.
TEST(EngineVulkan, ADeviceWithoutShaderFloat64IsRefusedNamingIt) {
  Engine engine({VK_API_VERSION_1_2, /*float64=*/false});
  engine.work();
  const std::string why = refusal(on(engine));
  EXPECT_NE(why.find("was created without shaderFloat64 (enabled_features)"), std::string::npos) << why;
  engine.work();
}

// Without 64-bit buffer atomics (which the bruteforce and aabblist methods
// alone need) the device is taken: a blob those methods read leaves the
// CPU answering, gpu_error() naming the feature and the method; a blob
// another method reads is the GPU's.
TEST(EngineVulkan, WithoutInt64AtomicsTheMethodsNeedingThemSayWhy) {
  Engine engine({VK_API_VERSION_1_2, true, /*int64_atomics=*/false});
  engine.work();
  const std::vector<Ray> rays = sphere_rays();
  for (const char* layout : {"BruteForce/Float3SOA128", "AABBList/BitPackSOA128"}) {
    const std::vector<uint8_t> blob = sphere_blob(layout);
    host::Caster caster(blob, "sphere", on(engine));
    EXPECT_FALSE(caster.gpu_available()) << layout;
    const std::string method = std::string(layout).starts_with("Brute") ? "the bruteforce method" : "the aabblist method";
    EXPECT_NE(caster.gpu_error().find("was created without shaderBufferInt64Atomics"), std::string::npos) << caster.gpu_error();
    EXPECT_NE(caster.gpu_error().find(method), std::string::npos) << caster.gpu_error();
    EXPECT_NE(caster.why(100).find("shaderBufferInt64Atomics"), std::string::npos) << caster.why(100);
    cast_and_check(caster, rays, layout);
  }
  const std::vector<uint8_t> blob = sphere_blob("QuadTreeHalfFloat/Indexed8BitPackSOA4");
  host::Caster caster(blob, "sphere", on(engine));
  ASSERT_TRUE(caster.gpu_available()) << caster.gpu_error();
  cast_and_check(caster, rays, "quadtree without 64-bit atomics");
  engine.work();
}

// The engine made its instance (with the layers it wanted) and chose its
// device: meshcast's validation or device option beside it is refused,
// not ignored.
TEST(EngineVulkan, ValidationOrADeviceWithAnEnginesDeviceIsRefused) {
  Engine engine;
  host::CasterOptions options = on(engine);
  options.validation = true;
  std::string why = refusal(options);
  EXPECT_NE(why.find("CasterOptions::validation is set together with engine_vulkan"), std::string::npos) << why;
  options = on(engine);
  options.device = std::string("0");  // not a literal: gcc 12 warns falsely (-Wrestrict) on that assignment
  why = refusal(options);
  EXPECT_NE(why.find("CasterOptions::device '0' is set together with engine_vulkan"), std::string::npos) << why;
  engine.work();
}

}  // namespace
}  // namespace meshcast::testing
