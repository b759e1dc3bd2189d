// OctTreeCompressed nodes (formats.h gives the bits): 8 child boxes in 8-bit
// codes on a per-axis power-of-two frame. The frame is chosen so the decode
// Origin + q * 2^e is exact in float for every code: a minimum coded down and
// a maximum coded up then bound the child exactly as the writer meant, on
// every walker and shader, whatever the distance from the origin.
//
// The header's node_origin[a] holds the largest |Origin| of axis a over the
// nodes and node_scale the largest 2^e of any axis (0 where the root is a
// leaf): the CPU walker's fused box test (cpu/walk_octtree.cpp) bounds its
// rounding with them, and validation checks every node against them.
#pragma once
#include <bit>
#include <cmath>
#include <cstdint>

#include "layout/blob_format.h"

namespace meshcast::layout {

inline uint32_t oct_count(uint32_t properties) { return properties >> MC_OCT_COUNT_SHIFT; }
inline uint32_t oct_offset(uint32_t properties) { return (properties & MC_OCT_OFFSET_MASK) * MC_OCT_OFFSET_UNIT; }
inline uint32_t oct_properties(uint32_t count, uint32_t offset) {
  return count << MC_OCT_COUNT_SHIFT | offset / MC_OCT_OFFSET_UNIT;
}

// 2^(byte - 127): the byte is the float's own exponent field (1..254).
inline float oct_scale(uint8_t exponent) { return std::bit_cast<float>(uint32_t(exponent) << 23); }

// One axis of a node's frame.
struct OctFrame {
  float origin = 0;
  uint8_t exponent = 127;
};

// The frame of an axis whose children span [lo, hi]: the smallest 2^e with
// 255 steps from a multiple of 2^e at or below lo reaching hi, and every
// value on the way a float. Throws InputError past 2^127.
OctFrame oct_frame(float lo, float hi);

// The code of v in a frame: the largest q whose decode is at most v (a
// minimum), or the smallest at least v (a maximum), within 0..255.
uint8_t oct_code(float v, const OctFrame& f, bool up);

inline float oct_decode(uint32_t q, float origin, float scale) { return std::fma(float(q), scale, origin); }

inline uint32_t oct_child_properties(const uint8_t* node, int k) {
  return load<uint32_t>(node + MC_OCT_PROPERTIES_AT + 4 * k);
}

// Child k's decoded box.
inline void oct_child_box(const uint8_t* node, int k, float min[3], float max[3]) {
  for (int a = 0; a < 3; ++a) {
    const float origin = load<float>(node + MC_OCT_ORIGIN_AT + 4 * a);
    const float scale = oct_scale(node[MC_OCT_EXPONENTS_AT + a]);
    min[a] = oct_decode(node[MC_OCT_QLO_AT + 8 * a + k], origin, scale);
    max[a] = oct_decode(node[MC_OCT_QHI_AT + 8 * a + k], origin, scale);
  }
}

}  // namespace meshcast::layout
