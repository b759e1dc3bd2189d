// layout/: half-float directed rounding, bit packing, blob validation, and
// corrupted blobs (run under AddressSanitizer by the CI's sanitizer job).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstddef>
#include <random>
#include <set>

#include "check/generate.h"
#include "layout/blob_format.h"
#include "layout/triangles/block.h"
#include "layout/tree/half.h"
#include "layout/tree/octtree.h"
#include "tests/testing.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace meshcast::testing {
namespace {

using namespace layout;

// Made while this file's statics are initialised, before main(): a blob
// built from arrays and walked through a BlobView, which needs no other
// translation unit's statics to be ready (the walker table is made on first
// use). The answer is checked in StaticInitialisationBuildsAndWalks.
const std::string g_static_walk = [] {
  try {
    const float xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t indices[] = {0, 1, 2};
    MeshView view;
    view.positions = xyz, view.vertex_count = 3, view.indices = indices, view.triangle_count = 1;
    const std::vector<uint8_t> blob = build_blob(view, BuildOptions{}, "static");
    const Ray ray{{0.25f, 0.25f, 1}, {0, 0, -1}, INFINITY};
    Hit hit;
    BlobView(blob, "static").trace({&ray, 1}, {&hit, 1});
    return hit.triangle == 0 && std::fabs(hit.t - 1.0f) < 1e-6f ? std::string() : std::string("wrong hit");
  } catch (const std::exception& e) {
    return std::string(e.what());
  }
}();

TEST(Layout, StaticInitialisationBuildsAndWalks) { EXPECT_EQ(g_static_walk, ""); }

// Every finite half, in increasing order: the independent reference for the
// directed conversions.
std::vector<float> all_finite_halves() {
  std::vector<float> v;
  for (uint32_t h = 0; h < 0x10000; ++h) {
    float f = half_to_float(uint16_t(h));
    if (std::isfinite(f)) v.push_back(f);
  }
  std::sort(v.begin(), v.end());
  return v;
}

#if defined(__x86_64__)
// The processor's own conversion (F16C), compiled for it alone: the test
// itself is built for the baseline.
__attribute__((target("f16c"))) float hardware_half(uint32_t h) {
  return _mm_cvtss_f32(_mm_cvtph_ps(_mm_cvtsi32_si128(int(h))));
}
#endif

TEST(Half, DecodeMatchesHardware) {
#if defined(__x86_64__)
  if (!__builtin_cpu_supports("f16c")) GTEST_SKIP() << "this processor has no F16C to compare with";
  for (uint32_t h = 0; h < 0x10000; ++h) {
    float hw = hardware_half(h);
    float sw = half_to_float(uint16_t(h));
    if (std::isnan(hw)) EXPECT_TRUE(std::isnan(sw)) << h;
    else EXPECT_EQ(std::bit_cast<uint32_t>(hw), std::bit_cast<uint32_t>(sw)) << h;
  }
#else
  GTEST_SKIP() << "not x86-64: no F16C to compare with";
#endif
}

TEST(Half, DirectedRoundingIsTightAndOutward) {
  std::vector<float> halves = all_finite_halves();
  std::mt19937 rng(5);
  std::vector<float> probes = {0.0f, -0.0f, 1e-9f, -1e-9f, 6.0e-8f, 65504.0f, 65505.0f, -65504.0f, 70000.0f,
                               -1e30f, 1e30f, 1.0f / 3.0f, -2.5f};
  for (int i = 0; i < 20000; ++i)
    probes.push_back(std::ldexp(std::uniform_real_distribution<float>(-1, 1)(rng), int(rng() % 40) - 24));
  for (float f : probes) {
    float down = half_to_float(float_to_half_down(f)), up = half_to_float(float_to_half_up(f));
    EXPECT_LE(down, f);
    EXPECT_GE(up, f);
    // Tight: no finite half lies strictly between the result and f.
    auto below = std::upper_bound(halves.begin(), halves.end(), f);
    float expect_down = below == halves.begin() ? -INFINITY : *(below - 1);
    auto above = std::lower_bound(halves.begin(), halves.end(), f);
    float expect_up = above == halves.end() ? INFINITY : *above;
    EXPECT_EQ(down, expect_down) << f;
    EXPECT_EQ(up, expect_up) << f;
  }
}

TEST(BitPack, RoundTripWithinHalfAStep) {
  float offset[3] = {-3.0f, 1000.0f, 0.0f}, scale[3];
  float extent[3] = {6.0f, 0.15f, 0.0f};
  for (int a = 0; a < 3; ++a) scale[a] = extent[a] / float(MC_BITPACK_MAX);
  float bound[3];
  quantization_bound(offset, scale, bound);
  std::mt19937 rng(9);
  for (int i = 0; i < 100000; ++i) {
    float v[3], d[3];
    for (int a = 0; a < 3; ++a) v[a] = offset[a] + std::uniform_real_distribution<float>(0, 1)(rng) * extent[a];
    uint64_t w = bitpack_encode(v, offset, scale);
    EXPECT_EQ(w >> 63, 0u);
    bitpack_decode(w, offset, scale, d);
    for (int a = 0; a < 3; ++a) ASSERT_LE(std::fabs(d[a] - v[a]), bound[a]) << a;
  }
}

std::vector<std::vector<uint8_t>> sample_blobs() {
  std::vector<std::vector<uint8_t>> blobs;
  Mesh sphere = make_sphere(12, 24, 1.0f, {0, 0, 0});
  Mesh grid = make_grid_plane(9, 7);
  for (const std::string& name : layout_names())
    for (const Mesh* m : {&sphere, &grid}) blobs.push_back(build_blob(*m, parse_layout(name), name));
  return blobs;
}

TEST(Blob, FreshBlobsValidate) {
  for (const auto& blob : sample_blobs()) EXPECT_EQ(validate(blob), "");
}

TEST(Blob, TruncationIsRefusedWithAReason) {
  for (const auto& blob : sample_blobs()) {
    for (size_t len : {size_t(0), size_t(3), size_t(100), size_t(160), blob.size() / 2, blob.size() - 1}) {
      std::vector<uint8_t> cut(blob.begin(), blob.begin() + std::ptrdiff_t(len));
      std::string why = validate(cut);
      EXPECT_NE(why, "") << len;
      EXPECT_TRUE(why.find("bytes") != std::string::npos || why.find("truncated") != std::string::npos) << why;
    }
  }
}

TEST(Blob, AnyFlippedByteIsRefused) {
  std::mt19937 rng(3);
  for (const auto& blob : sample_blobs())
    for (int i = 0; i < 200; ++i) {
      std::vector<uint8_t> bad = blob;
      bad[rng() % bad.size()] ^= uint8_t(1 + rng() % 255);
      EXPECT_NE(validate(bad), "");
    }
}

// The structural checks on their own: corrupt, re-seal so the checksum
// matches, then either validation refuses the blob or every walk ends with
// an answer that names a real triangle. Under ASan this also proves no read
// leaves the blob.
TEST(Blob, ResealedCorruptionIsRefusedOrWalkedSafely) {
  std::mt19937 rng(11);
  std::vector<Ray> rays = make_rays(make_sphere(12, 24, 1.0f, {0, 0, 0}), RayKind::Long, 64, 2);
  for (Ray& r : make_rays(make_grid_plane(9, 7), RayKind::Long, 64, 3)) rays.push_back(r);
  size_t refused = 0, walked = 0;
  for (const auto& blob : sample_blobs()) {
    const uint32_t triangles = header_of(blob.data()).triangle_count;
    for (int i = 0; i < 400; ++i) {
      std::vector<uint8_t> bad = blob;
      int flips = 1 + int(rng() % 4);
      for (int f = 0; f < flips; ++f) {
        // Half the flips land in the header, where every field matters.
        size_t at = (rng() & 1) ? rng() % sizeof(BlobHeader) : rng() % bad.size();
        bad[at] ^= uint8_t(1u << (rng() % 8));
      }
      if (bad.size() >= sizeof(BlobHeader)) seal(bad);
      if (!validate(bad).empty()) {
        ++refused;
        continue;
      }
      ++walked;
      BlobView view(bad, "corrupted");
      std::vector<Hit> hits(rays.size());
      view.trace(rays, hits);
      for (const Hit& h : hits) ASSERT_TRUE(h.triangle == MC_NO_HIT || h.triangle < triangles);
    }
  }
  EXPECT_GT(refused, 0u);
  EXPECT_GT(walked, 0u);  // flips of bounds or vertices still give a valid blob
}

}  // namespace
}  // namespace meshcast::testing

