#include "cpu/crossings.h"

#include <algorithm>
#include <array>
#include <optional>
#include <string>

#include "layout/blob_format.h"
#include "layout/tree/leaves.h"

namespace meshcast {

Corners TriangleCorners::corners(uint32_t triangle) const {
  const uint8_t* blob = blob_.data();
  const layout::BlobHeader& h = layout::header_of(blob);
  std::call_once(made_, [&] {
    // Without a remap, a triangle's id is its slot (holes included).
    leaf_of_.assign(layout::has_remap(h) ? h.triangle_count : h.remap_slots, 0);
    layout::for_each_leaf(blob, [&](uint32_t block, uint32_t count) {
      for (uint32_t i = 0; i < count; ++i)
        leaf_of_[layout::remap_entry(blob, h, layout::slot_of(h, block, i))] = uint64_t(block) << 8 | i;
    });
    table_bytes_.store(leaf_of_.capacity() * sizeof(uint64_t), std::memory_order_release);
  });
  float v[3][3];
  const uint64_t at = leaf_of_[triangle];
  layout::decode_triangle(blob, h.tree_offset + uint32_t(at >> 8), uint32_t(at & 0xFF), v);
  Corners out;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) out.c[c][k] = v[c][k];
  return out;
}

namespace {

using Vec = std::array<double, 3>;
Vec minus(const double a[3], const double b[3]) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
int sign(double x) { return (x > 0) - (x < 0); }
bool same_point(const double a[3], const double b[3]) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

}  // namespace

void crossing_triangles(std::span<const Corners> corners, const float dir[3], std::vector<bool>& keep) {
  const Vec d{dir[0], dir[1], dir[2]};
  // The step: a fixed direction of no special relation to a mesh's axes,
  // less its part along the ray; a second one, across both, settles an
  // edge that lies along the first (seen down the ray).
  const double dd = dot(d, d);
  Vec step{0.2718281828459045, 0.5772156649015329, 0.8414709848078965};
  if (std::fabs(dot(step, d)) > 0.9 * std::sqrt(dot(step, step) * dd)) step = {0.8414709848078965, -0.2718281828459045, 0.5772156649015329};
  const double along = dot(step, d) / dd;
  for (int k = 0; k < 3; ++k) step[k] -= along * d[k];
  const Vec second = cross(d, step);
  keep.assign(corners.size(), true);
  for (size_t t = 0; t < corners.size(); ++t) {
    const auto& c = corners[t].c;
    for (int e = 0; e < 3 && keep[t]; ++e) {
      const double* a = c[e];
      const double* b = c[(e + 1) % 3];
      const double* opposite = c[(e + 2) % 3];
      // Only an edge another triangle of the group shares is one the ray
      // meets exactly: the walker put the point on it, and the step
      // decides which side. Every other edge holds the point inside.
      bool shared = false;
      for (size_t o = 0; o < corners.size() && !shared; ++o)
        for (int f = 0; f < 3 && o != t && !shared; ++f) {
          const double* p = corners[o].c[f];
          const double* q = corners[o].c[(f + 1) % 3];
          shared = (same_point(a, p) && same_point(b, q)) || (same_point(a, q) && same_point(b, p));
        }
      if (!shared) continue;
      // Seen down the ray: the side of the edge its triangle lies on, and
      // the side the step goes to (both signs flip with the edge's
      // direction, so the winding cannot change the answer).
      const Vec edge = minus(b, a);
      const int side = sign(dot(cross(edge, minus(opposite, a)), d));
      int stepped = sign(dot(cross(edge, step), d));
      if (stepped == 0) stepped = sign(dot(cross(edge, second), d));
      keep[t] = side != 0 && stepped == side;
    }
  }
}

uint64_t count_crossings(const BlobView& view, std::span<const Ray> rays, std::span<uint32_t> counts,
                         const TriangleCorners* given) {
  if (counts.size() < rays.size())
    throw UsageError("count_crossings: " + std::to_string(rays.size()) + " rays but room for " +
                     std::to_string(counts.size()) + " counts");
  std::optional<TriangleCorners> own;
  if (!given) own.emplace(view.bytes());
  const TriangleCorners& corners = given ? *given : *own;
  const auto corners_of = [&corners](uint32_t) -> const TriangleCorners& { return corners; };
  HitLists lists;
  lists.max_hits = kMaxHitsLimit;
  uint64_t skipped = 0;
  // A few rays at a time: every-hit rows take memory as the hits come.
  constexpr size_t kPiece = 256;
  for (size_t begin = 0; begin < rays.size(); begin += kPiece) {
    const size_t n = std::min(kPiece, rays.size() - begin);
    skipped += view.trace_all_hits(rays.subspan(begin, n), lists);
    for (size_t i = 0; i < n; ++i) {
      const auto row = lists.row(i);
      uint64_t count = lists.found[i] - row.size();
      crossings(row, rays[begin + i].dir, corners_of, [&count](const Hit&) { ++count; });
      counts[begin + i] = uint32_t(std::min<uint64_t>(count, UINT32_MAX));
    }
  }
  return skipped;
}

}  // namespace meshcast
