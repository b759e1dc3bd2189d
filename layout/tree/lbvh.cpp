// StacklessLBVH's readings: validation and the leaf descent over the heap
// of layout/tree/lbvh.h.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"
#include "layout/tree/lbvh.h"

namespace meshcast::layout {

namespace {

void descend_lbvh(Descent& d, uint32_t index) {
  LBVHNode n = load_lbvh_node(d.tree, index);
  PathBox b = box_of(n.min, n.max);
  if (n.count > 0) return d.leaf(n.position, uint32_t(n.count), &b);
  d.path.push_back(b);
  descend_lbvh(d, 2 * index);
  descend_lbvh(d, 2 * index + 1);
  d.path.pop_back();
}

}  // namespace

// StacklessLBVH: every node a walk reaches is a leaf or has both children
// inside the array; holes are never reached.
std::string validate_tree(tree::StacklessLBVH, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  if (h.node_count == 0 || h.node_count > (1u << (MC_LBVH_MAX_DEPTH + 1)) - 1 ||
      uint64_t(h.node_count) * MC_LBVH_NODE_BYTES != h.triangle_base)
    return "StacklessLBVH: " + num(h.node_count) + " node slots do not fit its heap or its triangle base";
  return walk_nodes(h, 1, "node ", [&](uint32_t index, auto push) -> std::string {
    LBVHNode n = load_lbvh_node(tree, index);
    if (n.count == 0) return "node " + num(index) + " is a hole but its parent is an interior node";
    if (n.count > 0) {
      *triangles += uint32_t(n.count);
      return check_leaf(codec, blob, h, n.position, uint32_t(n.count));
    }
    if (uint64_t(index) * 2 + 1 > h.node_count)
      return "node " + num(index) + " has children past the " + num(h.node_count) + " node slots";
    push(2 * index), push(2 * index + 1);
    return "";
  });
}

void from_root(Descent& d, tree::StacklessLBVH) { descend_lbvh(d, 1); }

}  // namespace meshcast::layout
