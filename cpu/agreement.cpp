#include "cpu/agreement.h"

#include <cmath>

#include "layout/blob.h"
#include "layout/block.h"

namespace meshcast {

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
    const double t_tolerance = tolerance / len;
    const Hit& h = hits[i];
    const OracleHit& o = oracle[i];
    if (h.triangle == MC_NO_HIT && o.triangle == MC_NO_HIT) continue;
    if (h.triangle == MC_NO_HIT || o.triangle == MC_NO_HIT || h.triangle >= mesh.triangles.size()) {
      ++a.wrong;
      note(i, "hit/miss differs");
      continue;
    }
    if (h.triangle != o.triangle) {
      // A tie: the oracle itself hits the walker's triangle at the same t.
      double t = oracle_triangle(rays[i], mesh.corner(h.triangle, 0), mesh.corner(h.triangle, 1),
                                 mesh.corner(h.triangle, 2));
      if (std::isfinite(t) && std::fabs(t - o.t) <= t_tolerance) {
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

Mesh quantized_mesh(const Mesh& mesh, const std::vector<uint8_t>& blob) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  Mesh q = mesh;
  for (Vec3& v : q.vertices) {
    float p[3] = {v.x, v.y, v.z}, d[3];
    layout::bitpack_decode(layout::bitpack_encode(p, h.quant_offset, h.quant_scale), h.quant_offset, h.quant_scale, d);
    v = {d[0], d[1], d[2]};
  }
  return q;
}

}  // namespace meshcast
