// Float3SOA128 records of BruteForce and AABBList (layout/formats.h): [count][one block of
// 128 lanes], rows X1 Y1 Z1 X2 ... Z3 of 128 floats (layout/triangles/soa.h).
#ifndef MESHCAST_SOA128_GLSL
#define MESHCAST_SOA128_GLSL

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"

#define MC_SOA128_RECORD_BYTES (MC_BRUTE_RECORD_BYTES + 9u * 128u * 4u)

// Record k of the section: records start at the triangle base (BruteForce:
// 0; AABBList: after its entries) and every one is a full block.
uint brute_record(uint k) { return header(MC_HDR_TREE_OFFSET) + header(MC_HDR_TRIANGLE_BASE) + k * MC_SOA128_RECORD_BYTES; }

void brute_corners(uint record_at, uint lane, out vec3 corner[3]) {
  const uint block = record_at + MC_BRUTE_RECORD_BYTES;
  for (uint c = 0u; c < 3u; ++c)
    for (uint a = 0u; a < 3u; ++a) corner[c][a] = blob_f32(block + ((c * 3u + a) * 128u + lane) * 4u);
}

#endif
