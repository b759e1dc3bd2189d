#include "builder/top_level.h"

#include <algorithm>
#include <cmath>

namespace meshcast {

namespace {

struct TopBuilder {
  std::vector<layout::PlacedInstance>& placed;
  std::vector<layout::TopNode>& nodes;

  double centre(uint32_t i, int axis) const { return placed[i].box_min[axis] + placed[i].box_max[axis]; }

  // The node over placed[first, first + count); returns its index.
  uint32_t build(uint32_t first, uint32_t count) {
    const uint32_t index = uint32_t(nodes.size());
    layout::TopNode node{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, first, 0, 0};
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = first; i < first + count; ++i)
      for (int a = 0; a < 3; ++a) {
        node.min[a] = std::min(node.min[a], placed[i].box_min[a]);
        node.max[a] = std::max(node.max[a], placed[i].box_max[a]);
        lo[a] = std::min(lo[a], centre(i, a));
        hi[a] = std::max(hi[a], centre(i, a));
      }
    nodes.push_back(node);
    if (count <= layout::kTopLeafSize) {
      nodes[index].count = count;
      return index;
    }
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    const uint32_t half = count / 2;
    std::nth_element(placed.begin() + first, placed.begin() + first + half, placed.begin() + first + count,
                     [&](const layout::PlacedInstance& x, const layout::PlacedInstance& y) {
                       return x.box_min[axis] + x.box_max[axis] < y.box_min[axis] + y.box_max[axis];
                     });
    build(first, half);  // the left child is index + 1
    const uint32_t right = build(first + half, count - half);
    nodes[index].right = right;
    return index;
  }
};

}  // namespace

layout::TopLevel build_top_level(std::vector<layout::PlacedInstance> placed) {
  layout::TopLevel top;
  top.placed = std::move(placed);
  if (top.placed.empty()) return top;
  top.nodes.reserve(top.placed.size());
  TopBuilder{top.placed, top.nodes}.build(0, uint32_t(top.placed.size()));
  return top;
}

}  // namespace meshcast
