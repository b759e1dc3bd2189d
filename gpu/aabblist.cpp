// Method 2 of seed 000 §7: AABBList over Float3SOA128 or BitPackSOA128
// records. Rays go in chunks small enough that every (ray, batch) pair of a
// chunk fits the pair buffer, so the append can never overflow; a chunk is
// pass 1 (every ray of the chunk against every batch box, entered boxes
// appended as pairs), a one-thread pass writing pass 2's indirect dispatch
// from the count, and pass 2 (each pair's triangles folded into the ray's
// key). After the last chunk the brute force's resolve pass turns keys into
// hits: both methods read the same records and keys.
#include <algorithm>
#include <cstring>

#include "gpu/batch.h"
#include "shaders/aabblist_args.h"
#include "shaders/aabblist_boxes.h"

namespace meshcast::gpu {

namespace {

// The passes before the resolve read the rays, keys and hits in windows;
// their bindings 4 and 5 are the pairs and the dispatch arguments.
constexpr uint32_t kPassWindows = 0b01110;

class AABBListMethod : public BatchMethod {
 public:
  AABBListMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const MethodReading& line,
                 uint64_t pairs, uint32_t slots, uint32_t flags, uint32_t max_hits)
      : BatchMethod(ctx, blob, name, line, slots, flags, max_hits),
        boxes_(ctx, aabblist_boxes_spv, sizeof aabblist_boxes_spv, 6, sizeof(Push), slots, flags, max_hits, kPassWindows),
        args_(ctx, aabblist_args_spv, sizeof aabblist_args_spv, 6, sizeof(Push), slots, flags, max_hits, kPassWindows),
        test_(ctx, line.test.words, line.test.bytes, 6, sizeof(Push), slots, flags, max_hits, kPassWindows),
        resolve_(ctx, line.resolve.words, line.resolve.bytes, kBatchBindings, sizeof(Push), slots, flags, max_hits,
                 kPerRayWindows) {
    const uint64_t capacity = std::max<uint64_t>(pairs, records_);
    for (uint32_t k = 0; k < this->slots(); ++k) {  // every slot in flight has its own pairs and counter
      pairs_.push_back(std::make_unique<Buffer>(ctx, capacity * 8, "AABBList pair buffer"));
      control_.push_back(std::make_unique<Buffer>(ctx, 5 * 4, "AABBList dispatch arguments", VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT));
    }
    chunk_ = uint32_t(std::clamp<uint64_t>(capacity / records_, 1, ctx.limits().maxComputeWorkGroupCount[1]));
  }

 protected:
  void bind_all(uint32_t slot) override {
    // The passes before the resolve: (blob, rays, keys, hits, pairs,
    // control); the resolve's fifth binding is the rows.
    std::vector<const Buffer*> all = buffers(slot);
    all.resize(4);
    all.push_back(pairs_[slot].get()), all.push_back(control_[slot].get());
    for (Pipeline* p : {&boxes_, &args_, &test_}) p->bind(all, slot, windows(slot));
    resolve_.bind(buffers(slot), slot, windows(slot));
  }

  // The append counter starts at 0 (the slot's previous batch is finished).
  void prepare(uint32_t slot, uint32_t) override { std::memset(control_[slot]->data(), 0, control_[slot]->size()); }

  void record(VkCommandBuffer cb, uint32_t slot, const Piece& piece) override {
    const VkPhysicalDeviceLimits& limits = ctx_.limits();
    const uint32_t n = piece.rays;
    const uint32_t box_groups = (records_ + 63) / 64;
    for (uint32_t base = 0; base < n; base += chunk_) {
      const uint32_t end = std::min(n, base + chunk_);
      const Push boxes{base, end, records_}, args{0, 0, limits.maxComputeWorkGroupCount[0]}, test{0, n, records_};
      boxes_.dispatch(cb, slot, &boxes, box_groups, end - base, 1, piece.offsets);
      ctx_.compute_barrier(cb);
      args_.dispatch(cb, slot, &args, 1, 1, 1, piece.offsets);
      ctx_.indirect_barrier(cb);
      test_.dispatch_indirect(cb, slot, &test, *control_[slot], 4, piece.offsets);
      ctx_.compute_barrier(cb);
    }
    dispatch_rays(resolve_, cb, slot, piece);
  }

 private:
  Pipeline boxes_, args_, test_, resolve_;
  std::vector<std::unique_ptr<Buffer>> pairs_, control_;
  uint32_t chunk_ = 1;  // rays a chunk: chunk * batches pairs fit a pair buffer
};

// The method over the table's `line` for the blob, with a pair buffer of
// `pairs` a slot: what both entries below make.
std::unique_ptr<Method> make_over(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                  const MethodReading& line, uint64_t pairs, uint32_t slots, uint32_t flags,
                                  uint32_t max_hits) {
  ctx.require_int64_atomics("aabblist");
  return std::make_unique<AABBListMethod>(ctx, blob, name, line, pairs, slots, flags, max_hits);
}

}  // namespace

std::unique_ptr<Method> make_aabblist(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                      uint64_t pairs, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  return make_over(ctx, blob, name, method_line("aabblist", blob), pairs, slots, flags, max_hits);
}

// The table's factory: make_method has found the line already.
std::unique_ptr<Method> make_aabblist_method(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                             const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  return make_over(ctx, blob, name, line, kAABBListPairs, slots, flags, max_hits);
}

}  // namespace meshcast::gpu
