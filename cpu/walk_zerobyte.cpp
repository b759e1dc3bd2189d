// Zero-byte tree walkers (seed 004). A node reached is first bounded: its
// box is recomputed from the vertices of its triangles (or taken from the
// thread's box cache), tested conservatively, and only then are its
// triangles, which the box holds, tested; the children follow in the
// order of the node's sorting byte (seed 002), the near one on top of the
// stack. A leaf has no box of its own: its triangles' vertices are the
// box's, so the triangle test reads them once. ZeroByteHybrid walks its
// AABBTree nodes as walk_aabbtree does and each leaf's zero-byte tree so.
#include "cpu/aabb_walk.h"
#include "cpu/box_cache.h"
#include "cpu/walk.h"
#include "layout/tree/aabbtree.h"
#include "layout/tree/zerobyte.h"

#include <type_traits>

namespace meshcast {
MC_ISA_BEGIN

namespace {

// The zero-byte tree whose root triangle is at blob offset `root`, its
// slots from `slot0`.
template <TriangleTest kTest, bool kCache>
void walk_zbt(const uint8_t* blob, const layout::BlobHeader& h, uint32_t root, uint32_t slot0, uint32_t octant,
              const RayPre& r, Closest& c, BoxCache* cache) {
  const uint8_t* tris = blob + root;
  const uint8_t* vertices = blob + h.vertex_offset;
  uint32_t stack[MC_MAX_DEPTH + 2];
  int top = 0;
  stack[0] = 0;
  while (top >= 0) {
    uint32_t p = stack[top--];
    layout::ZbtNode n = layout::zbt_node(tris, p);
    if (n.child) {
      float mn[3], mx[3];
      if constexpr (kCache) {
        if (!cache->find(blob, h.checksum, slot0 + p, mn, mx)) {
          layout::zbt_box(tris, vertices, p, n, mn, mx);
          cache->put(blob, h.checksum, slot0 + p, mn, mx);
        }
      } else {
        layout::zbt_box(tris, vertices, p, n, mn, mx);
      }
      if (box_test(r, mn, mx, c.t) == INFINITY) continue;
    }
    test_leaf<layout::Indexed24, kTest>(blob, r, root + p * layout::Indexed24::kSlotDivisor, n.count, slot0 + p, c);
    if (!n.child) continue;
    uint32_t children[2] = {n.child, n.child + layout::zbt_node(tris, n.child).count};
    uint32_t bit = n.count >= 2 ? layout::zbt_pns(tris, p) >> octant & 1 : 0;
    stack[++top] = children[bit ^ 1];
    stack[++top] = children[bit];
  }
}

template <TriangleTest kTest, bool kCache>
void walk_zerobyte_tree(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  BoxCache* cache = kCache ? &BoxCache::for_this_thread() : nullptr;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    walk_zbt<kTest, kCache>(blob, h, h.tree_offset + h.triangle_base, 0, layout::pns_octant(r.dir), r, c, cache);
  });
}

template <TriangleTest kTest, bool kCache>
void walk_zerobyte_hybrid(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  BoxCache* cache = kCache ? &BoxCache::for_this_thread() : nullptr;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    const uint32_t octant = layout::pns_octant(r.dir);
    walk_aabb_nodes(blob + h.tree_offset, r, c, [&](const layout::AABBNode& node, uint32_t) {
      uint32_t root = h.tree_offset + h.triangle_base + node.value() * layout::Indexed24::kSlotDivisor;
      walk_zbt<kTest, kCache>(blob, h, root, node.value(), octant, r, c, cache);
    });
  });
}

// Both zero-byte formats: the header's box-cache flag picks the instantiation.
template <class Tree, TriangleTest kTest>
void walk_zero_byte(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const bool cache = layout::header_of(blob).root & MC_ZBT_FLAG_BOX_CACHE;
  if constexpr (std::is_same_v<Tree, layout::tree::ZeroByteHybrid>)
    return cache ? walk_zerobyte_hybrid<kTest, true>(blob, rays, hits, n, skipped, request)
                 : walk_zerobyte_hybrid<kTest, false>(blob, rays, hits, n, skipped, request);
  else
    return cache ? walk_zerobyte_tree<kTest, true>(blob, rays, hits, n, skipped, request)
                 : walk_zerobyte_tree<kTest, false>(blob, rays, hits, n, skipped, request);
}

}  // namespace

// The zero-byte trees hold the mesh's own indices: Indexed24 is their one codec.
template <class Codec, TriangleTest kTest>
void walk(layout::tree::ZeroByteTree tree, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  static_assert(std::is_same_v<Codec, layout::Indexed24>);
  walk_zero_byte<decltype(tree), kTest>(blob, rays, hits, n, skipped, request);
}

template <class Codec, TriangleTest kTest>
void walk(layout::tree::ZeroByteHybrid tree, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  static_assert(std::is_same_v<Codec, layout::Indexed24>);
  walk_zero_byte<decltype(tree), kTest>(blob, rays, hits, n, skipped, request);
}

template void walk<layout::Indexed24, kWalkersTriangleTest>(layout::tree::ZeroByteTree, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
template void walk<layout::Indexed24, kWalkersTriangleTest>(layout::tree::ZeroByteHybrid, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);

MC_ISA_END
}  // namespace meshcast
