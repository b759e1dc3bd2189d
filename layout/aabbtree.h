// AABBTree node (seed 000 §5.1), 28 bytes:
//   BoundingBoxMin (3 floats), BoundingBoxMax (3 floats), Properties (uint32)
// Properties high bit set: leaf, low bits = triangle count, block follows the
// node. Clear: first child follows the node, low bits = tree-section offset of
// the second child. The root node sits at tree-section offset 0.
#pragma once
#include <cstring>

#include "layout/blob.h"

namespace meshcast::layout {

struct AABBNode {
  float min[3];
  float max[3];
  uint32_t properties;

  bool is_leaf() const { return (properties & MC_AABB_LEAF_BIT) != 0; }
  uint32_t value() const { return properties & MC_AABB_VALUE_MASK; }
};
static_assert(sizeof(AABBNode) == MC_AABB_NODE_BYTES);

inline AABBNode load_aabb_node(const uint8_t* p) { return load<AABBNode>(p); }

}  // namespace meshcast::layout
