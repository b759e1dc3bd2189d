// The robustness corpus of ARCHITECTURE.md, for every layout: rays through
// shared edges and vertices of closed meshes (a leak is a failure),
// axis-parallel and signed-zero directions, grazing rays, far-from-origin,
// tiny and huge meshes, slivers and degenerate triangles, NaN and infinite
// rays, t_max of zero and infinity, origins on the surface.
//
// Built twice: robustness_test runs it on the CPU walkers of every layout;
// gpu_robustness_test (MESHCAST_TEST_GPU) runs the very same probes through
// every Vulkan method on the layout it reads, on the machine's device
// (lavapipe in CI) with the validation layers on.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "check/exact_t.h"
#include "check/generate.h"
#include "layout/blob_format.h"
#include "builder/writer.h"
#include "layout/queries.h"
#include "tests/testing.h"
#ifdef MESHCAST_TEST_GPU
#include "gpu/method.h"
#include "gpu/vulkan.h"
#endif

namespace meshcast::testing {
namespace {

#ifdef MESHCAST_TEST_GPU
gpu::Context& context() {
  static gpu::Context ctx(gpu::DeviceChoice{"", true});
  return ctx;
}

#endif

class Robustness : public ::testing::TestWithParam<std::string> {
 protected:
  // "TREE/TRIANGLES", with "+pairing": seed 003's pairs as the builder's
  // unit; with "+noids": no remap (hits name slots); with "@METHOD": traced
  // by that GPU method instead of the CPU.
  std::string layout() const { return GetParam().substr(0, GetParam().find_first_of("+@")); }
  std::string method() const {
    size_t at = GetParam().find('@');
    return at == std::string::npos ? "" : GetParam().substr(at + 1);
  }
  BuildOptions options() const {
    BuildOptions o = parse_layout(layout());
    o.pairing = GetParam().find("+pairing") != std::string::npos;
    o.triangle_ids = GetParam().find("+noids") == std::string::npos;
    return o;
  }
  // "auto:SETTING" (builder/auto_layout.h parse_auto_setting) builds the layout the automatic
  // layout chooses for each probe mesh; anything else the named layout.
  bool automatic() const { return GetParam().rfind("auto:", 0) == 0; }
  // A walk whose time grows with rays times triangles: the brute force and
  // AABBList, on the CPU or on the GPU.
  bool tests_every_triangle() const {
    if (!method().empty()) return method() == "bruteforce" || method() == "aabblist";
    return layout().rfind("BruteForce/", 0) == 0 || layout().rfind("AABBList/", 0) == 0;
  }
  std::vector<uint8_t> build(const Mesh& mesh, const char* what) const {
    if (!automatic()) return build_blob(mesh, options(), what);
    AutoLimits limits = parse_auto_setting(layout().substr(5));
#ifdef MESHCAST_TEST_GPU
    for (const gpu::MethodLayout& c : gpu::method_layouts()) limits.readers.push_back(c.layout);
#endif
    return choose_layout(mesh, limits, what).blob;
  }
  // `outputs`: the per-hit outputs asked for (MC_HIT_*).
  std::vector<Hit> trace(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, uint64_t* skipped = nullptr,
                         uint32_t outputs = 0) {
#ifdef MESHCAST_TEST_GPU
    std::unique_ptr<gpu::Method> m =
        gpu::make_method(context(), automatic() ? gpu::method_reading(blob) : method(), blob, GetParam(), 1, outputs);
    std::vector<Hit> hits(rays.size());
    uint64_t unwalkable = m->trace(rays, hits);
    if (skipped) *skipped = unwalkable;
    return hits;
#else
    return trace_all(blob, rays, skipped, outputs);
#endif
  }
  // A query on either side: the CPU walker, or a GPU method
  // made for it (its specialization constants).
  std::vector<Hit> trace_query(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, Query query, Cull cull) {
#ifdef MESHCAST_TEST_GPU
    std::vector<Hit> hits(rays.size());
    method_for(blob, layout::query_bits(query, cull), 1)->trace(rays, hits);
    return hits;
#else
    return trace_all(BlobView(blob, GetParam()), rays, query, cull);
#endif
  }
  HitLists trace_rows(const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, uint32_t max_hits,
                      Cull cull = Cull::None) {
#ifdef MESHCAST_TEST_GPU
    HitLists lists;
    method_for(blob, layout::query_bits(Query::All, cull), max_hits)->trace_all_hits(rays, lists);
    return lists;
#else
    return trace_lists(BlobView(blob, GetParam()), rays, max_hits, cull);
#endif
  }
#ifdef MESHCAST_TEST_GPU
  std::unique_ptr<gpu::Method> method_for(const std::vector<uint8_t>& blob, uint32_t flags, uint32_t max_hits) {
    return gpu::make_method(context(), automatic() ? gpu::method_reading(blob) : method(), blob, GetParam(), 1, flags,
                            max_hits);
  }
  // The context counts the layers' messages for the whole process: each
  // test answers for its own.
  uint64_t messages_before_ = 0;
  void SetUp() override { messages_before_ = context().validation_messages(); }
  void TearDown() override {
    EXPECT_EQ(context().validation_messages(), messages_before_) << context().last_validation_message();
  }
#endif
  static bool quantized(const std::vector<uint8_t>& blob) {
    return moves_vertices(layout::header_of(blob.data()).triangle_format);
  }
  // Oracle answers on the mesh as stored (quantized for bit-packed formats).
  void expect_answers(const Mesh& mesh, const std::vector<Ray>& rays, const char* what) {
    std::vector<uint8_t> blob = build(mesh, what);
    expect_oracle(mesh, blob, rays, trace(blob, rays), what);
  }
};

// Closed sphere, welded and unwelded: rays from inside must all hit; rays
// aimed at its vertices and edge midpoints from the centre must all hit.
// The walks that test every triangle (or every batch) for every ray take a
// sphere of a quarter of the triangles, so half the rays: on the finer one
// they took 130 s of the CPU suites' work and 139 s of lavapipe's, for the
// same watertight test at the same kind of shared edges and vertices.
TEST_P(Robustness, ClosedSphereNeverLeaks) {
  const bool linear = tests_every_triangle();
  for (bool soup : {false, true}) {
  Mesh s = linear ? make_sphere(12, 24, 1.0f, {0.1f, 0.2f, 0.3f}) : make_sphere(24, 48, 1.0f, {0.1f, 0.2f, 0.3f});
  if (soup) s = unwelded(s);
  std::vector<uint8_t> blob = build(s, "sphere");
  std::vector<Ray> rays;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int i = 0; i < 5000; ++i) rays.push_back({{0.1f + 0.3f * u(rng), 0.2f + 0.3f * u(rng), 0.3f + 0.3f * u(rng)},
                                                 {u(rng), u(rng), u(rng)}, INFINITY});
  // Through every vertex and edge midpoint from the centre, exactly.
  for (const Triangle& t : s.triangles)
    for (int c = 0; c < 3; ++c) {
      Vec3 a = s.vertices[t[c]], b = s.vertices[t[(c + 1) % 3]];
      Vec3 mid{0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)};
      for (Vec3 p : {a, mid}) rays.push_back({{0.1f, 0.2f, 0.3f}, {p.x - 0.1f, p.y - 0.2f, p.z - 0.3f}, INFINITY});
    }
  std::vector<Hit> hits = trace(blob, rays);
  size_t leaks = 0;
  for (const Hit& h : hits) leaks += h.triangle == MC_NO_HIT;
  EXPECT_EQ(leaks, 0u) << (soup ? "unwelded" : "welded");
  // Query::Any leaks no ray either.
  leaks = 0;
  for (const Hit& h : trace_query(blob, rays, Query::Any, Cull::None)) leaks += h.triangle == MC_NO_HIT;
  EXPECT_EQ(leaks, 0u) << (soup ? "unwelded" : "welded") << ", Query::Any";
  // The queries below on every ray in the CPU's full runs; on every 4th in
  // its quick runs (the sanitizers, the other instruction sets) and on the
  // GPU, every 16th for the methods that test every triangle (or every
  // batch) for every ray (7 passes of 19,000 rays took them 10-13 s each
  // on lavapipe).
  const size_t stride = !method().empty() && linear ? 16 : method().empty() && !quick() ? 1 : 4;
  std::vector<Ray> some;
  for (size_t i = 0; i < rays.size(); i += stride) some.push_back(rays[i]);
  // Query::All: every ray from inside finds at least one hit.
  const HitLists lists = trace_rows(blob, some, 8);
  EXPECT_EQ(std::count(lists.found.begin(), lists.found.end(), 0u), 0) << (soup ? "unwelded" : "welded") << ", Query::All";
  // From outside, through the sphere: a ray crosses a face of each side,
  // so culling either side leaks no ray (the entry through an edge or a
  // vertex included: culling keeps the test watertight).
  std::vector<Ray> outside;
  for (const Ray& r : some) {
    const float scale = 3 / std::sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]);
    const float away[3] = {0.1f - scale * r.dir[0], 0.2f - scale * r.dir[1], 0.3f - scale * r.dir[2]};
    outside.push_back({{away[0], away[1], away[2]}, {r.org[0] - away[0], r.org[1] - away[1], r.org[2] - away[2]}, INFINITY});
  }
  for (Cull cull : {Cull::Back, Cull::Front}) {
    leaks = 0;
    for (const Hit& h : trace_query(blob, outside, Query::Closest, cull)) leaks += h.triangle == MC_NO_HIT;
    EXPECT_EQ(leaks, 0u) << (soup ? "unwelded" : "welded") << ", from outside, cull " << int(cull);
    leaks = 0;
    for (const Hit& h : trace_query(blob, outside, Query::Any, cull)) leaks += h.triangle == MC_NO_HIT;
    EXPECT_EQ(leaks, 0u) << (soup ? "unwelded" : "welded") << ", from outside, Query::Any, cull " << int(cull);
  }
  }
}

