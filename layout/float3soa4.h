// Float3SOA4 (seed 000 §3.2): blocks of 4 triangles in structure-of-arrays
// order, X of corner 1 for the 4 triangles, then Y, Z, then corner 2, 3.
// A leaf is padded to a multiple of 4 with copies of its last triangle, so a
// padding lane never widens the leaf's bounds; the walker masks it anyway.
#pragma once
#include <algorithm>
#include <cstring>

#include "layout/block.h"

namespace meshcast::layout {

struct Float3SOA4 {
  static constexpr uint32_t kFormat = MC_TRI_FLOAT3SOA4;
  static constexpr uint32_t kSlotDivisor = MC_FLOAT3SOA4_BLOCK_BYTES / MC_SOA4_LANES;
  static constexpr uint32_t kLanes = MC_SOA4_LANES;
  static constexpr bool kBitPack = false;
  static uint32_t blocks(uint32_t count) { return (count + 3) / 4; }
  static uint32_t block_bytes(uint32_t count) { return blocks(count) * MC_FLOAT3SOA4_BLOCK_BYTES; }
  static void encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
    for (uint32_t b = 0; b < blocks(count); ++b) {
      float soa[36];
      for (uint32_t lane = 0; lane < 4; ++lane) {
        const TriCorners& t = tris[std::min(b * 4 + lane, count - 1)];
        for (int c = 0; c < 3; ++c)
          for (int a = 0; a < 3; ++a) soa[(c * 3 + a) * 4 + lane] = t.v[c][a];
      }
      std::memcpy(out + b * MC_FLOAT3SOA4_BLOCK_BYTES, soa, sizeof soa);
    }
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const uint8_t* p = blob + block + (i / 4) * MC_FLOAT3SOA4_BLOCK_BYTES;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) out[c][a] = load<float>(p + ((c * 3 + a) * 4 + i % 4) * 4);
  }
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }
};

}  // namespace meshcast::layout
