// OctTreeCompressed: the binary SAH tree with the caller's leaves;
// the wide plan gives every node up to 8 children (the collapse by table
// of builder/wide_plan.h), which sit in the slots that order them for the
// rays of each octant. An SAH collapse that chose the leaves again, counting
// a leaf in whole triangle blocks (from a tree of 2-triangle leaves), was
// measured and left out: no faster, and 20-22 bytes a triangle against 16
// (bench/RESULTS.md).
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>

#include "builder/wide_plan.h"
#include "layout/tree/octtree.h"

namespace meshcast {

namespace {

// CWBVH's slot order: bit a of a slot stands for the positive side of axis
// a, so a ray whose octant has bit a set when its direction is negative
// along a meets the children front to back in the slots j ^ octant, j = 0..7.
// Children are placed greedily, cheapest (child, slot) pair first, the cost
// the child centre's offset from the node's centre against the slot's sides.
std::array<int, MC_OCT_WIDTH> octant_slots(const BuildTree& t, const std::vector<uint32_t>& children, const Box3& box) {
  std::array<int, MC_OCT_WIDTH> slot_child;
  slot_child.fill(-1);
  const Vec3 centre = box.centre();
  std::vector<char> placed(children.size(), 0);
  for (size_t round = 0; round < children.size(); ++round) {
    double cheapest = std::numeric_limits<double>::infinity();
    int pick_child = -1, pick_slot = -1;
    for (size_t i = 0; i < children.size(); ++i) {
      if (placed[i]) continue;
      const Vec3 c = t.nodes[children[i]].box.centre();
      for (int s = 0; s < int(MC_OCT_WIDTH); ++s) {
        if (slot_child[size_t(s)] >= 0) continue;
        double cost = 0;
        for (int a = 0; a < 3; ++a) cost += (s >> a & 1 ? -1.0 : 1.0) * (double(c[a]) - centre[a]);
        if (pick_child < 0 || cost < cheapest) cheapest = cost, pick_child = int(i), pick_slot = s;
      }
    }
    if (pick_child < 0) break;  // (never: at most 8 children for 8 slots)
    placed[size_t(pick_child)] = 1;
    slot_child[size_t(pick_slot)] = int(children[size_t(pick_child)]);
  }
  return slot_child;
}

void write_oct_node(const BuildTree& t, const WidePlan& p, uint32_t q, uint8_t* out) {
  const Box3& box = t.nodes[p.binary_of[q]].box;  // refitted: the union of its children
  layout::OctFrame frame[3];
  for (int a = 0; a < 3; ++a) {
    frame[a] = layout::oct_frame(box.min[a], box.max[a]);
    std::memcpy(out + MC_OCT_ORIGIN_AT + 4 * a, &frame[a].origin, 4);
    out[MC_OCT_EXPONENTS_AT + a] = frame[a].exponent;
  }
  const std::array<int, MC_OCT_WIDTH> slots = octant_slots(t, p.children[q], box);
  for (int k = 0; k < int(MC_OCT_WIDTH); ++k) {
    uint32_t properties = 0;
    for (int a = 0; a < 3; ++a) out[MC_OCT_QLO_AT + 8 * a + k] = 255, out[MC_OCT_QHI_AT + 8 * a + k] = 0;
    if (slots[size_t(k)] >= 0) {
      const uint32_t n = uint32_t(slots[size_t(k)]);
      for (int a = 0; a < 3; ++a) {
        out[MC_OCT_QLO_AT + 8 * a + k] = layout::oct_code(t.nodes[n].box.min[a], frame[a], false);
        out[MC_OCT_QHI_AT + 8 * a + k] = layout::oct_code(t.nodes[n].box.max[a], frame[a], true);
      }
      properties = layout::oct_properties(t.nodes[n].leaf() ? t.nodes[n].count : 0, wide_child_offset(t, p, n));
    }
    std::memcpy(out + MC_OCT_PROPERTIES_AT + 4 * k, &properties, 4);
  }
}

class OctWriter : public TreeWriter {
 public:
  explicit OctWriter(NodeOrder order) : order_(order == NodeOrder::Default ? NodeOrder::DepthFirstTrianglesLast : order) {}
  void plan(Writer& w) override {
    plan_ = plan_wide(w.tree, MC_OCT_WIDTH);
    place_wide(w, plan_, order_, MC_OCT_NODE_BYTES, uint64_t(MC_OCT_OFFSET_MASK) * MC_OCT_OFFSET_UNIT,
               "OctTreeCompressed", "27-bit child offsets in 4-byte units (512 MiB)");
  }
  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    w.write_leaves(plan_.leaves, plan_.leaf_offset);
    w.refit();
    // The nodes, each its own bytes (on the build's threads); then the
    // header's reach of their frames (layout/tree/octtree.h), the largest over
    // the nodes (0 where the root is a leaf).
    for_each_on(w.threads, plan_.binary_of.size(), Writer::kGrain, [&](uint64_t q) {
      write_oct_node(t, plan_, uint32_t(q), w.bytes.data() + w.h.tree_offset + plan_.node_offset[q]);
    });
    for (uint32_t q = 0; q < plan_.binary_of.size(); ++q) {
      const uint8_t* node = w.bytes.data() + w.h.tree_offset + plan_.node_offset[q];
      for (int a = 0; a < 3; ++a) {
        w.h.node_origin[a] = std::max(w.h.node_origin[a], std::fabs(layout::load<float>(node + MC_OCT_ORIGIN_AT + 4 * a)));
        w.h.node_scale = std::max(w.h.node_scale, layout::oct_scale(node[MC_OCT_EXPONENTS_AT + a]));
      }
    }
    w.h.root = layout::oct_properties(t.nodes[0].leaf() ? t.nodes[0].count : 0, wide_child_offset(t, plan_, 0));
  }
  uint32_t depth(const BuildTree&) const override { return plan_.depth; }

 private:
  NodeOrder order_;
  WidePlan plan_;
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::OctTreeCompressed, const BuildOptions& o) {
  return std::make_unique<OctWriter>(o.node_order);
}

}  // namespace meshcast
