// WindingNumbers: the generalized winding number on an OctTreeCompressed
// blob's tree (meshcast/winding_number.h says what and why). The tree's
// children become clusters, their moments summed up from the leaves'
// triangles in double; a query walks down from the whole mesh, expanding
// the clusters far enough from the point and summing the near leaves'
// triangles' solid angles.
#include "meshcast/winding_number.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "layout/blob_format.h"
#include "layout/tree/leaves.h"
#include "layout/tree/octtree.h"
#include "meshcast/errors.h"

namespace meshcast {

namespace {

constexpr double kFourPi = 4 * std::numbers::pi;

double length(const double v[3]) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// The signed solid angle of triangle a b c seen from the origin (the
// corners taken relative to the point), Van Oosterom and Strackee's
// formula: positive where the normal (b - a) x (c - a) points away from
// the origin (the corners run clockwise seen from it).
double solid_angle(const double a[3], const double b[3], const double c[3]) {
  const double la = length(a), lb = length(b), lc = length(c);
  const double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]};
  const double det = a[0] * bc[0] + a[1] * bc[1] + a[2] * bc[2];
  const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const double bcd = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
  const double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
  return 2 * std::atan2(det, la * lb * lc + ab * lc + bcd * la + ca * lb);
}

// The expansion's rule for a tolerance: gap >= radius * sqrt(3 / tolerance).
double ratio_for(double tolerance) {
  if (!(tolerance > 0 && tolerance < 1))
    throw UsageError("WindingNumbers: tolerance " + std::to_string(tolerance) + " is not in (0, 1)");
  return std::sqrt(3 / tolerance);
}

}  // namespace

WindingNumbers::WindingNumbers(const BlobView& view) : blob_(view.bytes()) {
  const layout::BlobHeader& h = layout::header_of(blob_.data());
  if (h.tree_format != uint32_t(TreeFormat::OctTreeCompressed))
    throw UsageError("WindingNumbers: winding numbers walk OctTreeCompressed blobs (the recommended layout, and the "
                     "exact OctTreeCompressed/ClusterFloat3SOA8); this blob is " + layout_name(view.layout()));
  clusters_.resize(1);
  fill(0, h.root);
  clusters_.shrink_to_fit();
}

void WindingNumbers::fill(uint32_t index, uint32_t properties) {
  const layout::BlobHeader& h = layout::header_of(blob_.data());
  const uint32_t count = layout::oct_count(properties), offset = layout::oct_offset(properties);
  Cluster cluster{};
  if (count > 0) {
    // A leaf: each triangle's area, vector area and centroid from its
    // stored corners.
    float corners[MC_OCT_MAX_COUNT][3][3];
    layout::decode_leaf(blob_.data(), h.tree_offset + offset, count, corners);
    double vector_area[MC_OCT_MAX_COUNT][3], centroid[MC_OCT_MAX_COUNT][3], weighted[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
    for (uint32_t t = 0; t < count; ++t) {
      const float(&v)[3][3] = corners[t];
      double e1[3], e2[3];
      for (int k = 0; k < 3; ++k) {
        e1[k] = double(v[1][k]) - v[0][k], e2[k] = double(v[2][k]) - v[0][k];
        centroid[t][k] = (double(v[0][k]) + v[1][k] + v[2][k]) / 3;
        mean[k] += centroid[t][k] / count;
      }
      vector_area[t][0] = 0.5 * (e1[1] * e2[2] - e1[2] * e2[1]);
      vector_area[t][1] = 0.5 * (e1[2] * e2[0] - e1[0] * e2[2]);
      vector_area[t][2] = 0.5 * (e1[0] * e2[1] - e1[1] * e2[0]);
      const double area = length(vector_area[t]);
      cluster.area += area;
      for (int k = 0; k < 3; ++k) weighted[k] += area * centroid[t][k], cluster.n[k] += vector_area[t][k];
    }
    for (int k = 0; k < 3; ++k) cluster.c[k] = cluster.area > 0 ? weighted[k] / cluster.area : mean[k];
    for (uint32_t t = 0; t < count; ++t) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) cluster.m[3 * i + j] += vector_area[t][i] * (centroid[t][j] - cluster.c[j]);
      for (int corner = 0; corner < 3; ++corner) {
        const double d[3] = {corners[t][corner][0] - cluster.c[0], corners[t][corner][1] - cluster.c[1],
                             corners[t][corner][2] - cluster.c[2]};
        cluster.r = std::max(cluster.r, length(d));
      }
    }
    cluster.leaf_block = h.tree_offset + offset;
    cluster.leaf_count = count;
  } else {
    // A node: its children first (consecutive), then their sums.
    const uint8_t* node = blob_.data() + h.tree_offset + offset;
    uint32_t children[8], n = 0;
    for (int k = 0; k < 8; ++k)
      if (const uint32_t child = layout::oct_child_properties(node, k)) children[n++] = child;
    const uint32_t first = uint32_t(clusters_.size());
    clusters_.resize(first + n);
    for (uint32_t k = 0; k < n; ++k) fill(first + k, children[k]);  // clusters_ may move: indices only
    double weighted[3] = {0, 0, 0}, mean[3] = {0, 0, 0};
    for (uint32_t k = 0; k < n; ++k) {
      const Cluster& child = clusters_[first + k];
      cluster.area += child.area;
      for (int a = 0; a < 3; ++a) {
        weighted[a] += child.area * child.c[a], mean[a] += child.c[a] / n;
        cluster.n[a] += child.n[a];
      }
    }
    for (int a = 0; a < 3; ++a) cluster.c[a] = cluster.area > 0 ? weighted[a] / cluster.area : mean[a];
    for (uint32_t k = 0; k < n; ++k) {
      const Cluster& child = clusters_[first + k];
      // A child's first moment moved to this centre: m + N (c_child - c)^T.
      for (int i = 0; i < 9; ++i) cluster.m[i] += child.m[i];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) cluster.m[3 * i + j] += child.n[i] * (child.c[j] - cluster.c[j]);
      const double d[3] = {child.c[0] - cluster.c[0], child.c[1] - cluster.c[1], child.c[2] - cluster.c[2]};
      cluster.r = std::max(cluster.r, length(d) + child.r);
    }
    cluster.first_child = first;
    cluster.child_count = n;
  }
  // Room for double's rounding of the radius (the bound's one input that
  // must not come out small).
  cluster.r *= 1 + 0x1p-40;
  clusters_[index] = cluster;
}

