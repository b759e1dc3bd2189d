// The oracle itself: analytic cases, ties, and the tree oracle against brute
// force.
#include <gtest/gtest.h>

#include "check/oracle.h"
#include "check/scene_oracle.h"
#include "check/generate.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

Mesh one_triangle() {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  return m;
}

TEST(Oracle, AnalyticHitBothFaces) {
  Mesh m = one_triangle();
  Ray down{{0.25f, 0.25f, 2.0f}, {0, 0, -1}, INFINITY};
  Ray up{{0.25f, 0.25f, -3.0f}, {0, 0, 2}, INFINITY};
  EXPECT_DOUBLE_EQ(oracle_brute_force(m, down).t, 2.0);
  EXPECT_DOUBLE_EQ(oracle_brute_force(m, up).t, 1.5);  // t in units of the direction
  Ray miss{{0.75f, 0.75f, 2.0f}, {0, 0, -1}, INFINITY};
  EXPECT_EQ(oracle_brute_force(m, miss).triangle, MC_NO_HIT);
}

TEST(Oracle, TMaxIsInclusiveAndOriginOnSurfaceHitsAtZero) {
  Mesh m = one_triangle();
  Ray exact{{0.25f, 0.25f, 2.0f}, {0, 0, -1}, 2.0f};
  EXPECT_EQ(oracle_brute_force(m, exact).triangle, 0u);
  Ray short_{{0.25f, 0.25f, 2.0f}, {0, 0, -1}, 1.999f};
  EXPECT_EQ(oracle_brute_force(m, short_).triangle, MC_NO_HIT);
  Ray on{{0.25f, 0.25f, 0.0f}, {0, 0, -1}, 0.0f};
  EXPECT_DOUBLE_EQ(oracle_brute_force(m, on).t, 0.0);
}

// t_min, included as t_max is: a hit needs t_min <= t <= t_max. Past t_min
// the next triangle along is the answer (brute force and tree alike, and
// every hit's set starts there); a NaN, negative or inverted t_min is a
// ray the walkers refuse, a miss.
TEST(Oracle, TMinIsInclusiveAndSkipsWhatLiesBefore) {
  Mesh m = one_triangle();
  m.vertices.push_back({0, 0, -1}), m.vertices.push_back({1, 0, -1}), m.vertices.push_back({0, 1, -1});
  m.triangles.push_back({3, 4, 5});  // the same triangle 1 below
  const OracleTree tree(m);
  auto closest = [&](float tmin, float tmax) {
    const Ray r{{0.25f, 0.25f, 2.0f}, {0, 0, -1}, tmax, tmin};
    const OracleHit brute = oracle_brute_force(m, r), walked = tree.closest(r);
    EXPECT_EQ(brute.triangle, walked.triangle) << tmin;
    EXPECT_EQ(brute.t, walked.t) << tmin;
    return brute;
  };
  EXPECT_EQ(closest(2.0f, INFINITY).triangle, 0u);  // exactly at t_min: hit
  EXPECT_EQ(closest(2.0f, INFINITY).t, 2.0);
  EXPECT_EQ(closest(2.001f, INFINITY).triangle, 1u);  // past the first: the next
  EXPECT_EQ(closest(2.001f, INFINITY).t, 3.0);
  EXPECT_EQ(closest(3.0f, 3.0f).triangle, 1u);  // t_min = t_max = the hit's t
  EXPECT_EQ(closest(2.5f, 2.9f).triangle, MC_NO_HIT);
  EXPECT_EQ(closest(3.001f, INFINITY).triangle, MC_NO_HIT);
  for (float bad : {NAN, -0.5f, 5.0f})  // 5: past t_max 4
    EXPECT_EQ(closest(bad, 4.0f).triangle, MC_NO_HIT) << bad;
  const std::vector<OracleHit> all = tree.all({{0.25f, 0.25f, 2.0f}, {0, 0, -1}, INFINITY, 2.5f});
  ASSERT_EQ(all.size(), 1u);
  EXPECT_EQ(all[0].triangle, 1u);
  // The scene oracle, origins in double, by the same rule.
  const SceneOracle scene({&m}, {OracleInstance{7, 0, Transform{}}});
  const RayD far_down{{0.25, 0.25, 2.0}, {0, 0, -1}, INFINITY, 2.001f};
  EXPECT_EQ(scene.closest(far_down).triangle, 1u);
  EXPECT_EQ(scene.closest(far_down).t, 3.0);
  EXPECT_EQ(scene.all(far_down).size(), 1u);
  EXPECT_EQ(scene.closest({{0.25, 0.25, 2.0}, {0, 0, -1}, 1.0f, 2.0f}).instance, kNoHit);  // t_min past t_max
  EXPECT_EQ(scene.closest({{0.25, 0.25, 2.0}, {0, 0, -1}, INFINITY, NAN}).instance, kNoHit);
}

