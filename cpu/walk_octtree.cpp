// OctTreeCompressed walker: the 8 child boxes of a node tested
// at once, one fma a plane (the fused form below; the exact decode where a
// ray needs it), near and far planes picked by the ray's direction signs;
// one hit child is walked next without touching the stack, several are
// pushed farthest first with their entry distances, and popped entries are
// skipped once the closest hit is nearer. Every hit child's first lines are
// asked for when its parent is tested.
#include <algorithm>
#include <bit>
#include <cfloat>
#include <cmath>

#include "cpu/oct_children.h"
#include "cpu/walk.h"
#include "layout/triangles/codecs.h"
#include "layout/tree/octtree.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

// 7 entries a level at most stay behind on the stack (8 hit, 1 walked on).
constexpr int kStackSize = 7 * MC_MAX_DEPTH + 8;

// Where a ray finds each axis's near and far row of child codes in a node:
// the QLo row for a positive direction, QHi for a negative one (as the box
// test's near_is_max). Worked out once a ray, so the node test takes its rows
// by offset and has no branch on the direction (a branch there was a fifth
// of the walk's mispredictions).
struct OctRows {
  uint32_t near_at[3], far_at[3];
  explicit OctRows(const RayPre& r) {
    for (int a = 0; a < 3; ++a) {
      const uint32_t hi = uint32_t(r.near_is_max[a] != 0);
      near_at[a] = MC_OCT_QLO_AT + hi * (MC_OCT_QHI_AT - MC_OCT_QLO_AT) + 8 * uint32_t(a);
      far_at[a] = MC_OCT_QHI_AT - hi * (MC_OCT_QHI_AT - MC_OCT_QLO_AT) + 8 * uint32_t(a);
    }
  }
};

// The node test's two forms. The exact form decodes each plane (exact),
// subtracts the ray origin and multiplies by the inverse direction: four
// dependent operations a plane, each rounded relative to the distance, which
// kFarScale (Ize) covers. The fused form writes the same distance as
//   (Origin + q 2^e - o) inv  =  q (2^e inv) + (Origin inv - o inv)
// and takes one fma a plane once the node's three axis terms are formed:
// 2^e inv is exact (a power of two times inv, unless it falls below FLT_MIN),
// and Origin inv - o inv is one fma from -(o inv) -+ pad, which a ray forms
// once (two roundings). Those terms are rounded relative to |Origin inv| and
// |o inv|, not to the distance (they may nearly cancel): together at most
// u |Origin inv| + 3u |o inv| and a little (u = 2^-24). The header bounds
// |Origin| over the blob's nodes (its reach, checked node by node when the
// blob is validated), so one pad a ray covers them: near planes are moved
// nearer and far planes farther by 4u (reach + |o|) |inv|, at least FLT_MIN,
// which also covers what underflow loses on the way (at most 256 2^-150
// from a product below FLT_MIN). What rounding is left is relative to the
// distance, as in the exact form, and kFarScale covers it: the box stays
// conservative. In space the pad is 2^-22 of reach + |o|, a few ulps of the
// coordinates (a node's quantization step is 2^-8 of its extent). A ray
// takes the fused form where no term can overflow: 2^-40 <= |inv| <= 2^40
// and |o| <= 2^40, on a blob whose reach and largest scale are at most 2^40.
// Otherwise, and for a zero direction component (an infinite inverse, which
// the exact form's NaN rule handles), the exact form.
// The magnitudes past which a ray or blob takes the exact form.
constexpr float kFusedBig = 0x1p40f, kFusedSmall = 0x1p-40f;
struct OctFused {
  bool applies = false;
  float near_bias[3], far_bias[3];  // -(o inv) -+ pad
  // `blob_fits`: the blob's reach and largest scale are at most 2^40.
  OctFused(const RayPre& r, const layout::BlobHeader& h, bool blob_fits) {
    applies = blob_fits;
    for (int a = 0; a < 3; ++a) {
      const float inv = std::fabs(r.inv[a]);
      applies &= inv <= kFusedBig && inv >= kFusedSmall && std::fabs(r.org[a]) <= kFusedBig;
    }
    if (!applies) return;
    for (int a = 0; a < 3; ++a) {
      // (reach + |o|) |inv| first: scaled by 2^-22 last, it cannot underflow.
      const float pad = std::max((h.node_origin[a] + std::fabs(r.org[a])) * std::fabs(r.inv[a]) * 0x1p-22f, FLT_MIN);
      const float o_inv = r.org[a] * r.inv[a];
      near_bias[a] = -o_inv - pad;
      far_bias[a] = -o_inv + pad;
    }
  }
  static bool blob_fits(const layout::BlobHeader& h) {
    return h.node_origin[0] <= kFusedBig && h.node_origin[1] <= kFusedBig && h.node_origin[2] <= kFusedBig &&
           h.node_scale <= kFusedBig;
  }
};

