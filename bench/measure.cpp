#include "bench/measure.h"

#include <algorithm>
#include <chrono>

#include "check/agreement.h"
#include "cpu/counters.h"
#include "cpu/trace_with_triangle_test.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "layout/blob_format.h"
#include "layout/tree/lbvh.h"

namespace meshcast::bench {



uint64_t oracle_mistakes(const Mesh& mesh, const std::vector<uint8_t>& blob, const std::vector<Ray>& rays,
                         const std::vector<Hit>& hits, const std::vector<OracleHit>& oracle) {
  const double tolerance = 1e-5 * mesh.bounds().diagonal();
  Agreement a;
  if (moves_vertices(layout::header_of(blob.data()).triangle_format)) {
    Mesh stored = stored_mesh(blob);
    OracleTree stored_tree(stored);
    std::vector<OracleHit> answers(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) answers[i] = stored_tree.closest(rays[i]);
    a = compare(stored, rays, hits, answers, tolerance);
  } else {
    a = compare(mesh, rays, hits, oracle, tolerance);
  }
  return a.wrong + a.t_errors;
}

Setup setup(const Mesh& mesh, size_t count) {
  Setup s{make_rays(mesh, RayKind::Long, count, 1), {}};
  OracleTree tree(mesh);
  for (const Ray& r : s.rays) s.oracle.push_back(tree.closest(r));
  return s;
}

std::vector<double> time_passes(const BlobView& view, const std::vector<Ray>& rays, std::vector<Hit>& hits, uint32_t repeat,
                                TriangleTest test) {
  std::vector<double> ms;
  for (uint32_t r = 0; r < repeat; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    trace_with_triangle_test(view, test, rays, hits);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms;
}

Timing measure(const Mesh& mesh, const std::string& name, const BuildOptions& options, const std::vector<Ray>& rays,
               const std::vector<OracleHit>& oracle, uint32_t repeat, TriangleTest test) {
  BuildReport report;
  std::vector<uint8_t> blob = build_blob(mesh, options, name, &report);
  BlobView view(blob, name);
  std::vector<Hit> hits(rays.size());
  std::vector<double> ms = time_passes(view, rays, hits, repeat, test);
  const layout::BlobHeader& h = layout::header_of(blob.data());
  // Bytes of the triangle encoding: its blocks and its shared vertices.
  double bytes = double(h.tree_size - h.node_bytes + h.vertex_size) / h.triangle_count;
  const uint64_t disagreements = oracle_mistakes(mesh, blob, rays, hits, oracle);
  double tree_bytes = double(h.node_bytes) / h.triangle_count, walked = double(h.vertex_offset + h.vertex_size) / h.triangle_count;
  Timing t{ms.front(), ms[ms.size() / 2], bytes, disagreements, report.build_ms, tree_bytes, walked, report.sah_cost};
  t.total_bytes = double(blob.size()) / h.triangle_count;
  t.error_bound = relative_error_bound(blob, mesh.bounds().diagonal());
  if constexpr (kCountTests) {
    test_counts = {};
    trace_with_triangle_test(view, test, rays, hits);
    t.boxes_per_ray = double(test_counts.boxes) / double(rays.size());
    t.triangles_per_ray = double(test_counts.triangles) / double(rays.size());
  }
  if (h.tree_format == MC_TREE_STACKLESSLBVH) {
    uint64_t holes = 0;
    for (uint32_t n = 1; n <= h.node_count; ++n) holes += layout::load_lbvh_node(blob.data() + h.tree_offset, n).count == 0;
    t.hole_bytes = double(holes * MC_LBVH_NODE_BYTES) / h.triangle_count;
  }
  return t;
}

}  // namespace meshcast::bench
