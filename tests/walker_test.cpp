// Every layout against the double-precision oracle, on the generated meshes
// and the public ones, 10,000 rays of each kind.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <random>

#include "check/generate.h"
#include "layout/blob_format.h"
#include "layout/tree/leaves.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

class WalkerVsOracle : public ::testing::TestWithParam<std::string> {};

// The queries besides the closest hit on the first tenth of
// a ray set: closest and any hit with a face culled (the back faces on
// long rays, the front faces on probe and radial rays, which start inside
// closed meshes and see back faces there), and every hit, culled on long
// rays. Each against the oracle over `reference` with the same culling.
// The queries (testing's check_queries) on a tenth of the rays, and again
// with a t_min (check_t_min_queries).
void check_queries(const BlobView& blob, const NamedMesh& reference, RayKind kind,
                   const std::vector<Ray>& rays, double tolerance, const std::string& what) {
  const std::vector<Ray> part(rays.begin(), rays.begin() + std::ptrdiff_t(rays.size() / 10));
  const QueryTracer cpu{[&](const std::vector<Ray>& r, Query q, Cull c) { return trace_all(blob, r, q, c); },
                        [&](const std::vector<Ray>& r, uint32_t max_hits, Cull c) { return trace_lists(blob, r, max_hits, c); }};
  testing::check_queries(cpu, reference, kind, part, tolerance, 256, what);
  testing::check_t_min_queries(cpu, reference, kind, part, tolerance, 256, what);
}

// Every node's box, as the walker decodes it (half floats, 7-bit codes,
// SKD regions included), contains every corner its triangle format decodes
// below it. Checked on the blob check_layout walks: building every layout
// for every mesh once more took 40 s of the Release run.
void check_node_bounds(const std::vector<uint8_t>& blob, const std::string& name, const NamedMesh& m) {
  const layout::BlobHeader& h = layout::header_of(blob.data());
  size_t corners = 0;
  layout::for_each_leaf_path(blob.data(), [&](uint32_t block, uint32_t count, const std::vector<layout::PathBox>& path) {
    ASSERT_FALSE(path.empty()) << name << " on " << m.name << ": a leaf with no box above it";
    for (uint32_t i = 0; i < count; ++i) {
      float v[3][3];
      layout::decode_triangle(blob.data(), h.tree_offset + block, i, v);
      for (int c = 0; c < 3; ++c, ++corners)
        for (const layout::PathBox& b : path)
          for (int a = 0; a < 3; ++a)
            ASSERT_TRUE(b.min[a] <= v[c][a] && v[c][a] <= b.max[a])
                << name << " on " << m.name << ": corner outside a box above it (depth " << (&b - path.data()) << ")";
    }
  });
  EXPECT_EQ(corners, 3 * m.mesh->triangles.size()) << name << " on " << m.name;
}

// Every triangle format keeps each stored corner within its stated bound of
// the input vertex (0 for the float formats: stored exactly), checked on the
// decoded blob against the input mesh (a triangle format is the same
// encoder under every tree: the QuadTree and BruteForce layouts cover them).
void check_stored_corners(const std::vector<uint8_t>& blob, const std::string& name, const NamedMesh& m) {
  float bound[3];
  displacement_bound(blob, bound);
  Box3 box = m.mesh->bounds();
  for (int a = 0; a < 3; ++a)  // small: a few 2^-21 of the extent at most
    EXPECT_LE(bound[a], (box.max[a] - box.min[a]) * 0x1p-15f + std::fabs(box.max[a]) * 0x1p-22f + 1e-37f) << name;
  Mesh stored = stored_mesh(blob);
  // Stored corners are the input corners within the bound, in the same
  // order or (strips, pair blocks) a rotation of it: the winding is kept.
  auto near = [&](size_t t, int c, int k) {
    for (int a = 0; a < 3; ++a)
      if (!(std::fabs(double(stored.corner(t, c)[a]) - m.mesh->corner(t, k)[a]) <= bound[a])) return false;
    return true;
  };
  bool rotates = name.find("Strip") != std::string::npos || name.find("PairSOA4") != std::string::npos;
  for (size_t t = 0; t < m.mesh->triangles.size(); ++t) {
    int found = -1;
    for (int rot = 0; rot < (rotates ? 3 : 1) && found < 0; ++rot)
      if (near(t, 0, rot) && near(t, 1, (rot + 1) % 3) && near(t, 2, (rot + 2) % 3)) found = rot;
    ASSERT_GE(found, 0) << name << " on " << m.name << ", triangle " << t << " not the input's corners in order";
  }
}

