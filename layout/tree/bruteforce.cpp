// BruteForce's readings (seed 000 §3.11: records [count][block], no tree):
// validation and the leaf descent; AABBList's batches are such records too.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"

namespace meshcast::layout {

void Descent::records(uint32_t at, uint32_t end) {
  while (at < end) {
    uint32_t count = load<uint32_t>(tree + at);
    leaf(at + MC_BRUTE_RECORD_BYTES, count, nullptr);
    uint64_t bytes = 0;
#define MC_BYTES(Codec, name) \
if (h.triangle_format == Codec::kFormat) bytes = stored_bytes<Codec>(blob, h.tree_offset + at + MC_BRUTE_RECORD_BYTES, count, ~0ull);
    MC_FOR_EACH_TRIANGLE_CODEC(MC_BYTES)
#undef MC_BYTES
    at += MC_BRUTE_RECORD_BYTES + uint32_t(bytes);
  }
}

// BruteForce: the records must tile the tree section exactly.
template <class Codec>
std::string validate_tree(tree::BruteForce, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  uint64_t at = 0, records = 0;
  if (std::string e = check_records<Codec>(blob, h, &at, h.tree_size, triangles, &records); !e.empty()) return e;
  if (records != h.node_count) return "BruteForce holds " + num(records) + " records, the header says " + num(h.node_count);
  return "";
}

#define MC_INSTANTIATE(Codec, name) \
  template std::string validate_tree<Codec>(tree::BruteForce, const uint8_t*, const BlobHeader&, uint64_t*);
MC_FOR_EACH_TRIANGLE_CODEC(MC_INSTANTIATE)
#undef MC_INSTANTIATE

void from_root(Descent& d, tree::BruteForce) { d.records(0, d.h.tree_size); }

}  // namespace meshcast::layout
