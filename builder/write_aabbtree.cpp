// The 28-byte-node trees: AABBTree (seed 000 §5.1), AABBTreeSplitAxis
// (§5.2) and AABBTreePNS (§5.3, seed 002).
#include <functional>

#include "builder/writer.h"
#include "layout/tree/aabbtree.h"

namespace meshcast {

namespace {

// AABBTreeSplitAxis (§5.2): each interior node's axis is the one along which
// its children's centres lie farthest apart, and its children are ordered
// lower first along it. (The builders do not record the axis they split on;
// this one is the axis that separates the two children most.)
std::vector<uint8_t> order_by_split_axis(BuildTree& t) {
  std::vector<uint8_t> axis(t.nodes.size(), 0);
  for (size_t n = 0; n < t.nodes.size(); ++n) {
    BuildNode& b = t.nodes[n];
    if (b.leaf()) continue;
    Vec3 l = t.nodes[b.left].box.centre(), r = t.nodes[b.right].box.centre();
    float d[3] = {std::fabs(l.x - r.x), std::fabs(l.y - r.y), std::fabs(l.z - r.z)};
    int a = d[0] >= d[1] && d[0] >= d[2] ? 0 : (d[1] >= d[2] ? 1 : 2);
    axis[n] = uint8_t(a);
    if (l[a] > r[a]) std::swap(b.left, b.right);
  }
  return axis;
}

class AabbWriter : public TreeWriter {
 public:
  explicit AabbWriter(bool split_axis) : split_axis_(split_axis) {}

  // AABBTree, depth first: first child right behind its parent, the leaf's
  // triangle block right behind the leaf node.
  void plan(Writer& w) override {
    BuildTree& t = w.tree;
    if (split_axis_) axis_ = order_by_split_axis(t);
    offset_.assign(t.nodes.size(), 0);
    std::function<uint64_t(uint32_t, uint64_t)> place = [&](uint32_t n, uint64_t at) -> uint64_t {
      offset_[n] = uint32_t(std::min<uint64_t>(at, 0xFFFFFFFFu));
      const BuildNode& b = t.nodes[n];
      if (b.leaf()) return at + MC_AABB_NODE_BYTES + w.leaf_bytes[n];
      return place(b.right, place(b.left, at + MC_AABB_NODE_BYTES));
    };
    uint64_t tree_size = place(0, 0);
    const uint64_t limit = split_axis_ ? MC_SPLITAXIS_OFFSET_MASK : MC_AABB_VALUE_MASK;
    if (tree_size > limit)
      throw InputError("the " + std::string(split_axis_ ? "AABBTreeSplitAxis" : "AABBTree") + " section of " +
                       std::to_string(tree_size) + " bytes exceeds its " + (split_axis_ ? "29" : "31") +
                       "-bit child offsets (seed 000 5.1-5.2)");
    w.h.tree_size = uint32_t(tree_size);
    w.h.node_bytes = uint32_t(t.nodes.size() * MC_AABB_NODE_BYTES);
    w.h.node_count = uint32_t(t.nodes.size());
    w.h.triangle_base = 0;
    w.h.root = 0;
  }

  // Encodes the leaves, refits, then writes the nodes with the refitted boxes.
  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    for (uint32_t n = 0; n < t.nodes.size(); ++n)
      if (t.nodes[n].leaf()) w.write_leaf(n, offset_[n] + MC_AABB_NODE_BYTES);
    w.refit();
    for (uint32_t n = 0; n < t.nodes.size(); ++n) {
      const BuildNode& b = t.nodes[n];
      layout::AABBNode node{};
      for (int a = 0; a < 3; ++a) node.min[a] = b.box.min[a], node.max[a] = b.box.max[a];
      node.properties = b.leaf() ? (MC_AABB_LEAF_BIT | b.count) : offset_[b.right];
      if (split_axis_ && !b.leaf()) node.properties |= uint32_t(axis_[n]) << MC_SPLITAXIS_SHIFT;
      std::memcpy(w.bytes.data() + w.h.tree_offset + offset_[n], &node, sizeof node);
    }
  }

 private:
  bool split_axis_;
  std::vector<uint8_t> axis_;
  std::vector<uint32_t> offset_;
};

// AABBTreePNS (§5.3, seed 002): nodes depth first by index, then the blocks.
struct PnsPlan {
  std::vector<uint32_t> index;  // per binary node: its node index
  std::vector<uint32_t> block;  // per binary leaf: tree-section offset of its block
  std::vector<uint32_t> leaves; // leaves in block order
};

PnsPlan plan_pns(Writer& w) {
  const BuildTree& t = w.tree;
  PnsPlan p{std::vector<uint32_t>(t.nodes.size()), std::vector<uint32_t>(t.nodes.size()), {}};
  uint32_t next = 0;
  std::function<void(uint32_t)> visit = [&](uint32_t n) {
    p.index[n] = next++;
    if (t.nodes[n].leaf()) return p.leaves.push_back(n);
    visit(t.nodes[n].left);
    visit(t.nodes[n].right);
  };
  visit(0);
  uint64_t base = uint64_t(next) * MC_AABB_NODE_BYTES, at = base;
  for (uint32_t leaf : p.leaves) {
    p.block[leaf] = uint32_t(at);
    if ((at - base) / 4 > MC_PNS_BLOCK_MASK) throw InputError("AABBTreePNS: triangle blocks beyond its 26-bit offsets (256 MiB)");
    at += w.leaf_bytes[leaf];
  }
  if (next > MC_PNS_INDEX_MASK) throw InputError("AABBTreePNS: more than 2^23 nodes");
  if (at > 0x7FFFFFFFu) throw InputError("AABBTreePNS: the tree section exceeds 2 GiB");
  w.h.node_count = next;
  w.h.node_bytes = uint32_t(base);
  w.h.triangle_base = uint32_t(base);
  w.h.tree_size = uint32_t(at);
  w.h.root = 0;
  return p;
}

void fill_pns(Writer& w, const PnsPlan& p) {
  const BuildTree& t = w.tree;
  for (uint32_t leaf : p.leaves) w.write_leaf(leaf, p.block[leaf]);
  w.refit();
  for (uint32_t n = 0; n < t.nodes.size(); ++n) {
    const BuildNode& b = t.nodes[n];
    layout::AABBNode node{};
    for (int a = 0; a < 3; ++a) node.min[a] = b.box.min[a], node.max[a] = b.box.max[a];
    node.properties = b.leaf() ? MC_AABB_LEAF_BIT | b.count << MC_PNS_COUNT_SHIFT | (p.block[n] - w.h.triangle_base) / 4
                               : pns_code(t.nodes[b.left].box, t.nodes[b.right].box) << MC_PNS_SHIFT | p.index[b.right];
    std::memcpy(w.bytes.data() + w.h.tree_offset + uint64_t(p.index[n]) * MC_AABB_NODE_BYTES, &node, sizeof node);
  }
}

class PnsWriter : public TreeWriter {
 public:
  void plan(Writer& w) override { plan_ = plan_pns(w); }
  void fill(Writer& w) override { fill_pns(w, plan_); }

 private:
  PnsPlan plan_;
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::AABBTree, const BuildOptions&) { return std::make_unique<AabbWriter>(false); }
std::unique_ptr<TreeWriter> make_writer(layout::tree::AABBTreeSplitAxis, const BuildOptions&) {
  return std::make_unique<AabbWriter>(true);
}
std::unique_ptr<TreeWriter> make_writer(layout::tree::AABBTreePNS, const BuildOptions&) { return std::make_unique<PnsWriter>(); }

}  // namespace meshcast