void check_layout(const std::string& layout_name_, bool large) {
  BuildOptions options = parse_layout(layout_name_);
  static const std::vector<std::string> covering_names = covering_layouts(layout_names());
  const bool covering = std::find(covering_names.begin(), covering_names.end(), layout_name_) != covering_names.end();
  static const std::vector<std::string> few = covering_subset(layout_names());
  const bool one_of_few = std::find(few.begin(), few.end(), layout_name_) != few.end();
  const bool brute = uint32_t(options.layout.tree) == MC_TREE_BRUTEFORCE;
  for (const NamedMesh& m : test_meshes(large)) {
    if (large && m.name != "terrain_1M") continue;
    // The three largest public meshes (more than half the triangles of the
    // set, scanned surfaces as ChineseDragon-10kv is) on the layouts that
    // cover every tree and triangle format alone: building every layout on
    // them was most of this suite's time, the builds more than the walks
    // (and the brute force's walks took half of its own 160 s on them);
    // bunny00 alone was 44% of the triangles the other layouts built.
    if (!one_of_few && (m.name == "armadillo" || m.name == "refined_elephant" || m.name == "bunny00")) continue;
    std::vector<uint8_t> blob = build_blob(*m.mesh, options, m.name);
    // The view validates the blob (an InputError with the reason fails the test).
    const BlobView view(blob, m.name);
    if (!large) {
      // The largest public meshes take long to decode corner by corner; bunny00 and the dragon suffice.
      if (!brute && m.name != "armadillo" && m.name != "refined_elephant") check_node_bounds(blob, layout_name_, m);
      if (brute || layout_name_.rfind("QuadTree/", 0) == 0) check_stored_corners(blob, layout_name_, m);
    }
    double diag = m.mesh->bounds().diagonal();
    double tolerance = 1e-5 * diag;
    // Bit-packed formats walk the quantized mesh: the oracle over that mesh
    // gives the exact answers; the distance to the input mesh is checked
    // against the stated bound separately (QuantizedVerticesWithinBound).
    NamedMesh reference = m;
    if (moves_vertices(uint32_t(options.layout.triangles)))
      reference = {m.name + "#" + layout_name_, std::make_shared<const Mesh>(stored_mesh(blob))};
    // BruteForce tests every triangle for every ray: fewer rays keep it quick
    // (its 20 triangle formats at 400 rays were half of this suite's time,
    // every format's decode and test also walked under the trees below).
    // 2,000 a kind in Release on the layouts that take every tree and
    // triangle format between them (`few`), 1,000 on the others and in the
    // quick runs: this suite is the largest share of the Release stage
    // (10,000, then 5,000 and 3,000, took the whole test run past CI's 30
    // minutes), and every layout on every mesh and ray kind is what it
    // covers, not more rays of each: a pairing of a tree and a triangle
    // format is code of each, all of it walked at 2,000 on `few`.
    size_t count = brute ? 200 : quick() || !one_of_few ? 1000 : 2000;
    for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial, RayKind::Segment}) {
      // Line-of-sight segments: on the layouts that cover every tree and
      // triangle format, which is every walker's code, and fewer of them
      // (the oracle's double-precision walk is most of this test's time).
      if (kind == RayKind::Segment && !one_of_few) continue;
      const size_t kind_count = kind == RayKind::Segment ? std::min<size_t>(count, 1000) : count;
      const std::vector<Ray>& rays = test_rays(m, kind, kind_count);
      const std::vector<OracleHit>& oracle = oracle_answers(reference, kind, rays);
      std::vector<Hit> hits = trace_all(view, rays);
      Agreement a = compare(*reference.mesh, rays, hits, oracle, tolerance);
      EXPECT_EQ(a.wrong, 0u) << layout_name_ << " on " << m.name << " kind " << int(kind) << ": " << a.first_problem;
      EXPECT_EQ(a.t_errors + a.t_rounding, 0u) << layout_name_ << " on " << m.name << " kind " << int(kind) << ": "
                                << a.first_problem;
      size_t hit_count = 0;
      for (const Hit& h : hits) hit_count += h.triangle != MC_NO_HIT;
      // A ray set that never hits proves nothing: every kind must hit often.
      EXPECT_GT(hit_count, rays.size() / 20) << m.name << " kind " << int(kind);
      EXPECT_EQ(a.rays, kind_count);
      // The other queries: in the quick runs on the covering layouts only.
      if (quick() && !covering) continue;
      check_queries(view, reference, kind, rays, tolerance,
                    layout_name_ + " on " + m.name + " kind " + std::to_string(int(kind)));
      // Query::Any on the same rays: the oracle's hit/miss, and each hit a
      // triangle the ray hits in double at that t.
      std::vector<Hit> any = trace_all(view, rays, Query::Any);
      Agreement b = compare_any(*reference.mesh, rays, any, oracle, tolerance);
      EXPECT_EQ(b.wrong + b.t_errors + b.t_rounding, 0u) << layout_name_ << " on " << m.name << " kind " << int(kind)
                                          << ", Query::Any: " << b.first_problem;
      size_t any_count = 0;
      for (const Hit& h : any) any_count += h.triangle != MC_NO_HIT;
      EXPECT_EQ(any_count, hit_count) << layout_name_ << " on " << m.name << " kind " << int(kind) << ", Query::Any";
    }
  }
}

