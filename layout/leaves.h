// Visits every leaf of a validated blob: (tree-section offset of its block,
// triangle count). For tools and tests that read a blob back (the stored
// triangles, statistics); the walkers do not use it.
#pragma once
#include <cstdint>
#include <functional>

namespace meshcast::layout {

void for_each_leaf(const uint8_t* blob, const std::function<void(uint32_t block, uint32_t count)>& visit);

// The same, with the leaf's box as the walker decodes it from the tree (the
// AABBTree leaf node, the QuadTree parent's child bounds; BruteForce has no
// boxes: infinite), for checking that bounds contain what they bound.
void for_each_leaf_box(const uint8_t* blob,
                       const std::function<void(uint32_t block, uint32_t count, const float min[3],
                                                const float max[3])>& visit);

// The corners of triangle `i` of the block at blob offset `block`, decoded
// by the blob's triangle format (the scalar decoders of layout/).
void decode_triangle(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]);

}  // namespace meshcast::layout
