// The blob: one contiguous, versioned byte buffer holding a built mesh.
//
//   [BlobHeader][tree section: nodes and triangle blocks][vertex section][remap]
//
// The tree section holds the nodes and triangle blocks of the tree format in
// the order its writer chose; offsets inside it are relative to its start.
// The vertex section holds shared vertices for indexed triangle formats. The
// remap turns a triangle slot (see slot_of) into the caller's triangle index.
#pragma once
#include <cstddef>
#include <cstdint>
#include <bit>
#include <cstring>
#include <span>
#include <string>
#include <string_view>

#include "layout/formats.h"

namespace meshcast::layout {

struct BlobHeader {
  uint32_t magic;
  uint32_t version;
  uint32_t tree_format;
  uint32_t triangle_format;
  uint32_t triangle_count;  // triangles of the input mesh
  uint32_t node_count;      // nodes of the tree format (QuadTree: 4-wide nodes)
  uint32_t leaf_count;      // triangle blocks
  uint32_t max_depth;       // deepest node, root = 0
  uint32_t leaf_size;       // largest triangle count the builder allowed a leaf
  uint32_t root;            // AABBTree: offset of the root node; QuadTree: RootProperties
  float bounds_min[3];      // box of the decoded triangles
  float bounds_max[3];
  float quant_offset[3];    // BitPack vertices: v = q * quant_scale + quant_offset
  float quant_scale[3];
  // QuadTreeHalfFloat: bound = half * node_scale + node_origin (quadtree.h).
  // OctTreeCompressed: node_origin[a] the nodes' largest |Origin| of axis a,
  // node_scale their largest 2^e (octtree.h). Unused by the other trees.
  float node_origin[3];
  float node_scale;
  uint32_t tree_offset, tree_size;
  uint32_t node_bytes;      // bytes of nodes in the tree section (rest: triangle blocks)
  uint32_t triangle_base;   // tree-section offset where slot numbering starts
  uint32_t slot_divisor;    // bytes of triangle block per slot number
  uint32_t vertex_offset, vertex_size;
  uint32_t remap_offset, remap_size;
  uint32_t remap_bits;      // bits per remap entry (0: none, see has_remap)
  uint32_t remap_slots;     // slot numbers covered by the remap (used or not)
  uint32_t total_size;
  uint32_t checksum;        // FNV-1a over the header (this field as 0) and the payload
  uint32_t max_block_shift; // BitPackSOA: largest m of a block step grid * 2^m (soa.h)
};
static_assert(sizeof(BlobHeader) == MC_BLOB_HEADER_BYTES);
// The word indices of formats.h (what the shaders read) name these fields.
static_assert(offsetof(BlobHeader, tree_format) == 4 * MC_HDR_TREE_FORMAT);
static_assert(offsetof(BlobHeader, triangle_format) == 4 * MC_HDR_TRIANGLE_FORMAT);
static_assert(offsetof(BlobHeader, triangle_count) == 4 * MC_HDR_TRIANGLE_COUNT);
static_assert(offsetof(BlobHeader, node_count) == 4 * MC_HDR_NODE_COUNT);
static_assert(offsetof(BlobHeader, root) == 4 * MC_HDR_ROOT);
static_assert(offsetof(BlobHeader, bounds_min) == 4 * MC_HDR_BOUNDS_MIN);
static_assert(offsetof(BlobHeader, bounds_max) == 4 * MC_HDR_BOUNDS_MAX);
static_assert(offsetof(BlobHeader, quant_offset) == 4 * MC_HDR_QUANT_OFFSET);
static_assert(offsetof(BlobHeader, quant_scale) == 4 * MC_HDR_QUANT_SCALE);
static_assert(offsetof(BlobHeader, node_origin) == 4 * MC_HDR_NODE_ORIGIN);
static_assert(offsetof(BlobHeader, node_scale) == 4 * MC_HDR_NODE_SCALE);
static_assert(offsetof(BlobHeader, tree_offset) == 4 * MC_HDR_TREE_OFFSET);
static_assert(offsetof(BlobHeader, tree_size) == 4 * MC_HDR_TREE_SIZE);
static_assert(offsetof(BlobHeader, triangle_base) == 4 * MC_HDR_TRIANGLE_BASE);
static_assert(offsetof(BlobHeader, slot_divisor) == 4 * MC_HDR_SLOT_DIVISOR);
static_assert(offsetof(BlobHeader, vertex_offset) == 4 * MC_HDR_VERTEX_OFFSET);
static_assert(offsetof(BlobHeader, remap_offset) == 4 * MC_HDR_REMAP_OFFSET);
static_assert(offsetof(BlobHeader, remap_size) == 4 * MC_HDR_REMAP_SIZE);
static_assert(offsetof(BlobHeader, remap_bits) == 4 * MC_HDR_REMAP_BITS);
static_assert(offsetof(BlobHeader, remap_slots) == 4 * MC_HDR_REMAP_SLOTS);

// FNV-1a, 32 bits: cheap, and enough to catch accidental damage. Validation
// does not rely on it: every structural fact is checked on its own.
uint32_t checksum(std::span<const uint8_t> bytes);
void seal(std::span<uint8_t> blob);  // writes header.checksum

// Proves, before any walker runs, that every offset, count, index and remap
// entry is in range and that every walk ends (each child after its parent,
// node visits bounded by node_count, depth within MC_MAX_DEPTH). Returns "" when the
// blob is valid, otherwise a message naming what is wrong and the limit.
std::string validate(std::span<const uint8_t> blob);

std::string_view tree_format_name(uint32_t f);
std::string_view triangle_format_name(uint32_t f);

// Unaligned little-endian loads used by the walkers and validation.
template <class T>
inline T load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

inline const BlobHeader& header_of(const uint8_t* blob) {
  return *reinterpret_cast<const BlobHeader*>(blob);
}

// Triangles a BruteForce record holds for a codec of `lanes` lanes.
inline uint32_t brute_chunk(uint32_t lanes) { return lanes > MC_BRUTE_CHUNK ? lanes : MC_BRUTE_CHUNK; }

// Triangle slot of lane `lane` of the block at tree-section offset `block`.
inline uint32_t slot_of(const BlobHeader& h, uint32_t block, uint32_t lane) {
  return (block - h.triangle_base) / h.slot_divisor + lane;
}

// The remap section, smaller than one entry a slot number because slot
// numbers derived from block offsets leave holes (padding lanes, leaf
// headers):
//   used[W]   uint64: bit s set when slot number s holds a triangle
//   rank[W]   uint32: used slot numbers before word w
//   entries   triangle_count entries of remap_bits each, LSB first, in slot
//             order, then 8 bytes of padding so a 64-bit load never leaves it
// with W = ceil(remap_slots / 64). A slot's entry is number
// rank[s/64] + popcount(used[s/64] below bit s%64).
//
// Two smaller forms:
//   in order (remap_bits = 0): the build kept the input order, so the n-th
//             used slot holds input triangle n: only used[] and rank[]
//             (12 bytes every 64 slot numbers), no entries;
//   none      (remap_size = 0): the caller asked for no input triangle
//             numbers; a hit names its triangle by slot number, below
//             remap_slots.
inline bool has_remap(const BlobHeader& h) { return h.remap_size != 0; }
inline uint32_t remap_words(const BlobHeader& h) { return (h.remap_slots + 63) / 64; }

inline uint32_t remap_packed(const uint8_t* blob, const BlobHeader& h, uint32_t index) {
  uint64_t bit = uint64_t(index) * h.remap_bits;
  uint64_t word = load<uint64_t>(blob + h.remap_offset + 12ull * remap_words(h) + (bit >> 3));
  return uint32_t((word >> (bit & 7)) & ((uint64_t(1) << h.remap_bits) - 1));
}

inline uint64_t remap_used(const uint8_t* blob, const BlobHeader& h, uint32_t word) {
  return load<uint64_t>(blob + h.remap_offset + 8ull * word);
}

inline uint32_t remap_entry(const uint8_t* blob, const BlobHeader& h, uint32_t slot) {
  if (!has_remap(h)) return slot;
  uint32_t w = slot >> 6;
  uint64_t below = remap_used(blob, h, w) & ((uint64_t(1) << (slot & 63)) - 1);
  uint32_t rank = load<uint32_t>(blob + h.remap_offset + 8ull * remap_words(h) + 4ull * w);
  const uint32_t index = rank + uint32_t(std::popcount(below));
  return h.remap_bits == 0 ? index : remap_packed(blob, h, index);
}

}  // namespace meshcast::layout
