#include "builder/top_level.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>

namespace meshcast {

namespace {

// What the splits move: an instance's box centre (doubled) and its index,
// 32 bytes, not the 152 of a placed instance (a commit of 10,000 instances
// spent most of its time moving those).
struct Item {
  double centre[3];
  uint32_t index;
};

struct TopBuilder {
  const std::vector<layout::PlacedInstance>& placed;
  std::vector<Item>& items;
  std::vector<layout::TopNode>& nodes;

  // The node over items[first, first + count); returns its index.
  uint32_t build(uint32_t first, uint32_t count) {
    const uint32_t index = uint32_t(nodes.size());
    nodes.push_back({{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, first, 0, 0});
    if (count <= layout::kTopLeafSize) {
      layout::TopNode& leaf = nodes[index];
      leaf.count = count;
      for (uint32_t i = first; i < first + count; ++i)
        for (int a = 0; a < 3; ++a) {
          leaf.min[a] = std::min(leaf.min[a], placed[items[i].index].box_min[a]);
          leaf.max[a] = std::max(leaf.max[a], placed[items[i].index].box_max[a]);
        }
      return index;
    }
    // The split: the widest axis of the centres (the items are contiguous;
    // the boxes are joined on the way back up, each read once).
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = first; i < first + count; ++i)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], items[i].centre[a]), hi[a] = std::max(hi[a], items[i].centre[a]);
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    const uint32_t half = count / 2;
    std::nth_element(items.begin() + first, items.begin() + first + half, items.begin() + first + count,
                     [axis](const Item& x, const Item& y) { return x.centre[axis] < y.centre[axis]; });
    build(first, half);  // the left child is index + 1
    const uint32_t right = build(first + half, count - half);
    layout::TopNode& node = nodes[index];
    node.right = right;
    for (int a = 0; a < 3; ++a) {
      node.min[a] = std::min(nodes[index + 1].min[a], nodes[right].min[a]);
      node.max[a] = std::max(nodes[index + 1].max[a], nodes[right].max[a]);
    }
    return index;
  }
};

}  // namespace

layout::TopLevel build_top_level(const std::vector<layout::PlacedInstance>& placed) {
  layout::TopLevel top;
  if (placed.empty()) return top;
  std::vector<Item> items(placed.size());
  for (uint32_t i = 0; i < items.size(); ++i) {
    for (int a = 0; a < 3; ++a) items[i].centre[a] = placed[i].box_min[a] + placed[i].box_max[a];
    items[i].index = i;
  }
  top.nodes.reserve(2 * placed.size());
  TopBuilder{placed, items, top.nodes}.build(0, uint32_t(placed.size()));
  top.placed.reserve(placed.size());
  for (const Item& item : items) top.placed.push_back(placed[item.index]);
  collapse_top_level(top);
  return top;
}

