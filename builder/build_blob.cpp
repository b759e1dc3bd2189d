// Builds a mesh into a blob (meshcast/build.h's build_blob): quantize (if the
// triangle format does), build the binary tree from the stored triangles,
// lay it out in the tree format, encode each leaf with the triangle format,
// then the remap and the header.
#include "meshcast/build.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstring>
#include <numeric>

#include "builder/binary_tree.h"
#include "builder/build_threads.h"
#include "builder/error_bounds.h"
#include "builder/layout_names.h"
#include "builder/pairing.h"
#include "builder/quantize.h"
#include "builder/tree_source.h"
#include "layout/tree/aabbtree.h"
#include "layout/triangles/codecs.h"
#include "layout/tree/quadtree.h"
#include "builder/writer.h"

namespace meshcast {

using layout::BlobHeader;
using layout::TriCorners;

namespace {

// Seed 003: the tree over pairs (and the triangles left single), each
// expanded back to its triangles side by side.
BuildTree build_paired(const TreeInput& in, uint32_t depth_limit) {
  const BuildOptions& o = in.options;
  if (o.leaf_size < 2) throw InputError("pairing needs leaves of at least 2 triangles (leaf size " + std::to_string(o.leaf_size) + ")");
  Pairing p = pair_triangles(in.mesh);
  std::vector<uint32_t> members, start{0};
  std::vector<Box3> unit_boxes;
  for (uint32_t t = 0; t < p.partner.size(); ++t) {
    const uint32_t q = p.partner[t];
    if (q != MC_NO_HIT && q < t) continue;  // already in its partner's unit
    Box3 box = in.boxes[t];
    members.push_back(t);
    if (q != MC_NO_HIT) members.push_back(q), box.grow(in.boxes[q]);
    start.push_back(uint32_t(members.size()));
    unit_boxes.push_back(box);
  }
  if (in.report) in.report->pairing = p.decision, in.report->paired_ratio = p.paired_ratio;
  // A leaf of leaf_size / 2 units holds at most leaf_size triangles; at the
  // depth limit half the 5-bit count's 31.
  BuildTree units = build_tree(unit_boxes, o.splitter, o.leaf_size / 2, depth_limit, MC_QUAD_MAX_COUNT / 2, in.threads);
  return expand_groups(units, members, start);
}

}  // namespace

void TreeWriter::check(const Mesh&, const BuildOptions& o) const {
  if (o.leaf_size < 1 || o.leaf_size > MC_QUAD_MAX_COUNT)
    throw InputError("leaf size " + std::to_string(o.leaf_size) + " is outside 1.." + std::to_string(MC_QUAD_MAX_COUNT) +
                     " (5-bit triangle counts, seed 000 5.6)");
  if (std::string why = node_order_refusal(uint32_t(o.layout.tree), o.node_order); !why.empty()) throw InputError(why);
}

// A source's tree, checked: every triangle in one leaf, leaves within the
// capacity, children inside the node count.
BuildTree sourced_tree(const TreeInput& in, uint32_t depth_limit) {
  if (in.options.pairing) throw InputError("pairing builds its own tree over pairs; a given tree cannot pair");
  BuildTree t = (*in.source)(in.boxes, in.options.leaf_size, depth_limit, MC_QUAD_MAX_COUNT);
  std::vector<uint8_t> seen(in.boxes.size(), 0);
  if (t.nodes.empty() || t.order.size() != in.boxes.size())
    throw InputError("the given tree orders " + std::to_string(t.order.size()) + " triangles of " +
                     std::to_string(in.boxes.size()));
  for (uint32_t i : t.order) {
    if (i >= seen.size() || seen[i]) throw InputError("the given tree holds triangle " + std::to_string(i) + " twice or out of range");
    seen[i] = 1;
  }
  const uint32_t count = uint32_t(t.nodes.size());
  for (const BuildNode& n : t.nodes)
    if (n.leaf() ? n.count > MC_QUAD_MAX_COUNT || uint64_t(n.first) + n.count > t.order.size()
                 : n.left == 0 || n.right == 0 || n.left >= count || n.right >= count)
      throw InputError("the given tree has a malformed node");
  return t;
}

BuildTree TreeWriter::build(const TreeInput& in, uint32_t depth_limit) {
  const BuildOptions& o = in.options;
  if (in.source) return sourced_tree(in, depth_limit);
  if (o.pairing) return build_paired(in, depth_limit);
  return build_tree(in.boxes, o.splitter, o.leaf_size, depth_limit, MC_QUAD_MAX_COUNT, in.threads);
}

void refuse_given_tree(const TreeInput& in) {
  if (in.source)
    throw InputError(std::string(layout::tree_format_name(uint32_t(in.options.layout.tree))) +
                     " keeps its own triangle order; a given tree cannot lay it out");
}

BuildTree record_tree(const TreeInput& in, std::vector<uint32_t> order) {
  refuse_given_tree(in);
  if (in.options.pairing)
    throw InputError("pairing builds trees; " + std::string(layout::tree_format_name(uint32_t(in.options.layout.tree))) +
                     " keeps its own triangle order");
  const uint32_t chunk = layout::brute_chunk(in.codec.lanes);
  BuildTree t;
  t.order = std::move(order);
  t.nodes.emplace_back();
  for (uint32_t i : t.order) t.nodes[0].box.grow(in.boxes[i]);
  for (uint32_t first = 0; first < t.order.size(); first += chunk) {
    BuildNode leaf;
    leaf.first = first;
    leaf.count = std::min<uint32_t>(chunk, uint32_t(t.order.size()) - first);
    for (uint32_t i = first; i < first + leaf.count; ++i) leaf.box.grow(in.boxes[t.order[i]]);
    t.nodes.push_back(leaf);
  }
  return t;
}

std::unique_ptr<TreeWriter> make_tree_writer(const BuildOptions& o) {
  return layout::with_tree_format(uint32_t(o.layout.tree), std::unique_ptr<TreeWriter>(),
                                  [&](auto tag) { return make_writer(tag, o); });
}

// The remap section after the blob's bytes so far: slot -> input triangle
// (MC_NO_HIT: no triangle), as few bits as the triangle count needs; only
// the used slots and their ranks when the slots keep the input order; none
// when the caller asked for none (layout/blob_format.h).
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

// Meshes smaller than this build on the caller's thread alone: a thread's
// start would cost more than it saves.
constexpr size_t kParallelTriangles = 16384;

namespace {

std::vector<uint8_t> build_blob_with(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                     BuildReport* report, const TreeSource* source) {
  auto start = std::chrono::steady_clock::now();
  BuildOptions o = options;
  if (o.leaf_size == 0) o.leaf_size = default_leaf_size(o.layout);
  check_mesh(mesh, name);
  if (o.threads > kMaxBuildThreads)
    throw InputError(name + ": " + std::to_string(o.threads) + " build threads asked for, more than the " +
                     std::to_string(kMaxBuildThreads) + " a build takes (0: one a core)");
  std::unique_ptr<TreeWriter> tree_writer = make_tree_writer(o);
  if (!tree_writer) throw InputError(name + ": unknown tree format");
  try {
    tree_writer->check(mesh, o);
  } catch (const InputError& e) {
    throw InputError(name + ": " + e.what());
  }
  CodecOps codec = tree_writer->codec(o);

  BlobHeader h{};
  h.magic = MC_BLOB_MAGIC, h.version = MC_BLOB_VERSION;
  h.tree_format = uint32_t(o.layout.tree), h.triangle_format = uint32_t(o.layout.triangles);
  h.triangle_count = uint32_t(mesh.triangles.size());
  h.leaf_size = o.leaf_size;
  h.slot_divisor = codec.slot_divisor;

  // Stored triangle corners: bit-packed formats quantize against the mesh box.
  set_mesh_grid(mesh.bounds(), codec, name, h);
  BuildThreads threads(o.threads);
  BuildThreads* parallel = threads.total() > 1 && mesh.triangles.size() >= kParallelTriangles ? &threads : nullptr;
  StoredTriangles stored = store_triangles(mesh, codec, h, parallel);
  FilledVector<TriCorners>& corners = stored.corners;
  const std::vector<Box3>& boxes = stored.boxes;

  uint32_t depth_limit;
  try {
    depth_limit = tree_writer->depth_limit(mesh.triangles.size(), o);
  } catch (const InputError& e) {
    throw InputError(name + ": " + e.what());
  }
  BuildTree tree;
  try {
    tree = tree_writer->build(TreeInput{mesh, o, boxes, codec, report, parallel, source}, depth_limit);
  } catch (const InputError& e) {
    throw InputError(name + ": " + std::string(layout::tree_format_name(uint32_t(o.layout.tree))) + ": " + e.what());
  }
  uint32_t lattice_shift = codec.nested ? snap_to_block_lattices(tree, corners, codec.lanes, h.quant_scale) : 0;
  Writer writer{corners, tree, codec, h, {}, {}, {}, {}, {}, {}, parallel};
  BlobHeader& hd = writer.h;
  writer.measure_leaves();

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
  hd.leaf_count = tree_writer->leaf_count(tree);
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

}  // namespace

std::vector<uint8_t> build_blob(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                BuildReport* report) {
  return build_blob_with(mesh, options, name, report, nullptr);
}

std::vector<uint8_t> build_blob_over(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                     const TreeSource& source, BuildReport* report) {
  return build_blob_with(mesh, options, name, report, &source);
}

}  // namespace meshcast
