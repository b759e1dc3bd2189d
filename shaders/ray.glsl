// Rays as the host prepares them (gpu/rays.cpp): the ray and the per-ray
// constants of the CPU's RayPre, in the record of layout/ray_record.h,
// computed once on the host in correctly rounded arithmetic, so the shear
// the GPU applies is the CPU's bit for bit, and the box test's reciprocals
// likewise.
#ifndef MESHCAST_RAY_GLSL
#define MESHCAST_RAY_GLSL

#include "layout/ray_record.h"

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

// walked_direction of meshcast/ray.h, for the rays a shader makes itself
// (the scene method's): a component below FLT_MIN as 0, its sign kept.
vec3 walked_direction(vec3 d) {
  vec3 out_d;
  for (int a = 0; a < 3; ++a)
    out_d[a] = abs(d[a]) < uintBitsToFloat(0x00800000u) ? uintBitsToFloat(floatBitsToUint(d[a]) & 0x80000000u) : d[a];
  return out_d;
}

float ray_word(uint b, uint word) { return uintBitsToFloat(ray_words[b + word]); }

vec3 ray_vec3(uint b, uint word) { return vec3(ray_word(b, word), ray_word(b, word + 1u), ray_word(b, word + 2u)); }

GpuRay load_ray(uint i) {
  const uint b = i * MC_RAY_WORDS;
  GpuRay r;
  r.org = ray_vec3(b, MC_RAY_ORG);
  r.dir = ray_vec3(b, MC_RAY_DIR);
  r.tmax = ray_word(b, MC_RAY_TMAX);
  r.sx = ray_word(b, MC_RAY_SHEAR);
  r.sy = ray_word(b, MC_RAY_SHEAR + 1u);
  r.sz = ray_word(b, MC_RAY_SHEAR + 2u);
  const uint axes = ray_words[b + MC_RAY_AXES];
  r.kx = axes & 3u, r.ky = (axes >> 2) & 3u, r.kz = (axes >> 4) & 3u;
  r.walkable = ray_words[b + MC_RAY_WALKABLE] != 0u;
  r.inv = ray_vec3(b, MC_RAY_INV);
  r.tmin = ray_word(b, MC_RAY_TMIN);
  return r;
}

#endif
