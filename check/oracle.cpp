#include "check/oracle.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace meshcast {

double oracle_triangle(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, Cull cull) {
  if (!ray_is_walkable(ray)) return INFINITY;
  // The direction as the walkers read it (a denormal component as 0).
  const double o[3] = {ray.org[0], ray.org[1], ray.org[2]},
               d[3] = {walked_direction(ray.dir[0]), walked_direction(ray.dir[1]), walked_direction(ray.dir[2])};
  const double da[3] = {a[0], a[1], a[2]}, db[3] = {b[0], b[1], b[2]}, dc[3] = {c[0], c[1], c[2]};
  return oracle_triangle(o, d, ray.tmin, ray.tmax, da, db, dc, cull);
}

double oracle_triangle(const double org[3], const double dir[3], double tmin, double tmax, const double a[3], const double b[3],
                       const double c[3], Cull cull) {
  const double* d = dir;
  int kz = std::fabs(d[0]) > std::fabs(d[1]) ? (std::fabs(d[0]) > std::fabs(d[2]) ? 0 : 2)
                                             : (std::fabs(d[1]) > std::fabs(d[2]) ? 1 : 2);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (d[kz] < 0) std::swap(kx, ky);
  double sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.0 / d[kz];
  auto rel = [&](const double* p, int k) { return p[k] - org[k]; };
  double az = rel(a, kz), bz = rel(b, kz), cz = rel(c, kz);
  double ax = rel(a, kx) - sx * az, ay = rel(a, ky) - sy * az;
  double bx = rel(b, kx) - sx * bz, by = rel(b, ky) - sy * bz;
  double cx = rel(c, kx) - sx * cz, cy = rel(c, ky) - sy * cz;
  double U = cx * by - cy * bx, V = ax * cy - ay * cx, W = bx * ay - by * ax;
  if ((U < 0 || V < 0 || W < 0) && (U > 0 || V > 0 || W > 0)) return INFINITY;
  double det = U + V + W;
  if (det == 0) return INFINITY;
  if ((cull == Cull::Back && det < 0) || (cull == Cull::Front && det > 0)) return INFINITY;
  double T = (U * az + V * bz + W * cz) * sz;
  double t = T / det;
  // A t past the largest float is no hit: no walker could report it. Both
  // ends of the segment are included, as the walkers include them.
  if (!(t >= 0) || t < tmin || t > tmax || t > double(FLT_MAX)) return INFINITY;
  return t;
}

OracleHit oracle_brute_force(const Mesh& mesh, const Ray& ray, Cull cull) {
  OracleHit best;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    double t = oracle_triangle(ray, mesh.corner(i, 0), mesh.corner(i, 1), mesh.corner(i, 2), cull);
    if (t < best.t) best = {t, uint32_t(i)};  // strict: the lowest index wins a tie
  }
  return best;
}

OracleTree::OracleTree(const Mesh& mesh) : mesh_(mesh) {
  order_.resize(mesh.triangles.size());
  for (uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  nodes_.reserve(order_.size() / 2 + 1);
  build(0, uint32_t(order_.size()));
}

uint32_t OracleTree::build(uint32_t first, uint32_t count) {
  uint32_t index = uint32_t(nodes_.size());
  nodes_.push_back({{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, first, 0, 0});
  for (uint32_t i = first; i < first + count; ++i)
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) {
        double v = mesh_.corner(order_[i], k)[a];
        nodes_[index].min[a] = std::min(nodes_[index].min[a], v);
        nodes_[index].max[a] = std::max(nodes_[index].max[a], v);
      }
  if (count <= 4) {
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (nodes_[index].max[a] - nodes_[index].min[a] > nodes_[index].max[axis] - nodes_[index].min[axis]) axis = a;
  auto centre = [&](uint32_t t) {
    return double(mesh_.corner(t, 0)[axis]) + mesh_.corner(t, 1)[axis] + mesh_.corner(t, 2)[axis];
  };
  uint32_t* b = order_.data() + first;
  std::nth_element(b, b + count / 2, b + count, [&](uint32_t x, uint32_t y) { return centre(x) < centre(y); });
  build(first, count / 2);
  uint32_t right = build(first + count / 2, count - count / 2);
  nodes_[index].right = right;
  return index;
}

template <class Take>
void OracleTree::visit(const Ray& ray, Cull cull, const double* cut, Take&& take) const {
  if (!ray_is_walkable(ray)) return;
  // Box test in double: exact enough that the small widening below covers
  // every rounding (the boxes hold float vertices, the ray float values).
  auto touches = [&](const Node& n) {
    double tn = 0, tf = ray.tmax;
    for (int a = 0; a < 3; ++a) {
      double o = ray.org[a], d = walked_direction(ray.dir[a]);
      if (d == 0) {
        if (o < n.min[a] || o > n.max[a]) return false;
        continue;
      }
      double t0 = (n.min[a] - o) / d, t1 = (n.max[a] - o) / d;
      if (t0 > t1) std::swap(t0, t1);
      tn = std::max(tn, t0 - 1e-9 * std::fabs(t0));
      tf = std::min(tf, t1 + 1e-9 * std::fabs(t1));
    }
    return tn <= tf && tn <= *cut;
  };
  uint32_t stack[128];
  int top = 0;
  stack[0] = 0;
  while (top >= 0) {
    const Node& n = nodes_[stack[top--]];
    if (!touches(n)) continue;
    if (n.count) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        uint32_t t = order_[i];
        double d = oracle_triangle(ray, mesh_.corner(t, 0), mesh_.corner(t, 1), mesh_.corner(t, 2), cull);
        if (d != INFINITY) take(d, t);
      }
    } else {
      stack[++top] = n.right;
      stack[++top] = uint32_t(&n - nodes_.data()) + 1;
    }
  }
}

OracleHit OracleTree::closest(const Ray& ray, Cull cull) const {
  OracleHit best;
  visit(ray, cull, &best.t, [&](double d, uint32_t t) {
    if (d < best.t || (d == best.t && t < best.triangle)) best = {d, t};
  });
  return best;
}

std::vector<OracleHit> OracleTree::all(const Ray& ray, Cull cull) const {
  std::vector<OracleHit> hits;
  const double cut = INFINITY;  // tmax bounds every box already
  visit(ray, cull, &cut, [&](double d, uint32_t t) { hits.push_back({d, t}); });
  std::sort(hits.begin(), hits.end(), [](const OracleHit& a, const OracleHit& b) {
    return a.t < b.t || (a.t == b.t && a.triangle < b.triangle);
  });
  return hits;
}

}  // namespace meshcast
