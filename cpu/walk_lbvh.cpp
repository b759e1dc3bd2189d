// StacklessLBVH walker (seed 001, Algorithm 2) with nearer-child-first
// order and still no stack. The seed always goes left first, so next(n) is
// plain arithmetic on n. Here the walk runs on a virtual number v, in which
// the child a node sends the ray to first is always the left one:
//   v = n ^ o,  o = the bits "this level went right first" along the path,
// each bit taken from the node's 8 sorting bits at the ray's octant (seed
// 002). Descending appends a bit to both; next() is the seed's arithmetic on
// v, and shifting o by the same amount drops the levels it climbs out of.
// Nodes whose bits are all 0 walk exactly as the seed.
#include <bit>

#include "layout/triangles/codecs.h"
#include "cpu/walk.h"
#include "layout/tree/aabbtree.h"
#include "layout/tree/lbvh.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::StacklessLBVH, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    const uint32_t octant = layout::pns_octant(r.dir);
    uint32_t v = 1, o = 0, node_index = 1;
    for (;;) {
      const layout::LBVHNode node = layout::load_lbvh_node(tree, node_index);
      if (box_test(r, node.min, node.max, c.t) != INFINITY) {
        if (node.count < 0) {
          v <<= 1, o = o << 1 | (node.position >> octant & 1);
          node_index = v ^ o;
          continue;
        }
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + node.position, uint32_t(node.count),
                         layout::slot_of(h, node.position, 0), c);
      }
      // next(v) = (v + 1) >> ctz(v + 1); the root again ends the walk.
      const int up = std::countr_zero(v + 1);
      v = (v + 1) >> up, o >>= up;
      if (v == 1) break;
      node_index = v ^ o;
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::StacklessLBVH, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
