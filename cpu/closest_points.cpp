// BlobView::closest_points: the point of the stored mesh nearest each query
// point, on an OctTreeCompressed blob. The walk is best first: a node's 8
// child boxes are decoded (exactly, as the ray walk decodes them) and their
// squared distances from the point taken, the children no farther than the
// best distance so far wait in a heap, and the nearest waiting box is
// walked next; the walk ends when it is farther than the best. In a leaf
// each triangle's nearest point is worked out in double from its stored
// corners (cpu/point_triangle.h), after a test of its corners' box.
//
// The points are walked along a Morton curve (cpu/point_order.h), each
// starting from its predecessor's nearest triangle: that triangle's
// distance bounds the point's own from the start, so the walk drops at
// once the boxes a walk from nothing would first have to visit to learn
// it. The answer is the same: every box as near as the best is still
// walked, and ties still go to the lower number.
//
// Scene::closest_points walks the same way through the scene's top level
// (the instances' world boxes) and, for each instance near enough, its
// blob in the instance's frame: the boxes' distances there scaled down to
// a bound on the world's, each triangle's corners placed in the world and
// its nearest point found there, so a scaled instance answers its world
// distance.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cpu/point_order.h"
#include "cpu/point_triangle.h"
#include "layout/blob_format.h"
#include "layout/tree/top_level.h"
#include "layout/tree/leaves.h"
#include "layout/tree/octtree.h"
#include "meshcast/blob.h"
#include "meshcast/scene.h"
#include "scene/snapshot.h"

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
  uint32_t instance = 0;  // a scene's instance id (a blob's walk: 0)
  // The triangle's corners as stored, and the frame they were measured in
  // (a scene's placed instance; a blob's walk: 0): the next point's start.
  float corners[3][3] = {};
  uint32_t frame = 0;
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

// Where a walk measures. The blob's own frame: distances as they are.
struct OwnFrame {
  static constexpr uint32_t index = 0;
  double p[3];  // the query point
  // A lower bound on the distance squared from a local box's squared one.
  double bound(double local_d2) const { return local_d2; }
  PointOnTriangle nearest(const float (&v)[3][3]) const { return nearest_on_triangle(p, v[0], v[1], v[2]); }
};

// An instance's frame: the point taken into it (p) for the boxes, whose
// distances shrink by at most the transform's least stretch, and the
// triangles placed in the world (to_world: the inverse of the instance's
// float to_local, in double, as the walk of a ray sees it) for their
// distances from the world point.
struct InstanceFrame {
  uint32_t index;  // the placed instance's
  double p[3];
  double world[3];
  double to_world[9];
  double translation[3];
  double least_stretch2;  // 1 / (to_local's largest singular value)^2: no vector shrinks more under to_world
  double bound(double local_d2) const { return local_d2 * least_stretch2; }
  PointOnTriangle nearest(const float (&v)[3][3]) const {
    double w[3][3];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        w[c][r] = translation[r] + to_world[3 * r] * v[c][0] + to_world[3 * r + 1] * v[c][1] + to_world[3 * r + 2] * v[c][2];
    return nearest_on_triangle(world, w[0], w[1], w[2]);
  }
};

template <class Frame>
void test_leaf(const uint8_t* blob, const layout::BlobHeader& h, uint32_t offset, uint32_t count, const Frame& frame,
               uint32_t instance, Best& best) {
  float corners[MC_OCT_MAX_COUNT][3][3];
  layout::decode_leaf(blob, h.tree_offset + offset, count, corners);
  // The triangles whose corner box is near enough, nearest box first: the
  // nearest triangle is then most often tested first, and its distance
  // drops the boxes behind it untested.
  double box[MC_OCT_MAX_COUNT];
  uint32_t order[MC_OCT_MAX_COUNT], near_enough = 0;
  for (uint32_t i = 0; i < count; ++i) {
    const float(&v)[3][3] = corners[i];
    float lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min({v[0][a], v[1][a], v[2][a]});
      hi[a] = std::max({v[0][a], v[1][a], v[2][a]});
    }
    const double d2 = frame.bound(box_d2(frame.p, lo, hi)) * kBoxSlack;
    if (d2 > best.d2) continue;
    uint32_t j = near_enough++;
    for (; j > 0 && box[j - 1] > d2; --j) box[j] = box[j - 1], order[j] = order[j - 1];
    box[j] = d2, order[j] = i;
  }
  for (uint32_t j = 0; j < near_enough && box[j] <= best.d2; ++j) {
    const uint32_t i = order[j];
    const float(&v)[3][3] = corners[i];
    const PointOnTriangle near = frame.nearest(v);
    if (near.d2 > best.d2) continue;
    const uint32_t triangle = layout::remap_entry(blob, h, layout::slot_of(h, offset, i));
    // At one distance the lower instance, then the lower triangle number,
    // whatever the walk's order.
    if (near.d2 == best.d2 && best.triangle != kNoHit &&
        (instance > best.instance || (instance == best.instance && triangle > best.triangle)))
      continue;
    best.d2 = near.d2, best.near = near, best.triangle = triangle, best.instance = instance, best.frame = frame.index;
    std::memcpy(best.corners, v, sizeof best.corners);
  }
}

