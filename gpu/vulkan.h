// The Vulkan context every GPU method shares (Vulkan 1.2, its functions in
// a table of its own: gpu/vk_functions.h): an instance and one device chosen
// deterministically with its compute queue, or an engine's own, and small owners for buffers and compute pipelines. Nothing here knows a blob
// layout; the methods (gpu/bruteforce.cpp, ...) do.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "gpu/vk_functions.h"
#include "meshcast/errors.h"

namespace meshcast::gpu {

// GpuError (meshcast/errors.h): the CPU path never needs the GPU.
// UsageError: an engine's objects that lack what meshcast needs.
using meshcast::GpuError;
using meshcast::UsageError;

struct DeviceChoice {
  // "" : $MESHCAST_VK_DEVICE, else the first discrete GPU, else the first
  // integrated one, else the first device (enumeration order); otherwise a
  // device index or a case-insensitive part of its name.
  std::string device;
  // Validation layers (VK_LAYER_KHRONOS_validation); also turned on by
  // $MESHCAST_VK_VALIDATION=1. Every message they send is counted.
  bool validation = false;
  // The default choice ("" and no $MESHCAST_VK_DEVICE) passes over
  // CPU-type devices (VK_PHYSICAL_DEVICE_TYPE_CPU: a software rasterizer
  // such as lavapipe, running on the cores the CPU walkers use, and far
  // slower than them on the same rays):
  // GpuError saying so when no other device is there, the instance then
  // destroyed at once. A device named (an index, a part of its name) is
  // taken whatever its type. The Automatic backend's choice.
  bool hardware_only = false;
};

// The VkInstances contexts have created in this process, and how many of
// them still exist (an engine's are never counted): how a test sees that
// a caster that will not use the GPU starts no Vulkan, or keeps none.
struct InstanceCount {
  uint64_t created = 0, alive = 0;
};
InstanceCount instances_made();

// An engine's own Vulkan objects, for a context that makes none of its own
// (it still makes a command pool, fences and its buffers on that device).
// What meshcast needs of them (meshcast/caster.h, VulkanObjects, says it to
// the engine): an instance created for Vulkan 1.2 or later and a device
// offering 1.2 (the shaders are SPIR-V for Vulkan 1.2), shaderInt64 and
// shaderFloat64 enabled on the device (shaderBufferInt64Atomics too for the
// bruteforce and aabblist methods), no extension, and a queue of
// `queue_family`, which offers compute. Vulkan cannot tell which version an
// instance was created for, nor which features a device was created with:
// the engine states both (instance_api_version, enabled_features) and the
// context checks them, and what the physical device offers, before it
// calls anything of Vulkan 1.1 or later. Vulkan's rule holds that no two
// threads submit to one queue at once: give meshcast a queue the engine
// does not submit to from another thread (a Caster's: none the engine
// submits to at all, see VulkanObjects). The engine's objects must outlive
// the context, which never destroys them.
struct ExternalDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;  // null: the loader's
  // VkApplicationInfo::apiVersion of the instance (0: not stated, refused).
  uint32_t instance_api_version = 0;
  // The features the device was created with: the VkPhysicalDeviceFeatures2
  // the engine chained to VkDeviceCreateInfo, its pNext chain read for
  // VkPhysicalDeviceVulkan12Features or VkPhysicalDeviceShaderAtomicInt64Features
  // (null: not stated, refused). Read by the constructor alone.
  const VkPhysicalDeviceFeatures2* enabled_features = nullptr;
};

class Buffer;

