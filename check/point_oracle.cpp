// The point queries' oracle (check/point_oracle.h).
#include "check/point_oracle.h"

#include <cmath>
#include <numbers>

namespace meshcast {

namespace {

void cross(const double x[3], const double y[3], double out[3]) {
  out[0] = x[1] * y[2] - x[2] * y[1];
  out[1] = x[2] * y[0] - x[0] * y[2];
  out[2] = x[0] * y[1] - x[1] * y[0];
}
double dot(const double x[3], const double y[3]) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; }

// The nearest point of segment [a, b] (a point where a == b).
double segment(const double p[3], const double a[3], const double b[3], double near[3]) {
  double e[3], f[3];
  for (int k = 0; k < 3; ++k) e[k] = b[k] - a[k], f[k] = p[k] - a[k];
  const double length2 = dot(e, e);
  const double s = length2 > 0 ? std::fmin(1.0, std::fmax(0.0, dot(f, e) / length2)) : 0.0;
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    near[k] = a[k] + s * e[k];
    d2 += (p[k] - near[k]) * (p[k] - near[k]);
  }
  return std::sqrt(d2);
}

}  // namespace

double oracle_point_triangle(const double p[3], const Vec3& va, const Vec3& vb, const Vec3& vc, double near[3]) {
  const double a[3] = {va.x, va.y, va.z}, b[3] = {vb.x, vb.y, vb.z}, c[3] = {vc.x, vc.y, vc.z};
  double ab[3], ac[3], n[3];
  for (int k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k];
  cross(ab, ac, n);
  const double n2 = dot(n, n);
  if (n2 > 0) {
    // The projection q = p - ((p - a).n / n.n) n, and its barycentrics
    // u = n.((q - a) x ac) / n.n, v = n.(ab x (q - a)) / n.n.
    double aq[3], q[3], w[3];
    double h = 0;
    for (int k = 0; k < 3; ++k) h += (p[k] - a[k]) * n[k];
    for (int k = 0; k < 3; ++k) q[k] = p[k] - h / n2 * n[k], aq[k] = q[k] - a[k];
    cross(aq, ac, w);
    const double u = dot(n, w) / n2;
    cross(ab, aq, w);
    const double v = dot(n, w) / n2;
    if (u >= 0 && v >= 0 && u + v <= 1) {
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        near[k] = a[k] + u * ab[k] + v * ac[k];
        d2 += (p[k] - near[k]) * (p[k] - near[k]);
      }
      return std::sqrt(d2);
    }
  }
  double best = INFINITY, here[3];
  const double* corners[3] = {a, b, c};
  for (int e = 0; e < 3; ++e) {
    const double d = segment(p, corners[e], corners[(e + 1) % 3], here);
    if (d < best) best = d, near[0] = here[0], near[1] = here[1], near[2] = here[2];
  }
  return best;
}

OraclePoint oracle_closest_point(const Mesh& mesh, const double p[3]) {
  OraclePoint best;
  double near[3];
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const double d = oracle_point_triangle(p, mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2), near);
    if (d < best.distance) {
      best.distance = d, best.triangle = uint32_t(t);
      for (int k = 0; k < 3; ++k) best.point[k] = near[k];
    }
  }
  return best;
}

namespace {

// The angle at corner A of the spherical triangle A B C: between the great
// circles A-B and A-C, the angle between the normals of their planes.
double corner_angle(const double a[3], const double b[3], const double c[3]) {
  double ab[3], ac[3], both[3];
  cross(a, b, ab);
  cross(a, c, ac);
  cross(ab, ac, both);
  return std::atan2(std::sqrt(dot(both, both)), dot(ab, ac));
}

}  // namespace

double oracle_winding_number(const Mesh& mesh, const double p[3]) {
  double sum = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    double u[3][3];
    bool degenerate = false;
    for (int corner = 0; corner < 3; ++corner) {
      for (int k = 0; k < 3; ++k) u[corner][k] = double(mesh.corner(t, corner)[k]) - p[k];
      const double length = std::sqrt(dot(u[corner], u[corner]));
      if (!(length > 0)) degenerate = true;
      for (int k = 0; k < 3; ++k) u[corner][k] /= length;
    }
    if (degenerate) continue;  // p on a corner: that triangle sees no area
    double bc[3];
    cross(u[1], u[2], bc);
    const double det = dot(u[0], bc);
    if (det == 0) continue;  // p in the triangle's plane
    const double excess = corner_angle(u[0], u[1], u[2]) + corner_angle(u[1], u[2], u[0]) +
                          corner_angle(u[2], u[0], u[1]) - std::numbers::pi;
    sum += det > 0 ? excess : -excess;
  }
  return sum / (4 * std::numbers::pi);
}

}  // namespace meshcast