// The 8 children's entry distances and which of them the ray hits. The
// distances of each axis are taken together as trees, not one axis after
// another, and the hits come from the comparisons themselves: the walk waits
// on this test node after node, so its chain of dependent instructions is
// kept short. In the exact form min/max keep their second operand on NaN
// (see cpu/intersect.h), and each axis meets a constant first, so a NaN slab
// still constrains nothing; the fused form has no NaN or infinity but the
// closest hit's cut (every term finite), so its reduction is one level
// shorter.
struct OctHits {
  simd::F8 entry;  // meaningful in the hit lanes only
  int bits;
};
template <bool Fused>
inline OctHits oct_box_test(const uint8_t* node, const RayPre& r, const OctRows& rows, const OctFused& fused,
                            float closest) {
  count_node(8);
  using simd::F8;
  F8 tn[3], tf[3];
  const F8 zero = F8::splat(0.0f), cut = F8::splat(closest);
  for (int a = 0; a < 3; ++a) {
    const F8 origin = F8::splat(layout::load<float>(node + MC_OCT_ORIGIN_AT + 4 * a));
    const F8 scale = F8::splat(layout::oct_scale(node[MC_OCT_EXPONENTS_AT + a]));
    const F8 inv = F8::splat(r.inv[a]);
    const F8 near_q = simd::from_u8x8(node + rows.near_at[a]), far_q = simd::from_u8x8(node + rows.far_at[a]);
    if constexpr (Fused) {
      const F8 step = scale * inv;
      tn[a] = simd::fma(near_q, step, simd::fma(origin, inv, F8::splat(fused.near_bias[a])));
      tf[a] = simd::fma(far_q, step, simd::fma(origin, inv, F8::splat(fused.far_bias[a])));
    } else {
      const F8 o = F8::splat(r.org[a]);
      tn[a] = simd::max((simd::fma(near_q, scale, origin) - o) * inv, zero);
      tf[a] = simd::min((simd::fma(far_q, scale, origin) - o) * inv, cut);
    }
  }
  F8 entry, exit;
  if constexpr (Fused) {
    entry = simd::max(simd::max(tn[0], tn[1]), simd::max(tn[2], zero));
    exit = simd::min(simd::min(tf[0], tf[1]), simd::min(tf[2], cut)) * F8::splat(kFarScale);
    return {entry, simd::bits(entry <= exit) & simd::nonzero_bits8(node + MC_OCT_PROPERTIES_AT)};
  } else {
    entry = simd::max(simd::max(tn[0], tn[1]), tn[2]);
    exit = simd::min(simd::min(tf[0], tf[1]), tf[2]) * F8::splat(kFarScale);
    // An entry of +inf is a miss even where the exit is +inf too (a slab the
    // ray never reaches along a zero direction, with no hit yet).
    const F8 inf = F8::splat(INFINITY);
    return {entry, simd::bits((entry <= exit) & (entry < inf)) & simd::nonzero_bits8(node + MC_OCT_PROPERTIES_AT)};
  }
}

// Asks for a child's first four lines: a node's (96 bytes: two or three
// lines) and what follows, or a leaf's first four (leaves span three to
// four). No branch on which it is.
inline void prefetch_child(const uint8_t* child) {
  __builtin_prefetch(child);
  __builtin_prefetch(child + 64);
  __builtin_prefetch(child + 128);
  __builtin_prefetch(child + 192);
}

