// The part every GPU method shares: the blob uploaded once into device
// memory (checked against the layouts the method reads), ray/key/hit
// buffers that grow with the batch, one submission a batch between two timestamps, and the read-back.
// A method adds its pipelines and records its dispatches.
#pragma once
#include <algorithm>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpu/method.h"
#include "gpu/method_table.h"
#include "gpu/vulkan.h"
#include "layout/formats.h"

namespace meshcast::gpu {

// Push constants every shader of this backend declares.
struct Push {
  uint32_t ray_base, ray_count, records;
};

class BatchMethod : public Method {
 public:
  // Validates the blob and requires its layout to be the line's
  // (InputError naming the layouts the method reads and the blob's).
  // `flags`, `max_hits`: the batches' query (make_method); UsageError for
  // flags other than MC_HIT_*, MC_QUERY_*, MC_CULL_* or a row length out
  // of range.
  BatchMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const MethodReading& line,
              uint32_t slots, uint32_t flags, uint32_t max_hits);
  ~BatchMethod() override;
  uint32_t slots() const override { return uint32_t(slots_.size()); }
  std::string refusal(uint32_t rays) const override;
  uint64_t begin(uint32_t slot, std::span<const Ray> rays) override;
  bool ready(uint32_t slot) override;
  void wait(uint32_t slot) override;
  void finish(uint32_t slot, std::span<Hit> hits, GpuTiming* timing) override;
  void finish_lists(uint32_t slot, HitLists& lists, GpuTiming* timing) override;

 protected:
  // Points every pipeline's set `slot` at (blob, rays, keys, hits, rows,
  // ...) after the slot's buffers change.
  virtual void bind_all(uint32_t slot) = 0;
  // Host-side work before every submission of the slot (the command buffer
  // is recorded once and resubmitted while the batch size stays the same).
  virtual void prepare(uint32_t, uint32_t) {}
  // Records the dispatches for `n` packed rays in `slot`.
  virtual void record(VkCommandBuffer cb, uint32_t slot, uint32_t n) = 0;
  // Whether the shaders fold hits into keys (the brute force, AABBList),
  // not into the rows directly (the tree walkers).
  virtual bool reads_keys() const { return true; }
  std::vector<const Buffer*> buffers(uint32_t slot) const;

  Context& ctx_;
  uint32_t records_ = 0;  // the header's node_count (BruteForce: its records)
  const std::string method_;
  const uint32_t flags_, max_hits_;
  bool all() const { return (flags_ & MC_QUERY_ALL) != 0; }

 private:
  void release_slots();
  struct Slot {
    std::unique_ptr<Buffer> rays, keys, hits, rows;  // rows: Query::All's (a token buffer otherwise)
    uint32_t capacity = 0, recorded = 0, n = 0;  // recorded: the batch size its command buffer holds
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    bool in_flight = false;
    double begin_ms = 0;  // steady clock at begin()
  };
  // The bytes of a slot's buffers for `capacity` rays, as reserve() makes them.
  struct SlotBytes {
    uint64_t rays, keys, hits, rows;
    uint64_t total() const { return rays + keys + hits + rows; }
  };
  SlotBytes slot_bytes(uint32_t capacity) const;
  static uint32_t capacity_for(uint32_t n) { return std::max<uint32_t>(n, 1024); }
  // Room for n rays in the slot (GpuError with refusal(n) when it cannot fit).
  void reserve(uint32_t slot, uint32_t n);
  void finish_batch(Slot& s, GpuTiming* timing);
  // shaders/keys.glsl: a row of keys a ray for Query::All, where the method reads keys at all.
  uint32_t keys_a_ray() const { return all() && reads_keys() ? max_hits_ + 1 : 1; }
  std::shared_ptr<Buffer> blob_;  // shared by the methods made on the same blob (Context::blob_buffer)
  std::vector<Slot> slots_;
};

}  // namespace meshcast::gpu
