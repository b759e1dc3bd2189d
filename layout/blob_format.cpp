#include "layout/blob_format.h"

#include "layout/tree/leaves.h"
#include "layout/tree/zerobyte.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cfloat>
#include <cmath>
#include <vector>

#include "layout/catalog.h"
#include "layout/triangles/codecs.h"
#include "layout/tree/tree_walks.h"

namespace meshcast::layout {

uint32_t checksum(std::span<const uint8_t> bytes) {
  uint32_t h = 2166136261u;
  for (uint8_t b : bytes) h = (h ^ b) * 16777619u;
  return h;
}

// The checksum covers the header (its own field read as 0) and the payload,
// so no flipped bit anywhere goes unnoticed.
static uint32_t blob_checksum(std::span<const uint8_t> blob) {
  BlobHeader h;
  std::memcpy(&h, blob.data(), sizeof h);
  h.checksum = 0;
  uint32_t head = checksum({reinterpret_cast<const uint8_t*>(&h), sizeof h});
  uint32_t body = checksum(blob.subspan(sizeof h));
  return head * 16777619u ^ body;
}

void seal(std::span<uint8_t> blob) {
  BlobHeader h;
  std::memcpy(&h, blob.data(), sizeof h);
  h.checksum = blob_checksum(blob);
  std::memcpy(blob.data(), &h, sizeof h);
}

std::string_view tree_format_name(uint32_t f) { return tree_format_info(f).name; }

std::string_view triangle_format_name(uint32_t f) {
#define MC_NAME(Codec, text) \
  if (f == Codec::kFormat) return text;
  MC_FOR_EACH_TRIANGLE_CODEC(MC_NAME)
#undef MC_NAME
  if (f == MC_TRI_INDEXED24) return "Indexed24";
  return "";
}

namespace {

// The tree format's validator (the catalog's switch); the zero-byte trees
// have their own (validate_zerobyte).
std::string walk_tree(const LeafCodec& codec, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return with_tree_format(h.tree_format, "unknown tree format " + num(h.tree_format), [&](auto tag) -> std::string {
    if constexpr (decltype(tag)::kTriangles == TreeTriangles::AllCodecs)
      return validate_tree(tag, codec, blob, h, triangles);
    else
      return "the zero-byte trees hold Indexed24 triangles alone";
  });
}

struct Section { const char* name; uint32_t offset, size; };

}  // namespace

std::string validate(std::span<const uint8_t> blob) {
  if (blob.size() < sizeof(BlobHeader))
    return "blob of " + num(blob.size()) + " bytes is shorter than its header (" + num(sizeof(BlobHeader)) + ")";
  // The header and the sections' words are read in place as 32-bit words.
  if (const uintptr_t address = reinterpret_cast<uintptr_t>(blob.data()); address % alignof(BlobHeader) != 0) {
    char hex[2 * sizeof address + 1] = {};
    std::to_chars(hex, hex + sizeof hex - 1, address, 16);
    return "blob bytes at 0x" + std::string(hex) + " are not 4-byte aligned (address % 4 = " +
           num(address % alignof(BlobHeader)) + "): a blob must start at a 4-byte aligned address, as a " +
           "std::vector<uint8_t>, load_blob and MappedBlob give it";
  }
  BlobHeader h;
  std::memcpy(&h, blob.data(), sizeof h);
  if (h.magic != MC_BLOB_MAGIC) return "not a meshcast blob (bad magic)";
  if (h.version != MC_BLOB_VERSION)
    return "blob version " + num(h.version) + " is not the supported version " + num(MC_BLOB_VERSION);
  if (blob.size() < h.total_size)
    return "blob is " + num(blob.size()) + " bytes, shorter than the " + num(h.total_size) +
           " bytes its header says (truncated)";
  if (blob.size() > h.total_size)
    return "blob is " + num(blob.size()) + " bytes, longer than the " + num(h.total_size) +
           " bytes its header says (bytes after its end)";
  if (blob_checksum(blob) != h.checksum) return "blob checksum does not match its contents";
  if (tree_format_name(h.tree_format).empty()) return "unknown tree format " + num(h.tree_format);
  if (triangle_format_name(h.triangle_format).empty()) return "unknown triangle format " + num(h.triangle_format);
  if (h.triangle_count == 0 || h.triangle_count == MC_NO_HIT) return "triangle count out of range";

  // Sections follow each other in order, inside the blob.
  Section sections[] = {{"tree", h.tree_offset, h.tree_size},
                        {"vertex", h.vertex_offset, h.vertex_size},
                        {"remap", h.remap_offset, h.remap_size}};
  uint64_t end = sizeof h;
  for (const Section& s : sections) {
    if (s.offset < end || s.offset % 4 != 0 || uint64_t(s.offset) + s.size > blob.size())
      return std::string(s.name) + " section [" + num(s.offset) + ", +" + num(s.size) +
             ") overlaps another, is misaligned, or runs past the blob (" + num(blob.size()) + " bytes)";
    end = uint64_t(s.offset) + s.size;
  }
  const uint32_t node_size = tree_format_info(h.tree_format).smallest_node;
  if (uint64_t(h.node_count) * node_size > h.tree_size)
    return "node count " + num(h.node_count) + " does not fit the tree section";
  if (h.node_bytes > h.tree_size || h.triangle_base > h.tree_size)
    return "node area or triangle base lies past the tree section";
  if (!has_remap(h)) {
    // Hits name slots: every slot number must stay below MC_NO_HIT.
    if (h.remap_bits != 0) return "no remap section, yet remap entries of " + num(h.remap_bits) + " bits";
    // Slot numbers come from block offsets in the tree section plus a lane:
    // no more of them than that (stored_mesh and callers size arrays by it).
    const uint64_t reachable = uint64_t(h.tree_size) / std::max(1u, h.slot_divisor) + 128;
    if (h.remap_slots < h.triangle_count || h.remap_slots > reachable)
      return "no remap, and " + num(h.remap_slots) + " slot numbers for " + num(h.triangle_count) +
             " triangles (at most " + num(reachable) + " from the tree section)";
  } else {
    // remap_bits 0: in input order, no entries (layout/blob_format.h).
    if (h.remap_bits > 32 || (h.remap_bits != 0 && (uint64_t(1) << h.remap_bits) < h.triangle_count))
      return "remap entries of " + num(h.remap_bits) + " bits cannot hold " + num(h.triangle_count) + " triangles";
    const uint64_t entry_bytes = h.remap_bits ? (uint64_t(h.triangle_count) * h.remap_bits + 7) / 8 + 8 : 0;
    if (12ull * remap_words(h) + entry_bytes > h.remap_size)
      return "remap section of " + num(h.remap_size) + " bytes is too small for " + num(h.remap_slots) +
             " slots and " + num(h.triangle_count) + " entries";
    uint64_t used = 0;
    for (uint32_t w = 0; w < remap_words(h); ++w) {
      if (load<uint32_t>(blob.data() + h.remap_offset + 8ull * remap_words(h) + 4ull * w) != used)
        return "remap rank of word " + num(w) + " does not count the used slots before it";
      used += uint64_t(std::popcount(remap_used(blob.data(), h, w)));
    }
    if (used != h.triangle_count)
      return "remap marks " + num(used) + " slots used for " + num(h.triangle_count) + " triangles";
    for (uint32_t i = 0; h.remap_bits != 0 && i < h.triangle_count; ++i)
      if (remap_packed(blob.data(), h, i) >= h.triangle_count)
        return "remap entry " + num(i) + " names triangle " + num(remap_packed(blob.data(), h, i)) + " of " +
               num(h.triangle_count);
  }
  if (h.tree_format == MC_TREE_QUADTREEHALFFLOAT &&
      !(std::isfinite(h.node_scale) && h.node_scale > 0 && std::isfinite(h.node_origin[0]) &&
        std::isfinite(h.node_origin[1]) && std::isfinite(h.node_origin[2])))
    return "half-float node origin or scale is not finite";

  if (tree_format_info(h.tree_format).triangles == TreeTriangles::Indexed24) {
    if (std::string e = validate_zerobyte(blob, h); !e.empty()) return e;
    return check_tree_bounds(blob.data());
  }
  if (h.triangle_format == MC_TRI_INDEXED24) return "Indexed24 triangles belong to the zero-byte trees alone";

  uint64_t triangles = 0;
  if (const LeafCodec* codec = leaf_codec(h.triangle_format)) {
    if (h.slot_divisor != codec->slot_divisor)
      return "slot divisor does not match " + std::string(triangle_format_name(h.triangle_format));
    if (std::string e = walk_tree(*codec, blob.data(), h, &triangles); !e.empty()) return e;
  }
  if (triangles != h.triangle_count)
    return "leaves hold " + num(triangles) + " triangles but the header says " + num(h.triangle_count);
  return check_tree_bounds(blob.data());
}

}  // namespace meshcast::layout
