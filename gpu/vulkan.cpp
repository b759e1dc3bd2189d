#include "gpu/vulkan.h"

#include "layout/blob_format.h"

#include <algorithm>
#include <charconv>
#include <bit>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <mutex>

namespace meshcast::gpu {

namespace {

const char* result_name(VkResult r) {
  switch (r) {
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    default: return "a VkResult error";
  }
}

// "1.2": a Vulkan version as errors name it.
std::string version_text(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." + std::to_string(VK_API_VERSION_MINOR(version));
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool has_layer(const VulkanFunctions& vk, const char* name) {
  uint32_t n = 0;
  vk.EnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vk.EnumerateInstanceLayerProperties(&n, layers.data());
  for (const VkLayerProperties& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}

}  // namespace

namespace {
std::atomic<uint64_t> g_instances_created{0}, g_instances_alive{0};  // instances_made()
}  // namespace

InstanceCount instances_made() { return {g_instances_created.load(), g_instances_alive.load()}; }

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS)
    throw GpuError(std::string("Vulkan: ") + what + " failed (" + result_name(r) + ")", r == VK_ERROR_DEVICE_LOST);
}

VKAPI_ATTR VkBool32 VKAPI_CALL Context::on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* self) {
  auto* ctx = static_cast<Context*>(self);
  std::lock_guard<std::mutex> lock(ctx->message_mutex_);
  ++ctx->messages_;
  ctx->last_message_ = data && data->pMessage ? data->pMessage : "";
  return VK_FALSE;
}