// One ray's walk with the node test's exact or fused form. `Any`
// (Query::Any, the query as a template parameter): hit children are pushed
// as they come, unsorted and without their entries (nothing is culled on
// popping before the first hit, and the walk ends at that hit), as
// Embree's any-hit traversal does.
template <class Codec, TriangleTest kTest, bool Fused, bool Any>
inline void walk_ray(const uint8_t* blob, const layout::BlobHeader& h, const RayPre& r, const OctFused& fused,
                     Closest& c) {
  const uint8_t* tree = blob + h.tree_offset;
  const OctRows rows(r);
  uint32_t node_stack[kStackSize];
  float entry_stack[kStackSize];
  int top = 0;
  uint32_t properties = h.root;
  for (;;) {
    const uint32_t count = layout::oct_count(properties), offset = layout::oct_offset(properties);
    if (count == 0) {
      const uint8_t* node = tree + offset;
      const OctHits test = oct_box_test<Fused>(node, r, rows, fused, c.t);
      int hit = test.bits;
      if (hit) {
        int k = __builtin_ctz(unsigned(hit));
        properties = layout::oct_child_properties(node, k);
        prefetch_child(tree + layout::oct_offset(properties));
        hit &= hit - 1;
        if (hit == 0) continue;  // one child: walk it next, no stack traffic
        if constexpr (Any) {
          // The nearest walked next (a hit is likeliest there), the others
          // pushed as they come.
          float entry[8];
          test.entry.store(entry);
          int nearest = k;
          for (int m = hit; m; m &= m - 1) nearest = entry[__builtin_ctz(unsigned(m))] < entry[nearest] ? __builtin_ctz(unsigned(m)) : nearest;
          for (int m = test.bits & ~(1 << nearest); m; m &= m - 1) {
            const uint32_t child = layout::oct_child_properties(node, __builtin_ctz(unsigned(m)));
            prefetch_child(tree + layout::oct_offset(child));
            node_stack[top++] = child;
          }
          properties = layout::oct_child_properties(node, nearest);
          continue;
        }
        // Two: the farther pushed with
        // its entry, the nearer walked next (the lower lane on an exact
        // tie), without the sorting network's cost. order_hits ranks
        // entries within 8 ulps by lane instead; the walk's order changes
        // no answer (Closest::offer breaks equal t by slot).
        if ((hit & (hit - 1)) == 0) {
          const int j = __builtin_ctz(unsigned(hit));
          prefetch_child(tree + layout::oct_offset(layout::oct_child_properties(node, j)));
          float entry[8];
          test.entry.store(entry);
          const bool j_nearer = entry[j] < entry[k];
          const int far = j_nearer ? k : j;
          entry_stack[top] = entry[far];
          node_stack[top++] = layout::oct_child_properties(node, far);
          if (j_nearer) properties = layout::oct_child_properties(node, j);
          continue;
        }
        // More: pushed farthest first with their entry distances (sorted
        // in registers), each one's lines asked for now, to be there when it
        // is popped; the nearest is walked next.
        do {
          prefetch_child(tree + layout::oct_offset(layout::oct_child_properties(node, __builtin_ctz(unsigned(hit)))));
          hit &= hit - 1;
        } while (hit);
        properties = simd::order_hits(test.entry, test.bits, node + MC_OCT_PROPERTIES_AT, entry_stack + top, node_stack + top);
        top += std::popcount(unsigned(test.bits)) - 1;
        continue;
      }
    } else {
      test_leaf<Codec, kTest>(blob, r, h.tree_offset + offset, count, layout::slot_of(h, offset, 0), c);
      if (Any && c.slot != MC_NO_HIT) return;
    }
    if constexpr (Any) {
      if (top == 0) return;
      properties = node_stack[--top];
      continue;
    }
    do {
      if (top == 0) return;
      --top;
    } while (entry_stack[top] > c.t * kFarScale);
    properties = node_stack[top];
  }
}