namespace {

double half_area(const layout::TopNode& n) {
  const double e[3] = {n.max[0] - n.min[0], n.max[1] - n.min[1], n.max[2] - n.min[2]};
  return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

// The float next to a finite f towards -inf (down) or +inf (up), by its
// bits (std::nextafter is a library call, and a refit makes 24 of these a
// node).
float next_down(float f) {
  if (f == 0) return -0x1p-149f;
  const uint32_t bits = std::bit_cast<uint32_t>(f);
  return std::bit_cast<float>(f > 0 ? bits - 1 : bits + 1);
}
float next_up(float f) { return -next_down(-f); }

// d - anchor in float, rounded down (lo) or up (hi): the float box holds
// the double one.
float below(double d, double anchor) {
  const double x = d - anchor;  // exact enough: one rounding, covered by the walk's pad
  const float f = float(x);
  return double(f) > x && std::isfinite(f) ? next_down(f) : f;
}
float above(double d, double anchor) {
  const double x = d - anchor;
  const float f = float(x);
  return double(f) < x && std::isfinite(f) ? next_up(f) : f;
}

struct Collapser {
  layout::TopLevel& top;

  // The wide node over binary node `root` (an inner node); returns its index.
  uint32_t collapse(uint32_t root) {
    uint32_t kids[layout::kTopWidth] = {root + 1, top.nodes[root].right};
    int count = 2;
    // Open the largest inner child until there are kTopWidth.
    while (count < layout::kTopWidth) {
      int best = -1;
      for (int k = 0; k < count; ++k)
        if (top.nodes[kids[k]].count == 0 && (best < 0 || half_area(top.nodes[kids[k]]) > half_area(top.nodes[kids[best]])))
          best = k;
      if (best < 0) break;
      const uint32_t opened = kids[best];
      kids[best] = opened + 1;
      kids[count++] = top.nodes[opened].right;
    }
    const uint32_t index = uint32_t(top.wide.size());
    top.wide.emplace_back();
    top.wide_from.insert(top.wide_from.end(), layout::kTopWidth, layout::kTopEmpty);
    for (int k = 0; k < layout::kTopWidth; ++k) {
      uint32_t slot = layout::kTopEmpty;
      if (k < count) {
        const layout::TopNode& n = top.nodes[kids[k]];
        static_assert(layout::kTopLeafSize == 1, "a leaf's slot names its one instance");
        slot = n.count > 0 ? layout::kTopInstance | n.first : collapse(kids[k]);
        top.wide_from[layout::kTopWidth * size_t(index) + size_t(k)] = kids[k];
      }
      top.wide[index].slot[k] = slot;  // (collapse() may have moved the node)
    }
    return index;
  }
};

}  // namespace

void collapse_top_level(layout::TopLevel& top) {
  top.wide.clear();
  top.wide_from.clear();
  if (top.nodes.empty()) return;
  const layout::TopNode& root = top.nodes[0];
  top.wide.reserve(top.nodes.size() / 2 + 1);
  top.wide_from.reserve(layout::kTopWidth * (top.nodes.size() / 2 + 1));
  if (root.count > 0) {  // one instance: a wide root with it in slot 0
    top.wide.emplace_back();
    top.wide_from.assign(layout::kTopWidth, layout::kTopEmpty);
    top.wide_from[0] = 0;
    for (int k = 0; k < layout::kTopWidth; ++k) top.wide[0].slot[k] = k == 0 ? layout::kTopInstance | root.first : layout::kTopEmpty;
  } else {
    Collapser{top}.collapse(0);
  }
  fit_wide_boxes(top);
}

void fit_wide_boxes(layout::TopLevel& top) {
  if (top.nodes.empty()) return;
  // The anchor follows the root box on every fit: a ray's origin is rounded
  // to float relative to it, and the walk's pad is sized by the distance to
  // the root box, so the two must stay together as instances wander.
  for (int a = 0; a < 3; ++a) {
    top.min[a] = top.nodes[0].min[a], top.max[a] = top.nodes[0].max[a];
    top.anchor[a] = 0.5 * (top.min[a] + top.max[a]);
  }
  for (size_t w = 0; w < top.wide.size(); ++w)
    for (int k = 0; k < layout::kTopWidth; ++k) {
      layout::TopWideNode& node = top.wide[w];
      const uint32_t from = top.wide_from[layout::kTopWidth * w + size_t(k)];
      for (int a = 0; a < 3; ++a) {
        if (from == layout::kTopEmpty) {
          node.lo[a][k] = INFINITY, node.hi[a][k] = -INFINITY;  // never entered
        } else {
          node.lo[a][k] = below(top.nodes[from].min[a], top.anchor[a]);
          node.hi[a][k] = above(top.nodes[from].max[a], top.anchor[a]);
        }
      }
    }
}

void refit_top_level(layout::TopLevel& top) {
  if (top.nodes.empty()) return;  // nothing placed: nothing to fit
  for (size_t n = top.nodes.size(); n-- > 0;) {
    layout::TopNode& node = top.nodes[n];
    for (int a = 0; a < 3; ++a) node.min[a] = INFINITY, node.max[a] = -INFINITY;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i)
        for (int a = 0; a < 3; ++a) {
          node.min[a] = std::min(node.min[a], top.placed[i].box_min[a]);
          node.max[a] = std::max(node.max[a], top.placed[i].box_max[a]);
        }
      continue;
    }
    for (int a = 0; a < 3; ++a) {
      node.min[a] = std::min(top.nodes[n + 1].min[a], top.nodes[node.right].min[a]);
      node.max[a] = std::max(top.nodes[n + 1].max[a], top.nodes[node.right].max[a]);
    }
  }
  fit_wide_boxes(top);  // the same wide nodes and anchor, their boxes again
}

}  // namespace meshcast
