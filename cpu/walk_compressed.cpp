// AABBTreeCompressed walker (seed 000 §5.4): as the AABBTree walker, but a
// node's child boxes are decoded from its own decoded box, so each stack
// entry carries the box, the child's offset and its triangle count.
#include "layout/triangles/codecs.h"
#include "cpu/walk.h"
#include "layout/tree/compressed.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::AABBTreeCompressed, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  const layout::CompressedBox root = layout::compressed_root_box(tree);
  const uint32_t root_count = layout::compressed_root_count(tree);
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    struct Entry {
      layout::CompressedBox box;
      uint32_t at, count;
      float tnear;
    };
    Entry stack[MC_MAX_DEPTH + 2];
    int top = -1;
    layout::CompressedBox box = root;
    uint32_t at = MC_COMPRESSED_HEADER_BYTES, count = root_count;
    if (box_test(r, box.min, box.max, c.t) == INFINITY) return;
    for (;;) {
      if (count == 0) {
        const layout::CompressedNode node = layout::load<layout::CompressedNode>(tree + at);
        Entry child[2];
        node.unpack(box, child[0].box, child[1].box);
        child[0].at = at + MC_COMPRESSED_NODE_BYTES, child[0].count = node.left_count();
        child[1].at = node.right, child[1].count = node.right_count();
        for (Entry& e : child) e.tnear = box_test(r, e.box.min, e.box.max, c.t);
        bool lhit = child[0].tnear != INFINITY, rhit = child[1].tnear != INFINITY;
        if (lhit || rhit) {
          int first = lhit && (!rhit || child[0].tnear <= child[1].tnear) ? 0 : 1;
          if (lhit && rhit) stack[++top] = child[first ^ 1];
          box = child[first].box, at = child[first].at, count = child[first].count;
          continue;
        }
      } else {
        test_leaf<Codec, kTest>(blob, r, h.tree_offset + at, count, layout::slot_of(h, at, 0), c);
      }
      while (top >= 0 && stack[top].tnear > c.t * kFarScale) --top;
      if (top < 0) break;
      const Entry& e = stack[top--];
      box = e.box, at = e.at, count = e.count;
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::AABBTreeCompressed, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
