// Point queries (BlobView::closest_points) against the double-precision
// oracle of check/point_oracle.h, every triangle tried: on the recommended
// layout (quantized: judged on the mesh it stores, and against the input
// mesh within its stated bound) and on the exact OctTreeCompressed/Float3SOA8
// and OctTreeCompressed/ClusterFloat3SOA8.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include "check/generate.h"
#include "check/point_oracle.h"
#include "cpu/crossings.h"
#include "cpu/walk_points.h"
#include "meshcast/scene.h"
#include "meshcast/winding_number.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

// The compact cluster first, then the exact layouts: 8-wide float blocks,
// the exact cluster.
const char* const kPointLayouts[] = {"OctTreeCompressed/ClusterBitPackSOA8", "OctTreeCompressed/Float3SOA8",
                                     "OctTreeCompressed/ClusterFloat3SOA8"};

// Points of every kind a user asks about: scattered through the mesh's box
// grown by a fifth, just off the surface (a triangle's point moved along
// its normal by 10^-4 of the diagonal, either side), on corners and edge
// midpoints exactly, and far out (ten diagonals).
std::vector<Vec3> query_points(const Mesh& mesh, size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  const Box3 box = mesh.bounds();
  const double diagonal = box.diagonal();
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Vec3> points;
  for (size_t i = 0; i < count; ++i) {
    const size_t t = size_t(unit(rng) * double(mesh.triangles.size())) % mesh.triangles.size();
    const Vec3 a = mesh.corner(t, 0), b = mesh.corner(t, 1), c = mesh.corner(t, 2);
    Vec3 p;
    switch (i % 4) {
      case 0:
        for (int k = 0; k < 3; ++k) {
          const double grow = 0.2 * (box.max[k] - box.min[k]);
          p[k] = float(box.min[k] - grow + unit(rng) * (box.max[k] - box.min[k] + 2 * grow));
        }
        break;
      case 1: {
        double u = unit(rng), v = unit(rng);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        double n[3] = {(double(b.y) - a.y) * (double(c.z) - a.z) - (double(b.z) - a.z) * (double(c.y) - a.y),
                       (double(b.z) - a.z) * (double(c.x) - a.x) - (double(b.x) - a.x) * (double(c.z) - a.z),
                       (double(b.x) - a.x) * (double(c.y) - a.y) - (double(b.y) - a.y) * (double(c.x) - a.x)};
        const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const double off = (i % 8 == 1 ? 1e-4 : -1e-4) * diagonal / (length > 0 ? length : 1);
        for (int k = 0; k < 3; ++k) p[k] = float(a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]) + off * n[k]);
        break;
      }
      case 2:
        p = i % 8 == 2 ? a : Vec3{0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)};
        break;
      default:
        for (int k = 0; k < 3; ++k) p[k] = float(0.5 * (box.min[k] + box.max[k]) + 10 * diagonal * (2 * unit(rng) - 1));
    }
    points.push_back(p);
  }
  return points;
}

// float rounding of the answer (a few ulps of the distance) and of the
// double arithmetic on coordinates of magnitude `scale`.
double tolerance(double distance, double scale) { return 0x1p-21 * distance + 0x1p-40 * scale; }

