#include "layout/blob_format.h"
#include "layout/zerobyte.h"

#include <algorithm>
#include <concepts>
#include <type_traits>
#include <cmath>
#include <vector>

#include "layout/aabblist.h"
#include "layout/aabbtree.h"
#include "layout/catalog.h"
#include "layout/codecs.h"
#include "layout/compressed.h"
#include "layout/lbvh.h"
#include "layout/skdtree.h"
#include "layout/quadtree.h"

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

std::string num(uint64_t v) { return std::to_string(v); }

// Checks one leaf: its block lies in the triangle area of the tree section,
// its slots lie in the remap, and the codec's own indices are in range.
template <class Codec>
std::string check_leaf(const uint8_t* blob, const BlobHeader& h, uint32_t block, uint32_t count,
                       uint32_t max_count = MC_QUAD_MAX_COUNT) {
  if (count == 0 || count > max_count)
    return "leaf at tree offset " + num(block) + " has " + num(count) + " triangles (allowed 1.." +
           num(max_count) + ")";
  if (block < h.triangle_base || (block - h.triangle_base) % 4 != 0)
    return "triangle block at tree offset " + num(block) + " lies before the triangle area (" +
           num(h.triangle_base) + ") or is misaligned";
  uint64_t bytes = block <= h.tree_size ? stored_bytes<Codec>(blob, h.tree_offset + block, count, h.tree_size - block) : 0;
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
  if (!Codec::check(blob, h.tree_offset + block, count, &why)) return why;
  return "";
}

// What every node walk of the validator checks on reaching a node: visits
// bounded by node_count (so a walk of a corrupted DAG stays linear) and the
// depth by MC_MAX_DEPTH (the walkers' stacks).
std::string reach(uint64_t* visited, uint32_t depth, const BlobHeader& h, const std::string& node) {
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

template <class Codec, class Tag>
  requires std::same_as<Tag, tree::AABBTree> || std::same_as<Tag, tree::AABBTreeSplitAxis>
std::string validate_tree(Tag, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  constexpr bool split_axis = std::same_as<Tag, tree::AABBTreeSplitAxis>;
  return walk_nodes(h, 0, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_AABB_NODE_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    AABBNode n = load_aabb_node(blob + h.tree_offset + at);
    uint32_t next = at + MC_AABB_NODE_BYTES;
    if (n.is_leaf()) {
      *triangles += n.value();
      return check_leaf<Codec>(blob, h, next, n.value());
    }
    uint32_t second = aabb_second_child(n, split_axis);
    if (second <= next)
      return "node at tree offset " + num(at) + " has its second child at " + num(second) + ", not after its first child";
    if (split_axis && aabb_split_axis(n) > 2)
      return "node at tree offset " + num(at) + " names split axis " + num(aabb_split_axis(n)) + " (0..2)";
    push(next), push(second);
    return "";
  });
}

// QuadTree and QuadTreeHalfFloat: the same walk over their own child bounds.
template <class Tag>
using QuadBoundsOf = std::conditional_t<std::same_as<Tag, tree::QuadTree>, QuadBoundsFloat, QuadBoundsHalf>;

template <class Codec, class Tag>
  requires std::same_as<Tag, tree::QuadTree> || std::same_as<Tag, tree::QuadTreeHalfFloat>
std::string validate_tree(Tag, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  using Bounds = QuadBoundsOf<Tag>;
  struct Item { uint32_t properties, parent, depth; };
  std::vector<Item> stack{{h.root, 0, 0}};
  uint64_t visited = 0;
  bool root = true;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    uint32_t count = quad_count(it.properties), offset = quad_offset(it.properties);
    if (count != 0) {
      std::string e = check_leaf<Codec>(blob, h, offset, count);
      if (!e.empty()) return e;
      *triangles += count;
      continue;
    }
    if (!root && offset <= it.parent)
      return "node at tree offset " + num(offset) + " does not lie after its parent at " + num(it.parent);
    root = false;
    if (std::string e = reach(&visited, it.depth, h, "node at tree offset " + num(offset)); !e.empty()) return e;
    // Nodes lie before the triangle area, or anywhere in the section when
    // blocks sit among them (the §4.3 orders without "triangles last").
    const uint64_t node_area = h.triangle_base > 0 ? h.triangle_base : h.tree_size;
    if (offset % 4 != 0 || uint64_t(offset) + Bounds::kNodeBytes > node_area)
      return "node at tree offset " + num(offset) + " is misaligned or outside the node area (" + num(node_area) +
             " bytes)";
    const uint8_t* node = blob + h.tree_offset + offset;
    for (int k = 0; k < 4; ++k) {
      uint32_t p = quad_child_properties(node, Bounds::kPropertiesAt, k);
      if (p == 0) continue;  // unused child: the walker never follows it
      stack.push_back({p, offset, it.depth + 1});
    }
  }
  return "";
}

