// Triangle pairing (seed 003): the greedy scan on the seed's own worked
// example, complete pairing of quad meshes, the pre-scan's decision, and the
// compressed position keys against the index keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <set>

#include "builder/pairing.h"
#include "check/generate.h"
#include "layout/blob_format.h"
#include "layout/tree/leaves.h"
#include "layout/triangles/pairsoa.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

bool share_edge(const Mesh& m, uint32_t a, uint32_t b) {
  int shared = 0;
  for (uint32_t i : m.triangles[a])
    for (uint32_t j : m.triangles[b]) shared += i == j;
  return shared >= 2;
}

// Every pair is mutual and shares an edge.
void expect_valid(const Mesh& m, const Pairing& p) {
  ASSERT_EQ(p.partner.size(), m.triangles.size());
  for (uint32_t t = 0; t < p.partner.size(); ++t) {
    const uint32_t q = p.partner[t];
    if (q == MC_NO_HIT) continue;
    ASSERT_LT(q, m.triangles.size());
    EXPECT_EQ(p.partner[q], t);
    EXPECT_TRUE(share_edge(m, t, q)) << t << " and " << q;
  }
}

// The seed's table (6 vertices, 5 triangles), as the seed lists it before
// sorting; its scan accepts (2, 3) on the 30-area edge 2-4 and (0, 4) on
// 0-2, and rejects 1-2, 2-5 and 2-3 because a triangle is taken.
TEST(Pairing, TheSeedsWorkedExample) {
  const float area[] = {0, 15, 20, 10, 10, 15, 0, 30, 10, 18, 9, 30, 20, 20, 9};
  const uint32_t first[] = {0, 1, 0, 1, 2, 1, 4, 2, 2, 3, 2, 2, 0, 0, 2};
  const uint32_t second[] = {1, 2, 2, 5, 5, 2, 5, 4, 5, 4, 3, 4, 3, 2, 3};
  const uint32_t triangle[] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4};
  std::vector<HalfEdge> table;
  for (int i = 0; i < 15; ++i) table.push_back({area[i], first[i], second[i], triangle[i]});
  std::vector<uint32_t> partner = greedy_pairs(table, 5);
  EXPECT_EQ(partner, (std::vector<uint32_t>{4, MC_NO_HIT, 3, 2, 0}));
}

TEST(Pairing, AQuadGridPairsCompletelyAlongItsDiagonals) {
  Mesh m = make_grid_plane(40, 30);
  PairingOptions always;
  always.skip_above = 2;  // never skip: the pass itself
  Pairing p = pair_triangles(m, always);
  EXPECT_TRUE(p.ran);
  EXPECT_EQ(p.pairs, m.triangles.size() / 2);
  expect_valid(m, p);
  // The diagonals' boxes are the only ones with area: each quad pairs with itself.
  for (uint32_t t = 0; t < m.triangles.size(); ++t) EXPECT_EQ(p.partner[t], t ^ 1u) << t;
}

TEST(Pairing, ThePrescanSkipsWellPairedInputAndRunsOnScrambledInput) {
  Mesh grid = make_grid_plane(20, 20);
  Pairing kept = pair_triangles(grid);
  EXPECT_FALSE(kept.ran);
  EXPECT_DOUBLE_EQ(kept.prescan_ratio, 1.0);
  EXPECT_NE(kept.decision.find("skipped"), std::string::npos) << kept.decision;
  expect_valid(grid, kept);

  Mesh scrambled = make_sphere(24, 48, 1, {0, 0, 0});
  std::mt19937 rng(7);
  std::shuffle(scrambled.triangles.begin(), scrambled.triangles.end(), rng);
  Pairing p = pair_triangles(scrambled);
  EXPECT_TRUE(p.ran) << p.decision;
  EXPECT_LT(p.prescan_ratio, 0.1);
  EXPECT_GT(p.paired_ratio, 0.9);
  expect_valid(scrambled, p);
}