// Each answer against the oracle over `reference` (the stored mesh): the
// least distance, a triangle at that distance, its point on that triangle
// and as far from the query point as said, the barycentrics naming it.
void expect_oracle(const Mesh& reference, const std::vector<Vec3>& points, const std::vector<ClosestPoint>& got,
                   const std::string& what) {
  const Box3 box = reference.bounds();
  size_t wrong = 0;
  std::string first;
  for (size_t i = 0; i < points.size(); ++i) {
    const double p[3] = {points[i].x, points[i].y, points[i].z};
    const OraclePoint want = oracle_closest_point(reference, p);
    double scale = 0;
    for (int k = 0; k < 3; ++k) scale = std::fmax(scale, std::fmax(std::fabs(p[k]), std::fmax(std::fabs(box.min[k]), std::fabs(box.max[k]))));
    const double tol = tolerance(want.distance, scale);
    const ClosestPoint& g = got[i];
    std::string problem;
    if (g.triangle >= reference.triangles.size()) {
      problem = "no triangle";
    } else {
      double near[3];
      const double own = oracle_point_triangle(p, reference.corner(g.triangle, 0), reference.corner(g.triangle, 1),
                                               reference.corner(g.triangle, 2), near);
      double from_point = 0, from_uv = 0;
      for (int k = 0; k < 3; ++k) {
        from_point += (double(g.point[k]) - p[k]) * (double(g.point[k]) - p[k]);
        const double uv = (1.0 - g.u - g.v) * reference.corner(g.triangle, 0)[k] + double(g.u) * reference.corner(g.triangle, 1)[k] +
                          double(g.v) * reference.corner(g.triangle, 2)[k];
        from_uv = std::fmax(from_uv, std::fabs(uv - g.point[k]));
      }
      if (std::fabs(g.distance - want.distance) > tol)
        problem = "distance " + std::to_string(g.distance) + ", the oracle's " + std::to_string(want.distance);
      else if (std::fabs(own - want.distance) > tol)
        problem = "triangle " + std::to_string(g.triangle) + " lies " + std::to_string(own) + " away, the nearest " +
                  std::to_string(want.distance);
      else if (std::fabs(std::sqrt(from_point) - g.distance) > tol + 0x1p-22 * scale)
        problem = "the point lies " + std::to_string(std::sqrt(from_point)) + " away, not " + std::to_string(g.distance);
      else if (from_uv > 0x1p-20 * scale)
        problem = "u, v name a point " + std::to_string(from_uv) + " off the one given";
    }
    if (!problem.empty() && wrong++ == 0) first = "point " + std::to_string(i) + ": " + problem;
  }
  EXPECT_EQ(wrong, 0u) << what << ": " << first;
}

TEST(ClosestPoints, AgreeWithTheOracleOnEveryTestMesh) {
  for (const char* layout : kPointLayouts)
    for (const NamedMesh& m : test_meshes(false)) {
      if (m.name == "armadillo" || m.name == "refined_elephant") continue;  // bunny00 and the dragon suffice
      const std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout), m.name);
      const BlobView view(blob, m.name);
      const Mesh reference = stored_mesh(blob);
      const std::vector<Vec3> points = query_points(*m.mesh, quick() ? 150 : 300, 7);
      std::vector<ClosestPoint> got(points.size());
      EXPECT_EQ(view.closest_points(points, got), 0u);
      expect_oracle(reference, points, got, std::string(layout) + " on " + m.name);
    }
}

// The quantized layout's distances are the input mesh's within its stated
// bound (a fraction of the diagonal), as its rays' are.
TEST(ClosestPoints, QuantizedDistancesWithinTheStatedBound) {
  for (const NamedMesh& m : test_meshes(false)) {
    if (!is_chosen_public_mesh(m.name) && m.name != "sphere") continue;
    const std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(kPointLayouts[0]), m.name);
    const double diagonal = m.mesh->bounds().diagonal();
    const double bound = relative_error_bound(blob, diagonal) * diagonal;
    EXPECT_GT(bound, 0) << m.name;
    const std::vector<Vec3> points = query_points(*m.mesh, 200, 11);
    std::vector<ClosestPoint> got(points.size());
    BlobView(blob, m.name).closest_points(points, got);
    for (size_t i = 0; i < points.size(); ++i) {
      const double p[3] = {points[i].x, points[i].y, points[i].z};
      const double exact = oracle_closest_point(*m.mesh, p).distance;
      EXPECT_LE(std::fabs(got[i].distance - exact), bound + tolerance(exact, 10 * diagonal)) << m.name << ", point " << i;
    }
  }
}

