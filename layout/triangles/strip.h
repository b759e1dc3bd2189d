// UncompressedStrip and CompressedStrip (seed 000 §3.10): each new vertex C
// forms the triangle (A, B, C), A and B taken from the previous triangle
// (V1, V2, V3) as its 3 flag bits say:
//   START_STRIP_V1 = 3, START_STRIP_V2 = 7        (the first two of a strip)
//   A_IS_V1 = 0, A_IS_V2 = 1, A_IS_V3 = 2, OR-ed with
//   B_IS_A_PLUS_1 = 0, B_IS_A_PLUS_2 = 4          (V3 + 1 wraps to V1)
// A block is the leaf's strips, vertex after vertex, until the leaf's count
// of triangles is made; its length depends on how well the leaf strips.
//   UncompressedStrip: 3 floats a vertex, the flag bits in their lowest bits
//     (x: bit 0, y: bit 1, z: bit 2). The decoder clears them, so a vertex
//     decodes to the same bits in every strip; the writer stores each vertex
//     with its lowest bits cleared (a move of at most 1 ulp).
//   CompressedStrip: one uint64 a vertex, three 20-bit codes on the mesh's
//     power-of-two grid (kGridPowerOfTwo with 20 bits; the source uses the
//     leaf box, see bitpack.h for why the mesh grid) and the flags in bits
//     60-62.
// The stripifier is greedy within the leaf: it starts a strip at the first
// unused triangle and extends it through any unused triangle sharing an edge
// (by input vertex) with the last one, which the 6 continuation flags can
// always express.
#pragma once
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "layout/triangles/block.h"

namespace meshcast::layout {

enum : uint32_t { kStartV1 = 3, kStartV2 = 7 };

// One stored vertex: its position, input vertex, and flag.
struct StripVertex {
  float v[3];
  uint32_t id;
  uint32_t flag;
};

// The greedy stripifier; `tris` is left in strip order with corners (A, B, C).
std::vector<StripVertex> stripify(TriCorners* tris, uint32_t count);

// The state machine every reader shares: feed vertices, get triangles.
struct StripDecoder {
  float p[3][3] = {};  // previous triangle V1, V2, V3
  // Returns true when (position, flag) completes a triangle, left in p.
  bool feed(const float v[3], uint32_t flag) {
    if (flag == kStartV1) return std::memcpy(p[0], v, 12), false;
    if (flag == kStartV2) return std::memcpy(p[1], v, 12), false;
    uint32_t a = flag & 3, b = (a + 1 + (flag >> 2 & 1)) % 3;
    float A[3], B[3];
    std::memcpy(A, p[a], 12), std::memcpy(B, p[b], 12);
    std::memcpy(p[0], A, 12), std::memcpy(p[1], B, 12), std::memcpy(p[2], v, 12);
    return true;
  }
};

// Record codecs: how a vertex and its flag are stored.
struct UncompressedRecord {
  static constexpr uint32_t kBytes = 12;
  static constexpr uint32_t kGridBits = 0;
  static void write(const StripVertex& s, const BlobHeader&, uint8_t* out) {
    for (int a = 0; a < 3; ++a) {
      uint32_t bits;
      std::memcpy(&bits, &s.v[a], 4);
      bits = (bits & ~1u) | (s.flag >> a & 1);
      std::memcpy(out + 4 * a, &bits, 4);
    }
  }
  static uint32_t read(const uint8_t* in, const BlobHeader&, float v[3]) {
    uint32_t flag = 0;
    for (int a = 0; a < 3; ++a) {
      uint32_t bits = load<uint32_t>(in + 4 * a);
      flag |= (bits & 1) << a;
      bits &= ~1u;
      std::memcpy(&v[a], &bits, 4);
    }
    return flag;
  }
  static void stored(float v[3]) {  // the position the writer keeps
    for (int a = 0; a < 3; ++a) {
      uint32_t bits;
      std::memcpy(&bits, &v[a], 4);
      bits &= ~1u;
      std::memcpy(&v[a], &bits, 4);
    }
  }
};

struct CompressedRecord {
  static constexpr uint32_t kBytes = 8;
  static constexpr uint32_t kGridBits = 20;
  static constexpr uint32_t kMax = (1u << 20) - 1;
  static void write(const StripVertex& s, const BlobHeader& h, uint8_t* out) {
    uint64_t w = uint64_t(s.flag) << 60;
    for (int a = 0; a < 3; ++a) w |= uint64_t(quantize(s.v[a], h.quant_offset[a], h.quant_scale[a], kMax)) << (20 * a);
    std::memcpy(out, &w, 8);
  }
  static uint32_t read(const uint8_t* in, const BlobHeader& h, float v[3]) {
    uint64_t w = load<uint64_t>(in);
    for (int a = 0; a < 3; ++a) v[a] = std::fma(float(uint32_t(w >> (20 * a)) & kMax), h.quant_scale[a], h.quant_offset[a]);
    return uint32_t(w >> 60) & 7;
  }
  static void stored(float[3]) {}  // already on the grid
};

template <class Record, uint32_t kId>
struct Strip : ReadBack<Strip<Record, kId>> {
  static constexpr uint32_t kFormat = kId;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kSlotDivisor = Record::kBytes;  // a leaf of n triangles stores >= n + 2 vertices
  static constexpr uint32_t kLanes = 1;
  static constexpr GridKind kGrid = Record::kGridBits ? kGridPowerOfTwo : kGridNone;
  static constexpr uint32_t kGridBits = Record::kGridBits ? Record::kGridBits : 21;
  static constexpr bool kMovesFloats = true;  // UncompressedStrip clears the flag bits
  static constexpr bool kSequential = true;   // decoded vertex after vertex

