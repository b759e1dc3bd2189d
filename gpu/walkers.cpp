// The one-ray-a-thread methods of seed 000 §7: a tree walked per thread
// (a stack of its own, or none for the StacklessLBVH). Each is a shader and
// the layout it reads (a line of gpu/method_table.cpp); the host side is
// the same but for how threads find their rays: one a thread over the
// whole piece, or persistent threads taking rays from the batch counter.
#include "gpu/batch.h"

namespace meshcast::gpu {

namespace {

// Persistent threads a dispatch: 2^19, more than any current GPU keeps
// resident (an H100's 132 multiprocessors hold 2,048 threads each, 270k
// in all), so every multiprocessor is busy until the rays run out; the
// workgroups beyond the resident ones find the counter past the end and
// leave at once.
constexpr uint32_t kPersistentThreads = uint32_t(1) << 19;

class WalkMethod : public BatchMethod {
 public:
  WalkMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const MethodReading& line,
             uint32_t slots, uint32_t flags, uint32_t max_hits, bool persistent)
      : BatchMethod(ctx, blob, name, line, slots, flags, max_hits),
        walk_(ctx, line.test.words, line.test.bytes, kBatchBindings, sizeof(Push), slots, flags, max_hits, kPerRayWindows),
        persistent_(persistent) {}

 protected:
  void bind_all(uint32_t slot) override { walk_.bind(buffers(slot), slot, windows(slot)); }
  bool reads_keys() const override { return false; }
  void record(VkCommandBuffer cb, uint32_t slot, const Piece& piece) override {
    if (!persistent_) return dispatch_rays(walk_, cb, slot, piece);
    const Push push{0, piece.rays, records_};
    const uint32_t threads = std::min(piece.rays, kPersistentThreads);
    walk_.dispatch(cb, slot, &push, (threads + 63) / 64, 1, 1, piece.offsets);
  }

 private:
  Pipeline walk_;
  const bool persistent_;
};

}  // namespace

std::unique_ptr<Method> make_walker(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                    const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  return std::make_unique<WalkMethod>(ctx, blob, name, line, slots, flags, max_hits, false);
}

std::unique_ptr<Method> make_persistent_walker(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                               const MethodReading& line, uint32_t slots, uint32_t flags,
                                               uint32_t max_hits) {
  return std::make_unique<WalkMethod>(ctx, blob, name, line, slots, flags, max_hits, true);
}

}  // namespace meshcast::gpu