TEST(ClosestPoints, TheLimitIncludedAndNothingBeyondIt) {
  const Mesh grid = make_grid_plane(2, 2);  // z = 0 over [0, 2] x [0, 2]
  const std::vector<uint8_t> blob = build_blob(grid, parse_layout(kPointLayouts[1]), "grid");
  const BlobView view(blob, "grid");
  const std::vector<Vec3> points = {{1, 1, 0.5f}, {1, 1, 0.25f}, {1, 1, 0}, {3, 1, 0}, {1, 1, -0.75f}};
  std::vector<ClosestPoint> got(points.size());
  view.closest_points(points, got, 0.5f);
  EXPECT_EQ(got[0].distance, 0.5f);  // exactly at the limit: found
  EXPECT_EQ(got[1].distance, 0.25f);
  EXPECT_EQ(got[2].distance, 0.0f);
  EXPECT_EQ(got[3].triangle, kNoHit);  // 1 away
  EXPECT_EQ(got[3].distance, INFINITY);
  EXPECT_EQ(got[4].triangle, kNoHit);
  view.closest_points(points, got, 0.0f);
  EXPECT_EQ(got[2].distance, 0.0f);
  EXPECT_EQ(got[0].triangle, kNoHit);
}

TEST(ClosestPoints, RefusesWhatItCannotAnswer) {
  const Mesh sphere = make_sphere(8, 16, 1, {0, 0, 0});
  const std::vector<uint8_t> other = build_blob(sphere, parse_layout("AABBTree/Float3"), "sphere");
  std::vector<Vec3> points = {{0, 0, 0}, {NAN, 0, 0}, {0, INFINITY, 0}, {2, 0, 0}};
  std::vector<ClosestPoint> got(points.size());
  try {
    BlobView(other, "sphere").closest_points(points, got);
    FAIL() << "another tree format was walked";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("AABBTree/Float3"), std::string::npos) << e.what();
  }
  const std::vector<uint8_t> blob = build_blob(sphere, parse_layout(kPointLayouts[0]), "sphere");
  const BlobView view(blob, "sphere");
  std::vector<ClosestPoint> short_out(3);
  EXPECT_THROW(view.closest_points(points, short_out), UsageError);
  EXPECT_THROW(view.closest_points(points, got, NAN), UsageError);
  EXPECT_THROW(view.closest_points(points, got, -1.0f), UsageError);
  EXPECT_EQ(view.closest_points(points, got), 2u);  // NaN and infinity: counted, answered as none
  EXPECT_EQ(got[1].triangle, kNoHit);
  EXPECT_EQ(got[2].distance, INFINITY);
  EXPECT_NEAR(got[0].distance, 1.0, 0.05);
  EXPECT_NEAR(got[3].distance, 1.0, 0.05);
}

// The walk takes the points along a Morton curve, each from its
// predecessor's answer: no answer may depend on that. The same points
// asked in reverse, and one at a time, get the same bits, ties included
// (points on a grid's vertices and edges, where several triangles lie at
// one distance, go to the lower triangle number); in a scene too.
TEST(ClosestPoints, AnswersDoNotDependOnThePointsOrder) {
  const Mesh grid = make_grid_plane(12, 10);
  std::vector<Vec3> points = query_points(grid, 400, 3);
  for (const Vec3& v : grid.vertices) points.push_back({v.x, v.y, v.z + 0.25f});  // above a vertex: 6 triangles tie
  for (const char* layout : kPointLayouts) {
    const std::vector<uint8_t> blob = build_blob(grid, parse_layout(layout), "grid");
    const BlobView view(blob, "grid");
    std::vector<ClosestPoint> forward(points.size()), backward(points.size()), alone(points.size());
    view.closest_points(points, forward);
    const std::vector<Vec3> reversed(points.rbegin(), points.rend());
    view.closest_points(reversed, backward);
    std::reverse(backward.begin(), backward.end());
    for (size_t i = 0; i < points.size(); ++i) view.closest_points(std::span<const Vec3>(&points[i], 1), std::span<ClosestPoint>(&alone[i], 1));
    for (size_t i = 0; i < points.size(); ++i)
      for (const std::vector<ClosestPoint>* other : {&backward, &alone}) {
        const ClosestPoint &a = forward[i], &b = (*other)[i];
        ASSERT_EQ(a.triangle, b.triangle) << layout << " point " << i;
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << layout << " point " << i;
      }
    Scene scene;
    const MeshId mesh = scene.add_mesh(blob, "grid");
    Transform above;
    above.translation[2] = 0.5;
    scene.add_instance(mesh, Transform{});
    scene.add_instance(mesh, above);
    scene.commit();
    std::vector<std::array<double, 3>> world;
    for (const Vec3& p : points) world.push_back({p.x, p.y, p.z});
    std::vector<SceneClosestPoint> in_order(world.size()), reverse_order(world.size());
    scene.closest_points(world, in_order);
    const std::vector<std::array<double, 3>> world_reversed(world.rbegin(), world.rend());
    scene.closest_points(world_reversed, reverse_order);
    std::reverse(reverse_order.begin(), reverse_order.end());
    for (size_t i = 0; i < world.size(); ++i) {
      ASSERT_EQ(in_order[i].instance, reverse_order[i].instance) << layout << " point " << i;
      ASSERT_EQ(in_order[i].triangle, reverse_order[i].triangle) << layout << " point " << i;
      ASSERT_EQ(in_order[i].distance, reverse_order[i].distance) << layout << " point " << i;
    }
  }
}

