#include "bench/error.h"

#include "bench/timing.h"
#include "bench/measure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "check/agreement.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "gpu/method.h"
#include "gpu/vulkan.h"
#include "layout/blob_format.h"

namespace meshcast::bench {

namespace {

// The error columns of one layout's hits against the oracle over `mesh`.
void judge(const Mesh& mesh, const std::vector<Ray>& rays, const std::vector<Hit>& hits,
           const std::vector<OracleHit>& oracle, ErrorRow& row) {
  const double diag = std::max(1e-30, mesh.bounds().diagonal());
  double sum_dt = 0;
  uint64_t both = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    bool ohit = oracle[i].triangle != MC_NO_HIT, whit = hits[i].triangle != MC_NO_HIT;
    if (ohit && !whit) ++row.false_misses;
    if (!ohit && whit) ++row.false_hits;
    if (whit) {  // the hit point against the input triangle it names
      const Ray& r = rays[i];
      double p[3], len = 0;
      for (int a = 0; a < 3; ++a) p[a] = double(r.org[a]) + double(hits[i].t) * r.dir[a], len += double(r.dir[a]) * r.dir[a];
      const Triangle& t = mesh.triangles[hits[i].triangle];
      double d = point_triangle_distance(p, mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
      // Beyond 4 ulps of t along the ray: the float t of even an exact
      // format is that far off; what remains is the format's own move.
      double rounding = 4.0 * (std::nextafter(hits[i].t, INFINITY) - hits[i].t) * std::sqrt(len);
      row.max_surface = std::max(row.max_surface, std::max(0.0, d - rounding) / diag);
    }
    if (!ohit || !whit) continue;
    double len = std::sqrt(double(rays[i].dir[0]) * rays[i].dir[0] + double(rays[i].dir[1]) * rays[i].dir[1] +
                           double(rays[i].dir[2]) * rays[i].dir[2]);
    double dt = std::fabs(double(hits[i].t) - oracle[i].t) * len / diag;
    if (hits[i].triangle != oracle[i].triangle && dt > 1e-5) ++row.wrong_triangles;
    row.max_dt = std::max(row.max_dt, dt);
    sum_dt += dt, ++both;
  }
  row.mean_dt = both ? sum_dt / double(both) : 0.0;
  row.rays = rays.size();
}


}  // namespace

std::vector<ErrorRow> bench_error(const std::vector<NamedInput>& meshes, size_t count, uint32_t repeat,
                                  const std::string& device) {
  std::vector<ErrorRow> rows;
  std::unique_ptr<gpu::Context> ctx;
  if (!device.empty()) ctx = std::make_unique<gpu::Context>(gpu::DeviceChoice{device == "any" ? "" : device, false});
  for (const NamedInput& in : meshes) {
    std::vector<Ray> rays = make_rays(in.mesh, RayKind::Long, count, 1);
    OracleTree tree(in.mesh);
    std::vector<OracleHit> oracle;
    for (const Ray& r : rays) oracle.push_back(tree.closest(r));
    const double diag = std::max(1e-30, in.mesh.bounds().diagonal());
    auto finish = [&](ErrorRow row, const std::vector<uint8_t>& blob, const std::vector<Hit>& hits) {
      const layout::BlobHeader& h = layout::header_of(blob.data());
      row.mesh = in.name;
      row.bytes_per_tri = double(h.vertex_offset + h.vertex_size) / h.triangle_count;
      row.bound = relative_error_bound(blob, diag);
      judge(in.mesh, rays, hits, oracle, row);
      rows.push_back(row);
    };
    for (const std::string& layout : layout_names()) {
      BuildOptions o = parse_layout(layout);
      if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE || uint32_t(o.layout.tree) == MC_TREE_AABBLIST) continue;  // the GPU's
      std::fprintf(stderr, "  %s %s\n", in.name.c_str(), layout.c_str());
      std::vector<uint8_t> blob;
      try {
        blob = build_blob(in.mesh, o, in.name);
      } catch (const InputError&) {  // a format limit this mesh exceeds
        continue;
      }
      BlobView view(blob, in.name);
      std::vector<Hit> hits(rays.size());
      std::vector<double> ms = time_passes(view, rays, hits, repeat);
      ErrorRow row;
      row.backend = "CPU, one thread", row.layout = layout;
      row.us_per_ray = ms.front() * 1000.0 / double(rays.size());
      finish(row, blob, hits);
    }
    if (!ctx) continue;
    for (const gpu::MethodLayout& c : gpu::method_layouts()) {
      std::fprintf(stderr, "  %s %s on %s\n", in.name.c_str(), layout_name(c.layout).c_str(), ctx->device_name().c_str());
      std::vector<uint8_t> blob;
      std::unique_ptr<gpu::Method> method;
      try {
        blob = build_blob(in.mesh, parse_layout(layout_name(c.layout)), in.name);
        method = gpu::make_method(*ctx, c.method, blob, in.name);
      } catch (const std::exception&) {  // a limit of the format or the device (maxStorageBufferRange)
        continue;
      }
      std::vector<Hit> hits(rays.size());
      std::vector<double> ms;
      for (uint32_t r = 0; r < repeat; ++r) {
        gpu::GpuTiming t;
        method->trace(rays, hits, &t);
        ms.push_back(t.device_ms);
      }
      ErrorRow row;
      row.backend = "Vulkan " + std::string(c.method) + " (device time)", row.layout = layout_name(c.layout);
      row.us_per_ray = median(ms) * 1000.0 / double(rays.size());
      finish(row, blob, hits);
    }
  }
  return rows;
}

}  // namespace meshcast::bench