// Integer grid: vertical rays through every vertex and edge midpoint, with
// +0 and -0 in the parallel components. The walks that test every triangle
// (or every batch) for every ray take an 8 by 8 grid, a quarter of the
// rays over a quarter of the triangles: on the 16 by 16 one lavapipe took
// them 10-12 s a layout, for the same edges, vertices and signed zeros.
TEST_P(Robustness, GridEdgesAndVerticesWithSignedZeros) {
  const int cells = tests_every_triangle() ? 8 : 16;
  Mesh g = make_grid_plane(cells, cells);
  std::vector<Ray> rays;
  for (int x = 0; x <= 2 * cells; ++x)
    for (int y = 0; y <= 2 * cells; ++y)
      for (float zx : {0.0f, -0.0f})
        for (float zy : {0.0f, -0.0f})
          for (float dz : {-1.0f, 1.0f})
            rays.push_back({{0.5f * x, 0.5f * y, -dz * 2.0f}, {zx, zy, dz}, INFINITY});
  std::vector<uint8_t> blob = build(g, "grid");
  std::vector<Hit> hits = trace(blob, rays, nullptr, MC_HIT_UV);
  const Mesh stored = stored_mesh(blob);  // u, v follow the stored corner order
  for (size_t i = 0; i < hits.size(); ++i) {
    ASSERT_NE(hits[i].triangle, MC_NO_HIT) << "ray " << i << " leaked";
    EXPECT_EQ(hits[i].t, 2.0f);
    // The barycentrics name the hit point (many of these rays take the
    // double-precision fallback: they cross edges and vertices exactly).
    const Hit& h = hits[i];
    for (int a = 0; a < 2; ++a) {
      float p = rays[i].org[a] + h.t * rays[i].dir[a];
      float q = (1 - h.u - h.v) * stored.corner(h.triangle, 0)[a] + h.u * stored.corner(h.triangle, 1)[a] +
                h.v * stored.corner(h.triangle, 2)[a];
      EXPECT_NEAR(p, q, quantized(blob) ? 1e-4 : 1e-5) << "ray " << i;
    }
    EXPECT_GE(h.u, -1e-6f);
    EXPECT_GE(h.v, -1e-6f);
  }
  // Query::Any: every ray through an edge or vertex still hits, at t 2.
  std::vector<Hit> any = trace_query(blob, rays, Query::Any, Cull::None);
  for (size_t i = 0; i < any.size(); ++i) {
    ASSERT_NE(any[i].triangle, MC_NO_HIT) << "ray " << i << " leaked, Query::Any";
    EXPECT_EQ(any[i].t, 2.0f) << "ray " << i << ", Query::Any";
  }
  // Culling: the grid's triangles all face one way (+z or -z); a ray sees
  // their front faces when it runs against that normal. Through an edge or
  // a vertex, the face kept is hit at t 2, the other culled.
  float facing = 0;  // the sign of the normals' z
  for (size_t t = 0; t < g.triangles.size(); ++t) {
    const Vec3 a = g.corner(t, 0), b = g.corner(t, 1), c = g.corner(t, 2);
    const float nz = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (t == 0) facing = nz > 0 ? 1.0f : -1.0f;
    ASSERT_GT(nz * facing, 0) << "grid triangle " << t << " faces the other way";
  }
  for (Cull cull : {Cull::Back, Cull::Front}) {
    for (Query query : {Query::Closest, Query::Any}) {
      std::vector<Hit> culled = trace_query(blob, rays, query, cull);
      for (size_t i = 0; i < culled.size(); ++i) {
        const bool front = rays[i].dir[2] * facing < 0;
        if (front == (cull == Cull::Back)) {
          ASSERT_NE(culled[i].triangle, MC_NO_HIT) << "ray " << i << " leaked, cull " << int(cull);
          EXPECT_EQ(culled[i].t, 2.0f) << "ray " << i << ", cull " << int(cull);
        } else {
          ASSERT_EQ(culled[i].triangle, MC_NO_HIT) << "ray " << i << " hit a culled face, cull " << int(cull);
        }
      }
    }
  }
  // Query::All: through a vertex every triangle around it, through an edge
  // both of its triangles, each once: the oracle's set on the stored grid.
  const Mesh stored_grid = stored_mesh(blob);
  const OracleTree tree(stored_grid);
  std::vector<std::vector<OracleHit>> expected(rays.size());
  size_t shared = 0;
  for (size_t i = 0; i < rays.size(); ++i) expected[i] = tree.all(rays[i]), shared += expected[i].size() > 1;
  // (Quantized corners sit a rounding away from the rays' exact lines.)
  if (!quantized(blob)) {
    EXPECT_GT(shared, rays.size() / 2) << "most of these rays meet an edge or a vertex";
  }
  Agreement all = compare_all(stored_grid, rays, trace_rows(blob, rays, 16), expected, 1e-6);
  EXPECT_EQ(all.wrong + all.t_errors + all.t_rounding + all.ties, 0u) << all.first_problem;
  expect_answers(g, rays, "grid");
}

