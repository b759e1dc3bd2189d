// The other splitters of seed 000 §4.1, each a split step for TopDown:
//   LongestAxis    the centre of the centres' box along its longest axis
//   Mean           the mean of the centres along the axis of largest
//                  standard deviation
//   Morton         centres sorted by Morton code once; a node splits where
//                  the highest bit that differs flips (Karras 2012)
//   FixedLeafSize  triangles grouped by fours first (consecutive in Morton
//                  order), Binning over the groups, so leaves hold whole
//                  groups and SOA blocks need little padding
#include <cmath>

#include "builder/build_topdown.h"

namespace meshcast {

namespace {

int longest_axis(const Box3& b) {
  Vec3 e = b.extent();
  return e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
}

struct LongestAxisSplit {
  const std::vector<Vec3>& centres;
  uint32_t operator()(uint32_t* begin, uint32_t* end, const Box3& cbox) const {
    int axis = longest_axis(cbox);
    float mid = cbox.centre()[axis];
    return uint32_t(std::partition(begin, end, [&](uint32_t t) { return centres[t][axis] < mid; }) - begin);
  }
};

struct MeanSplit {
  const std::vector<Vec3>& centres;
  uint32_t operator()(uint32_t* begin, uint32_t* end, const Box3&) const {
    double sum[3] = {}, sq[3] = {};
    double n = double(end - begin);
    for (uint32_t* p = begin; p != end; ++p)
      for (int a = 0; a < 3; ++a) sum[a] += centres[*p][a], sq[a] += double(centres[*p][a]) * centres[*p][a];
    int axis = 0;
    double best = -1;
    for (int a = 0; a < 3; ++a) {
      double var = sq[a] / n - (sum[a] / n) * (sum[a] / n);
      if (var > best) best = var, axis = a;
    }
    double mean = sum[axis] / n;
    return uint32_t(std::partition(begin, end, [&](uint32_t t) { return centres[t][axis] < mean; }) - begin);
  }
};

// 10 bits an axis, interleaved x, y, z.
uint32_t spread(uint32_t v) {
  v = (v | v << 16) & 0x030000FFu;
  v = (v | v << 8) & 0x0300F00Fu;
  v = (v | v << 4) & 0x030C30C3u;
  return (v | v << 2) & 0x09249249u;
}

std::vector<uint32_t> morton_codes(const std::vector<Vec3>& centres) {
  // One scale for all three axes (the largest extent): scaling each axis to
  // its own extent would give a flat mesh's thin axis as many bits as the
  // others, and its top bit would split a terrain into two interleaved
  // height bands spread over the whole plane.
  Box3 box;
  for (const Vec3& c : centres) box.grow(c);
  const double e = std::max({double(box.max.x) - box.min.x, double(box.max.y) - box.min.y, double(box.max.z) - box.min.z});
  std::vector<uint32_t> codes(centres.size());
  for (size_t i = 0; i < centres.size(); ++i) {
    uint32_t q[3];
    for (int a = 0; a < 3; ++a) {
      double f = e > 0 ? (double(centres[i][a]) - box.min[a]) / e : 0.0;
      q[a] = uint32_t(std::clamp(f * 1023.0, 0.0, 1023.0));
    }
    codes[i] = spread(q[0]) << 2 | spread(q[1]) << 1 | spread(q[2]);
  }
  return codes;
}

std::vector<uint32_t> morton_order(const std::vector<uint32_t>& codes) {
  std::vector<uint32_t> order(codes.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return codes[a] < codes[b]; });
  return order;
}

struct MortonSplit {
  static constexpr bool kSorted = true;  // cuts ranges of the presorted order, keeps it
  const std::vector<uint32_t>& codes;
  uint32_t operator()(uint32_t* begin, uint32_t* end, const Box3&) const {
    uint32_t first = codes[*begin], last = codes[*(end - 1)];
    if (first == last) return 0;
    uint32_t bit = 1u << (31 - __builtin_clz(first ^ last));
    // The range is sorted: the first code with the bit set starts the right.
    return uint32_t(std::partition_point(begin, end, [&](uint32_t t) { return !(codes[t] & bit); }) - begin);
  }
};

// FixedLeafSize: groups of 4 consecutive primitives in Morton order become
// the primitives of a Binning build with leaves of leaf_size / 4 groups.
BuildTree build_fixed_leaf_size(const std::vector<Box3>& boxes, const std::vector<Vec3>& centres, uint32_t leaf,
                                uint32_t depth_limit, uint32_t leaf_capacity, BuildThreads* threads) {
  constexpr uint32_t kGroup = 4;
  std::vector<uint32_t> members = morton_order(morton_codes(centres));
  const uint32_t groups = uint32_t((members.size() + kGroup - 1) / kGroup);
  std::vector<uint32_t> start(groups + 1);
  std::vector<Box3> group_boxes(groups);
  for (uint32_t k = 0; k <= groups; ++k) start[k] = std::min<uint32_t>(k * kGroup, uint32_t(members.size()));
  for (size_t i = 0; i < members.size(); ++i) group_boxes[i / kGroup].grow(boxes[members[i]]);
  std::vector<Vec3> group_centres = box_centres(group_boxes, threads);
  BinningSplit split{group_boxes, group_centres};
  TopDown<BinningSplit> group_top{group_boxes, group_centres, std::max(1u, leaf / kGroup), split, {}, depth_limit};
  group_top.leaf_capacity = std::max(1u, leaf_capacity / kGroup);  // whole groups within the leaf capacity
  group_top.primitives = "groups of 4";
  group_top.threads = threads;
  return expand_groups(group_top.run(), members, start);
}

}  // namespace