// Every layout in Release; in the quick runs (the sanitizer build, the
// other instruction sets) the layouts that take every tree and triangle
// format: each walker's node code and each codec's leaf code run there,
// while every pairing of them is Release's (and the fuzz targets walk
// every layout under the sanitizers again). Every layout in the quick
// runs was half of the sanitizer stage's suites.
TEST_P(WalkerVsOracle, AllMeshesAllRayKinds) {
  static const std::vector<std::string> covering = covering_layouts(layout_names());
  if (std::find(covering.begin(), covering.end(), GetParam()) == covering.end())
    GTEST_SKIP() << "the quick runs walk the covering layouts alone";
  check_layout(GetParam(), false);
}

// Mistakes (wrong triangle or t) of `blob`, built from m with `o`, on
// `count` rays of `kind`, against the oracle over what the blob stores;
// `variant` names the build in the oracle's cache.
uint64_t oracle_mistakes(const std::vector<uint8_t>& blob, const NamedMesh& m, const BuildOptions& o,
                         const std::string& variant, RayKind kind, size_t count, std::string* problem) {
  NamedMesh reference = m;
  if (moves_vertices(uint32_t(o.layout.triangles)))
    reference = {m.name + "#" + variant, std::make_shared<const Mesh>(stored_mesh(blob))};
  const std::vector<Ray>& rays = test_rays(m, kind, count);
  Agreement a = compare(*reference.mesh, rays, trace_all(blob, rays), oracle_answers(reference, kind, rays),
                        1e-5 * m.mesh->bounds().diagonal());
  *problem = a.first_problem;
  return a.wrong + a.t_errors + a.t_rounding;
}

// Every splitter's trees walk to the oracle's answers.
TEST(WalkerVsOracleSplitters, EverySplitterOnTheFoundationLayouts) {
  for (Splitter s : all_splitters())
    for (const NamedMesh& m : test_meshes(false)) {
      if (m.name != "sphere" && m.name != "terrain_64k" && !is_chosen_public_mesh(m.name)) continue;
      for (const char* name : {"AABBTree/Float3", "QuadTreeHalfFloat/Indexed8BitPackSOA4"}) {
        BuildOptions o = parse_layout(name);
        o.splitter = s;
        std::vector<uint8_t> blob = build_blob(*m.mesh, o, m.name);
        std::string variant = std::string(name) + "#" + splitter_name(s), problem;
        EXPECT_EQ(oracle_mistakes(blob, m, o, variant, RayKind::Long, 2000, &problem), 0u) << variant << " on " << m.name << ": " << problem;
      }
    }
}

// The four node orders of seed 000 §4.3 on the quad trees: same answers, and
// the blocks where each order puts them.
TEST(WalkerVsOracleNodeOrders, EveryOrderOnTheQuadTrees) {
  for (NodeOrder order : all_node_orders())
    for (const NamedMesh& m : test_meshes(false)) {
      if (m.name != "sphere" && m.name != "terrain_64k" && !is_chosen_public_mesh(m.name)) continue;
      for (const char* name : {"QuadTree/Float3", "QuadTreeHalfFloat/Indexed8BitPackSOA4"}) {
        BuildOptions o = parse_layout(name);
        o.node_order = order;
        std::vector<uint8_t> blob = build_blob(*m.mesh, o, m.name);
        ASSERT_EQ(layout::validate(blob), "") << name << " " << node_order_name(order);
        const layout::BlobHeader& h = layout::header_of(blob.data());
        const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
        uint32_t lowest_block = ~0u;
        layout::for_each_leaf(blob.data(), [&](uint32_t block, uint32_t) { lowest_block = std::min(lowest_block, block); });
        if (last) EXPECT_EQ(lowest_block, h.node_bytes) << name << " " << node_order_name(order);
        else EXPECT_LT(lowest_block, h.node_bytes) << name << " " << node_order_name(order);
        std::string variant = std::string(name) + "#" + node_order_name(order), problem;
        EXPECT_EQ(oracle_mistakes(blob, m, o, variant, RayKind::Long, 2000, &problem), 0u) << variant << " on " << m.name << ": " << problem;
      }
    }
}

// StacklessLBVH walked left first (the seed) and nearer first give the same
// answers; so does a tight depth limit, which forces median splits.
TEST(WalkerVsOracleLBVH, LeftFirstNearFirstAndDepthLimits) {
  for (const NamedMesh& m : test_meshes(false)) {
    if (m.name != "sphere" && !is_chosen_public_mesh(m.name)) continue;
    for (int variant = 0; variant < 3; ++variant) {
      BuildOptions o = parse_layout("StacklessLBVH/Float3");
      o.lbvh_near_first = variant != 1;
      if (variant == 2) o.lbvh_depth = uint32_t(std::bit_width(m.mesh->triangles.size() / 31)) + 1;
      std::vector<uint8_t> blob = build_blob(*m.mesh, o, m.name);
      ASSERT_EQ(layout::validate(blob), "");
      if (variant == 2) {
        EXPECT_LT(layout::header_of(blob.data()).max_depth, o.lbvh_depth);
      }
      std::string problem;
      EXPECT_EQ(oracle_mistakes(blob, m, o, "lbvh", RayKind::Radial, 3000, &problem), 0u)
          << "variant " << variant << " on " << m.name << ": " << problem;
    }
  }
}

