// QuadTree (seed 000 §5.6) and QuadTreeHalfFloat (§5.7) nodes: the bounds of
// 4 children in SOA order (MinX[4], MinY[4], MinZ[4], MaxX[4], MaxY[4],
// MaxZ[4]) then NodeProperties[4]. A child property holds 5 bits of triangle
// count (0: a node) over 27 bits of tree-section offset. An unused child has
// an inverted box (min +inf, max -inf) that no ray test accepts.
//
// QuadTreeHalfFloat stores each bound as a half float relative to the tree:
//   bound = half * node_scale + node_origin   (one fma, header fields)
// with node_origin the centre of the root box and node_scale a power of two.
// The source stores absolute halves; relative ones keep their culling power
// for a mesh far from the origin, where absolute halves are coarser than the
// nodes. Minima round down and maxima up after decoding, so the decoded box
// always contains the box that was encoded.
#pragma once
#include <cmath>
#include <cstring>

#include "layout/blob_format.h"
#include "layout/tree/half.h"

namespace meshcast::layout {

struct QuadChild {
  float min[3] = {+INFINITY, +INFINITY, +INFINITY};
  float max[3] = {-INFINITY, -INFINITY, -INFINITY};
  uint32_t properties = 0;
};

inline uint32_t quad_count(uint32_t properties) { return properties >> MC_QUAD_COUNT_SHIFT; }
inline uint32_t quad_offset(uint32_t properties) { return properties & MC_QUAD_OFFSET_MASK; }
inline uint32_t quad_properties(uint32_t count, uint32_t offset) {
  return (count << MC_QUAD_COUNT_SHIFT) | offset;
}

// Bounds codecs: the only thing QuadTree and QuadTreeHalfFloat differ in.
struct QuadBoundsFloat {
  static constexpr uint32_t kFormat = MC_TREE_QUADTREE;
  static constexpr uint32_t kNodeBytes = MC_QUAD_NODE_BYTES;
  static constexpr uint32_t kPropertiesAt = MC_QUAD_PROPERTIES_AT;
  static void encode(const QuadChild c[4], const BlobHeader&, uint8_t* out) {
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < 4; ++k) {
        std::memcpy(out + (axis * 4 + k) * 4, &c[k].min[axis], 4);
        std::memcpy(out + ((3 + axis) * 4 + k) * 4, &c[k].max[axis], 4);
      }
  }
  static void decode(const uint8_t* node, const BlobHeader&, int k, float min[3], float max[3]) {
    for (int axis = 0; axis < 3; ++axis) {
      min[axis] = load<float>(node + (axis * 4 + k) * 4);
      max[axis] = load<float>(node + ((3 + axis) * 4 + k) * 4);
    }
  }
};

struct QuadBoundsHalf {
  static constexpr uint32_t kFormat = MC_TREE_QUADTREEHALFFLOAT;
  static constexpr uint32_t kNodeBytes = MC_QUADHALF_NODE_BYTES;
  static constexpr uint32_t kPropertiesAt = MC_QUADHALF_PROPERTIES_AT;
  static float decode_one(uint16_t h, const BlobHeader& hd, int axis) {
    return std::fma(half_to_float(h), hd.node_scale, hd.node_origin[axis]);
  }
  // Directed rounding of (v - origin) / scale, then corrected until the
  // decode (the walker's fma) lies on the right side of v.
  static uint16_t encode_one(float v, const BlobHeader& hd, int axis, bool up);
  static void encode(const QuadChild c[4], const BlobHeader& hd, uint8_t* out) {
    for (int axis = 0; axis < 3; ++axis)
      for (int k = 0; k < 4; ++k) {
        uint16_t lo = encode_one(c[k].min[axis], hd, axis, false);
        uint16_t hi = encode_one(c[k].max[axis], hd, axis, true);
        std::memcpy(out + (axis * 4 + k) * 2, &lo, 2);
        std::memcpy(out + ((3 + axis) * 4 + k) * 2, &hi, 2);
      }
  }
  static void decode(const uint8_t* node, const BlobHeader& hd, int k, float min[3], float max[3]) {
    for (int axis = 0; axis < 3; ++axis) {
      min[axis] = decode_one(load<uint16_t>(node + (axis * 4 + k) * 2), hd, axis);
      max[axis] = decode_one(load<uint16_t>(node + ((3 + axis) * 4 + k) * 2), hd, axis);
    }
  }
};

inline uint32_t quad_child_properties(const uint8_t* node, uint32_t properties_at, int k) {
  return load<uint32_t>(node + properties_at + 4 * k);
}

}  // namespace meshcast::layout
