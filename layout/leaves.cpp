#include "layout/leaves.h"

#include <cmath>
#include <vector>

#include "layout/aabbtree.h"
#include "layout/codecs.h"
#include "layout/quadtree.h"

namespace meshcast::layout {

void for_each_leaf(const uint8_t* blob, const std::function<void(uint32_t, uint32_t)>& visit) {
  const BlobHeader& h = header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  if (h.tree_format == MC_TREE_BRUTEFORCE) {
    for (uint32_t at = 0; at < h.tree_size;) {
      uint32_t count = load<uint32_t>(tree + at);
      visit(at + MC_BRUTE_RECORD_BYTES, count);
      uint32_t bytes = 0;
#define MC_BYTES(Codec, name) \
  if (h.triangle_format == Codec::kFormat)                                                           \
    bytes = uint32_t(stored_bytes<Codec>(blob, h.tree_offset + at + MC_BRUTE_RECORD_BYTES, count, ~0ull));
      MC_FOR_EACH_TRIANGLE_CODEC(MC_BYTES)
#undef MC_BYTES
      at += MC_BRUTE_RECORD_BYTES + bytes;
    }
  } else if (h.tree_format == MC_TREE_AABBTREEPNS) {
    for (uint32_t k = 0; k < h.node_count; ++k) {
      AABBNode n = load_aabb_node(tree + uint64_t(k) * MC_AABB_NODE_BYTES);
      if (n.is_leaf()) visit(pns_leaf_block(n, h), pns_leaf_count(n));
    }
  } else if (h.tree_format == MC_TREE_AABBTREE || h.tree_format == MC_TREE_AABBTREESPLITAXIS) {
    std::vector<uint32_t> stack{0};
    while (!stack.empty()) {
      uint32_t at = stack.back();
      stack.pop_back();
      AABBNode n = load_aabb_node(tree + at);
      if (n.is_leaf()) {
        visit(at + MC_AABB_NODE_BYTES, n.value());
      } else {
        stack.push_back(aabb_second_child(n, h.tree_format == MC_TREE_AABBTREESPLITAXIS));
        stack.push_back(at + MC_AABB_NODE_BYTES);
      }
    }
  } else {
    uint32_t props_at = h.tree_format == MC_TREE_QUADTREE ? QuadBoundsFloat::kPropertiesAt : QuadBoundsHalf::kPropertiesAt;
    std::vector<uint32_t> stack{h.root};
    while (!stack.empty()) {
      uint32_t p = stack.back();
      stack.pop_back();
      if (quad_count(p)) {
        visit(quad_offset(p), quad_count(p));
        continue;
      }
      for (int k = 3; k >= 0; --k)
        if (uint32_t c = quad_child_properties(tree + quad_offset(p), props_at, k)) stack.push_back(c);
    }
  }
}

void for_each_leaf_box(const uint8_t* blob,
                       const std::function<void(uint32_t, uint32_t, const float[3], const float[3])>& visit) {
  const BlobHeader& h = header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  if (h.tree_format == MC_TREE_BRUTEFORCE) {
    const float lo[3] = {-INFINITY, -INFINITY, -INFINITY}, hi[3] = {INFINITY, INFINITY, INFINITY};
    return for_each_leaf(blob, [&](uint32_t block, uint32_t count) { visit(block, count, lo, hi); });
  }
  if (h.tree_format == MC_TREE_AABBTREEPNS) {
    for (uint32_t k = 0; k < h.node_count; ++k) {
      AABBNode n = load_aabb_node(tree + uint64_t(k) * MC_AABB_NODE_BYTES);
      if (n.is_leaf()) visit(pns_leaf_block(n, h), pns_leaf_count(n), n.min, n.max);
    }
    return;
  }
  if (h.tree_format == MC_TREE_AABBTREE || h.tree_format == MC_TREE_AABBTREESPLITAXIS) {
    return for_each_leaf(blob, [&](uint32_t block, uint32_t count) {
      AABBNode n = load_aabb_node(tree + block - MC_AABB_NODE_BYTES);
      visit(block, count, n.min, n.max);
    });
  }
  bool half = h.tree_format == MC_TREE_QUADTREEHALFFLOAT;
  uint32_t props_at = half ? QuadBoundsHalf::kPropertiesAt : QuadBoundsFloat::kPropertiesAt;
  std::vector<uint32_t> stack{h.root};
  if (quad_count(h.root)) {  // a root leaf has no box above it
    const float lo[3] = {-INFINITY, -INFINITY, -INFINITY}, hi[3] = {INFINITY, INFINITY, INFINITY};
    return visit(quad_offset(h.root), quad_count(h.root), lo, hi);
  }
  while (!stack.empty()) {
    const uint8_t* node = tree + quad_offset(stack.back());
    stack.pop_back();
    for (int k = 0; k < 4; ++k) {
      uint32_t c = quad_child_properties(node, props_at, k);
      if (!c) continue;
      if (!quad_count(c)) {
        stack.push_back(c);
        continue;
      }
      float lo[3], hi[3];
      if (half) QuadBoundsHalf::decode(node, h, k, lo, hi);
      else QuadBoundsFloat::decode(node, h, k, lo, hi);
      visit(quad_offset(c), quad_count(c), lo, hi);
    }
  }
}

void decode_triangle(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
  const BlobHeader& h = header_of(blob);
#define MC_DECODE(Codec, name) \
  if (h.triangle_format == Codec::kFormat) return Codec::decode(blob, block, i, out);
  MC_FOR_EACH_TRIANGLE_CODEC(MC_DECODE)
#undef MC_DECODE
}

}  // namespace meshcast::layout
