// Method 2 of seed 000 §7, AABBList, pass 1: one thread a (ray, batch),
// the conservative box test of the CPU walker against the ray's whole
// [0, tmax] (from 0 whatever its tmin: the triangle test applies tmin, and
// a box entered before tmin may hold hits past it); an entered box appends
// the pair.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/aabblist.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#define MESHCAST_WALK_BOXES_ONLY  // the box test alone: binding 4 is the pairs here
#include "shaders/walk.glsl"

layout(local_size_x = 64) in;

// records: the batch count.
layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint batch = gl_GlobalInvocationID.x, ray = pc.ray_base + gl_WorkGroupID.y;
  if (batch >= pc.records || ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  if (!r.walkable) return;
  const uint at = list_entry(batch);
  const vec3 mn = blob_vec3(at + MC_LIST_MIN_AT);
  const vec3 mx = blob_vec3(at + MC_LIST_MAX_AT);
  if (box_test(r, mn, mx, r.tmax) == kInfinity) return;
  const uint k = atomicAdd(control.counter, 1u);
  if (k < pairs.length()) pairs[k] = uvec2(ray, batch);
}