BuildTree build_tree(const std::vector<Box3>& boxes, Splitter splitter, uint32_t leaf_size, uint32_t depth_limit,
                     uint32_t leaf_capacity, BuildThreads* threads) {
  leaf_size = std::max(1u, leaf_size);
  // Binning works out its centres itself.
  if (splitter == Splitter::Binning) return build_binning(boxes, leaf_size, depth_limit, leaf_capacity, threads);
  std::vector<Vec3> centres = box_centres(boxes, threads);
  switch (splitter) {
    case Splitter::Binning: break;
    case Splitter::LongestAxis: {
      LongestAxisSplit s{centres};
      return TopDown<LongestAxisSplit>{boxes, centres, leaf_size, s, {}, depth_limit, leaf_capacity, "triangles", threads}
          .run();
    }
    case Splitter::Mean: {
      MeanSplit s{centres};
      return TopDown<MeanSplit>{boxes, centres, leaf_size, s, {}, depth_limit, leaf_capacity, "triangles", threads}.run();
    }
    case Splitter::Morton: {
      std::vector<uint32_t> codes = morton_codes(centres);
      MortonSplit s{codes};
      return TopDown<MortonSplit>{boxes, centres, leaf_size, s, {}, depth_limit, leaf_capacity, "triangles", threads}
          .run(morton_order(codes));
    }
    case Splitter::FixedLeafSize:
      return build_fixed_leaf_size(boxes, centres, leaf_size, depth_limit, leaf_capacity, threads);
  }
  return build_binning(boxes, leaf_size, depth_limit, leaf_capacity, threads);
}

BuildTree expand_groups(const BuildTree& g, const std::vector<uint32_t>& members, const std::vector<uint32_t>& start) {
  // position p of g.order -> its first triangle position in t.order
  std::vector<uint32_t> at(g.order.size() + 1, 0);
  BuildTree t;
  t.order.reserve(members.size());
  for (size_t p = 0; p < g.order.size(); ++p) {
    const uint32_t group = g.order[p];
    at[p] = uint32_t(t.order.size());
    t.order.insert(t.order.end(), members.begin() + start[group], members.begin() + start[group + 1]);
  }
  at[g.order.size()] = uint32_t(t.order.size());
  t.nodes = g.nodes;
  for (BuildNode& n : t.nodes)
    if (n.leaf()) {
      const uint32_t first = at[n.first], end = at[n.first + n.count];
      n.first = first, n.count = end - first;
    }
  t.depth = g.depth;
  t.sah_cost = sah_cost(t);
  return t;
}

std::vector<uint32_t> morton_sorted(const std::vector<Vec3>& centres) { return morton_order(morton_codes(centres)); }

std::vector<Splitter> all_splitters() {
  return {Splitter::Binning, Splitter::LongestAxis, Splitter::Mean, Splitter::Morton, Splitter::FixedLeafSize};
}

const char* splitter_name(Splitter s) {
  switch (s) {
    case Splitter::Binning: return "Binning";
    case Splitter::LongestAxis: return "LongestAxis";
    case Splitter::Mean: return "Mean";
    case Splitter::Morton: return "Morton";
    case Splitter::FixedLeafSize: return "FixedLeafSize";
  }
  return "";
}

Splitter parse_splitter(const std::string& name) { return parse_named(name, all_splitters(), splitter_name, "splitter"); }

}  // namespace meshcast
