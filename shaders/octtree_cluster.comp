// OctTreeCompressed with ClusterBitPackSOA8 leaves: the walk of
// shaders/octtree_walk.glsl over the blob, on persistent threads (Aila and
// Laine 2009). The host launches no more workgroups than a device keeps
// resident (gpu/walkers.cpp); each workgroup takes its next 64 rays from
// the batch counter when all its threads are done, so no part of the
// device idles at the end of a batch while another still has rays queued
// behind it. A workgroup waits for its longest ray. (Taking rays a
// subgroup at a time, through a shared word its elected lane writes, lost
// a few rays in a thousand on lavapipe; the workgroup barrier is the
// spec's own guarantee.)
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/hits.glsl"
#include "shaders/octtree_walk.glsl"

#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

shared uint group_first;

void main() {
  for (;;) {
    if (gl_LocalInvocationIndex == 0u) group_first = atomicAdd(next_ray, gl_WorkGroupSize.x);
    barrier();
    const uint first = group_first;
    barrier();
    if (first >= pc.ray_count) break;
    const uint ray = first + gl_LocalInvocationIndex;
    if (ray < pc.ray_count) {
      const GpuRay r = load_ray(ray);
      count_unwalkable(r.walkable);
      Closest c = closest_start(ray, r);
      if (r.walkable) walk_octtree(r, c);
      write_closest(ray, c);
    }
  }
}
