// Rays both fuzz targets cast at whatever they built or were given: a grid
// across each face of a box toward the opposite face, the box's diagonals,
// grazing rays along its faces, diagonals with a t_min, and rays no walker
// may walk (NaN, zero direction, negative t_max, NaN, negative or inverted
// t_min). Deterministic: a crash replays from its input.
#pragma once
#include <cmath>
#include <vector>

#include "cpu/intersect.h"

namespace meshcast::fuzz {

inline std::vector<Ray> rays_through_box(const float lo_in[3], const float hi_in[3]) {
  float lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {  // a damaged header may hold anything
    lo[a] = std::isfinite(lo_in[a]) ? lo_in[a] : -1.0f;
    hi[a] = std::isfinite(hi_in[a]) && hi_in[a] >= lo[a] ? hi_in[a] : lo[a] + 1.0f;
  }
  std::vector<Ray> rays;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int i = 0; i <= 4; ++i)
      for (int j = 0; j <= 4; ++j)
        for (float sign : {1.0f, -1.0f}) {
          Ray r{};
          r.org[u] = lo[u] + (hi[u] - lo[u]) * 0.25f * float(i);
          r.org[v] = lo[v] + (hi[v] - lo[v]) * 0.25f * float(j);
          r.org[axis] = sign > 0 ? lo[axis] - 1.0f : hi[axis] + 1.0f;
          r.dir[axis] = sign;  // the other components stay +0: axis-parallel, on shared edges
          r.tmax = INFINITY;
          rays.push_back(r);
        }
  }
  for (int corner = 0; corner < 8; ++corner) {
    Ray r{};
    for (int a = 0; a < 3; ++a) {
      bool high = corner >> a & 1;
      r.org[a] = high ? hi[a] : lo[a];
      r.dir[a] = high ? lo[a] - hi[a] : hi[a] - lo[a];
    }
    r.tmax = corner & 1 ? 1.0f : INFINITY;
    rays.push_back(r);
  }
  rays.push_back({{lo[0], lo[1], lo[2]}, {1, 0, 0}, INFINITY});  // along an edge of the box
  // The box's diagonals again, starting half way: t_min skips what lies
  // before it, and t_min = t_max keeps one point.
  const size_t diagonals = rays.size() - 9;
  for (int corner = 0; corner < 8; corner += 3) {
    Ray r = rays[diagonals + size_t(corner)];
    r.tmin = 0.5f;
    if (corner == 6) r.tmax = 0.5f;
    rays.push_back(r);
  }
  rays.push_back({{NAN, lo[1], lo[2]}, {1, 0, 0}, INFINITY});
  rays.push_back({{lo[0], lo[1], lo[2]}, {0, 0, 0}, INFINITY});
  rays.push_back({{lo[0], lo[1], lo[2]}, {1, 1, 1}, -1.0f});
  rays.push_back({{lo[0], lo[1], lo[2]}, {1, 1, 1}, INFINITY, NAN});
  rays.push_back({{lo[0], lo[1], lo[2]}, {1, 1, 1}, 1.0f, 2.0f});  // t_min past t_max
  rays.push_back({{lo[0], lo[1], lo[2]}, {1, 1, 1}, 1.0f, -1.0f});
  return rays;
}

// Whether every hit lies on its ray's segment, t_min <= t <= t_max (a
// walker reporting one outside it is a bug whatever the blob holds).
inline bool hits_on_segments(const std::vector<Ray>& rays, const std::vector<Hit>& hits) {
  for (size_t i = 0; i < rays.size(); ++i)
    if (hits[i].triangle != MC_NO_HIT && !(hits[i].t >= rays[i].tmin && hits[i].t <= rays[i].tmax)) return false;
  return true;
}

}  // namespace meshcast::fuzz
