// The part every GPU method shares: the blob uploaded once into device
// memory (checked against the layouts the method reads), ray/key/hit
// buffers that grow with the batch, one submission a batch between two timestamps, and the read-back.
// A method adds its pipelines and records its dispatches.
#pragma once
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpu/method.h"

namespace meshcast::gpu {

// Push constants every shader of this backend declares.
struct Push {
  uint32_t ray_base, ray_count, records;
};

// The blob's triangle format (0 for a buffer too short to say): a method
// that reads several picks its shaders by it, BatchMethod refuses the rest.
uint32_t blob_triangle_format(std::span<const uint8_t> blob);

class BatchMethod : public Method {
 public:
  // Validates the blob and requires its layout to be `tree`/`triangles`
  // (InputError naming the method and both layouts otherwise).
  BatchMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const std::string& method,
              uint32_t tree, uint32_t triangles);
  ~BatchMethod() override;
  uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, GpuTiming* timing) override;

 protected:
  // Points every pipeline at (blob, rays, keys, hits) after the buffers change.
  virtual void bind_all() = 0;
  // Records the dispatches for `n` packed rays.
  virtual void record(VkCommandBuffer cb, uint32_t n) = 0;
  std::vector<const Buffer*> buffers() const { return {&*blob_, &*rays_, &*keys_, &*hits_}; }

  Context& ctx_;
  uint32_t records_ = 0;  // the header's node_count (BruteForce: its records)

 private:
  void reserve(uint32_t n);
  std::optional<Buffer> blob_, rays_, keys_, hits_;
  uint32_t capacity_ = 0;
  VkQueryPool queries_ = VK_NULL_HANDLE;
};

}  // namespace meshcast::gpu
