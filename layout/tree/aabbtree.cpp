// The AABBTree family's readings (AABBTree, AABBTreeSplitAxis, AABBTreePNS):
// validation and the leaf descent over the nodes of layout/tree/aabbtree.h.
#include "layout/tree/tree_walks.h"

#include "layout/tree/aabbtree.h"
#include "layout/triangles/codecs.h"

namespace meshcast::layout {

namespace {

// AABBTree and AABBTreeSplitAxis: depth first from offset 0, each second
// child after its first.
std::string validate_aabb_nodes(const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles, bool split_axis) {
  return walk_nodes(h, 0, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_AABB_NODE_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    AABBNode n = load_aabb_node(blob + h.tree_offset + at);
    uint32_t next = at + MC_AABB_NODE_BYTES;
    if (n.is_leaf()) {
      *triangles += n.value();
      return check_leaf(codec, blob, h, next, n.value());
    }
    uint32_t second = aabb_second_child(n, split_axis);
    if (second <= next)
      return "node at tree offset " + num(at) + " has its second child at " + num(second) + ", not after its first child";
    if (split_axis && aabb_split_axis(n) > 2)
      return "node at tree offset " + num(at) + " names split axis " + num(aabb_split_axis(n)) + " (0..2)";
    push(next), push(second);
    return "";
  });
}

void descend_aabbtree(Descent& d, uint32_t at, bool split_axis) {
  AABBNode n = load_aabb_node(d.tree + at);
  PathBox b = box_of(n.min, n.max);
  if (n.is_leaf()) return d.leaf(at + MC_AABB_NODE_BYTES, n.value(), &b);
  d.path.push_back(b);
  descend_aabbtree(d, at + MC_AABB_NODE_BYTES, split_axis);
  descend_aabbtree(d, aabb_second_child(n, split_axis), split_axis);
  d.path.pop_back();
}

void descend_pns(Descent& d, uint32_t index) {
  AABBNode n = load_aabb_node(d.tree + uint64_t(index) * MC_AABB_NODE_BYTES);
  PathBox b = box_of(n.min, n.max);
  if (n.is_leaf()) return d.leaf(pns_leaf_block(n, d.h), pns_leaf_count(n), &b);
  d.path.push_back(b);
  descend_pns(d, index + 1);
  descend_pns(d, pns_second_index(n));
  d.path.pop_back();
}

}  // namespace

std::string validate_tree(tree::AABBTree, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return validate_aabb_nodes(codec, blob, h, triangles, false);
}

std::string validate_tree(tree::AABBTreeSplitAxis, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return validate_aabb_nodes(codec, blob, h, triangles, true);
}

// AABBTreePNS: nodes by index, each child after its parent.
std::string validate_tree(tree::AABBTreePNS, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  if (h.node_count == 0 || uint64_t(h.node_count) * MC_AABB_NODE_BYTES != h.triangle_base)
    return "AABBTreePNS: the triangle base must follow the " + num(h.node_count) + " nodes";
  return walk_nodes(h, 0, "node ", [&](uint32_t index, auto push) -> std::string {
    if (index >= h.node_count) return "node index " + num(index) + " past the " + num(h.node_count) + " nodes";
    AABBNode n = load_aabb_node(blob + h.tree_offset + uint64_t(index) * MC_AABB_NODE_BYTES);
    if (n.is_leaf()) {
      uint64_t block = uint64_t(h.triangle_base) + 4ull * (n.properties & MC_PNS_BLOCK_MASK);
      if (block > h.tree_size) return "leaf " + num(index) + " points past the tree section";
      *triangles += pns_leaf_count(n);
      return check_leaf(codec, blob, h, uint32_t(block), pns_leaf_count(n));
    }
    uint32_t second = pns_second_index(n);
    if (second <= index + 1) return "node " + num(index) + " has its second child at " + num(second) + ", not after its first";
    push(index + 1), push(second);
    return "";
  });
}

void from_root(Descent& d, tree::AABBTree) { descend_aabbtree(d, 0, false); }
void from_root(Descent& d, tree::AABBTreeSplitAxis) { descend_aabbtree(d, 0, true); }
void from_root(Descent& d, tree::AABBTreePNS) { descend_pns(d, 0); }

}  // namespace meshcast::layout
