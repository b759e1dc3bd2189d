// An OctTreeCompressed node's 8 child boxes decoded in 8 lanes, a child a
// lane, for the walks that need the bounds themselves (a packet of rays,
// a point): Origin + q 2^e, a float by the format's rule
// (layout/tree/octtree.h), so the product and the sum are exact and need
// no fused multiply-add (which the scalar set would call from the maths
// library).
#pragma once
#include "cpu/simd.h"
#include "layout/tree/octtree.h"

namespace meshcast {
MC_ISA_BEGIN

[[gnu::always_inline]] inline void decode_oct_children(const uint8_t* node, simd::F8 lo[3], simd::F8 hi[3]) {
  using simd::F8;
  for (int a = 0; a < 3; ++a) {
    const F8 origin = F8::splat(layout::load<float>(node + MC_OCT_ORIGIN_AT + 4 * a));
    const F8 scale = F8::splat(layout::oct_scale(node[MC_OCT_EXPONENTS_AT + a]));
    lo[a] = simd::from_u8x8(node + MC_OCT_QLO_AT + 8 * a) * scale + origin;
    hi[a] = simd::from_u8x8(node + MC_OCT_QHI_AT + 8 * a) * scale + origin;
  }
}

MC_ISA_END
}  // namespace meshcast