// Per-hit outputs are computed only when asked: u, v and the
// point read 0 otherwise, and asking changes neither t nor the triangle.
// The point is org + t * dir; u, v name that point in the stored triangle.
TEST_P(Robustness, PerHitOutputsOnlyWhenAsked) {
  const Mesh s = make_sphere(12, 24, 1.5f, {0.25f, -0.5f, 2.0f});
  const std::vector<Ray> rays = make_rays(s, RayKind::Long, 256, 5);
  const std::vector<uint8_t> blob = build(s, "sphere");
  const Mesh stored = stored_mesh(blob);
  const std::vector<Hit> plain = trace(blob, rays);
  const std::vector<Hit> uv = trace(blob, rays, nullptr, MC_HIT_UV);
  const std::vector<Hit> point = trace(blob, rays, nullptr, MC_HIT_POINT);
  const std::vector<Hit> both = trace(blob, rays, nullptr, MC_HIT_UV | MC_HIT_POINT);
  const double tolerance = 1e-5 * s.bounds().diagonal();
  size_t hit = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    for (const std::vector<Hit>* h : {&uv, &point, &both}) {
      ASSERT_EQ((*h)[i].triangle, plain[i].triangle) << "ray " << i;
      ASSERT_EQ((*h)[i].t, plain[i].t) << "ray " << i;
    }
    for (const Hit* h : {&plain[i], &point[i]}) {
      EXPECT_EQ(h->u, 0.0f) << "ray " << i;
      EXPECT_EQ(h->v, 0.0f) << "ray " << i;
    }
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(plain[i].point[a], 0.0f) << "ray " << i;
      EXPECT_EQ(uv[i].point[a], 0.0f) << "ray " << i;
    }
    if (plain[i].triangle == MC_NO_HIT) continue;
    ++hit;
    const Hit& h = both[i];
    for (int a = 0; a < 3; ++a) {
      const double p = double(rays[i].org[a]) + double(h.t) * rays[i].dir[a];
      const double q = (1.0 - h.u - h.v) * stored.corner(h.triangle, 0)[a] + double(h.u) * stored.corner(h.triangle, 1)[a] +
                       double(h.v) * stored.corner(h.triangle, 2)[a];
      EXPECT_NEAR(h.point[a], p, tolerance) << "ray " << i << " axis " << a;
      EXPECT_EQ(point[i].point[a], h.point[a]) << "ray " << i;
      EXPECT_NEAR(q, p, tolerance) << "ray " << i << " axis " << a;
    }
    EXPECT_EQ(uv[i].u, h.u);
    EXPECT_EQ(uv[i].v, h.v);
    EXPECT_GE(h.u, -1e-6f);
    EXPECT_GE(h.v, -1e-6f);
    EXPECT_LE(h.u + h.v, 1.0f + 1e-6f);
  }
  EXPECT_GT(hit, rays.size() / 2);
}

TEST_P(Robustness, AxisParallelGrazingAndInPlane) {
  Mesh g = make_grid_plane(8, 8);
  std::vector<Ray> rays;
  for (int i = 0; i <= 16; ++i) {
    float c = 0.5f * i;
    rays.push_back({{-1.0f, c, 0.0f}, {1, 0, 0}, INFINITY});          // in the plane
    rays.push_back({{c, -1.0f, 1e-7f}, {0, 1, 0}, INFINITY});         // just above it
    rays.push_back({{-1.0f, c, 1.0f}, {1, 0, -1e-6f}, INFINITY});     // grazing
    rays.push_back({{c, c, 5.0f}, {0, 0, -1}, INFINITY});             // axis-parallel
    rays.push_back({{-1.0f, -1.0f, 1.0f}, {c + 1, c + 1, -1}, INFINITY});
  }
  expect_answers(g, rays, "grid in-plane");
}

