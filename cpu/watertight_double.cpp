// The watertight test's double-precision redo (cpu/intersect.h): compiled
// once, in the baseline code, for every instruction set's walkers.
#include <algorithm>
#include <cfloat>

#include "cpu/intersect.h"

namespace meshcast {

bool watertight_lane_double(const float ax, const float ay, const float bx, const float by, const float cx,
                            const float cy, const float az, const float bz, const float cz, const float sz,
                            float cull, float tmin, float closest, LaneHit* out) {
  double U = double(cx) * by - double(cy) * bx;
  double V = double(ax) * cy - double(ay) * cx;
  double W = double(bx) * ay - double(by) * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  double det = U + V + W;
  if (det == 0 || det * cull < 0) return false;  // cull: the face the query drops
  double T = (U * az + V * bz + W * cz) * double(sz);
  if (det < 0) T = -T, U = -U, V = -V, W = -W, det = -det;
  if (T < 0) return false;
  // The ends are compared with the float t reported, as the float test
  // does: a hit reported at t is found again by a ray whose tmin or tmax
  // is that t (a t in double just below tmin, rounded up to it, would not
  // be). A t that rounds past the largest float is no hit.
  const float t = float(T / det);
  if (!(t >= tmin && t <= std::min(closest, FLT_MAX))) return false;
  out->t = t, out->u = float(V / det), out->v = float(W / det);
  return true;
}

}  // namespace meshcast
