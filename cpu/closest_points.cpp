// BlobView::closest_points: the point of the stored mesh nearest each query
// point, on an OctTreeCompressed blob. The walk is best first: a node's 8
// child boxes are decoded (exactly, as the ray walk decodes them) and their
// squared distances from the point taken, the children no farther than the
// best distance so far wait in a heap, and the nearest waiting box is
// walked next; the walk ends when it is farther than the best. In a leaf
// each triangle's nearest point is worked out in double from its stored
// corners (cpu/point_triangle.h), after a test of its corners' box.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "cpu/point_triangle.h"
#include "layout/blob_format.h"
#include "layout/tree/leaves.h"
#include "layout/tree/octtree.h"
#include "meshcast/blob.h"

namespace meshcast {

namespace {

// A box's squared distance from the point is a lower bound for every
// triangle inside it. It is taken in double from the decoded float bounds
// (each difference exact or rounded by 2^-53 of itself, then three
// products and two sums): it may come out at most 2^-50 of itself above
// the true one, so a box is dropped only where it is farther than the best
// distance by more than that.
constexpr double kBoxSlack = 1 - 0x1p-48;

struct Best {
  double d2;             // the squared limit until a triangle is found
  PointOnTriangle near;
  uint32_t triangle = kNoHit;
};

// The squared distance from p to the box [lo, hi] (0 inside): a leaf's
// triangles' corner boxes (float) and a node's decoded child boxes (double).
template <class Bound>
inline double box_d2(const double p[3], const Bound lo[3], const Bound hi[3]) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double below = double(lo[a]) - p[a], above = p[a] - double(hi[a]);
    const double d = below > 0 ? below : above > 0 ? above : 0;
    d2 += d * d;
  }
  return d2;
}

void test_leaf(const uint8_t* blob, const layout::BlobHeader& h, uint32_t offset, uint32_t count, const double p[3],
               Best& best) {
  float corners[MC_OCT_MAX_COUNT][3][3];
  layout::decode_leaf(blob, h.tree_offset + offset, count, corners);
  for (uint32_t i = 0; i < count; ++i) {
    const float(&v)[3][3] = corners[i];
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min({v[0][a], v[1][a], v[2][a]});
      hi[a] = std::max({v[0][a], v[1][a], v[2][a]});
    }
    if (box_d2(p, lo, hi) * kBoxSlack > best.d2) continue;
    const PointOnTriangle near = nearest_on_triangle(p, v[0], v[1], v[2]);
    if (near.d2 > best.d2) continue;
    const uint32_t triangle = layout::remap_entry(blob, h, layout::slot_of(h, offset, i));
    // At one distance the lower triangle number, whatever the walk's order.
    if (near.d2 == best.d2 && best.triangle != kNoHit && triangle > best.triangle) continue;
    best.d2 = near.d2, best.near = near, best.triangle = triangle;
  }
}

// A child waiting to be walked, and its box's squared distance.
struct Pending {
  double d2;
  uint32_t properties;
};

// Best first over the whole tree, not only among siblings: the nearest box
// waiting anywhere is walked next, so every box walked is one nearer than
// the final answer would allow to skip (a point far from the mesh would
// otherwise walk down one side, then another, before the distance shrinks).
// `heap`: the caller's, reused from point to point.
void walk_point(const uint8_t* blob, const layout::BlobHeader& h, const double p[3], Best& best,
                std::vector<Pending>& heap) {
  const uint8_t* tree = blob + h.tree_offset;
  const auto farther = [](const Pending& x, const Pending& y) { return x.d2 > y.d2; };
  heap.clear();
  heap.push_back({0, h.root});
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), farther);
    const Pending next = heap.back();
    heap.pop_back();
    if (next.d2 * kBoxSlack > best.d2) return;  // every box left is farther still
    const uint32_t count = layout::oct_count(next.properties), offset = layout::oct_offset(next.properties);
    if (count > 0) {
      test_leaf(blob, h, offset, count, p, best);
      continue;
    }
    const uint8_t* node = tree + offset;
    // The 8 child boxes decoded in double: Origin + q 2^e is exact in float
    // by the format's rule (layout/tree/octtree.h), so in double too, with
    // no fused multiply-add.
    double origin[3], scale[3];
    for (int a = 0; a < 3; ++a) {
      origin[a] = layout::load<float>(node + MC_OCT_ORIGIN_AT + 4 * a);
      scale[a] = layout::oct_scale(node[MC_OCT_EXPONENTS_AT + a]);
    }
    for (int k = 0; k < 8; ++k) {
      const uint32_t child = layout::oct_child_properties(node, k);
      if (child == 0) continue;
      double lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = origin[a] + node[MC_OCT_QLO_AT + 8 * a + k] * scale[a];
        hi[a] = origin[a] + node[MC_OCT_QHI_AT + 8 * a + k] * scale[a];
      }
      const double d2 = box_d2(p, lo, hi);
      if (d2 * kBoxSlack > best.d2) continue;
      heap.push_back({d2, child});
      std::push_heap(heap.begin(), heap.end(), farther);
    }
  }
}

}  // namespace

uint64_t BlobView::closest_points(std::span<const Vec3> points, std::span<ClosestPoint> out, float max_distance) const {
  if (out.size() < points.size())
    throw UsageError("BlobView::closest_points: " + std::to_string(points.size()) + " points but room for " +
                     std::to_string(out.size()) + " answers; out must hold one a point");
  if (!(max_distance >= 0))
    throw UsageError("BlobView::closest_points: max_distance " + std::to_string(max_distance) +
                     " is not a distance (0 to infinity)");
  const layout::BlobHeader& h = layout::header_of(bytes_.data());
  if (h.tree_format != uint32_t(TreeFormat::OctTreeCompressed))
    throw UsageError("BlobView::closest_points: point queries walk OctTreeCompressed blobs (the recommended layout, "
                     "and the exact OctTreeCompressed/Float3SOA8); this blob is " + layout_name(layout()));
  uint64_t skipped = 0;
  std::vector<Pending> heap;
  heap.reserve(256);
  const double limit2 = double(max_distance) * double(max_distance);
  for (size_t i = 0; i < points.size(); ++i) {
    const double p[3] = {points[i].x, points[i].y, points[i].z};
    ClosestPoint& answer = out[i];
    answer = ClosestPoint{};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      ++skipped;
      continue;
    }
    Best best{limit2, {}, kNoHit};
    walk_point(bytes_.data(), h, p, best, heap);
    if (best.triangle == kNoHit) continue;
    answer.triangle = best.triangle;
    answer.distance = float(std::sqrt(best.d2));
    for (int k = 0; k < 3; ++k) answer.point[k] = float(best.near.point[k]);
    answer.u = float(best.near.u), answer.v = float(best.near.v);
  }
  return skipped;
}

}  // namespace meshcast