TEST_P(Robustness, FarTinyAndHugeMeshes) {
  std::mt19937 rng(2);
  for (auto [radius, centre] : {std::pair{0.15f, Vec3{1000, -1000, 1000}}, std::pair{150.0f, Vec3{30000, 0, 0}},
                                std::pair{1e-4f, Vec3{0, 0, 0}}, std::pair{1e5f, Vec3{0, 0, 0}},
                                std::pair{0.01f, Vec3{1e5f, 1e5f, 1e5f}}}) {
    Mesh s = make_sphere(16, 32, radius, centre);
    std::vector<Ray> rays = make_rays(s, RayKind::Long, 400, rng());
    for (const Ray& r : make_rays(s, RayKind::Radial, 200, rng())) rays.push_back(r);
    expect_answers(s, rays, "far/tiny/huge sphere");
  }
}

// Coordinates from 1e-30 to 1e30 (the +-2^100 limit) and direction
// lengths scaled by 2^-130 .. 2^100 (those with a component beyond 2^126 or
// all below FLT_MIN are counted misses, as the oracle has them). The float
// test overflows (det, T) or underflows there, and at 1e19 det passes 2^126;
// those lanes are settled in double, and a t past the largest float is a
// miss on both sides. Every ray gets the oracle's answer.
TEST_P(Robustness, ExtremeMagnitudesAndDirectionLengths) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double radius : {1e-30, 1e-20, 1e-13, 1e13, 1e19, 1e20, 1e30}) {
    const Mesh s = make_sphere(8, 16, float(radius), {0, 0, 0});
    std::vector<Ray> base;  // origins within 1.2 radii (inside the coordinate limit), aimed into the sphere's box
    for (int i = 0; i < 120; ++i) {
      double o[3], p[3], n = 0;
      for (int a = 0; a < 3; ++a) o[a] = u(rng), p[a] = u(rng) * radius, n += o[a] * o[a];
      const double k = (i % 4 == 0 ? 0.3 : 1.2) * radius / std::sqrt(n);  // a quarter from inside
      Ray r{};
      for (int a = 0; a < 3; ++a) r.org[a] = float(o[a] * k), r.dir[a] = float(p[a] - o[a] * k);
      r.tmax = INFINITY;
      base.push_back(r);
    }
    std::vector<Ray> rays;
    for (double f : {0x1p-130, 0x1p-60, 1.0, 0x1p60, 0x1p100})
      for (Ray r : base) {
        for (float& d : r.dir) d = float(d * f);
        const float m = std::max({std::fabs(r.dir[0]), std::fabs(r.dir[1]), std::fabs(r.dir[2])});
        if (m >= 0x1p-120f && m <= kMaxDirection) rays.push_back(r);
      }
    ASSERT_GT(rays.size(), 300u);
    expect_answers(s, rays, ("sphere of radius " + std::to_string(radius)).c_str());
  }
}

// Meshes under the least extent a grid takes: a sphere of radius 1e-37,
// and one 1e-38 across squashed to 7.5e-43 in z (its z coordinates
// denormal). A format that keeps its vertices on a grid refuses them,
// naming the mesh and the limit (the step would fall below FLT_MIN, where
// it rounded vertices past the stated bound and flattened z); every other
// layout, and the automatic choice, builds them and answers as the oracle.
TEST_P(Robustness, MeshesUnderAGridsLeastExtent) {
  Mesh squashed = make_sphere(8, 16, 0.5e-38f, {0, 0, 0});
  for (Vec3& v : squashed.vertices) v.z *= 1.5e-4f;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (const auto& [mesh, what] : {std::pair{make_sphere(8, 16, 1e-37f, {0, 0, 0}), "sphere of radius 1e-37"},
                                   std::pair{squashed, "squashed sphere 1e-38 across"}}) {
    const Box3 box = mesh.bounds();
    // (Zero-byte trees' Indexed24 keeps the mesh's floats.)
    const uint32_t format = automatic() ? MC_TRI_INDEXED24 : uint32_t(options().layout.triangles);
    if (format != MC_TRI_INDEXED24 && codec_ops(format).grid != layout::kGridNone) {
      try {
        build_blob(mesh, options(), what);
        ADD_FAILURE() << what << ": built on a grid";
      } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(what), std::string::npos) << message;
        EXPECT_NE(message.find("2^-126"), std::string::npos) << message;
      }
      continue;
    }
    if (automatic() && GetParam().find("bytes=") != std::string::npos) {
      // Under a byte limit the float formats may all be over it: then the
      // choice is refused, saying so (the grid formats' refusals counted).
      try {
        build(mesh, what);
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no layout meets the limits"), std::string::npos) << e.what();
        continue;
      }
    }
    // From 1.2 extents out, aimed at points of the box: unit directions,
    // and (every other ray) the difference itself, as small as the mesh
    // (components below FLT_MIN, read as 0: their reciprocals overflowed
    // and the box test culled boxes these rays cross).
    std::vector<Ray> rays;
    for (int i = 0; i < 400; ++i) {
      double o[3], d[3], len = 0;
      for (int a = 0; a < 3; ++a) {
        const double lo = box.min[a], hi = box.max[a], c = 0.5 * (lo + hi), e = hi - lo;
        o[a] = c + 1.2 * e * u(rng), d[a] = c + 0.5 * e * u(rng) - o[a];
      }
      for (double x : d) len += x * x;
      Ray r{};
      for (int a = 0; a < 3; ++a) r.org[a] = float(o[a]), r.dir[a] = float(i % 2 ? d[a] : d[a] / std::sqrt(len));
      r.tmax = INFINITY;
      rays.push_back(r);
    }
    expect_answers(mesh, rays, what);
  }
}