TEST(Oracle, SharedEdgeAndVertexNeverLeak) {
  Mesh grid = make_grid_plane(4, 4);
  for (float x = 0.5f; x <= 3.5f; x += 0.5f)
    for (float y = 0.5f; y <= 3.5f; y += 0.5f) {
      Ray r{{x, y, 1.0f}, {0, 0, -1}, INFINITY};
      OracleHit h = oracle_brute_force(grid, r);
      ASSERT_NE(h.triangle, MC_NO_HIT) << x << "," << y;
      EXPECT_DOUBLE_EQ(h.t, 1.0);
    }
}

TEST(Oracle, TiesGoToTheLowestIndex) {
  Mesh m = one_triangle();
  m.triangles.push_back({2, 1, 0});  // the same triangle again, other winding
  m.triangles.push_back({0, 1, 2});
  Ray r{{0.2f, 0.2f, 1.0f}, {0, 0, -1}, INFINITY};
  EXPECT_EQ(oracle_brute_force(m, r).triangle, 0u);
  OracleTree tree(m);
  EXPECT_EQ(tree.closest(r).triangle, 0u);
}

TEST(Oracle, DegenerateTrianglesAreNeverHit) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 0, 0}};
  m.triangles = {{0, 1, 2}, {0, 3, 1}};
  Ray r{{1.0f, 0.0f, 1.0f}, {0, 0, -1}, INFINITY};
  EXPECT_EQ(oracle_brute_force(m, r).triangle, MC_NO_HIT);
}

// The judge (check/agreement.h): a walker's miss where the oracle hits is
// wrong in the middle of a triangle, a tie only within float rounding of
// its edge (a grazed silhouette, decided by rounding either way).
TEST(Agreement, AMissIsWrongUnlessWithinRoundingOfAnEdge) {
  Mesh m = one_triangle();
  std::vector<Ray> rays = {{{0.25f, 0.25f, 1.0f}, {0, 0, -1}, INFINITY},   // the middle
                           {{0.5f, 1e-3f, 1.0f}, {0, 0, -1}, INFINITY},    // near the edge, far beyond rounding
                           {{0.5f, 1e-9f, 1.0f}, {0, 0, -1}, INFINITY}};   // within rounding of the edge y = 0
  std::vector<OracleHit> oracle;
  for (const Ray& r : rays) oracle.push_back(oracle_brute_force(m, r));
  for (const OracleHit& o : oracle) ASSERT_EQ(o.triangle, 0u);
  std::vector<Hit> misses(rays.size());
  Agreement a = compare(m, rays, misses, oracle, 1e-5 * m.bounds().diagonal());
  EXPECT_EQ(a.wrong, 2u);
  EXPECT_EQ(a.ties, 1u);
}

TEST(Oracle, TreeAgreesWithBruteForce) {
  std::vector<NamedMesh> meshes = test_meshes(false);
  for (const NamedMesh& m : meshes) {
    OracleTree tree(*m.mesh);
    for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
      std::vector<Ray> rays = make_rays(*m.mesh, kind, m.mesh->triangles.size() > 20000 ? 300 : 1500, 77);
      for (size_t i = 0; i < rays.size(); ++i) {
        OracleHit a = tree.closest(rays[i]), b = oracle_brute_force(*m.mesh, rays[i]);
        ASSERT_EQ(a.triangle, b.triangle) << m.name << " ray " << i;
        if (a.triangle != MC_NO_HIT) {
          ASSERT_EQ(a.t, b.t);
        }
      }
    }
  }
}

}  // namespace
}  // namespace meshcast::testing
