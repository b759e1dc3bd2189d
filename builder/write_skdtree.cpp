// SKDTree writer (seed 000 §5.5): depth first, the left child right behind
// its node's planes, a leaf's block right behind its Properties. Each
// interior node takes the axis whose two child regions (the parent's region
// cut at LeftPlane and at RightPlane) have the smallest summed surface, the
// child lower along it on the left.
#include <functional>

#include "builder/writer.h"
#include "layout/tree/skdtree.h"

namespace meshcast {

namespace {

class SkdWriter : public TreeWriter {
 public:
  void plan(Writer& w) override {
    BuildTree& t = w.tree;
    offset_.assign(t.nodes.size(), 0);
    axis_.assign(t.nodes.size(), 0);
    choose(t, 0, t.nodes[0].box);
    std::function<uint64_t(uint32_t, uint64_t)> place = [&](uint32_t n, uint64_t at) -> uint64_t {
      offset_[n] = uint32_t(std::min<uint64_t>(at, 0xFFFFFFFFu));
      const BuildNode& b = t.nodes[n];
      if (b.leaf()) return at + MC_SKD_LEAF_BYTES + w.leaf_bytes[n];
      return place(b.right, place(b.left, at + MC_SKD_INTERIOR_BYTES));
    };
    uint64_t end = place(0, 0);
    if (end > MC_SKD_VALUE_MASK)
      throw InputError("the SKDTree section of " + std::to_string(end) + " bytes exceeds its 30-bit offsets (seed 000 5.5)");
    uint32_t interior = 0;
    for (const BuildNode& b : t.nodes) interior += !b.leaf();
    w.h.tree_size = uint32_t(end);
    w.h.node_count = uint32_t(t.nodes.size());
    w.h.node_bytes = interior * MC_SKD_INTERIOR_BYTES + (uint32_t(t.nodes.size()) - interior) * MC_SKD_LEAF_BYTES;
    w.h.triangle_base = 0;
    w.h.root = 0;
  }

  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    for (uint32_t n = 0; n < t.nodes.size(); ++n)
      if (t.nodes[n].leaf()) w.write_leaf(n, offset_[n] + MC_SKD_LEAF_BYTES);
    w.refit();
    for (uint32_t n = 0; n < t.nodes.size(); ++n) {
      const BuildNode& b = t.nodes[n];
      uint8_t* out = w.bytes.data() + w.h.tree_offset + offset_[n];
      uint32_t properties = b.leaf() ? MC_SKD_LEAF_AXIS << MC_SKD_AXIS_SHIFT | b.count
                                     : uint32_t(axis_[n]) << MC_SKD_AXIS_SHIFT | offset_[b.right];
      std::memcpy(out, &properties, 4);
      if (b.leaf()) continue;
      // The refitted boxes: what the codec stores, so the planes bound it.
      float planes[2] = {t.nodes[b.left].box.max[axis_[n]], t.nodes[b.right].box.min[axis_[n]]};
      std::memcpy(out + 4, planes, 8);
    }
  }

 private:
  std::vector<uint32_t> offset_;
  std::vector<uint8_t> axis_;

  // Axis and child order of node n, whose region is `region`, then below.
  void choose(BuildTree& t, uint32_t n, const Box3& region) {
    BuildNode& b = t.nodes[n];
    if (b.leaf()) return;
    double best = INFINITY;
    Box3 best_left, best_right;
    for (int a = 0; a < 3; ++a) {
      uint32_t lo = b.left, hi = b.right;
      if (t.nodes[lo].box.centre()[a] > t.nodes[hi].box.centre()[a]) std::swap(lo, hi);
      Box3 l = region, r = region;
      l.max[a] = std::min(region.max[a], t.nodes[lo].box.max[a]);
      r.min[a] = std::max(region.min[a], t.nodes[hi].box.min[a]);
      double cost = l.half_area() + r.half_area();
      if (cost < best) best = cost, axis_[n] = uint8_t(a), best_left = l, best_right = r, b.left = lo, b.right = hi;
    }
    choose(t, b.left, best_left);
    choose(t, b.right, best_right);
  }
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::SKDTree, const BuildOptions&) { return std::make_unique<SkdWriter>(); }

}  // namespace meshcast
