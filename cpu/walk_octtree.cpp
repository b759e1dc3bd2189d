// OctTreeCompressed walker (issue 19): the 8 child boxes of a node decoded
// (one exact fma a plane) and tested at once, the near and far planes picked
// by the ray's direction signs; one hit child is walked next without touching
// the stack, several are pushed farthest first with their entry distances,
// and popped entries are skipped once the closest hit is nearer.
#include "cpu/walk.h"
#include "layout/codecs.h"
#include "layout/octtree.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

// 7 entries a level at most stay behind on the stack (8 hit, 1 walked on).
constexpr int kStackSize = 7 * MC_MAX_DEPTH + 8;

// Entry distances of the 8 children, +inf for a child the ray misses.
inline simd::F8 oct_box_test(const uint8_t* node, const RayPre& r, float closest) {
  count_boxes(8);
  using simd::F8;
  F8 tn = F8::splat(0.0f), tf = F8::splat(INFINITY);
  for (int a = 0; a < 3; ++a) {
    const F8 origin = F8::splat(layout::load<float>(node + MC_OCT_ORIGIN_AT + 4 * a));
    const F8 scale = F8::splat(layout::oct_scale(node[MC_OCT_EXPONENTS_AT + a]));
    const uint8_t* near_row = node + (r.near_is_max[a] ? MC_OCT_QHI_AT : MC_OCT_QLO_AT) + 8 * a;
    const uint8_t* far_row = node + (r.near_is_max[a] ? MC_OCT_QLO_AT : MC_OCT_QHI_AT) + 8 * a;
    const F8 o = F8::splat(r.org[a]), inv = F8::splat(r.inv[a]);
    tn = simd::max((simd::fma(simd::from_u8x8(near_row), scale, origin) - o) * inv, tn);
    tf = simd::min((simd::fma(simd::from_u8x8(far_row), scale, origin) - o) * inv, tf);
  }
  tf = simd::min(tf, F8::splat(closest)) * F8::splat(kFarScale);
  return simd::select(tn <= tf, tn, F8::splat(INFINITY));
}

}  // namespace

template <class Codec>
void walk(layout::tree::OctTreeCompressed, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
          uint32_t outputs) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, outputs, [&](const RayPre& r, Closest& c) {
    uint32_t node_stack[kStackSize];
    float entry_stack[kStackSize];
    int top = 0;
    uint32_t properties = h.root;
    for (;;) {
      const uint32_t count = layout::oct_count(properties), offset = layout::oct_offset(properties);
      if (count == 0) {
        const uint8_t* node = tree + offset;
        const simd::F8 entry = oct_box_test(node, r, c.t);
        int hit = simd::bits(entry != simd::F8::splat(INFINITY)) & simd::nonzero_bits8(node + MC_OCT_PROPERTIES_AT);
        if (hit) {
          // Ask for every hit child's first lines now: the one walked next is
          // needed at once, the others by the time they are popped.
          for (int m = hit; m; m &= m - 1) {
            const uint32_t p = layout::oct_child_properties(node, __builtin_ctz(unsigned(m)));
            const uint8_t* child = tree + layout::oct_offset(p);
            __builtin_prefetch(child);
            __builtin_prefetch(child + 64);
            if (layout::oct_count(p)) __builtin_prefetch(child + 128), __builtin_prefetch(child + 192);
          }
          alignas(32) float e[8];
          entry.store(e);
          if ((hit & (hit - 1)) == 0) {  // one child: walk it next, no stack traffic
            properties = layout::oct_child_properties(node, __builtin_ctz(unsigned(hit)));
            continue;
          }
          // Push the hit children farthest first (insertion into the stack's
          // top, at most 8), then walk the nearest.
          const int base = top;
          for (; hit; hit &= hit - 1) {
            const int k = __builtin_ctz(unsigned(hit));
            const float d = e[k];
            const uint32_t p = layout::oct_child_properties(node, k);
            int j = top++;
            while (j > base && entry_stack[j - 1] < d) entry_stack[j] = entry_stack[j - 1], node_stack[j] = node_stack[j - 1], --j;
            entry_stack[j] = d, node_stack[j] = p;
          }
          properties = node_stack[--top];
          continue;
        }
      } else {
        test_leaf<Codec>(blob, r, h.tree_offset + offset, count, layout::slot_of(h, offset, 0), c);
      }
      do {
        if (top == 0) return;
        --top;
      } while (entry_stack[top] > c.t * kFarScale);
      properties = node_stack[top];
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec>(layout::tree::OctTreeCompressed, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, uint32_t);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)
#undef MC_INSTANTIATE

MC_ISA_END
}  // namespace meshcast
