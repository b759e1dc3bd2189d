// The blob under construction, shared by every tree writer (builder/write_*.cpp
// and build_blob.cpp): the triangle codec as runtime values, the leaves' blocks,
// the vertex pool, the remap, and the refit that makes every node bound what
// the codec decodes.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "builder/binary_tree.h"
#include "builder/build_threads.h"
#include "builder/first_touch.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "layout/blob_format.h"
#include "layout/triangles/block.h"
#include "layout/catalog.h"

namespace meshcast {

// The parts of a triangle codec the writer needs, as a runtime value.
struct CodecOps {
  uint32_t format, slot_divisor;
  layout::GridKind grid;
  uint32_t grid_bits;  // codes a component of the mesh grid (21; CompressedStrip 20)
  bool nested;         // blocks on nested lattices of the grid (BitPackSOA)
  bool moves_floats;   // stores floats it has changed (UncompressedStrip)
  bool independent;    // leaves may be encoded at once (layout/triangles/block.h)
  uint32_t lanes;
  // Null for a format with no blocks (the zero-byte trees' Indexed24,
  // whose writer stores the index words itself).
  uint32_t (*measure)(layout::TriCorners*, uint32_t);  // bytes of a leaf's block
  void (*encode)(layout::TriCorners*, uint32_t, layout::BlockContext&, uint8_t*);
};

CodecOps codec_ops(uint32_t format);  // throws InputError for an unknown format

inline uint32_t align(uint64_t v, uint32_t a) { return uint32_t((v + a - 1) / a * a); }

// Appends the remap section (slot -> input triangle, MC_NO_HIT for an
// unused slot) and fills the header's remap fields: bitmap and ranks only
// when the slots keep the input order, none when `keep` is false.
void append_remap(std::vector<uint8_t>& bytes, layout::BlobHeader& h, const std::vector<uint32_t>& remap, bool keep);

// Shared by both tree writers: the blob under construction.
struct Writer {
  const FilledVector<layout::TriCorners>& corners;
  BuildTree& tree;  // leaf boxes are refitted to what the codec stores
  CodecOps codec;
  layout::BlobHeader h{};
  std::vector<uint8_t> bytes;
  std::vector<uint8_t> pool;
  std::unordered_map<uint64_t, uint32_t> last_index;
  std::vector<uint32_t> remap;
  uint32_t max_block_shift = 0;
  std::vector<uint32_t> leaf_bytes;  // per node: its block's bytes (leaves)
  BuildThreads* threads = nullptr;   // the build's threads (none: this one)

  std::vector<layout::TriCorners> leaf_triangles(uint32_t n) const {
    const BuildNode& leaf = tree.nodes[n];
    std::vector<layout::TriCorners> tris(leaf.count);
    for (uint32_t i = 0; i < leaf.count; ++i) {
      tris[i] = corners[tree.order[leaf.first + i]];
      tris[i].input = tree.order[leaf.first + i];
    }
    return tris;
  }
  void measure_leaves() {
    leaf_bytes.assign(tree.nodes.size(), 0);
    auto measure = [&](uint64_t n) {
      if (!tree.nodes[n].leaf()) return;
      std::vector<layout::TriCorners> tris = leaf_triangles(uint32_t(n));
      leaf_bytes[n] = codec.measure(tris.data(), tree.nodes[n].count);
    };
    for_each_on(threads, tree.nodes.size(), kGrain, measure);
  }
  static constexpr uint64_t kGrain = 512;  // nodes or leaves a chunk of a build thread's work

  // write_leaf(leaves[i], at[leaves[i]]) for every leaf of the list: at once
  // on the build's threads where the codec's blocks are independent, else
  // in the list's order (a shared vertex pool fills in that order).
  void write_leaves(const std::vector<uint32_t>& leaves, const std::vector<uint32_t>& at) {
    if (!threads || !codec.independent) {
      for (uint32_t n : leaves) write_leaf(n, at[n]);
      return;
    }
    uint64_t slots = remap.size();
    for (uint32_t n : leaves) slots = std::max<uint64_t>(slots, first_slot(at[n]) + tree.nodes[n].count);
    remap.resize(slots, MC_NO_HIT);  // write_leaf then only writes its own slots
    threads->for_each(leaves.size(), kGrain, [&](uint64_t i) { write_leaf(leaves[i], at[leaves[i]]); });
  }

  // The slot of the first triangle of a block at tree-section offset `at`.
  uint32_t first_slot(uint32_t at) const { return (at - h.triangle_base) / h.slot_divisor; }

  // Encodes leaf node n's triangles at tree-section offset `at`. The codec
  // hands back the triangles as stored (its order, its decoded corners): the
  // remap follows that order and the leaf's box is refitted to those corners,
  // so node bounds always contain what the walker will decode.
  void write_leaf(uint32_t n, uint32_t at) {
    BuildNode& leaf = tree.nodes[n];
    std::vector<layout::TriCorners> tris = leaf_triangles(n);
    layout::BlockContext ctx{h.tree_offset + at, h.vertex_offset, &pool, &last_index, h.quant_scale, &max_block_shift, &h};
    codec.encode(tris.data(), leaf.count, ctx, bytes.data() + h.tree_offset + at);
    uint32_t slot0 = first_slot(at);
    if (remap.size() < slot0 + leaf.count) remap.resize(slot0 + leaf.count, MC_NO_HIT);
    leaf.box = Box3{};
    for (uint32_t i = 0; i < leaf.count; ++i) {
      remap[slot0 + i] = tris[i].input;
      for (int c = 0; c < 3; ++c) leaf.box.grow(Vec3{tris[i].v[c][0], tris[i].v[c][1], tris[i].v[c][2]});
    }
  }

