// Float3 (seed 000 §3.1): the corners of each triangle as 9 floats.
#pragma once
#include <cstring>

#include "layout/triangles/block.h"

namespace meshcast::layout {

struct Float3 {
  static constexpr uint32_t kFormat = MC_TRI_FLOAT3;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kSlotDivisor = MC_FLOAT3_TRI_BYTES;  // exactly one slot a triangle
  static constexpr uint32_t kLanes = 1;
  static constexpr GridKind kGrid = kGridNone;
  static uint32_t block_bytes(uint32_t count) { return count * MC_FLOAT3_TRI_BYTES; }
  static void encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
    for (uint32_t i = 0; i < count; ++i) std::memcpy(out + i * MC_FLOAT3_TRI_BYTES, tris[i].v, 36);
  }
  // Corners of triangle `i` of the block at blob offset `block`.
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    std::memcpy(out, blob + block + i * MC_FLOAT3_TRI_BYTES, 36);
  }
  // Bytes past `block` that decoding lane `i` reads; validation checks them.
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }
};

}  // namespace meshcast::layout
