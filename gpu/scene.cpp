#include "gpu/scene.h"

#include <algorithm>

#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "layout/names.h"
#include "scene/snapshot.h"
#include "gpu/vulkan.h"
#include "layout/blob_format.h"
#include "layout/formats.h"
#include "layout/ray_record.h"
#include "meshcast/errors.h"
#include "shaders/scene_octtree.h"

namespace meshcast::gpu {

namespace {

// The shader's layout of the top buffer (shaders/scene_octtree.comp):
// header words, the meshes' first words, then the records.
constexpr uint32_t kTopNodes = 18, kTopPlacedAt = 19, kTopWideAt = 20, kTopMeshBase = 24;
constexpr uint32_t kSceneHitWords = 6;
constexpr uint32_t kGroup = 64;
// The one layout the scene shader reads (its walk is the octtree method's).
// The layouts shaders/octtree_walk.glsl reads: the octtree over either cluster.
constexpr Layout kSceneLayouts[] = {{TreeFormat::OctTreeCompressed, TriangleFormat::ClusterBitPackSOA8},
                                    {TreeFormat::OctTreeCompressed, TriangleFormat::ClusterFloat3SOA8}};

struct ScenePush {
  uint32_t ray_base, ray_count, mask;
};

// UsageError unless the hits span holds one hit a ray.
void check_room(size_t rays, size_t hits) {
  if (hits < rays)
    throw UsageError("GPU scene method: " + std::to_string(rays) + " rays but room for " + std::to_string(hits) + " hits");
}

// A Mapped buffer of at least `bytes`, made again only to grow.
void fit(std::unique_ptr<Buffer>& b, Context& ctx, uint64_t bytes, const char* what) {
  if (!b || b->size() < bytes) b.reset(), b = std::make_unique<Buffer>(ctx, std::max<uint64_t>(bytes, 256), what);
}

}  // namespace

// What one batch in flight holds (gpu/scene.h).
struct SceneMethod::Flight {
  Context& ctx;
  VkFence fence = VK_NULL_HANDLE;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  bool in_flight = false;
  explicit Flight(Context& c) : ctx(c) {
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(ctx.vk().CreateFence(ctx.device(), &fci, nullptr, &fence), "vkCreateFence");
    try {
      cb = ctx.allocate_command_buffer();
    } catch (...) {  // on an engine's device nothing may leak
      ctx.vk().DestroyFence(ctx.device(), fence, nullptr);
      throw;
    }
  }
  ~Flight() {
    wait_quietly();
    ctx.free_command_buffer(cb);
    ctx.vk().DestroyFence(ctx.device(), fence, nullptr);
  }
  Flight(const Flight&) = delete;
  Flight& operator=(const Flight&) = delete;
  // GpuError when the device is lost; in_flight stays until the wait succeeds.
  void wait() {
    if (!in_flight) return;
    check(ctx.vk().WaitForFences(ctx.device(), 1, &fence, VK_TRUE, kWaitNs), "waiting for the GPU");
    in_flight = false;
  }
  // The destructor's: a lost device's batch is given up, not thrown.
  void wait_quietly() {
    if (in_flight) ctx.vk().WaitForFences(ctx.device(), 1, &fence, VK_TRUE, kWaitNs);
    in_flight = false;
  }
  static constexpr uint64_t kWaitNs = 600ull * 1000 * 1000 * 1000;
};

SceneMethod::SceneMethod(Context& ctx, uint32_t flags) : ctx_(ctx), flags_(flags) {
  const uint32_t known = MC_HIT_UV | MC_QUERY_ANY | MC_CULL_BACK | MC_CULL_FRONT;
  if ((flags & ~known) || ((flags & MC_CULL_BACK) && (flags & MC_CULL_FRONT)))
    throw UsageError("GPU scene method: flags " + std::to_string(flags) +
                     " are not MC_HIT_UV, MC_QUERY_ANY and one MC_CULL_* (every hit and the point are the CPU's)");
  pipeline_ = std::make_unique<Pipeline>(ctx, scene_octtree_spv, sizeof scene_octtree_spv, 7, sizeof(ScenePush), 1,
                                         flags, 1);
  unused_ = std::make_unique<Buffer>(ctx, 16, "unused binding");
  flight_ = std::make_unique<Flight>(ctx);
}

SceneMethod::~SceneMethod() = default;

std::string SceneMethod::refusal(const SceneSnapshot& s) {
  uint64_t bytes = 0;
  for (const auto& m : s.meshes) {
    const layout::BlobHeader& h = layout::header_of(m->bytes.data());
    const Layout l{TreeFormat(h.tree_format), TriangleFormat(h.triangle_format)};
    if (std::find(std::begin(kSceneLayouts), std::end(kSceneLayouts), l) == std::end(kSceneLayouts))
      return m->name + ": the GPU scene method reads " + layout_name(kSceneLayouts[0]) + " and " +
             layout_name(kSceneLayouts[1]) + " blobs, not " + layout_name(h.tree_format, h.triangle_format);
    bytes += (m->bytes.size() + 3) / 4 * 4;  // each blob starts on a word
    if (bytes / 4 >= (uint64_t(1) << 32))
      return m->name + ": the scene's blobs pass 2^32 words, more than the GPU scene method addresses";
  }
  return "";
}

void SceneMethod::upload_blobs(const SceneSnapshot& s) {
  if (blobs_ && s.meshes == uploaded_) return;
  if (const std::string why = refusal(s); !why.empty()) throw InputError(why);
  std::vector<uint32_t> base;
  uint64_t bytes = 0;
  for (const auto& m : s.meshes) {
    base.push_back(uint32_t(bytes / 4));
    bytes += (m->bytes.size() + 3) / 4 * 4;  // the next blob on a word
  }
  auto blobs = std::make_unique<Buffer>(ctx_, std::max<uint64_t>(bytes, 16), "scene blobs", 0, Memory::DeviceLocal);
  // Each blob read where it lies (the scene's copy, a mapped file, the
  // caller's bytes) straight into the staging copy: no host copy of them all.
  blobs->upload(bytes, [&](uint8_t* staging) {
    for (size_t k = 0; k < s.meshes.size(); ++k) {
      const std::span<const uint8_t> b = s.meshes[k]->bytes;
      uint8_t* at = staging + uint64_t(base[k]) * 4;
      std::memcpy(at, b.data(), b.size());
      std::memset(at + b.size(), 0, (b.size() + 3) / 4 * 4 - b.size());
    }
  });
  blobs_ = std::move(blobs);
  uploaded_ = s.meshes;
  mesh_base_ = std::move(base);
}

uint64_t SceneMethod::trace(const SceneSnapshot& s, std::span<const RayD> rays, std::span<SceneHit> hits, uint8_t mask) {
  check_room(rays.size(), hits.size());
  begin(s, rays, mask);
  return finish(hits);
}

void SceneMethod::begin(const SceneSnapshot& s, std::span<const RayD> rays, uint8_t mask) {
  if (flight_->in_flight) throw std::logic_error("GPU scene method: a batch is still in flight");
  n_ = 0;
  if (rays.empty()) return;
  if (rays.size() >= (uint64_t(1) << 32) / kSceneHitWords)
    throw UsageError("GPU scene method: " + std::to_string(rays.size()) + " rays in one batch, more than it addresses");
  upload_blobs(s);
  // The top buffer: the header, the meshes' first words, the placed
  // records and the wide nodes as the snapshot holds them.
  const layout::TopLevel& t = s.top;
  const uint64_t placed_at = kTopMeshBase + mesh_base_.size();
  const uint64_t wide_at = placed_at + t.placed.size() * (MC_PLACED_BYTES / 4);
  const uint64_t words = wide_at + t.wide.size() * (MC_TOP_NODE_BYTES / 4);
  if (words >= (uint64_t(1) << 32)) throw UsageError("GPU scene method: the top level passes 2^32 words");
  fit(top_, ctx_, words * 4, "scene top level");
  auto* top = static_cast<uint32_t*>(top_->data());
  std::memset(top, 0, kTopMeshBase * 4);
  for (int a = 0; a < 3; ++a) {
    std::memcpy(top + 2 * a, &t.anchor[a], 8);
    std::memcpy(top + 6 + 2 * a, &t.min[a], 8);
    std::memcpy(top + 12 + 2 * a, &t.max[a], 8);
  }
  top[kTopNodes] = uint32_t(t.wide.size());
  top[kTopPlacedAt] = uint32_t(placed_at), top[kTopWideAt] = uint32_t(wide_at);
  std::memcpy(top + kTopMeshBase, mesh_base_.data(), mesh_base_.size() * 4);
  std::memcpy(top + placed_at, t.placed.data(), t.placed.size() * sizeof(layout::PlacedInstance));
  std::memcpy(top + wide_at, t.wide.data(), t.wide.size() * sizeof(layout::TopWideNode));
  // The rays as RayD records (layout/ray_record.h), the answers 6 words a ray.
  static_assert(sizeof(RayD) == MC_RAYD_WORDS * 4 && offsetof(RayD, org) == MC_RAYD_ORG * 4 &&
                    offsetof(RayD, dir) == MC_RAYD_DIR * 4 && offsetof(RayD, tmax) == MC_RAYD_TMAX * 4 &&
                    offsetof(RayD, tmin) == MC_RAYD_TMIN * 4,
                "RayD is the scene shader's record");
  const uint32_t n = uint32_t(rays.size());
  fit(rays_, ctx_, uint64_t(n) * sizeof(RayD), "scene ray buffer");
  fit(hits_, ctx_, uint64_t(n) * kSceneHitWords * 4, "scene hit buffer");
  std::memcpy(rays_->data(), rays.data(), rays.size_bytes());
  pipeline_->bind({blobs_.get(), rays_.get(), unused_.get(), unused_.get(), unused_.get(), top_.get(), hits_.get()});
  const uint32_t most = ctx_.limits().maxComputeWorkGroupCount[0];
  VkCommandBuffer cb = flight_->cb;
  check(ctx_.vk().ResetCommandBuffer(cb, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(ctx_.vk().BeginCommandBuffer(cb, &bi), "vkBeginCommandBuffer");
  for (uint32_t first = 0; first < n;) {
    const uint32_t groups = std::min<uint32_t>((n - first + kGroup - 1) / kGroup, most);
    const ScenePush push{first, n, mask};
    pipeline_->dispatch(cb, 0, &push, groups, 1, 1);
    first += std::min<uint32_t>(groups * kGroup, n - first);
  }
  ctx_.host_barrier(cb);  // the answers, read by the host after the fence
  check(ctx_.vk().EndCommandBuffer(cb), "vkEndCommandBuffer");
  ctx_.submit_async(cb, flight_->fence);
  flight_->in_flight = true;
  n_ = n;
}

uint64_t SceneMethod::finish(std::span<SceneHit> hits) {
  check_room(n_, hits.size());
  flight_->wait();
  const uint32_t n = n_;
  const auto* out = static_cast<const uint32_t*>(hits_ ? hits_->data() : nullptr);
  uint64_t skipped = 0;
  for (uint32_t i = 0; i < n; ++i, out += kSceneHitWords) {
    SceneHit& h = hits[i];
    std::memcpy(&h.t, out, 4);
    h.instance = out[1], h.triangle = out[2];
    std::memcpy(&h.u, out + 3, 4), std::memcpy(&h.v, out + 4, 4);
    skipped += out[5];
  }
  return skipped;
}

}  // namespace meshcast::gpu
