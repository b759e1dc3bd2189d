#include "cpu/encode.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <unordered_map>

#include "cpu/build.h"
#include "cpu/pairing.h"
#include "cpu/pairs.h"
#include "layout/aabbtree.h"
#include "layout/codecs.h"
#include "layout/quadtree.h"
#include "cpu/writer.h"
#include "cpu/zerobyte.h"

namespace meshcast {

using layout::BlobHeader;
using layout::TriCorners;

namespace {

template <class C>
constexpr bool nested_blocks() {
  if constexpr (requires { C::kNestedBlocks; }) return C::kNestedBlocks;
  return false;
}
template <class C>
constexpr uint32_t grid_bits() {
  if constexpr (requires { C::kGridBits; }) return C::kGridBits;
  return MC_BITPACK_BITS;
}
template <class C>
constexpr bool moves_floats() {
  if constexpr (requires { C::kMovesFloats; }) return C::kMovesFloats;
  return false;
}
template <class C>
uint32_t measure(TriCorners* tris, uint32_t count) {
  if constexpr (requires { C::measure(tris, count); }) return C::measure(tris, count);
  return C::block_bytes(count);
}

}  // namespace

CodecOps codec_ops(uint32_t format) {
#define MC_OPS(Codec, name)                                                                         \
  if (format == layout::Codec::kFormat)                                                            \
    return {layout::Codec::kFormat,        layout::Codec::kSlotDivisor,   layout::Codec::kGrid,        \
            grid_bits<layout::Codec>(),    nested_blocks<layout::Codec>(), moves_floats<layout::Codec>(), \
            layout::Codec::kLanes,         &measure<layout::Codec>,       &layout::Codec::encode};
  MC_FOR_EACH_TRIANGLE_CODEC(MC_OPS)
#undef MC_OPS
  throw InputError("unknown triangle format " + std::to_string(format));
}

// The public names (meshcast/build.h) are the ids a blob stores.
static_assert(uint32_t(TreeFormat::AABBTree) == MC_TREE_AABBTREE &&
              uint32_t(TreeFormat::QuadTree) == MC_TREE_QUADTREE &&
              uint32_t(TreeFormat::QuadTreeHalfFloat) == MC_TREE_QUADTREEHALFFLOAT &&
              uint32_t(TreeFormat::BruteForce) == MC_TREE_BRUTEFORCE &&
              uint32_t(TreeFormat::AABBTreeSplitAxis) == MC_TREE_AABBTREESPLITAXIS &&
              uint32_t(TreeFormat::AABBTreePNS) == MC_TREE_AABBTREEPNS &&
              uint32_t(TreeFormat::AABBTreeCompressed) == MC_TREE_AABBTREECOMPRESSED &&
              uint32_t(TreeFormat::SKDTree) == MC_TREE_SKDTREE &&
              uint32_t(TreeFormat::StacklessLBVH) == MC_TREE_STACKLESSLBVH &&
              uint32_t(TreeFormat::AABBList) == MC_TREE_AABBLIST &&
              uint32_t(TreeFormat::ZeroByteTree) == MC_TREE_ZEROBYTE &&
              uint32_t(TreeFormat::ZeroByteHybrid) == MC_TREE_ZEROBYTEHYBRID);
static_assert(uint32_t(TriangleFormat::Float3) == MC_TRI_FLOAT3 &&
              uint32_t(TriangleFormat::Float3SOA4) == MC_TRI_FLOAT3SOA4 &&
              uint32_t(TriangleFormat::Indexed8BitPackSOA4) == MC_TRI_INDEXED8BITPACKSOA4 &&
              uint32_t(TriangleFormat::Indexed16) == MC_TRI_INDEXED16 &&
              uint32_t(TriangleFormat::Indexed32) == MC_TRI_INDEXED32 &&
              uint32_t(TriangleFormat::Indexed16SOA4) == MC_TRI_INDEXED16SOA4 &&
              uint32_t(TriangleFormat::Indexed32SOA4) == MC_TRI_INDEXED32SOA4 &&
              uint32_t(TriangleFormat::Indexed16BitPackSOA4) == MC_TRI_INDEXED16BITPACKSOA4 &&
              uint32_t(TriangleFormat::Indexed32BitPackSOA4) == MC_TRI_INDEXED32BITPACKSOA4 &&
              uint32_t(TriangleFormat::Float3SOA8) == MC_TRI_FLOAT3SOA8 &&
              uint32_t(TriangleFormat::Float3SOA128) == MC_TRI_FLOAT3SOA128 &&
              uint32_t(TriangleFormat::BitPackSOA4) == MC_TRI_BITPACKSOA4 &&
              uint32_t(TriangleFormat::BitPackSOA128) == MC_TRI_BITPACKSOA128 &&
              uint32_t(TriangleFormat::BitPack) == MC_TRI_BITPACK &&
              uint32_t(TriangleFormat::UncompressedStrip) == MC_TRI_UNCOMPRESSEDSTRIP &&
              uint32_t(TriangleFormat::CompressedStrip) == MC_TRI_COMPRESSEDSTRIP &&
              uint32_t(TriangleFormat::Indexed24) == MC_TRI_INDEXED24 &&
              uint32_t(TriangleFormat::Float3PairSOA4) == MC_TRI_FLOAT3PAIRSOA4);

namespace {

// Every tree format id, in the order of cpu/pairs.h.
std::vector<uint32_t> tree_formats() {
  std::vector<uint32_t> ids;
#define MC_ID(Tree, id) ids.push_back(id);
  MC_FOR_EACH_TREE(MC_ID)
#undef MC_ID
  return ids;
}

// Every triangle format id, in the order of the list.
std::vector<uint32_t> triangle_formats() {
  std::vector<uint32_t> ids;
#define MC_ID(Codec, name) ids.push_back(layout::Codec::kFormat);
  MC_FOR_EACH_TRIANGLE_CODEC(MC_ID)
#undef MC_ID
  return ids;
}

// kGridPowerOfTwo formats (BitPackSOA, layout/soa.h): blocks of `lanes`
// consecutive triangles of each leaf; every position goes to the coarsest
// block lattice among the blocks that use it, repeated until no block needs
// a coarser step, so all blocks decode a shared position to the same bits.
// Positions are keyed by their mesh-grid word (so unwelded copies of a
// vertex move together) and rounded once, from the grid position, to their
// final lattice. Returns the largest shift.
uint32_t snap_to_block_lattices(const BuildTree& t, std::vector<TriCorners>& corners, uint32_t lanes,
                                const float grid[3]) {
  const std::vector<TriCorners> original = corners;
  uint32_t largest = 0;
  for (int axis = 0; axis < 3; ++axis) {
    std::unordered_map<uint64_t, uint32_t> shift;  // grid word -> lattice shift
    for (bool changed = true; changed;) {
      changed = false;
      for (const BuildNode& leaf : t.nodes) {
        if (!leaf.leaf()) continue;
        for (uint32_t b = 0; b < leaf.count; b += lanes) {
          float lo = INFINITY, hi = -INFINITY;
          uint32_t end = std::min(leaf.count, b + lanes);
          for (uint32_t i = b; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
              float v = corners[t.order[leaf.first + i]].v[c][axis];
              lo = std::min(lo, v), hi = std::max(hi, v);
            }
          float step, offset;
          uint32_t m;
          layout::block_step(lo, hi, grid[axis], &step, &offset, &m);
          for (uint32_t i = b; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
              uint32_t& s = shift[original[t.order[leaf.first + i]].packed[c]];
              if (m > s) s = m, changed = true;
            }
        }
      }
      for (size_t k = 0; k < corners.size(); ++k)
        for (int c = 0; c < 3; ++c) {
          auto it = shift.find(original[k].packed[c]);
          uint32_t m = it == shift.end() ? 0 : it->second;
          double step = double(grid[axis]) * std::ldexp(1.0, int(m));
          float v = original[k].v[c][axis];
          corners[k].v[c][axis] = step > 0 ? float(std::round(double(v) / step) * step) : v;
        }
    }
    for (const auto& [word, m] : shift) largest = std::max(largest, m);
  }
  return largest;
}

// BruteForce and AABBList: no tree. The "tree" is node 0 (the whole mesh)
// followed by one leaf a chunk of `chunk` triangles of `order` (BruteForce:
// input order; AABBList: batch after batch, and `chunk` divides the batch);
// each becomes a record [count][block].
BuildTree chunk_tree(const std::vector<Box3>& boxes, std::vector<uint32_t> order, uint32_t chunk) {
  BuildTree t;
  t.order = std::move(order);
  t.nodes.emplace_back();
  for (uint32_t i : t.order) t.nodes[0].box.grow(boxes[i]);
  for (uint32_t first = 0; first < t.order.size(); first += chunk) {
    BuildNode leaf;
    leaf.first = first;
    leaf.count = std::min<uint32_t>(chunk, uint32_t(t.order.size()) - first);
    for (uint32_t i = first; i < first + leaf.count; ++i) leaf.box.grow(boxes[t.order[i]]);
    t.nodes.push_back(leaf);
  }
  return t;
}

// Seed 003: the tree over pairs (and the triangles left single), each
// expanded back to its triangles side by side.
BuildTree build_paired(const Mesh& mesh, const BuildOptions& o, const std::vector<Box3>& boxes, uint32_t depth_limit,
                       BuildReport* report) {
  if (o.leaf_size < 2) throw InputError("pairing needs leaves of at least 2 triangles (leaf size " + std::to_string(o.leaf_size) + ")");
  Pairing p = pair_triangles(mesh);
  std::vector<uint32_t> members, start{0};
  std::vector<Box3> unit_boxes;
  for (uint32_t t = 0; t < p.partner.size(); ++t) {
    const uint32_t q = p.partner[t];
    if (q != MC_NO_HIT && q < t) continue;  // already in its partner's unit
    Box3 box = boxes[t];
    members.push_back(t);
    if (q != MC_NO_HIT) members.push_back(q), box.grow(boxes[q]);
    start.push_back(uint32_t(members.size()));
    unit_boxes.push_back(box);
  }
  if (report) report->pairing = p.decision, report->paired_ratio = p.paired_ratio;
  // A leaf of leaf_size / 2 units holds at most leaf_size triangles; at the
  // depth limit half the 5-bit count's 31.
  BuildTree units = build_tree(unit_boxes, o.splitter, o.leaf_size / 2, depth_limit, MC_QUAD_MAX_COUNT / 2);
  return expand_groups(units, members, start);
}

BuildTree build_for(const Mesh& mesh, const BuildOptions& o, const std::vector<Box3>& boxes, const CodecOps& codec,
                    uint32_t depth_limit, BuildReport* report) {
  const uint32_t chunk = layout::brute_chunk(codec.lanes);
  if (o.pairing && (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE || uint32_t(o.layout.tree) == MC_TREE_AABBLIST))
    throw InputError("pairing builds trees; " + std::string(layout::tree_format_name(uint32_t(o.layout.tree))) +
                     " keeps its own triangle order");
  if (o.pairing) return build_paired(mesh, o, boxes, depth_limit, report);
  if (uint32_t(o.layout.tree) == MC_TREE_BRUTEFORCE) {
    std::vector<uint32_t> input(boxes.size());
    std::iota(input.begin(), input.end(), 0u);
    return chunk_tree(boxes, std::move(input), chunk);
  }
  if (uint32_t(o.layout.tree) == MC_TREE_AABBLIST) {
    static_assert(MC_LIST_BATCH % MC_BRUTE_CHUNK == 0 && MC_LIST_BATCH % 128 == 0, "records must tile a batch");
    return chunk_tree(boxes, group_batches(boxes, MC_LIST_BATCH, o.grouping), chunk);
  }
  return build_tree(boxes, o.splitter, o.leaf_size, depth_limit);
}

}  // namespace

std::unique_ptr<TreeWriter> make_tree_writer(const BuildOptions& o) {
  switch (uint32_t(o.layout.tree)) {
    case MC_TREE_AABBTREE: return make_aabb_writer(false);
    case MC_TREE_AABBTREESPLITAXIS: return make_aabb_writer(true);
    case MC_TREE_AABBTREEPNS: return make_pns_writer();
    case MC_TREE_AABBTREECOMPRESSED: return make_compressed_writer();
    case MC_TREE_SKDTREE: return make_skd_writer();
    case MC_TREE_STACKLESSLBVH: return make_lbvh_writer(o.lbvh_near_first);
    case MC_TREE_QUADTREE: return make_quad_writer(false, o.node_order);
    case MC_TREE_QUADTREEHALFFLOAT: return make_quad_writer(true, o.node_order);
    case MC_TREE_AABBLIST: return make_aabblist_writer();
  }
  return make_bruteforce_writer();
}

std::string node_order_refusal(uint32_t tree, NodeOrder order) {
  if (order == NodeOrder::Default || tree == MC_TREE_QUADTREE || tree == MC_TREE_QUADTREEHALFFLOAT) return "";
  // What each other format's bits fix (seed 000 5.1-5.5, seed 001).
  NodeOrder fixed = NodeOrder::DepthFirst;
  const char* why = "its first child and its leaves' blocks sit right behind their node";
  if (tree == MC_TREE_AABBTREEPNS) fixed = NodeOrder::DepthFirstTrianglesLast, why = "it addresses nodes by depth-first index";
  if (tree == MC_TREE_STACKLESSLBVH) fixed = NodeOrder::BreadthFirstTrianglesLast, why = "its nodes are a heap";
  if (tree == MC_TREE_BRUTEFORCE) return "BruteForce has no tree, so no node order";
  if (tree == MC_TREE_AABBLIST) return "AABBList is a list of batches, so no node order";
  if (order == fixed) return "";
  return std::string(layout::tree_format_name(tree)) + " is always " + node_order_name(fixed) + ": " + why +
         " (seed 000 4.3 orders apply where a format allows them)";
}

void quantization_bound(const float offset[3], const float scale[3], float bound[3]) {
  for (int a = 0; a < 3; ++a) {
    float top = std::fabs(offset[a]) + float(MC_BITPACK_MAX) * scale[a];
    float ulp = std::nextafter(std::max(std::fabs(offset[a]), top), INFINITY) - std::max(std::fabs(offset[a]), top);
    bound[a] = 0.5f * scale[a] + float(MC_BITPACK_MAX) * scale[a] * 0x1p-23f + ulp;
  }
}

// The remap section after the blob's bytes so far: slot -> input triangle
// (MC_NO_HIT: no triangle), as few bits as the triangle count needs; only
// the used slots and their ranks when the slots keep the input order; none
// when the caller asked for none (layout/blob.h).
void append_remap(std::vector<uint8_t>& bytes, BlobHeader& hd, const std::vector<uint32_t>& remap, bool keep) {
  hd.remap_slots = uint32_t(remap.size());
  hd.remap_offset = align(bytes.size(), 8);
  if (!keep) {
    hd.remap_bits = hd.remap_size = 0;
    hd.remap_offset = align(bytes.size(), 4);
    bytes.resize(hd.remap_offset, 0);
    return;
  }
  uint32_t next = 0;  // in order: the used slots name triangles 0, 1, 2, ...
  for (uint32_t s = 0; s < hd.remap_slots && next != MC_NO_HIT; ++s)
    if (remap[s] != MC_NO_HIT) next = remap[s] == next ? next + 1 : MC_NO_HIT;
  const bool in_order = next == hd.triangle_count;
  hd.remap_bits = in_order ? 0 : std::max(1u, uint32_t(std::bit_width(hd.triangle_count - 1u)));
  const uint32_t words = layout::remap_words(hd);
  const uint64_t entry_bytes = in_order ? 0 : (uint64_t(hd.triangle_count) * hd.remap_bits + 7) / 8 + 8;
  hd.remap_size = align(12ull * words + entry_bytes, 8);
  bytes.resize(uint64_t(hd.remap_offset) + hd.remap_size, 0);
  uint8_t* used = bytes.data() + hd.remap_offset;
  uint8_t* rank = used + 8ull * words;
  uint8_t* entries = rank + 4ull * words;
  uint32_t index = 0;
  for (uint32_t s = 0; s < hd.remap_slots; ++s) {
    if (s % 64 == 0) std::memcpy(rank + 4ull * (s / 64), &index, 4);
    if (remap[s] == MC_NO_HIT) continue;
    used[s / 8] |= uint8_t(1u << (s % 8));
    if (in_order) {
      ++index;
      continue;
    }
    uint64_t bit = uint64_t(index++) * hd.remap_bits;
    uint64_t word;
    std::memcpy(&word, entries + (bit >> 3), 8);
    word |= uint64_t(remap[s]) << (bit & 7);
    std::memcpy(entries + (bit >> 3), &word, 8);
  }
}

std::vector<uint8_t> build_blob(const MeshView& mesh, const BuildOptions& options, const std::string& name,
                                BuildReport* report) {
  return build_blob(copy_mesh(mesh, name), options, name, report);
}

std::vector<uint8_t> build_blob(const Mesh& mesh, const BuildOptions& o, const std::string& name,
                                BuildReport* report) {
  auto start = std::chrono::steady_clock::now();
  check_mesh(mesh, name);
  if (uint32_t(o.layout.tree) == MC_TREE_ZEROBYTE || uint32_t(o.layout.tree) == MC_TREE_ZEROBYTEHYBRID)
    return build_zerobyte_blob(mesh, o, name, report);
  if (o.leaf_size < 1 || o.leaf_size > MC_QUAD_MAX_COUNT)
    throw InputError(name + ": leaf size " + std::to_string(o.leaf_size) + " is outside 1.." +
                     std::to_string(MC_QUAD_MAX_COUNT) + " (5-bit triangle counts, seed 000 5.6)");
  if (layout::tree_format_name(uint32_t(o.layout.tree)).empty()) throw InputError(name + ": unknown tree format");
  CodecOps codec = codec_ops(uint32_t(o.layout.triangles));
  if (std::string why = node_order_refusal(uint32_t(o.layout.tree), o.node_order); !why.empty())
    throw InputError(name + ": " + why);

  BlobHeader h{};
  h.magic = MC_BLOB_MAGIC, h.version = MC_BLOB_VERSION;
  h.tree_format = uint32_t(o.layout.tree), h.triangle_format = uint32_t(o.layout.triangles);
  h.triangle_count = uint32_t(mesh.triangles.size());
  h.leaf_size = o.leaf_size;
  h.slot_divisor = codec.slot_divisor;

  // Stored triangle corners: bit-packed formats quantize against the mesh box.
  Box3 mesh_box = mesh.bounds();
  const bool grid = codec.grid != layout::kGridNone;
  for (int a = 0; a < 3; ++a) {
    double lo = mesh_box.min[a], extent = double(mesh_box.max[a]) - lo;
    if (codec.grid == layout::kGridMeshBox) {
      h.quant_offset[a] = float(lo), h.quant_scale[a] = float(extent / MC_BITPACK_MAX);
    } else if (codec.grid == layout::kGridPowerOfTwo) {
      // The smallest power of two that spans the extent in 2^21 - 2 steps,
      // and the grid point at or below the minimum.
      // A flat axis keeps its one coordinate (step 0).
      double codes = std::ldexp(1.0, int(codec.grid_bits)) - 2;
      double step = extent > 0 ? std::ldexp(1.0, std::ilogb(extent / codes) + 1) : 0.0;
      h.quant_scale[a] = float(step), h.quant_offset[a] = step > 0 ? float(std::floor(lo / step) * step) : float(lo);
    } else {
      h.quant_offset[a] = 0, h.quant_scale[a] = 0;
    }
  }
  std::vector<uint64_t> packed(grid ? mesh.vertices.size() : 0);
  for (size_t v = 0; v < packed.size(); ++v) {
    float p[3] = {mesh.vertices[v].x, mesh.vertices[v].y, mesh.vertices[v].z};
    packed[v] = layout::bitpack_encode(p, h.quant_offset, h.quant_scale);
  }
  std::vector<TriCorners> corners(mesh.triangles.size());
  std::vector<Box3> boxes(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      uint32_t v = mesh.triangles[t][c];
      if (grid) {
        corners[t].vertex[c] = v;
        corners[t].packed[c] = packed[v];
        layout::bitpack_decode(packed[v], h.quant_offset, h.quant_scale, corners[t].v[c]);
      } else {
        corners[t].packed[c] = 0;
        corners[t].vertex[c] = v;
        corners[t].v[c][0] = mesh.vertices[v].x, corners[t].v[c][1] = mesh.vertices[v].y;
        corners[t].v[c][2] = mesh.vertices[v].z;
      }
      boxes[t].grow(Vec3{corners[t].v[c][0], corners[t].v[c][1], corners[t].v[c][2]});
    }
  }

