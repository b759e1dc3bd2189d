// BlobView::closest_points: the point of the stored mesh nearest each query
// point, on an OctTreeCompressed blob. The tree is walked by the chosen
// instruction set's point walk (cpu/walk_points.h: 8 child boxes and 8
// triangle boxes at once, in float, nearest first), which hands each
// leaf's triangles whose boxes are near enough, nearest box first; here
// each one's nearest point is worked out in double from its stored corners
// (cpu/point_triangle.h), and the walk's cut narrows to the best distance.
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
#include <cfloat>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "cpu/point_order.h"
#include "cpu/point_triangle.h"
#include "cpu/walk_points.h"
#include "layout/blob_format.h"
#include "layout/tree/top_level.h"
#include "layout/tree/leaves.h"
#include "layout/tree/octtree.h"
#include "meshcast/blob.h"
#include "meshcast/scene.h"
#include "scene/snapshot.h"

namespace meshcast {

namespace {

// The top level's boxes (a scene's) are measured in double: a box's
// squared distance from the point is a lower bound for every triangle
// inside it, taken from the float bounds (each difference exact or rounded
// by 2^-53 of itself, then three products and two sums): it may come out
// at most 2^-50 of itself above the true one, so a box is dropped only
// where it is farther than the best distance by more than that.
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

// The squared distance from p to the box [lo, hi] (0 inside).
inline double box_d2(const double p[3], const float lo[3], const float hi[3]) {
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double below = double(lo[a]) - p[a], above = p[a] - double(hi[a]);
    const double d = below > 0 ? below : above > 0 ? above : 0;
    d2 += d * d;
  }
  return d2;
}

// Where a walk measures. The blob's own frame: distances as they are, the
// point a float already.
struct OwnFrame {
  static constexpr uint32_t index = 0;
  double p[3];  // the query point
  float pf[3];  // the same, as the float walk takes it
  // The walk's cut for a best squared distance d2.
  float cut(double d2) const { return cut_above(d2, 0); }
  // Where triangles' nearest points are found: the point, and the
  // triangles' corners there.
  const double* query() const { return p; }
  void place(const float (&v)[3][3], double (&w)[3][3]) const {
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) w[c][k] = v[c][k];
  }
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
  float pf[3];   // p rounded to float, for the walk
  double widen;  // at least |p - pf|
  double world[3];
  double to_world[9];
  double translation[3];
  double least_stretch2;  // 1 / (to_local's largest singular value)^2: no vector shrinks more under to_world
  void place(const double local[3]) {
    double gap2 = 0;
    for (int k = 0; k < 3; ++k) {
      p[k] = local[k], pf[k] = float(local[k]);
      gap2 += (p[k] - double(pf[k])) * (p[k] - double(pf[k]));
    }
    widen = std::sqrt(gap2) * (1 + 0x1p-40);
  }
  // A world distance d shrinks to no less than d sqrt(least_stretch2) in
  // the frame: the cut is d2 / least_stretch2 (less its rounding), from pf.
  float cut(double d2) const { return cut_above(d2 / least_stretch2 * (1 + 0x1p-50), widen); }
  const double* query() const { return world; }
  void place(const float (&v)[3][3], double (&w)[3][3]) const {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        w[c][r] = translation[r] + to_world[3 * r] * v[c][0] + to_world[3 * r + 1] * v[c][1] + to_world[3 * r + 2] * v[c][2];
  }
  PointOnTriangle nearest(const float (&v)[3][3]) const {
    double w[3][3];
    place(v, w);
    return nearest_on_triangle(world, w[0], w[1], w[2]);
  }
};

// A point's tests of one blob's triangles, as its walk hands them over
// (walk_points's visit): the frame they are measured in, whose triangles
// they are, the answer so far.
template <class Frame>
struct LeafTests {
  const uint8_t* blob;
  const layout::BlobHeader& h;
  const Frame& frame;
  uint32_t instance;
  Best& best;
  NearestOnTrianglesFn nearest;

