// Method 1 of seed 000 §7, BruteForce over 128-lane records: a workgroup
// of 128 threads tests one record (128 triangles) against one ray, each
// thread one lane, and every hit takes part in one 64-bit atomic minimum a
// ray over (t bits << 32 | triangle position): non-negative floats order as
// their bits, so the smallest key is the nearest hit, and equal t goes to
// the lowest position, the same tie rule for every run.
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#extension GL_EXT_shader_atomic_int64 : require

#include "shaders/watertight.glsl"

layout(local_size_x = 128) in;

layout(std430, set = 0, binding = 2) buffer Keys { uint64_t keys[]; };

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = pc.ray_base + gl_WorkGroupID.y, record = gl_WorkGroupID.x, lane = gl_LocalInvocationID.x;
  if (ray >= pc.ray_count || record >= pc.records) return;
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
