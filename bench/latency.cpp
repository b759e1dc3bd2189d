#include "bench/latency.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/ray_files.h"
#include "meshcast/caster.h"

namespace meshcast::bench {

namespace {

const uint32_t kBatches[] = {1, 16, 64, 256, 1024, 4096, 16384, 65536};

double now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Batch k of size n: a window into the ray pool that moves from batch to batch.
std::span<const Ray> window(const std::vector<Ray>& pool, uint32_t n, uint32_t k) {
  const size_t start = (size_t(k) * 7919u * n) % (pool.size() - n + 1);
  return std::span<const Ray>(pool).subspan(start, n);
}

void measure(host::Caster& caster, host::Backend backend, const std::string& label, const std::vector<Ray>& pool,
             double frame_ms, std::vector<LatencyRow>* rows) {
  std::vector<Hit> hits(pool.size());
  for (uint32_t n : kBatches) {
    // Back to back: submit, wait. About 256k rays a size, 10 to 200 batches.
    const uint32_t batches = std::clamp<uint32_t>(262144 / n, 10, 200);
    for (uint32_t k = 0; k < 2; ++k) caster.wait(caster.submit(window(pool, n, k)), hits);  // warm-up: buffers, command buffers
    caster.clear_records();
    std::vector<double> device;
    for (uint32_t k = 0; k < batches; ++k) device.push_back(caster.wait(caster.submit(window(pool, n, k)), hits).device_ms);
    host::Percentiles p = caster.percentiles(backend, n);
    LatencyRow row{label, n, uint32_t(p.batches), p.p50_ms, p.p99_ms, p.rays_per_second};
    std::sort(device.begin(), device.end());
    row.device_ms = device[device.size() / 2];
    // Frame ahead: submit, other work for a frame (the submitting thread
    // busy, as a game's), collect.
    const uint32_t frames = 10;
    uint32_t ready = 0;
    const double start = now_ms();
    for (uint32_t f = 0; f < frames; ++f) {
      host::Ticket t = caster.submit(window(pool, n, f));
      const double until = now_ms() + frame_ms;
      while (now_ms() < until) {
      }
      ready += caster.poll(t);
      caster.wait(t, hits);
    }
    row.ready_share = double(ready) / frames;
    row.ahead_rays_per_second = double(n) * frames / ((now_ms() - start) * 1e-3);
    rows->push_back(row);
  }
}

}  // namespace

LatencyResult bench_latency(const Mesh& mesh, const std::string& name, double frame_ms, const std::string& device) {
  LatencyResult result;
  result.layout = "QuadTreeHalfFloat/Indexed8BitPackSOA4";  // the CPU's recommended layout, which the GPU's quadtree reads
  std::vector<uint8_t> blob = build_blob(mesh, parse_layout(result.layout), name);
  std::vector<Ray> pool = make_rays(mesh, RayKind::Long, 65536, 1);

  host::CasterOptions one;
  one.backend = host::Backend::Cpu, one.threads = 1, one.frames = 2;
  {
    host::Caster caster(blob, name, one);
    measure(caster, host::Backend::Cpu, "CPU, 1 thread", pool, frame_ms, &result.rows);
  }
  host::CasterOptions all = one;
  all.threads = 0;
  {
    host::Caster caster(blob, name, all);
    result.threads = caster.cpu_threads();
    measure(caster, host::Backend::Cpu, "CPU, " + std::to_string(result.threads) + " threads", pool, frame_ms, &result.rows);
  }
  host::CasterOptions gpu = all;
  gpu.backend = host::Backend::Vulkan, gpu.device = device;
  {
    host::Caster caster(blob, name, gpu);
    result.device = caster.device_name();
    result.gpu_error = caster.gpu_error();
    if (caster.gpu_available()) measure(caster, host::Backend::Vulkan, "Vulkan", pool, frame_ms, &result.rows);
  }
  // What the automatic backend measures for itself at start-up, on the
  // device of the table above, named: by itself it passes over a software
  // device (lavapipe), and would measure nothing there.
  host::CasterOptions automatic = all;
  automatic.backend = host::Backend::Automatic;
  automatic.device = device.empty() && result.gpu_error.empty() ? result.device : device;
  host::Caster caster(blob, name, automatic);
  caster.wait_for_crossover();
  result.crossover = caster.crossover();
  result.why_small = caster.why(16);
  result.why_large = caster.why(65536);
  return result;
}

}  // namespace meshcast::bench
