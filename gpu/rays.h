// Rays for the shaders (shaders/ray.glsl): each ray with the per-ray
// constants of the CPU's RayPre, computed here in correctly rounded float so
// the GPU shears exactly as the CPU does.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "cpu/intersect.h"

namespace meshcast::gpu {

constexpr uint32_t kRayWords = 16;  // MC_GPU_RAY_WORDS

// Packs the rays; returns how many are unwalkable (answered as misses).
uint64_t pack_rays(std::span<const Ray> rays, uint32_t* out);

}  // namespace meshcast::gpu
