#include "bench/gpu_scale.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>

#include "bench/timing.h"
#include "builder/layout_names.h"
#include "check/ray_files.h"
#include "gpu/method.h"
#include "gpu/vulkan.h"
#include "meshcast/blob.h"
#include "meshcast/build.h"

namespace meshcast::bench {

namespace {

// The calling thread's CPU time: what the submitting thread spends, its
// sleeps in a wait not counted.
double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

// The CPU's every core: a contiguous share of the rays a thread.
double cpu_all_cores_ms(const BlobView& view, std::span<const Ray> rays, std::span<Hit> hits, uint32_t threads) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  const size_t share = (rays.size() + threads - 1) / threads;
  for (uint32_t k = 0; k < threads; ++k) {
    const size_t begin = std::min(rays.size(), k * share), end = std::min(rays.size(), begin + share);
    pool.emplace_back([&, begin, end] { view.trace(rays.subspan(begin, end - begin), hits.subspan(begin, end - begin)); });
  }
  for (std::thread& t : pool) t.join();
  return ms_since(t0);
}

}  // namespace

GpuScaleResult bench_gpu_scale(const Mesh& mesh, const std::string& name, const std::vector<uint64_t>& sizes,
                               uint32_t repeat, const std::string& device) {
  GpuScaleResult res;
  gpu::Context ctx(gpu::DeviceChoice{device, false});
  res.device = ctx.device_name();
  res.method = "octtree";  // the recommended layout's method
  Layout layout{};
  for (const gpu::MethodLayout& m : gpu::method_layouts())
    if (res.method == m.method) layout = m.layout;
  res.layout = layout_name(layout);
  const std::vector<uint8_t> blob = build_blob(mesh, parse_layout(res.layout), name);
  const BlobView view(blob, name);
  res.frames = 3;
  std::unique_ptr<gpu::Method> method = gpu::make_method(ctx, res.method, blob, name, res.frames);
  res.cpu_threads = std::max(1u, std::thread::hardware_concurrency());
  const uint64_t most = *std::max_element(sizes.begin(), sizes.end());
  const std::vector<Ray> rays = make_rays(mesh, RayKind::Long, most, 1);
  std::vector<Hit> cpu_hits(most);
  for (uint64_t n : sizes) {
    GpuScaleRow row;
    row.rays = n;
    const std::span<const Ray> batch = std::span<const Ray>(rays).first(n);
    std::vector<double> device_ms, wall_ms, host_ms, copy_ms, cpu_ms;
    // One batch at a time in slot 0; the first pass of a size grows the
    // slot's buffers and records its command buffer, and is not counted.
    for (uint32_t pass = 0; pass <= repeat; ++pass) {
      const double c0 = thread_cpu_ms();
      std::span<Ray> to = method->rays(0, n);
      const double c1 = thread_cpu_ms();
      std::memcpy(to.data(), batch.data(), batch.size_bytes());
      const double c2 = thread_cpu_ms();
      const auto w0 = std::chrono::steady_clock::now();
      method->submit(0);
      const double c3 = thread_cpu_ms();
      method->wait(0);
      const double c4 = thread_cpu_ms();
      gpu::GpuTiming timing;
      const std::span<const Hit> hits = method->hits(0, &timing);
      const double wall = ms_since(w0), c5 = thread_cpu_ms();
      if (pass == 0) {  // judged against the CPU once a size
        cpu_ms.push_back(cpu_all_cores_ms(view, batch, std::span<Hit>(cpu_hits).first(n), res.cpu_threads));
        for (uint64_t i = 0; i < n; ++i)
          row.differ += hits[i].triangle != cpu_hits[i].triangle && hits[i].t != cpu_hits[i].t;
        continue;
      }
      device_ms.push_back(timing.device_ms), wall_ms.push_back(wall);
      host_ms.push_back((c1 - c0) + (c3 - c2) + (c5 - c4)), copy_ms.push_back(c2 - c1);
      cpu_ms.push_back(cpu_all_cores_ms(view, batch, std::span<Hit>(cpu_hits).first(n), res.cpu_threads));
    }
    row.device_ms = median(device_ms), row.wall_ms = median(wall_ms), row.cpu_ms = median(cpu_ms);
    row.host_ns_per_ray = median(host_ms) * 1e6 / double(n);
    row.copy_ns_per_ray = median(copy_ms) * 1e6 / double(n);
    // The stream: every frame slot in flight, each refilled as soon as its
    // batch is read (the hits touched, as a caller would read them).
    const uint32_t batches = std::max<uint32_t>(2 * res.frames, uint32_t(std::min<uint64_t>(32, (uint64_t(1) << 22) / n)));
    for (uint32_t s = 0; s < res.frames; ++s) method->rays(s, n), method->submit(s);  // warm: every slot sized
    for (uint32_t s = 0; s < res.frames; ++s) method->hits(s);
    const auto s0 = std::chrono::steady_clock::now();
    [[maybe_unused]] volatile uint32_t seen = 0;  // each batch's hits read, as a caller reads them
    for (uint32_t k = 0; k < batches + res.frames; ++k) {
      const uint32_t slot = k % res.frames;
      if (k >= res.frames) {
        const std::span<const Hit> hits = method->hits(slot);
        seen = hits[n / 2].triangle;
      }
      if (k < batches) {
        std::memcpy(method->rays(slot, n).data(), batch.data(), batch.size_bytes());
        method->submit(slot);
      }
    }
    row.stream_rays_per_s = double(batches) * double(n) / (ms_since(s0) * 1e-3);
    res.rows.push_back(row);
  }
  return res;
}

}  // namespace meshcast::bench
