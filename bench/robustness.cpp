#include "bench/robustness.h"

#include <algorithm>
#include <cstdio>

#include "check/oracle.h"
#include "check/ray_files.h"
#include "meshcast/blob.h"
#include "check/generate.h"
#include "cpu/trace_with_triangle_test.h"

namespace meshcast::bench {

namespace {

// Rays from the centre of a closed sphere to each vertex and each edge's
// midpoint: all must hit, whatever the rounding.
std::vector<Ray> probes(const Mesh& sphere) {
  std::vector<Ray> rays;
  auto aim = [&](Vec3 p) {
    Ray r{{0, 0, 0}, {p.x, p.y, p.z}, 10.0f};
    rays.push_back(r);
  };
  for (const Vec3& v : sphere.vertices) aim(v);
  for (const Triangle& t : sphere.triangles)
    for (int c = 0; c < 3; ++c) {
      Vec3 a = sphere.vertices[t[c]], b = sphere.vertices[t[(c + 1) % 3]];
      aim({0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)});
    }
  return rays;
}

uint64_t leaks(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, TriangleTest test) {
  BlobView view(blob, "probe sphere");
  std::vector<Hit> hits(rays.size());
  trace_with_triangle_test(view, test, rays, hits);
  return uint64_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.triangle == MC_NO_HIT; }));
}

}  // namespace

std::vector<RobustnessRow> bench_robustness(const Mesh& mesh, const std::string& name, size_t ray_count, uint32_t repeat) {
  std::vector<Ray> rays = make_rays(mesh, RayKind::Long, ray_count, 1);
  OracleTree tree(mesh);
  std::vector<OracleHit> oracle;
  for (const Ray& r : rays) oracle.push_back(tree.closest(r));
  Mesh sphere = make_sphere(96, 192, 1.0f, {0, 0, 0});
  std::vector<Ray> probe = probes(sphere);
  std::vector<RobustnessRow> rows;
  for (const char* layout : {"AABBTree/Float3", "AABBTree/Float3SOA8", "QuadTree/Float3SOA4",
                             "QuadTreeHalfFloat/Indexed8BitPackSOA4"}) {
    std::fprintf(stderr, "  %s\n", layout);
    RobustnessRow row{layout};
    BuildOptions o = parse_layout(layout);
    std::vector<uint8_t> sphere_blob = build_blob(sphere, o, "probe sphere");
    row.probes = probe.size();
    for (TriangleTest test : {TriangleTest::Watertight, TriangleTest::MollerTrumbore}) {
      bool plain = test == TriangleTest::MollerTrumbore;
      (plain ? row.plain : row.watertight) = measure(mesh, name, o, rays, oracle, repeat, test);
      (plain ? row.leaks_plain : row.leaks_watertight) = leaks(sphere_blob, probe, test);
    }
    rows.push_back(row);
  }
  return rows;
}

}  // namespace meshcast::bench
