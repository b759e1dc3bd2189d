#include "gpu/batch.h"

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <limits>

#include "meshcast/mesh.h"
#include "meshcast/blob.h"
#include "layout/blob_format.h"
#include "layout/ray_record.h"
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
      s.counters = std::make_unique<Buffer>(ctx, 16, "batch counters", VK_BUFFER_USAGE_TRANSFER_DST_BIT);
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

static_assert(sizeof(Ray) == MC_RAY_WORDS * 4 && offsetof(Ray, org) == MC_RAY_ORG * 4 &&
                  offsetof(Ray, dir) == MC_RAY_DIR * 4 && offsetof(Ray, tmax) == MC_RAY_TMAX * 4 &&
                  offsetof(Ray, tmin) == MC_RAY_TMIN * 4,
              "meshcast::Ray is the shaders' ray record (layout/ray_record.h)");

BatchMethod::PerRay BatchMethod::per_ray() const {
  // A row: found, then max_hits (t, triangle) records (shaders/hit_rows.glsl).
  return {sizeof(Ray), reads_keys() ? uint64_t(keys_a_ray()) * 8 : 0, sizeof(Hit),
          all() ? uint64_t(1 + 2 * max_hits_) * 4 : 0};
}

uint32_t BatchMethod::piece_rays() const {
  const PerRay r = per_ray();
  const uint64_t widest = std::max({r.rays, r.keys, r.hits, r.rows});
  uint64_t most = ctx_.limits().maxStorageBufferRange / widest / 256 * 256;
  most = std::clamp<uint64_t>(most, 256, uint64_t(1) << 30);
  if (piece_limit_) most = std::min<uint64_t>(most, (uint64_t(piece_limit_) + 255) / 256 * 256);
  return uint32_t(most);
}

uint64_t BatchMethod::capacity_for(uint64_t n) const {
  // Within one piece: the batch, at least 1024 rays. Past it: whole
  // pieces, so the last piece's windows lie inside the buffers.
  const uint64_t piece = piece_rays();
  if (n <= piece) return std::max<uint64_t>(n, std::min<uint64_t>(1024, piece));
  return (n + piece - 1) / piece * piece;
}

std::vector<const Buffer*> BatchMethod::buffers(uint32_t slot) const {
  const Slot& s = slots_[slot];
  return {blob_.get(), s.rays.get(), s.keys.get(), s.hits.get(), s.rows.get(), s.counters.get()};
}

std::vector<uint64_t> BatchMethod::windows(uint32_t slot) const {
  const Slot& s = slots_[slot];
  const uint64_t rays = std::min<uint64_t>(s.capacity, piece_rays());
  const std::array<uint64_t, 4> each = per_ray().each();
  std::vector<uint64_t> bytes(kBatchBindings, 0);
  for (int k = 0; k < 4; ++k) bytes[1 + k] = each[k] ? rays * each[k] : 16;
  return bytes;
}

std::string BatchMethod::refusal(uint64_t rays) const {
  const std::string batch = "GPU method " + method_ + ": a batch of " + std::to_string(rays) + " rays" +
                            (all() ? " (rows of " + std::to_string(max_hits_) + " hits a ray)" : "");
  if (rays > std::numeric_limits<uint32_t>::max())
    return batch + " is more than a batch addresses (2^32 - 1 rays); submit it in parts";
  const PerRay r = per_ray();
  const uint64_t bytes = capacity_for(rays) * r.total();
  const uint64_t heap = ctx_.mapped_heap_bytes();
  if (bytes > heap)
    return batch + " needs " + std::to_string(bytes) + " bytes of host-visible memory, more than " +
           ctx_.device_name() + "'s largest host-visible heap (" + std::to_string(heap) + " bytes)";
  // A piece's window starts at a 32-bit dynamic offset (vkCmdBindDescriptorSets).
  const uint64_t widest = capacity_for(rays) * std::max({r.rays, r.keys, r.hits, r.rows});
  if (widest > (uint64_t(1) << 32))
    return batch + " needs a buffer of " + std::to_string(widest) +
           " bytes, past the 4 GiB a buffer's 32-bit offsets reach; submit it in parts";
  return "";
}

void BatchMethod::limit_piece(uint32_t rays) {
  for (Slot& s : slots_)
    if (s.in_flight) throw std::logic_error("limit_piece() with a batch in flight");
  piece_limit_ = rays;
  for (Slot& s : slots_) s.capacity = 0, s.recorded = 0;  // every slot's windows made again
}

