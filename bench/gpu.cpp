#include "bench/gpu.h"

#include <algorithm>
#include <map>

#include "bench/timing.h"
#include "bench/measure.h"
#include "check/agreement.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "gpu/method.h"
#include "gpu/vulkan.h"
#include "layout/blob_format.h"
#include "layout/formats.h"

namespace meshcast::bench {

namespace {


}  // namespace

std::vector<GpuRow> bench_gpu(const Mesh& mesh, const std::string& name, size_t count, uint32_t repeat,
                              const std::string& device, std::string* device_name) {
  gpu::Context ctx(gpu::DeviceChoice{device, false});
  *device_name = ctx.device_name();
  std::vector<Ray> rays = make_rays(mesh, RayKind::Long, count, 1);
  OracleTree oracle_tree(mesh);
  std::vector<OracleHit> oracle;
  for (const Ray& r : rays) oracle.push_back(oracle_tree.closest(r));
  // Seed 000 §7 (GTX 1050, DirectX 11, bunny, 4 triangles a leaf): us per ray, bytes per triangle.
  const std::map<std::string, const char*> seed = {{"AABBTree/Float3", "0.34 us, 53.4 B"},
                                                   {"AABBTree/UncompressedStrip", "0.41 us, 37.1 B"},
                                                   {"AABBList/Float3SOA128", "1.06 us, 36.2 B (its Float3SOA256)"},
                                                   {"SKDTree/Float3", "1.15 us, 41.0 B"},
                                                   {"BruteForce/BitPackSOA128", "35.01 us, 24 B"},
                                                   {"BruteForce/Float3SOA128", "41.67 us, 36 B"}};
  std::vector<GpuRow> rows;
  for (const gpu::MethodLayout& c : gpu::method_layouts()) {
    BuildOptions o = parse_layout(layout_name(c.layout));
    o.leaf_size = 4;  // the source's GPU table
    std::vector<uint8_t> blob = build_blob(mesh, o, name);
    std::unique_ptr<gpu::Method> method = gpu::make_method(ctx, c.method, blob, name);
    std::vector<Hit> hits(rays.size());
    std::vector<double> device_ms, wall_ms;
    for (uint32_t r = 0; r < repeat; ++r) {
      gpu::GpuTiming t;
      method->trace(rays, hits, &t);
      device_ms.push_back(t.device_ms), wall_ms.push_back(t.wall_ms);
    }
    // The other queries, each a method of its own, the passes interleaved
    // with a closest-hit pass so both see the same state of the device.
    std::unique_ptr<gpu::Method> any = gpu::make_method(ctx, c.method, blob, name, 1, MC_QUERY_ANY);
    std::unique_ptr<gpu::Method> every = gpu::make_method(ctx, c.method, blob, name, 1, MC_QUERY_ALL, 16);
    std::vector<double> closest_ms, any_ms, all_ms;
    HitLists lists;
    auto ms_of = [](const gpu::GpuTiming& t) { return t.device_ms > 0 ? t.device_ms : t.wall_ms; };
    for (uint32_t r = 0; r < repeat; ++r) {
      gpu::GpuTiming t;
      method->trace(rays, hits, &t);
      closest_ms.push_back(ms_of(t));
      any->trace(rays, hits, &t);
      any_ms.push_back(ms_of(t));
      every->trace_all_hits(rays, lists, &t);
      all_ms.push_back(ms_of(t));
    }
    const layout::BlobHeader& h = layout::header_of(blob.data());
    auto figure = seed.find(layout_name(c.layout));
    GpuRow row{c.method, layout_name(c.layout), figure == seed.end() ? "" : figure->second};
    row.device_us = median(device_ms) * 1000.0 / double(rays.size());
    row.wall_us = median(wall_ms) * 1000.0 / double(rays.size());
    row.bytes = double(h.vertex_offset + h.vertex_size) / h.triangle_count;
    method->trace(rays, hits);  // the closest hits, judged
    row.disagreements = oracle_mistakes(mesh, blob, rays, hits, oracle);
    row.any_to_closest = median(any_ms) / median(closest_ms);
    row.all_to_closest = median(all_ms) / median(closest_ms);
    rows.push_back(row);
  }
  // The CPU's recommended layout, one thread, as the source's yellow row.
  Timing t = measure(mesh, name, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), rays, oracle, repeat);
  GpuRow cpu{"CPU, one thread", "QuadTreeHalfFloat/Indexed8BitPackSOA4 (leaf 8)", "0.47 us, 18.3 B (its QuadTree)"};
  cpu.wall_us = t.median_ms * 1000.0 / double(rays.size());
  cpu.bytes = t.walked_bytes;
  cpu.disagreements = t.disagreements;
  rows.push_back(cpu);
  return rows;
}

}  // namespace meshcast::bench