  static float visit(void* context, uint32_t offset, const NearTriangles& near, float cut) {
    LeafTests& t = *static_cast<LeafTests*>(context);
    Best& best = t.best;
    // Nearest box first, 8 at a time: a group's nearest points are worked
    // out side by side, and the boxes of the next are measured against the
    // cut the group leaves (the nearest triangle is most often in the
    // first, and its distance drops the boxes behind it untested).
    constexpr uint32_t kGroup = 8;
    const auto box_of = [&near](uint32_t j) { return near.box_d2[near.entry(j)]; };
    for (uint32_t first = 0; first < near.n && box_of(first) <= cut; first += kGroup) {
      uint32_t n = 1;
      while (n < kGroup && first + n < near.n && box_of(first + n) <= cut) ++n;
      double corners[kGroup][3][3];
      for (uint32_t i = 0; i < n; ++i) t.frame.place(near.corners[near.entry(first + i)], corners[i]);
      PointOnTriangle found[kGroup];
      t.nearest(t.frame.query(), corners, n, found);
      for (uint32_t i = 0; i < n; ++i) {
        if (found[i].d2 > best.d2) continue;
        const uint32_t entry = near.entry(first + i);
        const uint32_t triangle = layout::remap_entry(t.blob, t.h, layout::slot_of(t.h, offset, near.index[entry]));
        // At one distance the lower instance, then the lower triangle
        // number, whatever the walk's order.
        if (found[i].d2 == best.d2 && best.triangle != kNoHit &&
            (t.instance > best.instance || (t.instance == best.instance && triangle > best.triangle)))
          continue;
        best.d2 = found[i].d2, best.near = found[i], best.triangle = triangle, best.instance = t.instance;
        best.frame = t.frame.index;
        std::memcpy(best.corners, near.corners[entry], sizeof best.corners);
        cut = t.frame.cut(best.d2);
      }
    }
    return cut;
  }
};

// The walk of a point starts from `last`, the previous point's answer,
// where that triangle (`near`: its nearest point to this one) lies within
// the limit.
void start_from(const Best& last, const PointOnTriangle& near, Best& best) {
  if (near.d2 > best.d2) return;
  best = last;
  best.d2 = near.d2, best.near = near;
}

// The walk of one blob for a point in `frame`, from the answer so far.
template <class Frame>
void walk_point(const uint8_t* blob, const Frame& frame, uint32_t instance, Best& best) {
  static const WalkPointsFn walk = walk_points_fn();
  static const NearestOnTrianglesFn nearest = nearest_on_triangles_fn();
  LeafTests<Frame> tests{blob, layout::header_of(blob), frame, instance, best, nearest};
  walk(blob, frame.pf, frame.cut(best.d2), &LeafTests<Frame>::visit, &tests);
}

// A top-level box waiting to be walked, and its squared distance.
struct Pending {
  double d2;
  uint32_t properties;
};

}  // namespace

float cut_above(double limit2, double widen) {
  if (!(limit2 < INFINITY)) return INFINITY;
  double r2 = limit2;
  if (widen > 0) {
    const double r = std::sqrt(limit2) + widen;
    r2 = r * r * (1 + 0x1p-50);  // the root, the sum and the square: 2^-53 of themselves each
  }
  const double grown = r2 * (1 + 0x1p-20) + 0x1p-140;
  if (!(grown <= FLT_MAX)) return INFINITY;
  const float cut = float(grown);
  return double(cut) < grown ? std::nextafter(cut, INFINITY) : cut;
}

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
    const OwnFrame frame{{p[0], p[1], p[2]}, {points[i].x, points[i].y, points[i].z}};
    Best best{limit2, {}, kNoHit};
    if (last.triangle != kNoHit) start_from(last, frame.nearest(last.corners), best);
    walk_point(bytes_.data(), frame, 0, best);
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
  std::vector<Pending> top_heap;
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
        double d[3], local[3];
        for (int k = 0; k < 3; ++k) d[k] = w[k] - f.translation[k], f.world[k] = w[k];
        for (int r = 0; r < 3; ++r)
          local[r] = placed.to_local[3 * r] * d[0] + placed.to_local[3 * r + 1] * d[1] + placed.to_local[3 * r + 2] * d[2];
        f.place(local);
        walk_point(snapshot.meshes[placed.mesh]->bytes.data(), f, placed.id, best);
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
