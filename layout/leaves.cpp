#include "layout/leaves.h"


#include <cmath>

#include "layout/aabblist.h"
#include "layout/aabbtree.h"
#include "layout/catalog.h"
#include "layout/codecs.h"
#include "layout/compressed.h"
#include "layout/lbvh.h"
#include "layout/quadtree.h"
#include "layout/skdtree.h"
#include "layout/zerobyte.h"

namespace meshcast::layout {

namespace {

PathBox box_of(const float min[3], const float max[3]) {
  PathBox b;
  for (int a = 0; a < 3; ++a) b.min[a] = min[a], b.max[a] = max[a];
  return b;
}

// One descent per tree family; `path` grows and shrinks with the recursion
// (depth is bounded by validation).
struct Descent {
  const uint8_t* blob;
  const BlobHeader& h;
  const uint8_t* tree;
  const LeafPathVisitor& visit;
  std::vector<PathBox> path;

  void leaf(uint32_t block, uint32_t count, const PathBox* own) {
    if (own) path.push_back(*own);
    visit(block, count, path);
    if (own) path.pop_back();
  }

  // BruteForce records from tree-section offset `at` up to `end`.
  void records(uint32_t at, uint32_t end) {
    while (at < end) {
      uint32_t count = load<uint32_t>(tree + at);
      leaf(at + MC_BRUTE_RECORD_BYTES, count, nullptr);
      uint64_t bytes = 0;
#define MC_BYTES(Codec, name) \
  if (h.triangle_format == Codec::kFormat) bytes = stored_bytes<Codec>(blob, h.tree_offset + at + MC_BRUTE_RECORD_BYTES, count, ~0ull);
      MC_FOR_EACH_TRIANGLE_CODEC(MC_BYTES)
#undef MC_BYTES
      at += MC_BRUTE_RECORD_BYTES + uint32_t(bytes);
    }
  }

  // AABBList: each batch's box above its records.
  void aabblist() {
    for (uint32_t b = 0; b < h.node_count; ++b) {
      ListEntry e = load_list_entry(tree, b);
      path.push_back(box_of(e.min, e.max));
      records(e.records, list_records_end(tree, h, b));
      path.pop_back();
    }
  }

  void aabbtree(uint32_t at) {
    AABBNode n = load_aabb_node(tree + at);
    PathBox b = box_of(n.min, n.max);
    if (n.is_leaf()) return leaf(at + MC_AABB_NODE_BYTES, n.value(), &b);
    path.push_back(b);
    aabbtree(at + MC_AABB_NODE_BYTES);
    aabbtree(aabb_second_child(n, h.tree_format == MC_TREE_AABBTREESPLITAXIS));
    path.pop_back();
  }

  // Zero-byte trees: every node is a block of its own triangles; a hybrid
  // leaf's box sits above its zero-byte tree.
  void zerobyte(uint32_t root) {
    for_each_zbt_node(blob, root, path, [&](uint32_t p, ZbtNode n, const std::vector<PathBox>& boxes) {
      visit(root + p * Indexed24::kSlotDivisor, n.count, boxes);
    });
  }

  void hybrid(uint32_t at) {
    AABBNode n = load_aabb_node(tree + at);
    path.push_back(box_of(n.min, n.max));
    if (n.is_leaf()) {
      zerobyte(h.triangle_base + n.value() * Indexed24::kSlotDivisor);
    } else {
      hybrid(at + MC_AABB_NODE_BYTES);
      hybrid(n.value());
    }
    path.pop_back();
  }

  void pns(uint32_t index) {
    AABBNode n = load_aabb_node(tree + uint64_t(index) * MC_AABB_NODE_BYTES);
    PathBox b = box_of(n.min, n.max);
    if (n.is_leaf()) return leaf(pns_leaf_block(n, h), pns_leaf_count(n), &b);
    path.push_back(b);
    pns(index + 1);
    pns(pns_second_index(n));
    path.pop_back();
  }

  void compressed(uint32_t at, const CompressedBox& box) {
    CompressedNode n = load<CompressedNode>(tree + at);
    CompressedBox child[2];
    n.unpack(box, child[0], child[1]);
    const uint32_t offset[2] = {at + MC_COMPRESSED_NODE_BYTES, n.right}, count[2] = {n.left_count(), n.right_count()};
    path.push_back(box_of(box.min, box.max));
    for (int k = 0; k < 2; ++k) {
      PathBox b = box_of(child[k].min, child[k].max);
      if (count[k]) leaf(offset[k], count[k], &b);
      else compressed(offset[k], child[k]);
    }
    path.pop_back();
  }