double WindingNumbers::leaf_sum(const Cluster& leaf, const double p[3]) const {
  float corners[MC_OCT_MAX_COUNT][3][3];
  layout::decode_leaf(blob_.data(), leaf.leaf_block, leaf.leaf_count, corners);
  double sum = 0;
  for (uint32_t t = 0; t < leaf.leaf_count; ++t) {
    double v[3][3];
    for (int corner = 0; corner < 3; ++corner)
      for (int k = 0; k < 3; ++k) v[corner][k] = double(corners[t][corner][k]) - p[k];
    sum += solid_angle(v[0], v[1], v[2]);
  }
  return sum;
}

WindingNumbers::Answer WindingNumbers::walk(const double p[3], double ratio) const {
  Answer answer;
  double angles = 0;  // the near leaves' solid angles; the expansions go into answer.w as winding numbers
  uint32_t stack[8 * 64];
  uint32_t size = 0;
  stack[size++] = 0;
  while (size > 0) {
    const Cluster& cluster = clusters_[stack[--size]];
    const double v[3] = {cluster.c[0] - p[0], cluster.c[1] - p[1], cluster.c[2] - p[2]};
    const double s = length(v), gap = s - cluster.r;
    if (gap > cluster.r * ratio) {
      // g(c) = v / s^3 and its derivative I / s^3 - 3 v v^T / s^5,
      // against N and M (the header's second order expansion).
      const double s3 = s * s * s, s5 = s3 * s * s;
      const double first = (cluster.n[0] * v[0] + cluster.n[1] * v[1] + cluster.n[2] * v[2]) / s3;
      double vmv = 0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) vmv += v[i] * cluster.m[3 * i + j] * v[j];
      const double second = (cluster.m[0] + cluster.m[4] + cluster.m[8]) / s3 - 3 * vmv / s5;
      answer.w += (first + second) / kFourPi;
      const double gap2 = gap * gap;
      answer.bound += 3 * cluster.area * cluster.r * cluster.r / (kFourPi * gap2 * gap2);
    } else if (cluster.leaf_count > 0) {
      angles += leaf_sum(cluster, p);
    } else {
      // The stack holds at most 7 siblings a level below the path: 8 a
      // level of a tree at most 64 deep (the format's limit is far less).
      for (uint32_t k = 0; k < cluster.child_count; ++k) stack[size++] = cluster.first_child + k;
    }
  }
  answer.w += angles / kFourPi;
  return answer;
}

void WindingNumbers::evaluate(std::span<const Vec3> points, std::span<Answer> out, double tolerance) const {
  const double ratio = ratio_for(tolerance);
  if (out.size() < points.size())
    throw UsageError("WindingNumbers::evaluate: " + std::to_string(points.size()) + " points but room for " +
                     std::to_string(out.size()) + " answers");
  for (size_t i = 0; i < points.size(); ++i) {
    const double p[3] = {points[i].x, points[i].y, points[i].z};
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      out[i] = {NAN, NAN};
      continue;
    }
    out[i] = walk(p, ratio);
  }
}

double WindingNumbers::exact(const Vec3& point) const {
  const double p[3] = {point.x, point.y, point.z};
  return walk(p, INFINITY).w;
}

void WindingNumbers::inside(std::span<const Vec3> points, std::span<uint8_t> out) const {
  if (out.size() < points.size())
    throw UsageError("WindingNumbers::inside: " + std::to_string(points.size()) + " points but room for " +
                     std::to_string(out.size()) + " answers");
  for (size_t i = 0; i < points.size(); ++i) {
    const double p[3] = {points[i].x, points[i].y, points[i].z};
    // Loose, then tight, then every triangle: each step only where the
    // last left |w| within its bound of 1/2.
    static const double ratios[] = {ratio_for(kInsideTolerances[0]), ratio_for(kInsideTolerances[1]), INFINITY};
    Answer a;
    for (const double ratio : ratios) {
      a = walk(p, ratio);
      if (std::fabs(std::fabs(a.w) - 0.5) > a.bound) break;
    }
    out[i] = std::fabs(a.w) > 0.5;
  }
}

}  // namespace meshcast
