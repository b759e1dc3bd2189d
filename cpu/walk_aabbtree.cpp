// AABBTree walker (seed 000 §5.1): test both children, descend into the
// nearer, push the farther with its entry distance, and drop a popped node
// that can no longer beat the closest hit.
#include "cpu/aabb_walk.h"
#include "layout/triangles/codecs.h"
#include "cpu/walk.h"
#include "layout/tree/aabbtree.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::AABBTree, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    walk_aabb_nodes(tree, r, c, [&](const layout::AABBNode& node, uint32_t at) {
      uint32_t block = at + MC_AABB_NODE_BYTES;
      test_leaf<Codec, kTest>(blob, r, h.tree_offset + block, node.value(), layout::slot_of(h, block, 0), c);
    });
  });
}

// AABBTreeSplitAxis walker (seed 000 §5.2): a node's box is tested when it
// is reached; an interior node sends the ray first into the child on its
// side of the split axis (the first child is the lower one) and pushes the
// other.
template <class Codec, TriangleTest kTest>
void walk(layout::tree::AABBTreeSplitAxis, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    uint32_t stack[MC_MAX_DEPTH + 2];
    int top = -1;
    uint32_t at = 0;
    for (;;) {
      layout::AABBNode node = layout::load_aabb_node(tree + at);
      if (box_test(r, node.min, node.max, c.t) != INFINITY) {
        if (!node.is_leaf()) {
          uint32_t lower = at + MC_AABB_NODE_BYTES, upper = layout::aabb_second_child(node, true);
          bool positive = !r.near_is_max[layout::aabb_split_axis(node)];
          stack[++top] = positive ? upper : lower;
          at = positive ? lower : upper;
          continue;
        }
        uint32_t block = at + MC_AABB_NODE_BYTES;
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + block, node.value(), layout::slot_of(h, block, 0), c);
      }
      if (top < 0) break;
      at = stack[top--];
    }
  });
}

// AABBTreePNS walker (seed 000 §5.3, seed 002): as AABBTreeSplitAxis, but
// the near child is one AND away: bit octant(dir) of the node's 8 bits.
template <class Codec, TriangleTest kTest>
void walk(layout::tree::AABBTreePNS, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    const uint32_t octant = layout::pns_octant(r.dir);
    uint32_t stack[MC_MAX_DEPTH + 2];
    int top = -1;
    uint32_t index = 0;
    for (;;) {
      layout::AABBNode node = layout::load_aabb_node(tree + uint64_t(index) * MC_AABB_NODE_BYTES);
      if (box_test(r, node.min, node.max, c.t) != INFINITY) {
        if (!node.is_leaf()) {
          uint32_t children[2] = {index + 1, layout::pns_second_index(node)};
          uint32_t bit = layout::pns_bits(node) >> octant & 1;
          stack[++top] = children[bit ^ 1];
          index = children[bit];
          continue;
        }
        uint32_t block = layout::pns_leaf_block(node, h);
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + block, layout::pns_leaf_count(node), layout::slot_of(h, block, 0), c);
      }
      if (top < 0) break;
      index = stack[top--];
    }
  });
}

#define MC_INSTANTIATE(Codec, name)                                                                 \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::AABBTreePNS, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&); \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::AABBTree, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&); \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::AABBTreeSplitAxis, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