Context::Context(const DeviceChoice& choice) {
  const PFN_vkGetInstanceProcAddr loader = loader_get_instance_proc_addr();
  if (!loader) throw GpuError("Vulkan: no Vulkan loader found (install libvulkan1 and a driver, e.g. mesa-vulkan-drivers)");
  load_global_functions(vk_, loader);
  uint32_t version = VK_API_VERSION_1_0;
  if (vk_.EnumerateInstanceVersion) vk_.EnumerateInstanceVersion(&version);
  if (version < VK_API_VERSION_1_2)
    throw GpuError("Vulkan: the loader offers Vulkan " + version_text(version) + "; meshcast needs 1.2");
  const char* env_validation = std::getenv("MESHCAST_VK_VALIDATION");
  bool validation = choice.validation || (env_validation && std::string(env_validation) == "1");
  if (validation && !has_layer(vk_, "VK_LAYER_KHRONOS_validation"))
    throw GpuError("Vulkan: validation asked for, but VK_LAYER_KHRONOS_validation is not installed (vulkan-validationlayers)");

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "meshcast";
  app.apiVersion = VK_API_VERSION_1_2;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  // Synchronization validation besides the layer's default checks: a
  // missing barrier between a fill, a dispatch and the host's read (hazards
  // the default checks do not see) is a message like any other.
  const VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1, features.pEnabledValidationFeatures = enables;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  if (validation) ici.enabledLayerCount = 1, ici.ppEnabledLayerNames = &layer, ici.enabledExtensionCount = 2,
                  ici.ppEnabledExtensionNames = extensions, ici.pNext = &features;
  check(vk_.CreateInstance(&ici, nullptr, &instance_), "vkCreateInstance");
  ++g_instances_created, ++g_instances_alive;
  // A throw below (no such device, a missing feature) would skip the
  // destructor: release what exists so far, then let it go on.
  try {
    load_instance_functions(vk_, instance_);
    if (validation) {
      if (!vk_.CreateDebugUtilsMessengerEXT || !vk_.DestroyDebugUtilsMessengerEXT)
        throw GpuError("Vulkan: validation asked for, but VK_EXT_debug_utils is missing");
      VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
      mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      mci.pfnUserCallback = &Context::on_message;
      mci.pUserData = this;
      check(vk_.CreateDebugUtilsMessengerEXT(instance_, &mci, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }

    uint32_t count = 0;
    vk_.EnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vk_.EnumeratePhysicalDevices(instance_, &count, devices.data());
    if (devices.empty()) throw GpuError("Vulkan: no device found (install mesa-vulkan-drivers for lavapipe)");
    std::vector<VkPhysicalDeviceProperties> props(count);
    for (uint32_t i = 0; i < count; ++i) vk_.GetPhysicalDeviceProperties(devices[i], &props[i]);
    std::string wanted = choice.device;
    if (wanted.empty())
      if (const char* env = std::getenv("MESHCAST_VK_DEVICE")) wanted = env;
    int pick = -1;
    if (wanted.empty()) {
      for (VkPhysicalDeviceType type : {VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU})
        for (uint32_t i = 0; i < count && pick < 0; ++i)
          if (props[i].deviceType == type) pick = int(i);
      for (uint32_t i = 0; i < count && pick < 0; ++i)
        if (!choice.hardware_only || props[i].deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU) pick = int(i);
      if (pick < 0) {  // hardware_only, and every device is a CPU-type one
        std::string list;
        for (uint32_t i = 0; i < count; ++i) list += (i ? ", " : "") + std::string(props[i].deviceName);
        throw GpuError("Vulkan: no device but CPU-type (software) ones (" + list +
                       "), which the automatic choice passes over: the CPU walkers answer faster; name one "
                       "(CasterOptions::device, $MESHCAST_VK_DEVICE) or ask for Backend::Vulkan to use it");
      }
    } else if (std::all_of(wanted.begin(), wanted.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
      // An index: any number of digits (a long one is no device, not a crash).
      uint64_t index = 0;
      const auto [end, ec] = std::from_chars(wanted.data(), wanted.data() + wanted.size(), index);
      pick = ec == std::errc() && end == wanted.data() + wanted.size() && index < count ? int(index) : -1;
    } else {
      for (uint32_t i = 0; i < count && pick < 0; ++i)
        if (lower(props[i].deviceName).find(lower(wanted)) != std::string::npos) pick = int(i);
    }
    if (pick < 0) {
      std::string list;
      for (uint32_t i = 0; i < count; ++i) list += "\n  " + std::to_string(i) + ": " + props[i].deviceName;
      throw GpuError("Vulkan: no device matches '" + wanted + "' (" +
                     (choice.device.empty() ? "$MESHCAST_VK_DEVICE" : "the device asked for") + "): an index below " +
                     std::to_string(count) + " or part of a name; devices:" + list);
    }
    physical_ = devices[size_t(pick)];
    name_ = props[size_t(pick)].deviceName;
    if (props[size_t(pick)].apiVersion < VK_API_VERSION_1_2) throw GpuError("Vulkan: " + name_ + " does not offer Vulkan 1.2");

    // What every method needs: 64-bit integers (remap words, keys) and
    // doubles (the watertight test's rare redo, the exact BitPack decode).
    // The 64-bit atomics of the packed (t, triangle) minimum only the
    // bruteforce and aabblist methods need: enabled when present, and those
    // two refuse a device without them (require_int64_atomics).
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
    vk_.GetPhysicalDeviceFeatures2(physical_, &f2);
    if (!f2.features.shaderInt64 || !f2.features.shaderFloat64)
      throw GpuError("Vulkan: " + name_ + " lacks shaderInt64 or shaderFloat64, which every GPU method uses");
    VkPhysicalDeviceVulkan12Features e12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    e12.shaderBufferInt64Atomics = f12.shaderBufferInt64Atomics;
    VkPhysicalDeviceFeatures2 e2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &e12};
    e2.features.shaderInt64 = VK_TRUE;
    e2.features.shaderFloat64 = VK_TRUE;

    uint32_t families = 0;
    vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
    std::vector<VkQueueFamilyProperties> qf(families);
    vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, qf.data());
    family_ = families;
    for (uint32_t i = 0; i < families && family_ == families; ++i)
      if (qf[i].queueFlags & VK_QUEUE_COMPUTE_BIT) family_ = i;
    if (family_ == families) throw GpuError("Vulkan: " + name_ + " has no compute queue");

    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family_, qci.queueCount = 1, qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &e2};
    dci.queueCreateInfoCount = 1, dci.pQueueCreateInfos = &qci;
    check(vk_.CreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
    load_device_functions(vk_, device_);
    vk_.GetDeviceQueue(device_, family_, 0, &queue_);
    set_up_device(f12.shaderBufferInt64Atomics == VK_TRUE);
  } catch (...) {
    release();
    throw;
  }
}

namespace {

// The features meshcast reads, as an engine states it created its device
// with them (ExternalDevice::enabled_features) or as a device offers them.
struct Features {
  bool int64 = false, float64 = false, int64_atomics = false;
};

// What the engine's VkPhysicalDeviceFeatures2 chain enables; UsageError for
// a root that is not one, or a chain that does not end (a loop).
Features enabled_in(const VkPhysicalDeviceFeatures2& root) {
  if (root.sType != VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2)
    throw UsageError("Vulkan: the engine's enabled_features has sType " + std::to_string(int(root.sType)) +
                     ", not VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2 (the VkPhysicalDeviceFeatures2 given to vkCreateDevice)");
  Features f{root.features.shaderInt64 == VK_TRUE, root.features.shaderFloat64 == VK_TRUE, false};
  constexpr int kMostLinks = 256;  // far beyond any real chain: more is a loop
  int links = 0;
  for (auto* s = static_cast<const VkBaseInStructure*>(root.pNext); s; s = s->pNext) {
    if (++links > kMostLinks)
      throw UsageError("Vulkan: the engine's enabled_features chain has over " + std::to_string(kMostLinks) +
                       " structures (a pNext loop?)");
    if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES)
      f.int64_atomics |= reinterpret_cast<const VkPhysicalDeviceVulkan12Features*>(s)->shaderBufferInt64Atomics == VK_TRUE;
    else if (s->sType == VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES)
      f.int64_atomics |= reinterpret_cast<const VkPhysicalDeviceShaderAtomicInt64Features*>(s)->shaderBufferInt64Atomics == VK_TRUE;
  }
  return f;
}

}  // namespace

