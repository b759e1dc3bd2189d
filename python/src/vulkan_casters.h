// The Vulkan casters behind backend="vulkan": one host::Caster for each
// set of hit outputs a caller asks for, made on first use, for a blob
// (Blob.cast) or for scene batches (RaycastingScene's casts).
#pragma once
#include <sys/types.h>

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>

#include "host/jobs.h"
#include "meshcast/caster.h"

namespace meshcast::python {

class VulkanCasters {
 public:
  // Makes a caster with the options given (backend, frames, outputs and
  // the process's worker pool filled in).
  using Make = std::function<std::unique_ptr<host::Caster>(const host::CasterOptions&)>;
  VulkanCasters() = default;
  VulkanCasters(const VulkanCasters&) = delete;
  VulkanCasters& operator=(const VulkanCasters&) = delete;
  ~VulkanCasters();
  // The caster for answers carrying `outputs`, made with `make` the first
  // time; GpuError (RuntimeError) when it found no GPU, saying why.
  // Batches through it are one at a time: `lock` holds it from the call to
  // the caller's wait.
  host::Caster& get(HitOutputs outputs, const Make& make, std::unique_lock<std::mutex>& lock);

 private:
  // The casters of one process. A child forked from the process
  // (multiprocessing's default on Linux) inherits them without their
  // threads, with a device that is its parent's and a lock another thread
  // may have held at the fork: it makes a set of its own and never touches
  // (nor destroys) the parent's.
  struct Set {
    pid_t process;
    std::shared_ptr<host::WorkerPool> pool;  // the CPU's share of the casters' work: the process's pool
    std::mutex mutex;
    std::map<uint32_t, std::unique_ptr<host::Caster>> casters;
  };
  Set& of_this_process();
  std::atomic<Set*> set_{nullptr};
};

}  // namespace meshcast::python