  uint32_t depth_limit = ~0u;
  if (uint32_t(o.layout.tree) == MC_TREE_STACKLESSLBVH) {
    // The seed's choice, within the heap's reach (the capacity check then
    // says when a mesh is too large for it).
    uint32_t d = o.lbvh_depth ? o.lbvh_depth
                              : std::min(uint32_t(std::bit_width(mesh.triangles.size())) + 1, MC_LBVH_MAX_DEPTH + 1);
    if (d > MC_LBVH_MAX_DEPTH + 1)
      throw InputError(name + ": StacklessLBVH depth limit " + std::to_string(d) + " exceeds " +
                       std::to_string(MC_LBVH_MAX_DEPTH + 1) + " (2^26 node slots)");
    depth_limit = d - 1;
  }
  BuildTree tree;
  try {
    tree = build_for(mesh, o, boxes, codec, depth_limit, report);
  } catch (const InputError& e) {
    throw InputError(name + ": " + std::string(layout::tree_format_name(uint32_t(o.layout.tree))) + ": " + e.what());
  }
  uint32_t lattice_shift = codec.nested ? snap_to_block_lattices(tree, corners, codec.lanes, h.quant_scale) : 0;
  Writer writer{corners, tree, codec, h, {}, {}, {}, {}, {}, {}};
  BlobHeader& hd = writer.h;
  writer.measure_leaves();

