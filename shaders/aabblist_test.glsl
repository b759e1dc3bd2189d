// Method 2 of seed 000 §7, AABBList, pass 2 (dispatched indirectly): a
// workgroup of 128 threads takes a pair and one of its batch's records,
// each thread one lane folded into the ray's key (shaders/keys.glsl).
// The including file has defined the record's codec (shaders/soa128_*.glsl).
#include "shaders/aabblist.glsl"
#include "shaders/keys.glsl"

// Batch b's first record: records are full blocks from the triangle base.
uint list_first_record(uint batch) {
  return (blob_u32(list_entry(batch) + MC_LIST_RECORDS_AT) - header(MC_HDR_TRIANGLE_BASE)) / MC_SOA128_RECORD_BYTES;
}

layout(local_size_x = 128) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint part = gl_WorkGroupID.y;
  for (uint p = gl_WorkGroupID.x; p < control.pair_count; p += gl_NumWorkGroups.x) {
    const uvec2 pair = pairs[p];
    if (part * 128u >= list_count(pair.y)) continue;
    fold_lane(pair.x, list_first_record(pair.y) + part, gl_LocalInvocationID.x);
  }
}
