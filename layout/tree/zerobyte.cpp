// Validation and the read-back walk of the zero-byte formats (seed 004).
#include "layout/tree/zerobyte.h"

#include <cmath>

#include "layout/tree/aabbtree.h"
#include "layout/tree/tree_walks.h"

namespace meshcast::layout {

namespace {


// Checks the zero-byte tree rooted at position `base` of the triangle area,
// marking the positions it covers; `end` bounds its positions. Every node
// lies after its parent and every position is claimed once, so a walk of a
// valid tree ends; depth within MC_MAX_DEPTH (the walkers' stacks).
std::string check_zbt(const uint8_t* blob, const BlobHeader& h, uint32_t base, uint32_t end, uint32_t depth0,
                      std::vector<uint8_t>& covered, uint32_t* max_depth) {
  const uint8_t* tris = blob + h.tree_offset + h.triangle_base + uint64_t(base) * 12;
  const uint8_t* vertices = blob + h.vertex_offset;
  const uint64_t vertex_count = h.vertex_size / 12;
  const uint32_t limit = end - base;
  struct Item { uint32_t p, depth; };
  std::vector<Item> stack{{0, depth0}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    if (it.depth > MC_MAX_DEPTH) return "zero-byte tree deeper than " + num(MC_MAX_DEPTH) + " levels";
    *max_depth = std::max(*max_depth, it.depth);
    ZbtNode n = zbt_node(tris, it.p);
    std::string at = "zero-byte node at triangle " + num(base + it.p);
    if (n.count == 0 || it.p + uint64_t(n.count) > limit)
      return at + " holds " + num(n.count) + " triangles, past its tree's " + num(limit) + " (allowed 1..7)";
    for (uint32_t i = 0; i < n.count; ++i) {
      if (covered[base + it.p + i]++) return at + " claims triangle " + num(base + it.p + i) + " a second time";
      for (int c = 0; c < 3; ++c)
        if (Indexed24::index(tris, 0, it.p + i, c) >= vertex_count)
          return at + " names vertex " + num(Indexed24::index(tris, 0, it.p + i, c)) + " of " + num(vertex_count);
    }
    if (n.count == 6 && zbt_shuffled(tris, it.p)) {
      for (int j = 0; j < 6; ++j)
        if (zbt_corner(tris, it.p, j) > 2) return at + " names corner 3 for its extreme " + num(j);
      // A shuffled box must be the box of the node's triangles, or rays
      // would be culled wrongly.
      float smn[3], smx[3], fmn[3], fmx[3];
      zbt_box(tris, vertices, it.p, n, smn, smx);
      for (int a = 0; a < 3; ++a) fmn[a] = INFINITY, fmx[a] = -INFINITY;
      for (uint32_t i = 0; i < 6; ++i)
        for (int c = 0; c < 3; ++c)
          for (int a = 0; a < 3; ++a) {
            float v = reinterpret_cast<const float*>(vertices + uint64_t(Indexed24::index(tris, 0, it.p + i, c)) * 12)[a];
            fmn[a] = std::min(fmn[a], v), fmx[a] = std::max(fmx[a], v);
          }
      for (int a = 0; a < 3; ++a)
        if (smn[a] != fmn[a] || smx[a] != fmx[a]) return at + " is marked shuffled but its named corners miss its box";
    }
    if (n.child == 0) continue;
    if (n.child < it.p + n.count || n.child >= limit) return at + " names child " + num(n.child) + " outside " + num(it.p + n.count) + ".." + num(limit);
    ZbtNode first = zbt_node(tris, n.child);
    uint32_t second = n.child + first.count;
    if (first.count == 0 || second >= limit) return at + "'s second child lies past its tree";
    stack.push_back({second, it.depth + 1});
    stack.push_back({n.child, it.depth + 1});
  }
  return "";
}

}  // namespace

std::string validate_zerobyte(std::span<const uint8_t> blob, const BlobHeader& h) {
  if (h.triangle_format != MC_TRI_INDEXED24) return "zero-byte trees need the Indexed24 triangle format";
  if (h.slot_divisor != Indexed24::kSlotDivisor || h.triangle_base != h.node_bytes ||
      h.tree_size != h.node_bytes + 12ull * h.triangle_count || h.remap_slots != h.triangle_count)
    return "zero-byte index buffer does not hold 12 bytes for each of the " + num(h.triangle_count) + " triangles";
  if (h.vertex_size % 12 != 0 || h.vertex_size / 12 > MC_ZBT_MAX_VERTICES)
    return "zero-byte vertex section of " + num(h.vertex_size) + " bytes is not 3 floats a vertex within 2^24 vertices";
  std::vector<uint8_t> covered(h.triangle_count, 0);
  uint32_t depth = 0;
  if (h.tree_format == MC_TREE_ZEROBYTE) {
    if (h.node_bytes != 0) return "ZeroByteTree has " + num(h.node_bytes) + " bytes of nodes; it has none";
    if (h.triangle_count > MC_ZBT_MAX_TRIANGLES) return "ZeroByteTree of " + num(h.triangle_count) + " triangles exceeds its 21-bit positions";
    if (std::string e = check_zbt(blob.data(), h, 0, h.triangle_count, 0, covered, &depth); !e.empty()) return e;
  } else {
    // AABBTree nodes: the first child follows its parent, the second lies
    // after it; each leaf's zero-byte tree ends before the next leaf's root.
    if (h.node_bytes % MC_AABB_NODE_BYTES != 0 || h.node_bytes == 0) return "hybrid node area is not whole AABBTree nodes";
    std::vector<uint32_t> roots;
    struct Item { uint32_t at, depth; };
    std::vector<Item> stack{{0, 0}};
    uint64_t visits = 0;
    while (!stack.empty()) {
      Item it = stack.back();
      stack.pop_back();
      if (++visits > h.node_bytes / MC_AABB_NODE_BYTES || it.depth > MC_MAX_DEPTH)
        return "hybrid nodes revisit a node or nest deeper than " + num(MC_MAX_DEPTH);
      AABBNode node = load_aabb_node(blob.data() + h.tree_offset + it.at);
      if (node.is_leaf()) {
        if (node.value() >= h.triangle_count) return "hybrid leaf at " + num(it.at) + " names triangle " + num(node.value());
        roots.push_back(node.value());
        depth = std::max(depth, it.depth);
        continue;
      }
      uint32_t left = it.at + MC_AABB_NODE_BYTES, right = node.value();
      if (right <= left || right % MC_AABB_NODE_BYTES != 0 || right >= h.node_bytes || left >= h.node_bytes)
        return "hybrid node at " + num(it.at) + " names child " + num(right) + " outside the node area";
      stack.push_back({right, it.depth + 1});
      stack.push_back({left, it.depth + 1});
    }
    std::sort(roots.begin(), roots.end());
    const uint32_t top_depth = depth;
    for (size_t i = 0; i < roots.size(); ++i) {
      if (i && roots[i] == roots[i - 1]) return "two hybrid leaves share triangle " + num(roots[i]);
      uint32_t end = i + 1 < roots.size() ? roots[i + 1] : h.triangle_count;
      if (end - roots[i] > MC_ZBT_MAX_TRIANGLES) return "hybrid leaf of " + num(end - roots[i]) + " triangles exceeds 21-bit positions";
      if (std::string e = check_zbt(blob.data(), h, roots[i], end, top_depth, covered, &depth); !e.empty()) return e;
    }
  }
  for (uint32_t i = 0; i < h.triangle_count; ++i) {
    if (!covered[i]) return "triangle " + num(i) + " of the index buffer belongs to no zero-byte node";
    // Every slot is a triangle: its remap bit must say so, or two slots
    // could name one triangle.
    if (has_remap(h) && !(remap_used(blob.data(), h, i / 64) >> (i % 64) & 1)) return "remap marks slot " + num(i) + " unused";
  }
  if (depth > MC_MAX_DEPTH) return "tree deeper than " + num(MC_MAX_DEPTH);
  return "";
}

void for_each_zbt_node(const uint8_t* blob, uint32_t root, std::vector<PathBox> path,
                       const std::function<void(uint32_t p, ZbtNode n, const std::vector<PathBox>& path)>& visit) {
  const BlobHeader& h = header_of(blob);
  const uint8_t* tris = blob + h.tree_offset + root;
  const uint8_t* vertices = blob + h.vertex_offset;
  // Depth first with an explicit path: each item remembers its path length.
  struct Item { uint32_t p; size_t depth; };
  std::vector<Item> stack{{0, path.size()}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    path.resize(it.depth);
    ZbtNode n = zbt_node(tris, it.p);
    if (n.child != 0) {
      PathBox b;
      zbt_box(tris, vertices, it.p, n, b.min, b.max);
      path.push_back(b);
    }
    visit(it.p, n, path);
    if (n.child == 0) continue;
    stack.push_back({n.child + zbt_node(tris, n.child).count, path.size()});
    stack.push_back({n.child, path.size()});
  }
}

namespace {

// Zero-byte trees: every node is a block of its own triangles; a hybrid
// leaf's box sits above its zero-byte tree.
void descend_zerobyte(Descent& d, uint32_t root) {
  for_each_zbt_node(d.blob, root, d.path, [&](uint32_t p, ZbtNode n, const std::vector<PathBox>& boxes) {
    d.visit(root + p * Indexed24::kSlotDivisor, n.count, boxes);
  });
}

void descend_hybrid(Descent& d, uint32_t at) {
  AABBNode n = load_aabb_node(d.tree + at);
  d.path.push_back(box_of(n.min, n.max));
  if (n.is_leaf()) {
    descend_zerobyte(d, d.h.triangle_base + n.value() * Indexed24::kSlotDivisor);
  } else {
    descend_hybrid(d, at + MC_AABB_NODE_BYTES);
    descend_hybrid(d, n.value());
  }
  d.path.pop_back();
}

}  // namespace

void from_root(Descent& d, tree::ZeroByteTree) { descend_zerobyte(d, d.h.triangle_base); }
void from_root(Descent& d, tree::ZeroByteHybrid) { descend_hybrid(d, 0); }

}  // namespace meshcast::layout
