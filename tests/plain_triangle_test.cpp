// The plain Möller–Trumbore walkers `meshcast bench robustness` compares
// with the library's (cpu/trace_with_triangle_test.h). Built with the
// command-line program, where those walkers are (CMakeLists.txt), not in
// the sanitizer builds, which never link them.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "check/generate.h"
#include "cpu/trace_with_triangle_test.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

// Rays from the centre of a closed sphere aimed exactly at each vertex and
// each edge's midpoint: every one must hit (bench/robustness.cpp's probes).
std::vector<Ray> sphere_probes(const Mesh& sphere) {
  std::vector<Ray> rays;
  auto aim = [&](Vec3 p) { rays.push_back(Ray{{0, 0, 0}, {p.x, p.y, p.z}, 10.0f}); };
  for (const Vec3& v : sphere.vertices) aim(v);
  for (const Triangle& t : sphere.triangles)
    for (int c = 0; c < 3; ++c) {
      const Vec3 a = sphere.vertices[t[c]], b = sphere.vertices[t[(c + 1) % 3]];
      aim({0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)});
    }
  return rays;
}

size_t misses(const std::vector<Hit>& hits) {
  return size_t(std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.triangle == MC_NO_HIT; }));
}

// They find the oracle's hits for rays that pass nowhere near an edge (what
// the plain test may lose is the edge cases).
TEST(TriangleTests, MollerTrumboreWalkersFindTheOraclesHits) {
  for (const NamedMesh& m : test_meshes(false)) {
    if (m.name != "sphere" && !is_chosen_public_mesh(m.name)) continue;
    const std::vector<Ray>& rays = test_rays(m, RayKind::Long, 2000);
    for (const char* layout : {"AABBTree/Float3", "AABBTree/Float3SOA8", "QuadTree/Float3SOA4"}) {
      std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout), m.name);
      std::vector<Hit> plain(rays.size());
      trace_with_triangle_test(BlobView(blob, m.name), TriangleTest::MollerTrumbore, rays, plain);
      Agreement a = compare(*m.mesh, rays, plain, oracle_answers(m, RayKind::Long, rays), 1e-5 * m.mesh->bounds().diagonal());
      EXPECT_LE(a.wrong + a.t_errors, 2u) << layout << " on " << m.name << ": " << a.first_problem;
      EXPECT_GT(rays.size() - misses(plain), rays.size() / 10) << layout << " on " << m.name;
    }
  }
}

// They walk the plain test indeed, and the library's walkers the watertight
// one alone: rays aimed at a closed sphere's shared edges and vertices leak
// through the former and never through the latter, on the layouts the
// benchmark compares and the AABBTree family's depth-first-index variant.
// The plain walkers exist for those trees alone; any other is refused,
// naming its layout. Pair blocks have no plain test.
TEST(TriangleTests, OnlyTheMollerTrumboreWalkersLeak) {
  const Mesh sphere = make_sphere(48, 96, 1.0f, {0, 0, 0});
  const std::vector<Ray> rays = sphere_probes(sphere);
  for (const char* layout : {"AABBTree/Float3", "AABBTree/Float3SOA8", "AABBTreePNS/Float3SOA4", "QuadTree/Float3SOA4",
                             "QuadTreeHalfFloat/Indexed8BitPackSOA4"}) {
    const std::vector<uint8_t> blob = build_blob(sphere, parse_layout(layout), "probe sphere");
    const BlobView view(blob, "probe sphere");
    std::vector<Hit> library(rays.size()), watertight(rays.size()), plain(rays.size());
    view.trace(rays, library);
    trace_with_triangle_test(view, TriangleTest::Watertight, rays, watertight);
    trace_with_triangle_test(view, TriangleTest::MollerTrumbore, rays, plain);
    EXPECT_EQ(misses(library), 0u) << layout;
    EXPECT_EQ(misses(watertight), 0u) << layout;
    EXPECT_GT(misses(plain), 0u) << layout;
  }
  const std::vector<uint8_t> blob = build_blob(sphere, parse_layout("OctTreeCompressed/Float3SOA8"), "probe sphere");
  std::vector<Hit> plain(rays.size());
  try {
    trace_with_triangle_test(BlobView(blob, "probe sphere"), TriangleTest::MollerTrumbore, rays, plain);
    ADD_FAILURE() << "a tree without plain-test walkers was walked";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("OctTreeCompressed/Float3SOA8"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace meshcast::testing