// The walk of a point starts from `last`, the previous point's answer,
// where that triangle (`near`: its nearest point to this one) lies within
// the limit.
void start_from(const Best& last, const PointOnTriangle& near, Best& best) {
  if (near.d2 > best.d2) return;
  best = last;
  best.d2 = near.d2, best.near = near;
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
template <class Frame>
void walk_point(const uint8_t* blob, const layout::BlobHeader& h, const Frame& frame, uint32_t instance, Best& best,
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
      test_leaf(blob, h, offset, count, frame, instance, best);
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
      const double d2 = frame.bound(box_d2(frame.p, lo, hi));
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
                     "and the exact OctTreeCompressed/ClusterFloat3SOA8); this blob is " + layout_name(layout()));
  uint64_t skipped = 0;
  std::vector<Pending> heap;
  heap.reserve(256);
  const double limit2 = double(max_distance) * double(max_distance);
  Best last{limit2, {}, kNoHit};
  for (const size_t i : morton_order(points.size(), [&](size_t j, int k) { return double(points[j][k]); })) {
    const double p[3] = {points[i].x, points[i].y, points[i].z};
    ClosestPoint& answer = out[i];
    answer = ClosestPoint{};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      ++skipped;
      continue;
    }
    const OwnFrame frame{{p[0], p[1], p[2]}};
    Best best{limit2, {}, kNoHit};
    if (last.triangle != kNoHit) start_from(last, frame.nearest(last.corners), best);
    walk_point(bytes_.data(), h, frame, 0, best, heap);
    last = best;
    if (best.triangle == kNoHit) continue;
    answer.triangle = best.triangle;
    answer.distance = float(std::sqrt(best.d2));
    for (int k = 0; k < 3; ++k) answer.point[k] = float(best.near.point[k]);
    answer.u = float(best.near.u), answer.v = float(best.near.v);
  }
  return skipped;
}

namespace {

// The largest eigenvalue of a symmetric 3x3 (row-major), by the
// trigonometric solution of its characteristic cubic.
double largest_eigenvalue(const double b[9]) {
  const double off = b[1] * b[1] + b[2] * b[2] + b[5] * b[5];
  if (off == 0) return std::max({b[0], b[4], b[8]});
  const double q = (b[0] + b[4] + b[8]) / 3;
  const double p = std::sqrt(((b[0] - q) * (b[0] - q) + (b[4] - q) * (b[4] - q) + (b[8] - q) * (b[8] - q) + 2 * off) / 6);
  double c[9];
  for (int i = 0; i < 9; ++i) c[i] = (b[i] - (i % 4 == 0 ? q : 0)) / p;
  const double det = c[0] * (c[4] * c[8] - c[5] * c[7]) - c[1] * (c[3] * c[8] - c[5] * c[6]) +
                     c[2] * (c[3] * c[7] - c[4] * c[6]);
  const double r = std::clamp(det / 2, -1.0, 1.0);
  return q + 2 * p * std::cos(std::acos(r) / 3);
}

// The double inverse of a float 3x3 (row-major), by its adjugate.
void inverse(const float m[9], double out[9]) {
  const double a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5], g = m[6], k = m[7], l = m[8];
  const double det = a * (e * l - f * k) - b * (d * l - f * g) + c * (d * k - e * g);
  const double cof[9] = {e * l - f * k, c * k - b * l, b * f - c * e, f * g - d * l, a * l - c * g,
                         c * d - a * f, d * k - e * g, b * g - a * k, a * e - b * d};
  for (int i = 0; i < 9; ++i) out[i] = cof[i] / det;
}

}  // namespace

