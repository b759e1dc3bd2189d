// The top-down recursion every splitter of seed 000 §4.1 shares: a node
// with at most leaf_size triangles is a leaf, a larger one is split by the
// splitter (or at the median of the longest centre axis when the splitter
// cannot separate them, and always below kSplitterDepth so the depth stays
// within the walkers' stacks). Splitters see only triangle boxes and centres.
#pragma once
#include <algorithm>

#include "builder/binary_tree.h"
#include "builder/build_threads.h"
#include "layout/formats.h"

namespace meshcast {

constexpr uint32_t kSplitterDepth = 40;

// SAH cost relative to the root box, unit costs for nodes and triangles.
inline double sah_cost(const BuildTree& t) {
  double root = t.nodes[0].box.half_area(), cost = 0;
  if (!(root > 0)) root = 1;  // a flat or point-sized root: costs in absolute units
  for (const BuildNode& n : t.nodes) cost += n.box.half_area() / root * (n.leaf() ? n.count : 1.0);
  return cost;
}

// Split(begin, end, centre box) reorders [begin, end) and returns the count
// of the left part; 0 or the whole count means "cannot split".
template <class Split>
struct TopDown {
  const std::vector<Box3>& boxes;
  const std::vector<Vec3>& centres;
  uint32_t leaf_size;
  Split& split;
  BuildTree tree;
  uint32_t depth_limit = ~0u;
  uint32_t leaf_capacity = MC_QUAD_MAX_COUNT;  // most primitives a leaf at the depth limit may take
  const char* primitives = "triangles";
  BuildThreads* threads = nullptr;  // none: this thread alone

  // Least triangles on each side of a split that goes to another thread: a
  // thread's start costs tens of microseconds, a subtree this size about a
  // millisecond.
  static constexpr uint32_t kForkGrain = 4096;

  // Nodes in the order a one-thread build makes them (each node, then its
  // left subtree, then its right); a part built on another thread is
  // numbered from 0 and appended in its place (append_part).
  struct Part {
    std::vector<BuildNode> nodes;
    uint32_t depth = 0;
  };

  uint32_t build(Part& part, uint32_t first, uint32_t count, uint32_t depth) {
    uint32_t index = uint32_t(part.nodes.size());
    part.nodes.emplace_back();
    part.depth = std::max(part.depth, depth);
    Box3 box, cbox;
    for (uint32_t i = first; i < first + count; ++i) box.grow(boxes[tree.order[i]]), cbox.grow(centres[tree.order[i]]);
    part.nodes[index].box = box;
    if (count > capacity(depth))
      throw InputError("depth limit " + std::to_string(depth_limit + 1) + " holds at most " +
                       std::to_string(capacity(depth)) + " " + primitives + " (" + std::to_string(leaf_capacity) +
                       " a leaf), not " + std::to_string(count) + "; raise the depth limit");
    if (count <= leaf_size || depth >= depth_limit) {
      part.nodes[index].first = first, part.nodes[index].count = count;
      return index;
    }
    uint32_t* begin = tree.order.data() + first;
    uint32_t left = depth < kSplitterDepth ? split(begin, begin + count, cbox) : 0;
    // Under a depth limit a side must still fit the levels left below it
    // (halving each level, leaf_capacity a leaf); a split that would
    // overfill one is evened out, which always fits: a splitter whose range
    // stays sorted (Morton) moves its cut within that order, the others
    // split at the median.
    const uint64_t fits = capacity(depth + 1);
    if (left == 0 || left >= count) {
      left = median(begin, count, cbox);  // (Morton: all codes equal, any order stays sorted)
    } else if (std::max(left, count - left) > fits) {
      if constexpr (requires { Split::kSorted; })
        left = uint32_t(std::clamp<uint64_t>(left, count > fits ? count - fits : 1, std::min<uint64_t>(fits, count - 1)));
      else
        left = median(begin, count, cbox);
    }
    uint32_t l = 0, r = 0;
    if (threads && std::min(left, count - left) >= kForkGrain) {
      // The two sides touch disjoint ranges of the order. The right part's
      // nodes (at most 2n - 1 for n triangles) are reserved here, so the
      // other thread never allocates them: memory a thread allocates stays
      // in its own glibc arena after it is freed, where malloc_trim does
      // not reach it (a tenth of a blob's size, held by the process for
      // good). Reserved and not written, the rest costs address space alone.
      Part right;
      right.nodes.reserve(2 * size_t(count - left));
      threads->fork([&] { build(right, first + left, count - left, depth + 1); },
                    [&] { l = build(part, first, left, depth + 1); });
      r = append_part(part, right);
    } else {
      l = build(part, first, left, depth + 1);
      r = build(part, first + left, count - left, depth + 1);
    }
    part.nodes[index].left = l, part.nodes[index].right = r;
    return index;
  }

  // `from` after part's nodes, its links moved along; its root's index.
  static uint32_t append_part(Part& part, const Part& from) {
    const uint32_t base = uint32_t(part.nodes.size());
    for (BuildNode n : from.nodes) {
      if (!n.leaf()) n.left += base, n.right += base;
      part.nodes.push_back(n);
    }
    part.depth = std::max(part.depth, from.depth);
    return base;
  }

  // Most triangles a subtree rooted at `depth` can hold under depth_limit.
  uint64_t capacity(uint32_t depth) const {
    if (depth_limit >= 40) return ~0ull;
    return uint64_t(leaf_capacity) << (depth_limit - std::min(depth, depth_limit));
  }

  uint32_t median(uint32_t* begin, uint32_t count, const Box3& cbox) {
    Vec3 e = cbox.extent();
    int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    std::nth_element(begin, begin + count / 2, begin + count,
                     [&](uint32_t a, uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    return count / 2;
  }

  // `order`: the starting order (identity when empty), kept by splitters
  // that cut ranges of a presorted sequence (Morton).
  BuildTree run(std::vector<uint32_t> order = {}) {
    if (order.empty()) {
      order.resize(boxes.size());
      for (uint32_t i = 0; i < boxes.size(); ++i) order[i] = i;
    }
    tree.order = std::move(order);
    Part whole;
    whole.nodes.reserve(2 * boxes.size() / std::max(1u, leaf_size) + 1);
    build(whole, 0, uint32_t(boxes.size()), 0);
    tree.nodes = std::move(whole.nodes);
    tree.depth = whole.depth;
    tree.sah_cost = sah_cost(tree);
    return std::move(tree);
  }
};

std::vector<Vec3> box_centres(const std::vector<Box3>& boxes, BuildThreads* threads = nullptr);


}  // namespace meshcast