  static uint32_t block_bytes(uint32_t count) { return 3 * count * Record::kBytes; }  // the worst case
  static uint32_t measure(TriCorners* tris, uint32_t count) {
    std::vector<TriCorners> copy(tris, tris + count);
    return uint32_t(stripify(copy.data(), count).size()) * Record::kBytes;
  }
  static void encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out) {
    for (uint32_t i = 0; i < count; ++i)
      for (int c = 0; c < 3; ++c) Record::stored(tris[i].v[c]);
    std::vector<StripVertex> seq = stripify(tris, count);
    for (size_t k = 0; k < seq.size(); ++k) Record::write(seq[k], *ctx.header, out + k * Record::kBytes);
  }

  // Walks the block: calls emit(triangle index, corners) for each of the
  // `count` triangles; returns the bytes read, or 0 if the block ends (at
  // `limit` bytes) or breaks the flag grammar first.
  template <class Emit>
  static uint64_t read(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit, Emit&& emit) {
    const BlobHeader& h = header_of(blob);
    StripDecoder d;
    uint32_t made = 0, last = kStartV2 + 1;  // flag of the previous vertex; none yet
    uint64_t at = 0;
    while (made < count) {
      if (at + Record::kBytes > limit) return 0;
      float v[3];
      uint32_t flag = Record::read(blob + block + at, h, v);
      at += Record::kBytes;
      // Grammar: a strip starts V1, V2, then a triangle from them (flag 0).
      bool ok = flag == kStartV1 ? (last != kStartV1 && last != kStartV2)
                : flag == kStartV2 ? (last == kStartV1)
                : last == kStartV2 ? flag == 0
                                   : (last != kStartV1 && last <= kStartV2);
      if (!ok) return 0;
      last = flag;
      if (d.feed(v, flag)) emit(made++, d.p);
    }
    return at;
  }
};

using UncompressedStrip = Strip<UncompressedRecord, MC_TRI_UNCOMPRESSEDSTRIP>;
using CompressedStrip = Strip<CompressedRecord, MC_TRI_COMPRESSEDSTRIP>;

}  // namespace meshcast::layout
