// Walkers: one per tree family, instantiated per triangle codec. trace()
// (cpu/trace.h) picks the instantiation from the blob header once per batch.
#pragma once
#include <cstddef>
#include <cstdint>

#include "cpu/leaf.h"

namespace meshcast {

// Walks `n` rays through a validated blob. Unwalkable rays (ray_is_walkable)
// are answered as misses and counted in *skipped.
using WalkFn = void (*)(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped);

template <class Codec>
void walk_aabbtree(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped);

template <class Bounds, class Codec>
void walk_quadtree(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped);

// Turns the closest slot into the caller's hit.
inline Hit finish_hit(const uint8_t* blob, const layout::BlobHeader& h, const Closest& c) {
  Hit hit;
  if (c.slot == MC_NO_HIT) return hit;
  hit.t = c.t;
  hit.triangle = layout::remap_entry(blob, h, c.slot);
  hit.u = c.u, hit.v = c.v;
  return hit;
}

}  // namespace meshcast