// One ray's walk, in the node test's fused form where it applies.
template <class Codec, TriangleTest kTest>
inline void walk_one(const uint8_t* blob, const layout::BlobHeader& h, const RayPre& r, Closest& c) {
  const OctFused fused(r, h, OctFused::blob_fits(h));
  if (c.any) {
    if (fused.applies) walk_ray<Codec, kTest, true, true>(blob, h, r, fused, c);
    else walk_ray<Codec, kTest, false, true>(blob, h, r, fused, c);
  } else {
    if (fused.applies) walk_ray<Codec, kTest, true, false>(blob, h, r, fused, c);
    else walk_ray<Codec, kTest, false, false>(blob, h, r, fused, c);
  }
}

// Packets: up to kPacketRays rays of one origin walked together, each node
// decoded once for all of them. Where the rays share their origin, a child
// plane's distance along each ray is (plane - o) / d: the decode and the
// subtraction are the packet's, one multiply a plane is each ray's. That is
// the exact form's arithmetic operation for operation, so each ray's hit
// children are those its exact test finds (conservative, as the fused
// form's). The packet walks the children any of its rays hits, nearest first
// by the least entry among them, each with the mask of those rays; a leaf is
// tested for those rays alone, each with its own cut, by the leaf test a
// single walk makes. A ray thus tests every triangle its single walk would
// need to and answers the same: the closest hit, ties to the lower slot
// (Closest::offer), whatever order the leaves come in.
constexpr int kPacketRays = 8;

// Bit j of byte i to bit i of byte j: the packet's rays' hit children to
// each child's rays.
inline uint64_t transpose_bits8x8(uint64_t x) {
  uint64_t t;
  t = (x ^ (x >> 7)) & 0x00AA00AA00AA00AAull;
  x ^= t ^ (t << 7);
  t = (x ^ (x >> 14)) & 0x0000CCCC0000CCCCull;
  x ^= t ^ (t << 14);
  t = (x ^ (x >> 28)) & 0x00000000F0F0F0F0ull;
  x ^= t ^ (t << 28);
  return x;
}

template <class Codec, TriangleTest kTest>
void walk_packet(const uint8_t* blob, const layout::BlobHeader& h, const RayPre* pre, Closest* c, int n) {
  using simd::F8;
  const uint8_t* tree = blob + h.tree_offset;
  struct Entry {
    uint32_t properties;
    uint32_t rays;
    float entry;  // the least of its rays' entries
  };
  Entry stack[kStackSize];
  int top = 0;
  const F8 zero = F8::splat(0.0f), inf = F8::splat(INFINITY), scale_far = F8::splat(kFarScale);
  F8 origin_of[3];
  for (int a = 0; a < 3; ++a) origin_of[a] = F8::splat(pre[0].org[a]);
  uint32_t properties = h.root, rays = (1u << n) - 1;
  for (;;) {
    const uint32_t count = layout::oct_count(properties), offset = layout::oct_offset(properties);
    if (count == 0) {
      const uint8_t* node = tree + offset;
      F8 lo[3], hi[3];
      decode_oct_children(node, lo, hi);
      for (int a = 0; a < 3; ++a) lo[a] = lo[a] - origin_of[a], hi[a] = hi[a] - origin_of[a];
      const int used = simd::nonzero_bits8(node + MC_OCT_PROPERTIES_AT);
      uint64_t hit_rows = 0;  // byte i: ray i's hit children
      F8 least = inf;         // each child's least entry among the rays that hit it
      for (uint32_t m = rays; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        const RayPre& r = pre[i];
        count_node(8);
        F8 tn[3], tf[3];
        const F8 cut = F8::splat(c[i].t);
        for (int a = 0; a < 3; ++a) {
          const F8 inv = F8::splat(r.inv[a]);
          tn[a] = simd::max((r.near_is_max[a] ? hi[a] : lo[a]) * inv, zero);
          tf[a] = simd::min((r.near_is_max[a] ? lo[a] : hi[a]) * inv, cut);
        }
        const F8 entry = simd::max(simd::max(tn[0], tn[1]), tn[2]);
        const F8 exit = simd::min(simd::min(tf[0], tf[1]), tf[2]) * scale_far;
        const simd::M8 hit = (entry <= exit) & (entry < inf);
        const int bits = simd::bits(hit) & used;
        hit_rows |= uint64_t(uint32_t(bits)) << (8 * i);
        least = simd::select(hit, simd::min(least, entry), least);
      }
      if (hit_rows) {
        const uint64_t by_child = transpose_bits8x8(hit_rows);  // byte k: the rays that hit child k
        float entries[8];
        least.store(entries);
        // The hit children, farthest first (at most 8: insertion sort).
        Entry hit[8];
        int k = 0;
        for (int child = 0; child < 8; ++child) {
          const uint32_t child_rays = uint32_t(by_child >> (8 * child)) & 0xFF;
          if (!child_rays) continue;
          const Entry e{layout::oct_child_properties(node, child), child_rays, entries[child]};
          prefetch_child(tree + layout::oct_offset(e.properties));
          int at = k++;
          for (; at > 0 && hit[at - 1].entry < e.entry; --at) hit[at] = hit[at - 1];
          hit[at] = e;
        }
        for (int j = 0; j + 1 < k; ++j) stack[top++] = hit[j];
        properties = hit[k - 1].properties, rays = hit[k - 1].rays;
        continue;
      }
    } else {
      test_leaf_rays<Codec, kTest>(blob, pre, c, rays, h.tree_offset + offset, count, layout::slot_of(h, offset, 0));
    }
    // The next entry that some of its rays may still find a hit in (an
    // any-hit ray that has one has a cut below 0, and drops out here).
    for (;;) {
      if (top == 0) return;
      const Entry& e = stack[--top];
      rays = 0;
      for (uint32_t m = e.rays; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        if (e.entry <= c[i].t * kFarScale) rays |= 1u << i;
      }
      if (rays) {
        properties = e.properties;
        break;
      }
    }
  }
}

