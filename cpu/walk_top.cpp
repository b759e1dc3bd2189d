// walk_top (cpu/walk_top.h) for one instruction set: a node's 8 slots in
// one register of 8 lanes (AVX2, AVX-512) or 8 scalar lanes. Near and far
// planes go by the direction's sign, so a zero component gives -inf or +inf
// on the right sides, and NaN (0 * inf) only for a ray in a slab's plane,
// which min and max drop (they keep their second operand on NaN, as the
// walkers' box tests do): the closed box holds that ray.
#include <bit>

#include "cpu/simd.h"
#include "cpu/walk_top.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

// Node n's 8 slots against [0, cut]: the entered ones as bits. Each plane
// is one subtraction (its shift rounded once: the pad, 2^-16 of the scene,
// dwarfs that) and one product; `entry` holds the entry distances. An entry
// may be rounded down by a few ulps (it only ever culls, so it culls no
// more).
[[gnu::always_inline]] inline int enter_node(const TopRay& r, const layout::TopWideNode& n, float cut,
                                             simd::F8& entry) {
  using simd::F8;
  const auto* bytes = reinterpret_cast<const uint8_t*>(&n);
  F8 tn = F8::splat(0.0f), tf = F8::splat(cut);
  for (int a = 0; a < 3; ++a) {
    const F8 inv = F8::splat(r.inv[a]);
    const F8 near = (F8::load(reinterpret_cast<const float*>(bytes + r.near_at[a])) - F8::splat(r.near_shift[a])) * inv;
    const F8 far = (F8::load(reinterpret_cast<const float*>(bytes + r.far_at[a])) - F8::splat(r.far_shift[a])) * inv;
    tn = simd::max(near, tn);
    tf = simd::min(far, tf);
  }
  entry = tn;
  return simd::bits(tn <= tf);
}

}  // namespace

void walk_top(const layout::TopLevel& top, const TopRay& r, float tmax, uint8_t mask, VisitInstanceFn visit,
              void* context) {
  float cut = tmax;
  // The stack cannot fill (MC_TOP_MAX_DEPTH, layout/formats.h).
  constexpr int kStack = 7 * int(MC_TOP_MAX_DEPTH) + 8;
  uint32_t stack[kStack];
  float entries[kStack];
  int top_of = 0;
  const float widen = 1 + float(MC_TOP_BOX_SLACK);
  uint32_t item = 0;  // the root node
  for (;;) {
    if (item & layout::kTopInstance) {
      const uint32_t placed = item & ~layout::kTopInstance;
      if (top.placed[placed].mask & mask) {
        cut = visit(context, placed, cut);
        if (cut < 0) return;
      }
    } else {
      const layout::TopWideNode& n = top.wide[item];
      simd::F8 entry;
      const int bits = enter_node(r, n, cut * widen, entry);
      if (bits != 0 && (bits & (bits - 1)) == 0) {  // one slot (the commonest): walked next, no stack traffic
        item = n.slot[__builtin_ctz(unsigned(bits))];
        continue;
      }
      // Several: on the stack farthest first, the nearest popped next.
      if (bits != 0) {
        simd::order_hits(entry, bits, reinterpret_cast<const uint8_t*>(n.slot), entries + top_of, stack + top_of);
        top_of += std::popcount(unsigned(bits));
      }
    }
    do {
      if (top_of == 0) return;
      --top_of;
    } while (entries[top_of] > cut * widen);
    item = stack[top_of];
  }
}

MC_ISA_END
}  // namespace meshcast
