// The wide trees' common plan (QuadTree, QuadTreeHalfFloat: 4 children;
// OctTreeCompressed: 8): which binary nodes become a wide node's children,
// and where nodes and leaf blocks go in the tree section in each of seed 000
// §4.3's node orders. The formats differ in node bytes, offset reach and how
// they code a child; the plan is one mechanism with the width a parameter.
#pragma once
#include <cstdint>
#include <utility>
#include <vector>

#include "builder/writer.h"

namespace meshcast {

struct WidePlan {
  uint32_t width = 4;
  std::vector<std::vector<uint32_t>> children;  // per wide node: its children's binary nodes
  std::vector<uint32_t> binary_of;              // wide node -> binary node
  std::vector<uint32_t> leaves;                 // binary leaves, in write order
  std::vector<uint32_t> leaf_offset;            // per binary node (leaves): tree-section offset
  std::vector<uint32_t> node_offset;            // per wide node
  std::vector<uint32_t> wide_index;             // per binary node (wide nodes)
  uint32_t depth = 0;                           // deepest wide node, root 0
};

// Which binary nodes stay nodes, and their up to `width` children: the
// collapse that least sums the nodes' surface areas (the expected node tests
// a ray) over the binary tree's own leaves, found exactly by a table over
// the binary tree (Ylitie, Karras and Laine 2017), so nodes are full where
// the tree allows it instead of a half-empty level above the leaves.
WidePlan plan_wide(const BuildTree& t, uint32_t width);

// Places the wide nodes (node_bytes each) and the leaf blocks (w.leaf_bytes)
// in `order` and fills the header's tree_size, node_bytes, node_count and
// triangle_base. InputError, naming `format`, when the section passes `reach`
// bytes (what the format's child offsets address).
void place_wide(Writer& w, WidePlan& p, NodeOrder order, uint32_t node_bytes, uint64_t reach, const std::string& format,
                const std::string& offsets);

// The tree-section offset a child of a wide node is addressed by: its leaf
// block, or its wide node.
inline uint32_t wide_child_offset(const BuildTree& t, const WidePlan& p, uint32_t n) {
  return t.nodes[n].leaf() ? p.leaf_offset[n] : p.node_offset[p.wide_index[n]];
}

}  // namespace meshcast
