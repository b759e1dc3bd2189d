// QuadTree (seed 000 §5.6) and QuadTreeHalfFloat (§5.7), in the node orders
// of §4.3.
#include <algorithm>
#include <cmath>

#include "builder/wide_plan.h"
#include "layout/tree/quadtree.h"

namespace meshcast {

namespace {

// The frame the node boxes are stored in, after the refit: QuadTree's are
// plain floats; QuadTreeHalfFloat's half floats are relative to the root
// centre, scaled by a power of two that puts the root's half extent near
// 2^14, far from both the half range limit (65504) and the subnormals.
void frame_nodes(Writer&, layout::QuadBoundsFloat) {}
void frame_nodes(Writer& w, layout::QuadBoundsHalf) {
  const Box3& root = w.tree.nodes[0].box;
  layout::BlobHeader& h = w.h;
  float half_extent = 0;
  for (int a = 0; a < 3; ++a) {
    h.node_origin[a] = root.centre()[a];
    half_extent = std::max({half_extent, std::fabs(root.max[a] - h.node_origin[a]),
                            std::fabs(h.node_origin[a] - root.min[a])});
  }
  h.node_scale = std::max(std::ldexp(1.0f, half_extent > 0 ? std::ilogb(half_extent) - 13 : 0), 0x1p-126f);
}

// QuadTree (§5.6): every binary node that stays a node takes up to four
// children (plan_wide); nodes and triangle blocks are laid out in one of
// the four node orders of §4.3. DepthFirstTrianglesLast, the default, keeps
// 64-byte half-float nodes cache aligned.
template <class Bounds>
void fill_quadtree(Writer& w, WidePlan& p) {
  const BuildTree& t = w.tree;
  for (uint32_t leaf : p.leaves) w.write_leaf(leaf, p.leaf_offset[leaf]);
  w.refit();
  frame_nodes(w, Bounds{});
  auto props = [&](uint32_t n) { return layout::quad_properties(t.nodes[n].leaf() ? t.nodes[n].count : 0, wide_child_offset(t, p, n)); };
  for (size_t q = 0; q < p.binary_of.size(); ++q) {
    layout::QuadChild c[4];
    for (size_t k = 0; k < p.children[q].size(); ++k) {
      uint32_t n = p.children[q][k];
      for (int a = 0; a < 3; ++a) c[k].min[a] = t.nodes[n].box.min[a], c[k].max[a] = t.nodes[n].box.max[a];
      c[k].properties = props(n);
    }
    uint8_t* out = w.bytes.data() + w.h.tree_offset + p.node_offset[q];
    Bounds::encode(c, w.h, out);
    for (int k = 0; k < 4; ++k) std::memcpy(out + Bounds::kPropertiesAt + 4 * k, &c[k].properties, 4);
  }
  w.h.root = props(0);
}

template <class Bounds>
class QuadWriter : public TreeWriter {
 public:
  explicit QuadWriter(NodeOrder order) : order_(order == NodeOrder::Default ? NodeOrder::DepthFirstTrianglesLast : order) {}
  void plan(Writer& w) override {
    plan_ = plan_wide(w.tree, 4);
    place_wide(w, plan_, order_, Bounds::kNodeBytes, MC_QUAD_OFFSET_MASK, std::string(layout::tree_format_name(Bounds::kFormat)),
               "27-bit child offsets (seed 000 5.6)");
  }
  void fill(Writer& w) override { fill_quadtree<Bounds>(w, plan_); }
  uint32_t depth(const BuildTree&) const override { return plan_.depth; }

 private:
  NodeOrder order_;
  WidePlan plan_;
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::QuadTree, const BuildOptions& o) {
  return std::make_unique<QuadWriter<layout::QuadBoundsFloat>>(o.node_order);
}

std::unique_ptr<TreeWriter> make_writer(layout::tree::QuadTreeHalfFloat, const BuildOptions& o) {
  return std::make_unique<QuadWriter<layout::QuadBoundsHalf>>(o.node_order);
}

}  // namespace meshcast
