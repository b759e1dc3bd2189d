// What every tree family's two readings of its nodes share: validation
// (proves every offset and count in range, before any walker trusts them)
// and the leaf descent (a validated blob's leaves with the boxes above them).
// Each family's own readings live beside its bits in layout/tree/<family>.cpp,
// declared here from the catalog: validate_tree (one a format, given the
// codec's LeafCodec) and from_root.
#pragma once
#include <algorithm>
#include <string>
#include <vector>

#include "layout/blob_format.h"
#include "layout/triangles/block.h"
#include "layout/catalog.h"
#include "layout/tree/leaves.h"

namespace meshcast::layout {

inline std::string num(uint64_t v) { return std::to_string(v); }

// What a leaf's check needs of its triangle codec, as one record: the tree
// validators take it as an argument, so each is compiled once rather than
// once a codec (nineteen times over, most of the layout folder's build).
struct LeafCodec {
  uint32_t lanes;         // triangles a test takes (sizes BruteForce's records)
  uint32_t slot_divisor;  // block bytes a remap slot (the header's must match)
  // Bytes a block of `count` takes (block.h's stored_bytes).
  uint64_t (*stored_bytes)(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit);
  // What validation must prove of a block (the codec's check).
  bool (*check)(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why);
};

template <class Codec>
constexpr LeafCodec leaf_codec_of() {
  return {Codec::kLanes, Codec::kSlotDivisor, &stored_bytes<Codec>,
          [](const uint8_t* blob, uint32_t block, uint32_t count, std::string* why) -> bool {
            return Codec::check(blob, block, count, why);
          }};
}

// The blob's triangle format's record (bruteforce.cpp); null where the
// format has no codec (Indexed24, the zero-byte trees' own).
const LeafCodec* leaf_codec(uint32_t triangle_format);

// Checks one leaf: its block lies in the triangle area of the tree section,
// its slots lie in the remap, and the codec's own indices are in range.
inline std::string check_leaf(const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint32_t block,
                              uint32_t count, uint32_t max_count = MC_QUAD_MAX_COUNT) {
  if (count == 0 || count > max_count)
    return "leaf at tree offset " + num(block) + " has " + num(count) + " triangles (allowed 1.." +
           num(max_count) + ")";
  if (block < h.triangle_base || (block - h.triangle_base) % 4 != 0)
    return "triangle block at tree offset " + num(block) + " lies before the triangle area (" +
           num(h.triangle_base) + ") or is misaligned";
  uint64_t bytes = block <= h.tree_size ? codec.stored_bytes(blob, h.tree_offset + block, count, h.tree_size - block) : 0;
  if (bytes == 0 || uint64_t(block) + bytes > h.tree_size)
    return "triangle block at tree offset " + num(block) + " for " + num(count) +
           " triangles is broken or runs past the tree section (" + num(h.tree_size) + " bytes)";
  uint64_t slot0 = (block - h.triangle_base) / h.slot_divisor;
  if (slot0 + count > h.remap_slots)
    return "triangle block at tree offset " + num(block) + " maps past the remap (" + num(h.remap_slots) +
           " slots)";
  for (uint64_t s = slot0; has_remap(h) && s < slot0 + count; ++s)
    if (!(remap_used(blob, h, uint32_t(s >> 6)) >> (s & 63) & 1))
      return "triangle block at tree offset " + num(block) + " uses slot " + num(s) + ", which the remap marks unused";
  std::string why;
  if (!codec.check(blob, h.tree_offset + block, count, &why)) return why;
  return "";
}

// What every node walk of the validator checks on reaching a node: visits
// bounded by node_count (so a walk of a corrupted DAG stays linear) and the
// depth by MC_MAX_DEPTH (the walkers' stacks).
inline std::string reach(uint64_t* visited, uint32_t depth, const BlobHeader& h, const std::string& node) {
  if (++*visited > h.node_count) return "tree reaches more nodes than node_count (" + num(h.node_count) + ")";
  if (depth > h.max_depth || depth > MC_MAX_DEPTH)
    return node + " is deeper than the limit " + num(std::min<uint32_t>(h.max_depth, MC_MAX_DEPTH));
  return "";
}

// The depth-first walk every binary tree's validation shares: from `root`,
// each reached node (an offset or index, named `noun` in messages) is
// reach()-checked, then visit(at, push) checks it and push()es its children.
template <class Visit>
std::string walk_nodes(const BlobHeader& h, uint32_t root, const char* noun, Visit&& visit) {
  struct Item { uint32_t at, depth; };
  std::vector<Item> stack{{root, 0}};
  uint64_t visited = 0;
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    if (std::string e = reach(&visited, it.depth, h, noun + num(it.at)); !e.empty()) return e;
    auto push = [&](uint32_t child) { stack.push_back({child, it.depth + 1}); };
    if (std::string e = visit(it.at, push); !e.empty()) return e;
  }
  return "";
}

// BruteForce records from tree-section offset *at up to `end`: each a
// valid leaf of at most brute_chunk() triangles, the last ending at `end`.
inline std::string check_records(const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* at, uint64_t end, uint64_t* triangles,
                          uint64_t* records) {
  while (*at < end) {
    if (*at + MC_BRUTE_RECORD_BYTES > end) return "record at tree offset " + num(*at) + " is cut short";
    uint32_t count = load<uint32_t>(blob + h.tree_offset + *at);
    std::string e = check_leaf(codec, blob, h, uint32_t(*at + MC_BRUTE_RECORD_BYTES), count, brute_chunk(codec.lanes));
    if (!e.empty()) return e;
    *triangles += count;
    *at += MC_BRUTE_RECORD_BYTES + codec.stored_bytes(blob, h.tree_offset + uint32_t(*at) + MC_BRUTE_RECORD_BYTES, count, ~0ull);
    ++*records;
  }
  if (*at != end) return "record ending at tree offset " + num(*at) + " runs past " + num(end);
  return "";
}

inline PathBox box_of(const float min[3], const float max[3]) {
  PathBox b;
  for (int a = 0; a < 3; ++a) b.min[a] = min[a], b.max[a] = max[a];
  return b;
}

// A descent's state: `path` grows and shrinks with the recursion (depth is
// bounded by validation).
struct Descent {
  const uint8_t* blob;
  const BlobHeader& h;
  const uint8_t* tree;
  const LeafPathVisitor& visit;
  std::vector<PathBox> path;

  void leaf(uint32_t block, uint32_t count, const PathBox* own) {
    if (own) path.push_back(*own);
    visit(block, count, path);
    if (own) path.pop_back();
  }
  // BruteForce records from tree-section offset `at` up to `end`.
  void records(uint32_t at, uint32_t end);
};

// Each format's readings (the zero-byte trees validate as a whole, in
// validate_zerobyte, whatever their codec).
#define MC_READERS_AllCodecs(Name)                                                                          \
  std::string validate_tree(tree::Name, const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h,     \
                            uint64_t* triangles);                                                            \
  void from_root(Descent& d, tree::Name);
#define MC_READERS_Indexed24(Name) void from_root(Descent& d, tree::Name);
#define MC_DECLARE_READERS(Name, id, node_bytes, triangles, ...) MC_READERS_##triangles(Name)
MC_FOR_EACH_TREE_FORMAT(MC_DECLARE_READERS)
#undef MC_DECLARE_READERS
#undef MC_READERS_Indexed24
#undef MC_READERS_AllCodecs

}  // namespace meshcast::layout
