// Rays as the host prepares them (gpu/rays.cpp): the ray and the per-ray
// constants of the CPU's RayPre (cpu/intersect.h), computed once on the host in
// correctly rounded arithmetic, so the shear the GPU applies is the CPU's
// bit for bit, and the box test's reciprocals likewise. 16 words a ray:
//   org xyz, dir xyz, tmax, sx, sy, sz, axes (kx | ky << 2 | kz << 4),
//   walkable (0: answered as a miss, as the CPU does), inv xyz, tmin
#ifndef MESHCAST_RAY_GLSL
#define MESHCAST_RAY_GLSL

#define MC_GPU_RAY_WORDS 16u
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

GpuRay load_ray(uint i) {
  const uint b = i * MC_GPU_RAY_WORDS;
  GpuRay r;
  r.org = vec3(uintBitsToFloat(ray_words[b]), uintBitsToFloat(ray_words[b + 1u]), uintBitsToFloat(ray_words[b + 2u]));
  r.dir = vec3(uintBitsToFloat(ray_words[b + 3u]), uintBitsToFloat(ray_words[b + 4u]), uintBitsToFloat(ray_words[b + 5u]));
  r.tmax = uintBitsToFloat(ray_words[b + 6u]);
  r.sx = uintBitsToFloat(ray_words[b + 7u]);
  r.sy = uintBitsToFloat(ray_words[b + 8u]);
  r.sz = uintBitsToFloat(ray_words[b + 9u]);
  const uint axes = ray_words[b + 10u];
  r.kx = axes & 3u, r.ky = (axes >> 2) & 3u, r.kz = (axes >> 4) & 3u;
  r.walkable = ray_words[b + 11u] != 0u;
  r.inv = vec3(uintBitsToFloat(ray_words[b + 12u]), uintBitsToFloat(ray_words[b + 13u]), uintBitsToFloat(ray_words[b + 14u]));
  r.tmin = uintBitsToFloat(ray_words[b + 15u]);
  return r;
}

#endif
