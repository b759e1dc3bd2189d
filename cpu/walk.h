// Walkers: one per tree family, instantiated per triangle codec. trace()
// (include/meshcast/blob.h) picks the instantiation from the blob header once per batch.
#pragma once
#include <cstddef>
#include <cstdint>

#include "cpu/leaf.h"
#include "layout/catalog.h"

namespace meshcast {
MC_ISA_BEGIN

// Walks `n` rays through a validated blob. Unwalkable rays (ray_is_walkable)
// are answered as misses and counted in *skipped. `outputs`: the MC_HIT_*
// asked for.
using WalkFn = void (*)(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, uint32_t outputs);

// One walker a tree format, chosen by the catalog's tag (layout/catalog.h):
// each family's walk_*.cpp defines its formats' overloads and instantiates
// them for every triangle codec (the zero-byte trees: Indexed24 alone).
#define MC_DECLARE_WALK(Name, ...)                                                                          \
  template <class Codec>                                                                                     \
  void walk(layout::tree::Name, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, \
            uint32_t outputs);
MC_FOR_EACH_TREE_FORMAT(MC_DECLARE_WALK)
#undef MC_DECLARE_WALK

// Turns the closest slot into the caller's hit, with the outputs asked for.
inline Hit finish_hit(const uint8_t* blob, const layout::BlobHeader& h, const Closest& c, const RayPre& r) {
  Hit hit;
  if (c.slot == MC_NO_HIT) return hit;
  hit.t = c.t;
  hit.triangle = layout::remap_entry(blob, h, c.slot);
  if (r.outputs & MC_HIT_UV) hit.u = c.u, hit.v = c.v;
  if (r.outputs & MC_HIT_POINT)
    for (int a = 0; a < 3; ++a) hit.point[a] = r.org[a] + c.t * r.dir[a];
  return hit;
}

// The batch loop every walker shares: an unwalkable ray becomes a counted
// miss; walk_one(r, c) walks one ray, shortening c on every hit.
template <class WalkOne>
inline void for_each_ray(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
                         uint32_t outputs, WalkOne&& walk_one) {
  const layout::BlobHeader& h = layout::header_of(blob);
  for (size_t i = 0; i < n; ++i) {
    if (!ray_is_walkable(rays[i])) {
      hits[i] = Hit{};
      ++*skipped;
      continue;
    }
    const RayPre r(rays[i], outputs);
    Closest c{rays[i].tmax};
    walk_one(r, c);
    hits[i] = finish_hit(blob, h, c, r);
  }
}

MC_ISA_END
}  // namespace meshcast
