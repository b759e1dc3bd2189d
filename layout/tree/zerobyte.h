// Zero-byte trees (seed 004, see formats.h for the bits): the triangle
// section is the mesh's own index buffer, reordered so nodes sit on the
// triangles that bound them, with the tree in the top byte of each index.
//   ZeroByteTree/Indexed24    one zero-byte tree over the whole mesh
//   ZeroByteHybrid/Indexed24  AABBTree nodes (aabbtree.h) whose leaves are
//                             zero-byte trees: a leaf's value is the
//                             position of its tree's root
// Vertices: the mesh's own, 3 floats each, in input order.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstring>

#include <functional>
#include <string>
#include <vector>

#include "layout/blob_format.h"
#include "layout/tree/leaves.h"

namespace meshcast::layout {

// The triangle format: what every reader of a triangle sees (the index
// bits alone).
struct Indexed24 {
  static constexpr uint32_t kFormat = MC_TRI_INDEXED24;
  static constexpr uint32_t kSlotDivisor = 12;
  static uint32_t word(const uint8_t* tris, uint32_t i, int c) { return load<uint32_t>(tris + (uint64_t(i) * 3 + c) * 4); }
  static uint32_t index(const uint8_t* blob, uint32_t block, uint32_t i, int c) {
    return word(blob + block, i, c) & MC_ZBT_INDEX_MASK;
  }
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]) {
    const BlobHeader& h = header_of(blob);
    for (int c = 0; c < 3; ++c) std::memcpy(out[c], blob + h.vertex_offset + uint64_t(index(blob, block, i, c)) * 12, 12);
  }
};

struct ZbtNode {
  uint32_t child;  // first child's position, 0 for a leaf
  uint32_t count;  // triangles at the node
};

// `tris` points at the zero-byte tree's root triangle.
inline ZbtNode zbt_node(const uint8_t* tris, uint32_t p) {
  uint32_t bits = Indexed24::word(tris, p, 0) >> 24 | (Indexed24::word(tris, p, 1) >> 24) << 8 |
                  (Indexed24::word(tris, p, 2) >> 24) << 16;
  return {bits & MC_ZBT_CHILD_MASK, bits >> MC_ZBT_CHILD_BITS};
}
inline uint32_t zbt_pns(const uint8_t* tris, uint32_t p) { return Indexed24::word(tris, p + 1, 0) >> 24; }
inline bool zbt_shuffled(const uint8_t* tris, uint32_t p) { return (Indexed24::word(tris, p + 1, 1) >> 24) & 1; }
// Shuffled node: the corner of triangle P + j that gives extreme j.
inline uint32_t zbt_corner(const uint8_t* tris, uint32_t p, int j) {
  uint32_t sel = (Indexed24::word(tris, p + 1, 1) >> 25 & 0x3F) | (Indexed24::word(tris, p + 1, 2) >> 24 & 0x3F) << 6;
  return sel >> (2 * j) & 3;
}

// The node's box, from the vertices its triangles name. A shuffled node
// reads one named corner a triangle (6 vertices); any other every corner.
inline void zbt_box(const uint8_t* tris, const uint8_t* vertices, uint32_t p, ZbtNode n, float mn[3], float mx[3]) {
  auto vertex = [&](uint32_t i, int c) {
    return reinterpret_cast<const float*>(vertices + uint64_t(Indexed24::word(tris, p + i, c) & MC_ZBT_INDEX_MASK) * 12);
  };
  if (n.count == 6 && zbt_shuffled(tris, p)) {
    for (int a = 0; a < 3; ++a)
      mn[a] = vertex(uint32_t(a), int(zbt_corner(tris, p, a)))[a], mx[a] = vertex(uint32_t(a) + 3, int(zbt_corner(tris, p, a + 3)))[a];
    return;
  }
  for (int a = 0; a < 3; ++a) mn[a] = INFINITY, mx[a] = -INFINITY;
  for (uint32_t i = 0; i < n.count; ++i)
    for (int c = 0; c < 3; ++c) {
      const float* v = vertex(i, c);
      for (int a = 0; a < 3; ++a) mn[a] = std::min(mn[a], v[a]), mx[a] = std::max(mx[a], v[a]);
    }
}

// Visits every node of the zero-byte tree whose root triangle sits at
// tree-section offset `root` (validated blob), parents first: (its
// position, the node, the boxes the walker tests from the blob's root down
// to it: `path` on entry, then every interior node's own box).
void for_each_zbt_node(const uint8_t* blob, uint32_t root, std::vector<PathBox> path,
                       const std::function<void(uint32_t p, ZbtNode n, const std::vector<PathBox>& path)>& visit);

// Validation of both zero-byte formats (called by validate()): "" or why not.
std::string validate_zerobyte(std::span<const uint8_t> blob, const BlobHeader& h);

}  // namespace meshcast::layout