// Triangles of no area (corners on a line, or at one point) have their
// nearest point on their edges; a triangle twice over answers with the
// lower number; far from the origin the distances stay the stored mesh's.
TEST(ClosestPoints, DegenerateRepeatedAndFarOutTriangles) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {5, 5, 5}, {0, 0, 3}, {1, 0, 3}, {0, 1, 3}};
  m.triangles = {{0, 1, 2}, {4, 4, 4}, {0, 1, 3}, {5, 6, 7}, {5, 6, 7}};
  for (const char* layout : kPointLayouts) {
    for (float shift : {0.0f, 1e4f}) {
      Mesh moved = m;
      for (Vec3& v : moved.vertices) v.x += shift, v.y -= shift;
      const std::vector<uint8_t> blob = build_blob(moved, parse_layout(layout), "degenerate");
      const BlobView view(blob, "degenerate");
      const std::vector<Vec3> points = {{3 + shift, 0 - shift, 0},   {5 + shift, 6 - shift, 5}, {0.2f + shift, 0.2f - shift, 2},
                                        {1.5f + shift, -1 - shift, 0}, {0.25f + shift, 0.25f - shift, 0.5f}};
      std::vector<ClosestPoint> got(points.size());
      view.closest_points(points, got);
      const std::string what = std::string(layout) + ", shifted " + std::to_string(shift);
      expect_oracle(stored_mesh(blob), points, got, what);
      EXPECT_EQ(got[2].triangle, 3u) << what << ": the lower of the two copies";
      EXPECT_EQ(got[1].triangle, 1u) << what << ": the triangle at one point";
    }
  }
}