  // A BruteForce record [count][block] for leaf n at tree-section offset
  // `at` (BruteForce, AABBList); returns the offset after it.
  uint32_t record_bytes(uint32_t n) const { return MC_BRUTE_RECORD_BYTES + leaf_bytes[n]; }
  uint32_t write_record(uint32_t n, uint32_t at) {
    std::memcpy(bytes.data() + h.tree_offset + at, &tree.nodes[n].count, 4);
    write_leaf(n, at + MC_BRUTE_RECORD_BYTES);
    return at + record_bytes(n);
  }

  // Interior boxes from the refitted leaves (children follow their parent
  // in the builder's node order), then the header's bounds from the root.
  void refit() {
    for (size_t n = tree.nodes.size(); n-- > 0;) {
      BuildNode& b = tree.nodes[n];
      if (b.leaf() || b.left == 0) continue;
      b.box = tree.nodes[b.left].box;
      b.box.grow(tree.nodes[b.right].box);
    }
    frame(tree.nodes[0].box);
  }

  // The header's bounds: the box of what the tree's leaves decode to (a
  // writer whose nodes need a frame of their own sets it beside them).
  void frame(const Box3& root) {
    for (int a = 0; a < 3; ++a) h.bounds_min[a] = root.min[a], h.bounds_max[a] = root.max[a];
  }
};


// The 8 bits of seed 002: for the octant with sign bits (x, y, z), bit
// z | y << 1 | x << 2 is set when the second child's centre lies nearer
// along that octant's diagonal.
inline uint32_t pns_code(const Box3& first, const Box3& second) {
  Vec3 a = first.centre(), b = second.centre();
  uint32_t code = 0;
  for (uint32_t octant = 0; octant < 8; ++octant) {
    float dx = octant & 4 ? -1.0f : 1.0f, dy = octant & 2 ? -1.0f : 1.0f, dz = octant & 1 ? -1.0f : 1.0f;
    double d = double(a.x - b.x) * dx + double(a.y - b.y) * dy + double(a.z - b.z) * dz;
    if (d > 0) code |= 1u << octant;
  }
  return code;
}

// What a tree is built from: the mesh, the options, each triangle's box
// (of its stored corners) and the build's threads (none: this one).
struct TreeInput {
  const Mesh& mesh;
  const BuildOptions& options;
  const std::vector<Box3>& boxes;
  const CodecOps& codec;
  BuildReport* report;
  BuildThreads* threads;
  // Another builder's binary tree (builder/tree_source.h), taken where the
  // options' splitter would build one; null: the splitter's.
  const std::function<BuildTree(const std::vector<Box3>&, uint32_t, uint32_t, uint32_t)>* source = nullptr;
};

// The tree writers of builder/write_*.cpp, one a tree format, each step of
// build_blob a member: check refuses a mesh or options the format cannot
// take; codec is what encodes its leaves; depth_limit the deepest level its
// builder may reach; build(in) the tree it lays out (what triangles in what
// order); plan(w) sizes the tree section (header fields tree_size,
// node_bytes, node_count, triangle_base, root) before the buffer exists;
// fill(w) encodes the leaves, refits and writes the nodes. The defaults are
// the binary trees' (InputError texts without the mesh's name: build_blob
// adds it).
struct TreeWriter {
  virtual ~TreeWriter() = default;
  // A leaf size within the 5-bit triangle counts, a node order its bits allow.
  virtual void check(const Mesh& mesh, const BuildOptions& o) const;
  // The options' triangle format (InputError for one that is no codec).
  virtual CodecOps codec(const BuildOptions& o) const { return codec_ops(uint32_t(o.layout.triangles)); }
  // ~0u: no limit.
  virtual uint32_t depth_limit(size_t /*triangles*/, const BuildOptions&) const { return ~0u; }
  // The options' splitter over the triangles (or over seed 003's pairs).
  virtual BuildTree build(const TreeInput& in, uint32_t depth_limit);
  virtual void plan(Writer& w) = 0;
  virtual void fill(Writer& w) = 0;
  // Deepest node a walker's stack must hold (the wide trees' is their own).
  virtual uint32_t depth(const BuildTree& t) const { return t.depth; }
  // The header's leaf_count (BruteForce: its records).
  virtual uint32_t leaf_count(const BuildTree& t) const { return t.leaf_count(); }
};

// The trees of BruteForce and AABBList, which keep their own triangle order
// (so refuse pairing): node 0 (the whole mesh) followed by one leaf a chunk
// of brute_chunk(lanes) triangles of `order`, each written as a record
// [count][block].
BuildTree record_tree(const TreeInput& in, std::vector<uint32_t> order);
// InputError for a given tree (TreeInput::source) where the writer keeps
// its own order: the record trees above, the zero-byte trees.
void refuse_given_tree(const TreeInput& in);

// Each tree format's writer: a make_writer overload on its catalog tag, in
// its family's write_*.cpp.
#define MC_DECLARE_WRITER(Name, ...) std::unique_ptr<TreeWriter> make_writer(layout::tree::Name, const BuildOptions& options);
MC_FOR_EACH_TREE_FORMAT(MC_DECLARE_WRITER)
#undef MC_DECLARE_WRITER

// The writer for options.layout.tree (null for an unknown tree format).
std::unique_ptr<TreeWriter> make_tree_writer(const BuildOptions& options);

}  // namespace meshcast
