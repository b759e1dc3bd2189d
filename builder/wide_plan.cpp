#include "builder/wide_plan.h"

#include <functional>

namespace meshcast {

WidePlan plan_wide(const BuildTree& t, uint32_t width) {
  WidePlan p;
  p.width = width;
  p.leaf_offset.assign(t.nodes.size(), 0);
  p.wide_index.assign(t.nodes.size(), 0);
  std::function<void(uint32_t, uint32_t)> visit = [&](uint32_t n, uint32_t depth) {
    if (t.nodes[n].leaf()) return;
    p.depth = std::max(p.depth, depth);
    std::vector<uint32_t> list{t.nodes[n].left, t.nodes[n].right};
    while (list.size() < width) {
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
    p.wide_index[n] = uint32_t(p.binary_of.size());
    p.binary_of.push_back(n);
    p.children.push_back(list);
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
