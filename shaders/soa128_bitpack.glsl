// BitPackSOA128 records of BruteForce and AABBList: [count][one block of 128 lanes]: rows
// X1 Y1 Z1 X2 ... Z3 of 128 uint16, then the block's scale and offset (3
// floats each); v = q * scale + offset (layout/triangles/soa.h). The scale is a power
// of two (the mesh grid's step times 2^m), so the product is exact and the
// sum rounds once, as the CPU's fma does.
#ifndef MESHCAST_SOA128_GLSL
#define MESHCAST_SOA128_GLSL

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"

#define MC_SOA128_ROWS_BYTES (9u * 128u * 2u)
#define MC_SOA128_RECORD_BYTES (MC_BRUTE_RECORD_BYTES + MC_SOA128_ROWS_BYTES + 24u)

// Record k of the section: records start at the triangle base (BruteForce:
// 0; AABBList: after its entries) and every one is a full block.
uint brute_record(uint k) { return header(MC_HDR_TREE_OFFSET) + header(MC_HDR_TRIANGLE_BASE) + k * MC_SOA128_RECORD_BYTES; }

void brute_corners(uint record_at, uint lane, out vec3 corner[3]) {
  const uint block = record_at + MC_BRUTE_RECORD_BYTES;
  for (uint c = 0u; c < 3u; ++c)
    for (uint a = 0u; a < 3u; ++a) {
      const uint byte = block + ((c * 3u + a) * 128u + lane) * 2u;
      const uint q = (blob_u32(byte & ~3u) >> ((byte & 2u) * 8u)) & 0xFFFFu;
      precise float v = float(q) * blob_f32(block + MC_SOA128_ROWS_BYTES + 4u * a) +
                        blob_f32(block + MC_SOA128_ROWS_BYTES + 12u + 4u * a);
      corner[c][a] = v;
    }
}

#endif