Context::Context(const ExternalDevice& external) : owns_device_(false) {
  // What Vulkan cannot be asked is checked first, before any call that an
  // instance of an older version would not have.
  for (auto [handle, what] : {std::pair<const void*, const char*>{external.instance, "instance"},
                              {external.physical_device, "physical_device"},
                              {external.device, "device"},
                              {external.queue, "queue"}})
    if (!handle) throw UsageError(std::string("Vulkan: the engine's ") + what + " is null (an engine's device needs its instance, physical device, device and queue)");
  if (external.instance_api_version == 0)
    throw UsageError("Vulkan: the engine's instance_api_version is 0 (not stated): give the VkApplicationInfo::apiVersion "
                     "its instance was created with (Vulkan cannot be asked); meshcast needs 1.2 or later");
  if (external.instance_api_version < VK_API_VERSION_1_2)
    throw UsageError("Vulkan: the engine's instance was created for Vulkan " + version_text(external.instance_api_version) +
                     " (instance_api_version); meshcast needs an instance of Vulkan 1.2 or later (its shaders are "
                     "SPIR-V for Vulkan 1.2): create it with VkApplicationInfo::apiVersion VK_API_VERSION_1_2");
  if (!external.enabled_features)
    throw UsageError("Vulkan: the engine's enabled_features is null (not stated): give the VkPhysicalDeviceFeatures2 "
                     "chain its device was created with (Vulkan cannot be asked which features a device enabled)");
  const Features enabled = enabled_in(*external.enabled_features);
  const PFN_vkGetInstanceProcAddr get =
      external.get_instance_proc_addr ? external.get_instance_proc_addr : loader_get_instance_proc_addr();
  if (!get) throw GpuError("Vulkan: no vkGetInstanceProcAddr given and no Vulkan loader found");
  load_global_functions(vk_, get);
  instance_ = external.instance;
  physical_ = external.physical_device;
  device_ = external.device;
  queue_ = external.queue;
  family_ = external.queue_family;
  try {
    load_instance_functions(vk_, instance_);
    load_device_functions(vk_, device_);
    VkPhysicalDeviceProperties props;
    vk_.GetPhysicalDeviceProperties(physical_, &props);
    name_ = props.deviceName;
    uint32_t loader_version = VK_API_VERSION_1_0;
    if (vk_.EnumerateInstanceVersion) vk_.EnumerateInstanceVersion(&loader_version);
    if (loader_version < VK_API_VERSION_1_2)
      throw GpuError("Vulkan: the loader offers Vulkan " + version_text(loader_version) + ", meshcast needs 1.2");
    if (props.apiVersion < VK_API_VERSION_1_2)
      throw UsageError("Vulkan: the engine's device " + name_ + " offers Vulkan " + version_text(props.apiVersion) +
                       ", meshcast needs 1.2 or later");
    uint32_t families = 0;
    vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
    std::vector<VkQueueFamilyProperties> qf(families);
    vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, qf.data());
    if (family_ >= families || !(qf[family_].queueFlags & VK_QUEUE_COMPUTE_BIT))
      throw UsageError("Vulkan: the engine's queue_family " + std::to_string(family_) + " of " + name_ + " (of " +
                       std::to_string(families) + " families) offers no compute, which every GPU method dispatches");
    // What the device offers bounds what the engine may have enabled: a
    // statement beyond it is a mistake (vkCreateDevice would have failed).
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
    vk_.GetPhysicalDeviceFeatures2(physical_, &f2);
    const Features offered{f2.features.shaderInt64 == VK_TRUE, f2.features.shaderFloat64 == VK_TRUE,
                           f12.shaderBufferInt64Atomics == VK_TRUE};
    const std::tuple<bool Features::*, const char*> named[] = {
        {&Features::int64, "shaderInt64"}, {&Features::float64, "shaderFloat64"}, {&Features::int64_atomics, "shaderBufferInt64Atomics"}};
    for (const auto& [feature, what] : named)
      if ((enabled.*feature) && !(offered.*feature))
        throw UsageError("Vulkan: the engine's enabled_features enables " + std::string(what) + ", which " + name_ +
                         " does not offer (its device cannot have been created with it)");
    // What every method needs: 64-bit integers (remap words, keys) and
    // doubles (the watertight test's rare redo, the exact BitPack decode).
    std::string missing;
    for (const auto& [feature, what] : named)
      if (feature != &Features::int64_atomics && !(enabled.*feature)) missing += (missing.empty() ? "" : " and ") + std::string(what);
    if (!missing.empty())
      throw UsageError("Vulkan: the engine's device " + name_ + " was created without " + missing +
                       " (enabled_features), which every GPU method uses: enable it in VkPhysicalDeviceFeatures");
    set_up_device(enabled.int64_atomics);
  } catch (...) {
    release();
    throw;
  }
}

