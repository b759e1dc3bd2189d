#include "builder/wide_plan.h"

#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace meshcast {

namespace {

// The collapse's table (Ylitie, Karras and Laine 2017, with the leaves the
// binary tree made): for a binary node n and i = 1..width, the least cost of
// standing for n's subtree by at most i roots of a forest, each a leaf or a
// wide node, where a wide node costs its surface area (how often a ray
// tests its children). Leaves cost the same whatever the collapse, so they
// count 0. A small constant a node, far below any area difference that
// matters, makes the table prefer fewer nodes where areas tie (flat boxes).
struct Collapse {
  static constexpr uint32_t kMaxWidth = 8;
  uint32_t width;
  std::vector<double> cost;   // [n * width + i - 1]
  std::vector<uint8_t> left;  // roots taken from the left child when n is opened into i roots (0: n stays one root)
  double node_cost(const BuildTree& t, uint32_t n, double tie) const { return t.nodes[n].box.half_area() + tie; }

  Collapse(const BuildTree& t, uint32_t w) : width(w), cost(t.nodes.size() * w, 0.0), left(t.nodes.size() * w, 0) {
    fill(t, 0, 1e-9 * t.nodes[0].box.half_area());
  }
  // n's rows, its children's first (a post-order walk; recursion as deep as
  // the binary tree, which the builders bound).
  void fill(const BuildTree& t, uint32_t n, double tie) {
    const BuildNode& b = t.nodes[n];
    if (b.leaf()) return;  // cost 0 at every i
    fill(t, b.left, tie), fill(t, b.right, tie);
    // Opened into at most i roots: the best split of i between the children.
    std::array<double, kMaxWidth + 1> opened;
    std::array<uint8_t, kMaxWidth + 1> split{};
    opened.fill(INFINITY);
    for (uint32_t i = 2; i <= width; ++i)
      for (uint32_t k = 1; k < i; ++k) {
        const double c = at(b.left, k) + at(b.right, i - k);
        if (c < opened[i]) opened[i] = c, split[i] = uint8_t(k);
      }
    const size_t row = size_t(n) * width;
    const double as_node = node_cost(t, n, tie) + opened[width];
    cost[row] = as_node;
    for (uint32_t i = 2; i <= width; ++i) {
      const bool open = opened[i] <= as_node;
      cost[row + i - 1] = open ? opened[i] : as_node;
      left[row + i - 1] = open ? split[i] : 0;
    }
  }
  double at(uint32_t n, uint32_t i) const { return cost[size_t(n) * width + i - 1]; }

  // The roots standing for n's subtree in at most i of them.
  void roots(const BuildTree& t, uint32_t n, uint32_t i, std::vector<uint32_t>& out) const {
    const uint32_t k = t.nodes[n].leaf() ? 0 : left[size_t(n) * width + i - 1];
    if (k == 0) {
      out.push_back(n);
      return;
    }
    roots(t, t.nodes[n].left, k, out);
    roots(t, t.nodes[n].right, i - k, out);
  }
  // A wide node's children: n opened into at most `width` roots.
  std::vector<uint32_t> children(const BuildTree& t, uint32_t n) const {
    uint32_t best = 1;
    double c = INFINITY;
    for (uint32_t k = 1; k < width; ++k) {
      const double v = at(t.nodes[n].left, k) + at(t.nodes[n].right, width - k);
      if (v < c) c = v, best = k;
    }
    std::vector<uint32_t> out;
    roots(t, t.nodes[n].left, best, out);
    roots(t, t.nodes[n].right, width - best, out);
    return out;
  }
};

}  // namespace

WidePlan plan_wide(const BuildTree& t, uint32_t width) {
  WidePlan p;
  p.width = width;
  p.leaf_offset.assign(t.nodes.size(), 0);
  p.wide_index.assign(t.nodes.size(), 0);
  if (t.nodes[0].leaf()) return p;
  if (width < 2 || width > Collapse::kMaxWidth) throw std::invalid_argument("plan_wide: a width from 2 to 8");
  const Collapse collapse(t, width);
  std::function<void(uint32_t, uint32_t)> visit = [&](uint32_t n, uint32_t depth) {
    if (t.nodes[n].leaf()) return;
    p.depth = std::max(p.depth, depth);
    p.wide_index[n] = uint32_t(p.binary_of.size());
    p.binary_of.push_back(n);
    p.children.push_back(collapse.children(t, n));
    const std::vector<uint32_t> list = p.children.back();
    for (uint32_t m : list) visit(m, depth + 1);
  };
  visit(0, 0);
  return p;
}

namespace {

// The write order of §4.3: wide nodes (true, wide index) and leaf blocks
// (false, binary node) depth or breadth first, each node's leaf blocks
// right behind it or all blocks after all nodes.
std::vector<std::pair<bool, uint32_t>> wide_sequence(const BuildTree& t, const WidePlan& p, NodeOrder order) {
  std::vector<std::pair<bool, uint32_t>> seq, blocks;
  if (p.binary_of.empty()) return {{false, 0}};  // the root is a leaf
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  auto emit = [&](uint32_t q, std::vector<uint32_t>& next) {
    seq.push_back({true, q});
    for (uint32_t c : p.children[q]) {
      if (t.nodes[c].leaf()) (last ? blocks : seq).push_back({false, c});
      else next.push_back(p.wide_index[c]);
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

}  // namespace

void place_wide(Writer& w, WidePlan& p, NodeOrder order, uint32_t node_bytes, uint64_t reach, const std::string& format,
                const std::string& offsets) {
  uint64_t at = 0, nodes = uint64_t(p.binary_of.size()) * node_bytes;
  p.node_offset.assign(p.binary_of.size(), 0);
  for (auto [is_node, id] : wide_sequence(w.tree, p, order)) {
    if (is_node) {
      p.node_offset[id] = uint32_t(std::min<uint64_t>(at, reach));
      at += node_bytes;
    } else {
      p.leaves.push_back(id);
      p.leaf_offset[id] = uint32_t(std::min<uint64_t>(at, reach));
      at += w.leaf_bytes[id];
    }
  }
  if (at > reach)
    throw InputError("the " + format + " section of " + std::to_string(at) + " bytes exceeds its " + offsets);
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  w.h.tree_size = uint32_t(at);
  w.h.node_bytes = uint32_t(nodes);
  w.h.node_count = uint32_t(p.binary_of.size());
  w.h.triangle_base = last ? uint32_t(nodes) : 0;  // interleaved blocks: slots count from the section start
}

}  // namespace meshcast
