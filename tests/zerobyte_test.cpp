// Zero-byte trees (seed 004): the index buffer is the whole tree, every
// variant (box cache, named corners, the hybrid's leaf sizes) returns the
// oracle's answers, the seed's limits are refused with the number, and a
// damaged tree is refused by validation.
#include <gtest/gtest.h>

#include <cstring>

#include "cpu/box_cache.h"
#include "builder/write_zerobyte.h"
#include "check/generate.h"
#include "layout/tree/zerobyte.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

BuildOptions zbt(const char* layout, bool cache, bool shuffle, uint32_t leaf = 256) {
  BuildOptions o = parse_layout(layout);
  o.zbt_box_cache = cache, o.zbt_shuffle = shuffle, o.hybrid_leaf = leaf;
  return o;
}

// Nothing but the mesh: 12 bytes of indices a triangle, 12 of floats a
// vertex, no node bytes; the words' low 24 bits are the input's indices.
TEST(ZeroByte, TheIndexBufferIsTheTree) {
  Mesh m = make_sphere(24, 48, 1, {0, 0, 0});
  std::vector<uint8_t> blob = build_blob(m, zbt("ZeroByteTree/Indexed24", true, true), "sphere");
  const layout::BlobHeader& h = layout::header_of(blob.data());
  EXPECT_EQ(h.node_bytes, 0u);
  EXPECT_EQ(h.tree_size, 12u * m.triangles.size());
  EXPECT_EQ(h.vertex_size, 12u * m.vertices.size());
  const uint8_t* tris = blob.data() + h.tree_offset;
  std::vector<int> seen(m.triangles.size(), 0);
  for (uint32_t s = 0; s < h.triangle_count; ++s) {
    uint32_t t = layout::remap_entry(blob.data(), h, s);
    ++seen[t];
    for (int c = 0; c < 3; ++c) EXPECT_EQ(layout::Indexed24::index(tris - 0, 0, s, c), m.triangles[t][c]) << s;
  }
  for (int n : seen) EXPECT_EQ(n, 1);
}

// Every variant against the oracle, every test mesh and ray kind; the box
// cache changes no answer (the same bits with and without it).
TEST(ZeroByte, EveryVariantReturnsTheOraclesAnswers) {
  struct Variant { const char* layout; bool cache, shuffle; uint32_t leaf; };
  const Variant variants[] = {{"ZeroByteTree/Indexed24", true, true, 0},   {"ZeroByteTree/Indexed24", false, true, 0},
                              {"ZeroByteTree/Indexed24", true, false, 0},  {"ZeroByteTree/Indexed24", false, false, 0},
                              {"ZeroByteHybrid/Indexed24", true, true, 64}, {"ZeroByteHybrid/Indexed24", false, true, 1024}};
  for (const NamedMesh& m : test_meshes(false))
    for (RayKind kind : {RayKind::Long, RayKind::Probe, RayKind::Radial}) {
      const std::vector<Ray>& rays = test_rays(m, kind, 3000);
      std::vector<Hit> first;
      for (const Variant& v : variants) {
        std::vector<uint8_t> blob = build_blob(*m.mesh, zbt(v.layout, v.cache, v.shuffle, v.leaf ? v.leaf : 256), m.name);
        std::vector<Hit> hits = trace_all(blob, rays);
        std::string what = std::string(v.layout) + (v.cache ? " cache" : "") + (v.shuffle ? " shuffled" : "") + " on " +
                           m.name + " kind " + std::to_string(int(kind));
        Agreement a = compare(*m.mesh, rays, hits, oracle_answers(m, kind, rays), 1e-5 * m.mesh->bounds().diagonal());
        EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << what << ": " << a.first_problem;
        if (&v == &variants[1]) {  // the cache's twin: the very same answers
          for (size_t i = 0; i < hits.size(); ++i)
            ASSERT_TRUE(hits[i].triangle == first[i].triangle && hits[i].t == first[i].t) << what << " ray " << i;
        }
        if (&v == &variants[0]) first = hits;
      }
    }
}

