// The CPU entry point: closest hits for a batch of rays against a blob.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "cpu/ray.h"

namespace meshcast {

// A blob that passed layout::validate, kept with its walker.
class BlobView {
 public:
  // Validates; throws InputError naming `name` and the problem.
  BlobView(std::span<const uint8_t> bytes, const std::string& name);
  // Traces one thread's batch; returns how many rays were not walkable.
  // `outputs`: the per-hit outputs (MC_HIT_UV, MC_HIT_POINT) to compute;
  // the others read 0.
  uint64_t trace(std::span<const Ray> rays, std::span<Hit> hits, uint32_t outputs = 0) const;
  std::span<const uint8_t> bytes() const { return bytes_; }

 private:
  std::span<const uint8_t> bytes_;
  void (*walk_)(const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, uint32_t) = nullptr;
};

// Double-precision fallback of the watertight test lives in trace.cpp.

}  // namespace meshcast
