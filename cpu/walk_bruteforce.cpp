// BruteForce (seed 000 §3.11's measurement): every record of the tree
// section, in order, through the same leaf test the trees use.
#include "cpu/records.h"

namespace meshcast {
MC_ISA_BEGIN

template <class Codec, TriangleTest kTest>
void walk(layout::tree::BruteForce, const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped, const WalkRequest& request) {
  const layout::BlobHeader& h = layout::header_of(blob);
  for_each_ray(blob, rays, hits, n, skipped, request,
               [&](const RayPre& r, Closest& c) { test_records<Codec, kTest>(blob, h, r, 0, h.tree_size, c); });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk<layout::Codec, kWalkersTriangleTest>(layout::tree::BruteForce, const uint8_t*, const Ray*, Hit*, size_t, uint64_t*, const WalkRequest&);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

MC_ISA_END
}  // namespace meshcast
