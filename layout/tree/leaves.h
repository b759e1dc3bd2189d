// Visits every leaf of a validated blob: (tree-section offset of its block,
// triangle count), with the boxes the walker decodes on the way down from
// the root to it. For tools and tests that read a blob back (the stored
// triangles, statistics, "every node's box contains what lies below it");
// the walkers do not use it.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace meshcast::layout {

struct PathBox {
  float min[3], max[3];
};

// `path` holds the decoded box of every node from the root down to the leaf
// itself, as the walker would use it (QuadTree: each child's box in its
// parent; SKDTree: the root box cut by each plane; AABBTreeCompressed: each
// box decoded from its parent's). A format with no box above a leaf
// (BruteForce; a QuadTree whose root is a leaf) gives an empty path.
using LeafPathVisitor = std::function<void(uint32_t block, uint32_t count, const std::vector<PathBox>& path)>;
void for_each_leaf_path(const uint8_t* blob, const LeafPathVisitor& visit);

void for_each_leaf(const uint8_t* blob, const std::function<void(uint32_t block, uint32_t count)>& visit);

// The corners of triangle `i` of the block at blob offset `block`, decoded
// by the blob's triangle format (the scalar decoders of layout/).
void decode_triangle(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]);
// All `count` triangles of the block at once (the same bits as
// decode_triangle gives each): a format whose triangles share a decode
// (the cluster formats: each cluster's vertices) does it once a leaf.
void decode_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]);

// Whether every box on each leaf's path holds the leaf's decoded corners
// (all finite): the walkers cull a subtree by its box, so a tree whose
// boxes miss their triangles would hide hits (and answer by the order of
// the walk). "" or what is wrong, naming the block and the box. For
// validate(), once the structure is known sound.
std::string check_tree_bounds(const uint8_t* blob);

}  // namespace meshcast::layout