// AABBTreePNS: nodes by index, each child after its parent.
template <class Codec>
std::string validate_tree(tree::AABBTreePNS, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  if (h.node_count == 0 || uint64_t(h.node_count) * MC_AABB_NODE_BYTES != h.triangle_base)
    return "AABBTreePNS: the triangle base must follow the " + num(h.node_count) + " nodes";
  return walk_nodes(h, 0, "node ", [&](uint32_t index, auto push) -> std::string {
    if (index >= h.node_count) return "node index " + num(index) + " past the " + num(h.node_count) + " nodes";
    AABBNode n = load_aabb_node(blob + h.tree_offset + uint64_t(index) * MC_AABB_NODE_BYTES);
    if (n.is_leaf()) {
      uint64_t block = uint64_t(h.triangle_base) + 4ull * (n.properties & MC_PNS_BLOCK_MASK);
      if (block > h.tree_size) return "leaf " + num(index) + " points past the tree section";
      *triangles += pns_leaf_count(n);
      return check_leaf<Codec>(blob, h, uint32_t(block), pns_leaf_count(n));
    }
    uint32_t second = pns_second_index(n);
    if (second <= index + 1) return "node " + num(index) + " has its second child at " + num(second) + ", not after its first";
    push(index + 1), push(second);
    return "";
  });
}

// AABBTreeCompressed: the section header, then nodes and blocks, each
// right child after its node, each left child right behind it.
template <class Codec>
std::string validate_tree(tree::AABBTreeCompressed, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  if (h.tree_size < MC_COMPRESSED_HEADER_BYTES) return "AABBTreeCompressed: the tree section is shorter than its header";
  const uint8_t* tree = blob + h.tree_offset;
  CompressedBox root = compressed_root_box(tree);
  for (int a = 0; a < 3; ++a)
    if (!(root.min[a] <= root.max[a]) || !std::isfinite(root.min[a]) || !std::isfinite(root.max[a]))
      return "AABBTreeCompressed: the root box is empty or not finite";
  if (uint32_t count = compressed_root_count(tree)) {
    std::string e = check_leaf<Codec>(blob, h, MC_COMPRESSED_HEADER_BYTES, count);
    *triangles += count;
    return e;
  }
  return walk_nodes(h, MC_COMPRESSED_HEADER_BYTES, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_COMPRESSED_NODE_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    CompressedNode n = load<CompressedNode>(tree + at);
    uint32_t left = at + MC_COMPRESSED_NODE_BYTES;
    if (n.right <= left)
      return "node at tree offset " + num(at) + " has its right child at " + num(n.right) + ", not after its left";
    const uint32_t child[2] = {left, n.right}, count[2] = {n.left_count(), n.right_count()};
    for (int k = 0; k < 2; ++k) {
      if (count[k] == 0) {
        push(child[k]);
        continue;
      }
      if (std::string e = check_leaf<Codec>(blob, h, child[k], count[k]); !e.empty()) return e;
      *triangles += count[k];
    }
    return "";
  });
}

