// `meshcast bench latency`: the host layer's batches from 1 to
// 65,536 rays on the CPU (one thread, every thread) and on the Vulkan
// device, latency percentiles, rays a second, frame-ahead throughput, and
// the crossover the automatic backend measures.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct LatencyRow {
  std::string backend;
  uint32_t batch = 0, batches = 0;
  double p50_ms = 0, p99_ms = 0, rays_per_second = 0;
  double device_ms = 0;  // GPU timestamps, median (Vulkan)
  // Frame ahead: a batch submitted, `frame_ms` of other work on the
  // submitting thread, then collected; how many frames found it ready and
  // the rays a second that pace sustains.
  double ready_share = 0, ahead_rays_per_second = 0;
};

struct LatencyResult {
  std::vector<LatencyRow> rows;
  std::string device, gpu_error, layout, why_small, why_large;
  uint32_t threads = 0, crossover = ~0u;
};

LatencyResult bench_latency(const Mesh& mesh, const std::string& name, double frame_ms, const std::string& device);

}  // namespace meshcast::bench
