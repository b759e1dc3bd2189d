#include "scene/build_top_level.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace meshcast {

namespace {

// A binary node while building: `count` 1, a leaf over the item at
// `first`; 0, an inner node, its children this node + 1 and `right`. Its box
// in double picks what the collapse opens.
struct BinaryNode {
  double min[3], max[3];
  uint32_t first, count, right;
};

// What the splits move: an instance's box centre (doubled) and its id, 32
// bytes, not the whole record.
struct Item {
  double centre[3];
  uint32_t id;
};

struct Splitter {
  std::span<const WorldBox> boxes;
  std::vector<Item>& items;
  std::vector<BinaryNode>& nodes;

  // The node over items[first, first + count); returns its index.
  uint32_t build(uint32_t first, uint32_t count) {
    const uint32_t index = uint32_t(nodes.size());
    nodes.push_back({{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, first, 0, 0});
    if (count == 1) {
      BinaryNode& leaf = nodes[index];
      leaf.count = 1;
      for (int a = 0; a < 3; ++a) leaf.min[a] = boxes[items[first].id].min[a], leaf.max[a] = boxes[items[first].id].max[a];
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
    BinaryNode& node = nodes[index];
    node.right = right;
    for (int a = 0; a < 3; ++a) {
      node.min[a] = std::min(nodes[index + 1].min[a], nodes[right].min[a]);
      node.max[a] = std::max(nodes[index + 1].max[a], nodes[right].max[a]);
    }
    return index;
  }
};

double half_area(const BinaryNode& n) {
  const double e[3] = {n.max[0] - n.min[0], n.max[1] - n.min[1], n.max[2] - n.min[2]};
  return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

// The wide nodes over the binary ones, pre-order (a node before its
// children): slots name wide nodes and leaf items; boxes come later.
struct Collapser {
  const std::vector<BinaryNode>& nodes;
  std::vector<layout::TopWideNode>& wide;

  // The wide node over binary node `root` (an inner node); returns its index.
  uint32_t collapse(uint32_t root) {
    uint32_t kids[layout::kTopWidth] = {root + 1, nodes[root].right};
    int count = 2;
    // Open the largest inner child until there are kTopWidth.
    while (count < layout::kTopWidth) {
      int best = -1;
      for (int k = 0; k < count; ++k)
        if (nodes[kids[k]].count == 0 && (best < 0 || half_area(nodes[kids[k]]) > half_area(nodes[kids[best]])))
          best = k;
      if (best < 0) break;
      const uint32_t opened = kids[best];
      kids[best] = opened + 1;
      kids[count++] = nodes[opened].right;
    }
    const uint32_t index = uint32_t(wide.size());
    wide.emplace_back();
    for (int k = 0; k < layout::kTopWidth; ++k) {
      uint32_t slot = layout::kTopEmpty;
      if (k < count) {
        const BinaryNode& n = nodes[kids[k]];
        slot = n.count > 0 ? layout::kTopInstance | n.first : collapse(kids[k]);
      }
      wide[index].slot[k] = slot;  // (collapse() may have moved the vector)
    }
    return index;
  }
};

// The float next to a finite f towards -inf (down) or +inf (up), by its
// bits (std::nextafter is a library call, and a refit makes 6 of these an
// instance).
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

}  // namespace

void build_top_level(std::span<const WorldBox> boxes, std::span<const uint32_t> ids, layout::TopLevel& top,
                     std::vector<uint32_t>& order) {
  top.wide.clear();
  order.clear();
  if (ids.empty()) return;
  std::vector<Item> items(ids.size());
  for (size_t i = 0; i < ids.size(); ++i) {
    for (int a = 0; a < 3; ++a) items[i].centre[a] = boxes[ids[i]].min[a] + boxes[ids[i]].max[a];
    items[i].id = ids[i];
  }
  std::vector<BinaryNode> nodes;
  nodes.reserve(2 * ids.size());
  Splitter{boxes, items, nodes}.build(0, uint32_t(ids.size()));
  order.reserve(items.size());
  for (const Item& item : items) order.push_back(item.id);
  if (nodes[0].count > 0) {  // one instance: a wide root with it in slot 0
    top.wide.emplace_back();
    for (int k = 0; k < layout::kTopWidth; ++k) top.wide[0].slot[k] = k == 0 ? layout::kTopInstance : layout::kTopEmpty;
  } else {
    top.wide.reserve(ids.size() / 4 + 1);
    Collapser{nodes, top.wide}.collapse(0);
  }
  refit_top_level(boxes, order, top);
}

void refit_top_level(std::span<const WorldBox> boxes, std::span<const uint32_t> order, layout::TopLevel& top) {
  if (top.wide.empty()) return;  // nothing placed: nothing to fit
  // The anchor follows the root box on every fit: a ray's origin is rounded
  // to float relative to it, and the walk's pad is sized by the distance to
  // the root box, so the two must stay together as instances wander.
  for (int a = 0; a < 3; ++a) top.min[a] = INFINITY, top.max[a] = -INFINITY;
  for (const uint32_t id : order)
    for (int a = 0; a < 3; ++a)
      top.min[a] = std::min(top.min[a], boxes[id].min[a]), top.max[a] = std::max(top.max[a], boxes[id].max[a]);
  for (int a = 0; a < 3; ++a) top.anchor[a] = 0.5 * (top.min[a] + top.max[a]);
  // Children follow their parent: from the last node back, every child's
  // slots are fitted before its parent joins them (exactly: a min and a max
  // of floats round nothing).
  for (size_t w = top.wide.size(); w-- > 0;) {
    layout::TopWideNode& node = top.wide[w];
    for (int k = 0; k < layout::kTopWidth; ++k) {
      const uint32_t slot = node.slot[k];
      for (int a = 0; a < 3; ++a) {
        if (slot == layout::kTopEmpty) {
          node.lo[a][k] = INFINITY, node.hi[a][k] = -INFINITY;  // never entered
        } else if (slot & layout::kTopInstance) {
          const WorldBox& b = boxes[order[slot & ~layout::kTopInstance]];
          node.lo[a][k] = below(b.min[a], top.anchor[a]);
          node.hi[a][k] = above(b.max[a], top.anchor[a]);
        } else {
          const layout::TopWideNode& child = top.wide[slot];
          float lo = INFINITY, hi = -INFINITY;
          for (int c = 0; c < layout::kTopWidth; ++c) lo = std::min(lo, child.lo[a][c]), hi = std::max(hi, child.hi[a][c]);
          node.lo[a][k] = lo, node.hi[a][k] = hi;
        }
      }
    }
  }
}

}  // namespace meshcast