// CTest points MESHCAST_DATA at data/ (scripts/setup.sh fills it): there the
// public meshes must be present, so they can never drop out silently.
TEST(Data, PublicMeshesArePresentWhenCTestRuns) {
  if (!std::getenv("MESHCAST_DATA")) GTEST_SKIP() << "MESHCAST_DATA not set (not run by CTest)";
  for (const char* name : {"bunny00", "armadillo", "refined_elephant", "ChineseDragon-10kv"})
    EXPECT_TRUE(data_mesh(name).has_value()) << name << ".off missing under " << std::getenv("MESHCAST_DATA");
}

INSTANTIATE_TEST_SUITE_P(Layouts, WalkerVsOracle, ::testing::ValuesIn(layout_names()),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '/') c = '_';
                           return n;
                         });

// The layouts of the foundation issue and every tree with Float3 on the
// 1M-triangle terrain.
TEST(WalkerVsOracleLarge, Terrain1M) {
  if (quick()) GTEST_SKIP() << "large scenes: the Release run walks them";
  for (const char* name : {"AABBTree/Float3", "QuadTree/Float3SOA4", "QuadTreeHalfFloat/Indexed8BitPackSOA4",
                           "AABBTreeSplitAxis/Float3", "AABBTreePNS/Float3", "AABBTreeCompressed/Float3",
                           "SKDTree/Float3", "StacklessLBVH/Float3"})
    check_layout(name, true);
}

// Seed 000 6: the source's AABBTreePNS ran out of offset bits on its
// 2,264,303-triangle scene. This one holds a larger terrain and walks it.
TEST(WalkerVsOracleLarge, PNSHoldsTheSourcesLargestScene) {
  if (quick()) GTEST_SKIP() << "large scenes: the Release run walks them";
  Mesh terrain = make_terrain(1088, 1056, 13);  // 2,297,856 triangles
  ASSERT_GT(terrain.triangles.size(), 2264303u);
  std::vector<uint8_t> blob = build_blob(terrain, parse_layout("AABBTreePNS/Float3"), "terrain_2.3M");
  ASSERT_EQ(layout::validate(blob), "");
  std::vector<Ray> rays = make_rays(terrain, RayKind::Long, 2000, 5);
  OracleTree oracle(terrain);
  std::vector<OracleHit> answers;
  for (const Ray& r : rays) answers.push_back(oracle.closest(r));
  Agreement a = compare(terrain, rays, trace_all(blob, rays), answers, 1e-5 * terrain.bounds().diagonal());
  EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << a.first_problem;
}

}  // namespace
}  // namespace meshcast::testing

// The test counters (cpu/counters.h), in a counting build: the brute force
// tests every triangle of every ray and no box; a tree tests boxes and far
// fewer triangles. Skipped in builds without MESHCAST_COUNT_TESTS.
namespace meshcast::testing {
namespace {
TEST(Counters, CountEveryBoxAndTriangleTest) {
  if constexpr (!kCountTests) GTEST_SKIP() << "built without MESHCAST_COUNT_TESTS";
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  NamedMesh named{"counted_sphere", std::make_shared<const Mesh>(m)};
  const std::vector<Ray>& rays = test_rays(named, RayKind::Radial, 500);
  test_counts = {};
  trace_all(build_blob(m, parse_layout("BruteForce/Float3"), "sphere"), rays);
  EXPECT_EQ(test_counts.triangles, rays.size() * m.triangles.size());
  EXPECT_EQ(test_counts.boxes, 0u);
  test_counts = {};
  trace_all(build_blob(m, parse_layout("AABBTree/Float3"), "sphere"), rays);
  EXPECT_GT(test_counts.boxes, rays.size());
  EXPECT_GT(test_counts.triangles, 0u);
  EXPECT_LT(test_counts.triangles, rays.size() * m.triangles.size() / 4);
}

// Query::Any stops at its first hit on every walker: never more box or
// triangle tests than the closest hit on the same rays, and fewer in all.
// Rays from the centre of a sphere start inside every box around it, which
// the closest hit must all enter and an any-query leaves after one hit.
TEST(Counters, AnyStopsAtItsFirstHit) {
  if constexpr (!kCountTests) GTEST_SKIP() << "built without MESHCAST_COUNT_TESTS";
  Mesh m = make_sphere(16, 32, 1, {0, 0, 0});
  NamedMesh named{"counted_sphere", std::make_shared<const Mesh>(m)};
  const std::vector<Ray>& rays = test_rays(named, RayKind::Radial, 200);
  for (const std::string& name : quick() ? covering_layouts(layout_names()) : layout_names()) {
    std::vector<uint8_t> blob = build_blob(m, parse_layout(name), "sphere");
    test_counts = {};
    trace_all(blob, rays);
    const TestCounts closest = test_counts;
    test_counts = {};
    trace_all(blob, rays, nullptr, 0, Query::Any);
    EXPECT_LE(test_counts.boxes, closest.boxes) << name;
    EXPECT_LE(test_counts.triangles, closest.triangles) << name;
    EXPECT_LT(test_counts.boxes + test_counts.triangles, closest.boxes + closest.triangles) << name;
  }
}
}  // namespace
}  // namespace meshcast::testing

