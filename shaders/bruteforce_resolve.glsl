// After the brute-force pass: one thread a ray turns its key into a hit.
// The winning triangle is tested again (the same arithmetic gives the same
// answer) for its barycentrics, and its slot goes through the remap.
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Keys { uint64_t keys[]; };

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint ray = gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const uint64_t key = keys[ray];
  if (key == 0xFFFFFFFFFFFFFFFFul) {
    write_miss(ray);
    return;
  }
  const uint position = uint(key & 0xFFFFFFFFul), record = position / 128u, lane = position % 128u;
  const uint at = brute_record(record);
  vec3 corner[3];
  brute_corners(at, lane, corner);
  float t, u = 0.0, v = 0.0;
  watertight(load_ray(ray), corner[0], corner[1], corner[2], load_ray(ray).tmax, t, u, v);
  const uint block = at + MC_BRUTE_RECORD_BYTES - header(MC_HDR_TREE_OFFSET);  // tree-section offset
  const uint slot = (block - header(MC_HDR_TRIANGLE_BASE)) / header(MC_HDR_SLOT_DIVISOR) + lane;
  write_hit(ray, uintBitsToFloat(uint(key >> 32)), remap_entry(slot), u, v);
}
