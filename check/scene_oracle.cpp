#include "check/scene_oracle.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "check/agreement.h"

namespace meshcast {

SceneOracle::SceneOracle(const std::vector<const Mesh*>& meshes, const std::vector<OracleInstance>& instances) {
  for (const OracleInstance& i : instances) {
    const float* m = i.transform.rotation_scale;
    // A mirror (a negative determinant) runs the world corners the other
    // way round from the mesh's: (M a) x (M b) = det(M) M^-T (a x b), so
    // the world winding's normal points against the mesh's own. In double
    // from the float entries, a few roundings: its sign is in doubt only
    // for a matrix all but singular.
    const double det = double(m[0]) * (double(m[4]) * m[8] - double(m[5]) * m[7]) -
                       double(m[1]) * (double(m[3]) * m[8] - double(m[5]) * m[6]) +
                       double(m[2]) * (double(m[3]) * m[7] - double(m[4]) * m[6]);
    Placed p{i, {}, {INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, (det < 0) != i.flip_facing};
    const Mesh& mesh = *meshes.at(i.mesh);
    p.corners.reserve(mesh.triangles.size() * 9);
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const Vec3 v = mesh.corner(t, k);
        for (int r = 0; r < 3; ++r) {
          // Products of two floats are exact in double; two roundings at most.
          const double w = i.transform.translation[r] +
                           (double(m[3 * r]) * v[0] + double(m[3 * r + 1]) * v[1] + double(m[3 * r + 2]) * v[2]);
          p.corners.push_back(w);
          p.min[r] = std::min(p.min[r], w), p.max[r] = std::max(p.max[r], w);
        }
      }
    placed_.push_back(std::move(p));
  }
}

template <class Take>
void SceneOracle::visit(const RayD& ray, Cull cull, uint8_t mask, const double* cut, Take&& take) const {
  // A segment the walkers refuse (a NaN or negative end, t_min past t_max)
  // is a miss here too.
  if (!(ray.tmax >= 0 && ray.tmin >= 0 && ray.tmin <= ray.tmax)) return;
  // The direction as the walkers read it (a denormal component as 0).
  const double d[3] = {walked_direction(ray.dir[0]), walked_direction(ray.dir[1]), walked_direction(ray.dir[2])};
  for (const Placed& p : placed_) {
    if ((p.instance.mask & mask) == 0) continue;
    // The instance's box in double, inclusive: only a miss of every
    // triangle is skipped.
    double tn = 0, tf = std::min(double(ray.tmax), *cut);
    for (int a = 0; a < 3 && tn <= tf; ++a) {
      if (d[a] == 0) {
        if (ray.org[a] < p.min[a] || ray.org[a] > p.max[a]) tn = INFINITY;
        continue;
      }
      double t0 = (p.min[a] - ray.org[a]) / d[a], t1 = (p.max[a] - ray.org[a]) / d[a];
      if (t0 > t1) std::swap(t0, t1);
      // One rounding each way: widened by a relative 2^-50.
      tn = std::max(tn, t0 * (1 - 0x1p-50)), tf = std::min(tf, t1 * (1 + 0x1p-50));
    }
    if (!(tn <= tf)) continue;
    // The culling of the world corners' winding that drops the faces the
    // mesh's own winding says `cull` drops.
    const Cull world_cull = !p.world_winding_turned ? cull
                            : cull == Cull::Back    ? Cull::Front
                            : cull == Cull::Front   ? Cull::Back
                                                    : cull;
    for (size_t t = 0; t < p.corners.size() / 9; ++t) {
      const double* c = p.corners.data() + 9 * t;
      const double hit = oracle_triangle(ray.org, d, ray.tmin, ray.tmax, c, c + 3, c + 6, world_cull);
      if (hit != INFINITY) take(hit, p.instance.id, uint32_t(t));
    }
  }
}

SceneOracleHit SceneOracle::closest(const RayD& ray, Cull cull, uint8_t mask) const {
  SceneOracleHit best;
  visit(ray, cull, mask, &best.t, [&](double t, uint32_t instance, uint32_t triangle) {
    // Ties: the lower instance id, then the lower triangle.
    if (t < best.t || (t == best.t && (instance < best.instance || (instance == best.instance && triangle < best.triangle))))
      best = {t, instance, triangle};
  });
  return best;
}

std::vector<SceneOracleHit> SceneOracle::all(const RayD& ray, Cull cull, uint8_t mask) const {
  std::vector<SceneOracleHit> hits;
  const double no_cut = INFINITY;
  visit(ray, cull, mask, &no_cut, [&](double t, uint32_t instance, uint32_t triangle) { hits.push_back({t, instance, triangle}); });
  std::sort(hits.begin(), hits.end(), [](const SceneOracleHit& a, const SceneOracleHit& b) {
    return a.t < b.t || (a.t == b.t && (a.instance < b.instance || (a.instance == b.instance && a.triangle < b.triangle)));
  });
  return hits;
}

size_t SceneOracle::index_of(uint32_t id) const {
  for (size_t i = 0; i < placed_.size(); ++i)
    if (placed_[i].instance.id == id) return i;
  throw std::out_of_range("SceneOracle: no instance " + std::to_string(id));
}

double SceneOracle::distance_to(size_t instance, uint32_t triangle, const RayD& ray, double t) const {
  const double* c = placed_.at(instance).corners.data() + 9 * size_t(triangle);
  const double p[3] = {ray.org[0] + t * ray.dir[0], ray.org[1] + t * ray.dir[1], ray.org[2] + t * ray.dir[2]};
  return point_triangle_distance(p, c, c + 3, c + 6);
}

double SceneOracle::distance_to_edge(size_t instance, uint32_t triangle, const RayD& ray, double t) const {
  const double* c = placed_.at(instance).corners.data() + 9 * size_t(triangle);
  const double p[3] = {ray.org[0] + t * ray.dir[0], ray.org[1] + t * ray.dir[1], ray.org[2] + t * ray.dir[2]};
  return edge_distance(p, c, c + 3, c + 6);
}

double SceneOracle::distance_to_uv(size_t instance, uint32_t triangle, const RayD& ray, double t, double u,
                                   double v) const {
  const double* c = placed_.at(instance).corners.data() + 9 * size_t(triangle);
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double at_uv = c[a] + u * (c[3 + a] - c[a]) + v * (c[6 + a] - c[a]);
    const double d = ray.org[a] + t * ray.dir[a] - at_uv;
    d2 += d * d;
  }
  return std::sqrt(d2);
}

}  // namespace meshcast