// Culling's definition, judged apart from the walkers' determinant: in a
// soup of random triangles, a query culling back faces finds exactly the
// two-sided hits whose triangle's corners run counter-clockwise seen from
// the ray's origin (dot((b - a) x (c - a), o - a) > 0, in double), culling
// front faces exactly the others, on every layout (covering ones in quick
// runs); the closest culled hit is the first of its set.
namespace meshcast::testing {
namespace {
TEST(Culling, KeepsTheFaceSeenCounterClockwiseFromTheOrigin) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  Mesh soup;
  for (uint32_t t = 0; t < 300; ++t) {
    const Vec3 centre{u(rng), u(rng), u(rng)};
    for (int c = 0; c < 3; ++c)
      soup.vertices.push_back({centre.x + 0.3f * u(rng), centre.y + 0.3f * u(rng), centre.z + 0.3f * u(rng)});
    soup.triangles.push_back({3 * t, 3 * t + 1, 3 * t + 2});
  }
  std::vector<Ray> rays;
  for (int i = 0; i < 1000; ++i)
    rays.push_back({{2 * u(rng), 2 * u(rng), 2 * u(rng)}, {u(rng), u(rng), u(rng)}, INFINITY});
  // +1 front, -1 back; 0 for a ray within 1e-3 of the triangle's plane
  // (by angle), where the quantized formats' rounding may turn the face.
  auto facing = [&](const Ray& r, uint32_t t) {
    const Vec3 a = soup.corner(t, 0), b = soup.corner(t, 1), c = soup.corner(t, 2);
    double e1[3], e2[3], o[3];
    for (int k = 0; k < 3; ++k) e1[k] = double(b[k]) - a[k], e2[k] = double(c[k]) - a[k], o[k] = double(r.org[k]) - a[k];
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double dot = n[0] * o[0] + n[1] * o[1] + n[2] * o[2];
    const double norms = std::sqrt((n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) * (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]));
    return std::fabs(dot) < 1e-3 * norms ? 0 : dot > 0 ? 1 : -1;
  };
  for (const std::string& name : quick() ? covering_layouts(layout_names()) : layout_names()) {
    const BuildOptions options = parse_layout(name);
    std::vector<uint8_t> blob = build_blob(soup, options, "soup");
    if (!layout::has_remap(layout::header_of(blob.data()))) continue;  // hits would name slots
    const BlobView view(blob, name);
    const HitLists both = trace_lists(view, rays, 64);
    size_t kept[2] = {0, 0};
    for (Cull cull : {Cull::Back, Cull::Front}) {
      const HitLists culled = trace_lists(view, rays, 64, cull);
      const std::vector<Hit> closest = trace_all(view, rays, Query::Closest, cull);
      for (size_t i = 0; i < rays.size(); ++i) {
        std::vector<uint32_t> expected, got;
        bool unsure = false;
        for (const Hit& h : both.row(i)) {
          const int f = facing(rays[i], h.triangle);
          unsure = unsure || f == 0;
          if (f == (cull == Cull::Back ? 1 : -1)) expected.push_back(h.triangle);
        }
        if (unsure) continue;
        for (const Hit& h : culled.row(i)) got.push_back(h.triangle);
        ASSERT_EQ(got, expected) << name << ", ray " << i << ", cull " << int(cull);
        kept[cull == Cull::Front] += got.size();
        ASSERT_EQ(closest[i].triangle, got.empty() ? MC_NO_HIT : got[0]) << name << ", ray " << i;
      }
    }
    EXPECT_GT(kept[0], 100u) << name;
    EXPECT_GT(kept[1], 100u) << name;
  }
}
}  // namespace
}  // namespace meshcast::testing

// Rows shorter than the hits: 12 stacked planes, rows of 1, 3
// and 12, on every layout (covering ones in quick runs): each row the
// nearest of the oracle's set, the count all of them.
namespace meshcast::testing {
namespace {
TEST(EveryHit, RowsKeepTheNearestAndCountAll) {
  const Mesh planes = stacked_planes(12);
  const std::vector<Ray> rays = rays_down_through(12, 300);
  for (const std::string& name : quick() ? covering_layouts(layout_names()) : layout_names()) {
    const BuildOptions options = parse_layout(name);
    const std::vector<uint8_t> blob = build_blob(planes, options, "planes");
    const layout::BlobHeader& h = layout::header_of(blob.data());
    const Mesh stored = moves_vertices(h.triangle_format) || !layout::has_remap(h) ? stored_mesh(blob) : planes;
    const BlobView view(blob, name);
    for (uint32_t max_hits : {1u, 3u, 12u})
      expect_nearest_rows(stored, rays, trace_lists(view, rays, max_hits), name + ", rows of " + std::to_string(max_hits));
  }
}
}  // namespace
}  // namespace meshcast::testing

