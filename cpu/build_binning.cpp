#include <algorithm>
#include <array>

#include "cpu/build.h"

namespace meshcast {

uint32_t BuildTree::leaf_count() const {
  uint32_t n = 0;
  for (const BuildNode& b : nodes) n += b.leaf();
  return n;
}

namespace {

constexpr int kBins = 32;
constexpr uint32_t kSahDepth = 40;

struct Builder {
  const std::vector<Box3>& boxes;
  std::vector<Vec3> centres;
  uint32_t leaf_size;
  BuildTree tree;

  // Returns the index of the node built for order[first, first + count).
  uint32_t build(uint32_t first, uint32_t count, uint32_t depth) {
    uint32_t index = uint32_t(tree.nodes.size());
    tree.nodes.emplace_back();
    tree.depth = std::max(tree.depth, depth);
    Box3 box, cbox;
    for (uint32_t i = first; i < first + count; ++i) {
      box.grow(boxes[tree.order[i]]);
      cbox.grow(centres[tree.order[i]]);
    }
    tree.nodes[index].box = box;
    if (count <= leaf_size) {
      tree.nodes[index].first = first, tree.nodes[index].count = count;
      return index;
    }
    // Deep in a degenerate mesh, fall back to median splits so the depth
    // stays within what the walkers' stacks allow (MC_MAX_DEPTH).
    uint32_t mid = depth < kSahDepth ? split(first, count, cbox) : median_split(first, count, cbox);
    uint32_t left = build(first, mid - first, depth + 1);
    uint32_t right = build(mid, first + count - mid, depth + 1);
    tree.nodes[index].left = left, tree.nodes[index].right = right;
    return index;
  }

  uint32_t median_split(uint32_t first, uint32_t count, const Box3& cbox) {
    Vec3 e = cbox.extent();
    int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    uint32_t* begin = tree.order.data() + first;
    std::nth_element(begin, begin + count / 2, begin + count,
                     [&](uint32_t a, uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    return first + count / 2;
  }

  // Bin of a centre: computed the same way when binning and partitioning,
  // and safe for any finite input (a tiny or huge extent never yields NaN
  // or an index outside the bins).
  static int bin_of(float c, float lo, float extent) {
    float f = float((double(c) - lo) / extent * kBins);
    return !(f > 0) ? 0 : (f >= kBins ? kBins - 1 : int(f));
  }

  // SAH over binned centres on all three axes; returns the partition point.
  uint32_t split(uint32_t first, uint32_t count, const Box3& cbox) {
    uint32_t* begin = tree.order.data() + first;
    uint32_t* end = begin + count;
    float best_cost = INFINITY;
    int best_axis = -1, best_bin = 0;
    for (int axis = 0; axis < 3; ++axis) {
      float lo = cbox.min[axis], extent = cbox.max[axis] - lo;
      if (!(extent > 0)) continue;
      std::array<Box3, kBins> bin_box;
      std::array<uint32_t, kBins> bin_count{};
      for (uint32_t* p = begin; p != end; ++p) {
        int b = bin_of(centres[*p][axis], lo, extent);
        bin_box[b].grow(boxes[*p]);
        ++bin_count[b];
      }
      // Sweep from the right, then evaluate each split from the left.
      std::array<float, kBins> right_area{};
      std::array<uint32_t, kBins> right_count{};
      Box3 acc;
      uint32_t n = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.grow(bin_box[b]);
        n += bin_count[b];
        right_area[b] = acc.half_area(), right_count[b] = n;
      }
      acc = Box3{};
      n = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        acc.grow(bin_box[b]);
        n += bin_count[b];
        if (n == 0 || right_count[b + 1] == 0) continue;
        float cost = acc.half_area() * n + right_area[b + 1] * right_count[b + 1];
        if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = b;
      }
    }
    if (best_axis < 0) return first + count / 2;  // all centres coincide: split by index
    float lo = cbox.min[best_axis], extent = cbox.max[best_axis] - lo;
    uint32_t* mid = std::partition(begin, end, [&](uint32_t t) {
      return bin_of(centres[t][best_axis], lo, extent) <= best_bin;
    });
    return first + uint32_t(mid - begin);
  }
};

}  // namespace

BuildTree build_binning(const std::vector<Box3>& boxes, uint32_t leaf_size) {
  Builder b{boxes, {}, std::max(1u, leaf_size), {}};
  b.centres.reserve(boxes.size());
  for (const Box3& box : boxes) b.centres.push_back(box.centre());
  b.tree.order.resize(boxes.size());
  for (uint32_t i = 0; i < boxes.size(); ++i) b.tree.order[i] = i;
  b.tree.nodes.reserve(2 * boxes.size() / std::max(1u, leaf_size) + 1);
  b.build(0, uint32_t(boxes.size()), 0);
  // SAH cost relative to the root box, unit costs for nodes and triangles.
  double root = std::max(1e-30, double(b.tree.nodes[0].box.half_area()));
  for (const BuildNode& n : b.tree.nodes)
    b.tree.sah_cost += n.box.half_area() / root * (n.leaf() ? n.count : 1.0);
  return std::move(b.tree);
}

}  // namespace meshcast
