// Rays for the shaders: each ray with its per-ray constants, in the record
// of layout/ray_record.h.
#pragma once
#include <cstdint>
#include <span>

#include "layout/ray_record.h"
#include "meshcast/ray.h"

namespace meshcast::gpu {

constexpr uint32_t kRayWords = MC_RAY_WORDS;

// Packs the rays; returns how many are unwalkable (answered as misses).
uint64_t pack_rays(std::span<const Ray> rays, uint32_t* out);

}  // namespace meshcast::gpu