void Context::set_up_device(bool int64_atomics) {
  VkPhysicalDeviceProperties props;
  vk_.GetPhysicalDeviceProperties(physical_, &props);
  limits_ = props.limits;
  vk_.GetPhysicalDeviceMemoryProperties(physical_, &memory_);
  int64_atomics_ = int64_atomics;
  uint32_t families = 0;
  vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
  std::vector<VkQueueFamilyProperties> qf(families);
  vk_.GetPhysicalDeviceQueueFamilyProperties(physical_, &families, qf.data());
  timestamps_ = qf[family_].timestampValidBits > 0 && limits_.timestampPeriod > 0;
  timestamp_ns_ = limits_.timestampPeriod;
  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT, pci.queueFamilyIndex = family_;
  check(vk_.CreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vk_.CreateFence(device_, &fci, nullptr, &fence_), "vkCreateFence");
}

Context::~Context() { release(); }

void Context::release() {
  // Only what this context made: an engine's device and instance stay.
  if (device_) {
    if (owns_device_ && vk_.DeviceWaitIdle) vk_.DeviceWaitIdle(device_);
    if (fence_) vk_.DestroyFence(device_, fence_, nullptr);
    if (pool_) vk_.DestroyCommandPool(device_, pool_, nullptr);
    if (owns_device_ && vk_.DestroyDevice) vk_.DestroyDevice(device_, nullptr);
  }
  if (!owns_device_) return;
  if (messenger_) vk_.DestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  if (instance_ && vk_.DestroyInstance) {
    vk_.DestroyInstance(instance_, nullptr);
    --g_instances_alive;
  }
  instance_ = VK_NULL_HANDLE;
}

VkCommandBuffer Context::allocate_command_buffer() {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = pool_, ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY, ai.commandBufferCount = 1;
  VkCommandBuffer cb;
  check(vk_.AllocateCommandBuffers(device_, &ai, &cb), "vkAllocateCommandBuffers");
  return cb;
}

void Context::free_command_buffer(VkCommandBuffer cb) { vk_.FreeCommandBuffers(device_, pool_, 1, &cb); }

void Context::submit_async(VkCommandBuffer cb, VkFence fence) {
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1, si.pCommandBuffers = &cb;
  check(vk_.ResetFences(device_, 1, &fence), "vkResetFences");
  check(vk_.QueueSubmit(queue_, 1, &si, fence), "vkQueueSubmit");
}

