// Structure-of-arrays triangle blocks of N lanes (seed 000 §3.2, §3.3, §3.5,
// and the GPU blocks of §7): row (corner c, axis a) holds that component for
// the N triangles of the block, rows in the order X1 Y1 Z1 X2 ... Z3.
//   Float3SOA<N>    rows of N floats                   Float3SOA4/8/128
//   BitPackSOA<N>   rows of N uint16, then the block's  BitPackSOA4/128
//                   scale (3 floats) and offset (3 floats):
//                   v = q * scale + offset (one fma).
// BitPackSOA precision. The source quantizes against the block's own box
// (scale = extent / 65535), which decodes a vertex shared by two blocks to
// two positions and opens cracks. Here every block's step is the mesh grid's
// power-of-two step G (kGridPowerOfTwo, at most 2^-21 of the mesh extent)
// times 2^m, m the smallest that fits the block in 16 bits, and its offset a
// multiple of that step: the lattices of all blocks nest. The writer first
// moves each vertex to the coarsest lattice among the blocks that use it
// (block_step, and snap_to_block_lattices in builder/build_blob.cpp), so every code
// decodes exactly and a shared vertex decodes to the same bits in every
// block: no cracks. A vertex moves at most G/2 + G * 2^m / 2 for the largest
// m of its blocks; the header keeps the largest m of the blob (max_block_shift).
// A leaf is padded to a multiple of N with copies of its last triangle, so a
// padding lane never widens the leaf's bounds; the walker masks it anyway.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstring>

#include "layout/triangles/block.h"

namespace meshcast::layout {

template <uint32_t N, uint32_t kId>
struct Float3SOA {
  static constexpr uint32_t kFormat = kId;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kLanes = N;
  static constexpr uint32_t kBlockBytes = 9 * N * 4;
  static constexpr uint32_t kSlotDivisor = kBlockBytes / N;
  static constexpr GridKind kGrid = kGridNone;
  static uint32_t blocks(uint32_t count) { return (count + N - 1) / N; }
  static uint32_t block_bytes(uint32_t count) { return blocks(count) * kBlockBytes; }
  static uint32_t row(int c, int a, uint32_t lane) { return ((uint32_t(c) * 3 + uint32_t(a)) * N + lane) * 4; }
  static void encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
    for (uint32_t i = 0; i < blocks(count) * N; ++i) {
      const TriCorners& t = tris[std::min(i, count - 1)];
      for (int c = 0; c < 3; ++c)
        for (int a = 0; a < 3; ++a) std::memcpy(out + (i / N) * kBlockBytes + row(c, a, i % N), &t.v[c][a], 4);
    }
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const uint8_t* p = blob + block + (i / N) * kBlockBytes;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) out[c][a] = load<float>(p + row(c, a, i % N));
  }
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }
};

// The step and offset of a block spanning [lo, hi] on one axis, for mesh
// grid step `grid`: step = grid * 2^m, offset = a multiple of step at or
// below lo, m the smallest with (hi - offset) / step <= 65535.
inline void block_step(float lo, float hi, float grid, float* step, float* offset, uint32_t* shift) {
  *step = grid, *shift = 0;
  if (!(grid > 0)) {  // a flat axis: every code is 0
    *offset = lo;
    return;
  }
  for (;;) {
    *offset = float(std::floor(double(lo) / *step) * *step);
    if ((double(hi) - *offset) / *step <= 65535.0) return;
    *step *= 2, ++*shift;
  }
}

template <uint32_t N, uint32_t kId>
struct BitPackSOA {
  static constexpr uint32_t kFormat = kId;
  static constexpr uint32_t kLanes = N;
  static constexpr uint32_t kRowsBytes = 9 * N * 2;
  static constexpr uint32_t kBlockBytes = kRowsBytes + 24;  // + scale[3], offset[3]
  static constexpr uint32_t kSlotDivisor = kBlockBytes / N;
  static constexpr uint32_t kMax = 65535;
  static constexpr GridKind kGrid = kGridPowerOfTwo;
  static constexpr bool kNestedBlocks = true;  // 16-bit blocks on nested lattices
  static uint32_t blocks(uint32_t count) { return (count + N - 1) / N; }
  static uint32_t block_bytes(uint32_t count) { return blocks(count) * kBlockBytes; }
  static uint32_t row(int c, int a, uint32_t lane) { return ((uint32_t(c) * 3 + uint32_t(a)) * N + lane) * 2; }

  static void encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out) {
    for (uint32_t b = 0; b < blocks(count); ++b) {
      uint8_t* p = out + b * kBlockBytes;
      float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
      uint32_t end = std::min(count, (b + 1) * N);
      for (uint32_t i = b * N; i < end; ++i)
        for (int c = 0; c < 3; ++c)
          for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], tris[i].v[c][a]), hi[a] = std::max(hi[a], tris[i].v[c][a]);
      float scale[3], offset[3];
      for (int a = 0; a < 3; ++a) {
        uint32_t shift;
        block_step(lo[a], hi[a], ctx.grid_step[a], &scale[a], &offset[a], &shift);
        *ctx.max_block_shift = std::max(*ctx.max_block_shift, shift);
      }
      std::memcpy(p + kRowsBytes, scale, 12);
      std::memcpy(p + kRowsBytes + 12, offset, 12);
      for (uint32_t lane = 0; lane < N; ++lane) {
        TriCorners& t = tris[std::min(b * N + lane, count - 1)];
        for (int c = 0; c < 3; ++c)
          for (int a = 0; a < 3; ++a) {
            uint16_t q = uint16_t(quantize(t.v[c][a], offset[a], scale[a], kMax));
            std::memcpy(p + row(c, a, lane), &q, 2);
            if (b * N + lane < count) t.v[c][a] = std::fma(float(q), scale[a], offset[a]);  // as stored
          }
      }
    }
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const uint8_t* p = blob + block + (i / N) * kBlockBytes;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a)
        out[c][a] = std::fma(float(load<uint16_t>(p + row(c, a, i % N))), load<float>(p + kRowsBytes + 4 * a),
                             load<float>(p + kRowsBytes + 12 + 4 * a));
  }
  static bool check(const uint8_t*, uint32_t, uint32_t, std::string*) { return true; }
};

using Float3SOA4 = Float3SOA<4, MC_TRI_FLOAT3SOA4>;
using Float3SOA8 = Float3SOA<8, MC_TRI_FLOAT3SOA8>;
using Float3SOA128 = Float3SOA<128, MC_TRI_FLOAT3SOA128>;
using BitPackSOA4 = BitPackSOA<4, MC_TRI_BITPACKSOA4>;
using BitPackSOA128 = BitPackSOA<128, MC_TRI_BITPACKSOA128>;

}  // namespace meshcast::layout
