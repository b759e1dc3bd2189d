#include "gpu/rays.h"

#include <cstring>

namespace meshcast::gpu {

uint64_t pack_rays(std::span<const Ray> rays, uint32_t* out) {
  uint64_t skipped = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    uint32_t* w = out + i * kRayWords;
    std::memset(w, 0, kRayWords * 4);
    if (!ray_is_walkable(rays[i])) {
      ++skipped;
      continue;
    }
    const RayPre p(rays[i]);
    float f[10] = {p.org[0], p.org[1], p.org[2], p.dir[0], p.dir[1], p.dir[2], rays[i].tmax, p.sx, p.sy, p.sz};
    std::memcpy(w, f, sizeof f);
    w[10] = uint32_t(p.axis[0]) | uint32_t(p.axis[1]) << 2 | uint32_t(p.axis[2]) << 4;
    w[11] = 1;
    std::memcpy(w + 12, p.inv, 12);
    std::memcpy(w + 15, &rays[i].tmin, 4);
  }
  return skipped;
}

}  // namespace meshcast::gpu
