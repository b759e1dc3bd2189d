// Indexed8BitPackSOA4 (seed 000 §3.9): a leaf is
//   OffsetToVertices (uint32), TriangleBlock, TriangleBlock, ...
// each TriangleBlock holding 8-bit vertex indices of 4 triangles in SOA order
// (I11..I41, I12..I42, I13..I43). Vertex I of the leaf is the uint64 BitPack
// word at  <address of the leaf> + OffsetToVertices + 8 * I,  quantized
// against the box of the whole mesh (header quant_offset/quant_scale).
//
// Encoding is the source's greedy window: before a leaf of n triangles is
// written, its 256-vertex window is placed to end 3n vertices past the current
// end of the vertex pool, so even n unshared triangles fit; a corner whose
// word is already inside the window is reused, any other is appended.
//
// Precision: a decoded component lies within quant_scale/2 (rounding to the
// grid) plus one float rounding of the decode of the original; the encoder
// picks, of the grid points around the original, the one that decodes nearest.
#pragma once
#include <string>

#include "layout/triangles/block.h"

namespace meshcast::layout {

struct Indexed8BitPackSOA4 {
  static constexpr uint32_t kFormat = MC_TRI_INDEXED8BITPACKSOA4;
  // A leaf of b blocks takes 4 + 12b bytes for 4b slots: 3 bytes a slot
  // number leaves room for every slot (and 1-2 unused numbers a leaf).
  static constexpr uint32_t kSlotDivisor = 3;
  static constexpr GridKind kGrid = kGridMeshBox;
  static constexpr uint32_t kLanes = MC_SOA4_LANES;
  static uint32_t blocks(uint32_t count) { return (count + 3) / 4; }
  static uint32_t block_bytes(uint32_t count) { return MC_I8_HEADER_BYTES + blocks(count) * MC_I8_BLOCK_BYTES; }

  static void encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out);

  static uint32_t vertex_address(const uint8_t* blob, uint32_t block, uint32_t index) {
    return block + load<uint32_t>(blob + block) + 8 * index;
  }
  static uint8_t index(const uint8_t* blob, uint32_t block, uint32_t i, int corner) {
    return blob[block + MC_I8_HEADER_BYTES + (i / 4) * MC_I8_BLOCK_BYTES + corner * 4 + i % 4];
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const BlobHeader& h = header_of(blob);
    for (int c = 0; c < 3; ++c) {
      uint64_t w = load<uint64_t>(blob + vertex_address(blob, block, index(blob, block, i, c)));
      bitpack_decode(w, h.quant_offset, h.quant_scale, out[c]);
    }
  }
  // Every lane of every block (padding included: SIMD reads them) must index
  // a word inside the vertex section.
  static bool check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why);
};

}  // namespace meshcast::layout
