// Rays as the caller wrote them (meshcast::Ray, layout/ray_record.h: 8
// words, no packing on the host), each prepared here with the per-ray
// constants of the CPU's RayPre: the walked direction, the reciprocals,
// the dominant axis and the shear, every division rounded once
// (div_exact), so the GPU shears exactly as the CPU does; and the CPU's
// walkability test, an unwalkable ray answered as a miss.
#ifndef MESHCAST_RAY_GLSL
#define MESHCAST_RAY_GLSL

#include "layout/ray_record.h"
#include "shaders/exact.glsl"

#define kInfinity uintBitsToFloat(0x7F800000u)
#define kFloatMax uintBitsToFloat(0x7F7FFFFFu)

// The batch's flags word, specialization constant 0: the MC_HIT_* outputs,
// the MC_QUERY_* query and the MC_CULL_* culling (layout/formats.h), the
// word the CPU walkers get; Query::All's row length, constant 1.
layout(constant_id = 0) const uint kFlags = 0u;
layout(constant_id = 1) const uint kMaxHits = 1u;

struct GpuRay {
  vec3 org, dir, inv;
  float tmin, tmax, sx, sy, sz;
  uint kx, ky, kz;
  bool walkable;
};

layout(std430, set = 0, binding = 1) readonly buffer Rays { uint ray_words[]; };

// walked_direction of meshcast/ray.h: a component below FLT_MIN as 0, its
// sign kept (read from the bits: a device may flush the denormal itself).
vec3 walked_direction(vec3 d) {
  vec3 out_d;
  for (int a = 0; a < 3; ++a)
    out_d[a] = abs(d[a]) < uintBitsToFloat(0x00800000u) ? uintBitsToFloat(floatBitsToUint(d[a]) & 0x80000000u) : d[a];
  return out_d;
}

// ray_is_walkable of cpu/ray_is_walkable.cpp past the origin: a direction
// within 2^126 and not below 2^-126 on every axis, t_max and t_min not NaN
// nor < 0, t_min not past t_max (the comparisons fail on NaN).
bool directions_walkable(vec3 dir, float tmin, float tmax) {
  const float biggest = max(max(abs(dir.x), abs(dir.y)), abs(dir.z));
  return all(lessThanEqual(abs(dir), vec3(uintBitsToFloat(0x7E800000u)))) && biggest >= uintBitsToFloat(0x00800000u) &&
         !isnan(tmax) && !isnan(tmin) && tmax >= 0.0 && tmin >= 0.0 && tmin <= tmax;
}

// RayPre of cpu/intersect.h (layout::ray_constants): 1/d, the dominant
// axis, the shear; and whether the CPU walks the ray at all (an origin
// within 2^100 too).
GpuRay prepared(vec3 org, vec3 given_dir, float tmin, float tmax) {
  GpuRay r;
  const vec3 dir = walked_direction(given_dir);
  r.org = org, r.dir = dir, r.tmin = tmin, r.tmax = tmax;
  for (int a = 0; a < 3; ++a) r.inv[a] = div_exact(1.0, dir[a]);
  const float ax = abs(dir.x), ay = abs(dir.y), az = abs(dir.z);
  const uint kz = ax > ay ? (ax > az ? 0u : 2u) : (ay > az ? 1u : 2u);
  uint kx = (kz + 1u) % 3u, ky = (kx + 1u) % 3u;
  if (dir[kz] < 0.0) {
    const uint k = kx;
    kx = ky, ky = k;
  }
  r.sx = div_exact(dir[kx], dir[kz]);
  r.sy = div_exact(dir[ky], dir[kz]);
  r.sz = div_exact(1.0, dir[kz]);
  r.kx = kx, r.ky = ky, r.kz = kz;
  r.walkable = all(lessThanEqual(abs(org), vec3(uintBitsToFloat(0x71800000u)))) && directions_walkable(dir, tmin, tmax);
  return r;
}

float ray_word(uint b, uint word) { return uintBitsToFloat(ray_words[b + word]); }

vec3 ray_vec3(uint b, uint word) { return vec3(ray_word(b, word), ray_word(b, word + 1u), ray_word(b, word + 2u)); }

GpuRay load_ray(uint i) {
  const uint b = i * MC_RAY_WORDS;
  return prepared(ray_vec3(b, MC_RAY_ORG), ray_vec3(b, MC_RAY_DIR), ray_word(b, MC_RAY_TMIN), ray_word(b, MC_RAY_TMAX));
}

// org + t * dir, the direction walked: a hit's point (HitOutputs::Point).
// In double, as the CPU's (cpu/walk.h): t times a component is exact
// there, so the point is rounded once, whether or not a compiler fuses.
vec3 ray_point(uint i, float t) {
  const uint b = i * MC_RAY_WORDS;
  precise dvec3 p = dvec3(ray_vec3(b, MC_RAY_ORG)) + double(t) * dvec3(walked_direction(ray_vec3(b, MC_RAY_DIR)));
  return vec3(p);
}

#endif
