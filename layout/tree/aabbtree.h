// AABBTree node (seed 000 §5.1), 28 bytes:
//   BoundingBoxMin (3 floats), BoundingBoxMax (3 floats), Properties (uint32)
// Properties high bit set: leaf, low bits = triangle count, block follows the
// node. Clear: first child follows the node, low bits = tree-section offset of
// the second child. The root node sits at tree-section offset 0.
// AABBTreeSplitAxis (§5.2) uses the same node, see aabb_second_child.
#pragma once
#include <cmath>
#include <cstddef>
#include <cstring>

#include "layout/blob_format.h"

namespace meshcast::layout {

struct AABBNode {
  float min[3];
  float max[3];
  uint32_t properties;

  bool is_leaf() const { return (properties & MC_AABB_LEAF_BIT) != 0; }
  uint32_t value() const { return properties & MC_AABB_VALUE_MASK; }
};
static_assert(sizeof(AABBNode) == MC_AABB_NODE_BYTES && offsetof(AABBNode, min) == MC_AABB_MIN_AT &&
              offsetof(AABBNode, max) == MC_AABB_MAX_AT && offsetof(AABBNode, properties) == MC_AABB_PROPERTIES_AT);

inline AABBNode load_aabb_node(const uint8_t* p) { return load<AABBNode>(p); }

// The second child of an interior node: AABBTree keeps 31 bits of offset,
// AABBTreeSplitAxis 29 (two bits of split axis above them).
inline uint32_t aabb_second_child(const AABBNode& n, bool split_axis) {
  return split_axis ? n.properties & MC_SPLITAXIS_OFFSET_MASK : n.value();
}
inline uint32_t aabb_split_axis(const AABBNode& n) { return (n.properties >> MC_SPLITAXIS_SHIFT) & 3; }

// AABBTreePNS fields (see formats.h).
inline uint32_t pns_bits(const AABBNode& n) { return (n.properties >> MC_PNS_SHIFT) & 0xFF; }
inline uint32_t pns_second_index(const AABBNode& n) { return n.properties & MC_PNS_INDEX_MASK; }
inline uint32_t pns_leaf_count(const AABBNode& n) { return (n.properties >> MC_PNS_COUNT_SHIFT) & 31; }
inline uint32_t pns_leaf_block(const AABBNode& n, const BlobHeader& h) {
  return h.triangle_base + 4 * (n.properties & MC_PNS_BLOCK_MASK);
}
// The octant bit of seed 002: sign bits of the direction, z | y << 1 | x << 2.
// Always inlined: the walkers' instruction sets must not share a copy (cpu/isa.h).
[[gnu::always_inline]] inline uint32_t pns_octant(const float dir[3]) {
  return uint32_t(std::signbit(dir[2])) | uint32_t(std::signbit(dir[1])) << 1 | uint32_t(std::signbit(dir[0])) << 2;
}

}  // namespace meshcast::layout
