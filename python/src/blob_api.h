// meshcast.Blob: a built or loaded blob, validated once, cast against on
// the library's threads or, with backend="vulkan", by the host layer's
// Vulkan caster; and meshcast.build, meshcast.load, meshcast.read_mesh.
#pragma once
#include <pybind11/pybind11.h>

#include <sys/types.h>

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "meshcast/blob.h"
#include "host/jobs.h"
#include "meshcast/caster.h"

namespace meshcast::python {

namespace py = pybind11;

class PyBlob {
 public:
  PyBlob(std::vector<uint8_t> bytes, std::string name);            // built here
  PyBlob(std::shared_ptr<const MappedBlob> file, std::string name);  // mapped from a file
  ~PyBlob();
  PyBlob(const PyBlob&) = delete;
  PyBlob& operator=(const PyBlob&) = delete;
  const BlobView& view() const { return *view_; }
  const std::string& name() const { return name_; }
  bool mapped() const { return mapped_ != nullptr; }
  const std::shared_ptr<const MappedBlob>& mapped_file() const { return mapped_; }
  // The Vulkan caster for answers carrying `outputs`, made on first use;
  // RuntimeError when it has no GPU (its reason). Batches through it are
  // one at a time (the lock held from submit to wait).
  host::Caster& vulkan(HitOutputs outputs, std::unique_lock<std::mutex>& lock);

 private:
  // The Vulkan casters of one process. A child forked from the process
  // (multiprocessing's default on Linux) inherits them without their
  // threads, with a device that is its parent's and a lock another thread
  // may have held at the fork: it makes a set of its own and never touches
  // (nor destroys) the parent's.
  struct GpuCasters {
    pid_t process;
    std::shared_ptr<host::WorkerPool> pool;  // the CPU's share of the casters' work: the process's pool
    std::mutex mutex;
    std::map<uint32_t, std::unique_ptr<host::Caster>> casters;
  };
  GpuCasters& gpu_casters();
  std::vector<uint8_t> owned_;
  std::shared_ptr<const MappedBlob> mapped_;
  std::string name_;
  std::optional<BlobView> view_;
  std::atomic<GpuCasters*> gpu_{nullptr};
};

void register_blob(py::module_& m);

}  // namespace meshcast::python
