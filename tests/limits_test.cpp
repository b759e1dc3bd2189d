// Meshes at the edge of each format's limits, and just beyond them: the
// edge must build, validate and return the oracle's answers; one more must
// be refused with an error that names the limit. (The zero-byte trees'
// limits: zerobyte_test; the StacklessLBVH depth limit: build_test.)
#include <gtest/gtest.h>

#include <cmath>

#include "check/generate.h"
#include "layout/blob_format.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

// The oracle's answers, and most rays hitting (misses prove little).
void expect_answers(const Mesh& mesh, const std::vector<uint8_t>& blob, const std::vector<Ray>& rays, const std::string& what) {
  EXPECT_GT(expect_oracle(mesh, blob, rays, trace_all(blob, rays), what), rays.size() / 2) << what << ": rays that miss prove little";
}

std::string refusal(const Mesh& mesh, const BuildOptions& o, const std::string& name) {
  try {
    build_blob(mesh, o, name);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(built)";
}

// 16-bit indices: a 255 x 255 grid has exactly 65,536 vertices, the most
// they reach; one vertex more is refused, naming the mesh and the limit.
TEST(Limits, SixteenBitIndicesTakeExactly65536Vertices) {
  Mesh edge = make_grid_plane(255, 255);
  ASSERT_EQ(edge.vertices.size(), 65536u);
  Mesh beyond = edge;
  beyond.vertices.push_back({0.5f, 0.25f, 1.0f});
  beyond.triangles.push_back({0, 1, 65536});
  std::vector<Ray> rays = make_rays(edge, RayKind::Long, 500, 7);
  for (int i = 0; i <= 255; i += 15)  // straight down onto shared vertices, up to the last one (index 65,535)
    rays.push_back({{float(i), float(255 - i), 3.0f}, {0, 0, -1}, INFINITY});
  rays.push_back({{255.0f, 255.0f, 3.0f}, {0, 0, -1}, INFINITY});
  rays.push_back({{254.5f, 254.75f, 3.0f}, {0, 0, -1}, INFINITY});
  std::vector<std::string> indexed16;
  for (const std::string& layout : layout_names())
    if (layout.find("Indexed16") != std::string::npos) indexed16.push_back(layout);
  EXPECT_GE(indexed16.size(), 30u) << "every tree with Indexed16, Indexed16SOA4 and Indexed16BitPackSOA4";
  for (const std::string& layout : covering_layouts(indexed16)) {
    BuildOptions o = parse_layout(layout);
    std::vector<uint8_t> blob = build_blob(edge, o, "grid255");
    ASSERT_EQ(layout::validate(blob), "") << layout;
    expect_answers(edge, blob, rays, layout + " at 65,536 vertices");
    std::string why = refusal(beyond, o, "grid255+1");
    EXPECT_NE(why.find("16-bit indices reach 65536 vertices"), std::string::npos) << layout << ": " << why;
    EXPECT_NE(why.find("grid255+1"), std::string::npos) << why;
  }
}

// Offsets at the edge of their field: QuadTree's child offsets have 27 bits
// (seed 000 5.6), and Float3SOA128 leaves of one triangle each take 4,608
// bytes, so about 29,000 triangles fill them. A mesh past them is refused
// naming the field; one that fills 99% of it builds, and rays onto every
// part of it (the last leaves sit at offsets near 2^27) return the oracle's
// answers.
TEST(Limits, QuadTreeOffsetsNearTheirTwentySevenBits) {
  const Mesh grid = make_grid_plane(130, 130);  // 33,800 triangles
  auto first = [&](size_t n) {
    Mesh m = grid;
    m.triangles.resize(n);
    return m;
  };
  BuildOptions o = parse_layout("QuadTree/Float3SOA128");
  o.leaf_size = 1;
  std::string why = refusal(grid, o, "grid130");
  ASSERT_NE(why.find("exceeds its 27-bit child offsets"), std::string::npos) << why;
  // The refusal names the bytes the section would take: scale down to just
  // inside the field.
  const double bytes = std::stod(why.substr(why.find("section of ") + 11));
  const size_t n = size_t(double(grid.triangles.size()) * double(MC_QUAD_OFFSET_MASK) / bytes * 0.995);
  Mesh edge = first(n);
  std::vector<uint8_t> blob = build_blob(edge, o, "grid130 part");
  ASSERT_EQ(layout::validate(blob), "");
  const uint32_t tree_size = layout::header_of(blob.data()).tree_size;
  EXPECT_GT(tree_size, 0.98 * MC_QUAD_OFFSET_MASK) << n << " triangles";
  EXPECT_LE(tree_size, MC_QUAD_OFFSET_MASK);
  std::vector<Ray> rays = make_rays(edge, RayKind::Long, 400, 3);
  for (size_t t = 0; t < n; t += 97) {  // straight down onto triangles across the whole mesh
    Vec3 a = edge.corner(t, 0), b = edge.corner(t, 1), c = edge.corner(t, 2);
    rays.push_back({{(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, 1.0f}, {0, 0, -1}, INFINITY});
  }
  expect_answers(edge, blob, rays, "QuadTree/Float3SOA128 near 2^27 bytes");
}

// A chain: triangle k sits at x = 2.05^(k - 96) (from 2^-99 to 2^99, inside
// the coordinate range), so the LongestAxis splitter (the middle of the
// centres' box) cuts off one triangle a level: the worst a splitter can do.
// The builder lets a splitter go kSplitterDepth (40) levels deep and splits
// at the median below, so no mesh under 2^24 triangles makes a tree deeper
// than the walkers' MC_MAX_DEPTH (64); a deeper blob is refused by
// validation (layout_test: DepthBeyondTheLimitIsRefused). Here the longest
// chain the coordinate range allows (193 triangles) makes the deepest trees
// a mesh of that size can: 40 levels of chain plus 8 of median splits in a
// binary tree. Each tree format must walk them right.
Mesh chain(int n) {
  Mesh m;
  for (int k = 0; k < n; ++k) {
    float x = float(std::pow(2.05, k - 96));
    uint32_t b = uint32_t(m.vertices.size());
    m.vertices.push_back({x, 0, 0});
    m.vertices.push_back({1.1f * x, 0, 0});
    m.vertices.push_back({x, 0.1f * x, 0});
    m.triangles.push_back({b, b + 1, b + 2});
  }
  return m;
}

TEST(Limits, TheDeepestTreesTheBuilderMakesWalkRight) {
  const int n = 193;
  Mesh m = chain(n);
  std::vector<Ray> rays;  // down onto every triangle, and along the chain
  for (size_t t = 0; t < m.triangles.size(); ++t) {
    Vec3 a = m.corner(t, 0);
    rays.push_back({{1.02f * a.x, 0.02f * a.x, 1.0f}, {0, 0, -1}, INFINITY});
  }
  rays.push_back({{-1.0f, 1e-30f, 0.0f}, {1, 0, 0}, INFINITY});
  for (const char* layout : {"AABBTree/Float3", "AABBTreeSplitAxis/Float3", "AABBTreePNS/Float3", "AABBTreeCompressed/Float3",
                             "SKDTree/Float3", "QuadTree/Float3", "QuadTreeHalfFloat/Float3"}) {
    BuildOptions o = parse_layout(layout);
    o.splitter = Splitter::LongestAxis;
    o.leaf_size = 1;
    std::vector<uint8_t> blob = build_blob(m, o, "chain");
    ASSERT_EQ(layout::validate(blob), "") << layout;
    const uint32_t depth = layout::header_of(blob.data()).max_depth;
    // The quad trees pull grandchildren up into 4-wide nodes and the
    // SKDTree places its own planes: shallower, still deep.
    const bool binary = uint32_t(o.layout.tree) != MC_TREE_QUADTREE && uint32_t(o.layout.tree) != MC_TREE_QUADTREEHALFFLOAT &&
                        uint32_t(o.layout.tree) != MC_TREE_SKDTREE;
    if (binary)
      EXPECT_EQ(depth, 48u) << layout;
    else
      EXPECT_GT(depth, 12u) << layout;
    EXPECT_LE(depth, MC_MAX_DEPTH) << layout;
    expect_answers(m, blob, rays, std::string(layout) + " chain of " + std::to_string(n));
  }
}

}  // namespace
}  // namespace meshcast::testing
