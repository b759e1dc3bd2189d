// OctTreeCompressed with ClusterBitPackSOA8 leaves, one ray a thread: the
// walk of shaders/octtree_walk.glsl over the blob.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/hits.glsl"
#include "shaders/octtree_walk.glsl"

#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  Closest c = closest_start(ray, r);
  if (r.walkable) walk_octtree(r, c);
  write_closest(ray, c);
}
