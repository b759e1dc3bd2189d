// BitPack (seed 000 §3.4): each corner one uint64 of three 21-bit codes,
// triangle by triangle, 24 bytes a triangle.
//
// The source quantizes against the leaf's box. Here the codes are on the
// mesh grid (kGridPowerOfTwo: a power-of-two step of at most 2^-21 of the
// mesh extent, offset in the header): a leaf's box would need its own step
// and offset stored beside the block (the tree formats here hand the walker
// no leaf box), and two leaves would decode a shared vertex to different
// bits. On the mesh grid every code decodes exactly, shared vertices meet,
// and a vertex moves at most half a step.
#pragma once
#include <algorithm>
#include <cstring>

#include "layout/triangles/block.h"

namespace meshcast::layout {

struct BitPack {
  static constexpr uint32_t kFormat = MC_TRI_BITPACK;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kSlotDivisor = 24;
  static constexpr uint32_t kLanes = 1;
  static constexpr GridKind kGrid = kGridPowerOfTwo;
  static uint32_t block_bytes(uint32_t count) { return count * 24; }
  static void encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
    for (uint32_t i = 0; i < count; ++i) std::memcpy(out + i * 24, tris[i].packed, 24);
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const BlobHeader& h = header_of(blob);
    for (int c = 0; c < 3; ++c)
      bitpack_decode(load<uint64_t>(blob + block + i * 24 + c * 8), h.quant_offset, h.quant_scale, out[c]);
  }
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }
};

}  // namespace meshcast::layout
