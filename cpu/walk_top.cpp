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

// Node n's 8 slots against [0, cut]: the entered slots' contents and entry
// distances to children[] and entries[] farthest first, the nearest last
// (up to 8 of each written); returns how many were entered. An entry may be
// rounded down by a few ulps (it only ever culls, so it culls no more).
[[gnu::always_inline]] inline int enter_node(const TopRay& r, const layout::TopWideNode& n, float cut, float* entries,
                                             uint32_t* children) {
  using simd::F8;
  F8 tn = F8::splat(0.0f), tf = F8::splat(cut);
  const F8 pad = F8::splat(r.pad);
  for (int a = 0; a < 3; ++a) {
    const F8 rel = F8::splat(r.rel[a]), inv = F8::splat(r.inv[a]);
    const F8 t0 = (F8::load(n.lo[a]) - pad - rel) * inv, t1 = (F8::load(n.hi[a]) + pad - rel) * inv;
    tn = simd::max(r.negative[a] ? t1 : t0, tn);
    tf = simd::min(r.negative[a] ? t0 : t1, tf);
  }
  const int bits = simd::bits(tn <= tf);
  if (bits == 0) return 0;
  if ((bits & (bits - 1)) == 0) {  // one slot (the commonest): no sort
    alignas(32) float entry[8];
    tn.store(entry);
    const int k = __builtin_ctz(unsigned(bits));
    entries[0] = entry[k], children[0] = n.slot[k];
    return 1;
  }
  simd::order_hits(tn, bits, reinterpret_cast<const uint8_t*>(n.slot), entries, children);
  return std::popcount(unsigned(bits));
}

}  // namespace

void walk_top(const layout::TopLevel& top, const TopRay& r, float tmax, uint8_t mask, VisitInstanceFn visit,
              void* context) {
  float cut = tmax;
  // A wide node leaves at most 7 entries behind a level, and the binary
  // tree under it is at most 64 deep (median splits of fewer than 2^32);
  // a node's test writes 8 past the top: the stack cannot fill.
  constexpr int kStack = 7 * 64 + 8;
  uint32_t stack[kStack];
  float entries[kStack];
  int top_of = 0;
  stack[top_of] = 0, entries[top_of++] = 0;  // the root node
  const float widen = 1 + float(MC_TOP_BOX_SLACK);
  while (top_of > 0) {
    --top_of;
    if (entries[top_of] > cut * widen) continue;
    const uint32_t item = stack[top_of];
    if (item & layout::kTopInstance) {
      const uint32_t placed = item & ~layout::kTopInstance;
      if ((top.placed[placed].mask & mask) == 0) continue;
      cut = visit(context, placed, cut);
      if (cut < 0) return;
      continue;
    }
    // The entered slots go on the stack farthest first: the nearest is
    // popped next.
    top_of += enter_node(r, top.wide[item], cut * widen, entries + top_of, stack + top_of);
  }
}

MC_ISA_END
}  // namespace meshcast