  void skd(uint32_t at, const PathBox& region) {
    uint32_t p = load<uint32_t>(tree + at);
    if (skd_is_leaf(p)) return leaf(at + MC_SKD_LEAF_BYTES, skd_value(p), &region);
    PathBox l, r;
    skd_child_regions(tree + at, region.min, region.max, l.min, l.max, r.min, r.max);
    path.push_back(region);
    skd(at + MC_SKD_INTERIOR_BYTES, l);
    skd(skd_value(p), r);
    path.pop_back();
  }

  void lbvh(uint32_t index) {
    LBVHNode n = load_lbvh_node(tree, index);
    PathBox b = box_of(n.min, n.max);
    if (n.count > 0) return leaf(n.position, uint32_t(n.count), &b);
    path.push_back(b);
    lbvh(2 * index);
    lbvh(2 * index + 1);
    path.pop_back();
  }

  template <class Bounds>
  void quadtree(uint32_t properties) {
    const uint8_t* node = tree + quad_offset(properties);
    for (int k = 0; k < 4; ++k) {
      uint32_t c = quad_child_properties(node, Bounds::kPropertiesAt, k);
      if (!c) continue;
      PathBox b;
      Bounds::decode(node, h, k, b.min, b.max);
      if (quad_count(c)) {
        leaf(quad_offset(c), quad_count(c), &b);
        continue;
      }
      path.push_back(b);
      quadtree<Bounds>(c);
      path.pop_back();
    }
  }

  // Where each tree format's descent starts (the catalog's switch calls these).
  void from_root(tree::BruteForce) { records(0, h.tree_size); }
  void from_root(tree::AABBList) { aabblist(); }
  void from_root(tree::AABBTree) { aabbtree(0); }
  void from_root(tree::AABBTreeSplitAxis) { aabbtree(0); }
  void from_root(tree::AABBTreePNS) { pns(0); }
  void from_root(tree::ZeroByteTree) { zerobyte(h.triangle_base); }
  void from_root(tree::ZeroByteHybrid) { hybrid(0); }
  void from_root(tree::AABBTreeCompressed) {
    const CompressedBox root = compressed_root_box(tree);
    if (uint32_t count = compressed_root_count(tree)) {
      PathBox b = box_of(root.min, root.max);
      return leaf(MC_COMPRESSED_HEADER_BYTES, count, &b);
    }
    compressed(MC_COMPRESSED_HEADER_BYTES, root);
  }
  void from_root(tree::SKDTree) { skd(0, box_of(h.bounds_min, h.bounds_max)); }
  void from_root(tree::StacklessLBVH) { lbvh(1); }
  void from_root(tree::QuadTree) { quad_root<QuadBoundsFloat>(); }
  void from_root(tree::QuadTreeHalfFloat) { quad_root<QuadBoundsHalf>(); }
  template <class Bounds>
  void quad_root() {
    if (quad_count(h.root)) return leaf(quad_offset(h.root), quad_count(h.root), nullptr);
    quadtree<Bounds>(h.root);
  }
};

}  // namespace

void for_each_leaf_path(const uint8_t* blob, const LeafPathVisitor& visit) {
  const BlobHeader& h = header_of(blob);
  Descent d{blob, h, blob + h.tree_offset, visit, {}};
  with_tree_format(h.tree_format, 0, [&](auto tag) {
    d.from_root(tag);
    return 0;
  });
}

void for_each_leaf(const uint8_t* blob, const std::function<void(uint32_t, uint32_t)>& visit) {
  for_each_leaf_path(blob, [&](uint32_t block, uint32_t count, const std::vector<PathBox>&) { visit(block, count); });
}

void decode_triangle(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
  const BlobHeader& h = header_of(blob);
  if (h.triangle_format == MC_TRI_INDEXED24) return Indexed24::decode(blob, block, i, out);
#define MC_DECODE(Codec, name) \
  if (h.triangle_format == Codec::kFormat) return Codec::decode(blob, block, i, out);
  MC_FOR_EACH_TRIANGLE_CODEC(MC_DECODE)
#undef MC_DECODE
}

}  // namespace meshcast::layout
