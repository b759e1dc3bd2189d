// Point queries: the point of a blob's stored mesh nearest each query
// point (BlobView::closest_points), for distances, signed distances and
// snapping. The nearest point on each triangle is worked out in double
// from the stored corners, so a distance is the exact one to the stored
// mesh, rounded once to float. On a layout that stores vertices exactly
// (ClusterFloat3SOA8, Float3SOA8) that is the input mesh; on a quantized one
// (ClusterBitPackSOA8) the stored corners lie within the layout's stated
// bound of the input's (relative_error_bound, a fraction of the mesh's
// diagonal), and so does every distance.
#pragma once
#include <cmath>
#include <cstdint>

#include "meshcast/ray.h"

namespace meshcast {

struct ClosestPoint {
  float point[3] = {0, 0, 0};   // the nearest point, on the stored triangle
  float distance = INFINITY;    // from the query point; INFINITY: none within the limit
  uint32_t triangle = kNoHit;   // the caller's triangle number (without a remap: the slot)
  // The nearest point's barycentrics: point = (1 - u - v) a + u b + v c of
  // the stored corners a, b, c (strips: of a rotation of them, as for hits).
  float u = 0, v = 0;
};

}  // namespace meshcast
