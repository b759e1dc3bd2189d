// `meshcast bench gpu --sizes`: the recommended layout's GPU method at
// batch sizes from a thousand rays to millions, beside the CPU's every core
// on the same rays: where the time goes, and from which size the GPU pays.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct GpuScaleRow {
  uint64_t rays = 0;
  // One batch (medians of the passes): the GPU's timestamps, and submit()
  // until the hits are readable where the device wrote them.
  double device_ms = 0, wall_ms = 0;
  // Several batches in flight (`frames` slots): rays over the whole stream.
  double stream_rays_per_s = 0;
  // The submitting thread's CPU time a ray in rays(), submit() and hits(),
  // its waits left out; and the bench's own copy of its rays into the
  // mapped buffer (what a caller that builds rays elsewhere first pays).
  double host_ns_per_ray = 0, copy_ns_per_ray = 0;
  double cpu_ms = 0;  // every core of this machine, the same rays (BlobView::trace on a thread each)
  uint64_t differ = 0;  // rays whose triangle differs from the CPU's (not at the same t)
};

struct GpuScaleResult {
  std::string device, layout, method;
  uint32_t cpu_threads = 0, frames = 0;
  std::vector<GpuScaleRow> rows;
};

// Long random rays; `repeat` passes a size. Throws GpuError without a device.
GpuScaleResult bench_gpu_scale(const Mesh& mesh, const std::string& name, const std::vector<uint64_t>& sizes,
                               uint32_t repeat, const std::string& device);

}  // namespace meshcast::bench