class Context {
 public:
  explicit Context(const DeviceChoice& choice = {});
  // UsageError naming what the engine's objects lack (a version, a
  // feature, a compute queue) or left unstated; GpuError for a Vulkan call
  // that failed.
  explicit Context(const ExternalDevice& external);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const std::string& device_name() const { return name_; }
  VkDevice device() const { return device_; }
  const VulkanFunctions& vk() const { return vk_; }
  const VkPhysicalDeviceLimits& limits() const { return limits_; }
  uint32_t validation_messages() const { return messages_.load(); }
  std::string last_validation_message() const {
    std::lock_guard<std::mutex> lock(message_mutex_);
    return last_message_;
  }
  double timestamp_period_ns() const { return timestamp_ns_; }
  bool has_timestamps() const { return timestamps_; }
  // GpuError naming `method` when the device lacks 64-bit buffer atomics
  // (an engine's device: was not created with them).
  void require_int64_atomics(const std::string& method) const;

  // The blob's device-local copy, uploaded once and shared by every method
  // made on the same bytes (a caster's methods for its queries): kept while
  // a method holds it. The bytes are the caller's, unchanged while in use
  // (BlobView's rule); the key is their address, size and checksum.
  std::shared_ptr<Buffer> blob_buffer(std::span<const uint8_t> blob, const std::string& name);

  // Command buffers kept for resubmission, and their submission without
  // waiting (the caller's fence signals completion). Not thread-safe.
  VkCommandBuffer allocate_command_buffer();
  void free_command_buffer(VkCommandBuffer cb);
  void submit_async(VkCommandBuffer cb, VkFence fence);

  // Records `record` into a one-time command buffer, submits it and waits.
  template <class F>
  void submit(F&& record) {
    VkCommandBuffer cb = begin();
    record(cb);
    end_and_wait(cb);
  }

  // A memory type among `bits` with all of `wanted`; with `required` false
  // any of `bits` when none has them, else GpuError.
  uint32_t memory_type(uint32_t bits, VkMemoryPropertyFlags wanted, bool required = true) const;

  // A barrier that makes compute-shader writes visible to the next dispatch.
  void compute_barrier(VkCommandBuffer cb) const;
  // The same, and visible as the arguments of the next indirect dispatch.
  void indirect_barrier(VkCommandBuffer cb) const;
  // vkCmdFillBuffer's writes made visible to the next dispatch.
  void fill_barrier(VkCommandBuffer cb) const;
  // Compute-shader writes to mapped memory made visible to the host that
  // reads them once the submission's fence signals.
  void host_barrier(VkCommandBuffer cb) const;
  bool has_memory_type(uint32_t bits, VkMemoryPropertyFlags wanted) const;
  // The largest memory heap with a host-visible, coherent memory type: what
  // every Memory::Mapped buffer of a batch (rays, keys, hits, rows) is
  // allocated from, together with whatever else holds it.
  uint64_t mapped_heap_bytes() const;

 private:
  VkCommandBuffer begin();
  void end_and_wait(VkCommandBuffer cb);
  void release();
  // What both constructors do once the device is known: its properties,
  // features, queue family, command pool and fence.
  void set_up_device(bool int64_atomics);
  // From the compute shaders' reads and writes (or `src_*`) to `dst_*`.
  void barrier(VkCommandBuffer cb, VkPipelineStageFlags dst_stages, VkAccessFlags dst_access,
               VkPipelineStageFlags src_stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
               VkAccessFlags src_access = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT) const;
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                   VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT*, void*);

  std::mutex blobs_mutex_;
  std::map<std::tuple<const void*, size_t, uint32_t>, std::weak_ptr<Buffer>> blobs_;
  VulkanFunctions vk_;
  bool owns_device_ = true;  // false: the engine's instance and device
  uint32_t family_ = 0;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkPhysicalDeviceLimits limits_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  std::string name_;
  // The validation layer may call on_message from any thread that calls Vulkan.
  mutable std::mutex message_mutex_;
  std::string last_message_;
  std::atomic<uint32_t> messages_{0};
  double timestamp_ns_ = 0;
  bool timestamps_ = false;
  bool int64_atomics_ = false;
};

