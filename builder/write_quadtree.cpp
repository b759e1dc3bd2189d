// QuadTree (seed 000 §5.6) and QuadTreeHalfFloat (§5.7), in the node orders
// of §4.3.
#include <array>
#include <functional>

#include "builder/writer.h"
#include "layout/quadtree.h"

namespace meshcast {

namespace {

// QuadTree (§5.6): every binary node that stays a node takes up to four
// children, found by opening its largest interior descendant until four are
// reached. Nodes and triangle blocks are then laid out in one of the four
// node orders of §4.3 (quad_sequence); DepthFirstTrianglesLast, the
// default, keeps 64-byte half-float nodes cache aligned.
struct QuadPlan {
  std::vector<std::array<int64_t, 4>> children;  // binary node index or -1
  std::vector<uint32_t> binary_of;               // quad node -> binary node
  std::vector<uint32_t> leaves;                  // binary leaves, in write order
  std::vector<uint32_t> leaf_offset;             // per binary node (leaves)
  std::vector<uint32_t> node_offset;             // per quad node
  std::vector<uint32_t> quad_index;              // per binary node (quad nodes)
  uint32_t depth = 0;
};

QuadPlan plan_quadtree(const BuildTree& t) {
  QuadPlan p;
  p.leaf_offset.assign(t.nodes.size(), 0);
  p.quad_index.assign(t.nodes.size(), 0);
  std::function<void(uint32_t, uint32_t)> visit = [&](uint32_t n, uint32_t depth) {
    if (t.nodes[n].leaf()) return;
    p.depth = std::max(p.depth, depth);
    std::vector<uint32_t> list{t.nodes[n].left, t.nodes[n].right};
    while (list.size() < 4) {
      int open = -1;
      for (size_t i = 0; i < list.size(); ++i)
        if (!t.nodes[list[i]].leaf() &&
            (open < 0 || t.nodes[list[i]].box.half_area() > t.nodes[list[size_t(open)]].box.half_area()))
          open = int(i);
      if (open < 0) break;
      uint32_t m = list[size_t(open)];
      list.erase(list.begin() + open);
      list.insert(list.begin() + open, {t.nodes[m].left, t.nodes[m].right});
    }
    p.quad_index[n] = uint32_t(p.binary_of.size());
    p.binary_of.push_back(n);
    std::array<int64_t, 4> c{-1, -1, -1, -1};
    for (size_t i = 0; i < list.size(); ++i) c[i] = list[i];
    p.children.push_back(c);
    for (uint32_t m : list) visit(m, depth + 1);
  };
  visit(0, 0);
  return p;
}

// The write order of §4.3: quad nodes (true, quad index) and leaf blocks
// (false, binary node) depth or breadth first, each node's leaf blocks
// right behind it or all blocks after all nodes.
std::vector<std::pair<bool, uint32_t>> quad_sequence(const BuildTree& t, const QuadPlan& p, NodeOrder order) {
  std::vector<std::pair<bool, uint32_t>> seq, blocks;
  if (p.binary_of.empty()) return {{false, 0}};  // the root is a leaf
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  auto emit = [&](uint32_t q, std::vector<uint32_t>& next) {
    seq.push_back({true, q});
    for (int64_t c : p.children[q]) {
      if (c < 0) continue;
      if (t.nodes[size_t(c)].leaf()) (last ? blocks : seq).push_back({false, uint32_t(c)});
      else next.push_back(p.quad_index[size_t(c)]);
    }
  };
  if (order == NodeOrder::BreadthFirst || order == NodeOrder::BreadthFirstTrianglesLast) {
    std::vector<uint32_t> level{0};
    while (!level.empty()) {
      std::vector<uint32_t> next;
      for (uint32_t q : level) emit(q, next);
      level.swap(next);
    }
  } else {
    std::function<void(uint32_t)> visit = [&](uint32_t q) {
      std::vector<uint32_t> next;
      emit(q, next);
      for (uint32_t c : next) visit(c);
    };
    visit(0);
  }
  seq.insert(seq.end(), blocks.begin(), blocks.end());
  return seq;
}

template <class Bounds>
void write_quadtree(Writer& w, QuadPlan& p, NodeOrder order) {
  uint64_t at = 0, nodes = uint64_t(p.binary_of.size()) * Bounds::kNodeBytes;
  p.node_offset.assign(p.binary_of.size(), 0);
  for (auto [is_node, id] : quad_sequence(w.tree, p, order)) {
    if (is_node) {
      p.node_offset[id] = uint32_t(std::min<uint64_t>(at, MC_QUAD_OFFSET_MASK));
      at += Bounds::kNodeBytes;
    } else {
      p.leaves.push_back(id);
      p.leaf_offset[id] = uint32_t(std::min<uint64_t>(at, MC_QUAD_OFFSET_MASK));
      at += w.leaf_bytes[id];
    }
  }
  if (at > MC_QUAD_OFFSET_MASK)
    throw InputError("the " + std::string(layout::tree_format_name(Bounds::kFormat)) + " section of " +
                     std::to_string(at) + " bytes exceeds its 27-bit child offsets (seed 000 5.6)");
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  w.h.tree_size = uint32_t(at);
  w.h.node_bytes = uint32_t(nodes);
  w.h.node_count = uint32_t(p.binary_of.size());
  w.h.triangle_base = last ? uint32_t(nodes) : 0;  // interleaved blocks: slots count from the section start
}

template <class Bounds>
void fill_quadtree(Writer& w, QuadPlan& p) {
  const BuildTree& t = w.tree;
  for (uint32_t leaf : p.leaves) w.write_leaf(leaf, p.leaf_offset[leaf]);
  w.refit();
  auto props = [&](uint32_t n) {
    return t.nodes[n].leaf() ? layout::quad_properties(t.nodes[n].count, p.leaf_offset[n])
                             : layout::quad_properties(0, p.node_offset[p.quad_index[n]]);
  };
  for (size_t q = 0; q < p.binary_of.size(); ++q) {
    layout::QuadChild c[4];
    for (int k = 0; k < 4; ++k) {
      if (p.children[q][k] < 0) continue;
      uint32_t n = uint32_t(p.children[q][k]);
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
    plan_ = plan_quadtree(w.tree);
    write_quadtree<Bounds>(w, plan_, order_);
  }
  void fill(Writer& w) override { fill_quadtree<Bounds>(w, plan_); }
  uint32_t depth(const BuildTree&) const override { return plan_.depth; }

 private:
  NodeOrder order_;
  QuadPlan plan_;
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::QuadTree, const BuildOptions& o) {
  return std::make_unique<QuadWriter<layout::QuadBoundsFloat>>(o.node_order);
}

std::unique_ptr<TreeWriter> make_writer(layout::tree::QuadTreeHalfFloat, const BuildOptions& o) {
  return std::make_unique<QuadWriter<layout::QuadBoundsHalf>>(o.node_order);
}

}  // namespace meshcast
