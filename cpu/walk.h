// Walkers: one per tree family, instantiated per triangle codec. A
// BlobView (include/meshcast/blob.h) and a scene's mesh (scene/snapshot.h) pick
// the instantiation from the blob header once (walker_for, cpu/walk_table.h).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "cpu/leaf.h"
#include "layout/catalog.h"

namespace meshcast {

// What a batch asks of a walker: `flags`, the MC_HIT_* outputs, the
// MC_QUERY_* query and the MC_CULL_* culling; for Query::All (MC_QUERY_ALL)
// where the hits go: found[i], and row i of `lists`, the max_hits records
// from i * max_hits, of which the first min(found[i], max_hits) are
// written, nearest first, and the rest left as they were (the caller
// copies the kept ones out: filling whole rows of misses cost more than
// the walks of rays with few hits). The walker's `hits` are then not
// written.
struct WalkRequest {
  uint32_t flags = 0;
  uint32_t max_hits = 0;
  uint32_t* found = nullptr;
  Hit* lists = nullptr;
  // Closest and any hit: leave each hit's triangle a slot of the blob
  // (layout::remap_entry turns it into the caller's triangle; no point is
  // written). A scene walks an instance one ray at a time: it looks the
  // slots up afterwards, many rays side by side, as finish_hits does.
  bool keep_slots = false;
  // The rays share one origin and come sorted by direction (BlobView::trace,
  // cpu/common_origin.h): a walker with a packet walk (OctTreeCompressed)
  // takes them in groups, each node decoded once for a group; the others
  // walk them one by one as ever. The answers are the same either way.
  bool packets = false;
};

MC_ISA_BEGIN

// Walks `n` rays through a validated blob. Unwalkable rays (ray_is_walkable)
// are answered as misses and counted in *skipped.
using WalkFn = void (*)(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
                        const WalkRequest& request);

// One walker a tree format, chosen by the catalog's tag (layout/catalog.h):
// each family's walk_*.cpp defines its formats' overloads and instantiates
// them for every triangle codec (the zero-byte trees: Indexed24 alone) with
// the triangle test it is compiled for (kWalkersTriangleTest), which every
// walker carries down to its triangle tests.
#define MC_DECLARE_WALK(Name, ...)                                                                          \
  template <class Codec, TriangleTest kTest>                                                                 \
  void walk(layout::tree::Name, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, \
            const WalkRequest& request);
MC_FOR_EACH_TREE_FORMAT(MC_DECLARE_WALK)
#undef MC_DECLARE_WALK

// A walked ray's answer with its triangle still a slot: finish_hits turns
// slots into the caller's triangles afterwards.
inline void keep_slot(Hit& hit, const Closest& c, uint32_t outputs) {
  if (c.slot == MC_NO_HIT) return;
  hit.t = c.hit_t;
  hit.triangle = c.slot;
  if (outputs & MC_HIT_UV) hit.u = c.u, hit.v = c.v;
}

// Axis a of the point o + t d, in double (t d is exact there) and rounded
// once, as the GPU's (shaders/ray.glsl): within half an ulp of the point at
// the float t reported.
inline float hit_point(const Ray& ray, float t, int a) {
  return float(double(ray.org[a]) + double(t) * walked_direction(ray.dir[a]));
}

// Hits [begin, end) from slots to the caller's triangles, with the point if
// asked for. A remap lookup is two dependent loads that miss the cache on
// large meshes: made at the end of each walk they stalled every ray, made
// here side by side for many rays they overlap.
inline void finish_hits(const uint8_t* blob, const Ray* rays, Hit* hits, size_t begin, size_t end, uint32_t outputs) {
  const layout::BlobHeader& h = layout::header_of(blob);
  for (size_t i = begin; i < end; ++i) {
    Hit& hit = hits[i];
    if (hit.triangle == kNoHit) continue;
    hit.triangle = layout::remap_entry(blob, h, hit.triangle);
    if (outputs & MC_HIT_POINT)
      for (int a = 0; a < 3; ++a) hit.point[a] = hit_point(rays[i], hit.t, a);
  }
}

// Query::All's row of one ray, after its walk: slots to the caller's
// triangles, the point if asked for, and the row in order of t, then
// triangle (a tie's order no longer depends on where the walk met it).
inline void finish_list(const uint8_t* blob, const Ray& ray, Hit* row, uint32_t used, uint32_t outputs) {
  const layout::BlobHeader& h = layout::header_of(blob);
  for (uint32_t k = 0; k < used; ++k) {
    row[k].triangle = layout::remap_entry(blob, h, row[k].triangle);
    if (!(outputs & MC_HIT_UV)) row[k].u = row[k].v = 0;  // the double redo sets them unasked
    if (outputs & MC_HIT_POINT)
      for (int a = 0; a < 3; ++a) row[k].point[a] = hit_point(ray, row[k].t, a);
  }
  std::sort(row, row + used, [](const Hit& a, const Hit& b) { return a.t < b.t || (a.t == b.t && a.triangle < b.triangle); });
}

// The batch loop every walker shares: an unwalkable ray becomes a counted
// miss; walk_one(r, c) walks one ray, shortening c on every hit. Rays go in
// chunks, walked first, then finished (finish_hits), unless the request
// keeps the slots.
template <class WalkOne>
inline void for_each_ray(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
                         const WalkRequest& request, WalkOne&& walk_one) {
  const uint32_t outputs = request.flags;
  if (outputs & MC_QUERY_ALL) {
    for (size_t i = 0; i < n; ++i) {
      Hit* row = request.lists + i * request.max_hits;
      request.found[i] = 0;
      if (!ray_is_walkable(rays[i])) {
        ++*skipped;
        continue;
      }
      const RayPre r(rays[i], outputs);
      HitList list{row, request.max_hits};
      Closest c{rays[i].tmax};
      c.list = &list;
      walk_one(r, c);
      request.found[i] = list.found;
      finish_list(blob, rays[i], row, std::min(list.found, list.cap), outputs);
    }
    return;
  }
  constexpr size_t kChunk = 32;
  for (size_t begin = 0; begin < n; begin += kChunk) {
    const size_t end = std::min(n, begin + kChunk);
    for (size_t i = begin; i < end; ++i) {
      hits[i] = Hit{};
      if (!ray_is_walkable(rays[i])) {
        ++*skipped;
        continue;
      }
      const RayPre r(rays[i], outputs);
      Closest c{rays[i].tmax};
      c.any = (outputs & MC_QUERY_ANY) != 0;
      walk_one(r, c);
      keep_slot(hits[i], c, outputs);
    }
    if (!request.keep_slots) finish_hits(blob, rays, hits, begin, end, outputs);
  }
}

MC_ISA_END
}  // namespace meshcast