void BatchMethod::reserve(uint32_t slot, uint64_t n) {
  Slot& s = slots_[slot];
  if (s.capacity >= n) return;
  // Refused before anything is made; then all four made before any is
  // replaced: a refusal (memory) leaves the slot as it was.
  if (const std::string why = refusal(n); !why.empty()) throw GpuError(why);
  const uint64_t capacity = capacity_for(n);
  const PerRay r = per_ray();
  auto make = [&](uint64_t per, const char* what, VkBufferUsageFlags usage) {
    return std::make_unique<Buffer>(ctx_, per ? capacity * per : 16, what, usage, Memory::Mapped, true);
  };
  auto rays = make(r.rays, "ray buffer", 0);
  auto keys = make(r.keys, "key buffer", VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  auto hits = make(r.hits, "hit buffer", 0);
  auto rows = make(r.rows, "hit row buffer", 0);
  s.rays = std::move(rays), s.keys = std::move(keys), s.hits = std::move(hits), s.rows = std::move(rows);
  s.capacity = capacity;
  s.recorded = 0;  // the command buffer names the old buffers
  bind_all(slot);
}

static double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::span<Ray> BatchMethod::rays(uint32_t slot, uint64_t n) {
  Slot& s = slots_.at(slot);
  if (s.in_flight) throw std::logic_error("GPU slot " + std::to_string(slot) + " is still in flight");
  s.begin_ms = now_ms();
  s.submitted = false;
  s.n = 0;
  if (n == 0) return {};
  reserve(slot, n);
  s.n = uint32_t(n);
  return {static_cast<Ray*>(s.rays->data()), n};
}

void BatchMethod::record_batch(Slot& s, uint32_t slot) {
  check(ctx_.vk().ResetCommandBuffer(s.cb, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  check(ctx_.vk().BeginCommandBuffer(s.cb, &bi), "vkBeginCommandBuffer");
  if (s.queries) {
    ctx_.vk().CmdResetQueryPool(s.cb, s.queries, 0, 2);
    ctx_.vk().CmdWriteTimestamp(s.cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, s.queries, 0);
  }
  // The counters and the keys start on the device: the host touches no
  // buffer of the batch but the rays it writes and the hits it reads.
  ctx_.vk().CmdFillBuffer(s.cb, s.counters->handle(), 0, VK_WHOLE_SIZE, 0);
  const PerRay r = per_ray();
  if (r.keys) ctx_.vk().CmdFillBuffer(s.cb, s.keys->handle(), 0, uint64_t(s.n) * r.keys, 0xFFFFFFFFu);
  ctx_.fill_barrier(s.cb);
  const uint32_t piece = piece_rays();
  const std::array<uint64_t, 4> each = r.each();
  for (uint32_t first = 0, k = 0; first < s.n; first += piece, ++k) {
    if (k) ctx_.compute_barrier(s.cb);  // a piece's passes reuse the slot's scratch (AABBList's pairs)
    Piece p{std::min(piece, s.n - first), {}};
    for (int b = 0; b < 4; ++b) p.offsets[b] = uint32_t(uint64_t(first) * each[b]);
    record(s.cb, slot, p);
  }
  ctx_.host_barrier(s.cb);  // the hits, read by the host after the fence
  if (s.queries) ctx_.vk().CmdWriteTimestamp(s.cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries, 1);
  check(ctx_.vk().EndCommandBuffer(s.cb), "vkEndCommandBuffer");
  s.recorded = s.n;
}

void BatchMethod::submit(uint32_t slot) {
  Slot& s = slots_.at(slot);
  if (s.in_flight) throw std::logic_error("GPU slot " + std::to_string(slot) + " is still in flight");
  s.submitted = true;
  if (s.n == 0) return;
  prepare(slot, s.n);
  if (s.recorded != s.n) record_batch(s, slot);  // recorded once a batch size, resubmitted after
  ctx_.submit_async(s.cb, s.fence);
  s.in_flight = true;
}

void BatchMethod::dispatch_rays(const Pipeline& p, VkCommandBuffer cb, uint32_t slot, const Piece& piece) const {
  const uint64_t most = uint64_t(ctx_.limits().maxComputeWorkGroupCount[0]) * 64;
  for (uint64_t base = 0; base < piece.rays; base += most) {
    const Push push{uint32_t(base), piece.rays, records_};
    const uint64_t rays = std::min<uint64_t>(most, piece.rays - base);
    p.dispatch(cb, slot, &push, uint32_t((rays + 63) / 64), 1, 1, piece.offsets);
  }
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

std::span<const Hit> BatchMethod::hits(uint32_t slot, GpuTiming* timing, uint64_t* unwalkable) {
  if (all()) throw UsageError("GPU method made for Query::All: finish_lists() reads its rows");
  Slot& s = slots_.at(slot);
  finish_batch(s, timing);
  if (unwalkable) *unwalkable = s.n ? static_cast<const uint32_t*>(s.counters->data())[0] : 0;
  if (!s.n) return {};
  return {static_cast<const Hit*>(s.hits->data()), s.n};
}

uint64_t BatchMethod::finish_lists(uint32_t slot, HitLists& lists, GpuTiming* timing) {
  if (!all()) throw UsageError("GPU method made for one hit a ray: finish() reads its hits");
  Slot& s = slots_.at(slot);
  finish_batch(s, timing);
  // The device's rows stay fixed (found, then max_hits (t, triangle)
  // records, per_ray()); each ray's kept records alone are read back.
  lists.max_hits = max_hits_;
  lists.clear();
  lists.found.reserve(s.n);
  lists.offsets.reserve(size_t(s.n) + 1);
  if (!s.n) return 0;
  const uint32_t* row = static_cast<const uint32_t*>(s.rows->data());
  const Ray* ray = static_cast<const Ray*>(s.rays->data());  // as the caller wrote them
  for (uint32_t i = 0; i < s.n; ++i, row += 1 + 2 * max_hits_) {
    const uint32_t kept = std::min(row[0], max_hits_);
    for (uint32_t k = 0; k < kept; ++k) {
      Hit h;
      std::memcpy(&h.t, &row[1 + 2 * k], 4);
      h.triangle = row[2 + 2 * k];
      if (flags_ & MC_HIT_POINT)
        for (int a = 0; a < 3; ++a) h.point[a] = ray[i].org[a] + h.t * walked_direction(ray[i].dir[a]);
      lists.hits.push_back(h);
    }
    lists.end_row(row[0]);
  }
  return static_cast<const uint32_t*>(s.counters->data())[0];
}

void BatchMethod::finish_batch(Slot& s, GpuTiming* timing) {
  if (!s.submitted) throw std::logic_error("a GPU slot read before its rays were submitted");
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
