// The point of a triangle nearest a point, in double: the library's point
// queries (cpu/closest_points.cpp) on stored corners.
//
// The regions of the triangle's plane (Ericson, Real-Time Collision
// Detection, 5.1.5): the point's projection falls beyond a corner, beyond
// an edge, or inside, told apart by the signs of dot products of the edges
// with the point's offsets from the corners; each region's nearest point
// follows without a square root. A triangle of no area (its corners on a
// line or at one point) has no inside: its nearest point is the nearest of
// its three edges'.
//
// The functions live in the instruction set's namespace (cpu/isa.h): the
// walkers' files of each set compile them too (cpu/point_triangle_lanes.cpp),
// and an inline function one set compiled must never be the copy the
// baseline code calls.
#pragma once
#include <cmath>

#include "cpu/isa.h"

namespace meshcast {

struct PointOnTriangle {
  double point[3];
  double u, v;  // point = (1 - u - v) a + u b + v c
  double d2;    // squared distance from the query point
};

MC_ISA_BEGIN
namespace point_detail {
inline double dot(const double x[3], const double y[3]) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; }
inline void finish(const double p[3], const double a[3], const double ab[3], const double ac[3], double u, double v,
                   PointOnTriangle& out) {
  out.u = u, out.v = v, out.d2 = 0;
  for (int k = 0; k < 3; ++k) {
    out.point[k] = a[k] + u * ab[k] + v * ac[k];
    const double d = p[k] - out.point[k];
    out.d2 += d * d;
  }
}
// The nearest point of the segment from corner `from` (barycentrics
// (fu, fv)) to corner `to` ((tu, tv)), as barycentrics of the triangle.
inline void nearest_on_edge(const double p[3], const double a[3], const double ab[3], const double ac[3],
                            const double from[3], const double to[3], double fu, double fv, double tu, double tv,
                            PointOnTriangle& best) {
  double e[3], f[3];
  for (int k = 0; k < 3; ++k) e[k] = to[k] - from[k], f[k] = p[k] - from[k];
  const double length2 = dot(e, e);
  double s = length2 > 0 ? dot(f, e) / length2 : 0;
  s = s < 0 ? 0 : s > 1 ? 1 : s;
  PointOnTriangle here;
  finish(p, a, ab, ac, fu + s * (tu - fu), fv + s * (tv - fv), here);
  if (here.d2 < best.d2) best = here;
}
}  // namespace point_detail

// Corners in float (a blob's, as stored) or double (an instance's, placed
// in the world).
template <class Real>
inline PointOnTriangle nearest_on_triangle(const double p[3], const Real fa[3], const Real fb[3], const Real fc[3]) {
  using point_detail::dot;
  using point_detail::finish;
  const double a[3] = {fa[0], fa[1], fa[2]}, b[3] = {fb[0], fb[1], fb[2]}, c[3] = {fc[0], fc[1], fc[2]};
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  for (int k = 0; k < 3; ++k) {
    ab[k] = b[k] - a[k], ac[k] = c[k] - a[k];
    ap[k] = p[k] - a[k], bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
  }
  PointOnTriangle out;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
  const double area = va + vb + vc;
  const auto edges = [&] {
    out.d2 = INFINITY;
    point_detail::nearest_on_edge(p, a, ab, ac, a, b, 0, 0, 1, 0, out);
    point_detail::nearest_on_edge(p, a, ab, ac, b, c, 1, 0, 0, 1, out);
    point_detail::nearest_on_edge(p, a, ab, ac, c, a, 0, 1, 0, 0, out);
  };
  // No area: the corners on a line (within 2^-30 of the edges' lengths,
  // far below float's resolution; the cross product's rounding is 2^-52 of
  // it), or at one point.
  const double n[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  if (!(dot(n, n) > 0x1p-60 * dot(ab, ab) * dot(ac, ac))) {
    edges();
    return out;
  }
  if (d1 <= 0 && d2 <= 0) finish(p, a, ab, ac, 0, 0, out);                               // corner a
  else if (d3 >= 0 && d4 <= d3) finish(p, a, ab, ac, 1, 0, out);                         // corner b
  else if (vc <= 0 && d1 >= 0 && d3 <= 0) finish(p, a, ab, ac, d1 / (d1 - d3), 0, out);  // edge ab
  else if (d6 >= 0 && d5 <= d6) finish(p, a, ab, ac, 0, 1, out);                         // corner c
  else if (vb <= 0 && d2 >= 0 && d6 <= 0) finish(p, a, ab, ac, 0, d2 / (d2 - d6), out);  // edge ac
  else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {                                    // edge bc
    const double s = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    finish(p, a, ab, ac, 1 - s, s, out);
  } else {
    finish(p, a, ab, ac, vb / area, vc / area, out);                                     // inside
  }
  return out;
}

MC_ISA_END
}  // namespace meshcast
