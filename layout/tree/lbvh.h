// StacklessLBVH (seed 001): a pointer-less binary heap of 32-byte nodes
// (formats.h gives the fields). Children and the next node are arithmetic
// on the node number, so the walk needs no stack:
//   left(n) = 2n, right(n) = 2n + 1,
//   next(n) = (n + 1) / ((n + 1) ^ n & (n + 1)) = (n + 1) >> ctz(n + 1),
// the first right sibling of n or of its nearest ancestor that has one;
// the walk ends when next() returns the root.
#pragma once
#include <bit>
#include <cstddef>
#include <cstdint>

#include "layout/blob_format.h"

namespace meshcast::layout {

struct LBVHNode {
  float min[3], max[3];
  int32_t count;
  uint32_t position;
};
static_assert(sizeof(LBVHNode) == MC_LBVH_NODE_BYTES && offsetof(LBVHNode, min) == MC_LBVH_MIN_AT &&
              offsetof(LBVHNode, max) == MC_LBVH_MAX_AT && offsetof(LBVHNode, count) == MC_LBVH_COUNT_AT &&
              offsetof(LBVHNode, position) == MC_LBVH_POSITION_AT);

inline uint64_t lbvh_node_offset(uint32_t n) { return uint64_t(n - 1) * MC_LBVH_NODE_BYTES; }
inline LBVHNode load_lbvh_node(const uint8_t* tree, uint32_t n) { return load<LBVHNode>(tree + lbvh_node_offset(n)); }
inline uint32_t lbvh_next(uint32_t n) { return (n + 1) >> std::countr_zero(n + 1); }

}  // namespace meshcast::layout
