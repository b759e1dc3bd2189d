// AABBTreeCompressed writer (seed 000 §5.4): depth first, the left child
// (node or triangle block) right behind its node, the right child after the
// left's subtree. Codes are chosen top down against the parent's decoded
// box (layout/tree/compressed.h), so they round outward from what the walker
// will decode, not from the exact boxes.
#include <functional>

#include "builder/writer.h"
#include "layout/tree/compressed.h"

namespace meshcast {

namespace {

class CompressedWriter : public TreeWriter {
 public:
  void plan(Writer& w) override {
    const BuildTree& t = w.tree;
    offset_.assign(t.nodes.size(), 0);
    uint64_t interior = 0;
    std::function<uint64_t(uint32_t, uint64_t)> place = [&](uint32_t n, uint64_t at) -> uint64_t {
      offset_[n] = uint32_t(std::min<uint64_t>(at, 0xFFFFFFFFu));
      const BuildNode& b = t.nodes[n];
      if (b.leaf()) return at + w.leaf_bytes[n];
      ++interior;
      return place(b.right, place(b.left, at + MC_COMPRESSED_NODE_BYTES));
    };
    uint64_t end = place(0, MC_COMPRESSED_HEADER_BYTES);
    if (end > 0x7FFFFFFFu)
      throw InputError("the AABBTreeCompressed section of " + std::to_string(end) + " bytes exceeds 2 GiB");
    w.h.tree_size = uint32_t(end);
    w.h.node_count = uint32_t(interior);
    w.h.node_bytes = uint32_t(MC_COMPRESSED_HEADER_BYTES + interior * MC_COMPRESSED_NODE_BYTES);
    w.h.triangle_base = 0;
    w.h.root = 0;
  }

  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    for (uint32_t n = 0; n < t.nodes.size(); ++n)
      if (t.nodes[n].leaf()) w.write_leaf(n, offset_[n]);
    w.refit();
    uint8_t* tree = w.bytes.data() + w.h.tree_offset;
    layout::CompressedBox root;
    for (int a = 0; a < 3; ++a) root.min[a] = t.nodes[0].box.min[a], root.max[a] = t.nodes[0].box.max[a];
    uint32_t root_count = t.nodes[0].leaf() ? t.nodes[0].count : 0;
    std::memcpy(tree, &root, sizeof root);
    std::memcpy(tree + 24, &root_count, 4);
    if (!t.nodes[0].leaf()) encode(w, 0, root);
  }

 private:
  std::vector<uint32_t> offset_;

  // Node n, whose decoded box is `parent`; then its children with theirs.
  void encode(Writer& w, uint32_t n, const layout::CompressedBox& parent) {
    const BuildNode& b = w.tree.nodes[n];
    const Box3& l = w.tree.nodes[b.left].box;
    const Box3& r = w.tree.nodes[b.right].box;
    layout::CompressedNode node{};
    for (int a = 0; a < 3; ++a) {
      // The child whose value equals the parent's inherits it; the other's is coded.
      bool min_right = l.min[a] <= r.min[a];
      bool max_right = l.max[a] >= r.max[a];
      uint32_t lo = layout::compressed_code(parent.min[a], parent.max[a], min_right ? r.min[a] : l.min[a], false);
      uint32_t hi = layout::compressed_code(parent.min[a], parent.max[a], max_right ? r.max[a] : l.max[a], true);
      node.bounds_min |= lo << (7 * a) | uint32_t(min_right) << (MC_COMPRESSED_SIDE_SHIFT + a);
      node.bounds_max |= hi << (7 * a) | uint32_t(max_right) << (MC_COMPRESSED_SIDE_SHIFT + a);
    }
    const BuildNode& lb = w.tree.nodes[b.left];
    const BuildNode& rb = w.tree.nodes[b.right];
    node.bounds_min |= (lb.leaf() ? lb.count : 0) << MC_COMPRESSED_COUNT_SHIFT;
    node.bounds_max |= (rb.leaf() ? rb.count : 0) << MC_COMPRESSED_COUNT_SHIFT;
    node.right = offset_[b.right];
    std::memcpy(w.bytes.data() + w.h.tree_offset + offset_[n], &node, sizeof node);
    layout::CompressedBox left, right;
    node.unpack(parent, left, right);
    if (!lb.leaf()) encode(w, b.left, left);
    if (!rb.leaf()) encode(w, b.right, right);
  }
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::AABBTreeCompressed, const BuildOptions&) {
  return std::make_unique<CompressedWriter>();
}

}  // namespace meshcast
