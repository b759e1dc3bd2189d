// meshcast.Blob: a built or loaded blob, validated once, cast against on
// the library's threads or, with backend="vulkan", by the host layer's
// Vulkan caster; and meshcast.build, meshcast.load, meshcast.read_mesh.
#pragma once
#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/caster.h"
#include "python/src/vulkan_casters.h"

namespace meshcast::python {

namespace py = pybind11;

class PyBlob {
 public:
  PyBlob(std::vector<uint8_t> bytes, std::string name);            // built here
  // Mapped from the file at `path` (absolute: what a pickled Blob names).
  PyBlob(std::shared_ptr<const MappedBlob> file, std::string name, std::string path);
  PyBlob(const PyBlob&) = delete;
  PyBlob& operator=(const PyBlob&) = delete;
  const BlobView& view() const { return *view_; }
  const std::string& name() const { return name_; }
  bool mapped() const { return mapped_ != nullptr; }
  const std::shared_ptr<const MappedBlob>& mapped_file() const { return mapped_; }
  const std::string& path() const { return path_; }  // empty for bytes in memory
  // The Vulkan caster for answers carrying `outputs` (VulkanCasters::get).
  host::Caster& vulkan(HitOutputs outputs, std::unique_lock<std::mutex>& lock);

 private:
  std::vector<uint8_t> owned_;
  std::shared_ptr<const MappedBlob> mapped_;
  std::string name_;
  std::string path_;
  std::optional<BlobView> view_;
  VulkanCasters gpu_;
};

void register_blob(py::module_& m);

}  // namespace meshcast::python