  std::unique_ptr<TreeWriter> tree_writer = make_tree_writer(o);
  try {
    tree_writer->plan(writer);
  } catch (const InputError& e) {
    throw InputError(name + ": " + e.what());
  }
  uint32_t depth = tree_writer->depth(tree);
  if (depth > MC_MAX_DEPTH)
    throw InputError(name + ": the tree is " + std::to_string(depth) + " levels deep, beyond the walkers' limit of " +
                     std::to_string(MC_MAX_DEPTH));
  hd.max_depth = depth;
  hd.leaf_count = tree.leaf_count();  // BruteForce: the records
  hd.tree_offset = align(MC_BLOB_HEADER_BYTES, 64);  // 64-byte nodes start on a cache line
  hd.vertex_offset = align(uint64_t(hd.tree_offset) + hd.tree_size, 8);
  writer.bytes.assign(hd.vertex_offset, 0);
  try {
    tree_writer->fill(writer);
  } catch (const std::length_error& e) {  // a codec's own limit (index width)
    throw InputError(name + ": " + layout_name(uint32_t(o.layout.tree), uint32_t(o.layout.triangles)) + ": " + e.what());
  }
  // Vertices and remap at most 8 + 12 bytes a triangle on top of this.
  if (uint64_t(hd.vertex_offset) + writer.pool.size() + 12ull * mesh.triangles.size() + 4096 > 0xF0000000ull)
    throw InputError(name + ": the blob would exceed the 4 GiB its 32-bit offsets reach");