// SKDTree: interior nodes and leaves of two sizes, each right child after
// its node.
template <class Codec>
std::string validate_tree(tree::SKDTree, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  for (int a = 0; a < 3; ++a)
    if (!(h.bounds_min[a] <= h.bounds_max[a]) || !std::isfinite(h.bounds_min[a]) || !std::isfinite(h.bounds_max[a]))
      return "SKDTree: the root box in the header is empty or not finite";
  return walk_nodes(h, 0, "node at tree offset ", [&](uint32_t at, auto push) -> std::string {
    if (at % 4 != 0 || uint64_t(at) + MC_SKD_LEAF_BYTES > h.tree_size)
      return "node at tree offset " + num(at) + " is misaligned or past the tree section";
    uint32_t p = load<uint32_t>(tree + at);
    if (skd_is_leaf(p)) {
      *triangles += skd_value(p);
      return check_leaf<Codec>(blob, h, at + MC_SKD_LEAF_BYTES, skd_value(p));
    }
    uint32_t left = at + MC_SKD_INTERIOR_BYTES;
    if (uint64_t(left) > h.tree_size || skd_value(p) <= left)
      return "node at tree offset " + num(at) + " has its right child at " + num(skd_value(p)) + ", not after its left";
    if (!std::isfinite(skd_left_plane(tree + at)) || !std::isfinite(skd_right_plane(tree + at)))
      return "node at tree offset " + num(at) + " has a plane that is not finite";
    push(left), push(skd_value(p));
    return "";
  });
}

// StacklessLBVH: every node a walk reaches is a leaf or has both children
// inside the array; holes are never reached.
template <class Codec>
std::string validate_tree(tree::StacklessLBVH, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  if (h.node_count == 0 || h.node_count > (1u << (MC_LBVH_MAX_DEPTH + 1)) - 1 ||
      uint64_t(h.node_count) * MC_LBVH_NODE_BYTES != h.triangle_base)
    return "StacklessLBVH: " + num(h.node_count) + " node slots do not fit its heap or its triangle base";
  return walk_nodes(h, 1, "node ", [&](uint32_t index, auto push) -> std::string {
    LBVHNode n = load_lbvh_node(tree, index);
    if (n.count == 0) return "node " + num(index) + " is a hole but its parent is an interior node";
    if (n.count > 0) {
      *triangles += uint32_t(n.count);
      return check_leaf<Codec>(blob, h, n.position, uint32_t(n.count));
    }
    if (uint64_t(index) * 2 + 1 > h.node_count)
      return "node " + num(index) + " has children past the " + num(h.node_count) + " node slots";
    push(2 * index), push(2 * index + 1);
    return "";
  });
}

// BruteForce records from tree-section offset *at up to `end`: each a
// valid leaf of at most brute_chunk() triangles, the last ending at `end`.
template <class Codec>
std::string check_records(const uint8_t* blob, const BlobHeader& h, uint64_t* at, uint64_t end, uint64_t* triangles,
                          uint64_t* records) {
  while (*at < end) {
    if (*at + MC_BRUTE_RECORD_BYTES > end) return "record at tree offset " + num(*at) + " is cut short";
    uint32_t count = load<uint32_t>(blob + h.tree_offset + *at);
    std::string e = check_leaf<Codec>(blob, h, uint32_t(*at + MC_BRUTE_RECORD_BYTES), count, brute_chunk(Codec::kLanes));
    if (!e.empty()) return e;
    *triangles += count;
    *at += MC_BRUTE_RECORD_BYTES + stored_bytes<Codec>(blob, h.tree_offset + uint32_t(*at) + MC_BRUTE_RECORD_BYTES, count, ~0ull);
    ++*records;
  }
  if (*at != end) return "record ending at tree offset " + num(*at) + " runs past " + num(end);
  return "";
}

// BruteForce: the records must tile the tree section exactly.
template <class Codec>
std::string validate_tree(tree::BruteForce, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  uint64_t at = 0, records = 0;
  if (std::string e = check_records<Codec>(blob, h, &at, h.tree_size, triangles, &records); !e.empty()) return e;
  if (records != h.node_count) return "BruteForce holds " + num(records) + " records, the header says " + num(h.node_count);
  return "";
}

