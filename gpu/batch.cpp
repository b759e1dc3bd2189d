#include "gpu/batch.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "meshcast/mesh.h"
#include "meshcast/blob.h"
#include "gpu/rays.h"
#include "layout/blob_format.h"
#include "layout/names.h"

namespace meshcast::gpu {

BatchMethod::BatchMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                         const MethodReading& line, uint32_t slots, uint32_t flags, uint32_t max_hits)
    : ctx_(ctx), method_(line.what.method), flags_(flags), max_hits_(max_hits), slots_(std::max(slots, 1u)) {
  const std::string& method = method_;
  const uint32_t known = MC_HIT_UV | MC_HIT_POINT | MC_QUERY_ANY | MC_QUERY_ALL | MC_CULL_BACK | MC_CULL_FRONT;
  if ((flags & ~known) || ((flags & MC_QUERY_ANY) && (flags & MC_QUERY_ALL)) ||
      ((flags & MC_CULL_BACK) && (flags & MC_CULL_FRONT)))
    throw UsageError("GPU method " + method + ": flags " + std::to_string(flags) +
                     " are not MC_HIT_* with at most one MC_QUERY_* and one MC_CULL_*");
  if ((flags & MC_QUERY_ALL) && (flags & MC_HIT_UV))
    throw UsageError("GPU method " + method + ": every hit's rows carry t and the triangle (and the point, " +
                     "filled on the host), not u and v: ask the CPU for those");
  if (max_hits < 1 || max_hits > kMaxHitsLimit)
    throw UsageError("GPU method " + method + ": max_hits " + std::to_string(max_hits) + " is not in 1.." +
                     std::to_string(kMaxHitsLimit));
  BlobView view(blob, name);  // validates: the shaders trust what validation proved
  const layout::BlobHeader& h = layout::header_of(blob.data());
  if (h.tree_format != uint32_t(line.what.layout.tree) || h.triangle_format != uint32_t(line.what.layout.triangles))
    throw InputError(name + ": the GPU method " + method + " reads " + layouts_read_by(method) + " blobs, not " +
                     layout_name(h.tree_format, h.triangle_format));
  records_ = h.node_count;
  blob_ = ctx.blob_buffer(blob, name);
  try {
    for (Slot& s : slots_) {
      VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
      check(ctx_.vk().CreateFence(ctx.device(), &fci, nullptr, &s.fence), "vkCreateFence");
      s.cb = ctx.allocate_command_buffer();
      if (ctx.has_timestamps()) {
        VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
        q.queryType = VK_QUERY_TYPE_TIMESTAMP, q.queryCount = 2;
        check(ctx_.vk().CreateQueryPool(ctx.device(), &q, nullptr, &s.queries), "vkCreateQueryPool");
      }
    }
  } catch (...) {  // the slots made so far go with it (on an engine's device nothing may leak)
    release_slots();
    throw;
  }
}

BatchMethod::~BatchMethod() { release_slots(); }

void BatchMethod::release_slots() {
  for (Slot& s : slots_) {
    if (s.in_flight) ctx_.vk().WaitForFences(ctx_.device(), 1, &s.fence, VK_TRUE, 600ull * 1000 * 1000 * 1000);
    if (s.queries) ctx_.vk().DestroyQueryPool(ctx_.device(), s.queries, nullptr);
    if (s.cb) ctx_.free_command_buffer(s.cb);
    if (s.fence) ctx_.vk().DestroyFence(ctx_.device(), s.fence, nullptr);
  }
}

std::vector<const Buffer*> BatchMethod::buffers(uint32_t slot) const {
  const Slot& s = slots_[slot];
  return {blob_.get(), s.rays.get(), s.keys.get(), s.hits.get(), s.rows.get()};
}

BatchMethod::SlotBytes BatchMethod::slot_bytes(uint32_t capacity) const {
  // A row: found, then max_hits (t, triangle) records (shaders/hit_rows.glsl).
  return {uint64_t(capacity) * kRayWords * 4, uint64_t(capacity) * keys_a_ray() * 8, uint64_t(capacity) * sizeof(Hit),
          all() ? uint64_t(capacity) * (1 + 2 * max_hits_) * 4 : 16};
}

std::string BatchMethod::refusal(uint32_t rays) const {
  const SlotBytes b = slot_bytes(capacity_for(rays));
  const std::string batch = "GPU method " + method_ + ": a batch of " + std::to_string(rays) + " rays" +
                            (all() ? " (rows of " + std::to_string(max_hits_) + " hits a ray)" : "") + " needs ";
  const uint64_t range = ctx_.limits().maxStorageBufferRange;
  for (auto [bytes, what] : {std::pair{b.rays, "ray buffer"}, std::pair{b.keys, "key buffer"},
                             std::pair{b.hits, "hit buffer"}, std::pair{b.rows, "hit row buffer"}})
    if (bytes > range)
      return batch + "a " + what + " of " + std::to_string(bytes) + " bytes, more than " + ctx_.device_name() +
             "'s maxStorageBufferRange (" + std::to_string(range) + " bytes)";
  const uint64_t heap = ctx_.mapped_heap_bytes();
  if (b.total() > heap)
    return batch + std::to_string(b.total()) + " bytes of host-visible memory, more than " + ctx_.device_name() +
           "'s largest host-visible heap (" + std::to_string(heap) + " bytes)";
  return "";
}

