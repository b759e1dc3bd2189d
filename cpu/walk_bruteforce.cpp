// BruteForce (seed 000 §3.11's measurement): every record of the tree
// section, in order, through the same leaf test the trees use.
#include "cpu/pairs.h"
#include "cpu/walk.h"

namespace meshcast {

template <class Codec>
void walk_bruteforce(const uint8_t* blob, const Ray* rays, Hit* hits, size_t n, uint64_t* skipped) {
  const layout::BlobHeader& h = layout::header_of(blob);
  for_each_ray(blob, rays, hits, n, skipped, [&](const RayPre& r, Closest& c) {
    for (uint32_t at = 0; at < h.tree_size;) {
      uint32_t count = layout::load<uint32_t>(blob + h.tree_offset + at);
      uint32_t block = at + MC_BRUTE_RECORD_BYTES;
      if constexpr (requires { Codec::kSequential; }) {  // strips: the decode tells the length
        at = block + uint32_t(test_sequential_leaf<Codec>(blob, r, h.tree_offset + block, count,
                                                          layout::slot_of(h, block, 0), c));
      } else {
        test_leaf<Codec>(blob, r, h.tree_offset + block, count, layout::slot_of(h, block, 0), c);
        at = block + Codec::block_bytes(count);
      }
    }
  });
}

#define MC_INSTANTIATE(Codec, name) \
  template void walk_bruteforce<layout::Codec>(const uint8_t*, const Ray*, Hit*, size_t, uint64_t*);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)

}  // namespace meshcast
