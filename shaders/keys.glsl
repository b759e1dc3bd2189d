// The per-ray 64-bit keys of the methods that test triangles in 128-lane
// records (BruteForce, AABBList): every hit takes part in one atomic
// minimum a ray over (t bits << 32 | triangle position). Non-negative
// floats order as their bits, so the smallest key is the nearest hit, and
// equal t goes to the lowest position (the record order the CPU walks), the
// same tie rule for every run; the resolve pass turns a key into a hit.
// A Query::Any takes the nearest hit too (it is a hit); culling is the
// triangle test's (kFlags). A Query::All keeps a row of kMaxHits + 1 keys
// a ray instead (fold_into_row).
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#ifndef MESHCAST_KEYS_GLSL
#define MESHCAST_KEYS_GLSL
#extension GL_EXT_shader_atomic_int64 : require

#include "shaders/watertight.glsl"

layout(std430, set = 0, binding = 2) buffer Keys { uint64_t keys[]; };

#define MC_KEY_EMPTY 0xFFFFFFFFFFFFFFFFul  // what the host fills every key with

// Query::All: the ray's row of keys holds its nearest kMaxHits in places
// 0..kMaxHits-1, kept by a chain of atomic minimums: the key a place gives
// up moves on to the next, so whatever leaves the last place is farther
// than every key kept then and after (places only ever decrease). Place
// kMaxHits counts the hits, from the fill value (all ones): found =
// counter + 1, modulo 2^64.
void fold_into_row(uint ray, uint64_t key) {
  const uint base = ray * (kMaxHits + 1u);
  atomicAdd(keys[base + kMaxHits], 1ul);
  for (uint k = 0u; k < kMaxHits; ++k) {
    const uint64_t old = atomicMin(keys[base + k], key);
    if (old == MC_KEY_EMPTY) return;
    key = max(old, key);
  }
}

// Lane `lane` of record `record` (a padding lane past the record's count
// does nothing) against ray `ray`.
void fold_lane(uint ray, uint record, uint lane) {
  const GpuRay r = load_ray(ray);
  if (!r.walkable) return;
  const uint at = brute_record(record);
  if (lane >= blob_u32(at)) return;
  vec3 corner[3];
  brute_corners(at, lane, corner);
  float t, u, v;
  if (!watertight(r, corner[0], corner[1], corner[2], r.tmax, t, u, v)) return;
  // -0 (an origin on the triangle) keys as +0.
  const uint64_t key = (uint64_t(floatBitsToUint(t) & 0x7FFFFFFFu) << 32) | uint64_t(record * 128u + lane);
  if ((kFlags & MC_QUERY_ALL) != 0u) fold_into_row(ray, key);
  else atomicMin(keys[ray], key);
}

#endif