// Rows at the limit (kMaxHitsLimit hits a ray) are compact: they hold the
// hits found alone, so their memory follows the hits, not rays x max_hits
// (2,000 such rows were 229 MB of mostly misses), and each row is the one
// rows of 3 keep, extended. Rays through all 12 planes, rays cut short
// between planes and rays aimed away (misses), on the covering layouts.
namespace meshcast::testing {
namespace {
TEST(EveryHit, RowsAtTheLimitHoldTheHitsFoundAlone) {
  constexpr int kPlanes = 12;
  const Mesh planes = stacked_planes(kPlanes);
  std::vector<Ray> rays = rays_down_through(kPlanes, 2000);
  for (size_t i = 0; i < rays.size(); ++i) {
    if (i % 4 == 1) rays[i].tmax = float(i % kPlanes) + 0.5f;  // the planes within t_max alone
    if (i % 4 == 2) rays[i].dir[2] = 1;                          // up, away from every plane
  }
  for (const std::string& name : covering_layouts(layout_names())) {
    const std::vector<uint8_t> blob = build_blob(planes, parse_layout(name), "planes");
    const layout::BlobHeader& h = layout::header_of(blob.data());
    const Mesh stored = moves_vertices(h.triangle_format) || !layout::has_remap(h) ? stored_mesh(blob) : planes;
    const BlobView view(blob, name);
    const HitLists every = trace_lists(view, rays, kMaxHitsLimit), few = trace_lists(view, rays, 3);
    ASSERT_EQ(every.found.size(), rays.size()) << name;
    size_t kept = 0;
    for (uint32_t found : every.found) kept += std::min(found, kMaxHitsLimit);
    ASSERT_GT(kept, rays.size()) << name << ": too few hits to show anything";
    ASSERT_EQ(every.hits.size(), kept) << name << ": the rows hold more than the hits found";
    EXPECT_LE(every.hits.capacity(), 2 * kept + kMaxHitsLimit) << name;
    expect_nearest_rows(stored, rays, every, name + ", rows of " + std::to_string(kMaxHitsLimit));
    for (size_t i = 0; i < rays.size(); ++i) {
      ASSERT_EQ(few.found[i], every.found[i]) << name << ", ray " << i;
      ASSERT_EQ(few.row(i).size(), std::min(every.found[i], 3u)) << name << ", ray " << i;
      for (size_t k = 0; k < few.row(i).size(); ++k) {
        EXPECT_EQ(few.row(i)[k].triangle, every.row(i)[k].triangle) << name << ", ray " << i << ", record " << k;
        EXPECT_EQ(few.row(i)[k].t, every.row(i)[k].t) << name << ", ray " << i << ", record " << k;
      }
    }
  }
}
}  // namespace
}  // namespace meshcast::testing