VkCommandBuffer Context::begin() {
  VkCommandBuffer cb = allocate_command_buffer();
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vk_.BeginCommandBuffer(cb, &bi), "vkBeginCommandBuffer");
  return cb;
}

void Context::end_and_wait(VkCommandBuffer cb) {
  check(vk_.EndCommandBuffer(cb), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1, si.pCommandBuffers = &cb;
  check(vk_.ResetFences(device_, 1, &fence_), "vkResetFences");
  check(vk_.QueueSubmit(queue_, 1, &si, fence_), "vkQueueSubmit");
  VkResult r = vk_.WaitForFences(device_, 1, &fence_, VK_TRUE, 600ull * 1000 * 1000 * 1000);
  vk_.FreeCommandBuffers(device_, pool_, 1, &cb);
  check(r, "waiting for the GPU");
}

void Context::require_int64_atomics(const std::string& method) const {
  if (!int64_atomics_)
    throw GpuError("Vulkan: " +
                   (owns_device_ ? name_ + " lacks shaderBufferInt64Atomics"
                                 : "the engine's device " + name_ +
                                       " was created without shaderBufferInt64Atomics (enabled_features: "
                                       "VkPhysicalDeviceVulkan12Features)") +
                   ", which the " + method + " method's 64-bit atomic minimum needs");
}

bool Context::has_memory_type(uint32_t bits, VkMemoryPropertyFlags wanted) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((bits >> i & 1) && (memory_.memoryTypes[i].propertyFlags & wanted) == wanted) return true;
  return false;
}

uint64_t Context::mapped_heap_bytes() const {
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint64_t most = 0;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((memory_.memoryTypes[i].propertyFlags & host) == host)
      most = std::max<uint64_t>(most, memory_.memoryHeaps[memory_.memoryTypes[i].heapIndex].size);
  return most;
}