void BatchMethod::reserve(uint32_t slot, uint32_t n) {
  Slot& s = slots_[slot];
  if (s.capacity >= n) return;
  // Refused before anything is made; then all four made before any is
  // replaced: a refusal (memory) leaves the slot as it was.
  if (const std::string why = refusal(n); !why.empty()) throw GpuError(why);
  const uint32_t capacity = capacity_for(n);
  const SlotBytes bytes = slot_bytes(capacity);
  auto rays = std::make_unique<Buffer>(ctx_, bytes.rays, "ray buffer");
  auto keys = std::make_unique<Buffer>(ctx_, bytes.keys, "key buffer");
  auto hits = std::make_unique<Buffer>(ctx_, bytes.hits, "hit buffer");
  auto rows = std::make_unique<Buffer>(ctx_, bytes.rows, "hit row buffer");
  s.rays = std::move(rays), s.keys = std::move(keys), s.hits = std::move(hits), s.rows = std::move(rows);
  s.capacity = capacity;
  s.recorded = 0;  // the command buffer names the old buffers
  bind_all(slot);
}

static double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

uint64_t BatchMethod::begin(uint32_t slot, std::span<const Ray> rays) {
  Slot& s = slots_.at(slot);
  if (s.in_flight) throw std::logic_error("GPU slot " + std::to_string(slot) + " is still in flight");
  s.begin_ms = now_ms();
  s.n = uint32_t(rays.size());
  if (s.n == 0) return 0;
  reserve(slot, s.n);
  uint64_t skipped = pack_rays(rays, static_cast<uint32_t*>(s.rays->data()));
  std::memset(s.keys->data(), 0xFF, uint64_t(s.n) * keys_a_ray() * 8);
  prepare(slot, s.n);
  if (s.recorded != s.n) {  // recorded once a batch size, resubmitted after
    check(ctx_.vk().ResetCommandBuffer(s.cb, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    check(ctx_.vk().BeginCommandBuffer(s.cb, &bi), "vkBeginCommandBuffer");
    if (s.queries) {
      ctx_.vk().CmdResetQueryPool(s.cb, s.queries, 0, 2);
      ctx_.vk().CmdWriteTimestamp(s.cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s.queries, 0);
    }
    record(s.cb, slot, s.n);
    ctx_.host_barrier(s.cb);  // the hits, read by the host after the fence
    if (s.queries) ctx_.vk().CmdWriteTimestamp(s.cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries, 1);
    check(ctx_.vk().EndCommandBuffer(s.cb), "vkEndCommandBuffer");
    s.recorded = s.n;
  }
  ctx_.submit_async(s.cb, s.fence);
  s.in_flight = true;
  return skipped;
}

bool BatchMethod::ready(uint32_t slot) {
  Slot& s = slots_.at(slot);
  if (!s.in_flight) return true;
  VkResult r = ctx_.vk().GetFenceStatus(ctx_.device(), s.fence);
  if (r == VK_NOT_READY) return false;
  check(r, "waiting for the GPU");
  return true;
}

void BatchMethod::wait(uint32_t slot) {
  Slot& s = slots_.at(slot);
  if (s.in_flight)
    check(ctx_.vk().WaitForFences(ctx_.device(), 1, &s.fence, VK_TRUE, 600ull * 1000 * 1000 * 1000), "waiting for the GPU");
}

void BatchMethod::finish(uint32_t slot, std::span<Hit> hits, GpuTiming* timing) {
  if (all()) throw UsageError("GPU method made for Query::All: finish_lists() reads its rows");
  Slot& s = slots_.at(slot);
  finish_batch(s, timing);
  if (s.n) std::memcpy(hits.data(), s.hits->data(), uint64_t(std::min<size_t>(s.n, hits.size())) * sizeof(Hit));
}

void BatchMethod::finish_lists(uint32_t slot, HitLists& lists, GpuTiming* timing) {
  if (!all()) throw UsageError("GPU method made for one hit a ray: finish() reads its hits");
  Slot& s = slots_.at(slot);
  finish_batch(s, timing);
  // The device's rows stay fixed (found, then max_hits (t, triangle)
  // records, slot_bytes()); each ray's kept records alone are read back.
  lists.max_hits = max_hits_;
  lists.clear();
  lists.found.reserve(s.n);
  lists.offsets.reserve(size_t(s.n) + 1);
  const uint32_t* row = static_cast<const uint32_t*>(s.rows->data());
  const float* ray = static_cast<const float*>(s.rays->data());  // packed: origin, direction first (gpu/rays.h)
  for (uint32_t i = 0; i < s.n; ++i, row += 1 + 2 * max_hits_, ray += kRayWords) {
    const uint32_t kept = std::min(row[0], max_hits_);
    for (uint32_t k = 0; k < kept; ++k) {
      Hit h;
      std::memcpy(&h.t, &row[1 + 2 * k], 4);
      h.triangle = row[2 + 2 * k];
      if (flags_ & MC_HIT_POINT)
        for (int a = 0; a < 3; ++a) h.point[a] = ray[a] + h.t * ray[3 + a];
      lists.hits.push_back(h);
    }
    lists.end_row(row[0]);
  }
}

void BatchMethod::finish_batch(Slot& s, GpuTiming* timing) {
  if (s.in_flight) {
    check(ctx_.vk().WaitForFences(ctx_.device(), 1, &s.fence, VK_TRUE, 600ull * 1000 * 1000 * 1000), "waiting for the GPU");
    s.in_flight = false;  // only once done: a failed wait leaves the destructor to wait again
  }
  if (timing) {
    timing->wall_ms = now_ms() - s.begin_ms;
    timing->device_ms = 0;
    uint64_t stamps[2];
    if (s.n && s.queries &&
        ctx_.vk().GetQueryPoolResults(ctx_.device(), s.queries, 0, 2, sizeof stamps, stamps, 8,
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) == VK_SUCCESS)
      timing->device_ms = double(stamps[1] - stamps[0]) * ctx_.timestamp_period_ns() * 1e-6;
  }
}

}  // namespace meshcast::gpu
