// AABBList (seed 000 §7): every batch box in list order, and the records of
// each batch whose box the ray enters before its closest hit so far. The
// GPU's two passes (shaders/aabblist_*.comp) do the same work spread over
// (ray, batch) pairs.
#include "cpu/records.h"
#include "layout/tree/aabblist.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::AABBList, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  for_each_ray(blob, rays, hits, n, skipped, request, [&](const RayPre& r, Closest& c) {
    for (uint32_t b = 0; b < h.node_count; ++b) {
      const layout::ListEntry e = layout::load_list_entry(tree, b);
      if (box_test(r, e.min, e.max, c.t) != INFINITY)
        test_records<Codec, kTest>(blob, h, r, e.records, layout::list_records_end(tree, h, b), c);
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::AABBList, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