// The leaves' nearest points, 8 triangles side by side on each
// instruction set this processor runs, carry nearest_on_triangle's bits:
// points in every region of a triangle (its corners, edges and inside,
// and exactly on them), slivers, triangles of no area (on a line, at one
// point), and groups of every size from 1 to 19 (partial lane groups).
TEST(ClosestPoints, EverySetsLanesGiveTheScalarBits) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<std::array<std::array<double, 3>, 3>> triangles;
  std::vector<std::array<double, 3>> points;
  for (int i = 0; i < 600; ++i) {
    std::array<std::array<double, 3>, 3> t;
    for (auto& corner : t)
      for (double& x : corner) x = double(float(unit(rng)));
    switch (i % 6) {
      case 1: t[2] = t[1]; break;                                              // two corners at one point
      case 2: t[1] = t[0], t[2] = t[0]; break;                                 // all at one point
      case 3: for (int k = 0; k < 3; ++k) t[2][k] = 2 * t[1][k] - t[0][k]; break;  // on a line
      case 4: for (int k = 0; k < 3; ++k) t[2][k] = t[1][k] + 1e-7 * t[0][k]; break;  // a sliver
      default: break;
    }
    triangles.push_back(t);
    std::array<double, 3> p;
    for (double& x : p) x = 3 * unit(rng);
    if (i % 5 == 0) p = t[i % 3];                                               // on a corner
    if (i % 5 == 1) for (int k = 0; k < 3; ++k) p[k] = 0.5 * (t[0][k] + t[1][k]);  // on an edge
    points.push_back(p);
  }
  const WalkerIsa sets[] = {WalkerIsa::Scalar, WalkerIsa::Avx2, WalkerIsa::Avx512};
  int tried = 0;
  for (const WalkerIsa isa : sets) {
    const NearestOnTrianglesFn nearest = nearest_on_triangles_of(isa);
    if (!nearest) continue;
    ++tried;
    size_t at = 0;
    for (uint32_t n = 1; at + n <= triangles.size(); n = n % 19 + 1) {
      for (size_t j = at; j < at + n; ++j) {
        // Each point against its own group of n triangles.
        double corners[19][3][3];
        for (uint32_t i = 0; i < n; ++i)
          for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) corners[i][c][k] = triangles[at + i][c][k];
        PointOnTriangle got[19];
        nearest(points[j].data(), corners, n, got);
        for (uint32_t i = 0; i < n; ++i) {
          const PointOnTriangle want = nearest_on_triangle(points[j].data(), corners[i][0], corners[i][1], corners[i][2]);
          const std::string what = std::string(walker_isa_name(isa)) + ", triangle " + std::to_string(at + i) +
                                   " in a group of " + std::to_string(n) + ", point " + std::to_string(j);
          ASSERT_EQ(std::memcmp(&got[i].d2, &want.d2, 8), 0) << what << ": " << got[i].d2 << " != " << want.d2;
          ASSERT_EQ(std::memcmp(&got[i].u, &want.u, 8), 0) << what;
          ASSERT_EQ(std::memcmp(&got[i].v, &want.v, 8), 0) << what;
          ASSERT_EQ(std::memcmp(got[i].point, want.point, 24), 0) << what;
        }
      }
      at += n;
    }
  }
  EXPECT_GE(tried, 1);
}

}  // namespace
}  // namespace meshcast::testing

