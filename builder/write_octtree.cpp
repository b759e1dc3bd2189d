// OctTreeCompressed (issue 19): the binary SAH tree, built with leaves of at
// most two triangles, has its leaves chosen again by an SAH collapse that
// counts a leaf's cost in whole triangle blocks; the wide plan then gives
// every node up to 8 children, which sit in the slots that order them for
// the rays of each octant.
#include <array>
#include <limits>

#include "builder/wide_plan.h"
#include "layout/octtree.h"

namespace meshcast {

namespace {

// The collapse's costs, in units of one triangle block test: an 8-box node
// test costs about one block test, and an 8-wide node stands in for about
// seven binary ones, so a binary node is charged a seventh of it.
constexpr double kBlockCost = 1.0;
constexpr double kBinaryNodeCost = 1.0 / 7.0;

// Bottom-up SAH choice for every binary node: a leaf of all its triangles
// (when they are at most `cap`, contiguous in the order, and blocks of
// `lanes` cost less) or a node over its two children's best; then the tree
// rebuilt, parents before children, with the chosen leaves.
BuildTree collapse_leaves(const BuildTree& t, uint32_t lanes, uint32_t cap) {
  const size_t n = t.nodes.size();
  std::vector<uint32_t> first(n), count(n);
  std::vector<double> best(n);
  std::vector<char> leaf(n, 0);
  auto blocks = [&](uint32_t c) { return double((c + lanes - 1) / lanes); };
  for (size_t i = n; i-- > 0;) {  // children follow their parent in the builder's order
    const BuildNode& b = t.nodes[i];
    const double area = b.box.half_area();
    if (b.leaf()) {
      first[i] = b.first, count[i] = b.count, best[i] = area * blocks(b.count) * kBlockCost, leaf[i] = 1;
      continue;
    }
    const uint32_t l = b.left, r = b.right;
    count[i] = count[l] + count[r];
    first[i] = std::min(first[l], first[r]);
    const bool contiguous = first[r] == first[l] + count[l] || first[l] == first[r] + count[r];
    const double split = area * kBinaryNodeCost + best[l] + best[r];
    const double as_leaf = count[i] <= cap && contiguous ? area * blocks(count[i]) * kBlockCost
                                                          : std::numeric_limits<double>::infinity();
    leaf[i] = as_leaf <= split;
    best[i] = std::min(as_leaf, split);
  }
  BuildTree out;
  out.order = t.order;
  out.sah_cost = t.sah_cost;
  struct Item { uint32_t binary, parent, depth; bool right; };
  std::vector<Item> stack{{0, 0, 0, false}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const uint32_t at = uint32_t(out.nodes.size());
    BuildNode node;
    node.box = t.nodes[it.binary].box;
    if (leaf[it.binary]) node.first = first[it.binary], node.count = count[it.binary];
    out.nodes.push_back(node);
    out.depth = std::max(out.depth, it.depth);
    if (at != 0) (it.right ? out.nodes[it.parent].right : out.nodes[it.parent].left) = at;
    if (!leaf[it.binary]) {
      stack.push_back({t.nodes[it.binary].right, at, it.depth + 1, true});
      stack.push_back({t.nodes[it.binary].left, at, it.depth + 1, false});
    }
  }
  return out;
}

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
  uint32_t binary_leaf_size(uint32_t asked) const override { return std::min(asked, 2u); }
  void reshape(BuildTree& t, const CodecOps& codec, uint32_t asked) override {
    t = collapse_leaves(t, codec.lanes, std::min(asked, MC_OCT_MAX_COUNT));
  }
  void plan(Writer& w) override {
    plan_ = plan_wide(w.tree, MC_OCT_WIDTH);
    place_wide(w, plan_, order_, MC_OCT_NODE_BYTES, uint64_t(MC_OCT_OFFSET_MASK) * MC_OCT_OFFSET_UNIT,
               "OctTreeCompressed", "27-bit child offsets in 4-byte units (512 MiB)");
  }
  void fill(Writer& w) override {
    const BuildTree& t = w.tree;
    for (uint32_t leaf : plan_.leaves) w.write_leaf(leaf, plan_.leaf_offset[leaf]);
    w.refit();
    for (uint32_t q = 0; q < plan_.binary_of.size(); ++q)
      write_oct_node(t, plan_, q, w.bytes.data() + w.h.tree_offset + plan_.node_offset[q]);
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
