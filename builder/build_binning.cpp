// Binning (seed 000 §4.1, after Günther et al. 2007): triangle centres are
// sorted into 32 bins along each axis and the split with the lowest surface
// area heuristic is taken.
#include <array>

#include "builder/build_topdown.h"

namespace meshcast {

uint32_t BuildTree::leaf_count() const {
  uint32_t n = 0;
  for (const BuildNode& b : nodes) n += b.leaf();
  return n;
}

std::vector<Vec3> box_centres(const std::vector<Box3>& boxes) {
  std::vector<Vec3> c;
  c.reserve(boxes.size());
  for (const Box3& b : boxes) c.push_back(b.centre());
  return c;
}

namespace {

constexpr int kBins = 32;

// Bin of a centre: computed the same way when binning and partitioning, and
// safe for any finite input (a tiny or huge extent never yields NaN or an
// index outside the bins).
int bin_of(float c, float lo, float extent) {
  float f = float((double(c) - lo) / extent * kBins);
  return !(f > 0) ? 0 : (f >= kBins ? kBins - 1 : int(f));
}

// A bin's box as two 4-float vectors: min and max of a whole corner in one
// instruction each, with no branch (std::min on floats inlined into this
// loop became compare-and-branch, mispredicted on every other triangle).
using Float4 = float __attribute__((vector_size(16)));
struct BinBox {
  Float4 min = {INFINITY, INFINITY, INFINITY, INFINITY}, max = {-INFINITY, -INFINITY, -INFINITY, -INFINITY};
  void grow(Float4 lo, Float4 hi) {
    min = lo < min ? lo : min;  // std::min(min, lo), lane by lane
    max = max < hi ? hi : max;  // std::max(max, hi)
  }
  Box3 box() const { return {{min[0], min[1], min[2]}, {max[0], max[1], max[2]}}; }
};

Float4 load3(const Vec3& v) { return Float4{v.x, v.y, v.z, 0.0f}; }

}  // namespace

uint32_t BinningSplit::operator()(uint32_t* begin, uint32_t* end, const Box3& cbox) const {
  // One pass over the triangles bins all three axes (each triangle's box
  // and centre read once); an axis whose centres coincide is not binned.
  float lo[3], extent[3];
  bool binned[3];
  for (int axis = 0; axis < 3; ++axis) {
    lo[axis] = cbox.min[axis], extent[axis] = cbox.max[axis] - lo[axis];
    binned[axis] = extent[axis] > 0;
  }
  std::array<std::array<BinBox, kBins>, 3> bin_box;
  std::array<std::array<uint32_t, kBins>, 3> bin_count{};
  for (uint32_t* p = begin; p != end; ++p) {
    const Box3& box = boxes[*p];
    const Float4 box_min = load3(box.min), box_max = load3(box.max);
    const Vec3& c = centres[*p];
    for (int axis = 0; axis < 3; ++axis) {
      if (!binned[axis]) continue;
      const int b = bin_of(c[axis], lo[axis], extent[axis]);
      bin_box[axis][b].grow(box_min, box_max);
      ++bin_count[axis][b];
      if (bins) bins[3 * size_t(*p) + size_t(axis)] = uint8_t(b);
    }
  }
  double best_cost = INFINITY;
  int best_axis = -1, best_bin = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (!binned[axis]) continue;
    // Sweep from the right, then evaluate each split from the left.
    std::array<double, kBins> right_area{};
    std::array<uint32_t, kBins> right_count{};
    Box3 acc;
    uint32_t n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[axis][b].box());
      n += bin_count[axis][b];
      right_area[b] = box_half_area(acc), right_count[b] = n;
    }
    acc = Box3{};
    n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(bin_box[axis][b].box());
      n += bin_count[axis][b];
      if (n == 0 || right_count[b + 1] == 0) continue;
      double cost = box_half_area(acc) * n + right_area[b + 1] * right_count[b + 1];
      if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = b;
    }
  }
  if (best_axis < 0) return 0;  // all centres coincide
  uint32_t* mid = bins ? std::partition(begin, end, [&](uint32_t t) { return bins[3 * size_t(t) + size_t(best_axis)] <= best_bin; })
                       : std::partition(begin, end, [&](uint32_t t) {
                           return bin_of(centres[t][best_axis], lo[best_axis], extent[best_axis]) <= best_bin;
                         });
  return uint32_t(mid - begin);
}

BuildTree build_binning(const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit, uint32_t leaf_capacity,
                        BuildThreads* threads) {
  std::vector<Vec3> centres = box_centres(boxes);
  std::vector<uint8_t> bins(3 * boxes.size());
  BinningSplit split{boxes, centres, bins.data()};
  return TopDown<BinningSplit>{boxes, centres, std::max(1u, leaf_size), split, {}, depth_limit, leaf_capacity, "triangles",
                               threads}
      .run();
}

}  // namespace meshcast
