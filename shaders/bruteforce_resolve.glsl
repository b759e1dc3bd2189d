// After the brute-force pass: one thread a ray turns its key into a hit.
// The winning triangle is tested again (the same arithmetic gives the same
// answer) for its barycentrics, and its slot goes through the remap.
// The including file has defined the record's codec (shaders/soa128_*.glsl).
// A Query::All's row of keys (shaders/keys.glsl) becomes its row of hits.
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/hit_rows.glsl"
#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 2) readonly buffer Keys { uint64_t keys[]; };

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

// The slot of a key's triangle position (record * 128 + lane).
uint slot_of_position(uint position) {
  const uint block = brute_record(position / 128u) + MC_BRUTE_RECORD_BYTES - header(MC_HDR_TREE_OFFSET);
  return (block - header(MC_HDR_TRIANGLE_BASE)) / header(MC_HDR_SLOT_DIVISOR) + position % 128u;
}

void resolve_row(uint ray) {
  const uint from = ray * (kMaxHits + 1u), base = row_base(ray);
  row_start(ray);
  rows[base] = uint(keys[from + kMaxHits] + 1ul);
  for (uint k = 0u; k < min(rows[base], kMaxHits); ++k) {
    const uint64_t key = keys[from + k];
    row_set(base, k, uintBitsToFloat(uint(key >> 32)), remap_entry(slot_of_position(uint(key & 0xFFFFFFFFul))));
  }
  row_sort(ray);
  write_miss(ray);
}

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  if ((kFlags & MC_QUERY_ALL) != 0u) {
    resolve_row(ray);
    return;
  }
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
  watertight(r, corner[0], corner[1], corner[2], r.tmax, t, u, v);
  write_hit(ray, uintBitsToFloat(uint(key >> 32)), remap_entry(slot_of_position(position)), u, v);
}