uint64_t closest_points_snapshot(const SceneSnapshot& snapshot, std::span<const std::array<double, 3>> points,
                                 std::span<SceneClosestPoint> out, double max_distance, uint8_t mask) {
  if (out.size() < points.size())
    throw UsageError("Scene::closest_points: " + std::to_string(points.size()) + " points but room for " +
                     std::to_string(out.size()) + " answers; out must hold one a point");
  if (!(max_distance >= 0))
    throw UsageError("Scene::closest_points: max_distance " + std::to_string(max_distance) +
                     " is not a distance (0 to infinity)");
  const layout::TopLevel& top = snapshot.top;
  for (const auto& mesh : snapshot.meshes) {
    const layout::BlobHeader& h = layout::header_of(mesh->bytes.data());
    if (h.tree_format != uint32_t(TreeFormat::OctTreeCompressed))
      throw UsageError("Scene::closest_points: point queries walk OctTreeCompressed blobs (the recommended layout, "
                       "and the exact OctTreeCompressed/ClusterFloat3SOA8); mesh " + mesh->name + " is " +
                       layout_name(mesh->view.layout()));
  }
  // Each placed instance's frame, the point aside.
  std::vector<InstanceFrame> frames(top.placed.size());
  for (size_t i = 0; i < top.placed.size(); ++i) {
    const layout::PlacedInstance& placed = top.placed[i];
    InstanceFrame& f = frames[i];
    f.index = uint32_t(i);
    inverse(placed.to_local, f.to_world);
    // |to_local x| <= s |x| with s^2 the largest eigenvalue of
    // to_local^T to_local, so |to_world y| >= |y| / s; less a millionth for
    // the rounding of the eigenvalue's solution (2^-40 of it at most here).
    double gram[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        gram[3 * r + c] = 0;
        for (int k = 0; k < 3; ++k) gram[3 * r + c] += double(placed.to_local[3 * k + r]) * placed.to_local[3 * k + c];
      }
    f.least_stretch2 = (1 - 1e-6) / largest_eigenvalue(gram);
    for (int k = 0; k < 3; ++k) f.translation[k] = placed.translation[k];
  }
  uint64_t skipped = 0;
  std::vector<Pending> top_heap, heap;
  const double limit2 = max_distance * max_distance;
  const auto farther = [](const Pending& x, const Pending& y) { return x.d2 > y.d2; };
  Best last{limit2, {}, kNoHit};
  for (const size_t i : morton_order(points.size(), [&](size_t j, int k) { return points[j][k]; })) {
    const double* w = points[i].data();
    SceneClosestPoint& answer = out[i];
    answer = SceneClosestPoint{};
    if (!std::isfinite(w[0]) || !std::isfinite(w[1]) || !std::isfinite(w[2])) {
      ++skipped;
      continue;
    }
    Best best{limit2, {}, kNoHit};
    if (last.triangle != kNoHit) {
      InstanceFrame& f = frames[last.frame];
      for (int k = 0; k < 3; ++k) f.world[k] = w[k];
      start_from(last, f.nearest(last.corners), best);
    }
    // Best first over the top level's boxes (float, about the anchor,
    // rounded outward), then each instance's blob as it comes up.
    top_heap.clear();
    if (!top.wide.empty()) top_heap.push_back({0, 0});
    const double from_anchor[3] = {w[0] - top.anchor[0], w[1] - top.anchor[1], w[2] - top.anchor[2]};
    while (!top_heap.empty()) {
      std::pop_heap(top_heap.begin(), top_heap.end(), farther);
      const Pending next = top_heap.back();
      top_heap.pop_back();
      if (next.d2 * kBoxSlack > best.d2) break;
      if (next.properties & layout::kTopInstance) {
        const uint32_t index = next.properties & ~layout::kTopInstance;
        const layout::PlacedInstance& placed = top.placed[index];
        if (!(placed.mask & mask)) continue;
        InstanceFrame& f = frames[index];
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = w[k] - f.translation[k], f.world[k] = w[k];
        for (int r = 0; r < 3; ++r)
          f.p[r] = placed.to_local[3 * r] * d[0] + placed.to_local[3 * r + 1] * d[1] + placed.to_local[3 * r + 2] * d[2];
        const uint8_t* blob = snapshot.meshes[placed.mesh]->bytes.data();
        walk_point(blob, layout::header_of(blob), f, placed.id, best, heap);
        continue;
      }
      const layout::TopWideNode& node = top.wide[next.properties];
      for (int k = 0; k < layout::kTopWidth; ++k) {
        const uint32_t slot = node.slot[k];
        if (slot == layout::kTopEmpty) continue;
        const float lo[3] = {node.lo[0][k], node.lo[1][k], node.lo[2][k]};
        const float hi[3] = {node.hi[0][k], node.hi[1][k], node.hi[2][k]};
        const double d2 = box_d2(from_anchor, lo, hi);
        if (d2 * kBoxSlack > best.d2) continue;
        top_heap.push_back({d2, slot});
        std::push_heap(top_heap.begin(), top_heap.end(), farther);
      }
    }
    last = best;
    if (best.triangle == kNoHit) continue;
    answer.instance = best.instance;
    answer.triangle = best.triangle;
    answer.distance = std::sqrt(best.d2);
    for (int k = 0; k < 3; ++k) answer.point[k] = best.near.point[k];
    answer.u = float(best.near.u), answer.v = float(best.near.v);
  }
  return skipped;
}

uint64_t Scene::closest_points(std::span<const std::array<double, 3>> points, std::span<SceneClosestPoint> out,
                               double max_distance, uint8_t mask) const {
  return closest_points_snapshot(*snapshot(), points, out, max_distance, mask);
}

}  // namespace meshcast
