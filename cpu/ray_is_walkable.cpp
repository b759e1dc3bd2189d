// The rays every walker, CPU and GPU alike, walks (meshcast/ray.h).
#include <algorithm>
#include <cmath>

#include "meshcast/ray.h"

namespace meshcast {

bool ray_is_walkable(const Ray& r) {
  for (int a = 0; a < 3; ++a)
    if (!(std::fabs(r.org[a]) <= kMaxCoordinate) || !(std::fabs(r.dir[a]) <= kMaxDirection)) return false;
  const float m = std::max({std::fabs(r.dir[0]), std::fabs(r.dir[1]), std::fabs(r.dir[2])});
  if (!(m >= 0x1p-126f)) return false;
  // Comparisons false on NaN: a NaN tmax or tmin is refused with them.
  return r.tmax >= 0 && r.tmin >= 0 && r.tmin <= r.tmax;
}

}  // namespace meshcast