namespace meshcast::testing {
namespace {

using namespace layout;

// Golden bytes: the seed's layouts, checked at literal offsets (not through
// the constants of formats.h, so a swapped field shows here).
Mesh two_triangles() {
  Mesh m;
  m.vertices = {{1, 2, 3}, {4, 5, 6}, {7, 8, 10}, {-1, -2, -3}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

template <class T>
T at(const std::vector<uint8_t>& b, size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof v);
  return v;
}

TEST(GoldenBytes, AABBTreeFloat3IsSeed51And31) {
  std::vector<uint8_t> b = build_blob(two_triangles(), parse_layout("AABBTree/Float3"), "golden");
  size_t tree = at<uint32_t>(b, 104);  // header field tree_offset: after 10 uint32 and 16 floats
  ASSERT_EQ(tree, 192u);
  // One leaf: BoundingBoxMin, BoundingBoxMax, Properties = high bit | count.
  EXPECT_EQ(at<float>(b, tree + 0), -1.0f);
  EXPECT_EQ(at<float>(b, tree + 8), -3.0f);
  EXPECT_EQ(at<float>(b, tree + 12), 7.0f);
  EXPECT_EQ(at<float>(b, tree + 20), 10.0f);
  EXPECT_EQ(at<uint32_t>(b, tree + 24), 0x80000002u);
  // Float3 block right behind the node: 9 floats a triangle, corner order kept.
  std::vector<float> corners;
  for (int i = 0; i < 18; ++i) corners.push_back(at<float>(b, tree + 28 + 4 * i));
  std::vector<float> a = {1, 2, 3, 4, 5, 6, 7, 8, 10}, c = {1, 2, 3, 7, 8, 10, -1, -2, -3};
  std::vector<float> first(corners.begin(), corners.begin() + 9), second(corners.begin() + 9, corners.end());
  EXPECT_TRUE((first == a && second == c) || (first == c && second == a));
}

TEST(GoldenBytes, QuadTreeFloat3SOA4IsSeed56And32) {
  Mesh m = two_triangles();
  BuildOptions o = parse_layout("QuadTree/Float3SOA4");
  o.leaf_size = 1;  // two leaves under one node
  std::vector<uint8_t> b = build_blob(m, o, "golden");
  size_t tree = 192;
  uint32_t root = at<uint32_t>(b, 9 * 4);
  EXPECT_EQ(root, 0u);  // a node (count 0) at offset 0
  // Node: MinX[4] MinY[4] MinZ[4] MaxX[4] MaxY[4] MaxZ[4] NodeProperties[4].
  uint32_t p0 = at<uint32_t>(b, tree + 96), p1 = at<uint32_t>(b, tree + 100);
  EXPECT_EQ(p0 >> 27, 1u);
  EXPECT_EQ(p1 >> 27, 1u);
  EXPECT_EQ(at<uint32_t>(b, tree + 104), 0u);  // unused children
  EXPECT_EQ(at<float>(b, tree + 8), INFINITY);  // MinX of child 2
  EXPECT_EQ(at<float>(b, tree + 48 + 8), -INFINITY);  // MaxX of child 2
  // Child k's MinX at 4k, MaxZ at 80 + 4k, and its block holds X of corner 1 for 4 lanes first.
  for (int k = 0; k < 2; ++k) {
    uint32_t block = tree + (at<uint32_t>(b, tree + 96 + 4 * k) & 0x07FFFFFFu);
    float x1 = at<float>(b, block), y1 = at<float>(b, block + 16), z3 = at<float>(b, block + 128);
    EXPECT_EQ(x1, 1.0f);  // both triangles start at vertex 0
    EXPECT_EQ(y1, 2.0f);
    EXPECT_TRUE(z3 == 10.0f || z3 == -3.0f);
    EXPECT_EQ(at<float>(b, block + 4), x1);  // padding lane repeats the triangle
    float min_x = at<float>(b, tree + 4 * k), max_z = at<float>(b, tree + 80 + 4 * k);
    EXPECT_EQ(min_x, z3 == 10.0f ? 1.0f : -1.0f);
    EXPECT_EQ(max_z, 10.0f);  // both triangles reach z = 10
  }
}

TEST(GoldenBytes, Indexed8BitPackSOA4IsSeed39) {
  Mesh m = two_triangles();
  std::vector<uint8_t> b = build_blob(m, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "golden");
  uint32_t root = at<uint32_t>(b, 9 * 4);
  ASSERT_EQ(root >> 27, 2u);  // the root is one leaf of 2 triangles
  uint32_t block = 192 + (root & 0x07FFFFFFu);
  uint32_t offset_to_vertices = at<uint32_t>(b, block);
  // 12-byte TriangleBlock: I11..I41, I12..I42, I13..I43; 4 distinct vertices.
  std::set<uint8_t> used;
  for (int i = 0; i < 12; ++i) used.insert(at<uint8_t>(b, block + 4 + i));
  EXPECT_EQ(used.size(), 4u);
  // Vertex I at <block> + OffsetToVertices + 8 I, 21 bits a component, x low.
  const BlobHeader& h = header_of(b.data());
  for (int lane = 0; lane < 2; ++lane) {
    uint8_t i0 = at<uint8_t>(b, block + 4 + lane);
    uint64_t w = at<uint64_t>(b, block + offset_to_vertices + 8 * i0);
    float x = float(w & 0x1FFFFF) * h.quant_scale[0] + h.quant_offset[0];
    EXPECT_NEAR(x, 1.0f, 1e-5);  // both triangles start at vertex (1, 2, 3)
    EXPECT_NEAR(float((w >> 21) & 0x1FFFFF) * h.quant_scale[1] + h.quant_offset[1], 2.0f, 1e-5);
    EXPECT_NEAR(float((w >> 42) & 0x1FFFFF) * h.quant_scale[2] + h.quant_offset[2], 3.0f, 1e-5);
  }
}

TEST(GoldenBytes, AABBTreeSplitAxisIsSeed52) {
  std::vector<uint8_t> b = build_blob(make_sphere(8, 16, 1, {0, 0, 0}), parse_layout("AABBTreeSplitAxis/Float3"), "s");
  const size_t tree = 192;
  size_t interior = 0;
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    uint32_t node = stack.back();
    stack.pop_back();
    uint32_t props = at<uint32_t>(b, tree + node + 24);
    if (props & 0x80000000u) continue;  // leaf
    ++interior;
    uint32_t axis = props >> 29, second = props & 0x1FFFFFFFu, first = node + 28;
    ASSERT_LE(axis, 2u);
    // Node: min at 0, max at 12; the first child is the lower along the axis.
    float first_centre = at<float>(b, tree + first + 4 * axis) + at<float>(b, tree + first + 12 + 4 * axis);
    float second_centre = at<float>(b, tree + second + 4 * axis) + at<float>(b, tree + second + 12 + 4 * axis);
    EXPECT_LE(first_centre, second_centre);
    stack.push_back(first), stack.push_back(second);
  }
  EXPECT_GT(interior, 10u);
}

TEST(GoldenBytes, AABBTreePNSIsSeed53And002) {
  Mesh m;  // two triangles 10 apart along x: the octants with x < 0 see the second first
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {10, 0, 0}, {11, 0, 0}, {10, 1, 0}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  BuildOptions o = parse_layout("AABBTreePNS/Float3");
  o.leaf_size = 1;
  std::vector<uint8_t> b = build_blob(m, o, "pns");
  const size_t tree = 192;
  uint32_t root = at<uint32_t>(b, tree + 24);
  EXPECT_EQ(root >> 31, 0u);
  EXPECT_EQ(root >> 23 & 0xFF, 0xF0u);  // bit z | y << 1 | x << 2 set for x negative
  EXPECT_EQ(root & 0x7FFFFFu, 2u);      // second child: node 2 (node 1 is the first)
  uint32_t first = at<uint32_t>(b, tree + 28 + 24), second = at<uint32_t>(b, tree + 56 + 24);
  EXPECT_EQ(first >> 31, 1u);
  EXPECT_EQ(first >> 26 & 31, 1u);  // one triangle
  EXPECT_EQ(at<float>(b, tree + 28 + 0), 0.0f);   // the lower child first
  EXPECT_EQ(at<float>(b, tree + 56 + 0), 10.0f);
  // Blocks follow the 3 nodes, 4-byte units from there.
  EXPECT_EQ(192 + 3 * 28 + 4 * (second & 0x3FFFFFFu), 192 + 3 * 28 + 36u);
}

// The three trees below use the two triangles 10 apart along x, one a leaf.
std::vector<uint8_t> two_apart(const char* layout) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {10, 0, 0}, {11, 0, 0}, {10, 1, 0}};
  m.triangles = {{0, 1, 2}, {3, 4, 5}};
  BuildOptions o = parse_layout(layout);
  o.leaf_size = 1;
  return build_blob(m, o, layout);
}

