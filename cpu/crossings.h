// How the crossings of a ray with a mesh are counted (the Python
// package's count_intersections and list_intersections, the signed
// distances' inside test): a crossing of a surface counts once, whether
// the ray passes through a triangle's inside, a shared edge or a vertex,
// and whichever way the triangles are wound.
//
// Where a ray meets a mesh exactly on an edge or a vertex, the watertight
// test reports every triangle there (its edge function is exactly 0 for
// each), each at its own t, equal but for rounding. Those hits of one
// geometry within 2^-20 of each other's t make a group, and the group
// counts the triangles that a ray moved off the point by an infinitely
// small step, in a fixed direction across the ray, would pass through
// inside: through an edge, the one of its two triangles on the step's
// side; through a vertex, the triangles whose corner there holds the step
// (simulation of simplicity). That count is what a ray in general position
// counts: odd where the ray crosses a closed mesh, even (0 or 2) where it
// only touches it (a silhouette edge, a saddle it grazes), whatever the
// winding, so parity tells inside from outside on any closed mesh. It is
// decided from the triangles' corners as the walker decoded them, never
// from their facing.
#pragma once
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include "meshcast/blob.h"
#include "meshcast/ray.h"
#include "meshcast/scene.h"

namespace meshcast {

// A triangle's corners, in double.
struct Corners {
  double c[3][3];
};

// The corners of a geometry's triangles, as its blob's walker decodes them,
// by the caller's triangle id. The table from an id to its leaf (8 bytes a
// triangle) is made on first need: only rays through edges and vertices
// need it.
class TriangleCorners {
 public:
  explicit TriangleCorners(std::span<const uint8_t> blob) : blob_(blob) {}
  Corners corners(uint32_t triangle) const;
  size_t nbytes() const { return table_bytes_.load(std::memory_order_acquire); }  // of the table, once made

 private:
  std::span<const uint8_t> blob_;
  mutable std::once_flag made_;
  mutable std::vector<uint64_t> leaf_of_;  // the leaf block's offset << 8 | the triangle's lane
  mutable std::atomic<size_t> table_bytes_{0};  // read by nbytes() while another thread may be making the table
};

// The geometry of a hit: a scene's instance, or 0 for one geometry's blob
// walked alone.
inline uint32_t geometry_of(const SceneHit& h) { return h.instance; }
inline uint32_t geometry_of(const Hit& h) { return h.triangle == kNoHit ? kNoHit : 0; }

// Of the triangles of one group, each with its corners, which the ray
// stepped off the point passes through: keep[k] for each.
void crossing_triangles(std::span<const Corners> corners, const float dir[3], std::vector<bool>& keep);

// Calls keep(hit) for each crossing of a ray's hits (nearest first, as
// trace_all_hits rows them), each by one triangle. corners_of(geometry):
// that geometry's TriangleCorners.
template <class Record, class CornersOf, class Keep>
void crossings(std::span<const Record> row, const float dir[3], const CornersOf& corners_of, const Keep& keep) {
  static thread_local std::vector<Corners> corners;
  static thread_local std::vector<bool> inside;
  static thread_local std::vector<size_t> members;
  static thread_local std::vector<bool> kept, done;
  for (size_t g = 0; g < row.size();) {
    // The window of hits within 2^-20 of the first's t, of any geometry:
    // each geometry's t carries its own frame's rounding, so two meeting
    // at a point may sort interleaved (t, then instance).
    const float t0 = row[g].t;
    const float tol = std::ldexp(std::fabs(t0), -20);
    size_t end = g + 1;  // the first hit always, so a window ends even on a NaN t
    while (end < row.size() && row[end].t - t0 <= tol) ++end;
    if (end - g == 1) {
      keep(row[g]);
      g = end;
      continue;
    }
    kept.assign(end - g, false);
    done.assign(end - g, false);
    for (size_t first = g; first < end; ++first) {  // each geometry's group of the window
      if (done[first - g]) continue;
      const uint32_t geometry = geometry_of(row[first]);
      members.clear();
      for (size_t k = first; k < end; ++k)
        if (!done[k - g] && geometry_of(row[k]) == geometry) members.push_back(k), done[k - g] = true;
      if (members.size() == 1) {
        kept[first - g] = true;
        continue;
      }
      corners.resize(members.size());
      const TriangleCorners& of = corners_of(geometry);
      for (size_t m = 0; m < members.size(); ++m) corners[m] = of.corners(row[members[m]].triangle);
      crossing_triangles(corners, dir, inside);
      for (size_t m = 0; m < members.size(); ++m) kept[members[m] - g] = inside[m];
    }
    for (size_t k = g; k < end; ++k)
      if (kept[k - g]) keep(row[k]);
    g = end;
  }
}

// The crossings of each ray with the blob's mesh along [tmin, tmax], counted
// as above: every hit found (Query::All, rows of kMaxHitsLimit; hits beyond
// a row counted one each), through a shared edge or vertex once. Parity
// tells inside from outside of a closed mesh. Returns the rays not walkable
// (counted 0). counts must hold one a ray.
// `corners`: the blob's TriangleCorners, made once by a caller that counts
// batch after batch (its table is made on first need: a whole-mesh pass);
// null: one made for this call.
uint64_t count_crossings(const BlobView& view, std::span<const Ray> rays, std::span<uint32_t> counts,
                         const TriangleCorners* corners = nullptr);

}  // namespace meshcast
