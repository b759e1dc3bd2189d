// BruteForce's readings (seed 000 §3.11: records [count][block], no tree):
// validation and the leaf descent; AABBList's batches are such records too.
#include "layout/tree/tree_walks.h"

#include "layout/triangles/codecs.h"

namespace meshcast::layout {

const LeafCodec* leaf_codec(uint32_t triangle_format) {
#define MC_RECORD(Codec, name) {Codec::kFormat, leaf_codec_of<Codec>()},
  static constexpr struct { uint32_t format; LeafCodec codec; } kCodecs[] = {MC_FOR_EACH_TRIANGLE_CODEC(MC_RECORD)};
#undef MC_RECORD
  for (const auto& c : kCodecs)
    if (c.format == triangle_format) return &c.codec;
  return nullptr;
}

void Descent::records(uint32_t at, uint32_t end) {
  while (at < end) {
    uint32_t count = load<uint32_t>(tree + at);
    leaf(at + MC_BRUTE_RECORD_BYTES, count, nullptr);
    const LeafCodec* codec = leaf_codec(h.triangle_format);
    const uint64_t bytes = codec ? codec->stored_bytes(blob, h.tree_offset + at + MC_BRUTE_RECORD_BYTES, count, ~0ull) : 0;
    at += MC_BRUTE_RECORD_BYTES + uint32_t(bytes);
  }
}

// BruteForce: the records must tile the tree section exactly.
std::string validate_tree(tree::BruteForce, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  uint64_t at = 0, records = 0;
  if (std::string e = check_records(codec, blob, h, &at, h.tree_size, triangles, &records); !e.empty()) return e;
  if (records != h.node_count) return "BruteForce holds " + num(records) + " records, the header says " + num(h.node_count);
  return "";
}

void from_root(Descent& d, tree::BruteForce) { d.records(0, d.h.tree_size); }

}  // namespace meshcast::layout
