// Method 1 of seed 000 §7: BruteForce over Float3SOA128 or BitPackSOA128
// records. Two dispatches a batch: every (record, ray) workgroup tests 128
// triangles and folds its hits into the ray's 64-bit key with one atomic
// minimum (shaders/bruteforce_test.glsl), then one thread a ray resolves its
// key into a hit (shaders/bruteforce_resolve.glsl); the two codecs differ
// only in how a lane's corners load (shaders/soa128_*.glsl).
#include <algorithm>

#include "gpu/batch.h"

namespace meshcast::gpu {

namespace {

class BruteForceMethod : public BatchMethod {
 public:
  BruteForceMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const MethodReading& line,
                   uint32_t slots, uint32_t flags, uint32_t max_hits)
      : BatchMethod(ctx, blob, name, line, slots, flags, max_hits),
        test_(ctx, line.test.words, line.test.bytes, 4, sizeof(Push), slots, flags, max_hits, kPerRayWindows & 0b1111),
        resolve_(ctx, line.resolve.words, line.resolve.bytes, kBatchBindings, sizeof(Push), slots, flags, max_hits,
                 kPerRayWindows) {}

 protected:
  void bind_all(uint32_t slot) override {
    const std::vector<const Buffer*> all = buffers(slot);
    test_.bind({all.begin(), all.begin() + 4}, slot, windows(slot));  // no rows: the resolve pass writes them
    resolve_.bind(all, slot, windows(slot));
  }
  void record(VkCommandBuffer cb, uint32_t slot, const Piece& piece) override {
    const uint32_t max_y = ctx_.limits().maxComputeWorkGroupCount[1], n = piece.rays;
    for (uint32_t base = 0; base < n; base += max_y) {
      Push push{base, n, records_};
      test_.dispatch(cb, slot, &push, records_, std::min(max_y, n - base), 1, piece.offsets);
    }
    ctx_.compute_barrier(cb);
    dispatch_rays(resolve_, cb, slot, piece);
  }

 private:
  Pipeline test_, resolve_;
};

}  // namespace

std::unique_ptr<Method> make_bruteforce(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                        const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  ctx.require_int64_atomics("bruteforce");
  return std::make_unique<BruteForceMethod>(ctx, blob, name, line, slots, flags, max_hits);
}

}  // namespace meshcast::gpu
