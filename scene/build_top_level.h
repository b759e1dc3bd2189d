// Builds and refits a scene's top level (layout/tree/top_level.h) over the
// instances' world boxes: what Scene::commit() does once a frame.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "layout/tree/top_level.h"

namespace meshcast {

// What an instance's triangles cover in the world, padded outward (Scene
// places it); kept by the scene's edits, not walked.
struct WorldBox {
  double min[3], max[3];
};

// The tree over boxes[ids[i]], the instances to place: a binary tree by
// median splits (each node's instances split in half at the median of their
// box centres along the widest axis of those centres: std::nth_element,
// O(n log n), no sort), down to leaves of one instance, collapsed to 8-wide
// nodes (each takes the largest of its binary descendants' boxes apart until
// it has 8 children or only leaves), then fitted as refit_top_level does.
// The binary tree is not kept. `order` gets the ids in the walk's order: the
// caller fills top.placed[k] with instance order[k]'s record.
void build_top_level(std::span<const WorldBox> boxes, std::span<const uint32_t> ids, layout::TopLevel& top,
                     std::vector<uint32_t>& order);

// The same tree's boxes after its instances moved (none added or taken
// away; placed k's box is boxes[order[k]]): the root box and the anchor
// (its centre) from the instances' boxes in double, then every wide node
// from the last to the first, an instance's slot its box rounded outward to
// float relative to the anchor, a node's slot the union of that node's
// slots. O(n), where a build is O(n log n); the splits stay as they were,
// so the tree fits less well the farther the instances have gone.
void refit_top_level(std::span<const WorldBox> boxes, std::span<const uint32_t> order, layout::TopLevel& top);

}  // namespace meshcast
