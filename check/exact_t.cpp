#include "check/exact_t.h"

#include <gmpxx.h>

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace meshcast {

namespace {

// The spacing of floats at x (x >= 0): 2^(e - 23) for x in [2^e, 2^(e+1)),
// 2^-149 among the denormals.
double float_ulp(double x) {
  if (x < double(FLT_MIN)) return 0x1p-149;
  return std::ldexp(1.0, std::ilogb(x) - 23);
}

struct Exact {
  mpq_class t, u, v;
  bool defined = false;
};

Exact exact_hit(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c) {
  mpq_class o[3], d[3], e1[3], e2[3], s[3];
  for (int k = 0; k < 3; ++k) {
    o[k] = double(ray.org[k]), d[k] = double(walked_direction(ray.dir[k]));
    e1[k] = mpq_class(double(b[k])) - double(a[k]), e2[k] = mpq_class(double(c[k])) - double(a[k]);
    s[k] = mpq_class(double(a[k])) - o[k];
  }
  auto cross = [](const mpq_class x[3], const mpq_class y[3], mpq_class out[3]) {
    out[0] = x[1] * y[2] - x[2] * y[1], out[1] = x[2] * y[0] - x[0] * y[2], out[2] = x[0] * y[1] - x[1] * y[0];
  };
  auto dot = [](const mpq_class x[3], const mpq_class y[3]) { return mpq_class(x[0] * y[0] + x[1] * y[1] + x[2] * y[2]); };
  mpq_class n[3];
  cross(e1, e2, n);
  Exact e;
  const mpq_class nd = dot(n, d);
  if (nd == 0) return e;
  e.defined = true;
  e.t = dot(n, s) / nd;
  // The point p = o + t d in barycentrics: p - a = u e1 + v e2, solved by
  // Cramer's rule on the normal's components.
  mpq_class w[3], x[3];
  for (int k = 0; k < 3; ++k) w[k] = e.t * d[k] - s[k];
  const mpq_class nn = dot(n, n);
  cross(w, e2, x);
  e.u = dot(x, n) / nn;
  cross(e1, w, x);
  e.v = dot(x, n) / nn;
  return e;
}

// |x - exact| as a double.
double distance(float x, const mpq_class& exact) { return mpq_class(abs(mpq_class(double(x)) - exact)).get_d(); }

double ulps_off(float t, const mpq_class& exact) { return distance(t, exact) / float_ulp(std::fabs(exact.get_d())); }

}  // namespace

ExactHitError exact_hit_error(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, const Hit& hit) {
  const Exact e = exact_hit(ray, a, b, c);
  ExactHitError out;
  if (!e.defined) return out;
  out.defined = true;
  out.t_ulps = ulps_off(hit.t, e.t);
  out.uv = std::max(distance(hit.u, e.u), distance(hit.v, e.v));
  // The scale: the largest of o, t d and the point on any axis (o + t d
  // cancels where a long ray from far away ends near the origin, and t's
  // rounding is relative to t d).
  double worst = 0, largest = 0;
  for (int k = 0; k < 3; ++k) {
    const mpq_class along = e.t * double(walked_direction(ray.dir[k]));
    const mpq_class p = mpq_class(double(ray.org[k])) + along;
    worst = std::max(worst, distance(hit.point[k], p));
    largest = std::max({largest, std::fabs(p.get_d()), std::fabs(along.get_d()), std::fabs(double(ray.org[k]))});
  }
  out.point_ulps = worst / float_ulp(largest);
  return out;
}

bool t_within_ulps(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, float t, double ulps) {
  // In double first, with a bound on its own error: the differences of
  // floats are exact but where their exponents lie far apart (then off by
  // 2^-53 of themselves), each product and sum adds 2^-53 of its size.
  double d[3], e1[3], e2[3], s[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = walked_direction(ray.dir[k]);
    e1[k] = double(b[k]) - a[k], e2[k] = double(c[k]) - a[k], s[k] = double(a[k]) - ray.org[k];
  }
  double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  double m[3] = {std::fabs(e1[1] * e2[2]) + std::fabs(e1[2] * e2[1]), std::fabs(e1[2] * e2[0]) + std::fabs(e1[0] * e2[2]),
                 std::fabs(e1[0] * e2[1]) + std::fabs(e1[1] * e2[0])};
  const double num = n[0] * s[0] + n[1] * s[1] + n[2] * s[2];
  const double num_size = m[0] * std::fabs(s[0]) + m[1] * std::fabs(s[1]) + m[2] * std::fabs(s[2]);
  const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
  const double nd_size = m[0] * std::fabs(d[0]) + m[1] * std::fabs(d[1]) + m[2] * std::fabs(d[2]);
  // Relative errors at most 8 * 2^-53 of each size: generous for these
  // few operations.
  const double num_err = 0x1p-50 * num_size, nd_err = 0x1p-50 * nd_size;
  if (std::fabs(nd) > 2 * nd_err && std::isfinite(num) && std::isfinite(nd)) {
    const double td = num / nd;
    // |t - td| for the true t, to first order, and the division's rounding.
    const double err = (num_err + std::fabs(td) * nd_err) / (std::fabs(nd) - nd_err) + 0x1p-52 * std::fabs(td);
    const double off = std::fabs(double(t) - td);
    // The ulp at the exact t lies between those at td - err and td + err.
    const double lo_ulp = float_ulp(std::max(0.0, std::fabs(td) - err)), hi_ulp = float_ulp(std::fabs(td) + err);
    if (off + err <= ulps * lo_ulp) return true;
    if (off - err > ulps * hi_ulp) return false;
  }
  const Exact e = exact_hit(ray, a, b, c);
  return !e.defined || ulps_off(t, e.t) <= ulps;
}

}  // namespace meshcast
