// Float3PairSOA4 (seed 003's pair as the unit of storage and of the test):
// blocks of 4 lanes, each lane a triangle pair sharing an edge, or one
// triangle. A lane holds 4 corners A, B, C, D: the first triangle is
// (A, B, C) and the second (B, A, D), so the shared edge A-B is stored once
// and its edge function is computed once for both (cpu/leaf.h). A block:
//   uint32  lanes used (bits 0-3), lanes holding a pair (bits 4-7)
//   rows    A.x A.y A.z B.x ... D.z, 4 floats each (12 rows)
// 196 bytes for up to 8 triangles (24.5 bytes a triangle when all pair,
// Float3SOA4's 36 otherwise: 49 a single). The leaf's triangles are stored
// lane by lane (a lane's first triangle, then its second), corners rotated
// so each pair's shared edge comes first: decode() returns those corners
// and u, v refer to them, as for the strips. Pairs are found in the leaf:
// a triangle takes the first later one sharing an edge in the opposite
// direction (so both keep their winding), singles stay alone; with
// --pairing the builder has put each pair's triangles side by side.
// Used lanes are the first of their block; only the last block has unused.
#pragma once
#include <algorithm>
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "layout/triangles/block.h"

namespace meshcast::layout {

struct Float3PairSOA4 : ReadBack<Float3PairSOA4> {
  static constexpr uint32_t kFormat = MC_TRI_FLOAT3PAIRSOA4;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kLanes = 4;
  static constexpr uint32_t kRowsBytes = 12 * 4 * 4;
  static constexpr uint32_t kBlockBytes = 4 + kRowsBytes;
  static constexpr uint32_t kSlotDivisor = 4;  // slot numbers leave holes; the remap skips them
  static constexpr GridKind kGrid = kGridNone;
  static constexpr bool kPairLanes = true;

  static uint32_t row(int corner, int axis) { return 4 + uint32_t(corner * 3 + axis) * 16; }
  static uint32_t block_bytes(uint32_t count) { return (count + 3) / 4 * kBlockBytes; }  // the worst case: singles

  // The lanes of a leaf: (first, second) positions in `tris`, second = ~0u
  // for a single; the corner rotations that put a shared edge first.
  struct Lane {
    uint32_t first, second;
    int rot_first, rot_second;
  };
  static std::vector<Lane> plan(const TriCorners* tris, uint32_t count) {
    std::vector<Lane> lanes;
    std::vector<bool> used(count, false);
    for (uint32_t i = 0; i < count; ++i) {
      if (used[i]) continue;
      used[i] = true;
      Lane lane{i, ~0u, 0, 0};
      for (uint32_t j = i + 1; j < count && lane.second == ~0u; ++j) {
        if (used[j]) continue;
        // Edge (a, b) of i, k = 0..2, met as (b, a) in j.
        for (int k = 0; k < 3 && lane.second == ~0u; ++k)
          for (int m = 0; m < 3; ++m)
            if (tris[j].vertex[m] == tris[i].vertex[(k + 1) % 3] && tris[j].vertex[(m + 1) % 3] == tris[i].vertex[k]) {
              lane = {i, j, k, m};  // i rotated to start at corner k (A), j at corner m (B)
              used[j] = true;
              break;
            }
      }
      lanes.push_back(lane);
    }
    return lanes;
  }
  static uint32_t measure(TriCorners* tris, uint32_t count) {
    return (uint32_t(plan(tris, count).size()) + 3) / 4 * kBlockBytes;
  }

  static void encode(TriCorners* tris, uint32_t count, BlockContext&, uint8_t* out) {
    std::vector<Lane> lanes = plan(tris, count);
    auto rotated = [](const TriCorners& t, int r) {
      TriCorners o = t;
      for (int c = 0; c < 3; ++c) {
        std::memcpy(o.v[c], t.v[(c + r) % 3], 12);
        o.packed[c] = t.packed[(c + r) % 3], o.vertex[c] = t.vertex[(c + r) % 3];
      }
      return o;
    };
    std::vector<TriCorners> order;
    for (size_t l = 0; l < lanes.size(); ++l) {
      const Lane& lane = lanes[l];
      TriCorners a = rotated(tris[lane.first], lane.rot_first);
      order.push_back(a);
      float corner[4][3];
      std::memcpy(corner, a.v, 36);
      std::memcpy(corner[3], a.v[2], 12);  // a single: D = C, never tested
      if (lane.second != ~0u) {
        TriCorners b = rotated(tris[lane.second], lane.rot_second);  // (B, A, D)
        order.push_back(b);
        std::memcpy(corner[3], b.v[2], 12);
      }
      uint8_t* block = out + (l / 4) * kBlockBytes;
      uint32_t header = load<uint32_t>(block) | 1u << (l % 4) | uint32_t(lane.second != ~0u) << (4 + l % 4);
      std::memcpy(block, &header, 4);
      for (int c = 0; c < 4; ++c)
        for (int a = 0; a < 3; ++a) std::memcpy(block + row(c, a) + 4 * (l % 4), &corner[c][a], 4);
    }
    // Unused lanes of the last block repeat its first lane (kept finite).
    for (size_t l = lanes.size(); l % 4 != 0; ++l) {
      uint8_t* block = out + (l / 4) * kBlockBytes;
      for (int c = 0; c < 4; ++c)
        for (int a = 0; a < 3; ++a) std::memcpy(block + row(c, a) + 4 * (l % 4), block + row(c, a), 4);
    }
    std::copy(order.begin(), order.end(), tris);
  }

  // Walks the blocks of a leaf of `count` triangles: emit(triangle index,
  // corners) for each; returns the bytes, or 0 when the headers do not make
  // exactly `count` triangles within `limit` bytes (used lanes first, pairs
  // only in used lanes, every block but the last full).
  template <class Emit>
  static uint64_t read(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit, Emit&& emit) {
    uint32_t made = 0;
    uint64_t at = 0;
    while (made < count) {
      if (at + kBlockBytes > limit) return 0;
      const uint8_t* p = blob + block + at;
      uint32_t header = load<uint32_t>(p), used = header & 15, paired = header >> 4 & 15;
      if ((header >> 8) != 0 || used == 0 || (used & (used + 1)) != 0 || (paired & ~used) != 0) return 0;
      for (uint32_t l = 0; l < 4 && (used >> l & 1); ++l) {
        float corner[4][3];
        for (int c = 0; c < 4; ++c)
          for (int a = 0; a < 3; ++a) corner[c][a] = load<float>(p + row(c, a) + 4 * l);
        float first[3][3], second[3][3];
        std::memcpy(first, corner, 36);
        std::memcpy(second[0], corner[1], 12), std::memcpy(second[1], corner[0], 12), std::memcpy(second[2], corner[3], 12);
        if (made >= count) return 0;
        emit(made++, first);
        if (paired >> l & 1) {
          if (made >= count) return 0;
          emit(made++, second);
        }
      }
      at += kBlockBytes;
      if (made < count && used != 15) return 0;
    }
    return at;
  }
};

}  // namespace meshcast::layout