TEST(GoldenBytes, AABBTreeCompressedIsSeed54) {
  std::vector<uint8_t> b = two_apart("AABBTreeCompressed/Float3");
  const size_t tree = 192;
  // Header: RootBoundsMin, RootBoundsMax, RootTriangleCount (0: a node follows).
  EXPECT_EQ(at<float>(b, tree + 0), 0.0f);
  EXPECT_EQ(at<float>(b, tree + 12), 11.0f);
  EXPECT_EQ(at<float>(b, tree + 16), 1.0f);
  EXPECT_EQ(at<uint32_t>(b, tree + 24), 0u);
  // Min word: x codes the right child's 10 in [0, 11]: floor(10 * 127 / 11) =
  // 115; y and z inherit 0 on the left and code 0 on the right (side bits
  // 1); left count 1 on top.
  EXPECT_EQ(at<uint32_t>(b, tree + 28), 115u | 7u << 21 | 1u << 24);
  // Max word: x codes the left child's 1: ceil(127 / 11) = 12 (side 0); y
  // codes the right child's 1 in [0, 1]: 127; z 0; right count 1.
  EXPECT_EQ(at<uint32_t>(b, tree + 32), 12u | 127u << 7 | 6u << 21 | 1u << 24);
  // The left block (36 bytes of Float3) follows the node; the right after it.
  EXPECT_EQ(at<uint32_t>(b, tree + 36), 28u + 12u + 36u);
  EXPECT_EQ(at<float>(b, tree + 40), 0.0f);   // first corner of the left triangle
  EXPECT_EQ(at<float>(b, tree + 76), 10.0f);  // and of the right one
}