// The adversarial run's case: two triangles with corners (0,0),
// (1e13,0), (0,1e13) at z = -1e13 and at z = 0. From (1e12, 1e12, 1e13)
// straight down the ray must hit the upper one (triangle 1) at t = 1e13;
// float's T overflowed, giving t = inf and triangle 0, and with t_max 3e13
// a miss. Two grids far off to the side give every layout some bulk (auto's
// byte limit counts a blob's fixed overhead per triangle).
TEST_P(Robustness, LargeCoordinatesHitTheNearTriangle) {
  const float e = 1e13f;
  Mesh m;
  m.vertices = {{0, 0, -e}, {e, 0, -e}, {0, e, -e}, {0, 0, 0}, {e, 0, 0}, {0, e, 0}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  for (float z : {-e, 0.0f}) {
    const Mesh g = make_grid_plane(6, 6);
    const uint32_t base = uint32_t(m.vertices.size());
    for (Vec3 v : g.vertices) m.vertices.push_back({3 * e + v.x * (e / 6), v.y * (e / 6), z});
    for (Triangle t : g.triangles) m.triangles.push_back({base + t[0], base + t[1], base + t[2]});
  }
  std::vector<Ray> rays;
  for (float tmax : {INFINITY, 3e13f})
    for (float len : {1.0f, 1e-20f, 1e20f}) rays.push_back({{1e12f, 1e12f, e}, {0, 0, -len}, tmax});
  const std::vector<uint8_t> blob = build(m, "two triangles at 1e13");
  const std::vector<Hit> hits = trace(blob, rays);
  const bool ids = layout::has_remap(layout::header_of(blob.data()));
  for (size_t i = 0; i < rays.size(); ++i) {
    const float expected = e / -rays[i].dir[2];
    if (expected > rays[i].tmax) {
      EXPECT_EQ(hits[i].triangle, MC_NO_HIT) << "ray " << i;
      continue;
    }
    if (ids) {
      EXPECT_EQ(hits[i].triangle, 1u) << "ray " << i;
    }
    EXPECT_NE(hits[i].triangle, MC_NO_HIT) << "ray " << i;
    EXPECT_NEAR(hits[i].t, expected, 1e-6 * expected) << "ray " << i;
  }
  expect_answers(m, rays, "two triangles at 1e13");
}

TEST_P(Robustness, SliversAndDegenerateTriangles) {
  Mesh m = make_grid_plane(6, 6);
  uint32_t base = uint32_t(m.vertices.size());
  m.vertices.push_back({1.0f, 1.0f, 0.5f});
  m.vertices.push_back({5.0f, 5.0f, 0.5f});
  m.vertices.push_back({3.0f, 3.0f, 0.5f});               // collinear: zero area
  m.vertices.push_back({1.0f, 1.0f, 0.5f});               // duplicate position
  m.vertices.push_back({5.0f, 5.0000005f, 0.5f});         // needle
  m.triangles.push_back({base, base + 1, base + 2});
  m.triangles.push_back({base, base + 3, base + 1});
  m.triangles.push_back({base, base + 1, base + 4});
  std::vector<Ray> rays;
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0, 6);
  for (int i = 0; i < 3000; ++i) rays.push_back({{u(rng), u(rng), 2.0f}, {0.01f * (u(rng) - 3), 0.0f, -1}, INFINITY});
  for (int i = 0; i <= 40; ++i) {
    float c = 1.0f + 0.1f * i;
    rays.push_back({{c, c, 2.0f}, {0, 0, -1}, INFINITY});  // along the sliver
  }
  expect_answers(m, rays, "slivers");
}

// Directions with denormal components (their inverses overflow to
// infinity in the box tests) and coplanar overlapping triangles (the same
// plane hit by two or three triangles at once: any of them is right, none
// may be missed).
TEST_P(Robustness, DenormalDirectionsAndCoplanarOverlaps) {
  Mesh g = make_grid_plane(8, 8);
  uint32_t base = uint32_t(g.vertices.size());
  for (Vec3 v : {Vec3{0.25f, 0.25f, 0}, Vec3{3.75f, 0.5f, 0}, Vec3{1.0f, 3.5f, 0},   // overlaps the grid
                 Vec3{0.5f, 0.25f, 0}, Vec3{3.5f, 3.5f, 0}, Vec3{0.25f, 3.0f, 0}})  // and that triangle
    g.vertices.push_back(v);
  g.triangles.push_back({base, base + 1, base + 2});
  g.triangles.push_back({base + 3, base + 4, base + 5});
  const float d = 1e-40f, e = -3e-42f;  // denormals
  std::vector<Ray> rays;
  for (int x = 0; x <= 16; ++x)
    for (int y = 0; y <= 16; ++y) {
      float px = 0.25f * float(x), py = 0.25f * float(y);
      rays.push_back({{px, py, 2.0f}, {d, e, -1}, INFINITY});
      rays.push_back({{px, py, -2.0f}, {-0.0f, d, 1}, INFINITY});
      rays.push_back({{px, py, 1e-30f}, {e, 0.0f, -d}, INFINITY});  // crawls down onto the plane
    }
  rays.push_back({{-1.0f, 1.5f, 1e-38f}, {1, 0, -d}, INFINITY});  // nearly in the plane
  std::vector<Hit> hits = trace(build(g, "coplanar"), rays);
  size_t leaks = 0;
  for (size_t i = 0; i + 1 < rays.size(); ++i)  // the steep rays from inside the grid's border (on it, -3e-42 in y leaves)
    leaks += hits[i].triangle == MC_NO_HIT && rays[i].dir[2] * rays[i].dir[2] == 1 && rays[i].org[0] > 0 && rays[i].org[1] > 0;
  EXPECT_EQ(leaks, 0u);
  expect_answers(g, rays, "coplanar, denormal directions");
}

