// The indexed triangle formats of seed 000 §3.6-3.8, one template:
//   Indexed16, Indexed32            3 indices a triangle, triangle by triangle (§3.6)
//   Indexed16SOA4, Indexed32SOA4    4 triangles' indices in SOA order,
//                                   I11..I41, I12..I42, I13..I43 (§3.7)
//   Indexed16BitPackSOA4,
//   Indexed32BitPackSOA4            the same over BitPack vertices (§3.8)
// The indices point into the blob's vertex section: 3 floats a vertex, or one
// uint64 BitPack word quantized against the box of the whole mesh. Vertices
// are numbered in the order the leaves first use them (depth first), one
// record per input vertex, so a shared vertex decodes to the same bits in
// every triangle that uses it. SOA leaves are padded with the last triangle.
#pragma once
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "layout/triangles/block.h"

namespace meshcast::layout {

template <class IndexT, bool kBitPackVertices, bool kSoa, uint32_t kFormatId>
struct Indexed {
  static constexpr uint32_t kFormat = kFormatId;
  static constexpr uint32_t kIndexBytes = sizeof(IndexT);
  static constexpr uint32_t kVertexBytes = kBitPackVertices ? 8 : 12;
  static constexpr GridKind kGrid = kBitPackVertices ? kGridMeshBox : kGridNone;
  static constexpr uint32_t kLanes = kSoa ? MC_SOA4_LANES : 1;
  static constexpr uint32_t kSlotDivisor = 3 * kIndexBytes;  // bytes of indices a triangle
  static constexpr uint64_t kMaxVertices = uint64_t(IndexT(~IndexT(0))) + 1;

  static uint32_t lanes(uint32_t count) { return kSoa ? (count + 3) / 4 * 4 : count; }
  static uint32_t block_bytes(uint32_t count) { return (lanes(count) * 3 * kIndexBytes + 3) / 4 * 4; }
  // Position (in indices) of corner c of triangle i.
  static uint32_t slot(uint32_t i, int c) { return kSoa ? (i / 4) * 12 + uint32_t(c) * 4 + i % 4 : i * 3 + uint32_t(c); }
  static uint32_t index(const uint8_t* blob, uint32_t block, uint32_t i, int c) {
    return load<IndexT>(blob + block + slot(i, c) * kIndexBytes);
  }

  static void encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out) {
    for (uint32_t i = 0; i < lanes(count); ++i) {
      const TriCorners& t = tris[std::min(i, count - 1)];
      for (int c = 0; c < 3; ++c) {
        auto it = ctx.last_index->find(t.vertex[c]);
        uint32_t at;
        if (it != ctx.last_index->end()) {
          at = it->second;
        } else {
          if constexpr (kBitPackVertices) at = pool_append(*ctx.pool, &t.packed[c], 8);
          else at = pool_append(*ctx.pool, t.v[c], 12);
          if (at >= kMaxVertices)
            throw std::length_error(std::to_string(kIndexBytes * 8) + "-bit indices reach " +
                                    std::to_string(kMaxVertices) + " vertices; this mesh uses more");
          (*ctx.last_index)[t.vertex[c]] = at;
        }
        IndexT v = IndexT(at);
        std::memcpy(out + slot(i, c) * kIndexBytes, &v, kIndexBytes);
      }
    }
  }

  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const BlobHeader& h = header_of(blob);
    for (int c = 0; c < 3; ++c) {
      const uint8_t* record = blob + h.vertex_offset + uint64_t(index(blob, block, i, c)) * kVertexBytes;
      if constexpr (kBitPackVertices) bitpack_decode(load<uint64_t>(record), h.quant_offset, h.quant_scale, out[c]);
      else std::memcpy(out[c], record, 12);
    }
  }

  // Every lane, padding included, must name a vertex record.
  static bool check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why) {
    const BlobHeader& h = header_of(blob);
    uint64_t vertices = h.vertex_size / kVertexBytes;
    for (uint32_t i = 0; i < lanes(count); ++i)
      for (int c = 0; c < 3; ++c)
        if (index(blob, block, i, c) >= vertices) {
          *why = "triangle block at byte " + std::to_string(block) + " names vertex " +
                 std::to_string(index(blob, block, i, c)) + " of " + std::to_string(vertices);
          return false;
        }
    return true;
  }
};

using Indexed16 = Indexed<uint16_t, false, false, MC_TRI_INDEXED16>;
using Indexed32 = Indexed<uint32_t, false, false, MC_TRI_INDEXED32>;
using Indexed16SOA4 = Indexed<uint16_t, false, true, MC_TRI_INDEXED16SOA4>;
using Indexed32SOA4 = Indexed<uint32_t, false, true, MC_TRI_INDEXED32SOA4>;
using Indexed16BitPackSOA4 = Indexed<uint16_t, true, true, MC_TRI_INDEXED16BITPACKSOA4>;
using Indexed32BitPackSOA4 = Indexed<uint32_t, true, true, MC_TRI_INDEXED32BITPACKSOA4>;

}  // namespace meshcast::layout
