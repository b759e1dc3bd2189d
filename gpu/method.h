// The GPU methods of seed 000 §7, each reading a blob exactly as uploaded.
// A method is made once per mesh (pipelines, descriptor sets and the blob's
// buffer), then traces any number of ray batches.
#pragma once
#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "meshcast/build.h"
#include "meshcast/errors.h"
#include "meshcast/ray.h"

namespace meshcast::gpu {

// The Vulkan context (gpu/vulkan.h): a Method's user needs no Vulkan header,
// so the host layer builds the same with the Vulkan backend off.
class Context;

struct GpuTiming {
  double device_ms = 0;  // between the batch's first and last GPU timestamps (0 without timestamps)
  double wall_ms = 0;    // from rays() (or begin()) to the hits read
};

// A method runs batches in frame slots, each batch in three steps:
// rays() hands out room for the batch in the slot's mapped ray buffer,
// where the caller writes meshcast::Ray records as they are (the device
// prepares each ray itself: no packing), submit() sends it without
// waiting, and hits() (or finish(), finish_lists()) waits and reads the
// answers where the device wrote them. begin() is rays() filled with a
// copy, then submit(). A batch of any size the device's memory holds
// runs, cut into pieces that fit its buffer and dispatch limits, in one
// submission; a slot's buffers grow to the largest batch it has run and
// its command buffer is recorded again only when the batch size changes,
// so after the first batch of a size nothing is allocated. Slots run
// independently, so a game can keep several frames in flight. A Method is
// not thread-safe: one caller at a time (host/ serializes its threads).
class Method {
 public:
  virtual ~Method() = default;
  virtual uint32_t slots() const = 0;
  // Why a batch of `rays` cannot run on this device, naming the bytes its
  // buffers would need and the device's limit they exceed (Query::All's
  // device rows are max_hits records a ray whatever the hits: 100,000 rays
  // of 4096 take 3.3 GB); "" when it fits. rays() refuses such a batch
  // with GpuError before it allocates anything; a caller may ask first.
  virtual std::string refusal(uint64_t rays) const = 0;
  // Room for `n` rays in the slot's mapped ray buffer, written by the
  // caller and read by the device as they are after submit(). The slot
  // must be idle (never begun, or finished).
  virtual std::span<Ray> rays(uint32_t slot, uint64_t n) = 0;
  // Sends the slot's rays to the device without waiting.
  virtual void submit(uint32_t slot) = 0;
  void begin(uint32_t slot, std::span<const Ray> batch) {
    std::span<Ray> to = rays(slot, batch.size());
    std::copy(batch.begin(), batch.end(), to.begin());
    submit(slot);
  }
  virtual bool ready(uint32_t slot) = 0;
  // Blocks until the slot's batch is done. Safe to call from another thread
  // while the owner begins or finishes other slots (it only waits on the
  // slot's fence); GpuError when the device is lost.
  virtual void wait(uint32_t slot) = 0;
  // Waits, then the slot's hits where the device wrote them (host-visible
  // memory: no copy), valid until the slot's next rays(). `unwalkable`:
  // the rays answered as misses because no walker walks them
  // (ray_is_walkable). UsageError for a Query::All method.
  virtual std::span<const Hit> hits(uint32_t slot, GpuTiming* timing = nullptr, uint64_t* unwalkable = nullptr) = 0;
  // hits() copied into `hits` (at least the batch's size); returns the
  // unwalkable rays.
  uint64_t finish(uint32_t slot, std::span<Hit> out, GpuTiming* timing = nullptr) {
    uint64_t unwalkable = 0;
    std::span<const Hit> h = hits(slot, timing, &unwalkable);
    std::copy(h.begin(), h.begin() + std::min(h.size(), out.size()), out.begin());
    return unwalkable;
  }
  // A Query::All method's rows of the slot's batch into `lists`, compact
  // (meshcast/ray.h: cleared, then each ray's kept hits alone; max_hits
  // the method's); returns the unwalkable rays. UsageError for a method
  // made for another query.
  virtual uint64_t finish_lists(uint32_t slot, HitLists& lists, GpuTiming* timing = nullptr) = 0;
  // Tests: cut batches into pieces of at most `rays` (rounded up to 256),
  // fewer than the device's limits would, to run many pieces on few rays.
  virtual void limit_piece(uint32_t rays) = 0;

  // One batch in slot 0, waited for; returns the unwalkable rays.
  uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, GpuTiming* timing = nullptr) {
    if (rays.empty() || hits.empty()) return 0;
    const size_t n = std::min(rays.size(), hits.size());
    begin(0, rays.first(n));
    return finish(0, hits.first(n), timing);
  }
  // One Query::All batch in slot 0, waited for.
  uint64_t trace_all_hits(std::span<const Ray> rays, HitLists& lists, GpuTiming* timing = nullptr) {
    begin(0, rays);
    return finish_lists(0, lists, timing);
  }
};

// The method named `method` over the blob (method_layouts() lists what each
// reads; gpu/method_table.cpp is the one table).
// Throws GpuError, or InputError (an unknown method, or a blob whose layout
// the method does not read, naming both).
// `flags`: the per-hit outputs (MC_HIT_UV, MC_HIT_POINT) its shaders
// compute (the others read 0), the query (MC_QUERY_ANY, MC_QUERY_ALL with
// rows of `max_hits`, 1..kMaxHitsLimit) and the culling (MC_CULL_BACK,
// MC_CULL_FRONT) of every batch: the shaders' specialization constants.
std::unique_ptr<Method> make_method(Context& ctx, const std::string& method, std::span<const uint8_t> blob,
                                    const std::string& name, uint32_t slots = 1, uint32_t flags = 0,
                                    uint32_t max_hits = 16);
std::vector<std::string> method_names();

// Every (method, layout) pair the GPU reads, in the order of seed 000 §7's
// table: the tests, the stiff and extreme suite, bench gpu and bench error
// run this one list, and the automatic layout choice keeps to its layouts
// when the GPU reads the blob too.
struct MethodLayout {
  const char* method;
  Layout layout;
};
std::span<const MethodLayout> method_layouts();
// The first method of that list that reads the blob's layout; "" for none.
std::string method_reading(std::span<const uint8_t> blob);
// What `method` reads, as a refusal or a --help names it: "AABBTree/Float3
// or AABBTree/UncompressedStrip".
std::string layouts_read_by(const std::string& method);

// AABBList (method 2) with a pair buffer of `pairs` (ray, batch) pairs a
// slot: a batch of rays goes in chunks of pairs / batches rays. make_method's
// uses kAABBListPairs; a test passes a small one to split batches into many
// chunks.
// 2^21 pairs (16 MiB a slot): far below every device's
// maxStorageBufferRange, and still thousands of rays a chunk on large meshes.
constexpr uint64_t kAABBListPairs = uint64_t(1) << 21;
std::unique_ptr<Method> make_aabblist(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                      uint64_t pairs, uint32_t slots = 1, uint32_t flags = 0, uint32_t max_hits = 16);

}  // namespace meshcast::gpu