// t_min on every layout, with answers known without the oracle: rays
// straight down through 12 stacked planes (a hit each at t = 13 - z) with
// t_min half way between two planes find the plane just past it first,
// and Query::All's rows hold the planes from there on alone; any hit lies
// in [t_min, t_max]. The rows against the oracle's sets too.
namespace meshcast::testing {
namespace {
TEST(TMin, HitsBeforeItAreSkippedOnEveryQuery) {
  constexpr int kPlanes = 12;
  const Mesh planes = stacked_planes(kPlanes);
  std::vector<Ray> rays = rays_down_through(kPlanes, 240);
  for (size_t i = 0; i < rays.size(); ++i) rays[i].tmin = float(i % (kPlanes + 1)) + 1.5f;  // 1.5 .. 13.5
  for (const std::string& name : covering_layouts(layout_names())) {
    const std::vector<uint8_t> blob = build_blob(planes, parse_layout(name), "planes");
    const layout::BlobHeader& h = layout::header_of(blob.data());
    const Mesh stored = moves_vertices(h.triangle_format) || !layout::has_remap(h) ? stored_mesh(blob) : planes;
    const BlobView view(blob, name);
    const std::vector<Hit> closest = trace_all(view, rays), any = trace_all(view, rays, Query::Any);
    const HitLists rows = trace_lists(view, rays, kPlanes);
    for (size_t i = 0; i < rays.size(); ++i) {
      // The planes at t = 2 .. 13; the first at or past t_min is at ceil(t_min).
      const int first_t = int(std::ceil(rays[i].tmin));
      const std::string what = name + ", ray " + std::to_string(i) + ", t_min " + std::to_string(rays[i].tmin);
      if (first_t > kPlanes + 1) {
        EXPECT_EQ(closest[i].triangle, MC_NO_HIT) << what;
        EXPECT_EQ(any[i].triangle, MC_NO_HIT) << what;
      } else {
        EXPECT_NEAR(closest[i].t, first_t, 1e-5) << what;
        if (closest[i].triangle != MC_NO_HIT) {  // on the plane z = 13 - t (as stored: quantized formats move it a little)
          EXPECT_NEAR(stored.corner(closest[i].triangle, 0).z, float(kPlanes + 1 - first_t), 1e-4) << what;
        }
        EXPECT_NE(any[i].triangle, MC_NO_HIT) << what;
        EXPECT_TRUE(any[i].t >= rays[i].tmin && any[i].t <= rays[i].tmax) << what << ": any hit at " << any[i].t;
      }
      EXPECT_EQ(rows.found[i], uint32_t(std::max(0, kPlanes + 2 - first_t))) << what;
    }
    expect_nearest_rows(stored, rays, rows, name + ", t_min");
  }
}

// A secondary ray from a hit point (meshcast/ray.h's rule, t_min = 2^-16
// m / |d . n|), on every layout, around a convex sphere at the origin and
// 10^4 units out. Primary rays from outside hit the sphere; from each hit
// point, the reflected ray leaves the convex surface and hits nothing in
// exact arithmetic: with the rule's t_min every one misses, while with
// t_min 0 the rounded hit point makes some meet their own triangle again
// (what a shadow ray without t_min did). The ray going on through the
// surface never names its own triangle and, at the origin, gets the
// oracle's far-side hit.
TEST(TMin, SecondaryRaysFromHitPointsMissTheirOwnTriangle) {
  struct Place {
    const char* name;
    Vec3 centre;
  };
  for (const Place& place : {Place{"at the origin", {0.5f, -0.25f, 1.0f}}, Place{"10^4 out", {1e4f, -2e4f, 5e3f}}}) {
    const Mesh sphere = make_sphere(24, 48, 2.0f, place.centre);
    const double c[3] = {place.centre.x, place.centre.y, place.centre.z};
    std::mt19937 rng(17);
    std::normal_distribution<double> normal;
    std::vector<Ray> primary(quick() ? 150 : 400);
    for (Ray& r : primary) {
      double u[3] = {normal(rng), normal(rng), normal(rng)};
      const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (int a = 0; a < 3; ++a) {
        r.org[a] = float(c[a] + 10 * u[a] / len);
        r.dir[a] = float(c[a] + 0.6 * normal(rng) - r.org[a]);  // at a point well inside the sphere
      }
      r.tmax = INFINITY;
    }
    size_t self_hits_without = 0;
    for (const std::string& name : covering_layouts(layout_names())) {
      const std::vector<uint8_t> blob = build_blob(sphere, parse_layout(name), "sphere");
      const Mesh stored = stored_mesh(blob);  // what the walk meets, numbered as its hits
      const BlobView view(blob, name);
      std::vector<Hit> hits(primary.size());
      view.trace(primary, hits, HitOutputs::Point);
      std::vector<Ray> reflected, through;
      std::vector<uint32_t> own;
      for (size_t i = 0; i < primary.size(); ++i) {
        if (hits[i].triangle == MC_NO_HIT) continue;
        const Ray& r = primary[i];
        const Vec3 a = stored.corner(hits[i].triangle, 0), b = stored.corner(hits[i].triangle, 1),
                   d = stored.corner(hits[i].triangle, 2);
        const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
        const double e2[3] = {double(d.x) - a.x, double(d.y) - a.y, double(d.z) - a.z};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        const double n_len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double& x : n) x /= n_len;
        const double dn = r.dir[0] * n[0] + r.dir[1] * n[1] + r.dir[2] * n[2];
        const double d_len = std::sqrt(double(r.dir[0]) * r.dir[0] + double(r.dir[1]) * r.dir[1] + double(r.dir[2]) * r.dir[2]);
        if (std::fabs(dn) < 1e-3 * d_len) continue;  // grazing: the reflection's sign along n is rounding's
        double m = 0;
        for (int k = 0; k < 3; ++k) m = std::max({m, std::fabs(double(hits[i].point[k])), std::fabs(double(r.org[k]))});
        const float t_min = float(0x1p-16 * m / std::fabs(dn));  // |d' . n| = |d . n| for the reflection too
        Ray out{{hits[i].point[0], hits[i].point[1], hits[i].point[2]}, {}, INFINITY, t_min};
        for (int k = 0; k < 3; ++k) out.dir[k] = float(r.dir[k] - 2 * dn * n[k]);
        reflected.push_back(out);
        for (int k = 0; k < 3; ++k) out.dir[k] = r.dir[k];
        through.push_back(out);
        own.push_back(hits[i].triangle);
      }
      ASSERT_GT(reflected.size(), primary.size() / 2) << name << " " << place.name;
      const std::vector<Hit> off = trace_all(view, reflected), go_on = trace_all(view, through);
      std::vector<Ray> at_zero = reflected;
      for (Ray& r : at_zero) r.tmin = 0;
      const std::vector<Hit> from_zero = trace_all(view, at_zero);
      for (size_t i = 0; i < reflected.size(); ++i) {
        EXPECT_EQ(off[i].triangle, MC_NO_HIT) << name << " " << place.name << ", reflected ray " << i << " hit "
                                              << off[i].triangle << " (its own: " << own[i] << ") at t " << off[i].t
                                              << ", t_min " << reflected[i].tmin;
        EXPECT_NE(go_on[i].triangle, own[i]) << name << " " << place.name << ", ray " << i << " going on";
        self_hits_without += from_zero[i].triangle == own[i];
      }
      if (place.centre.x < 1) expect_oracle(stored, blob, through, go_on, name + " " + place.name + ", going on");
    }
    EXPECT_GT(self_hits_without, 0u) << place.name << ": with t_min 0 no ray met its own triangle; the test shows nothing";
  }
}
}  // namespace
}  // namespace meshcast::testing

