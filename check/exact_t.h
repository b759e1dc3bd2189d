// A hit's t, u and v against exact arithmetic: the ray o + t d (the walked
// direction) meets the plane of the triangle abc at t = n.(a - o) / n.d,
// n = (b - a) x (c - a), a rational number of the float inputs that GMP
// works out without rounding. How far a reported float lies from it is
// measured in float ulps of the exact value (the spacing of floats there;
// 2^-149 below FLT_MIN), so 0.5 is a correctly rounded t.
#pragma once
#include "meshcast/mesh.h"
#include "meshcast/ray.h"

namespace meshcast {

struct ExactHitError {
  bool defined = false;  // false: the ray is parallel to the plane (n.d = 0), no single t
  double t_ulps = 0;     // |t - exact| in ulps of the exact t
  double uv = 0;         // the larger of |u - exact u| and |v - exact v| (barycentrics of b and c)
  // The point against o + t d at the exact t (t's own error included), in
  // ulps of the largest coordinate of o, t d and the point.
  double point_ulps = 0;
};

// A hit's t, u, v and point (HitOutputs::Uv | Point) against the exact
// values on the triangle abc. Exact throughout (slow: microseconds a hit).
ExactHitError exact_hit_error(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, const Hit& hit);

// Whether t lies within `ulps` of the exact t: decided in double where the
// double result's own error bound settles it, exactly (GMP) elsewhere.
// A ray parallel to the plane passes (it has no t to compare with).
bool t_within_ulps(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, float t, double ulps);

}  // namespace meshcast
