#include "gpu/batch.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "cpu/mesh.h"
#include "cpu/trace.h"
#include "gpu/rays.h"
#include "layout/blob.h"

namespace meshcast::gpu {

uint32_t blob_triangle_format(std::span<const uint8_t> blob) {
  return blob.size() >= sizeof(layout::BlobHeader) ? layout::header_of(blob.data()).triangle_format : 0;
}

BatchMethod::BatchMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name, const std::string& method,
                         uint32_t tree, uint32_t triangles)
    : ctx_(ctx) {
  BlobView view(blob, name);  // validates: the shaders trust what validation proved
  const layout::BlobHeader& h = layout::header_of(blob.data());
  if (h.tree_format != tree || h.triangle_format != triangles)
    throw InputError(name + ": the GPU method " + method + " reads " + std::string(layout::tree_format_name(tree)) + "/" +
                     std::string(layout::triangle_format_name(triangles)) + " blobs, not " +
                     std::string(layout::tree_format_name(h.tree_format)) + "/" +
                     std::string(layout::triangle_format_name(h.triangle_format)));
  records_ = h.node_count;
  blob_.emplace(ctx, blob.size(), "blob of " + name, 0, Memory::DeviceLocal);
  blob_->upload(blob);
  if (ctx.has_timestamps()) {
    VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    q.queryType = VK_QUERY_TYPE_TIMESTAMP, q.queryCount = 2;
    check(vkCreateQueryPool(ctx.device(), &q, nullptr, &queries_), "vkCreateQueryPool");
  }
}

BatchMethod::~BatchMethod() {
  if (queries_) vkDestroyQueryPool(ctx_.device(), queries_, nullptr);
}

void BatchMethod::reserve(uint32_t n) {
  if (capacity_ >= n) return;
  capacity_ = std::max<uint32_t>(n, 1024);
  rays_.emplace(ctx_, uint64_t(capacity_) * kRayWords * 4, "ray buffer");
  keys_.emplace(ctx_, uint64_t(capacity_) * 8, "key buffer");
  hits_.emplace(ctx_, uint64_t(capacity_) * sizeof(Hit), "hit buffer");
  bind_all();
}

uint64_t BatchMethod::trace(std::span<const Ray> rays, std::span<Hit> hits, GpuTiming* timing) {
  auto t0 = std::chrono::steady_clock::now();
  const uint32_t n = uint32_t(std::min(rays.size(), hits.size()));
  if (n == 0) return 0;
  reserve(n);
  uint64_t skipped = pack_rays(rays.first(n), static_cast<uint32_t*>(rays_->data()));
  std::memset(keys_->data(), 0xFF, uint64_t(n) * 8);
  ctx_.submit([&](VkCommandBuffer cb) {
    if (queries_) {
      vkCmdResetQueryPool(cb, queries_, 0, 2);
      vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
    }
    record(cb, n);
    if (queries_) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries_, 1);
  });
  std::memcpy(hits.data(), hits_->data(), uint64_t(n) * sizeof(Hit));
  if (timing) {
    timing->wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    timing->device_ms = 0;
    uint64_t stamps[2];
    if (queries_ && vkGetQueryPoolResults(ctx_.device(), queries_, 0, 2, sizeof stamps, stamps, 8,
                                          VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT) == VK_SUCCESS)
      timing->device_ms = double(stamps[1] - stamps[0]) * ctx_.timestamp_period_ns() * 1e-6;
  }
  return skipped;
}

}  // namespace meshcast::gpu
