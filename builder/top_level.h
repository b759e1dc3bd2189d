// Builds a scene's top level (layout/top_level.h) over placed instances whose
// world boxes are set: what Scene::commit() does once a frame.
#pragma once
#include <vector>

#include "layout/top_level.h"

namespace meshcast {

// A binary tree by median splits: each node's instances split in half at the
// median of their box centres along the widest axis of those centres
// (std::nth_element: O(n log n), no sort), down to leaves of at most
// kTopLeafSize. Every box is the union of its instances' boxes, in double,
// so nothing is rounded inward.
layout::TopLevel build_top_level(const std::vector<layout::PlacedInstance>& placed);

// The 8-wide nodes of top.wide and the anchor, made again from the binary
// nodes (each wide node takes the largest of its binary descendants' boxes
// apart until it has 8 children or only leaves): O(n), after every build
// and refit.
void collapse_top_level(layout::TopLevel& top);
// The wide nodes' boxes read again from the binary nodes they were
// collapsed from (top.wide_from), relative to the anchor: what a refit does
// after joining the binary boxes.
void fit_wide_boxes(layout::TopLevel& top);

// The same tree over instances that moved (top.placed updated in place,
// none added or taken away): every box joined again from the leaves up, in
// one pass over the nodes (children follow their parent in the array).
// O(n), where a build is O(n log n); the tree's splits stay as they were, so
// it fits less well the farther the instances have gone.
void refit_top_level(layout::TopLevel& top);

}  // namespace meshcast
