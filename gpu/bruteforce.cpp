// Method 1 of seed 000 §7: BruteForce over Float3SOA128 records. Two
// dispatches a batch: every (record, ray) workgroup tests 128 triangles and
// folds its hits into the ray's 64-bit key with one atomic minimum
// (shaders/bruteforce_soa128.comp), then one thread a ray resolves its key
// into a hit (shaders/bruteforce_resolve.comp).
#include <algorithm>
#include <chrono>
#include <cstring>
#include <optional>

#include "cpu/mesh.h"
#include "cpu/trace.h"
#include "gpu/method.h"
#include "gpu/rays.h"
#include "layout/blob.h"
#include "shaders/bruteforce_resolve.h"
#include "shaders/bruteforce_soa128.h"

namespace meshcast::gpu {

namespace {

struct Push {
  uint32_t ray_base, ray_count, records;
};

class BruteForceMethod : public Method {
 public:
  BruteForceMethod(Context& ctx, std::span<const uint8_t> blob, const std::string& name)
      : ctx_(ctx),
        test_(ctx, bruteforce_soa128_spv, sizeof bruteforce_soa128_spv, 4, sizeof(Push)),
        resolve_(ctx, bruteforce_resolve_spv, sizeof bruteforce_resolve_spv, 4, sizeof(Push)) {
    BlobView view(blob, name);  // validates
    const layout::BlobHeader& h = layout::header_of(blob.data());
    if (h.tree_format != MC_TREE_BRUTEFORCE || h.triangle_format != MC_TRI_FLOAT3SOA128)
      throw InputError(name + ": the GPU bruteforce method reads BruteForce/Float3SOA128 blobs, not " +
                       std::string(layout::tree_format_name(h.tree_format)) + "/" +
                       std::string(layout::triangle_format_name(h.triangle_format)));
    records_ = h.node_count;
    blob_.emplace(ctx, blob.size(), "blob of " + name);
    std::memcpy(blob_->data(), blob.data(), blob.size());
    if (ctx.has_timestamps()) {
      VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
      q.queryType = VK_QUERY_TYPE_TIMESTAMP, q.queryCount = 2;
      check(vkCreateQueryPool(ctx.device(), &q, nullptr, &queries_), "vkCreateQueryPool");
    }
  }

  ~BruteForceMethod() override {
    if (queries_) vkDestroyQueryPool(ctx_.device(), queries_, nullptr);
  }

  uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, GpuTiming* timing) override {
    auto t0 = std::chrono::steady_clock::now();
    const uint32_t n = uint32_t(std::min(rays.size(), hits.size()));
    if (n == 0) return 0;
    reserve(n);
    uint64_t skipped = pack_rays(rays.first(n), static_cast<uint32_t*>(rays_->data()));
    std::memset(keys_->data(), 0xFF, uint64_t(n) * 8);
    const uint32_t max_y = ctx_.limits().maxComputeWorkGroupCount[1];
    ctx_.submit([&](VkCommandBuffer cb) {
      if (queries_) {
        vkCmdResetQueryPool(cb, queries_, 0, 2);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries_, 0);
      }
      for (uint32_t base = 0; base < n; base += max_y) {
        Push push{base, n, records_};
        test_.dispatch(cb, &push, records_, std::min(max_y, n - base), 1);
      }
      compute_barrier(cb);
      Push push{0, n, records_};
      resolve_.dispatch(cb, &push, (n + 63) / 64, 1, 1);
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

 private:
  // Ray, key and hit buffers sized for `n` rays, reallocated only to grow.
  void reserve(uint32_t n) {
    if (capacity_ >= n) return;
    capacity_ = std::max<uint32_t>(n, 1024);
    rays_.emplace(ctx_, uint64_t(capacity_) * kRayWords * 4, "ray buffer");
    keys_.emplace(ctx_, uint64_t(capacity_) * 8, "key buffer");
    hits_.emplace(ctx_, uint64_t(capacity_) * sizeof(Hit), "hit buffer");
    test_.bind({&*blob_, &*rays_, &*keys_, &*hits_});
    resolve_.bind({&*blob_, &*rays_, &*keys_, &*hits_});
  }

  Context& ctx_;
  Pipeline test_, resolve_;
  std::optional<Buffer> blob_, rays_, keys_, hits_;
  uint32_t records_ = 0, capacity_ = 0;
  VkQueryPool queries_ = VK_NULL_HANDLE;
};

}  // namespace

std::unique_ptr<Method> make_method(Context& ctx, const std::string& method, std::span<const uint8_t> blob,
                                    const std::string& name) {
  if (method == "bruteforce") return std::make_unique<BruteForceMethod>(ctx, blob, name);
  throw InputError("unknown GPU method '" + method + "'; implemented: bruteforce");
}

}  // namespace meshcast::gpu