TEST_P(Robustness, UnwalkableRaysAreCountedMisses) {
  Mesh g = make_grid_plane(4, 4);
  std::vector<uint8_t> blob = build(g, "grid");
  const float nan = NAN, inf = INFINITY;
  std::vector<Ray> rays = {
      {{nan, 1, 1}, {0, 0, -1}, inf}, {{1, 1, 1}, {0, nan, -1}, inf}, {{inf, 1, 1}, {0, 0, -1}, inf},
      {{1, 1, 1}, {0, 0, -inf}, inf}, {{1, 1, 1}, {0, 0, 0}, inf},    {{1, 1, 1}, {-0.0f, 0.0f, -0.0f}, inf},
      {{1, 1, 1}, {0, 0, -1}, nan},   {{1, 1, 1}, {0, 0, -1}, -1.0f},
      {{0x1p101f, 1, 1}, {-1, 0, -1}, inf},  // origin beyond +-2^100
      {{1, 1, 1}, {0, 0, -0x1p127f}, inf},   // a component beyond 2^126
      {{1, 1, 1}, {0x1p-127f, 0, 0}, inf},   // every component below FLT_MIN
      // t_min refused as t_max is: NaN, negative, and past t_max.
      {{1, 1, 1}, {0, 0, -1}, inf, nan}, {{1, 1, 1}, {0, 0, -1}, inf, -1.0f}, {{1, 1, 1}, {0, 0, -1}, 1.0f, 1.5f},
  };
  uint64_t skipped = 0;
  std::vector<Hit> hits = trace(blob, rays, &skipped);
  EXPECT_EQ(skipped, rays.size());
  for (const Hit& h : hits) {
    EXPECT_EQ(h.triangle, MC_NO_HIT);
    EXPECT_EQ(h.t, INFINITY);
  }
}

TEST_P(Robustness, TMinTMaxZeroInfinityAndOriginsOnTheSurface) {
  Mesh g = make_grid_plane(4, 4);
  std::vector<Ray> rays = {
      {{1.3f, 1.6f, 0.0f}, {0, 0, -1}, 0.0f},     // on the surface, t_max 0: hit at 0
      {{1.3f, 1.6f, 0.0f}, {0.3f, 0.1f, 1}, 0.0f},
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, 0.0f},     // above, t_max 0: miss
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, 1.0f},     // exactly t_max: hit
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, 0.999f},   // just short: miss
      {{1.3f, 1.6f, 1e30f}, {0, 0, -1}, INFINITY},
      {{2.0f, 2.0f, 0.0f}, {0, 0, 1}, INFINITY},  // on a vertex, leaving
      // t_min, included as t_max is.
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, INFINITY, 1.0f},    // exactly t_min: hit
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, INFINITY, 1.001f},  // just past: miss
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, 1.0f, 1.0f},        // t_min = t_max at the surface: hit
      {{1.3f, 1.6f, 0.0f}, {0, 0, -1}, INFINITY, 1e-6f},   // on the surface, t_min past 0: miss
      {{1.3f, 1.6f, 1.0f}, {0, 0, -1}, INFINITY, -0.0f},   // -0 is 0
  };
  expect_answers(g, rays, "t_max");
  uint64_t skipped = 0;
  std::vector<Hit> hits = trace(build(g, "grid"), rays, &skipped);
  EXPECT_EQ(skipped, 0u);
  EXPECT_EQ(hits[0].t, 0.0f);
  EXPECT_EQ(hits[2].triangle, MC_NO_HIT);
  EXPECT_NE(hits[3].triangle, MC_NO_HIT);
  EXPECT_EQ(hits[4].triangle, MC_NO_HIT);
  EXPECT_EQ(hits[7].t, 1.0f);
  EXPECT_EQ(hits[8].triangle, MC_NO_HIT);
  EXPECT_EQ(hits[9].t, 1.0f);
  EXPECT_EQ(hits[10].triangle, MC_NO_HIT);
  EXPECT_EQ(hits[11].t, 1.0f);
}

// Both ends are compared with the t a walk reports: a ray cast again with
// t_min (or t_max) set to a hit's t finds that hit at that t, and with the
// next float past it does not. On a tilted grid, rays straight down each
// grid line meet an edge function of exactly 0 (the test's double
// precision path, where t is computed in double and rounded), and rays
// between the lines take the float path.
TEST_P(Robustness, ReportedTIsFoundAgainAsTMinAndTMax) {
  Mesh tilted = make_grid_plane(8, 8);
  for (Vec3& v : tilted.vertices) v.z = 0.3137f * v.x + 0.7071f * v.y + 0.1f;
  std::vector<Ray> rays;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> along(0.05f, 7.95f);
  for (int i = 0; i < 240; ++i) {
    const float line = float(1 + i % 7), other = along(rng);
    Vec3 o = i % 3 == 0 ? Vec3{line, other, 9.3f} : i % 3 == 1 ? Vec3{other, line, 9.3f} : Vec3{other, along(rng), 9.3f};
    rays.push_back({{o.x, o.y, o.z}, {0, 0, -1}, INFINITY});
  }
  const std::vector<uint8_t> blob = build(tilted, "tilted grid");
  const std::vector<Hit> first = trace(blob, rays);
  // Cast again in one batch: t_min = t, t_max = t, t_min past t, t_max short of t.
  const size_t n = rays.size();
  std::vector<Ray> again;
  for (int variant = 0; variant < 4; ++variant)
    for (size_t i = 0; i < n; ++i) {
      ASSERT_NE(first[i].triangle, MC_NO_HIT) << "ray " << i << " misses the grid under it";
      Ray r = rays[i];
      const float t = first[i].t;
      if (variant == 0) r.tmin = t;
      if (variant == 1) r.tmax = t;
      if (variant == 2) r.tmin = std::nextafter(t, INFINITY);
      if (variant == 3) r.tmax = std::nextafter(t, 0.0f);
      again.push_back(r);
    }
  const std::vector<Hit> hits = trace(blob, again);
  for (size_t i = 0; i < n; ++i) {
    const std::string what = "ray " + std::to_string(i) + " (hit at t " + std::to_string(first[i].t) + ")";
    for (size_t at : {i, n + i}) {
      EXPECT_EQ(hits[at].t, first[i].t) << what << (at == i ? ", t_min = t" : ", t_max = t");
      EXPECT_EQ(hits[at].triangle, first[i].triangle) << what << (at == i ? ", t_min = t" : ", t_max = t");
    }
    EXPECT_EQ(hits[2 * n + i].triangle, MC_NO_HIT) << what << ", t_min past t: a hit at " << hits[2 * n + i].t;
    EXPECT_EQ(hits[3 * n + i].triangle, MC_NO_HIT) << what << ", t_max short of t: a hit at " << hits[3 * n + i].t;
  }
}

