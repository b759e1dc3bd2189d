// `meshcast bench gpu`: seed 000 §7 on the Vulkan device that runs it, the
// CPU's best layout beside it as the source did.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast::bench {

struct GpuRow {
  std::string method, layout, seed;  // seed: the source's us/ray and bytes/tri ("" where it has none)
  double device_us = 0, wall_us = 0;  // per ray: GPU timestamps; submission to read-back (CPU row: one thread)
  double bytes = 0;                   // walked bytes per triangle
  uint64_t disagreements = 0;
  // Each query's time on the same rays against the closest hit's
  // (device time where the device has timestamps, else wall): any hit, and
  // every hit (rows of 16). 0 for the CPU row.
  double any_to_closest = 0, all_to_closest = 0;
};

// Throws gpu::GpuError when no device can be had. `device` as --device.
std::vector<GpuRow> bench_gpu(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat,
                              const std::string& device, std::string* device_name);

}  // namespace meshcast::bench