TEST(GoldenBytes, SKDTreeIsSeed55) {
  std::vector<uint8_t> b = two_apart("SKDTree/Float3");
  const size_t tree = 192;
  // Root: axis x (0) in the top 2 bits, right child's offset below; the planes
  // are the left child's max x and the right child's min x.
  EXPECT_EQ(at<uint32_t>(b, tree + 0), 12u + 4u + 36u);
  EXPECT_EQ(at<float>(b, tree + 4), 1.0f);
  EXPECT_EQ(at<float>(b, tree + 8), 10.0f);
  // Leaves: axis 3, count 1, block right behind.
  EXPECT_EQ(at<uint32_t>(b, tree + 12), 0xC0000001u);
  EXPECT_EQ(at<float>(b, tree + 16), 0.0f);
  EXPECT_EQ(at<uint32_t>(b, tree + 52), 0xC0000001u);
  EXPECT_EQ(at<float>(b, tree + 56), 10.0f);
}

TEST(GoldenBytes, StacklessLBVHIsSeed001) {
  std::vector<uint8_t> b = two_apart("StacklessLBVH/Float3");
  const size_t tree = 192;
  // Heap of depth 1: nodes 1, 2, 3 at 32 (n - 1); min, max, count, position.
  EXPECT_EQ(at<float>(b, tree + 12), 11.0f);
  EXPECT_EQ(at<int32_t>(b, tree + 24), -2);       // interior: minus the triangles below
  EXPECT_EQ(at<uint32_t>(b, tree + 28), 0xF0u);   // seed 002 bits: x-negative octants go right first
  EXPECT_EQ(at<float>(b, tree + 32 + 12), 1.0f);  // node 2 (left): the triangle at x 0..1
  EXPECT_EQ(at<int32_t>(b, tree + 32 + 24), 1);
  EXPECT_EQ(at<uint32_t>(b, tree + 32 + 28), 96u);  // its block right after the 3 nodes
  EXPECT_EQ(at<float>(b, tree + 64 + 0), 10.0f);
  EXPECT_EQ(at<uint32_t>(b, tree + 64 + 28), 96u + 36u);
  BuildOptions o = parse_layout("StacklessLBVH/Float3");
  EXPECT_EQ(o.splitter, Splitter::Morton);  // the seed's Morton-code middle split
}

