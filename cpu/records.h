// BruteForce records [count][block] from tree-section offset `at` to `end`,
// tested in order through the leaf test every tree uses, which also tells
// each block's length: the whole of a BruteForce walk, and one batch of an
// AABBList walk.
#pragma once
#include "layout/triangles/codecs.h"
#include "cpu/walk.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
inline void test_records(const uint8_t* blob, const layout::BlobHeader& h, const RayPre& r, uint32_t at,
                         uint32_t end, Closest& c) {
  while (at < end && c.t >= 0) {  // below 0: an any-hit query has its hit
    uint32_t count = layout::load<uint32_t>(blob + h.tree_offset + at);
    uint32_t block = at + MC_BRUTE_RECORD_BYTES;
    at = block + uint32_t(test_leaf<Codec, kTest>(blob, r, h.tree_offset + block, count, layout::slot_of(h, block, 0), c));
  }
}

MC_ISA_END
}  // namespace meshcast