// A hit's t is the distance along the ray to the stored triangle, worked
// out in double: within an ulp of the exact value (check/exact_t.h), on
// rays that graze the surface too, where the float test's own t drifts by
// tens of ulps (up to 1.2e-5 of the diagonal on the two rays below, past
// the tolerance the oracle is judged by). Each query: the closest hit, any
// hit, every hit; t_rounding in expect_oracle and compare_all is the
// 1-ulp check.
TEST_P(Robustness, TIsTheExactDistanceOnGrazingRays) {
  struct Probe {
    const char* mesh;
    Ray ray;
  };
  const Probe probes[] = {
      {"sphere", {{0x1.97c2eep+0f, -0x1.907d36p+0f, -0x1.54285p+0f}, {-0x1.cf28fep-2f, 0x1.566d5cp-1f, 0x1.2e1702p-1f}, INFINITY}},
      {"fandisk", {{-0x1.ad5b7cp-1f, -0x1.19aee6p-2f, 0x1.fdcd6cp+0f}, {0x1.8837a6p-2f, 0x1.48944cp-3f, -0x1.d1c4p-1f}, INFINITY}},
  };
  for (const Probe& probe : probes) {
    const std::optional<Mesh> mesh = data_mesh(probe.mesh);
    if (!mesh) GTEST_SKIP() << "data/" << probe.mesh << ".off is not there (scripts/fetch_meshes.sh)";
    // The probe, and rays that graze the mesh's triangles: from a point
    // just off each of a spread of triangles' planes (1e-4 of its size),
    // along the plane through the triangle's centroid, and back out.
    std::vector<Ray> rays = {probe.ray};
    const size_t step = std::max<size_t>(1, mesh->triangles.size() / (tests_every_triangle() ? 64 : 512));
    for (size_t t = 0; t < mesh->triangles.size(); t += step) {
      const Vec3 a = mesh->corner(t, 0), b = mesh->corner(t, 1), c = mesh->corner(t, 2);
      const Vec3 centroid{(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3};
      const Vec3 e1{b.x - a.x, b.y - a.y, b.z - a.z}, e2{c.x - a.x, c.y - a.y, c.z - a.z};
      const Vec3 n{e1.y * e2.z - e1.z * e2.y, e1.z * e2.x - e1.x * e2.z, e1.x * e2.y - e1.y * e2.x};
      for (float off : {1e-4f, -1e-4f}) {
        Ray r{};
        for (int k = 0; k < 3; ++k) {
          r.dir[k] = e1[k] + off * n[k] / std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
          r.org[k] = centroid[k] - 2 * r.dir[k];
        }
        r.tmax = INFINITY;
        rays.push_back(r);
      }
    }
    const std::vector<uint8_t> blob = build(*mesh, probe.mesh);
    const Mesh stored = stored_mesh(blob);
    const std::vector<Hit> hits = trace(blob, rays);
    EXPECT_GT(expect_oracle(*mesh, blob, rays, hits, probe.mesh), rays.size() / 4) << probe.mesh;
    ASSERT_NE(hits[0].triangle, MC_NO_HIT) << probe.mesh << ": the probe";
    EXPECT_TRUE(t_within_ulps(rays[0], stored.corner(hits[0].triangle, 0), stored.corner(hits[0].triangle, 1),
                              stored.corner(hits[0].triangle, 2), hits[0].t, kTUlps))
        << probe.mesh << ": the probe's t " << hits[0].t;
    const std::vector<Hit> any = trace_query(blob, rays, Query::Any, Cull::None);
    for (size_t i = 0; i < rays.size(); ++i) {
      if (any[i].triangle == MC_NO_HIT) continue;
      EXPECT_TRUE(t_within_ulps(rays[i], stored.corner(any[i].triangle, 0), stored.corner(any[i].triangle, 1),
                                  stored.corner(any[i].triangle, 2), any[i].t, kTUlps))
          << probe.mesh << " ray " << i << ", Query::Any: t " << any[i].t;
    }
    const OracleTree tree(stored);
    std::vector<std::vector<OracleHit>> expected(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) expected[i] = tree.all(rays[i]);
    const Agreement all = compare_all(stored, rays, trace_rows(blob, rays, 64), expected, 1e-5 * mesh->bounds().diagonal());
    EXPECT_EQ(all.wrong + all.t_errors + all.t_rounding, 0u) << probe.mesh << ", Query::All: " << all.first_problem;
  }
}

// A ray whose origin lies on a triangle meets it at t = 0, which t_min = 0
// includes: every origin below lies exactly on its triangle (in float), the
// first triangle flat, the second tilted (z = (x + y) / 2, which dyadic x
// and y keep exact), each ray leaving in a direction off the plane, either
// side. With t_min past 0 the triangle is behind the ray: a miss. (Both
// triangles where the layout stores the input's corners, the flat one
// where it moves them to a grid.)
TEST_P(Robustness, OriginsOnATriangleHitItAtZero) {
  for (bool tilted : {false, true}) {
    // The triangle, then a small grid at x = 64 (what a layout's bytes a
    // triangle are measured on: one triangle is mostly header), which the
    // rays below, all leaving toward -x, never reach. The corners and the
    // grid lie on every grid format's grid (powers of two): the stored
    // triangle is the input's.
    Mesh m = make_grid_plane(4, 4);
    for (Vec3& v : m.vertices) v = {64, v.x, v.y};
    const uint32_t first = uint32_t(m.vertices.size());
    for (const Vec3& v : tilted ? std::vector<Vec3>{{0, 0, 0}, {4, 0, 2}, {0, 4, 2}} : std::vector<Vec3>{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})
      m.vertices.push_back(v);
    m.triangles.push_back({first, first + 1, first + 2});
    uint32_t ours = uint32_t(m.triangles.size() - 1);
    const float size = tilted ? 4.0f : 1.0f;
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> grid(1, 1022);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Ray> rays, past;
    while (rays.size() < 2000) {
      const int i = grid(rng), j = grid(rng);
      if (i + j >= 1023) continue;  // inside, off the long edge
      const float x = size * float(i) / 1024, y = size * float(j) / 1024;
      Ray r{{x, y, tilted ? (x + y) / 2 : 0.0f}, {-std::fabs(u(rng)), u(rng), u(rng)}, INFINITY};
      // Off the plane by at least a tenth of the direction's length.
      const float nd = tilted ? -r.dir[0] - r.dir[1] + 2 * r.dir[2] : r.dir[2];
      if (std::fabs(nd) < 0.1f * (tilted ? 2.45f : 1.0f) * std::sqrt(r.dir[0] * r.dir[0] + r.dir[1] * r.dir[1] + r.dir[2] * r.dir[2]))
        continue;
      rays.push_back(r);
      r.tmin = 0x1p-20f;
      past.push_back(r);
    }
    const std::vector<uint8_t> blob = build(m, tilted ? "tilted triangle" : "triangle");
    // A grid format stores the tilted triangle's corners a rounding off the
    // input's (its steps are no powers of two), and these origins are then
    // off its plane; the flat one stays in z = 0 on every grid.
    if (tilted && quantized(blob)) continue;
    // Without a remap hits name slots: ours is the stored triangle with a
    // corner at x in (0, 32) (the grid's lie at 64, unused slots at 0).
    const Mesh stored = stored_mesh(blob);
    for (uint32_t k = 0; k < stored.triangles.size(); ++k)
      for (int c = 0; c < 3; ++c)
        if (stored.corner(k, c).x > 0 && stored.corner(k, c).x < 32) ours = k;
    for (Query query : {Query::Closest, Query::Any}) {
      const std::vector<Hit> hits = trace_query(blob, rays, query, Cull::None);
      size_t missed = 0, off_zero = 0;
      for (const Hit& h : hits) missed += h.triangle != ours, off_zero += h.triangle == ours && h.t != 0.0f;
      EXPECT_EQ(missed + off_zero, 0u) << (tilted ? "tilted" : "flat") << ", query " << int(query) << ": " << missed
                                       << " missed, " << off_zero << " hit at another t than 0";
      size_t hit_past = 0;
      for (const Hit& h : trace_query(blob, past, query, Cull::None)) hit_past += h.triangle != MC_NO_HIT;
      EXPECT_EQ(hit_past, 0u) << (tilted ? "tilted" : "flat") << ", query " << int(query) << ", t_min 2^-20";
    }
    const HitLists rows = trace_rows(blob, rays, 4);
    size_t zero = 0;
    for (size_t i = 0; i < rays.size(); ++i) zero += rows.found[i] == 1 && rows.row(i)[0].t == 0.0f && rows.row(i)[0].triangle == ours;
    EXPECT_EQ(zero, rays.size()) << (tilted ? "tilted" : "flat") << ", Query::All; the first ray's row: " << rows.found[0]
                                 << " found, " << (rows.found[0] ? rows.row(0)[0].t : -1.0f) << ", triangle "
                                 << (rows.found[0] ? rows.row(0)[0].triangle : 0u);
  }
}

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (char& c : n)
    if (c == '/' || c == '+' || c == '@' || c == ':' || c == ',' || c == '-' || c == '.' || c == '=') c = '_';
  return n;
}

