// Hits as the CPU's Hit (cpu/intersect.h): t, triangle (MC_NO_HIT for a miss), u,
// v, the hit point; 7 words. u, v and the point are written only when the
// pipeline was made for them (kFlags, MC_HIT_*), else 0,
// so a method asked for neither leaves their arithmetic to dead-code
// elimination.
#ifndef MESHCAST_HITS_GLSL
#define MESHCAST_HITS_GLSL

#include "shaders/ray.glsl"

struct GpuHit {
  float t;
  uint triangle;
  float u, v;
  float px, py, pz;
};

layout(std430, set = 0, binding = 3) writeonly buffer Hits { GpuHit hits[]; };

void write_miss(uint ray) { hits[ray] = GpuHit(uintBitsToFloat(0x7F800000u), MC_NO_HIT, 0.0, 0.0, 0.0, 0.0, 0.0); }

void write_hit(uint ray, float t, uint triangle, float u, float v) {
  GpuHit h = GpuHit(t, triangle, 0.0, 0.0, 0.0, 0.0, 0.0);
  if ((kFlags & MC_HIT_UV) != 0u) {
    h.u = u;
    h.v = v;
  }
  if ((kFlags & MC_HIT_POINT) != 0u) {
    const vec3 p = ray_point(ray, t);
    h.px = p.x, h.py = p.y, h.pz = p.z;
  }
  hits[ray] = h;
}

#endif
