// The binary AABB tree every layout is written from. Builders see only
// triangle boxes and centres, so one builder serves every format.
#pragma once
#include <cstdint>
#include <vector>

#include "cpu/mesh.h"

namespace meshcast {

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

// Binning (seed 000 §4.1, after Günther et al. 2007): at each node, triangle
// centres are sorted into bins along each axis and the split with the lowest
// surface area heuristic is taken. A node with at most `leaf_size` triangles
// becomes a leaf; a larger one is always split (by index at the median when
// all centres coincide), so no leaf exceeds leaf_size.
BuildTree build_binning(const std::vector<Box3>& boxes, uint32_t leaf_size);

}  // namespace meshcast
