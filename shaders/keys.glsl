// The per-ray 64-bit keys of the methods that test triangles in 128-lane
// records (BruteForce, AABBList): every hit takes part in one atomic
// minimum a ray over (t bits << 32 | triangle position). Non-negative
// floats order as their bits, so the smallest key is the nearest hit, and
// equal t goes to the lowest position (the record order the CPU walks), the
// same tie rule for every run; the resolve pass turns a key into a hit.
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#ifndef MESHCAST_KEYS_GLSL
#define MESHCAST_KEYS_GLSL
#extension GL_EXT_shader_atomic_int64 : require

#include "shaders/watertight.glsl"

layout(std430, set = 0, binding = 2) buffer Keys { uint64_t keys[]; };

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
  atomicMin(keys[ray], (uint64_t(floatBitsToUint(t) & 0x7FFFFFFFu) << 32) | uint64_t(record * 128u + lane));
}

#endif