// Without vertex indices (every triangle its own three vertices) the
// compressed keys find as many pairs, each sharing an edge by position.
TEST(Pairing, CompressedPositionKeysPairAnUnweldedMesh) {
  Mesh welded = make_sphere(24, 48, 1, {0.5f, -0.25f, 3.0f});
  std::mt19937 rng(11);
  std::shuffle(welded.triangles.begin(), welded.triangles.end(), rng);
  Mesh soup;
  for (const Triangle& t : welded.triangles) {
    const uint32_t base = uint32_t(soup.vertices.size());
    for (uint32_t v : t) soup.vertices.push_back(welded.vertices[v]);
    soup.triangles.push_back({base, base + 1, base + 2});
  }
  Pairing by_index = pair_triangles(welded);
  PairingOptions positions;
  positions.by_position = true;
  Pairing by_position = pair_triangles(soup, positions);
  EXPECT_EQ(pair_triangles(soup).pairs, 0u);  // no shared indices: the index keys find nothing
  EXPECT_GE(by_position.pairs + soup.triangles.size() / 100, by_index.pairs);
  for (uint32_t t = 0; t < soup.triangles.size(); ++t) {
    const uint32_t q = by_position.partner[t];
    if (q == MC_NO_HIT) continue;
    EXPECT_EQ(by_position.partner[q], t);
    int shared = 0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const Vec3 a = soup.corner(t, i), b = soup.corner(q, j);
        shared += a.x == b.x && a.y == b.y && a.z == b.z;
      }
    EXPECT_GE(shared, 2) << t << " and " << q;
  }
}

// Pairs as the builder's unit: every tree built from pairs keeps each
// pair in one leaf, leaves within the leaf size, and the oracle's answers,
// on every test mesh and ray kind, with four encodings (the pair blocks
// among them).
TEST(PairedTrees, LeavesHoldWholePairsAndWalkersAgreeWithTheOracle) {
  for (const NamedMesh& m : test_meshes(false)) {
    const Pairing pairs = pair_triangles(*m.mesh);
    for (const std::string& name : layout_names()) {
      BuildOptions o = parse_layout(name);
      if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE || uint32_t(o.layout.tree) == MC_TREE_AABBLIST) continue;
      if (uint32_t(o.layout.triangles) != MC_TRI_FLOAT3 && uint32_t(o.layout.triangles) != MC_TRI_FLOAT3SOA4 &&
          uint32_t(o.layout.triangles) != MC_TRI_INDEXED8BITPACKSOA4 && uint32_t(o.layout.triangles) != MC_TRI_FLOAT3PAIRSOA4)
        continue;
      if (uint32_t(o.layout.tree) == MC_TREE_ZEROBYTE || uint32_t(o.layout.tree) == MC_TREE_ZEROBYTEHYBRID) continue;
      o.pairing = true;
      BuildReport report;
      std::vector<uint8_t> blob = build_blob(*m.mesh, o, m.name, &report);
      EXPECT_FALSE(report.pairing.empty());
      const layout::BlobHeader& h = layout::header_of(blob.data());
      std::vector<uint32_t> leaf_of(m.mesh->triangles.size(), ~0u);
      uint32_t leaf = 0, split = 0;
      layout::for_each_leaf(blob.data(), [&](uint32_t block, uint32_t count) {
        EXPECT_LE(count, uint32_t(o.layout.tree) == MC_TREE_STACKLESSLBVH ? MC_QUAD_MAX_COUNT - 1 : o.leaf_size) << name;
        for (uint32_t i = 0; i < count; ++i) leaf_of[layout::remap_entry(blob.data(), h, layout::slot_of(h, block, i))] = leaf;
        ++leaf;
      });
      for (uint32_t t = 0; t < pairs.partner.size(); ++t)
        split += pairs.partner[t] != MC_NO_HIT && leaf_of[t] != leaf_of[pairs.partner[t]];
      EXPECT_EQ(split, 0u) << name << " on " << m.name << ": pairs split across leaves";
      NamedMesh reference = m;
      if (moves_vertices(uint32_t(o.layout.triangles)))
        reference = {m.name + "#paired#" + name, std::make_shared<const Mesh>(stored_mesh(blob))};
      for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
        const std::vector<Ray>& rays = test_rays(m, kind, 2000);
        Agreement a = compare(*reference.mesh, rays, trace_all(blob, rays), oracle_answers(reference, kind, rays),
                              1e-5 * m.mesh->bounds().diagonal());
        EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << name << " on " << m.name << " kind " << int(kind) << ": " << a.first_problem;
      }
    }
  }
}