#ifdef MESHCAST_TEST_GPU
// Every GPU method on every layout it reads; the no-remap path (hits
// naming slots: blob.glsl's remap_entry, called from walk.glsl by every
// tree method and from the resolve pass of the brute force and AABBList)
// on one method of each kind, octtree and bruteforce; the automatic
// layout's choice for each goal, and under an error limit (what it picks
// is a layout of the list above: its timed trial and byte limit choose
// among the same).
std::vector<std::string> gpu_cases() {
  std::vector<std::string> names;
  std::vector<std::string> methods;
  for (const gpu::MethodLayout& c : gpu::method_layouts()) {
    names.push_back(layout_name(c.layout) + "@" + c.method);
    if (std::find(methods.begin(), methods.end(), c.method) != methods.end()) continue;
    methods.push_back(c.method);
    if (std::string(c.method) == "octtree" || std::string(c.method) == "bruteforce") names.push_back(layout_name(c.layout) + "+noids@" + c.method);
  }
  for (const std::string& setting : auto_settings())
    if (setting.find("trial") == std::string::npos && setting.find("bytes") == std::string::npos)
      names.push_back("auto:" + setting);
  return names;
}
INSTANTIATE_TEST_SUITE_P(Vulkan, Robustness, ::testing::ValuesIn(gpu_cases()), param_name);
#else
INSTANTIATE_TEST_SUITE_P(Layouts, Robustness, ::testing::ValuesIn(covering_layouts(layout_names())), param_name);

// The automatic layout's choice for each probe mesh, under each setting.
std::vector<std::string> auto_cases() {
  std::vector<std::string> names;
  for (const std::string& setting : auto_settings()) names.push_back("auto:" + setting);
  return names;
}
INSTANTIATE_TEST_SUITE_P(Auto, Robustness, ::testing::ValuesIn(auto_cases()), param_name);

// Paired trees (seed 003): every tree that takes pairs, with a float and a
// quantized encoding.
std::vector<std::string> paired_layouts() {
  std::vector<std::string> names;
  for (const std::string& n : layout_names()) {
    BuildOptions o = parse_layout(n);
    if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE || uint32_t(o.layout.tree) == MC_TREE_AABBLIST || uint32_t(o.layout.tree) == MC_TREE_ZEROBYTE ||
        uint32_t(o.layout.tree) == MC_TREE_ZEROBYTEHYBRID)
      continue;
    if (uint32_t(o.layout.triangles) == MC_TRI_FLOAT3SOA4 || uint32_t(o.layout.triangles) == MC_TRI_INDEXED8BITPACKSOA4) names.push_back(n + "+pairing");
  }
  return names;
}
INSTANTIATE_TEST_SUITE_P(Paired, Robustness, ::testing::ValuesIn(covering_layouts(paired_layouts())), param_name);

#endif

}  // namespace
}  // namespace meshcast::testing