// AABBList: the entries, then the batches' records tiling the rest of the
// section in batch order, each batch's records holding its count, and every
// batch but the last full (the shaders find records by arithmetic).
template <class Codec>
std::string validate_tree(tree::AABBList, const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  const uint8_t* tree = blob + h.tree_offset;
  if (h.node_count == 0 || h.triangle_base != uint64_t(h.node_count) * MC_LIST_ENTRY_BYTES)
    return "AABBList of " + num(h.node_count) + " batches does not start its records at tree offset " +
           num(uint64_t(h.node_count) * MC_LIST_ENTRY_BYTES);
  uint64_t at = h.triangle_base, records = 0;
  for (uint32_t b = 0; b < h.node_count; ++b) {
    const ListEntry e = load_list_entry(tree, b);
    const std::string batch = "AABBList batch " + num(b);
    if (e.records != at) return batch + " starts at tree offset " + num(e.records) + ", not " + num(at);
    if (e.count == 0 || e.count > MC_LIST_BATCH || (b + 1 < h.node_count && e.count != MC_LIST_BATCH))
      return batch + " holds " + num(e.count) + " triangles (" + num(MC_LIST_BATCH) + " each, the last 1.." +
             num(MC_LIST_BATCH) + ")";
    const uint32_t end = list_records_end(tree, h, b);
    if (end < at || end > h.tree_size) return batch + "'s records end at " + num(end) + ", outside the tree section";
    uint64_t held = 0;
    if (std::string why = check_records<Codec>(blob, h, &at, end, &held, &records); !why.empty()) return why;
    if (held != e.count) return batch + "'s records hold " + num(held) + " triangles, its entry says " + num(e.count);
    *triangles += held;
  }
  return "";
}

// The tree format's validator (the catalog's switch); the zero-byte trees
// have their own (validate_zerobyte).
template <class Codec>
std::string walk_tree(const uint8_t* blob, const BlobHeader& h, uint64_t* triangles) {
  return with_tree_format(h.tree_format, "unknown tree format " + num(h.tree_format), [&](auto tag) -> std::string {
    if constexpr (decltype(tag)::kTriangles == TreeTriangles::AllCodecs)
      return validate_tree<Codec>(tag, blob, h, triangles);
    else
      return "the zero-byte trees hold Indexed24 triangles alone";
  });
}

struct Section { const char* name; uint32_t offset, size; };

}  // namespace

std::string validate(std::span<const uint8_t> blob) {
  if (blob.size() < sizeof(BlobHeader))
    return "blob of " + num(blob.size()) + " bytes is shorter than its header (" + num(sizeof(BlobHeader)) + ")";
  if (reinterpret_cast<uintptr_t>(blob.data()) % alignof(BlobHeader) != 0)
    return "blob buffer is not 4-byte aligned; load it into aligned memory";
  BlobHeader h;
  std::memcpy(&h, blob.data(), sizeof h);
  if (h.magic != MC_BLOB_MAGIC) return "not a meshcast blob (bad magic)";
  if (h.version != MC_BLOB_VERSION)
    return "blob version " + num(h.version) + " is not the supported version " + num(MC_BLOB_VERSION);
  if (h.total_size != blob.size())
    return "blob is " + num(blob.size()) + " bytes but its header says " + num(h.total_size) + " (truncated?)";
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

  if (tree_format_info(h.tree_format).triangles == TreeTriangles::Indexed24) return validate_zerobyte(blob, h);
  if (h.triangle_format == MC_TRI_INDEXED24) return "Indexed24 triangles belong to the zero-byte trees alone";

  uint64_t triangles = 0;
  std::string e;
#define MC_WALK(Codec, text)                                                          \
  if (h.triangle_format == Codec::kFormat) {                                          \
    if (h.slot_divisor != Codec::kSlotDivisor) return "slot divisor does not match " text; \
    e = walk_tree<Codec>(blob.data(), h, &triangles);                                 \
  }
  MC_FOR_EACH_TRIANGLE_CODEC(MC_WALK)
#undef MC_WALK
  if (!e.empty()) return e;
  if (triangles != h.triangle_count)
    return "leaves hold " + num(triangles) + " triangles but the header says " + num(h.triangle_count);
  return "";
}

}  // namespace meshcast::layout
