// AABBTreeCompressed (seed 000 §5.4): 12-byte nodes whose two child boxes
// are coded relative to the parent's decoded box (formats.h gives the bits).
// Decoding runs top down, each box from its parent's decoded box, with this
// one function in the writer and every reader, so the writer can choose
// each code knowing exactly what the walker will decode: minima round down
// and maxima up, and every decoded box contains the triangles below it.
#pragma once
#include <cstdint>

#include "layout/blob_format.h"

namespace meshcast::layout {

struct CompressedBox {
  float min[3], max[3];
};

// What code q of [lo, hi] decodes to: lo + q * step, with q = 127 landing on
// hi itself (so the largest code always covers the parent's max).
inline float compressed_value(float lo, float hi, uint32_t q) {
  float step = (hi - lo) * (1.0f / float(MC_COMPRESSED_STEPS));
  return q >= MC_COMPRESSED_STEPS ? hi : lo + float(q) * step;
}

struct CompressedNode {
  uint32_t bounds_min, bounds_max, right;

  uint32_t left_count() const { return bounds_min >> MC_COMPRESSED_COUNT_SHIFT; }
  uint32_t right_count() const { return bounds_max >> MC_COMPRESSED_COUNT_SHIFT; }

  // The two child boxes of a node whose decoded box is `parent`.
  // Always inlined: the walkers of every instruction set call it, and an
  // out-of-line copy compiled for a wide set could stand in for the
  // baseline one (tests/isa_symbols_test.sh).
  [[gnu::always_inline]] void unpack(const CompressedBox& parent, CompressedBox& left, CompressedBox& right) const {
    left = parent, right = parent;
    for (int a = 0; a < 3; ++a) {
      float lo = compressed_value(parent.min[a], parent.max[a], bounds_min >> (7 * a) & 127);
      float hi = compressed_value(parent.min[a], parent.max[a], bounds_max >> (7 * a) & 127);
      bool min_right = bounds_min >> (MC_COMPRESSED_SIDE_SHIFT + a) & 1;
      bool max_right = bounds_max >> (MC_COMPRESSED_SIDE_SHIFT + a) & 1;
      (min_right ? right : left).min[a] = lo;
      (max_right ? right : left).max[a] = hi;
    }
  }
};
static_assert(sizeof(CompressedNode) == MC_COMPRESSED_NODE_BYTES);

inline CompressedBox compressed_root_box(const uint8_t* tree) { return load<CompressedBox>(tree); }
inline uint32_t compressed_root_count(const uint8_t* tree) { return load<uint32_t>(tree + MC_COMPRESSED_ROOT_COUNT_AT); }

// The code of one changed value v inside [lo, hi] decoded: the largest q
// decoding to at most v (a minimum), or the smallest decoding to at least v
// (a maximum). q = 0 decodes to lo and q = 127 to hi, so one always exists
// when lo <= v <= hi.
inline uint32_t compressed_code(float lo, float hi, float v, bool up) {
  if (!(hi > lo)) return 0;  // a flat box: every code decodes to lo
  double f = (double(v) - lo) / (double(hi) - lo) * MC_COMPRESSED_STEPS;
  int q = f <= 0 ? 0 : f >= MC_COMPRESSED_STEPS ? int(MC_COMPRESSED_STEPS) : int(f);
  if (up) {
    while (q > 0 && compressed_value(lo, hi, uint32_t(q - 1)) >= v) --q;
    while (q < int(MC_COMPRESSED_STEPS) && compressed_value(lo, hi, uint32_t(q)) < v) ++q;
  } else {
    while (q < int(MC_COMPRESSED_STEPS) && compressed_value(lo, hi, uint32_t(q + 1)) <= v) ++q;
    while (q > 0 && compressed_value(lo, hi, uint32_t(q)) > v) --q;
  }
  return uint32_t(q);
}

}  // namespace meshcast::layout