  hd.vertex_size = uint32_t(writer.pool.size());
  hd.max_block_shift = std::max(writer.max_block_shift, lattice_shift);
  writer.bytes.resize(hd.vertex_offset + hd.vertex_size);
  if (hd.vertex_size) std::memcpy(writer.bytes.data() + hd.vertex_offset, writer.pool.data(), hd.vertex_size);

  append_remap(writer.bytes, hd, writer.remap, o.triangle_ids);
  hd.total_size = uint32_t(writer.bytes.size());
  std::memcpy(writer.bytes.data(), &hd, sizeof hd);
  layout::seal(writer.bytes);

  if (report) {
    report->sah_cost = tree.sah_cost;
    report->build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return std::move(writer.bytes);
}

void displacement_bound(const std::vector<uint8_t>& blob, float bound[3]) {
  const BlobHeader& h = layout::header_of(blob.data());
  if (h.triangle_format == MC_TRI_INDEXED24) {  // the mesh's own floats
    for (int a = 0; a < 3; ++a) bound[a] = 0;
    return;
  }
  layout::GridKind grid = codec_ops(h.triangle_format).grid;
  if (grid == layout::kGridMeshBox) return quantization_bound(h.quant_offset, h.quant_scale, bound);
  for (int a = 0; a < 3; ++a) {
    float top = std::max(std::fabs(h.bounds_min[a]), std::fabs(h.bounds_max[a]));
    if (grid == layout::kGridNone) {  // floats kept, or moved by 1 ulp (UncompressedStrip)
      bound[a] = codec_ops(h.triangle_format).moves_floats ? std::nextafter(top, INFINITY) - top : 0.0f;
      continue;
    }
    // Half the grid step (the input rounded to the mesh grid), half the
    // coarsest block step for nested formats (the grid position rounded once
    // to its block lattice), and one rounding of the largest coordinate.
    float lattice = codec_ops(h.triangle_format).nested ? 0.5f * h.quant_scale[a] * std::ldexp(1.0f, int(h.max_block_shift)) : 0.0f;
    bound[a] = 0.5f * h.quant_scale[a] + lattice + (std::nextafter(top, INFINITY) - top);
  }
}

double relative_error_bound(const std::vector<uint8_t>& blob, double diagonal) {
  float b[3];
  displacement_bound(blob, b);
  return std::sqrt(double(b[0]) * b[0] + double(b[1]) * b[1] + double(b[2]) * b[2]) / std::max(1e-30, diagonal);
}

bool moves_vertices(uint32_t triangle_format) {
  if (triangle_format == MC_TRI_INDEXED24) return false;
  CodecOps c = codec_ops(triangle_format);
  return c.grid != layout::kGridNone || c.moves_floats;
}

std::vector<Layout> all_layouts() {
  std::vector<Layout> all;
  for (uint32_t t : tree_formats())
    for (uint32_t c : triangle_formats()) all.push_back({TreeFormat(t), TriangleFormat(c)});
  // Seed 004's trees live in the mesh's own indices: one triangle format.
  all.push_back({TreeFormat::ZeroByteTree, TriangleFormat::Indexed24});
  all.push_back({TreeFormat::ZeroByteHybrid, TriangleFormat::Indexed24});
  return all;
}

std::vector<std::string> layout_names() {
  std::vector<std::string> names;
  for (Layout l : all_layouts()) names.push_back(layout_name(l));
  return names;
}

std::string layout_name(uint32_t tree, uint32_t triangles) {
  return std::string(layout::tree_format_name(tree)) + "/" + std::string(layout::triangle_format_name(triangles));
}

std::string layout_name(Layout l) { return layout_name(uint32_t(l.tree), uint32_t(l.triangles)); }

Layout parse_layout_name(const std::string& name) { return parse_layout(name).layout; }

BuildOptions parse_layout(const std::string& text) {
  auto lower = [](std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  for (Layout l : all_layouts())
    if (lower(layout_name(l)) == lower(text)) {
      BuildOptions o;
      o.layout = l;
      // The seed 001 heap is built by Morton-code middle split.
      if (l.tree == TreeFormat::StacklessLBVH) o.splitter = Splitter::Morton;
      return o;
    }
  std::string valid;
  for (const std::string& n : layout_names()) valid += "\n  " + n;
  throw InputError("unknown layout '" + text + "'; valid layouts (TREE/TRIANGLES):" + valid);
}

}  // namespace meshcast

namespace meshcast {

std::vector<NodeOrder> all_node_orders() {
  return {NodeOrder::DepthFirst, NodeOrder::DepthFirstTrianglesLast, NodeOrder::BreadthFirst,
          NodeOrder::BreadthFirstTrianglesLast};
}

const char* node_order_name(NodeOrder order) {
  switch (order) {
    case NodeOrder::Default: return "Default";
    case NodeOrder::DepthFirst: return "DepthFirst";
    case NodeOrder::DepthFirstTrianglesLast: return "DepthFirstTrianglesLast";
    case NodeOrder::BreadthFirst: return "BreadthFirst";
    case NodeOrder::BreadthFirstTrianglesLast: return "BreadthFirstTrianglesLast";
  }
  return "";
}

NodeOrder parse_node_order(const std::string& name) {
  return parse_named(name, all_node_orders(), node_order_name, "node order");
}

}  // namespace meshcast