// On a closed mesh most interior nodes find 6 triangles, each giving one
// extreme by a named corner.
TEST(ZeroByte, MostNodesOfAClosedMeshAreShuffled) {
  BuildReport report;
  build_blob(make_sphere(64, 128, 1, {0, 0, 0}), zbt("ZeroByteTree/Indexed24", true, true), "sphere", &report);
  double share = std::stod(report.zerobyte.substr(report.zerobyte.find("triangles an interior node, ") + 28));
  EXPECT_GT(share, 25.0) << report.zerobyte;
}

TEST(ZeroByte, TheSeedsLimitsAreRefusedWithTheNumbers) {
  Mesh big;
  big.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  big.triangles.assign(MC_ZBT_MAX_TRIANGLES + 1, Triangle{0, 1, 2});
  try {
    build_blob(big, zbt("ZeroByteTree/Indexed24", true, true), "big");
    FAIL();
  } catch (const InputError& e) {
    std::string s = e.what();
    EXPECT_NE(s.find("big"), std::string::npos) << s;
    EXPECT_NE(s.find("2097152"), std::string::npos) << s;
    EXPECT_NE(s.find("2097153"), std::string::npos) << s;
  }
  // Other triangle formats do not pair with the zero-byte trees.
  BuildOptions o = parse_layout("ZeroByteTree/Indexed24");
  o.layout.triangles = TriangleFormat::Float3;
  EXPECT_THROW(build_blob(make_sphere(6, 12, 1, {0, 0, 0}), o, "sphere"), InputError);
}

// Damaged trees: each change is resealed so only validation can catch it.
TEST(ZeroByte, DamagedTreesAreRefused) {
  Mesh m = make_sphere(24, 48, 1, {0, 0, 0});
  std::vector<uint8_t> good = build_blob(m, zbt("ZeroByteTree/Indexed24", false, true), "sphere");
  ASSERT_EQ(layout::validate(good), "");
  const layout::BlobHeader& h = layout::header_of(good.data());
  const uint32_t tris = h.tree_offset + h.triangle_base;
  layout::ZbtNode root = layout::zbt_node(good.data() + tris, 0);
  ASSERT_NE(root.child, 0u);
  auto damaged = [&](auto change) {
    std::vector<uint8_t> b = good;
    change(b.data() + tris);
    layout::seal(b);
    return layout::validate(b);
  };
  // The root's child pointing back at the root.
  EXPECT_NE(damaged([](uint8_t* t) { t[3] = 0, t[7] = t[7] & 0xE0; }), "");
  // The root's count set to 0.
  EXPECT_NE(damaged([](uint8_t* t) { t[11] &= 0x1F; }), "");
  // A vertex index past the vertex section.
  EXPECT_NE(damaged([&](uint8_t* t) { uint32_t w = 0x00FFFFFFu; std::memcpy(t + 12 * 5, &w, 3); }), "");
  // A named corner changed: the box no longer holds the triangles.
  if (root.count == 6 && layout::zbt_shuffled(good.data() + tris, 0)) {
    EXPECT_NE(damaged([](uint8_t* t) { t[12 + 7] ^= 0x06; }), "");
  }
}

TEST(ZeroByte, TheBoxCacheKnowsItsBlob) {
  BoxCache cache;
  uint8_t a = 0, b = 0;
  float mn[3] = {0, 1, 2}, mx[3] = {3, 4, 5}, got[3], got2[3];
  cache.put(&a, 7, 42, mn, mx);
  EXPECT_TRUE(cache.find(&a, 7, 42, got, got2));
  EXPECT_EQ(got2[2], 5.0f);
  EXPECT_FALSE(cache.find(&b, 7, 42, got, got2));  // another blob
  EXPECT_FALSE(cache.find(&a, 8, 42, got, got2));  // the same address, other bytes
  EXPECT_FALSE(cache.find(&a, 7, 43, got, got2));  // another node
}

}  // namespace
}  // namespace meshcast::testing
