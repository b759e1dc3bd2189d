// `meshcast bench splitters` and `meshcast bench leafsize`: seed 000 §4.1 and
// §4.2 on this machine.
#pragma once
#include <string>
#include <vector>

#include "bench/measure.h"

namespace meshcast::bench {

struct TreeRow {
  std::string label, layout;
  double seed_ms = 0;  // the source's figure, 0 where it has none
  Timing timing;
  double seed_tree_bytes = 0;
  double seed_bytes_per_tri = 0;  // §6 combinations: the source's bytes a triangle
  std::string refused{};          // why the layout cannot hold this mesh (no timing then)
};

// §4.1: every splitter, AABBTree/Float3 and AABBTree/Float3SOA4, leaf 8.
std::vector<TreeRow> bench_splitters(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §4.2: leaf sizes 4, 8, 16, AABBTree/Float3, Binning.
std::vector<TreeRow> bench_leafsize(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §6, first table: every tree format with Float3, leaf 8, Binning (Morton for
// StacklessLBVH, its seed's builder), and StacklessLBVH walked left first as
// seed 001 does.
std::vector<TreeRow> bench_trees(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §4.3: the four node orders, on the quad trees (the formats that take them).
std::vector<TreeRow> bench_order(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);
// §6, second table: every tree with every CPU triangle encoding (the
// 128-lane GPU blocks left out: in a tree each leaf pads to 128 lanes).
// Then seed 004's zero-byte variants: with and without the box cache and
// the shuffled bounds, the hybrid with leaves of 64, 256 and 1024.
// `only`: comma-separated parts of layout names to keep ("" keeps all).
std::vector<TreeRow> bench_combos(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat,
                                  const std::string& only = "");

// The offset test: QuadTreeHalfFloat (and its peers in this format
// family) on a mesh at the origin and the same mesh moved far away.
struct OffsetRow {
  std::string layout, mesh;  // "0.15 units at 1000" etc.
  Timing origin, offset;
};
std::vector<OffsetRow> bench_offset(const Mesh& mesh, const std::string& name, size_t rays, uint32_t repeat);

}  // namespace meshcast::bench
