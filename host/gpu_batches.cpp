// The caster's GPU: its device and methods, blob batches begun on the
// caller's thread, scene batches begun on the caster's GPU thread, which
// waits for every GPU batch's fence in submission order; and a lost
// device, after which the CPU answers.
#include "host/caster_impl.h"

#include <chrono>

#include "meshcast/errors.h"
#include "gpu/method.h"
#if MESHCAST_VULKAN
#include "gpu/scene.h"
#include "gpu/vulkan.h"
#endif
#include "layout/blob_format.h"
#include "layout/queries.h"

namespace meshcast::host {

// The device and the method reading the blob, and the thread that waits
// for their batches; a device that is missing or fails leaves gpu_error_
// saying why (an engine's that lacks what meshcast needs: UsageError).
void Caster::Impl::open_gpu(std::span<const uint8_t> blob, const std::string& name) {
#if !MESHCAST_VULKAN
  (void)blob, (void)name;
  gpu_error_ = "meshcast was built without its Vulkan backend (MESHCAST_VULKAN=OFF): the CPU answers";
#else
  bool refused_at_the_door = false;
  try {
    const VulkanObjects& engine = options_.engine_vulkan;
    if (engine.device) {
      gpu::ExternalDevice external;
      external.instance = static_cast<VkInstance>(engine.instance);
      external.physical_device = static_cast<VkPhysicalDevice>(engine.physical_device);
      external.device = static_cast<VkDevice>(engine.device);
      external.queue = static_cast<VkQueue>(engine.queue);
      external.queue_family = engine.queue_family;
      external.get_instance_proc_addr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(engine.get_instance_proc_addr);
      external.instance_api_version = engine.instance_api_version;
      external.enabled_features = static_cast<const VkPhysicalDeviceFeatures2*>(engine.enabled_features);
      try {
        gpu_ = std::make_shared<gpu::Context>(external);
      } catch (const UsageError&) {  // the engine's objects lack what meshcast needs
        refused_at_the_door = true;
        throw;
      }
    } else {
      // Automatic takes no software device by itself: it would measure
      // for a moment only to find the CPU faster at every size.
      gpu_ = std::make_shared<gpu::Context>(
          gpu::DeviceChoice{options_.device, options_.validation, options_.backend == Backend::Automatic});
    }
    // The method that reads the blob's layout, or the one asked for:
    // trying each method in turn would let one that needs a feature the
    // device lacks (64-bit atomics) refuse the device for a blob that
    // only another method reads.
    const std::string m = options_.gpu_method.empty() && view_ ? gpu::method_reading(blob) : options_.gpu_method;
    if (view_ && m.empty())
      throw GpuError("no GPU method reads " + std::string(layout::tree_format_name(layout::header_of(blob.data()).tree_format)) +
                          "/" + std::string(layout::triangle_format_name(layout::header_of(blob.data()).triangle_format)));
    if (view_) {  // scene batches alone: the context is all they need
      method_ = gpu::make_method(*gpu_, m, blob, name, uint32_t(slots_.size()), uint32_t(options_.hit_outputs));
      method_name_ = m;
    }
    completion_ = std::thread([this] { gpu_completions(); });
  } catch (const std::exception& e) {  // GpuError, or InputError for a method that does not read the layout
    method_.reset();
    gpu_.reset();
    if (refused_at_the_door) throw;  // nothing was started: the caster is not made
    gpu_error_ = e.what();
  }
#endif
}

#if MESHCAST_VULKAN
VulkanInstances vulkan_instances() {
  const gpu::InstanceCount n = gpu::instances_made();
  return {n.created, n.alive};
}
#else
VulkanInstances vulkan_instances() { return {}; }
#endif

#if MESHCAST_VULKAN
std::string Caster::Impl::device_name() const { return gpu_ ? gpu_->device_name() : "none"; }
uint32_t Caster::Impl::validation_messages() const { return gpu_ ? gpu_->validation_messages() : 0; }
#else
std::string Caster::Impl::device_name() const { return "none"; }
uint32_t Caster::Impl::validation_messages() const { return 0; }
#endif

gpu::Method* Caster::Impl::method_for(const BatchQuery& q) {
#if !MESHCAST_VULKAN
  (void)q;
  return method_.get();  // not reached: without the Vulkan backend no batch goes to a GPU
#else
  const uint32_t flags = uint32_t(options_.hit_outputs) | layout::query_bits(q.query, q.cull);
  if (flags == uint32_t(options_.hit_outputs)) return method_.get();
  const uint32_t max_hits = q.query == Query::All ? q.max_hits : 1;
  std::unique_ptr<gpu::Method>& m = query_methods_[{flags, max_hits}];
  if (!m) m = gpu::make_method(*gpu_, method_name_, view_->bytes(), "the caster's blob", uint32_t(slots_.size()), flags, max_hits);
  return m.get();
#endif
}

void Caster::Impl::place_on_gpu(Slot& s) {
  std::lock_guard<std::mutex> lock(gpu_mutex_);
  s.method = method_for(s.query);
  s.placed = s.method->rays(s.index, s.n);
}

void Caster::Impl::start_gpu(Slot& s) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    std::lock_guard<std::mutex> lock(gpu_mutex_);
    if (options_.before_gpu_submit) options_.before_gpu_submit();
    s.method->submit(s.index);
  }
  s.ran_on = Backend::Vulkan;
  s.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  {
    std::lock_guard<std::mutex> lock(pending_mutex_);
    pending_.push_back(&s);
  }
  pending_changed_.notify_one();
}

