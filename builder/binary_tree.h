// The binary AABB tree every layout is written from. Builders see only
// triangle boxes and centres, so one builder serves every format.
#pragma once
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/build.h"
#include "meshcast/mesh.h"
#include "layout/formats.h"

namespace meshcast {

// Box3::half_area, inline for the builder's loops (the library is built
// without contracted multiply-adds; the public one stays out of line so a
// caller's copy cannot round it another way). In double: float products of
// extents near 1e-30 underflow to 0 (every split then costs the same and
// the tree degenerates into a chain), and near 1e20 they overflow.
inline double box_half_area(const Box3& b) {
  if (b.empty()) return 0.0;
  const double x = double(b.max.x) - b.min.x, y = double(b.max.y) - b.min.y, z = double(b.max.z) - b.min.z;
  return x * y + y * z + z * x;
}

struct BuildNode {
  Box3 box;
  uint32_t left = 0, right = 0;  // children (interior nodes)
  uint32_t first = 0, count = 0; // range of BuildTree::order (leaves: count > 0)
  bool leaf() const { return count > 0; }
};

struct BuildTree {
  std::vector<BuildNode> nodes;  // nodes[0] is the root
  std::vector<uint32_t> order;   // triangle indices, leaf by leaf
  uint32_t depth = 0;            // deepest node, root = 0
  double sah_cost = 0;           // SAH with unit node and triangle costs, relative to the root box
  uint32_t leaf_count() const;
};

// The splitters of seed 000 §4.1 (meshcast/build.h's Splitter). Every one
// builds top down (build_topdown.h): a node with at most `leaf_size`
// triangles becomes a leaf; a larger one is always split, so no leaf
// exceeds leaf_size.

// SAH over 32 binned centres per axis (Günther et al. 2007).
// `depth_limit`: nodes at that depth become leaves whatever their count
// (StacklessLBVH's D - 1); InputError when such a leaf would exceed
// `leaf_capacity` primitives (MC_QUAD_MAX_COUNT triangles; fewer when a
// primitive is a group of triangles, as a pair of seed 003).
// `threads`: the build's threads (builder/build_threads.h); none, or one,
// builds on the caller's thread alone, to the same tree.
class BuildThreads;
BuildTree build_binning(const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit = ~0u,
                        uint32_t leaf_capacity = MC_QUAD_MAX_COUNT, BuildThreads* threads = nullptr);
BuildTree build_tree(const std::vector<Box3>& boxes, Splitter splitter, uint32_t leaf_size,
                     uint32_t depth_limit = ~0u, uint32_t leaf_capacity = MC_QUAD_MAX_COUNT,
                     BuildThreads* threads = nullptr);

// A tree built over groups of triangles (FixedLeafSize's runs of 4, seed
// 003's pairs) back to triangles: group k is members[start[k] .. start[k+1]),
// each position of g.order expands to its group's members, so a group stays
// whole in one leaf.
BuildTree expand_groups(const BuildTree& g, const std::vector<uint32_t>& members, const std::vector<uint32_t>& start);

// The option value among `all` whose name_of() matches `name`,
// case-insensitive; else InputError naming `what` and listing the valid ones.
template <class E>
E parse_named(const std::string& name, const std::vector<E>& all, const char* (*name_of)(E), const char* what) {
  std::string valid;
  for (E e : all) {
    std::string n = name_of(e);
    if (n.size() == name.size() && std::equal(n.begin(), n.end(), name.begin(), [](char a, char b) {
          return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
        }))
      return e;
    valid += " " + n;
  }
  throw InputError("unknown " + std::string(what) + " '" + name + "'; valid " + what + "s:" + valid);
}

// "Binning", "LongestAxis", ... case-insensitive; throws InputError listing
// the valid names.
Splitter parse_splitter(const std::string& name);
const char* splitter_name(Splitter s);
std::vector<Splitter> all_splitters();

// The triangles (by their box centres) in Morton order, one scale for all
// axes: the order the Morton splitter cuts.
std::vector<uint32_t> morton_sorted(const std::vector<Vec3>& centres);

// AABBList batches (meshcast/build.h's Grouping).
// The triangle order, batch after batch (every batch full but the last).
std::vector<uint32_t> group_batches(const std::vector<Box3>& boxes, uint32_t batch, Grouping grouping);
Grouping parse_grouping(const std::string& name);
const char* grouping_name(Grouping g);
std::vector<Grouping> all_groupings();

// One splitter step (see build_topdown.h for the contract).
struct BinningSplit {
  const std::vector<Box3>& boxes;
  const std::vector<Vec3>& centres;
  // Optional, 3 bytes a triangle: each triangle's bin on each axis, kept
  // from binning for the partition (which otherwise works them out again).
  // Threads splitting disjoint ranges write disjoint bytes.
  uint8_t* bins = nullptr;
  uint32_t operator()(uint32_t* begin, uint32_t* end, const Box3& cbox) const;
};

}  // namespace meshcast
