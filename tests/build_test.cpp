// The builder, the blob writer and their limits.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <functional>
#include <set>

#include "builder/binary_tree.h"
#include "builder/build_threads.h"
#include "builder/tree_source.h"
#include "builder/writer.h"
#include "check/generate.h"
#include "layout/blob_format.h"
#include "layout/catalog.h"
#include "layout/tree/leaves.h"
#include "tests/testing.h"

namespace meshcast::testing {
namespace {

std::vector<Box3> triangle_boxes(const Mesh& m) {
  std::vector<Box3> boxes(m.triangles.size());
  for (size_t t = 0; t < m.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) boxes[t].grow(m.corner(t, c));
  return boxes;
}

bool contains(const Box3& outer, const Box3& inner) {
  for (int a = 0; a < 3; ++a)
    if (inner.min[a] < outer.min[a] || inner.max[a] > outer.max[a]) return false;
  return true;
}

TEST(Binning, LeavesRespectTheLeafSizeAndCoverEveryTriangleOnce) {
  Mesh m = make_terrain(64, 64, 3);
  std::vector<Box3> boxes = triangle_boxes(m);
  for (uint32_t leaf : {4u, 8u, 16u}) {
    BuildTree t = build_binning(boxes, leaf);
    std::multiset<uint32_t> seen;
    for (const BuildNode& n : t.nodes) {
      if (n.leaf()) {
        EXPECT_LE(n.count, leaf);
        for (uint32_t i = n.first; i < n.first + n.count; ++i) {
          seen.insert(t.order[i]);
          EXPECT_TRUE(contains(n.box, boxes[t.order[i]]));
        }
      } else {
        EXPECT_TRUE(contains(n.box, t.nodes[n.left].box));
        EXPECT_TRUE(contains(n.box, t.nodes[n.right].box));
      }
    }
    ASSERT_EQ(seen.size(), m.triangles.size());
    for (uint32_t i = 0; i < m.triangles.size(); ++i) EXPECT_EQ(seen.count(i), 1u);
    EXPECT_GT(t.sah_cost, 0);
    EXPECT_LE(t.depth, 40u);
  }
}

// SAH cost of a median split by the longest axis of the centres, written
// here as an independent reference: Binning must do at least as well.
double median_split_sah(const std::vector<Box3>& boxes, uint32_t leaf) {
  std::vector<uint32_t> order(boxes.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  Box3 root;
  for (const Box3& b : boxes) root.grow(b);
  double cost = 0;
  std::function<void(uint32_t, uint32_t)> split = [&](uint32_t first, uint32_t count) {
    Box3 box, centres;
    for (uint32_t i = first; i < first + count; ++i) box.grow(boxes[order[i]]), centres.grow(boxes[order[i]].centre());
    cost += box.half_area() / root.half_area() * (count <= leaf ? count : 1);
    if (count <= leaf) return;
    Vec3 e = centres.extent();
    int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    std::nth_element(order.begin() + first, order.begin() + first + count / 2, order.begin() + first + count,
                     [&](uint32_t a, uint32_t b) { return boxes[a].centre()[axis] < boxes[b].centre()[axis]; });
    split(first, count / 2);
    split(first + count / 2, count - count / 2);
  };
  split(0, uint32_t(boxes.size()));
  return cost;
}

TEST(Binning, BeatsAMedianSplit) {
  std::vector<Mesh> meshes = {make_sphere(64, 128, 1, {0, 0, 0}), make_terrain(128, 128, 9)};
  if (std::optional<Mesh> bunny = data_mesh("bunny00")) meshes.push_back(std::move(*bunny));
  for (const Mesh& m : meshes) {
    std::vector<Box3> boxes = triangle_boxes(m);
    double binning = build_binning(boxes, 8).sah_cost, median = median_split_sah(boxes, 8);
    EXPECT_LE(binning, median) << m.triangles.size() << " triangles";
  }
}

TEST(Splitters, EveryOneRespectsTheLeafSizeAndCoversEveryTriangleOnce) {
  Mesh m = make_terrain(48, 40, 3);
  std::vector<Box3> boxes = triangle_boxes(m);
  for (Splitter s : all_splitters())
    for (uint32_t leaf : {4u, 8u, 16u}) {
      BuildTree t = build_tree(boxes, s, leaf);
      std::vector<int> seen(m.triangles.size(), 0);
      uint32_t leaves = 0, not_multiple_of_4 = 0;
      for (const BuildNode& n : t.nodes) {
        if (!n.leaf()) {
          EXPECT_TRUE(contains(n.box, t.nodes[n.left].box) && contains(n.box, t.nodes[n.right].box));
          continue;
        }
        ++leaves;
        EXPECT_LE(n.count, leaf) << splitter_name(s);
        not_multiple_of_4 += n.count % 4 != 0;
        for (uint32_t i = n.first; i < n.first + n.count; ++i) {
          ++seen[t.order[i]];
          EXPECT_TRUE(contains(n.box, boxes[t.order[i]]));
        }
      }
      for (int c : seen) ASSERT_EQ(c, 1) << splitter_name(s);
      // FixedLeafSize: whole groups of 4, but for the one short group.
      if (s == Splitter::FixedLeafSize && leaf >= 4) {
        EXPECT_LE(not_multiple_of_4, 1u);
      }
      EXPECT_LE(t.depth, 48u) << splitter_name(s);
    }
  EXPECT_EQ(parse_splitter("morton"), Splitter::Morton);
  EXPECT_THROW(parse_splitter("Octree"), InputError);
}

// The seed's greedy grouping, written the slow obvious way: the unused
// triangle lowest along the sweep axis (ties: lower index) and the
// batch - 1 unused ones nearest to its centre (ties: lower along the
// sweep, then lower index), batch after batch.
std::vector<std::set<uint32_t>> greedy_batches_by_hand(const std::vector<Box3>& boxes, uint32_t batch) {
  std::vector<Vec3> c;
  Box3 all;
  for (const Box3& b : boxes) c.push_back(b.centre()), all.grow(b.centre());
  const Vec3 e = all.extent();
  const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
  auto before = [&](uint32_t a, uint32_t b) { return c[a][axis] < c[b][axis] || (c[a][axis] == c[b][axis] && a < b); };
  std::vector<bool> used(boxes.size(), false);
  std::vector<std::set<uint32_t>> out;
  for (;;) {
    uint32_t seed = ~0u;
    for (uint32_t i = 0; i < boxes.size(); ++i)
      if (!used[i] && (seed == ~0u || before(i, seed))) seed = i;
    if (seed == ~0u) break;  // every box taken
    std::vector<uint32_t> rest;
    for (uint32_t i = 0; i < boxes.size(); ++i)
      if (!used[i] && i != seed) rest.push_back(i);
    auto d2 = [&](uint32_t i) {
      double dx = double(c[i].x) - c[seed].x, dy = double(c[i].y) - c[seed].y, dz = double(c[i].z) - c[seed].z;
      return dx * dx + dy * dy + dz * dz;
    };
    std::sort(rest.begin(), rest.end(), [&](uint32_t a, uint32_t b) { return d2(a) < d2(b) || (d2(a) == d2(b) && before(a, b)); });
    rest.resize(std::min<size_t>(rest.size(), batch - 1));
    rest.push_back(seed);
    for (uint32_t i : rest) used[i] = true;
    out.emplace_back(rest.begin(), rest.end());
  }
  return out;
}

TEST(AABBListGrouping, ClosestCentroidIsTheSeedsGreedyAndMortonCoversAll) {
  // A terrain (flat: the sweep runs along its long side) and a sphere.
  for (const Mesh& m : {make_terrain(40, 24, 5), make_sphere(20, 30, 1, {0, 0, 0})}) {
    std::vector<Box3> boxes = triangle_boxes(m);
    std::vector<std::set<uint32_t>> expected = greedy_batches_by_hand(boxes, 64);
    std::vector<uint32_t> order = group_batches(boxes, 64, Grouping::ClosestCentroid);
    ASSERT_EQ(order.size(), boxes.size());
    ASSERT_EQ(expected.size(), (boxes.size() + 63) / 64);
    for (size_t b = 0; b < expected.size(); ++b) {
      std::set<uint32_t> got(order.begin() + b * 64, order.begin() + std::min(order.size(), b * 64 + 64));
      EXPECT_EQ(got, expected[b]) << "batch " << b << " of " << m.triangles.size() << " triangles";
    }
    std::vector<uint32_t> morton = group_batches(boxes, 64, Grouping::Morton);
    std::sort(morton.begin(), morton.end());
    for (uint32_t i = 0; i < morton.size(); ++i) ASSERT_EQ(morton[i], i);
  }
  EXPECT_EQ(parse_grouping("morton"), Grouping::Morton);
  EXPECT_THROW(parse_grouping("Octree"), InputError);
}

TEST(Binning, CoincidentCentresStillSplit) {
  Mesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 1000; ++i) m.triangles.push_back({0, 1, 2});
  BuildTree t = build_binning(triangle_boxes(m), 8);
  for (const BuildNode& n : t.nodes)
    if (n.leaf()) {
      EXPECT_LE(n.count, 8u);
    }
  EXPECT_LE(t.depth, 12u);
}

TEST(Build, TwoMillionTriangleTerrainBuildsAndValidates) {
  Mesh m = make_terrain(1024, 1024, 5);
  ASSERT_EQ(m.triangles.size(), 2097152u);
  for (const char* layout : {"AABBTree/Float3", "QuadTree/Float3SOA4", "QuadTreeHalfFloat/Indexed8BitPackSOA4"}) {
    std::vector<uint8_t> blob = build_blob(m, parse_layout(layout), "terrain");
    EXPECT_EQ(layout::validate(blob), "") << layout;
  }
}

// The build's threads never change the blob: every layout, splitter and
// pairing builds to the same bytes on one thread and on several (the mesh is
// large enough that the tree is split across threads and leaves are encoded
// at once), and a refused build is refused the same way on any number.
TEST(Build, AnyNumberOfThreadsBuildsTheSameBytes) {
  const Mesh m = make_terrain(96, 96, 3);  // 18,432 triangles
  auto bytes = [&](BuildOptions o, uint32_t threads) {
    o.threads = threads;
    return build_blob(m, o, "terrain");
  };
  std::vector<std::string> names;
  for (Layout layout : all_layouts())
    if (layout.tree != TreeFormat::ZeroByteTree && layout.tree != TreeFormat::ZeroByteHybrid)  // no binary tree
      names.push_back(layout_name(layout));
  for (const std::string& name : covering_layouts(names)) {
    BuildOptions o;
    o.layout = parse_layout_name(name);
    EXPECT_EQ(bytes(o, 5), bytes(o, 1)) << name;
  }
  for (Splitter s : all_splitters()) {
    BuildOptions o = parse_layout("AABBTree/Float3");
    o.splitter = s;
    EXPECT_EQ(bytes(o, 4), bytes(o, 1)) << splitter_name(s);
  }
  BuildOptions paired;
  paired.pairing = true;
  EXPECT_EQ(bytes(paired, 4), bytes(paired, 1));

  // A depth limit too tight for the mesh: refused the same way.
  BuildOptions tight = parse_layout("StacklessLBVH/Float3");
  tight.lbvh_depth = 8;
  std::string one_thread, many;
  try {
    bytes(tight, 1);
  } catch (const InputError& e) {
    one_thread = e.what();
  }
  try {
    bytes(tight, 4);
  } catch (const InputError& e) {
    many = e.what();
  }
  EXPECT_NE(one_thread.find("raise the depth limit"), std::string::npos) << one_thread;
  EXPECT_EQ(many, one_thread);
}

// What a build's thread throws reaches the caller, the caller's own part's
// first (as a one-thread build, which builds that part first, raises it),
// and the threads are all there for the next fork.
TEST(BuildThreads, ExceptionsReachTheCallerAndNoThreadIsLost) {
  BuildThreads threads(4);
  auto message = [](auto&& call) {
    try {
      call();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("nothing thrown");
  };
  EXPECT_EQ(message([&] { threads.fork([] { throw InputError("side"); }, [] {}); }), "side");
  EXPECT_EQ(message([&] { threads.fork([] {}, [] { throw InputError("main"); }); }), "main");
  EXPECT_EQ(message([&] { threads.fork([] { throw InputError("side"); }, [] { throw InputError("main"); }); }), "main");
  EXPECT_EQ(message([&] {
              threads.for_each(100000, 64, [](uint64_t i) {
                if (i == 77777) throw InputError("item " + std::to_string(i));
              });
            }),
            "item 77777");
  // Nested forks, as the tree build makes them, each side counted once.
  std::atomic<int> ran{0};
  std::function<void(int)> split = [&](int depth) {
    if (depth == 0) {
      ++ran;
      return;
    }
    threads.fork([&] { split(depth - 1); }, [&] { split(depth - 1); });
  };
  split(6);
  EXPECT_EQ(ran.load(), 64);
  std::vector<uint64_t> out(10000, 0);
  threads.for_each(out.size(), 7, [&](uint64_t i) { out[i] = i * i; });
  for (uint64_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], i * i);

  BuildOptions too_many;
  too_many.threads = kMaxBuildThreads + 1;
  expect_throws<InputError>([&] { build_blob(make_grid_plane(4, 4), too_many, "grid"); }, {"grid", "1025", "1024"});
}

TEST(Build, RecommendedLayoutFitsSixteenBytesPerTriangleOnBunny) {
  std::optional<Mesh> bunny = data_mesh("bunny00");
  if (!bunny) GTEST_SKIP() << "data/bunny00.off not fetched";
  std::vector<uint8_t> blob = build_blob(*bunny, parse_layout("QuadTreeHalfFloat/Indexed8BitPackSOA4"), "bunny00");
  const layout::BlobHeader& h = layout::header_of(blob.data());
  // Everything a walk reads: header, nodes, triangle blocks, vertices.
  double walked = double(h.vertex_offset + h.vertex_size) / double(h.triangle_count);
  EXPECT_LE(walked, 16.0);
  EXPECT_EQ(h.node_count * MC_QUADHALF_NODE_BYTES, h.node_bytes);
  EXPECT_EQ(h.tree_offset % 64, 0u);  // 64-byte nodes on cache lines (given an aligned buffer)
}

TEST(Build, BadMeshesAreRefusedWithTheirNameAndProblem) {
  Mesh empty;
  EXPECT_THROW(build_blob(empty, {}, "empty.off"), InputError);
  Mesh nan_vertex;
  nan_vertex.vertices = {{0, 0, 0}, {1, NAN, 0}, {0, 1, 0}};
  nan_vertex.triangles = {{0, 1, 2}};
  try {
    build_blob(nan_vertex, {}, "nan.obj");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nan.obj"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos);
  }
  Mesh bad_index;
  bad_index.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  bad_index.triangles = {{0, 1, 3}};
  try {
    build_blob(bad_index, {}, "idx.ply");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("idx.ply"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("vertex 3"), std::string::npos);
  }
  Mesh ok = make_grid_plane(2, 2);
  BuildOptions big_leaf = parse_layout("QuadTree/Float3");
  big_leaf.leaf_size = 32;
  EXPECT_THROW(build_blob(ok, big_leaf, "grid"), InputError);
}

// What building a view of "level.mesh" is refused with, or "built".
std::string refusal(const MeshView& view) {
  try {
    build_blob(view, {}, "level.mesh");
  } catch (const InputError& e) {
    return std::string(e.what());
  }
  return std::string("built");
}

// A mesh from typed spans: interleaved vertices (position, normal, uv: 8
// floats) and 16-bit indices build the same blob as the packed mesh, and a
// stride or index buffer that does not fit the data is refused by name.
TEST(Build, TypedMeshViewsDeduceSizesAndRefuseWrongStrides) {
  const Mesh m = make_grid_plane(4, 3);
  std::vector<float> interleaved;
  for (const Vec3& v : m.vertices) interleaved.insert(interleaved.end(), {v.x, v.y, v.z, 0, 0, 1, 0.5f, 0.5f});
  std::vector<uint16_t> short_indices;
  std::vector<uint32_t> indices;
  for (const Triangle& t : m.triangles)
    for (uint32_t v : t) short_indices.push_back(uint16_t(v)), indices.push_back(v);
  const std::vector<uint8_t> expected = build_blob(m, {}, "grid");
  const MeshView interleaved16(interleaved, 8, short_indices);
  EXPECT_EQ(interleaved16.vertex_count, m.vertices.size());
  EXPECT_EQ(interleaved16.triangle_count, m.triangles.size());
  EXPECT_EQ(build_blob(interleaved16, {}, "grid"), expected);
  // The position third in a vertex: a subspan from the first vertex's x; the
  // last vertex then ends 5 floats before the buffer does.
  std::vector<float> normal_first;
  for (const Vec3& v : m.vertices) normal_first.insert(normal_first.end(), {0, 0, 1, v.x, v.y, v.z, 0.5f, 0.5f});
  EXPECT_EQ(build_blob(MeshView(std::span<const float>(normal_first).subspan(3), 8, indices), {}, "grid"), expected);

  // A stride under 3 floats, a last vertex cut short, indices that are not
  // whole triangles.
  const std::string under = refusal(MeshView(interleaved, 2, short_indices));
  EXPECT_NE(under.find("level.mesh"), std::string::npos) << under;
  EXPECT_NE(under.find("shorter than a position"), std::string::npos) << under;
  std::vector<float> cut(interleaved.begin(), interleaved.end() - 6);  // the last vertex's x and y alone
  const std::string short_vertex = refusal(MeshView(cut, 8, short_indices));
  EXPECT_NE(short_vertex.find("level.mesh"), std::string::npos) << short_vertex;
  EXPECT_NE(short_vertex.find("cut short"), std::string::npos) << short_vertex;
  std::vector<uint16_t> ragged(short_indices.begin(), short_indices.end() - 1);
  const std::string ragged_indices = refusal(MeshView(interleaved, 8, ragged));
  EXPECT_NE(ragged_indices.find("whole triangles"), std::string::npos) << ragged_indices;
  // By hand, with the sizes stated: the default 32-bit index type over a
  // 16-bit buffer reads past its end and is refused.
  MeshView by_hand;
  by_hand.positions = interleaved.data(), by_hand.vertex_count = m.vertices.size(), by_hand.vertex_stride = 32;
  by_hand.positions_bytes = interleaved.size() * sizeof(float);
  by_hand.indices = short_indices.data(), by_hand.triangle_count = m.triangles.size();
  by_hand.indices_bytes = short_indices.size() * sizeof(uint16_t);
  EXPECT_NE(refusal(by_hand).find("32-bit indices, fewer than three"), std::string::npos) << refusal(by_hand);
  by_hand.index_type = IndexType::Uint16;
  EXPECT_EQ(build_blob(by_hand, {}, "grid"), expected);
}

// A typed view's stride is named as the caller gave it, in floats: one
// under a position, one of bytes passed as floats (too few vertices for
// the indices), one whose bytes overflow. A view filled in by hand names
// its stride in bytes, refuses a stride whose product with the vertex
// count overflows, and an index_type that is neither IndexType.
TEST(Build, MeshViewsNameTheStrideAsGivenAndRefuseUnknownIndexTypes) {
  const std::vector<float> xyz = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::vector<uint32_t> one = {0, 1, 2};
  const std::string under = refusal(MeshView(xyz, 2, one));
  EXPECT_NE(under.find("level.mesh: vertex stride 2 floats is shorter than a position (3 floats)"), std::string::npos)
      << under;
  const std::string bytes = refusal(MeshView(xyz, 12, one));
  EXPECT_NE(bytes.find("triangle 0 uses vertex 1"), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("vertex stride 12 floats"), std::string::npos) << bytes;
  EXPECT_NE(bytes.find("floats, not bytes"), std::string::npos) << bytes;
  const std::string huge = refusal(MeshView(xyz, SIZE_MAX, one));
  EXPECT_NE(huge.find("vertices of vertex stride " + std::to_string(SIZE_MAX) + " floats do not fit in this process's "
                      "address space"),
            std::string::npos)
      << huge;
  EXPECT_EQ(refusal(MeshView(xyz, 3, one)), "built");

  MeshView by_hand;
  by_hand.positions = xyz.data(), by_hand.vertex_count = 3, by_hand.indices = one.data(), by_hand.triangle_count = 1;
  by_hand.vertex_stride = 8;
  const std::string short_bytes = refusal(by_hand);
  EXPECT_NE(short_bytes.find("vertex stride 8 bytes is shorter than a position (12 bytes"), std::string::npos)
      << short_bytes;
  by_hand.vertex_stride = SIZE_MAX / 2;  // times 3 vertices: past what memory addresses
  const std::string wraps = refusal(by_hand);
  EXPECT_NE(wraps.find("3 vertices of vertex stride " + std::to_string(SIZE_MAX / 2) +
                       " bytes do not fit in this process's address space"),
            std::string::npos)
      << wraps;
  by_hand.vertex_stride = 12;
  by_hand.triangle_stride = SIZE_MAX / 2, by_hand.triangle_count = 3;
  EXPECT_NE(refusal(by_hand).find("3 triangles of triangle stride " + std::to_string(SIZE_MAX / 2) +
                                  " bytes do not fit in this process's address space"),
            std::string::npos)
      << refusal(by_hand);
  by_hand.triangle_stride = 0, by_hand.triangle_count = SIZE_MAX / 64;  // refused before a copy is allocated
  EXPECT_NE(refusal(by_hand).find(std::to_string(SIZE_MAX / 64) + " triangles, more than 2^32-2"), std::string::npos)
      << refusal(by_hand);
  by_hand.triangle_count = 1;
  by_hand.index_type = IndexType(7);
  const std::string unknown = refusal(by_hand);
  EXPECT_NE(unknown.find("level.mesh: index_type 7 is neither IndexType::Uint16 (0) nor IndexType::Uint32 (1)"),
            std::string::npos)
      << unknown;
  by_hand.index_type = IndexType::Uint32;
  EXPECT_EQ(refusal(by_hand), "built");
}

// A mistyped layout name is answered with the few nearest names, not the
// whole list of some 200.
TEST(LayoutNames, AnUnknownNameOffersTheClosestFew) {
  auto refusal = [](const std::string& name) {
    try {
      parse_layout(name);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("parsed");
  };
  const std::string part = refusal("OctTree/Float3");  // the tree's name in part
  EXPECT_NE(part.find("did you mean OctTreeCompressed/Float3,"), std::string::npos) << part;
  const std::string typo = refusal("octtreecompressed/clusterbitpacksoa4");
  EXPECT_NE(typo.find("did you mean OctTreeCompressed/ClusterBitPackSOA8"), std::string::npos) << typo;
  const std::string half = refusal("ClusterBitPackSOA8");  // a triangle format alone
  EXPECT_NE(half.find("did you mean AABBTree/ClusterBitPackSOA8"), std::string::npos) << half;
  const std::string zero = refusal("ZeroByteTree/Float3");  // a tree that takes one triangle format
  EXPECT_NE(zero.find("ZeroByteTree/Indexed24"), std::string::npos) << zero;
  for (const std::string& m : {part, typo, half, zero}) EXPECT_LT(m.size(), 300u) << m;
}

// Format limits are build errors that name the limit.
TEST(Build, SixteenBitIndicesRefuseMeshesBeyondTheirReach) {
  Mesh big = make_grid_plane(300, 300);  // 90,601 vertices
  for (const char* layout : {"QuadTree/Indexed16", "BruteForce/Indexed16SOA4", "AABBTree/Indexed16BitPackSOA4"}) {
    try {
      build_blob(big, parse_layout(layout), "grid300");
      FAIL() << layout;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("16-bit indices reach 65536 vertices"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("grid300"), std::string::npos);
    }
  }
  // 32-bit indices take the same mesh.
  EXPECT_EQ(layout::validate(build_blob(big, parse_layout("QuadTree/Indexed32"), "grid300")), "");
}

// A tight StacklessLBVH depth limit with every splitter: the build evens out
// splits that would overfill the levels left, so it fits, keeps leaves at 31
// triangles or fewer, and stays within the limit.
TEST(Build, TightDepthLimitsFitWithEverySplitter) {
  Mesh m = make_sphere(24, 48, 1, {0, 0, 0});  // 2,208 triangles
  const uint32_t n = uint32_t(m.triangles.size());
  for (Splitter s : all_splitters()) {
    BuildOptions o = parse_layout("StacklessLBVH/Float3");
    o.splitter = s;
    o.lbvh_depth = uint32_t(std::bit_width(n / 28)) + 1;  // 28: FixedLeafSize's 7 groups of 4 a leaf
    std::vector<uint8_t> blob = build_blob(m, o, "sphere");
    ASSERT_EQ(layout::validate(blob), "") << splitter_name(s);
    EXPECT_LT(layout::header_of(blob.data()).max_depth, o.lbvh_depth) << splitter_name(s);
    uint32_t largest = 0, total = 0;
    layout::for_each_leaf(blob.data(), [&](uint32_t, uint32_t count) { largest = std::max(largest, count), total += count; });
    EXPECT_LE(largest, 31u) << splitter_name(s);
    EXPECT_EQ(total, n) << splitter_name(s);
  }
}

TEST(Build, NodeOrdersAFormatCannotHoldAreRefusedWithTheReason) {
  Mesh m = make_sphere(6, 12, 1, {0, 0, 0});
  BuildOptions o = parse_layout("AABBTree/Float3");
  o.node_order = NodeOrder::BreadthFirst;
  try {
    build_blob(m, o, "sphere");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("right behind"), std::string::npos) << e.what();
  }
  o.node_order = NodeOrder::DepthFirst;  // what AABBTree is anyway
  EXPECT_NO_THROW(build_blob(m, o, "sphere"));
  o = parse_layout("StacklessLBVH/Float3");
  o.lbvh_depth = 2;  // 31 triangles a leaf, 2 leaves: far too few for the sphere
  EXPECT_THROW(build_blob(m, o, "sphere"), InputError);
  EXPECT_EQ(parse_node_order("breadthfirsttriangleslast"), NodeOrder::BreadthFirstTrianglesLast);
  EXPECT_THROW(parse_node_order("Random"), InputError);
}

// The catalog's leaf size and splitter columns are the defaults the
// public API states: --leaf's "16 for OctTreeCompressed, 8 for the
// others", and the seed 001 heap built by Morton-code middle split.
TEST(Build, CatalogDefaultsAreTheLayoutsOwn) {
  EXPECT_EQ(layout::tree_format_info(MC_TREE_OCTTREECOMPRESSED).default_leaf_size, 16u);
  EXPECT_EQ(layout::tree_format_info(MC_TREE_AABBTREE).default_leaf_size, 8u);
  EXPECT_EQ(layout::tree_format_info(MC_TREE_STACKLESSLBVH).default_splitter, Splitter::Morton);
  EXPECT_EQ(layout::tree_format_info(MC_TREE_QUADTREEHALFFLOAT).default_splitter, Splitter::Binning);
  for (const std::string& name : layout_names()) {
    BuildOptions o = parse_layout(name);
    layout::TreeFormatInfo info = layout::tree_format_info(uint32_t(o.layout.tree));
    EXPECT_EQ(default_leaf_size(o.layout), info.default_leaf_size) << name;
    EXPECT_EQ(o.leaf_size, info.default_leaf_size) << name;
    EXPECT_EQ(o.splitter, info.default_splitter) << name;
  }
}

// Every tree format of the catalog, the zero-byte trees included, is built
// through its writer (builder/writer.h), not a path of its own.
TEST(Build, EveryTreeFormatHasAWriter) {
  for (const std::string& name : layout_names()) EXPECT_NE(make_tree_writer(parse_layout(name)), nullptr) << name;
  BuildOptions unknown;
  unknown.layout.tree = TreeFormat(0xFFFF);
  EXPECT_EQ(make_tree_writer(unknown), nullptr);
  try {
    build_blob(make_sphere(4, 8, 1, {0, 0, 0}), unknown, "sphere");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "sphere: unknown tree format");
  }
}

// The zero-byte trees' leaves and order are fixed by their bits: the leaf
// size and node order options, which the binary trees check, change
// nothing there.
TEST(Build, ZeroByteTreesIgnoreLeafSizeAndNodeOrder) {
  Mesh m = make_sphere(12, 24, 1, {0, 0, 0});
  for (const char* name : {"ZeroByteTree/Indexed24", "ZeroByteHybrid/Indexed24"}) {
    BuildOptions o = parse_layout(name);
    o.hybrid_leaf = 64;
    const std::vector<uint8_t> plain = build_blob(m, o, "sphere");
    o.leaf_size = 200;
    o.node_order = NodeOrder::BreadthFirst;
    EXPECT_EQ(build_blob(m, o, "sphere"), plain) << name;
  }
}

// A blob laid out over a tree another builder made (builder/tree_source.h):
// given the tree the options' splitter builds, the very bytes build_blob
// writes; a walk of it answers as the oracle; a tree that misses a
// triangle, holds one twice or names a child past the nodes is refused,
// as is a layout that keeps its own order.
TEST(Build, AGivenTreeLaysOutAsTheBuildersOwn) {
  const Mesh m = make_sphere(12, 24, 1, {0.5f, -0.25f, 1.0f});
  for (const char* name : {"OctTreeCompressed/ClusterBitPackSOA8", "QuadTree/Float3", "AABBTree/Float3"}) {
    const BuildOptions o = parse_layout(name);
    const TreeSource own = [&](const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit, uint32_t capacity) {
      return build_tree(boxes, o.splitter, leaf_size, depth_limit, capacity);
    };
    EXPECT_EQ(build_blob_over(m, o, "sphere", own), build_blob(m, o, "sphere")) << name;
  }
  // Another tree: every triangle a leaf of its own, in reverse, under a
  // chain of nodes. Laid out, it walks to the oracle's answers.
  const BuildOptions o = parse_layout("OctTreeCompressed/ClusterBitPackSOA8");
  const TreeSource chain = [](const std::vector<Box3>& boxes, uint32_t, uint32_t, uint32_t) {
    BuildTree t;
    const uint32_t n = uint32_t(boxes.size());
    for (uint32_t i = 0; i < n; ++i) t.order.push_back(n - 1 - i);
    // Balanced halves over `order`, leaves of 3 at most.
    std::function<uint32_t(uint32_t, uint32_t, uint32_t)> node = [&](uint32_t first, uint32_t count, uint32_t depth) {
      const uint32_t at = uint32_t(t.nodes.size());
      t.nodes.emplace_back();
      t.depth = std::max(t.depth, depth);
      for (uint32_t k = first; k < first + count; ++k) t.nodes[at].box.grow(boxes[t.order[k]]);
      if (count <= 3) {
        t.nodes[at].first = first, t.nodes[at].count = count;
        return at;
      }
      const uint32_t left = node(first, count / 2, depth + 1), right = node(first + count / 2, count - count / 2, depth + 1);
      t.nodes[at].left = left, t.nodes[at].right = right;
      return at;
    };
    node(0, n, 0);
    return t;
  };
  const std::vector<uint8_t> blob = build_blob_over(m, o, "sphere", chain);
  const NamedMesh named{"sphere", std::make_shared<const Mesh>(m)};
  const NamedMesh stored{"sphere#given tree", std::make_shared<const Mesh>(stored_mesh(blob))};
  const std::vector<Ray>& rays = test_rays(named, RayKind::Long, 2000);
  const Agreement a = compare(*stored.mesh, rays, trace_all(blob, rays), oracle_answers(stored, RayKind::Long, rays),
                              1e-5 * m.bounds().diagonal());
  EXPECT_EQ(a.wrong + a.t_errors + a.t_rounding, 0u) << a.first_problem;
  // Malformed trees, and the layouts that keep their own order.
  auto broken = [&](const std::function<void(BuildTree&)>& spoil) -> TreeSource {
    return [&, spoil](const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit, uint32_t capacity) {
      BuildTree t = build_tree(boxes, o.splitter, leaf_size, depth_limit, capacity);
      spoil(t);
      return t;
    };
  };
  EXPECT_THROW(build_blob_over(m, o, "sphere", broken([](BuildTree& t) { t.order.pop_back(); })), InputError);
  EXPECT_THROW(build_blob_over(m, o, "sphere", broken([](BuildTree& t) { t.order[1] = t.order[0]; })), InputError);
  EXPECT_THROW(build_blob_over(m, o, "sphere", broken([](BuildTree& t) { t.nodes[0].left = uint32_t(t.nodes.size()); })),
               InputError);
  EXPECT_THROW(build_blob_over(m, parse_layout("BruteForce/Float3SOA128"), "sphere", chain), InputError);
  EXPECT_THROW(build_blob_over(m, parse_layout("AABBList/Float3SOA128"), "sphere", chain), InputError);
  EXPECT_THROW(build_blob_over(m, parse_layout("ZeroByteTree/Indexed24"), "sphere", chain), InputError);
  EXPECT_THROW(build_blob_over(m, parse_layout("ZeroByteHybrid/Indexed24"), "sphere", chain), InputError);
}

TEST(Build, LayoutNamesAreCaseInsensitive) {
  EXPECT_EQ(uint32_t(parse_layout("quadtreehalffloat/indexed8bitpacksoa4").layout.tree), MC_TREE_QUADTREEHALFFLOAT);
}

}  // namespace
}  // namespace meshcast::testing