uint32_t Context::memory_type(uint32_t bits, VkMemoryPropertyFlags wanted, bool required) const {
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i)
    if ((bits >> i & 1) && (memory_.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  if (!required && bits) return uint32_t(std::countr_zero(bits));
  throw GpuError("Vulkan: " + name_ + " has no host-visible coherent memory for storage buffers");
}

Buffer::Buffer(Context& ctx, uint64_t bytes, const std::string& what, VkBufferUsageFlags usage, Memory memory,
               bool windowed)
    : ctx_(ctx), size_(std::max<uint64_t>(bytes, 4)) {
  const bool mapped = memory == Memory::Mapped;
  if (!mapped) usage |= VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (!windowed && size_ > ctx.limits().maxStorageBufferRange)
    throw GpuError("Vulkan: the " + what + " of " + std::to_string(size_) + " bytes exceeds " + ctx.device_name() +
                   "'s maxStorageBufferRange (" + std::to_string(ctx.limits().maxStorageBufferRange) + " bytes)");
  // A refusal part way leaves nothing behind (an engine's device lives on).
  try {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size_, bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | usage, bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(ctx_.vk().CreateBuffer(ctx.device(), &bci, nullptr, &buffer_), "vkCreateBuffer");
    VkMemoryRequirements req;
    ctx_.vk().GetBufferMemoryRequirements(ctx.device(), buffer_, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    // Mapped memory is read back by the host every batch (hits, keys): cached
    // memory where the device has it, since reading uncached (write-combined)
    // memory runs at a fraction of the speed; coherent either way.
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    mai.memoryTypeIndex = !mapped ? ctx.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, false)
                          : ctx.has_memory_type(req.memoryTypeBits, host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                              ? ctx.memory_type(req.memoryTypeBits, host | VK_MEMORY_PROPERTY_HOST_CACHED_BIT)
                              : ctx.memory_type(req.memoryTypeBits, host);
    check(ctx_.vk().AllocateMemory(ctx.device(), &mai, nullptr, &memory_), ("allocating the " + what).c_str());
    check(ctx_.vk().BindBufferMemory(ctx.device(), buffer_, memory_, 0), "vkBindBufferMemory");
    if (mapped) check(ctx_.vk().MapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
  } catch (...) {
    release();
    throw;
  }
}

void Buffer::upload(std::span<const uint8_t> bytes) {
  upload(bytes.size(), [&](uint8_t* staging) { std::memcpy(staging, bytes.data(), bytes.size()); });
}

void Buffer::upload(uint64_t bytes, const std::function<void(uint8_t*)>& fill) {
  if (bytes == 0) return;
  Buffer staging(ctx_, bytes, "staging copy", VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  fill(static_cast<uint8_t*>(staging.data()));
  ctx_.submit([&](VkCommandBuffer cb) {
    VkBufferCopy region{0, 0, bytes};
    ctx_.vk().CmdCopyBuffer(cb, staging.handle(), buffer_, 1, &region);
    // The copy is done before any later submission's shaders read it.
    VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT, mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    ctx_.vk().CmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0, nullptr,
                         0, nullptr);
  });
}

Buffer::~Buffer() { release(); }

void Buffer::release() {  // null handles are ignored by Vulkan's destroy calls
  ctx_.vk().DestroyBuffer(ctx_.device(), buffer_, nullptr);
  ctx_.vk().FreeMemory(ctx_.device(), memory_, nullptr);
  buffer_ = VK_NULL_HANDLE, memory_ = VK_NULL_HANDLE;
}

Pipeline::Pipeline(Context& ctx, const uint32_t* spirv, size_t spirv_bytes, uint32_t bindings, uint32_t push_bytes,
                   uint32_t sets, uint32_t flags, uint32_t max_hits, uint32_t windows)
    : ctx_(ctx), bindings_(bindings), push_bytes_(push_bytes), windows_(windows) {
  try {
    VkDevice d = ctx.device();
    std::vector<VkDescriptorSetLayoutBinding> b(bindings);
    for (uint32_t i = 0; i < bindings; ++i)
      b[i] = {i, type_of(i), 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = bindings, dl.pBindings = b.data();
    check(ctx_.vk().CreateDescriptorSetLayout(d, &dl, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1, pl.pSetLayouts = &set_layout_;
    if (push_bytes) pl.pushConstantRangeCount = 1, pl.pPushConstantRanges = &range;
    check(ctx_.vk().CreatePipelineLayout(d, &pl, nullptr, &layout_), "vkCreatePipelineLayout");
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = spirv_bytes, sm.pCode = spirv;
    VkShaderModule module;
    check(ctx_.vk().CreateShaderModule(d, &sm, nullptr, &module), "vkCreateShaderModule");
    VkComputePipelineCreateInfo cp{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    // A shader that does not declare a constant ignores it (Vulkan spec,
    // VkSpecializationMapEntry).
    const uint32_t constants[2] = {flags, max_hits};
    const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(uint32_t)}, {1, 4, sizeof(uint32_t)}};
    const VkSpecializationInfo spec{2, entries, sizeof constants, constants};
    cp.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_COMPUTE_BIT, module, "main", &spec};
    cp.layout = layout_;
    VkResult r = ctx_.vk().CreateComputePipelines(d, VK_NULL_HANDLE, 1, &cp, nullptr, &pipeline_);
    ctx_.vk().DestroyShaderModule(d, module, nullptr);
    check(r, "vkCreateComputePipelines");
    const uint32_t dynamic = uint32_t(std::popcount(windows_));
    std::vector<VkDescriptorPoolSize> sizes;
    if (bindings > dynamic) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, (bindings - dynamic) * sets});
    if (dynamic) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC, dynamic * sets});
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = sets, dp.poolSizeCount = uint32_t(sizes.size()), dp.pPoolSizes = sizes.data();
    check(ctx_.vk().CreateDescriptorPool(d, &dp, nullptr, &pool_), "vkCreateDescriptorPool");
    std::vector<VkDescriptorSetLayout> layouts(sets, set_layout_);
    sets_handles_.resize(sets);
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = pool_, da.descriptorSetCount = sets, da.pSetLayouts = layouts.data();
    check(ctx_.vk().AllocateDescriptorSets(d, &da, sets_handles_.data()), "vkAllocateDescriptorSets");
  } catch (...) {
    release();
    throw;
  }
}

Pipeline::~Pipeline() { release(); }

