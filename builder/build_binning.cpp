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

}  // namespace

uint32_t BinningSplit::operator()(uint32_t* begin, uint32_t* end, const Box3& cbox) const {
  double best_cost = INFINITY;
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
    std::array<double, kBins> right_area{};
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
      double cost = acc.half_area() * n + right_area[b + 1] * right_count[b + 1];
      if (cost < best_cost) best_cost = cost, best_axis = axis, best_bin = b;
    }
  }
  if (best_axis < 0) return 0;  // all centres coincide
  float lo = cbox.min[best_axis], extent = cbox.max[best_axis] - lo;
  uint32_t* mid = std::partition(begin, end, [&](uint32_t t) { return bin_of(centres[t][best_axis], lo, extent) <= best_bin; });
  return uint32_t(mid - begin);
}

BuildTree build_binning(const std::vector<Box3>& boxes, uint32_t leaf_size, uint32_t depth_limit, uint32_t leaf_capacity) {
  std::vector<Vec3> centres = box_centres(boxes);
  BinningSplit split{boxes, centres};
  return TopDown<BinningSplit>{boxes, centres, std::max(1u, leaf_size), split, {}, depth_limit, leaf_capacity}.run();
}

}  // namespace meshcast