// A request's packets: rays in groups of kPacketRays as they come (the
// caller has found that they share one origin and sorted them by
// direction: WalkRequest::packets).
template <class Codec, TriangleTest kTest>
void walk_packets(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
                  const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint32_t outputs = request.flags;
  const bool any = (outputs & MC_QUERY_ANY) != 0;
  alignas(32) uint8_t pre_bytes[kPacketRays * sizeof(RayPre)];
  RayPre* pre = reinterpret_cast<RayPre*>(pre_bytes);
  Closest c[kPacketRays];
  int walked[kPacketRays];
  for (size_t begin = 0; begin < n; begin += kPacketRays) {
    const size_t end = std::min(n, begin + kPacketRays);
    int k = 0;
    for (size_t i = begin; i < end; ++i) {
      hits[i] = Hit{};
      if (!ray_is_walkable(rays[i])) {
        ++*skipped;
        continue;
      }
      new (&pre[k]) RayPre(rays[i], outputs);
      c[k] = Closest{rays[i].tmax};
      c[k].any = any;
      walked[k++] = int(i - begin);
    }
    if (k > 0) walk_packet<Codec, kTest>(blob, h, pre, c, k);
    for (int j = 0; j < k; ++j) keep_slot(hits[begin + size_t(walked[j])], c[j], outputs);
    if (!request.keep_slots) finish_hits(blob, rays, hits, begin, end, outputs);
  }
}

}  // namespace

template <class Codec, TriangleTest kTest>
void walk(layout::tree::OctTreeCompressed, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped,
          const WalkRequest& request) {
  if (request.packets && !(request.flags & MC_QUERY_ALL)) return walk_packets<Codec, kTest>(blob, rays, hits, n, skipped, request);
  const layout::BlobHeader& h = layout::header_of(blob);
  for_each_ray(blob, rays, hits, n, skipped, request,
               [&](const RayPre& r, Closest& c) { walk_one<Codec, kTest>(blob, h, r, c); });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::OctTreeCompressed, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)
#undef MC_INSTANTIATE

MC_ISA_END
}  // namespace meshcast