void Pipeline::release() {  // null handles are ignored by Vulkan's destroy calls
  VkDevice d = ctx_.device();
  ctx_.vk().DestroyDescriptorPool(d, pool_, nullptr);
  ctx_.vk().DestroyPipeline(d, pipeline_, nullptr);
  ctx_.vk().DestroyPipelineLayout(d, layout_, nullptr);
  ctx_.vk().DestroyDescriptorSetLayout(d, set_layout_, nullptr);
}

VkDescriptorType Pipeline::type_of(uint32_t binding) const {
  return (windows_ >> binding & 1) ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

void Pipeline::bind(const std::vector<const Buffer*>& buffers, uint32_t set, const std::vector<uint64_t>& window_bytes) {
  std::vector<VkDescriptorBufferInfo> info(bindings_);
  std::vector<VkWriteDescriptorSet> writes(bindings_);
  const uint64_t range = ctx_.limits().maxStorageBufferRange;
  for (uint32_t i = 0; i < bindings_; ++i) {
    const bool window = (windows_ >> i & 1) != 0;
    const uint64_t bytes = window && i < window_bytes.size() ? window_bytes[i] : buffers[i]->size();
    if (bytes > range)
      throw GpuError("Vulkan: binding " + std::to_string(i) + " of " + std::to_string(bytes) + " bytes exceeds " +
                     ctx_.device_name() + "'s maxStorageBufferRange (" + std::to_string(range) + " bytes)");
    info[i] = {buffers[i]->handle(), 0, window ? bytes : VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, sets_handles_[set], i, 0, 1, type_of(i),
                 nullptr, &info[i], nullptr};
  }
  ctx_.vk().UpdateDescriptorSets(ctx_.device(), bindings_, writes.data(), 0, nullptr);
}

void Pipeline::bind_for(VkCommandBuffer cb, uint32_t set, const void* push, std::span<const uint32_t> offsets) const {
  const uint32_t dynamic = uint32_t(std::popcount(windows_));
  if (offsets.size() < dynamic) throw std::logic_error("a dispatch without an offset for each window binding");
  ctx_.vk().CmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  ctx_.vk().CmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &sets_handles_[set], dynamic,
                                  dynamic ? offsets.data() : nullptr);
  if (push_bytes_) ctx_.vk().CmdPushConstants(cb, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, push);
}

void Pipeline::dispatch(VkCommandBuffer cb, uint32_t set, const void* push, uint32_t x, uint32_t y, uint32_t z,
                        std::span<const uint32_t> offsets) const {
  bind_for(cb, set, push, offsets);
  ctx_.vk().CmdDispatch(cb, x, y, z);
}

void Pipeline::dispatch_indirect(VkCommandBuffer cb, uint32_t set, const void* push, const Buffer& args,
                                 uint64_t offset, std::span<const uint32_t> offsets) const {
  bind_for(cb, set, push, offsets);
  ctx_.vk().CmdDispatchIndirect(cb, args.handle(), offset);
}

std::shared_ptr<Buffer> Context::blob_buffer(std::span<const uint8_t> blob, const std::string& name) {
  std::lock_guard<std::mutex> lock(blobs_mutex_);
  // The header's checksum: the blob was validated before any method reads it.
  const auto key = std::make_tuple(static_cast<const void*>(blob.data()), blob.size(), layout::header_of(blob.data()).checksum);
  std::erase_if(blobs_, [](const auto& entry) { return entry.second.expired(); });
  if (std::shared_ptr<Buffer> kept = blobs_[key].lock()) return kept;
  auto buffer = std::make_shared<Buffer>(*this, blob.size(), "blob of " + name, 0, Memory::DeviceLocal);
  buffer->upload(blob);
  blobs_[key] = buffer;
  return buffer;
}

void Context::barrier(VkCommandBuffer cb, VkPipelineStageFlags dst_stages, VkAccessFlags dst_access,
                      VkPipelineStageFlags src_stages, VkAccessFlags src_access) const {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = src_access;
  mb.dstAccessMask = dst_access;
  vk_.CmdPipelineBarrier(cb, src_stages, dst_stages, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

void Context::compute_barrier(VkCommandBuffer cb) const {
  barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void Context::fill_barrier(VkCommandBuffer cb) const {
  barrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
}

void Context::host_barrier(VkCommandBuffer cb) const { barrier(cb, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT); }

void Context::indirect_barrier(VkCommandBuffer cb) const {
  barrier(cb, VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace meshcast::gpu
