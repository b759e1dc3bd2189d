// The part every GPU method shares: the blob uploaded once into device
// memory (checked against the layouts the method reads), a slot's ray, key,
// hit and row buffers that grow with the batch, a batch cut into pieces
// that fit the device's buffer windows, one submission a batch between two
// timestamps, and the read-back. A method adds its pipelines and records
// each piece's dispatches.
#pragma once
#include <algorithm>
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpu/method.h"
#include "gpu/method_table.h"
#include "gpu/vulkan.h"
#include "layout/formats.h"

namespace meshcast::gpu {

// Push constants every shader of this backend declares. A piece's rays
// from ray_base on, of ray_count; indices are the piece's own.
struct Push {
  uint32_t ray_base, ray_count, records;
};

// The bindings every batch shader shares: 0 the blob, then the per-ray
// buffers read in windows (1 rays, 2 keys, 3 hits, 4 Query::All's rows),
// 5 the batch counters (shaders/batch_counters.glsl).
constexpr uint32_t kBatchBindings = 6;
constexpr uint32_t kPerRayWindows = 0b11110;

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
  std::string refusal(uint64_t rays) const override;
  std::span<Ray> rays(uint32_t slot, uint64_t n) override;
  void submit(uint32_t slot) override;
  bool ready(uint32_t slot) override;
  void wait(uint32_t slot) override;
  std::span<const Hit> hits(uint32_t slot, GpuTiming* timing, uint64_t* unwalkable) override;
  uint64_t finish_lists(uint32_t slot, HitLists& lists, GpuTiming* timing) override;
  void limit_piece(uint32_t rays) override;

 protected:
  // A piece of a batch: its rays, and where its windows of the per-ray
  // buffers start (rays, keys, hits, rows: Pipeline::dispatch's offsets).
  struct Piece {
    uint32_t rays;
    std::array<uint32_t, 4> offsets;
  };
  // Points every pipeline's set `slot` at buffers(slot) with windows(slot)
  // after the slot's buffers change.
  virtual void bind_all(uint32_t slot) = 0;
  // Host-side work before every submission of the slot (the command buffer
  // is recorded once and resubmitted while the batch size stays the same).
  virtual void prepare(uint32_t, uint32_t) {}
  // Records the dispatches of one piece of the slot's batch.
  virtual void record(VkCommandBuffer cb, uint32_t slot, const Piece& piece) = 0;
  // Whether the shaders fold hits into keys (the brute force, AABBList),
  // not into the rows directly (the tree walkers).
  virtual bool reads_keys() const { return true; }
  // The slot's buffers in binding order (kBatchBindings), and the bytes of
  // each window binding's window.
  std::vector<const Buffer*> buffers(uint32_t slot) const;
  std::vector<uint64_t> windows(uint32_t slot) const;
  // A dispatch of one thread a ray over a piece, in as many dispatches as
  // the device's workgroup count limit asks (ray_base steps through it).
  void dispatch_rays(const Pipeline& p, VkCommandBuffer cb, uint32_t slot, const Piece& piece) const;

  Context& ctx_;
  uint32_t records_ = 0;  // the header's node_count (BruteForce: its records)
  const std::string method_;
  const uint32_t flags_, max_hits_;
  bool all() const { return (flags_ & MC_QUERY_ALL) != 0; }

 private:
  void release_slots();
  struct Slot {
    std::unique_ptr<Buffer> rays, keys, hits, rows, counters;
    uint64_t capacity = 0;                 // rays the buffers hold
    uint32_t recorded = 0, n = 0;          // recorded: the batch size its command buffer holds
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    bool in_flight = false, submitted = false;
    double begin_ms = 0;  // steady clock at rays()
  };
  // The bytes a ray takes in each per-ray buffer (0: a 16-byte token the
  // method's shaders never read).
  struct PerRay {
    uint64_t rays, keys, hits, rows;
    uint64_t total() const { return rays + keys + hits + rows; }
    std::array<uint64_t, 4> each() const { return {rays, keys, hits, rows}; }
  };
  PerRay per_ray() const;
  // Rays a piece: the most whose every window fits maxStorageBufferRange,
  // a multiple of 256 (every window's offset then meets any device's
  // minStorageBufferOffsetAlignment), or limit_piece's.
  uint32_t piece_rays() const;
  uint64_t capacity_for(uint64_t n) const;
  // Room for n rays in the slot (GpuError with refusal(n) when it cannot fit).
  void reserve(uint32_t slot, uint64_t n);
  void record_batch(Slot& s, uint32_t slot);
  void finish_batch(Slot& s, GpuTiming* timing);
  // shaders/keys.glsl: a row of keys a ray for Query::All, where the method reads keys at all.
  uint32_t keys_a_ray() const { return all() ? max_hits_ + 1 : 1; }
  std::shared_ptr<Buffer> blob_;  // shared by the methods made on the same blob (Context::blob_buffer)
  std::vector<Slot> slots_;
  uint32_t piece_limit_ = 0;  // limit_piece's (0: the device's)
};

}  // namespace meshcast::gpu
