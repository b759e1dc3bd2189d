#include "python/src/vulkan_casters.h"

#include <unistd.h>

#include "meshcast/errors.h"
#include "python/src/parallel.h"

namespace meshcast::python {

VulkanCasters::~VulkanCasters() {
  Set* set = set_.load();
  if (set && set->process == getpid()) delete set;  // a parent's casters are left alone (of_this_process())
}

VulkanCasters::Set& VulkanCasters::of_this_process() {
  const pid_t process = getpid();
  Set* set = set_.load();
  while (!set || set->process != process) {
    auto* made = new Set;
    made->process = process;
    if (set_.compare_exchange_strong(set, made)) return *made;  // a parent's set, if any, is dropped unread
    delete made;  // another thread of this process made one first: `set` is that one now
  }
  return *set;
}

host::Caster& VulkanCasters::get(HitOutputs outputs, const Make& make, std::unique_lock<std::mutex>& lock) {
  Set& set = of_this_process();
  lock = std::unique_lock<std::mutex>(set.mutex);
  std::unique_ptr<host::Caster>& caster = set.casters[uint32_t(outputs)];
  if (!caster) {
    host::CasterOptions options;
    options.backend = host::Backend::Vulkan;
    options.frames = 1;  // one batch at a time, under the lock
    options.hit_outputs = outputs;
    // The process's pool, not one more of every core's threads a caster.
    if (!set.pool) set.pool = shared_pool(thread_count(0));
    options.jobs = set.pool.get();
    caster = make(options);
  }
  if (!caster->gpu_available()) throw GpuError("backend \"vulkan\": " + caster->gpu_error());
  return *caster;
}

}  // namespace meshcast::python
