// The GPU methods of seed 000 §7, each reading a blob exactly as uploaded.
// A method is made once per mesh (pipelines, descriptor sets and the blob's
// buffer), then traces any number of ray batches.
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cpu/ray.h"
#include "gpu/vulkan.h"

namespace meshcast::gpu {

struct GpuTiming {
  double device_ms = 0;  // between the batch's first and last GPU timestamps (0 without timestamps)
  double wall_ms = 0;    // packing, submission, waiting and reading back
};

class Method {
 public:
  virtual ~Method() = default;
  // Hits for `rays` (hits.size() >= rays.size()); returns the unwalkable
  // rays, answered as misses as on the CPU.
  virtual uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, GpuTiming* timing = nullptr) = 0;
};

// The methods and the layouts they read so far:
//   bruteforce  BruteForce/Float3SOA128 or BruteForce/BitPackSOA128
//   aabblist    AABBList/Float3SOA128 or AABBList/BitPackSOA128
//   aabbtree    AABBTree/Float3 or AABBTree/UncompressedStrip
//   skdtree     SKDTree/Float3               lbvh      StacklessLBVH/Float3
//   quadtree    QuadTreeHalfFloat/Indexed8BitPackSOA4
// Throws GpuError, or InputError (an unknown method, or a blob whose layout
// the method does not read, naming both).
std::unique_ptr<Method> make_method(Context& ctx, const std::string& method, std::span<const uint8_t> blob,
                                    const std::string& name);
std::vector<std::string> method_names();

// AABBList (method 2) with a pair buffer of `pairs` (ray, batch) pairs: a
// batch of rays goes in chunks of pairs / batches rays. make_method's uses
// 2^22 (32 MiB); a test passes a small one to split batches into many chunks.
std::unique_ptr<Method> make_aabblist(Context& ctx, std::span<const uint8_t> blob, const std::string& name,
                                      uint64_t pairs);

}  // namespace meshcast::gpu
