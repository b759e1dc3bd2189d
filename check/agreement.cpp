#include "check/agreement.h"

#include <algorithm>
#include <cmath>

#include "check/exact_t.h"
#include "layout/blob_format.h"
#include "layout/triangles/block.h"
#include "layout/tree/leaves.h"

namespace meshcast {

namespace {

double dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

}  // namespace

namespace {
struct Corners {
  double a[3], b[3], c[3];
  Corners(const Vec3& x, const Vec3& y, const Vec3& z) {
    for (int k = 0; k < 3; ++k) a[k] = x[k], b[k] = y[k], c[k] = z[k];
  }
};
}  // namespace

double edge_distance(const double p[3], const Vec3& a, const Vec3& b, const Vec3& c) {
  const Corners k(a, b, c);
  return edge_distance(p, k.a, k.b, k.c);
}

double point_triangle_distance(const double p[3], const Vec3& a, const Vec3& b, const Vec3& c) {
  const Corners k(a, b, c);
  return point_triangle_distance(p, k.a, k.b, k.c);
}

// Distance from p to the nearest edge of the triangle abc.
double edge_distance(const double p[3], const double a[3], const double b[3], const double c[3]) {
  auto segment = [&](const double* s, const double* e) {
    double d[3], w[3];
    for (int k = 0; k < 3; ++k) d[k] = double(e[k]) - s[k], w[k] = p[k] - s[k];
    double dd = dot(d, d), u = dd > 0 ? std::clamp(dot(w, d) / dd, 0.0, 1.0) : 0.0;
    for (int k = 0; k < 3; ++k) w[k] -= u * d[k];
    return std::sqrt(dot(w, w));
  };
  return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

// Closest point on a triangle by its Voronoi regions (vertex, edge, face),
// in double.
double point_triangle_distance(const double p[3], const double a[3], const double b[3], const double c[3]) {
  double ab[3], ac[3], ap[3];
  for (int k = 0; k < 3; ++k) ab[k] = double(b[k]) - a[k], ac[k] = double(c[k]) - a[k], ap[k] = p[k] - a[k];
  double q[3];
  auto at = [&](double v, double w) {
    for (int k = 0; k < 3; ++k) q[k] = a[k] + v * ab[k] + w * ac[k];
  };
  double d1 = dot(ab, ap), d2 = dot(ac, ap);
  double bp[3], cp[3];
  for (int k = 0; k < 3; ++k) bp[k] = p[k] - b[k], cp[k] = p[k] - c[k];
  double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
  double va = d3 * d6 - d5 * d4, vb = d5 * d2 - d1 * d6, vc = d1 * d4 - d3 * d2;
  if (d1 <= 0 && d2 <= 0) at(0, 0);
  else if (d3 >= 0 && d4 <= d3) at(1, 0);
  else if (d6 >= 0 && d5 <= d6) at(0, 1);
  else if (vc <= 0 && d1 >= 0 && d3 <= 0) at(d1 / (d1 - d3), 0);
  else if (vb <= 0 && d2 >= 0 && d6 <= 0) at(0, d2 / (d2 - d6));
  else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    at(1 - w, w);
  } else {
    double sum = va + vb + vc;
    if (sum == 0) at(0, 0);  // degenerate triangle: fall back to a corner
    else at(vb / sum, vc / sum);
  }
  double d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
  return std::sqrt(dot(d, d));
}

Agreement compare(const Mesh& mesh, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                  const std::vector<OracleHit>& oracle, double tolerance) {
  Agreement a;
  a.rays = rays.size();
  auto note = [&](size_t i, const std::string& what) {
    if (a.first_problem.empty())
      a.first_problem = "ray " + std::to_string(i) + ": " + what + " (walker t " + std::to_string(hits[i].t) +
                        " tri " + std::to_string(hits[i].triangle) + ", oracle t " + std::to_string(oracle[i].t) +
                        " tri " + std::to_string(oracle[i].triangle) + ")";
  };
  for (size_t i = 0; i < rays.size(); ++i) {
    // t is in units of the direction; the tolerance is a distance.
    const double len = std::sqrt(double(rays[i].dir[0]) * rays[i].dir[0] + double(rays[i].dir[1]) * rays[i].dir[1] +
                                 double(rays[i].dir[2]) * rays[i].dir[2]);
    const Hit& h = hits[i];
    const OracleHit& o = oracle[i];
    // A float t cannot be closer than its own rounding: allow 4 ulps of the
    // oracle's distance beside the tolerance (it matters only for origins
    // very far from the mesh).
    const double t_tolerance = tolerance / len + (std::isfinite(o.t) ? o.t * 0x1p-21 : 0.0);
    if (h.triangle == MC_NO_HIT && o.triangle == MC_NO_HIT) continue;
    if (h.triangle >= mesh.triangles.size() && h.triangle != MC_NO_HIT) {
      ++a.wrong;
      note(i, "triangle index out of range");
      continue;
    }
    if (h.triangle != MC_NO_HIT) {
      // Whichever triangle it names, the walker's t is the distance to it
      // within an ulp, by exact arithmetic (meaningful where `mesh` is what
      // the blob stores: callers judge t_rounding there).
      const Vec3 ta = mesh.corner(h.triangle, 0), tb = mesh.corner(h.triangle, 1), tc = mesh.corner(h.triangle, 2);
      if (!t_within_ulps(rays[i], ta, tb, tc, h.t, kTUlps)) {
        ++a.t_rounding;
        note(i, "t lies more than " + std::to_string(kTUlps) + " ulp from the exact distance to its triangle");
      }
    }
    if (h.triangle == MC_NO_HIT || o.triangle == MC_NO_HIT) {
      // Hit/miss may differ only where the hit lies within rounding of the
      // ends of the segment [t_min, t_max]: a surface at t_min (an origin
      // on the surface when t_min is 0), or a surface at t_max.
      const Ray& r = rays[i];
      auto at = [&](double t, double p[3]) {
        for (int k = 0; k < 3; ++k) p[k] = double(r.org[k]) + t * double(r.dir[k]);
      };
      bool boundary = false;
      double p[3];
      if (h.triangle != MC_NO_HIT) {
        const Vec3 ta = mesh.corner(h.triangle, 0), tb = mesh.corner(h.triangle, 1), tc = mesh.corner(h.triangle, 2);
        at(r.tmin, p);
        boundary = std::fabs(h.t - r.tmin) * len <= tolerance && point_triangle_distance(p, ta, tb, tc) <= tolerance;
        if (!boundary && std::isfinite(r.tmax)) {
          at(r.tmax, p);
          boundary = std::fabs(h.t - r.tmax) <= t_tolerance && point_triangle_distance(p, ta, tb, tc) <= tolerance;
        }
        if (!boundary) {
          // A ray in the triangle's plane (to within rounding) touches it
          // along a segment: float may see a hit where double sees det = 0.
          double e1[3], e2[3], n[3];
          for (int k = 0; k < 3; ++k) e1[k] = double(tb[k]) - ta[k], e2[k] = double(tc[k]) - ta[k];
          n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2], n[2] = e1[0] * e2[1] - e1[1] * e2[0];
          double nd = n[0] * r.dir[0] + n[1] * r.dir[1] + n[2] * r.dir[2];
          double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
          at(h.t, p);
          boundary = std::fabs(nd) <= 1e-5 * nn * len && point_triangle_distance(p, ta, tb, tc) <= tolerance;
          // A hit on the triangle's edge or corner, where the double test
          // rounded the other way (a miss there leaks only if no neighbour
          // takes the ray: the closed-mesh tests check that).
          boundary = boundary || edge_distance(p, ta, tb, tc) <= tolerance;
        }
      } else {
        boundary = std::fabs(o.t - r.tmin) * len <= tolerance ||
                   (std::isfinite(r.tmax) && std::fabs(o.t - r.tmax) <= t_tolerance);
        if (!boundary) {
          // A miss where the oracle's hit lies within float rounding of its
          // triangle's edge: a ray grazing a silhouette, where the surface
          // folds over, meets both triangles of the edge or neither, and
          // rounding decides which (through a shared edge it would be a
          // leak, which the closed-mesh tests catch). Rounding here is a few
          // float ulps of the largest coordinate the test computes with.
          const Vec3 ta = mesh.corner(o.triangle, 0), tb = mesh.corner(o.triangle, 1), tc = mesh.corner(o.triangle, 2);
          double scale = 0;
          for (int k = 0; k < 3; ++k)
            scale = std::max({scale, std::fabs(double(r.org[k])), std::fabs(double(ta[k])), std::fabs(double(tb[k])),
                              std::fabs(double(tc[k]))});
          at(o.t, p);
          boundary = edge_distance(p, ta, tb, tc) <= 8 * 0x1p-23 * scale;
        }
      }
      if (boundary) {
        ++a.ties;
      } else {
        ++a.wrong;
        note(i, "hit/miss differs");
      }
      continue;
    }
    if (h.triangle != o.triangle && rays[i].tmin > 0 &&
        (std::fabs(double(h.t) - rays[i].tmin) * len <= tolerance || std::fabs(o.t - rays[i].tmin) * len <= tolerance)) {
      // One of the two lies at t_min, where rounding decides whether it is
      // on the segment: the other answer is then the next hit along. The
      // walker's triangle must still lie on the ray at its t, and where the
      // oracle's hit is the one at t_min the walker's comes no nearer.
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = double(rays[i].org[k]) + double(h.t) * double(rays[i].dir[k]);
      const double gap = point_triangle_distance(p, mesh.corner(h.triangle, 0), mesh.corner(h.triangle, 1),
                                                 mesh.corner(h.triangle, 2));
      const bool oracle_at_t_min = std::fabs(o.t - rays[i].tmin) * len <= tolerance;
      if (gap <= tolerance && (!oracle_at_t_min || double(h.t) >= o.t - t_tolerance)) {
        ++a.ties;
      } else {
        ++a.wrong;
        note(i, "different triangle beside t_min");
      }
      continue;
    }
    if (h.triangle != o.triangle) {
      // A tie: both hit at the same t, and the walker's triangle touches the
      // point where the ray meets the oracle's (a shared edge or vertex, or
      // coincident triangles), within the tolerance.
      double p[3];
      for (int k = 0; k < 3; ++k) p[k] = double(rays[i].org[k]) + o.t * double(rays[i].dir[k]);
      double gap = point_triangle_distance(p, mesh.corner(h.triangle, 0), mesh.corner(h.triangle, 1),
                                           mesh.corner(h.triangle, 2));
      if (std::fabs(double(h.t) - o.t) <= t_tolerance && gap <= tolerance) {
        ++a.ties;
      } else {
        ++a.wrong;
        note(i, "different triangle");
        continue;
      }
    }
    double err = std::fabs(double(h.t) - o.t);
    a.max_t_error = std::max(a.max_t_error, err * len);
    if (!(err <= t_tolerance)) {
      ++a.t_errors;
      note(i, "t differs by " + std::to_string(err));
    }
  }
  return a;
}

