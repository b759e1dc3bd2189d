#include "gpu/rays.h"

#include <cstring>

namespace meshcast::gpu {

namespace {

void put(uint32_t* record, uint32_t word, const float* values, int count) {
  std::memcpy(record + word, values, size_t(count) * 4);
}

}  // namespace

uint64_t pack_rays(std::span<const Ray> rays, uint32_t* out) {
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    uint32_t* w = out + i * kRayWords;
    std::memset(w, 0, kRayWords * 4);
    const Ray& r = rays[i];
    if (!ray_is_walkable(r)) {
      ++skipped;
      continue;
    }
    const float dir[3] = {walked_direction(r.dir[0]), walked_direction(r.dir[1]), walked_direction(r.dir[2])};
    const layout::RayConstants c = layout::ray_constants(dir);
    const float shear[3] = {c.sx, c.sy, c.sz};
    put(w, MC_RAY_ORG, r.org, 3);
    put(w, MC_RAY_DIR, dir, 3);
    put(w, MC_RAY_TMAX, &r.tmax, 1);
    put(w, MC_RAY_SHEAR, shear, 3);
    w[MC_RAY_AXES] = uint32_t(c.axis[0]) | uint32_t(c.axis[1]) << 2 | uint32_t(c.axis[2]) << 4;
    w[MC_RAY_WALKABLE] = 1;
    put(w, MC_RAY_INV, c.inv, 3);
    put(w, MC_RAY_TMIN, &r.tmin, 1);
  }
  return skipped;
}

}  // namespace meshcast::gpu
