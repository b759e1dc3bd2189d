// Query::All's rows (binding 4), one a ray: the hits found, then kMaxHits
// records of (t bits, triangle) in order of t, of which the first
// min(found, kMaxHits) are written; the rest are left as they were (the
// host reads the kept ones alone into compact rows, gpu/batch.cpp, so a
// ray's time follows its hits, not kMaxHits). While a walk runs, a
// record's second word is a slot; row_finish turns them into triangles.
#ifndef MESHCAST_HIT_ROWS_GLSL
#define MESHCAST_HIT_ROWS_GLSL

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"

layout(std430, set = 0, binding = 4) buffer HitRows { uint rows[]; };

uint row_base(uint ray) { return ray * (1u + 2u * kMaxHits); }
float row_t(uint base, uint k) { return uintBitsToFloat(rows[base + 1u + 2u * k]); }
uint row_entry(uint base, uint k) { return rows[base + 2u + 2u * k]; }
void row_set(uint base, uint k, float t, uint entry) {
  rows[base + 1u + 2u * k] = floatBitsToUint(t);
  rows[base + 2u + 2u * k] = entry;
}

void row_start(uint ray) { rows[row_base(ray)] = 0u; }

// One more hit: counted, and kept when among the nearest kMaxHits (the
// CPU's HitList::add in cpu/leaf.h; the last record is read only once
// written).
void row_add(uint ray, float t, uint entry) {
  const uint base = row_base(ray), found = rows[base];
  rows[base] = found + 1u;
  uint k = min(found, kMaxHits);
  if (k == kMaxHits) {
    if (!(t < row_t(base, kMaxHits - 1u))) return;
    --k;
  }
  for (; k > 0u && row_t(base, k - 1u) > t; --k) row_set(base, k, row_t(base, k - 1u), row_entry(base, k - 1u));
  row_set(base, k, t, entry);
}

// The kept records in order of t, then triangle (an insertion sort: they
// arrive in order of t).
void row_sort(uint ray) {
  const uint base = row_base(ray), used = min(rows[base], kMaxHits);
  for (uint i = 1u; i < used; ++i) {
    const float t = row_t(base, i);
    const uint tri = row_entry(base, i);
    uint k = i;
    for (; k > 0u && (row_t(base, k - 1u) > t || (row_t(base, k - 1u) == t && row_entry(base, k - 1u) > tri)); --k)
      row_set(base, k, row_t(base, k - 1u), row_entry(base, k - 1u));
    row_set(base, k, t, tri);
  }
}

// After a walk: slots to the caller's triangles, then the row in order.
void row_finish(uint ray) {
  const uint base = row_base(ray), used = min(rows[base], kMaxHits);
  for (uint k = 0u; k < used; ++k) rows[base + 2u + 2u * k] = remap_entry(row_entry(base, k));
  row_sort(ray);
}

#endif
