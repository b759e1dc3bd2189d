// The one-ray-a-thread methods of seed 000 §7: a tree walked per thread
// (a stack of its own, or none for the StacklessLBVH), one dispatch a batch.
// Each is a shader and the layout it reads (a line of gpu/method_table.cpp);
// the host side is the same.
#include "gpu/batch.h"

namespace meshcast::gpu {

namespace {

class WalkMethod : public BatchMethod {
 public:
  WalkMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const MethodReading& line,
             uint32_t slots, uint32_t flags, uint32_t max_hits)
      : BatchMethod(ctx, blob, name, line, slots, flags, max_hits),
        walk_(ctx, line.test.words, line.test.bytes, kBatchBindings, sizeof(Push), slots, flags, max_hits, kPerRayWindows) {}

 protected:
  void bind_all(uint32_t slot) override { walk_.bind(buffers(slot), slot, windows(slot)); }
  bool reads_keys() const override { return false; }
  void record(VkCommandBuffer cb, uint32_t slot, const Piece& piece) override { dispatch_rays(walk_, cb, slot, piece); }

 private:
  Pipeline walk_;
};

}  // namespace

std::unique_ptr<Method> make_walker(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                    const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits) {
  return std::make_unique<WalkMethod>(ctx, blob, name, line, slots, flags, max_hits);
}

}  // namespace meshcast::gpu