// A storage buffer; `usage` adds to STORAGE_BUFFER (INDIRECT_BUFFER for
// dispatch arguments).
//   Mapped       host-visible and coherent, mapped for its whole life: what
//                the host writes or reads every batch (rays, hits, keys).
//   DeviceLocal  the device's own memory where it has any, never mapped,
//                filled once by upload() through a staging copy: the blob,
//                which the shaders read over and over (on a discrete GPU
//                host-visible memory would be read across the bus).
enum class Memory { Mapped, DeviceLocal };

class Buffer {
 public:
  // `windowed`: bound only in windows (Pipeline's window bindings), so its
  // size is not held to maxStorageBufferRange.
  Buffer(Context& ctx, uint64_t bytes, const std::string& what, VkBufferUsageFlags usage = 0,
         Memory memory = Memory::Mapped, bool windowed = false);
  ~Buffer();
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  VkBuffer handle() const { return buffer_; }
  uint64_t size() const { return size_; }
  void* data() const { return mapped_; }  // null for DeviceLocal
  // Copies `bytes` (at most size()) to the start of a DeviceLocal buffer
  // through a mapped staging buffer and one transfer; waits for it.
  void upload(std::span<const uint8_t> bytes);
  // The same for `bytes` that fill() writes into the staging buffer itself:
  // pieces gathered from several places (the scene's blobs, each where its
  // owner keeps it) without a host copy of the whole first.
  void upload(uint64_t bytes, const std::function<void(uint8_t* staging)>& fill);

 private:
  void release();
  Context& ctx_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  uint64_t size_ = 0;
};

// A compute pipeline over `sets` descriptor sets (one a frame slot) of
// `bindings` storage buffers (binding i = buffer i) and `push_bytes` of push
// constants. `hit_outputs` (MC_HIT_*) is specialization constant 0, which
// shaders/hits.glsl reads: the per-hit outputs are fixed with the pipeline.
// The bindings in `windows` (a bit a binding) are dynamic storage buffers:
// each dispatch reads a window of its buffer at an offset of its own (a
// batch's piece: gpu/batch.h), so a buffer may pass maxStorageBufferRange.
class Pipeline {
 public:
  // `flags` and `max_hits`: specialization constants 0 and 1 (the batch's
  // MC_HIT_*, MC_QUERY_* and MC_CULL_* word; Query::All's row length).
  Pipeline(Context& ctx, const uint32_t* spirv, size_t spirv_bytes, uint32_t bindings, uint32_t push_bytes,
           uint32_t sets = 1, uint32_t flags = 0, uint32_t max_hits = 1, uint32_t windows = 0);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;
  // Points binding i of descriptor set `set` at buffers[i]: the whole
  // buffer, or for a window binding its first window_bytes[i] bytes
  // (GpuError past maxStorageBufferRange, naming the buffer).
  void bind(const std::vector<const Buffer*>& buffers, uint32_t set = 0, const std::vector<uint64_t>& window_bytes = {});
  // `offsets`: where each window binding's window starts, in binding
  // order (the first popcount(windows) of them are read).
  void dispatch(VkCommandBuffer cb, uint32_t set, const void* push, uint32_t x, uint32_t y, uint32_t z,
                std::span<const uint32_t> offsets = {}) const;
  // The workgroup counts from a VkDispatchIndirectCommand at `offset` of `args`.
  void dispatch_indirect(VkCommandBuffer cb, uint32_t set, const void* push, const Buffer& args, uint64_t offset,
                         std::span<const uint32_t> offsets = {}) const;

 private:
  void bind_for(VkCommandBuffer cb, uint32_t set, const void* push, std::span<const uint32_t> offsets) const;
  VkDescriptorType type_of(uint32_t binding) const;
  void release();
  Context& ctx_;
  uint32_t bindings_, push_bytes_, windows_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_handles_;
};

// Throws GpuError naming `what` when r is not VK_SUCCESS.
void check(VkResult r, const char* what);

}  // namespace meshcast::gpu
