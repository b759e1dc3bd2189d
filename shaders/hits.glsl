// Hits as the CPU's Hit (cpu/ray.h): t, triangle (MC_NO_HIT for a miss), u, v.
#ifndef MESHCAST_HITS_GLSL
#define MESHCAST_HITS_GLSL

struct GpuHit {
  float t;
  uint triangle;
  float u, v;
};

layout(std430, set = 0, binding = 3) writeonly buffer Hits { GpuHit hits[]; };

void write_miss(uint ray) { hits[ray] = GpuHit(uintBitsToFloat(0x7F800000u), MC_NO_HIT, 0.0, 0.0); }
void write_hit(uint ray, float t, uint triangle, float u, float v) { hits[ray] = GpuHit(t, triangle, u, v); }

#endif