TEST(PairedTrees, WhatCannotPairIsRefusedWithTheReason) {
  Mesh m = make_sphere(8, 16, 1, {0, 0, 0});
  BuildOptions o = parse_layout("BruteForce/Float3");
  o.pairing = true;
  try {
    build_blob(m, o, "sphere");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("keeps its own triangle order"), std::string::npos) << e.what();
  }
  o = parse_layout("AABBTree/Float3");
  o.pairing = true, o.leaf_size = 1;
  EXPECT_THROW(build_blob(m, o, "sphere"), InputError);
}

}  // namespace
}  // namespace meshcast::testing

// Float3PairSOA4 (layout/triangles/pairsoa.h): a quad's two triangles become one lane
// of 4 corners, the second stored as (B, A, D) after the first (A, B, C);
// the header says lane 0 is used and holds a pair; a header with bits no
// block may hold is refused.
namespace meshcast::testing {
namespace {
TEST(PairBlocks, AQuadIsOneLaneOfFourCorners) {
  Mesh quad;
  quad.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.triangles = {Triangle{0, 1, 2}, Triangle{0, 2, 3}};  // shared edge 0-2, met as (2, 0) in the first
  std::vector<uint8_t> blob = build_blob(quad, parse_layout("AABBTree/Float3PairSOA4"), "quad");
  uint32_t leaf_block = 0, leaf_count = 0;
  layout::for_each_leaf(blob.data(), [&](uint32_t block, uint32_t count) { leaf_block = block, leaf_count = count; });
  ASSERT_EQ(leaf_count, 2u);
  const layout::BlobHeader& h = layout::header_of(blob.data());
  const uint8_t* p = blob.data() + h.tree_offset + leaf_block;
  EXPECT_EQ(layout::load<uint32_t>(p), 0x11u);
  float first[3][3], second[3][3];
  layout::decode_triangle(blob.data(), h.tree_offset + leaf_block, 0, first);
  layout::decode_triangle(blob.data(), h.tree_offset + leaf_block, 1, second);
  // (A, B, C) and (B, A, D): the shared edge, reversed, then the other corner.
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(second[0][a], first[1][a]);
    EXPECT_EQ(second[1][a], first[0][a]);
  }
  float d[3];
  for (int a = 0; a < 3; ++a) d[a] = layout::load<float>(p + layout::Float3PairSOA4::row(3, a));
  EXPECT_EQ(std::memcmp(d, second[2], 12), 0);
  // The two triangles' shared corners are the quad's diagonal 0-2.
  std::set<std::pair<float, float>> diagonal = {{first[0][0], first[0][1]}, {first[1][0], first[1][1]}};
  EXPECT_EQ(diagonal, (std::set<std::pair<float, float>>{{0, 0}, {1, 1}}));
  // Rays through each triangle hit it, through the diagonal one of them.
  std::vector<Ray> rays = {Ray{{0.8f, 0.2f, 1}, {0, 0, -1}, 10}, Ray{{0.2f, 0.8f, 1}, {0, 0, -1}, 10},
                           Ray{{0.5f, 0.5f, 1}, {0, 0, -1}, 10}};
  std::vector<Hit> hits = trace_all(blob, rays);
  EXPECT_EQ(hits[0].triangle, 0u);
  EXPECT_EQ(hits[1].triangle, 1u);
  EXPECT_NE(hits[2].triangle, MC_NO_HIT);

  std::vector<uint8_t> bad = blob;
  uint32_t header = 0x111;
  std::memcpy(bad.data() + h.tree_offset + leaf_block, &header, 4);
  layout::seal(bad);
  EXPECT_NE(layout::validate(bad), "");
}
}  // namespace
}  // namespace meshcast::testing