// Hand-made structural faults, re-sealed so only the structure is judged.
std::string corrupt(std::vector<uint8_t> b, size_t offset, uint32_t value) {
  std::memcpy(b.data() + offset, &value, 4);
  seal(b);
  return validate(b);
}

TEST(Corruption, ChildBeforeItsParentIsRefused) {
  std::vector<uint8_t> b = build_blob(make_sphere(8, 16, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s");
  // The root's properties: its second child pointing back at the root.
  EXPECT_NE(corrupt(b, 192 + 24, 0u).find("not after its first child"), std::string::npos);
  std::vector<uint8_t> q = build_blob(make_sphere(8, 16, 1, {0, 0, 0}), parse_layout("QuadTree/Float3"), "s");
  // The root node's first child: a node at offset 0, the root itself.
  std::string why = corrupt(q, 192 + 96, 0u);
  EXPECT_TRUE(why.empty() || why.find("after its parent") != std::string::npos ||
              why.find("leaves hold") != std::string::npos) << why;
  // The second node's first child pointing back at the second node itself.
  EXPECT_NE(corrupt(q, 192 + 112 + 96, 112u).find("after its parent"), std::string::npos);
}

TEST(Corruption, NewTreesRefuseBrokenLinks) {
  const size_t tree = 192;
  // A right child inside its left sibling.
  EXPECT_NE(corrupt(two_apart("AABBTreeCompressed/Float3"), tree + 36, 40), "");
  EXPECT_NE(corrupt(two_apart("SKDTree/Float3"), tree + 0, 8), "");
  // A hole where an interior node's child must be.
  std::string why = corrupt(two_apart("StacklessLBVH/Float3"), tree + 64 + 24, 0);
  EXPECT_NE(why.find("hole"), std::string::npos) << why;
  // An interior node whose children lie past the node array.
  EXPECT_NE(corrupt(two_apart("StacklessLBVH/Float3"), tree + 32 + 24, uint32_t(-1)), "");
}

// OctTreeCompressed's header bounds its nodes' frames (the CPU walker's
// fused box test pads its rounding with them): a header that claims a
// smaller reach than a node's origin or scale, or one that is not finite,
// is refused.
TEST(Corruption, OctTreeNodesBeyondTheHeaderReachAreRefused) {
  const Mesh sphere = make_sphere(12, 24, 1.0f, {5.0f, -3.0f, 2.0f});
  std::vector<uint8_t> b = build_blob(sphere, parse_layout("OctTreeCompressed/Float3"), "s");
  const BlobHeader& h = header_of(b.data());
  ASSERT_EQ(oct_count(h.root), 0u) << "the root is a node";
  const uint8_t* root = b.data() + h.tree_offset + oct_offset(h.root);
  for (int a = 0; a < 3; ++a) {
    const float origin = std::fabs(load<float>(root + MC_OCT_ORIGIN_AT + 4 * a));
    EXPECT_GE(h.node_origin[a], origin) << a;
    EXPECT_GE(h.node_scale, oct_scale(root[MC_OCT_EXPONENTS_AT + a])) << a;
    const size_t field = offsetof(BlobHeader, node_origin) + 4 * size_t(a);
    EXPECT_NE(corrupt(b, field, std::bit_cast<uint32_t>(std::nextafter(origin, 0.0f))).find("node reach"),
              std::string::npos) << a;
    EXPECT_NE(corrupt(b, field, std::bit_cast<uint32_t>(NAN)).find("node reach"), std::string::npos) << a;
  }
  EXPECT_NE(corrupt(b, offsetof(BlobHeader, node_scale), std::bit_cast<uint32_t>(h.node_scale / 2)).find("node reach"),
            std::string::npos);
  EXPECT_NE(corrupt(b, offsetof(BlobHeader, node_scale), std::bit_cast<uint32_t>(-1.0f)).find("node reach"),
            std::string::npos);
}

// A root that is a leaf (16 triangles or fewer) leaves no node to reach:
// the header says 0 for every field, wherever the mesh lies.
TEST(Corruption, OctTreeLeafRootHasNoReach) {
  const Mesh small = make_sphere(3, 4, 1.0f, {-2.0f, 0.5f, -1.0f});  // a negative centre
  ASSERT_LE(small.triangles.size(), 16u);
  std::vector<uint8_t> b = build_blob(small, parse_layout("OctTreeCompressed/Float3"), "small sphere");
  EXPECT_EQ(validate(b), "");
  const BlobHeader& h = header_of(b.data());
  EXPECT_NE(oct_count(h.root), 0u) << "the root is a leaf";
  EXPECT_EQ(h.node_origin[0], 0.0f);
  EXPECT_EQ(h.node_origin[1], 0.0f);
  EXPECT_EQ(h.node_origin[2], 0.0f);
  EXPECT_EQ(h.node_scale, 0.0f);
}

TEST(GoldenBytes, AABBListIsSeed7) {
  std::vector<uint8_t> b = two_apart("AABBList/Float3");
  const size_t tree = 192;
  // One batch entry: BoundingBoxMin, BoundingBoxMax, TriangleCount, RecordOffset.
  EXPECT_EQ(at<float>(b, tree + 0), 0.0f);
  EXPECT_EQ(at<float>(b, tree + 12), 11.0f);
  EXPECT_EQ(at<float>(b, tree + 16), 1.0f);
  EXPECT_EQ(at<uint32_t>(b, tree + 24), 2u);
  EXPECT_EQ(at<uint32_t>(b, tree + 28), 32u);
  // Its one record right after: [count][two Float3 triangles].
  EXPECT_EQ(at<uint32_t>(b, tree + 32), 2u);
  EXPECT_EQ(header_of(b.data()).tree_size, 32u + 4u + 72u);
}

TEST(Corruption, AABBListRecordsMustTileFullBatches) {
  // 1,200 triangles: four full batches of 256 and a last one of 176.
  std::vector<uint8_t> b = build_blob(make_sphere(20, 30, 1, {0, 0, 0}), parse_layout("AABBList/Float3SOA128"), "s");
  const BlobHeader& h = header_of(b.data());
  ASSERT_EQ(h.node_count, 5u);
  const size_t entry1 = h.tree_offset + MC_LIST_ENTRY_BYTES;
  std::string why = corrupt(b, entry1 + MC_LIST_RECORDS_AT, at<uint32_t>(b, entry1 + MC_LIST_RECORDS_AT) + 4);
  EXPECT_NE(why.find("runs past"), std::string::npos) << why;  // batch 0 now ends short of it
  why = corrupt(b, h.tree_offset + MC_LIST_COUNT_AT, 255);
  EXPECT_NE(why.find("batch 0 holds 255"), std::string::npos) << why;
  why = corrupt(b, h.tree_offset + 4 * MC_LIST_ENTRY_BYTES + MC_LIST_COUNT_AT, 177);
  EXPECT_NE(why.find("entry says 177"), std::string::npos) << why;
}

TEST(Corruption, VertexIndexOutsideTheVertexSectionIsRefused) {
  std::vector<uint8_t> b =
      build_blob(make_sphere(8, 16, 1, {0, 0, 0}), parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "s");
  const BlobHeader& h = header_of(b.data());
  uint32_t first_block = h.tree_offset + h.triangle_base;
  // OffsetToVertices pointing into the remap section.
  uint32_t into_remap = h.remap_offset - first_block;
  EXPECT_NE(corrupt(b, first_block, into_remap).find("outside the vertex section"), std::string::npos);
}

TEST(Corruption, WrongRemapRankIsRefused) {
  std::vector<uint8_t> b = build_blob(make_sphere(16, 32, 1, {0, 0, 0}), parse_layout("QuadTree/Float3SOA4"), "s");
  const BlobHeader& h = header_of(b.data());
  ASSERT_GT(remap_words(h), 1u);
  size_t rank1 = h.remap_offset + 8ull * remap_words(h) + 4;
  EXPECT_NE(corrupt(b, rank1, at<uint32_t>(b, rank1) + 1).find("remap rank"), std::string::npos);
}

// A blob without a remap (remap_size 0) must have slot numbers for every
// triangle and no entry width; a remap in input order (remap_bits 0) must
// still count its used slots right.
TEST(Corruption, MissingOrInOrderRemapMustBeWhole) {
  BuildOptions o = parse_layout("QuadTree/Float3SOA4");
  o.triangle_ids = false;
  const Mesh sphere = make_sphere(16, 32, 1, {0, 0, 0});
  std::vector<uint8_t> b = build_blob(sphere, o, "s");
  const BlobHeader& h = header_of(b.data());
  ASSERT_FALSE(has_remap(h));
  ASSERT_EQ(validate(b), "");
  EXPECT_NE(corrupt(b, 4 * MC_HDR_REMAP_SLOTS, h.triangle_count - 1).find("slot numbers for"), std::string::npos);
  EXPECT_NE(corrupt(b, 4 * MC_HDR_REMAP_BITS, 17).find("no remap section, yet"), std::string::npos);

  std::vector<uint8_t> in_order = build_blob(sphere, parse_layout("BruteForce/Float3"), "s");
  const BlobHeader& k = header_of(in_order.data());
  ASSERT_TRUE(has_remap(k));
  ASSERT_EQ(k.remap_bits, 0u) << "brute force keeps the input order";
  ASSERT_GT(remap_words(k), 1u);
  const size_t rank1 = k.remap_offset + 8ull * remap_words(k) + 4;
  EXPECT_NE(corrupt(in_order, rank1, at<uint32_t>(in_order, rank1) + 1).find("remap rank"), std::string::npos);
  EXPECT_NE(corrupt(in_order, 4 * MC_HDR_REMAP_SIZE, 8).find("too small"), std::string::npos);
}

TEST(Corruption, DepthBeyondTheLimitIsRefused) {
  std::vector<uint8_t> b = build_blob(make_sphere(8, 16, 1, {0, 0, 0}), parse_layout("AABBTree/Float3"), "s");
  // max_depth is the header's 8th field; a tree deeper than it claims is refused.
  EXPECT_NE(corrupt(b, 7 * 4, 1u).find("deeper than"), std::string::npos);
}

TEST(Box, GrowingByAnEmptyBoxChangesNothing) {
  Box3 b;
  b.grow(Vec3{1, 2, 3});
  Box3 empty;
  b.grow(empty);
  EXPECT_EQ(b.min.x, 1.0f);
  EXPECT_EQ(b.max.z, 3.0f);
  EXPECT_FLOAT_EQ(b.half_area(), 0.0f);
}

}  // namespace
}  // namespace meshcast::testing