namespace meshcast::testing {
namespace {

// The crossings behind signed distances: odd from inside a closed mesh,
// even from outside, on rays through the triangles' insides, through
// shared vertices and, from outside, in at one vertex and out at its
// opposite; the winding either way.
TEST(Crossings, ParityTellsInsideFromOutsideThroughVertices) {
  const Vec3 centre{0.25f, -0.5f, 1.0f};
  Mesh sphere = make_sphere(8, 16, 2.0f, centre);
  for (bool flip : {false, true}) {
    if (flip)
      for (Triangle& t : sphere.triangles) std::swap(t[1], t[2]);
    const std::vector<uint8_t> blob = build_blob(sphere, parse_layout(kPointLayouts[0]), "sphere");
    const BlobView view(blob, "sphere");
    std::vector<Ray> rays;
    std::vector<uint32_t> want;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(-1, 1);
    for (int i = 0; i < 400; ++i) {
      const float scale = i % 2 ? 1.5f : 3.0f;  // inside (within the inscribed sphere) or out beyond it
      const Vec3 o{centre.x + scale * unit(rng), centre.y + scale * unit(rng), centre.z + scale * unit(rng)};
      const double r = std::sqrt(double(o.x - centre.x) * (o.x - centre.x) + double(o.y - centre.y) * (o.y - centre.y) +
                                 double(o.z - centre.z) * (o.z - centre.z));
      if (r > 1.5 && r < 2.05) continue;  // between the inscribed and circumscribed spheres: either
      rays.push_back({{o.x, o.y, o.z}, {unit(rng), unit(rng), unit(rng)}, INFINITY});
      want.push_back(r < 1.5 ? 1 : 0);
    }
    for (size_t v = 0; v < sphere.vertices.size(); ++v) {
      const Vec3 p = sphere.vertices[v];
      const float d[3] = {p.x - centre.x, p.y - centre.y, p.z - centre.z};
      rays.push_back({{centre.x, centre.y, centre.z}, {d[0], d[1], d[2]}, INFINITY});  // out through the vertex
      want.push_back(1);
      rays.push_back({{centre.x + 2 * d[0], centre.y + 2 * d[1], centre.z + 2 * d[2]}, {-d[0], -d[1], -d[2]}, INFINITY});
      want.push_back(0);  // in at the vertex, out at its opposite
    }
    std::vector<uint32_t> counts(rays.size());
    EXPECT_EQ(count_crossings(view, rays, counts), 0u);
    size_t wrong = 0;
    std::string first;
    for (size_t i = 0; i < rays.size(); ++i)
      if (counts[i] % 2 != want[i] && wrong++ == 0) first = "ray " + std::to_string(i) + ": " + std::to_string(counts[i]);
    EXPECT_EQ(wrong, 0u) << (flip ? "wound inward: " : "wound outward: ") << first;
    EXPECT_THROW(count_crossings(view, rays, std::span(counts).first(1)), UsageError);
  }
}

// Winding numbers: within their stated bound of the oracle's exact sum
// over the stored triangles (Girard's formula, every triangle), on a
// closed sphere, an open grid and a public mesh in both point layouts;
// and the inside test equal to the oracle's |w| > 1/2 wherever that is not
// within rounding of 1/2.
TEST(WindingNumbers, WithinTheirBoundOfTheOracle) {
  for (const char* layout : kPointLayouts)
    for (const NamedMesh& m : test_meshes(false)) {
      if (m.name != "sphere" && m.name != "grid_plane" && !is_chosen_public_mesh(m.name)) continue;
      const std::vector<uint8_t> blob = build_blob(*m.mesh, parse_layout(layout), m.name);
      const BlobView view(blob, m.name);
      const Mesh reference = stored_mesh(blob);
      const WindingNumbers winding(view);
      const std::vector<Vec3> points = query_points(*m.mesh, is_chosen_public_mesh(m.name) ? 60 : 200, 9);
      std::vector<WindingNumbers::Answer> got(points.size());
      std::vector<uint8_t> inside(points.size());
      std::vector<WindingNumbers::Answer> loose(points.size());
      winding.evaluate(points, got);
      winding.evaluate(points, loose, 0.3);
      winding.inside(points, inside);
      const double diagonal = reference.bounds().diagonal();
      size_t wrong = 0, expanded = 0;
      std::string first;
      for (size_t i = 0; i < points.size(); ++i) {
        const double p[3] = {points[i].x, points[i].y, points[i].z};
        // On the surface (a corner, an edge's midpoint) a winding number
        // is any of the values about it.
        if (oracle_closest_point(reference, p).distance < 1e-6 * diagonal) continue;
        const double want = oracle_winding_number(reference, p);
        // Double's rounding of two sums of solid angles, each within a few
        // ulps of pi a triangle.
        const double rounding = 1e-14 * double(reference.triangles.size());
        expanded += got[i].bound > 0;
        std::string problem;
        if (!(std::fabs(got[i].w - want) <= got[i].bound + rounding))
          problem = "w " + std::to_string(got[i].w) + " +- " + std::to_string(got[i].bound) + ", the oracle's " +
                    std::to_string(want);
        else if (!(std::fabs(loose[i].w - want) <= loose[i].bound + rounding))
          problem = "at tolerance 0.3, w " + std::to_string(loose[i].w) + " +- " + std::to_string(loose[i].bound) +
                    ", the oracle's " + std::to_string(want);
        else if (std::fabs(std::fabs(want) - 0.5) > rounding && inside[i] != (std::fabs(want) > 0.5))
          problem = "inside " + std::to_string(inside[i]) + " where the oracle's w is " + std::to_string(want);
        else if (std::fabs(winding.exact(points[i]) - want) > rounding)
          problem = "the exact sum " + std::to_string(winding.exact(points[i])) + ", the oracle's " + std::to_string(want);
        if (!problem.empty() && wrong++ == 0) first = "point " + std::to_string(i) + ": " + problem;
      }
      EXPECT_EQ(wrong, 0u) << layout << " on " << m.name << ": " << first;
      // The far points (a quarter of them) are the expansion's.
      EXPECT_GE(expanded, points.size() / 5) << layout << " on " << m.name;
    }
}

TEST(WindingNumbers, RefusesWhatItCannotAnswer) {
  const Mesh sphere = make_sphere(6, 8, 1.0f, Vec3{0, 0, 0});
  const std::vector<uint8_t> other = build_blob(sphere, parse_layout("AABBTree/Float3"), "sphere");
  EXPECT_THROW(WindingNumbers(BlobView(other, "sphere")), UsageError);
  const std::vector<uint8_t> blob = build_blob(sphere, parse_layout(kPointLayouts[0]), "sphere");
  const BlobView view(blob, "sphere");
  const WindingNumbers winding(view);
  const std::vector<Vec3> points = {{0, 0, 0}, {NAN, 0, 0}};
  std::vector<WindingNumbers::Answer> got(1);
  EXPECT_THROW(winding.evaluate(points, got), UsageError);
  got.resize(2);
  EXPECT_THROW(winding.evaluate(points, got, 0.0), UsageError);
  EXPECT_THROW(winding.evaluate(points, got, NAN), UsageError);
  EXPECT_THROW(winding.evaluate(points, got, 1.0), UsageError);
  winding.evaluate(points, got);
  EXPECT_NEAR(got[0].w, 1.0, 1e-9);  // the centre of a closed sphere wound outward
  EXPECT_TRUE(std::isnan(got[1].w));
}

}  // namespace
}  // namespace meshcast::testing