Agreement compare_any(const Mesh& mesh, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
                      const std::vector<OracleHit>& closest, double tolerance, Cull cull) {
  // The oracle's answer a ray is judged by: the walker's own triangle where
  // the double test hits it, a miss where it does not (so only compare()'s
  // boundary rules can excuse it), the closest hit where the walker missed.
  std::vector<OracleHit> judge(closest);
  for (size_t i = 0; i < rays.size() && i < hits.size(); ++i) {
    const uint32_t tri = hits[i].triangle;
    if (tri == MC_NO_HIT || tri >= mesh.triangles.size()) continue;
    const double t = oracle_triangle(rays[i], mesh.corner(tri, 0), mesh.corner(tri, 1), mesh.corner(tri, 2), cull);
    judge[i] = std::isfinite(t) ? OracleHit{t, tri} : OracleHit{};
  }
  return compare(mesh, rays, hits, judge, tolerance);
}

Agreement compare_all(const Mesh& mesh, const std::vector<Ray>& rays, const HitLists& lists,
                      const std::vector<std::vector<OracleHit>>& oracle, double tolerance) {
  Agreement a;
  auto wrong = [&](size_t i, const std::string& what) {
    ++a.wrong;
    if (a.first_problem.empty()) a.first_problem = "ray " + std::to_string(i) + ": " + what;
  };
  // Every (ray, triangle) of either set as one compare() case: the walker's
  // hit or a miss against the oracle's hit or a miss.
  std::vector<Ray> pair_rays;
  std::vector<Hit> pair_hits;
  std::vector<OracleHit> pair_oracle;
  std::vector<size_t> pair_ray;
  // Compact rows (meshcast/ray.h): a row a ray, offsets covering the hits.
  if (lists.rays() != rays.size() || lists.offsets.size() != rays.size() + 1 || lists.offsets.front() != 0 ||
      lists.offsets.back() != lists.hits.size() || !std::is_sorted(lists.offsets.begin(), lists.offsets.end())) {
    wrong(0, "rows for " + std::to_string(lists.rays()) + " rays with " + std::to_string(lists.offsets.size()) +
                 " offsets over " + std::to_string(lists.hits.size()) + " hits, for " + std::to_string(rays.size()) +
                 " rays");
    return a;
  }
  for (size_t i = 0; i < rays.size(); ++i) {
    const std::span<const Hit> row = lists.row(i);
    if (lists.found[i] > lists.max_hits) {
      wrong(i, std::to_string(lists.found[i]) + " hits found, more than the row's " + std::to_string(lists.max_hits));
      continue;
    }
    if (row.size() != lists.found[i])
      wrong(i, std::to_string(lists.found[i]) + " hits found but the row keeps " + std::to_string(row.size()));
    for (size_t k = 1; k < row.size(); ++k)
      if (row[k].t < row[k - 1].t || (row[k].t == row[k - 1].t && row[k].triangle <= row[k - 1].triangle))
        wrong(i, "the row is not in order of t, then triangle, or names a triangle twice");
    size_t w = 0, o = 0;
    const std::vector<OracleHit>& expected = oracle[i];
    // Both sets by triangle.
    std::vector<Hit> mine(row.begin(), row.end());
    std::vector<OracleHit> theirs(expected);
    std::sort(mine.begin(), mine.end(), [](const Hit& x, const Hit& y) { return x.triangle < y.triangle; });
    std::sort(theirs.begin(), theirs.end(), [](const OracleHit& x, const OracleHit& y) { return x.triangle < y.triangle; });
    while (w < mine.size() || o < theirs.size()) {
      Hit h;
      OracleHit ref;
      if (o == theirs.size() || (w < mine.size() && mine[w].triangle < theirs[o].triangle)) {
        h = mine[w++];
      } else if (w == mine.size() || theirs[o].triangle < mine[w].triangle) {
        ref = theirs[o++];
      } else {
        h = mine[w++], ref = theirs[o++];
      }
      pair_rays.push_back(rays[i]), pair_hits.push_back(h), pair_oracle.push_back(ref), pair_ray.push_back(i);
    }
  }
  Agreement b = compare(mesh, pair_rays, pair_hits, pair_oracle, tolerance);
  a.rays = b.rays, a.ties = b.ties, a.wrong += b.wrong, a.t_errors = b.t_errors, a.t_rounding = b.t_rounding, a.max_t_error = b.max_t_error;
  if (a.first_problem.empty() && !b.first_problem.empty()) {
    // compare() names its own index: the pair's; name the ray too.
    const size_t at = std::stoul(b.first_problem.substr(4));
    a.first_problem = "ray " + std::to_string(pair_ray[at]) + ", " + b.first_problem.substr(b.first_problem.find(':') + 2);
  }
  return a;
}

Mesh stored_mesh(const std::vector<uint8_t>& blob) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  Mesh m;
  // Without a remap, triangles are numbered by slot: holes become
  // triangles of one point (zero area, vertex 0 three times), which no ray
  // hits.
  const size_t count = layout::has_remap(h) ? h.triangle_count : h.remap_slots;
  m.vertices.resize(count * 3);
  m.triangles.assign(count, Triangle{0, 0, 0});
  layout::for_each_leaf(blob.data(), [&](uint32_t block, uint32_t count) {
    for (uint32_t i = 0; i < count; ++i) {
      uint32_t t = layout::remap_entry(blob.data(), h, layout::slot_of(h, block, i));
      float v[3][3];
      layout::decode_triangle(blob.data(), h.tree_offset + block, i, v);
      for (int c = 0; c < 3; ++c) m.vertices[size_t(t) * 3 + c] = {v[c][0], v[c][1], v[c][2]};
      m.triangles[t] = {t * 3, t * 3 + 1, t * 3 + 2};
    }
  });
  return m;
}

}  // namespace meshcast
