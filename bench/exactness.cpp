#include "bench/exactness.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>

#include "builder/layout_names.h"
#include "builder/ray_sets.h"
#include "check/agreement.h"
#include "check/exact_t.h"
#include "meshcast/blob.h"
#include "meshcast/build.h"

namespace meshcast::bench {

namespace {

// Rays that graze each of a spread of triangles: along its first edge, off
// its plane by 1e-4 of its normal, through its centroid (from 2 edge
// lengths before it).
std::vector<Ray> grazing_rays(const Mesh& mesh, size_t count) {
  std::vector<Ray> rays;
  const size_t step = std::max<size_t>(1, mesh.triangles.size() / std::max<size_t>(1, count / 2));
  for (size_t t = 0; t < mesh.triangles.size() && rays.size() < count; t += step) {
    const Vec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    const float e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e2[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) continue;
    for (float off : {1e-4f, -1e-4f}) {
      Ray r{};
      for (int k = 0; k < 3; ++k) {
        r.dir[k] = e1[k] + off * n[k] / len;
        r.org[k] = (a[k] + b[k] + c[k]) / 3 - 2 * r.dir[k];
      }
      r.tmax = INFINITY;
      rays.push_back(r);
    }
  }
  return rays;
}

void measure(ExactnessRow& row, const Mesh& stored, const Ray& ray, const Hit& h) {
  if (h.triangle == MC_NO_HIT) return;
  const Vec3 a = stored.corner(h.triangle, 0), b = stored.corner(h.triangle, 1), c = stored.corner(h.triangle, 2);
  const ExactHitError e = exact_hit_error(ray, a, b, c, h);
  if (!e.defined) return;
  ++row.hits;
  row.rounded += e.t_ulps <= 0.5;
  row.t_ulps = std::max(row.t_ulps, e.t_ulps);
  row.uv = std::max(row.uv, e.uv);
  row.point_ulps = std::max(row.point_ulps, e.point_ulps);
}

}  // namespace

std::vector<ExactnessRow> bench_exactness(const Mesh& mesh, const std::string& name, size_t count) {
  std::vector<ExactnessRow> rows;
  for (const char* layout : {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/ClusterFloat3SOA8"}) {
    const std::vector<uint8_t> blob = build_blob(mesh, parse_layout(layout), name);
    const BlobView view(blob, name);
    const Mesh stored = stored_mesh(blob);  // the triangles t is the distance to
    const HitOutputs outputs = HitOutputs::Uv | HitOutputs::Point;
    for (size_t kind = 0; kind <= ray_kind_names().size(); ++kind) {
      const bool grazing = kind == ray_kind_names().size();
      const std::vector<Ray> rays = grazing ? grazing_rays(stored, count) : make_rays(mesh, RayKind(kind), count, 1);
      ExactnessRow row{name, layout, grazing ? "grazing" : ray_kind_names()[kind]};
      for (Query query : {Query::Closest, Query::Any}) {
        std::vector<Hit> hits(rays.size());
        view.trace(rays, hits, outputs, query);
        for (size_t i = 0; i < rays.size(); ++i) measure(row, stored, rays[i], hits[i]);
      }
      HitLists lists;
      lists.max_hits = 64;
      view.trace_all_hits(rays, lists, outputs);
      for (size_t i = 0; i < rays.size(); ++i)
        for (const Hit& h : lists.row(i)) measure(row, stored, rays[i], h);
      rows.push_back(row);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
