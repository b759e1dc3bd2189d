#include "builder/mesh_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "builder/pairing.h"

namespace meshcast {

MeshStats measure_mesh(const Mesh& mesh) {
  MeshStats s;
  s.triangles = mesh.triangles.size();
  s.vertices = mesh.vertices.size();
  std::vector<uint32_t> uses(mesh.vertices.size(), 0);
  std::vector<float> sizes;
  sizes.reserve(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) ++uses[mesh.triangles[t][k]];
    const Vec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
    const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (area > 0)
      sizes.push_back(float(std::sqrt(area)));
    else
      ++s.degenerate;
  }
  s.used_vertices = size_t(std::count_if(uses.begin(), uses.end(), [](uint32_t u) { return u > 0; }));
  s.corners_per_vertex = s.used_vertices ? 3.0 * double(s.triangles) / double(s.used_vertices) : 0;
  if (!sizes.empty()) {
    auto at = [&](double q) {
      auto it = sizes.begin() + ptrdiff_t(q * double(sizes.size() - 1));
      std::nth_element(sizes.begin(), it, sizes.end());
      return double(*it);
    };
    const double p10 = at(0.1), p90 = at(0.9);
    s.size_spread = p10 > 0 ? p90 / p10 : 0;
  }
  const Box3 box = mesh.bounds();
  s.diagonal = box.diagonal();
  const Vec3 c = box.centre(), e = box.extent();
  const double dc = std::sqrt(double(c.x) * c.x + double(c.y) * c.y + double(c.z) * c.z);
  s.origin_distance = s.diagonal > 0 ? dc / s.diagonal : 0;
  const float big = std::max({e.x, e.y, e.z}), small = std::min({e.x, e.y, e.z});
  s.flatness = big > 0 ? double(small) / double(big) : 0;
  PairingOptions po;
  po.skip_above = 2;  // always run the pass: the pre-scan alone undercounts shuffled input
  s.paired_ratio = pair_triangles(mesh, po).paired_ratio;
  return s;
}

std::string describe(const MeshStats& s) {
  char text[640];
  std::snprintf(text, sizeof text,
                "  triangles        %zu (%zu degenerate)\n"
                "  vertices         %zu (%zu used), %.2f corners a vertex\n"
                "  paired           %.1f%% of triangles across a shared edge (seed 003)\n"
                "  box              diagonal %g, centre %.3g diagonals from the origin, flatness %.3f (reported)\n"
                "  triangle sizes   90th / 10th percentile %.2f (reported)\n",
                s.triangles, s.degenerate, s.vertices, s.used_vertices, s.corners_per_vertex, 100 * s.paired_ratio,
                s.diagonal, s.origin_distance, s.flatness, s.size_spread);
  return text;
}

}  // namespace meshcast
