// Method 1 of seed 000 §7, BruteForce over 128-lane records: a workgroup
// of 128 threads tests one record (128 triangles) against one ray, each
// thread one lane, folding its hit into the ray's key (shaders/keys.glsl).
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#include "shaders/keys.glsl"

layout(local_size_x = 128) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = pc.ray_base + gl_WorkGroupID.y, record = gl_WorkGroupID.x;
  if (ray >= pc.ray_count || record >= pc.records) return;
  fold_lane(ray, record, gl_LocalInvocationID.x);
}