void Caster::Impl::gpu_refused(Slot& s, const GpuError& e) {
  if (e.lost) gpu_failed(e.what());
  s.rays_to_own_array();  // the mapped memory is the method's, the next batch's
  start_cpu(s);
}

// The one thread that waits for GPU batches, in submission order, so each
// batch's ready time is taken when its fence signals, not when the game
// happens to ask. A failed wait (a lost device) moves the batch, and every
// later one, to the CPU.
void Caster::Impl::gpu_completions() {
  for (;;) {
    Slot* s = nullptr;
    {
      std::unique_lock<std::mutex> lock(pending_mutex_);
      pending_changed_.wait(lock, [this] { return stopping_ || !pending_.empty(); });
      if (pending_.empty()) {
        scene_methods_.clear();  // made and used by this thread alone: let go here too
        return;
      }
      s = pending_.front();
      pending_.pop_front();
    }
    try {
      if (gpu_failed_) throw GpuError(gpu_error());
      if (s->scene) run_scene_on_gpu(*s);
      else s->method->wait(s->index);
      complete(*s, Backend::Vulkan);
    } catch (const GpuError& e) {  // the device is lost, or (a scene batch, before it began) refused it
      if (e.lost || !s->scene) gpu_failed(e.what());
      cpu_instead(*s);
    } catch (...) {  // a scene the GPU method does not read (a layout, a limit), or the test hook's own: the CPU's
      cpu_instead(*s);
    }
  }
}

bool Caster::Impl::scene_on_gpu(const SceneBatchQuery& q, const SceneSnapshot& frame) const {
#if !MESHCAST_VULKAN
  (void)q, (void)frame;
  return false;
#else
  return options_.backend == Backend::Vulkan && gpu_available() && q.query != Query::All &&
         gpu::SceneMethod::refusal(frame).empty();  // a mesh it does not read: the CPU's at once, not after the queue
#endif
}

void Caster::Impl::run_scene_on_gpu(Slot& s) {
#if !MESHCAST_VULKAN
  (void)s;  // not reached: without the Vulkan backend there is no device
#else
  const SceneBatchQuery& q = s.scene_query;
  const uint32_t flags = (uint32_t(options_.hit_outputs) & MC_HIT_UV) | layout::query_bits(q.query, q.cull);
  gpu::SceneMethod* method = nullptr;
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(gpu_mutex_);  // the queue and the command pool are shared
    if (options_.before_gpu_submit) options_.before_gpu_submit();
    std::shared_ptr<gpu::SceneMethod>& m = scene_methods_[flags];
    if (!m) m = std::make_shared<gpu::SceneMethod>(*gpu_, flags);
    method = m.get();
    method->begin(*s.scene, s.world, q.mask);
    s.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  try {
    method->finish(s.scene_hits);  // waits for the fence alone: blob batches may begin meanwhile
  } catch (const GpuError& e) {
    // A batch begun but not finished (its fence never signalled) leaves
    // the device unusable, whatever the error says: lost.
    throw GpuError(e.what(), true);
  }
#endif
}

void Caster::Impl::gpu_failed(const std::string& why) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!gpu_failed_.exchange(true)) gpu_error_ = why;
}

}  // namespace meshcast::host
