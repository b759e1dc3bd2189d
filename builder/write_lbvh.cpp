// StacklessLBVH writer (seed 001): the binary tree laid out as a heap (node
// n's children at 2n and 2n + 1), every slot of the deepest level kept, so
// the slots no node uses are holes: zeroed nodes no walk reaches, the
// format's price for needing no child pointers and no stack. Triangle
// blocks follow the node array in depth-first order.
#include <algorithm>
#include <bit>
#include <functional>

#include "builder/writer.h"
#include "layout/tree/lbvh.h"

namespace meshcast {

namespace {

class LbvhWriter : public TreeWriter {
 public:
  explicit LbvhWriter(bool near_first) : near_first_(near_first) {}

  // The seed's choice, within the heap's reach (plan's capacity check then
  // says when a mesh is too large for it). The option counts levels from 1.
  uint32_t depth_limit(size_t triangles, const BuildOptions& o) const override {
    uint32_t d = o.lbvh_depth ? o.lbvh_depth : std::min(uint32_t(std::bit_width(triangles)) + 1, MC_LBVH_MAX_DEPTH + 1);
    if (d > MC_LBVH_MAX_DEPTH + 1)
      throw InputError("StacklessLBVH depth limit " + std::to_string(d) + " exceeds " + std::to_string(MC_LBVH_MAX_DEPTH + 1) +
                       " (2^26 node slots)");
    return d - 1;
  }

  void plan(Writer& w) override {
    const BuildTree& t = w.tree;
    if (t.depth > MC_LBVH_MAX_DEPTH)
      throw InputError("StacklessLBVH: the tree is " + std::to_string(t.depth) + " levels deep, beyond the heap's " +
                       std::to_string(MC_LBVH_MAX_DEPTH) + " (2^26 node slots); lower the depth limit");
    heap_.assign(t.nodes.size(), 0);
    block_.assign(t.nodes.size(), 0);
    const uint64_t slots = (uint64_t(2) << t.depth) - 1;
    const uint64_t base = slots * MC_LBVH_NODE_BYTES;
    uint64_t at = base;
    std::function<void(uint32_t, uint32_t)> place = [&](uint32_t n, uint32_t index) {
      heap_[n] = index;
      const BuildNode& b = t.nodes[n];
      if (b.leaf()) {
        block_[n] = uint32_t(std::min<uint64_t>(at, 0xFFFFFFFFu));
        at += w.leaf_bytes[n];
        return;
      }
      place(b.left, 2 * index);
      place(b.right, 2 * index + 1);
    };
    place(0, 1);
    if (at > 0x7FFFFFFFu)
      throw InputError("StacklessLBVH: " + std::to_string(slots) + " node slots and the triangle blocks exceed 2 GiB");
    w.h.node_count = uint32_t(slots);
    w.h.node_bytes = uint32_t(base);
    w.h.triangle_base = uint32_t(base);
    w.h.tree_size = uint32_t(at);
    w.h.root = 1;
  }

  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    for (uint32_t n = 0; n < t.nodes.size(); ++n)
      if (t.nodes[n].leaf()) w.write_leaf(n, block_[n]);
    w.refit();
    std::function<uint32_t(uint32_t)> below = [&](uint32_t n) -> uint32_t {
      const BuildNode& b = t.nodes[n];
      uint32_t count = b.leaf() ? b.count : below(b.left) + below(b.right);
      layout::LBVHNode node{};
      for (int a = 0; a < 3; ++a) node.min[a] = b.box.min[a], node.max[a] = b.box.max[a];
      node.count = b.leaf() ? int32_t(count) : -int32_t(count);
      node.position = b.leaf() ? block_[n] : near_first_ ? pns_code(t.nodes[b.left].box, t.nodes[b.right].box) : 0;
      std::memcpy(w.bytes.data() + w.h.tree_offset + layout::lbvh_node_offset(heap_[n]), &node, sizeof node);
      return count;
    };
    below(0);
  }

 private:
  bool near_first_;
  std::vector<uint32_t> heap_, block_;
};

}  // namespace

// near_first: the 8 sorting bits of seed 002 in each interior node, else
// zeros (left child first, as the seed walks).
std::unique_ptr<TreeWriter> make_writer(layout::tree::StacklessLBVH, const BuildOptions& o) {
  return std::make_unique<LbvhWriter>(o.lbvh_near_first);
}

}  // namespace meshcast