namespace meshcast::testing {
namespace {

// Scene::closest_points against the oracle over the world's triangles:
// every instance's stored triangles placed by its own transform (a
// rotation, a scale uneven across axes, a mirror), in double. The
// distances are the world's, not the frames' (a local walk would answer
// distances scaled by each axis differently).
TEST(SceneClosestPoints, WorldDistancesUnderUnevenScales) {
  const Mesh sphere = make_sphere(12, 24, 1.0f, Vec3{0.1f, -0.2f, 0.3f});
  const Mesh grid = make_grid_plane(12, 10);
  Scene scene;
  std::vector<std::vector<uint8_t>> blobs;
  std::vector<Mesh> stored;
  std::vector<MeshId> mesh_ids;
  for (const Mesh* m : {&sphere, &grid}) {
    blobs.push_back(build_blob(*m, parse_layout(kPointLayouts[blobs.size() % 2]), "mesh"));
    stored.push_back(stored_mesh(blobs.back()));
    mesh_ids.push_back(scene.add_mesh(blobs.back(), "mesh " + std::to_string(blobs.size() - 1)));
  }
  // The world, as the oracle sees it, and which instance and triangle
  // each of its triangles is.
  Mesh world;
  std::vector<std::pair<uint32_t, uint32_t>> owner;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> angle(0, 6.283), scale(0.3, 3.0), spot(-8, 8);
  for (uint32_t i = 0; i < 8; ++i) {
    const uint32_t mesh = i % 2;
    const double a = angle(rng), s[3] = {scale(rng), scale(rng), scale(rng)};
    const double rotation[9] = {std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1};
    Transform t;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) t.rotation_scale[3 * r + c] = float(rotation[3 * r + c] * s[c] * (i == 3 && c == 0 ? -1 : 1));
    for (int k = 0; k < 3; ++k) t.translation[k] = spot(rng);
    const uint8_t mask = i == 5 ? 2 : 1;  // instance 5 is seen only by mask 2
    const InstanceId id = scene.add_instance(mesh_ids[mesh], t, mask);
    if (mask != 1) continue;
    const Mesh& m = stored[mesh];
    for (size_t tri = 0; tri < m.triangles.size(); ++tri) {
      Triangle placed;
      for (int corner = 0; corner < 3; ++corner) {
        const Vec3 x = m.corner(tri, corner);
        Vec3 w;
        for (int r = 0; r < 3; ++r)
          w[r] = float(t.translation[r] + double(t.rotation_scale[3 * r]) * x.x + double(t.rotation_scale[3 * r + 1]) * x.y +
                       double(t.rotation_scale[3 * r + 2]) * x.z);
        placed[corner] = uint32_t(world.vertices.size());
        world.vertices.push_back(w);
      }
      world.triangles.push_back(placed);
      owner.push_back({id.index, uint32_t(tri)});
    }
  }
  scene.commit();
  std::vector<std::array<double, 3>> points;
  std::uniform_real_distribution<double> around(-14, 14);
  for (int i = 0; i < 300; ++i) points.push_back({around(rng), around(rng), i % 3 ? around(rng) * 0.2 : around(rng)});
  points.push_back({NAN, 0, 0});
  std::vector<SceneClosestPoint> got(points.size());
  EXPECT_EQ(scene.closest_points(points, got, INFINITY, 1), 1u);
  size_t wrong = 0;
  std::string first;
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const double p[3] = {points[i][0], points[i][1], points[i][2]};
    const OraclePoint want = oracle_closest_point(world, p);
    const SceneClosestPoint& g = got[i];
    // The world corners the oracle holds are float roundings of the
    // placed ones (about 1e-6 at these coordinates), and the scene places
    // them through the float inverse's inverse.
    const double tol = 1e-5 * (1 + want.distance);
    std::string problem;
    size_t index = 0;
    while (index < owner.size() && owner[index] != std::make_pair(g.instance, g.triangle)) ++index;
    if (index == owner.size()) {
      problem = "instance " + std::to_string(g.instance) + " triangle " + std::to_string(g.triangle) + " is not one seen";
    } else {
      double near[3];
      const double own = oracle_point_triangle(p, world.corner(index, 0), world.corner(index, 1), world.corner(index, 2), near);
      double from_point = 0;
      for (int k = 0; k < 3; ++k) from_point += (g.point[k] - p[k]) * (g.point[k] - p[k]);
      if (std::fabs(g.distance - want.distance) > tol)
        problem = "distance " + std::to_string(g.distance) + ", the oracle's " + std::to_string(want.distance);
      else if (std::fabs(own - want.distance) > tol)
        problem = "its triangle lies " + std::to_string(own) + " away, the nearest " + std::to_string(want.distance);
      else if (std::fabs(std::sqrt(from_point) - g.distance) > tol)
        problem = "the point lies " + std::to_string(std::sqrt(from_point)) + " away, not " + std::to_string(g.distance);
    }
    if (!problem.empty() && wrong++ == 0) first = "point " + std::to_string(i) + ": " + problem;
  }
  EXPECT_EQ(wrong, 0u) << first;
  // Mask 2 sees instance 5 alone; a limit leaves the far points out.
  std::vector<SceneClosestPoint> masked(points.size());
  scene.closest_points(points, masked, 2.0, 2);
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    EXPECT_TRUE(masked[i].instance == 5u || masked[i].instance == kNoHit) << i;
    EXPECT_TRUE(masked[i].distance <= 2.0 || masked[i].triangle == kNoHit) << i;
  }
  EXPECT_THROW(scene.closest_points(points, std::span(got).first(3)), UsageError);
  EXPECT_THROW(scene.closest_points(points, got, NAN), UsageError);
  Scene other;
  other.add_instance(other.add_mesh(build_blob(grid, parse_layout("AABBTree/Float3"), "grid"), "grid"), Transform{});
  other.commit();
  EXPECT_THROW(other.closest_points(points, got), UsageError);
}

}  // namespace
}  // namespace meshcast::testing
