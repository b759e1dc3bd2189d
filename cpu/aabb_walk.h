// The AABBTree walk of seed 000 §5.1, shared by AABBTree and the
// zero-byte hybrid's nodes: test both children, descend into the nearer,
// push the farther with its entry distance, and drop a popped node that can
// no longer beat the closest hit. leaf(node, offset) handles each leaf.
#pragma once
#include "cpu/leaf.h"
#include "layout/tree/aabbtree.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Leaf>
inline void walk_aabb_nodes(const uint8_t* tree, const RayPre& r, Closest& c, Leaf&& leaf) {
  struct Entry { uint32_t node; float tnear; };
  Entry stack[MC_MAX_DEPTH + 2];
  int top = -1;
  layout::AABBNode node = layout::load_aabb_node(tree);
  uint32_t at = 0;
  if (box_test(r, node.min, node.max, c.t) == INFINITY) return;
  for (;;) {
    if (!node.is_leaf()) {
      uint32_t left = at + MC_AABB_NODE_BYTES, right = node.value();
      layout::AABBNode ln = layout::load_aabb_node(tree + left), rn = layout::load_aabb_node(tree + right);
      float lt = box_test(r, ln.min, ln.max, c.t), rt = box_test(r, rn.min, rn.max, c.t);
      bool lhit = lt != INFINITY, rhit = rt != INFINITY;
      if (lhit && rhit) {
        if (lt <= rt) stack[++top] = {right, rt}, at = left, node = ln;
        else stack[++top] = {left, lt}, at = right, node = rn;
        continue;
      }
      if (lhit || rhit) {
        at = lhit ? left : right, node = lhit ? ln : rn;
        continue;
      }
    } else {
      leaf(node, at);
    }
    while (top >= 0 && stack[top].tnear > c.t * kFarScale) --top;
    if (top < 0) break;
    at = stack[top--].node;
    node = layout::load_aabb_node(tree + at);
  }
}

MC_ISA_END
}  // namespace meshcast