// Batches of one origin (a sensor, a point's visibility) walk as packets
// on the octtree: each ray answers exactly as it does walked alone
// (Packets::Off): the same t, triangle, u and v bits for the closest hit,
// culled or not, with or without t_min; the same hit or miss for any hit.
// From inside, from outside and from just off the surface, on every
// octtree triangle format (covering ones in quick runs); against the
// oracle too.
namespace meshcast::testing {
namespace {
TEST(Packets, CommonOriginBatchesAnswerAsSingleRays) {
  std::vector<std::string> octtree;
  for (const std::string& name : layout_names())
    if (name.rfind("OctTreeCompressed/", 0) == 0) octtree.push_back(name);
  if (quick()) octtree = {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/Float3"};
  std::mt19937 rng(7);
  std::normal_distribution<float> gauss;
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  size_t packets_hit = 0;
  for (const NamedMesh& m : test_meshes(false)) {
    const Box3 box = m.mesh->bounds();
    const Vec3 centre = box.centre(), extent = box.extent();
    const double size = std::sqrt(double(extent.x) * extent.x + double(extent.y) * extent.y + double(extent.z) * extent.z);
    // Just off triangle 0's centroid along its normal, by 1e-3 of the mesh.
    const Vec3 a = m.mesh->corner(0, 0), b = m.mesh->corner(0, 1), c = m.mesh->corner(0, 2);
    const double e1[3] = {b.x - a.x, b.y - a.y, b.z - a.z}, e2[3] = {c.x - a.x, c.y - a.y, c.z - a.z};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double off = 1e-3 * size / std::max(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1e-300);
    Vec3 surface;
    for (int k = 0; k < 3; ++k) surface[k] = float((double(a[k]) + b[k] + c[k]) / 3 + n[k] * off);
    Vec3 outside;
    for (int k = 0; k < 3; ++k) outside[k] = centre[k] + 1.5f * extent[k];
    const Vec3 origins[3] = {centre, outside, surface};
    const size_t count = quick() ? 600 : 3000;
    for (const std::string& name : octtree) {
      const std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(name), m.name);
      const BlobView view(blob, m.name);
      for (int o = 0; o < 3; ++o) {
        std::vector<Ray> rays(count);
        for (size_t i = 0; i < count; ++i) {
          Ray& r = rays[i];
          for (int k = 0; k < 3; ++k) r.org[k] = origins[o][k], r.dir[k] = gauss(rng);
          r.tmax = INFINITY;
          // A third of the rays start a little way out (t_min), as the
          // secondary rays of a hit point do.
          r.tmin = i % 3 == 0 ? unit(rng) * 0.2f * float(size) : 0.0f;
        }
        const std::string what = name + " on " + m.name + " from origin " + std::to_string(o);
        for (Cull cull : {Cull::None, Cull::Back}) {
          std::vector<Hit> alone(count), packed(count);
          view.trace(rays, alone, HitOutputs::Uv, Query::Closest, cull, Packets::Off);
          view.trace(rays, packed, HitOutputs::Uv, Query::Closest, cull, Packets::Auto);
          for (size_t i = 0; i < count; ++i) {
            ASSERT_EQ(packed[i].triangle, alone[i].triangle) << what << ", ray " << i;
            ASSERT_EQ(std::bit_cast<uint32_t>(packed[i].t), std::bit_cast<uint32_t>(alone[i].t)) << what << ", ray " << i;
            ASSERT_EQ(std::bit_cast<uint32_t>(packed[i].u), std::bit_cast<uint32_t>(alone[i].u)) << what << ", ray " << i;
            ASSERT_EQ(std::bit_cast<uint32_t>(packed[i].v), std::bit_cast<uint32_t>(alone[i].v)) << what << ", ray " << i;
            packets_hit += packed[i].triangle != kNoHit;
          }
          view.trace(rays, alone, HitOutputs::None, Query::Any, cull, Packets::Off);
          view.trace(rays, packed, HitOutputs::None, Query::Any, cull, Packets::Auto);
          for (size_t i = 0; i < count; ++i)
            ASSERT_EQ(packed[i].triangle == kNoHit, alone[i].triangle == kNoHit) << what << ", any hit, ray " << i;
        }
        if (o == 0 && name == octtree[0]) {
          std::vector<Ray> from_zero = rays;
          for (Ray& r : from_zero) r.tmin = 0;
          std::vector<Hit> packed(count);
          view.trace(from_zero, packed, HitOutputs::None, Query::Closest, Cull::None, Packets::Auto);
          expect_oracle(*m.mesh, blob, from_zero, packed, what + " against the oracle");
        }
      }
    }
  }
  EXPECT_GT(packets_hit, 0u);
}
}  // namespace
}  // namespace meshcast::testing
