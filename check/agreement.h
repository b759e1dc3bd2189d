// How a walker's answers are judged against the oracle: used by the tests
// and by the main job's disagreement column.
#pragma once
#include <string>
#include <vector>

#include "meshcast/mesh.h"
#include "check/oracle.h"
#include "cpu/intersect.h"

namespace meshcast {

// How far from the exact distance to the named triangle a walker's t may
// lie, in float ulps (check/exact_t.h): the walkers work each hit's t out
// in double from the stored corners, so it is correctly rounded (0.5) but
// where the origin lies far closer to the triangle's plane than to its
// corners.
constexpr double kTUlps = 1.0;

struct Agreement {
  // t_rounding: hits whose t lies more than kTUlps from the exact distance
  // to their triangle in `mesh` (judged by the callers whose mesh is the
  // one the blob stores).
  size_t rays = 0, ties = 0, wrong = 0, t_errors = 0, t_rounding = 0;
  double max_t_error = 0;
  std::string first_problem;
};

// Distances in double: to the triangle abc, and to its nearest edge.
double point_triangle_distance(const double p[3], const Vec3& a, const Vec3& b, const Vec3& c);
double edge_distance(const double p[3], const Vec3& a, const Vec3& b, const Vec3& c);
// The same with corners in double (scenes far from the origin).
double point_triangle_distance(const double p[3], const double a[3], const double b[3], const double c[3]);
double edge_distance(const double p[3], const double a[3], const double b[3], const double c[3]);

// The foundation rules: the walker returns the oracle's hit/miss and
// triangle, with t within `tolerance`, a distance along the ray (1e-5 of the
// diagonal), plus 4 float ulps of t for origins very far away. Where only
// rounding decides, a difference is counted as a tie instead:
//  - another triangle at the same t that touches the oracle's hit point
//    (a shared edge or vertex, coincident triangles);
//  - a walker hit against an oracle miss at the ends of the segment (a
//    surface at t_min, i.e. the origin on the surface when t_min is 0, or
//    at t_max), on the hit triangle's edge, or for a ray lying in the
//    triangle's plane;
//  - with t_min above 0, different triangles where either lies at t_min
//    (rounding decides whether it is on the segment);
//  - a walker miss against an oracle hit at the ends of the segment, or
//    within a few float ulps of the hit triangle's edge (a grazed silhouette).
// A walker miss in the middle of a triangle is always wrong; leaks through
// shared edges are checked by the closed-mesh tests. max_t_error is a
// distance.
Agreement compare(const Mesh& mesh, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                  const std::vector<OracleHit>& oracle, double tolerance);

// Query::Any's rules: the walker's hit/miss is the oracle's, and a hit
// names a triangle the ray hits in double at the walker's t (the rules of
// compare() above, with that triangle as the oracle's answer); a triangle
// the double test misses counts only where compare() would call it a tie
// (its edge, the segment's ends, the ray in its plane).
// `closest`: the oracle's closest hits under the same culling, `cull`.
Agreement compare_any(const Mesh& mesh, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                      const std::vector<OracleHit>& closest, double tolerance, Cull cull = Cull::None);

// Query::All's rules: ray i's row names the oracle's set of triangles
// (oracle[i], OracleTree::all), each once, in order of t, with found[i] its
// size (every row must hold all its hits: max_hits above the largest set).
// Each triangle of one set and not the other is judged as compare() judges
// a hit against a miss (its edge, the segment's ends, the ray in its plane
// are ties); each triangle of both by its t. `rays` counts pairs of a ray
// and a triangle.
Agreement compare_all(const Mesh& mesh, const std::vector<Ray>& rays, const HitLists& lists,
                      const std::vector<std::vector<OracleHit>>& oracle, double tolerance);

// The triangles as the blob stores them, decoded by its triangle format and
// put back in input order: a triangle soup, three vertices a triangle. The
// exact reference for formats that move vertices. A blob without a remap
// numbers its triangles by slot (layout/blob_format.h has_remap), and so does this.
Mesh stored_mesh(const std::vector<uint8_t>& blob);

}  // namespace meshcast
