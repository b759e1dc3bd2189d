// What the watertight test (cpu/intersect.h) works out in double: the
// inside test of a lane float could not settle, and every hit's t, u and v.
// Compiled once, in the baseline code, for every instruction set's walkers.
#include <algorithm>
#include <cfloat>
#include <cmath>

#include "cpu/intersect.h"

namespace meshcast {

bool watertight_inside_double(const float ax, const float ay, const float bx, const float by, const float cx,
                              const float cy, float cull) {
  // Each product of two floats is exact in double, so each edge function's
  // sign is; inside, the three share a sign and their sum cannot cancel.
  const double U = double(cx) * by - double(cy) * bx;
  const double V = double(ax) * cy - double(ay) * cx;
  const double W = double(bx) * ay - double(by) * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return false;
  const double det = U + V + W;
  return det != 0 && det * cull >= 0;  // cull: the face the query drops
}

bool hit_in_double(const float o[3], const float d[3], const float a[3], const float b[3], const float c[3],
                   float tmin, float limit, bool uv, LaneHit* out) {
  // The plane through the corner nearest the origin (largest coordinate
  // difference least): the sums below lose bits in proportion to that
  // distance, so a hit near a corner keeps them all, however far the other
  // corners lie. p[0] is that corner, p[1] and p[2] the next ones in the
  // winding.
  const float* corner[3] = {a, b, c};
  int base = 0;
  double nearest = INFINITY;
  for (int k = 0; k < 3; ++k) {
    double far = 0;
    for (int j = 0; j < 3; ++j) far = std::max(far, std::fabs(double(corner[k][j]) - o[j]));
    if (far < nearest) nearest = far, base = k;
  }
  const float* p[3] = {corner[base], corner[(base + 1) % 3], corner[(base + 2) % 3]};
  // Differences of floats of nearby magnitude are exact in double; the
  // normal n = e1 x e2 and t = n.(p0 - o) / n.d then carry about 2^-52 of
  // their terms' size, far below a float's half ulp unless the origin lies
  // much closer to the plane than to that corner.
  double e1[3], e2[3], s[3];
  for (int k = 0; k < 3; ++k)
    e1[k] = double(p[1][k]) - p[0][k], e2[k] = double(p[2][k]) - p[0][k], s[k] = double(p[0][k]) - o[k];
  const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
  if (nd == 0) return false;  // the ray lies in the plane, to double's precision: no single t
  double num = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
  // An origin on the plane to within the rounding of that sum is on it, and
  // the hit is at t = 0: the sum's error is below 2^-50 of its terms'
  // magnitudes, each n[k] formed from two products.
  const double size = std::fabs(s[0]) * (std::fabs(e1[1] * e2[2]) + std::fabs(e1[2] * e2[1])) +
                      std::fabs(s[1]) * (std::fabs(e1[2] * e2[0]) + std::fabs(e1[0] * e2[2])) +
                      std::fabs(s[2]) * (std::fabs(e1[0] * e2[1]) + std::fabs(e1[1] * e2[0]));
  if (std::fabs(num) <= 0x1p-49 * size) num = 0;
  const double t = num / nd;
  if (!(t >= 0)) return false;
  // The ends are compared with the float t reported: a hit reported at t is
  // found again by a ray whose tmin or tmax is that t. A t that rounds past
  // the largest float is no hit.
  const float tf = float(std::fabs(t));
  if (!(tf >= tmin && tf <= std::min(limit, FLT_MAX))) return false;
  out->t = tf, out->u = out->v = 0;
  if (uv) {
    // The weights of p[1] and p[2] where the ray meets the plane (Moller and
    // Trumbore's forms, in double), then those of b and c.
    const double q[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
    const double r[3] = {-s[1] * e1[2] + s[2] * e1[1], -s[2] * e1[0] + s[0] * e1[2], -s[0] * e1[1] + s[1] * e1[0]};
    const double w1 = -(s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) / det;
    const double w2 = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / det;
    const double w[3] = {1 - w1 - w2, w1, w2};  // of p[0], p[1], p[2]
    out->u = float(w[(4 - base) % 3]), out->v = float(w[(5 - base) % 3]);  // b is p[(1 - base) mod 3]
  }
  return true;
}

}  // namespace meshcast
