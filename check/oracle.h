// The double-precision oracle every layout is checked against: the closest
// hit over the unmodified input mesh, two-sided, t in [t_min, t_max], no epsilon
// that drops small or thin triangles, ties broken by the lowest triangle
// index. The triangle test is the watertight one (Woop et al. 2013) carried
// out entirely in double, so shared edges and vertices never leak.
#pragma once
#include <vector>

#include "meshcast/mesh.h"
#include "cpu/intersect.h"

namespace meshcast {

struct OracleHit {
  double t = INFINITY;
  uint32_t triangle = MC_NO_HIT;
};

// Hit distance of one triangle, or +inf when the ray misses it or `cull`
// drops the face it meets (the sign of the same double determinant: the
// front face's corners run counter-clockwise seen from the origin).
double oracle_triangle(const Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c, Cull cull = Cull::None);
// The same test on double coordinates (a ray's origin and corners far from
// the origin, scenes): the ray's walkability is the caller's to check.
double oracle_triangle(const double org[3], const double dir[3], double tmin, double tmax, const double a[3], const double b[3],
                       const double c[3], Cull cull = Cull::None);

// Every triangle, in input order.
OracleHit oracle_brute_force(const Mesh& mesh, const Ray& ray, Cull cull = Cull::None);

// A simple median-split tree with double-precision boxes over the same
// triangles, for meshes too large to brute-force; it visits every box the
// ray touches within the best t so far (inclusive), so it finds the same
// answer, ties included.
class OracleTree {
 public:
  explicit OracleTree(const Mesh& mesh);
  OracleHit closest(const Ray& ray, Cull cull = Cull::None) const;
  // Query::All's answer: every triangle the ray hits in [t_min, t_max], in
  // order of t, then triangle.
  std::vector<OracleHit> all(const Ray& ray, Cull cull = Cull::None) const;

 private:
  struct Node {
    double min[3], max[3];
    uint32_t first, count, right;  // count > 0: leaf; else left child = this + 1
  };
  const Mesh& mesh_;
  std::vector<Node> nodes_;
  std::vector<uint32_t> order_;
  uint32_t build(uint32_t first, uint32_t count);
  // Tests every triangle in a box the ray touches before *cut (read again
  // after each leaf), giving each hit to take(t, triangle).
  template <class Take>
  void visit(const Ray& ray, Cull cull, const double* cut, Take&& take) const;
};

}  // namespace meshcast
