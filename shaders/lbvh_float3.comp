// Method 5 of seed 000 §7: StacklessLBVH (seed 001) with Float3 triangles,
// one ray a thread and no stack at all: the walk of cpu/walk_lbvh.cpp, the
// nearer child first through v = n ^ o, next(v) = (v + 1) >> ctz(v + 1).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/walk.glsl"

#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  Closest c = closest_start(ray, r);
  if (r.walkable) {
    const uint tree = header(MC_HDR_TREE_OFFSET);
    const uint octant = (sign_bit(r.dir.z) ? 1u : 0u) | (sign_bit(r.dir.y) ? 2u : 0u) | (sign_bit(r.dir.x) ? 4u : 0u);
    uint v = 1u, o = 0u, n = 1u;
    for (;;) {
      const uint at = tree + (n - 1u) * MC_LBVH_NODE_BYTES;
      const vec3 mn = blob_vec3(at + MC_LBVH_MIN_AT);
      const vec3 mx = blob_vec3(at + MC_LBVH_MAX_AT);
      if (box_test(r, mn, mx, c.t) != kInfinity) {
        const int count = int(blob_u32(at + MC_LBVH_COUNT_AT));
        const uint position = blob_u32(at + MC_LBVH_POSITION_AT);
        if (count < 0) {
          v <<= 1, o = (o << 1) | ((position >> octant) & 1u);
          n = v ^ o;
          continue;
        }
        test_float3_leaf(r, tree + position, uint(count), slot_of(position), c);
      }
      const int up = findLSB(v + 1u);
      v = (v + 1u) >> up, o >>= up;
      if (v == 1u) break;
      n = v ^ o;
    }
  }
  write_closest(ray, c);
}
