#include "cpu/encode.h"

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <unordered_map>

#include "cpu/build.h"
#include "cpu/pairs.h"
#include "layout/aabbtree.h"
#include "layout/codecs.h"
#include "layout/quadtree.h"
#include "cpu/writer.h"

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

// AABBTree (§5.1), depth first: first child right behind its parent, the
// leaf's triangle block right behind the leaf node.
void write_aabbtree(Writer& w) {
  const BuildTree& t = w.tree;
  // Every node, and behind each leaf its block.
  uint64_t tree_size = uint64_t(t.nodes.size()) * MC_AABB_NODE_BYTES;
  for (uint32_t bytes : w.leaf_bytes) tree_size += bytes;
  if (tree_size > MC_AABB_VALUE_MASK)
    throw InputError("the AABBTree section of " + std::to_string(tree_size) +
                     " bytes exceeds its 31-bit child offsets");
  w.h.tree_size = uint32_t(tree_size);
  w.h.node_bytes = uint32_t(t.nodes.size() * MC_AABB_NODE_BYTES);
  w.h.node_count = uint32_t(t.nodes.size());
  w.h.triangle_base = 0;
  w.h.root = 0;
}

// Places every node (pre-order), encodes the leaves, refits, then writes
// the nodes with the refitted boxes.
void fill_aabbtree(Writer& w, bool split_axis, const std::vector<uint8_t>& axis) {
  const BuildTree& t = w.tree;
  std::vector<uint32_t> offset(t.nodes.size());
  std::function<uint32_t(uint32_t, uint32_t)> place = [&](uint32_t n, uint32_t at) -> uint32_t {
    offset[n] = at;
    const BuildNode& b = t.nodes[n];
    if (b.leaf()) return at + MC_AABB_NODE_BYTES + w.leaf_bytes[n];
    return place(b.right, place(b.left, at + MC_AABB_NODE_BYTES));
  };
  place(0, 0);
  for (uint32_t n = 0; n < t.nodes.size(); ++n)
    if (t.nodes[n].leaf()) w.write_leaf(n, offset[n] + MC_AABB_NODE_BYTES);
  w.refit();
  for (uint32_t n = 0; n < t.nodes.size(); ++n) {
    const BuildNode& b = t.nodes[n];
    layout::AABBNode node{};
    for (int a = 0; a < 3; ++a) node.min[a] = b.box.min[a], node.max[a] = b.box.max[a];
    node.properties = b.leaf() ? (MC_AABB_LEAF_BIT | b.count) : offset[b.right];
    if (split_axis && !b.leaf()) node.properties |= uint32_t(axis[n]) << MC_SPLITAXIS_SHIFT;
    std::memcpy(w.bytes.data() + w.h.tree_offset + offset[n], &node, sizeof node);
  }
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

// BruteForce: no tree. The "tree" is node 0 (the whole mesh) followed by one
// leaf a chunk of brute_chunk() triangles in input order; each becomes a
// record [count][block].
BuildTree chunk_tree(const std::vector<Box3>& boxes, uint32_t chunk) {
  BuildTree t;
  t.order.resize(boxes.size());
  t.nodes.emplace_back();
  for (uint32_t i = 0; i < boxes.size(); ++i) t.order[i] = i, t.nodes[0].box.grow(boxes[i]);
  for (uint32_t first = 0; first < boxes.size(); first += chunk) {
    BuildNode leaf;
    leaf.first = first;
    leaf.count = std::min<uint32_t>(chunk, uint32_t(boxes.size()) - first);
    for (uint32_t i = first; i < first + leaf.count; ++i) leaf.box.grow(boxes[i]);
    t.nodes.push_back(leaf);
  }
  return t;
}

void write_bruteforce(Writer& w) {
  uint64_t size = 0;
  for (size_t n = 1; n < w.tree.nodes.size(); ++n)
    size += MC_BRUTE_RECORD_BYTES + w.leaf_bytes[n];
  if (size > 0x7FFFFFFFu) throw InputError("the BruteForce section of " + std::to_string(size) + " bytes exceeds 2 GiB");
  w.h.tree_size = uint32_t(size);
  w.h.node_count = uint32_t(w.tree.nodes.size() - 1);
  w.h.node_bytes = w.h.node_count * MC_BRUTE_RECORD_BYTES;  // the count words
  w.h.triangle_base = 0;
  w.h.root = 0;
}

void fill_bruteforce(Writer& w) {
  uint32_t at = 0;
  Box3 all;
  for (size_t n = 1; n < w.tree.nodes.size(); ++n) {
    const BuildNode& leaf = w.tree.nodes[n];
    std::memcpy(w.bytes.data() + w.h.tree_offset + at, &leaf.count, 4);
    w.write_leaf(uint32_t(n), at + MC_BRUTE_RECORD_BYTES);
    all.grow(leaf.box);
    at += MC_BRUTE_RECORD_BYTES + w.leaf_bytes[n];
  }
  w.frame(all);
}

// AABBTreeSplitAxis (§5.2): each interior node's axis is the one along which
// its children's centres lie farthest apart, and its children are ordered
// lower first along it. (The builders do not record the axis they split on;
// this one is the axis that separates the two children most.)
std::vector<uint8_t> order_by_split_axis(BuildTree& t) {
  std::vector<uint8_t> axis(t.nodes.size(), 0);
  for (size_t n = 0; n < t.nodes.size(); ++n) {
    BuildNode& b = t.nodes[n];
    if (b.leaf()) continue;
    Vec3 l = t.nodes[b.left].box.centre(), r = t.nodes[b.right].box.centre();
    float d[3] = {std::fabs(l.x - r.x), std::fabs(l.y - r.y), std::fabs(l.z - r.z)};
    int a = d[0] >= d[1] && d[0] >= d[2] ? 0 : (d[1] >= d[2] ? 1 : 2);
    axis[n] = uint8_t(a);
    if (l[a] > r[a]) std::swap(b.left, b.right);
  }
  return axis;
}

// AABBTreePNS (§5.3, seed 002): nodes depth first by index, then the blocks.
struct PnsPlan {
  std::vector<uint32_t> index;  // per binary node: its node index
  std::vector<uint32_t> block;  // per binary leaf: tree-section offset of its block
  std::vector<uint32_t> leaves; // leaves in block order
};

PnsPlan plan_pns(Writer& w) {
  const BuildTree& t = w.tree;
  PnsPlan p{std::vector<uint32_t>(t.nodes.size()), std::vector<uint32_t>(t.nodes.size()), {}};
  uint32_t next = 0;
  std::function<void(uint32_t)> visit = [&](uint32_t n) {
    p.index[n] = next++;
    if (t.nodes[n].leaf()) return p.leaves.push_back(n);
    visit(t.nodes[n].left);
    visit(t.nodes[n].right);
  };
  visit(0);
  uint64_t base = uint64_t(next) * MC_AABB_NODE_BYTES, at = base;
  for (uint32_t leaf : p.leaves) {
    p.block[leaf] = uint32_t(at);
    if ((at - base) / 4 > MC_PNS_BLOCK_MASK) throw InputError("AABBTreePNS: triangle blocks beyond its 26-bit offsets (256 MiB)");
    at += w.leaf_bytes[leaf];
  }
  if (next > MC_PNS_INDEX_MASK) throw InputError("AABBTreePNS: more than 2^23 nodes");
  if (at > 0x7FFFFFFFu) throw InputError("AABBTreePNS: the tree section exceeds 2 GiB");
  w.h.node_count = next;
  w.h.node_bytes = uint32_t(base);
  w.h.triangle_base = uint32_t(base);
  w.h.tree_size = uint32_t(at);
  w.h.root = 0;
  return p;
}

void fill_pns(Writer& w, const PnsPlan& p) {
  const BuildTree& t = w.tree;
  for (uint32_t leaf : p.leaves) w.write_leaf(leaf, p.block[leaf]);
  w.refit();
  for (uint32_t n = 0; n < t.nodes.size(); ++n) {
    const BuildNode& b = t.nodes[n];
    layout::AABBNode node{};
    for (int a = 0; a < 3; ++a) node.min[a] = b.box.min[a], node.max[a] = b.box.max[a];
    node.properties = b.leaf() ? MC_AABB_LEAF_BIT | b.count << MC_PNS_COUNT_SHIFT | (p.block[n] - w.h.triangle_base) / 4
                               : pns_code(t.nodes[b.left].box, t.nodes[b.right].box) << MC_PNS_SHIFT | p.index[b.right];
    std::memcpy(w.bytes.data() + w.h.tree_offset + uint64_t(p.index[n]) * MC_AABB_NODE_BYTES, &node, sizeof node);
  }
}

// QuadTree (§5.6): every binary node that stays a node takes up to four
// children, found by opening its largest interior descendant until four are
// reached. Nodes and triangle blocks are then laid out in one of the four
// node orders of §4.3 (quad_sequence); DepthFirstTrianglesLast, the
// default, keeps 64-byte half-float nodes cache aligned.
struct QuadPlan {
  std::vector<std::array<int64_t, 4>> children;  // binary node index or -1
  std::vector<uint32_t> binary_of;               // quad node -> binary node
  std::vector<uint32_t> leaves;                  // binary leaves, in write order
  std::vector<uint32_t> leaf_offset;             // per binary node (leaves)
  std::vector<uint32_t> node_offset;             // per quad node
  std::vector<uint32_t> quad_index;              // per binary node (quad nodes)
  uint32_t depth = 0;
};

QuadPlan plan_quadtree(const BuildTree& t) {
  QuadPlan p;
  p.leaf_offset.assign(t.nodes.size(), 0);
  p.quad_index.assign(t.nodes.size(), 0);
  std::function<void(uint32_t, uint32_t)> visit = [&](uint32_t n, uint32_t depth) {
    if (t.nodes[n].leaf()) return;
    p.depth = std::max(p.depth, depth);
    std::vector<uint32_t> list{t.nodes[n].left, t.nodes[n].right};
    while (list.size() < 4) {
      int open = -1;
      for (size_t i = 0; i < list.size(); ++i)
        if (!t.nodes[list[i]].leaf() &&
            (open < 0 || t.nodes[list[i]].box.half_area() > t.nodes[list[size_t(open)]].box.half_area()))
          open = int(i);
      if (open < 0) break;
      uint32_t m = list[size_t(open)];
      list.erase(list.begin() + open);
      list.insert(list.begin() + open, {t.nodes[m].left, t.nodes[m].right});
    }
    p.quad_index[n] = uint32_t(p.binary_of.size());
    p.binary_of.push_back(n);
    std::array<int64_t, 4> c{-1, -1, -1, -1};
    for (size_t i = 0; i < list.size(); ++i) c[i] = list[i];
    p.children.push_back(c);
    for (uint32_t m : list) visit(m, depth + 1);
  };
  visit(0, 0);
  return p;
}

// The write order of §4.3: quad nodes (true, quad index) and leaf blocks
// (false, binary node) depth or breadth first, each node's leaf blocks
// right behind it or all blocks after all nodes.
std::vector<std::pair<bool, uint32_t>> quad_sequence(const BuildTree& t, const QuadPlan& p, NodeOrder order) {
  std::vector<std::pair<bool, uint32_t>> seq, blocks;
  if (p.binary_of.empty()) return {{false, 0}};  // the root is a leaf
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  auto emit = [&](uint32_t q, std::vector<uint32_t>& next) {
    seq.push_back({true, q});
    for (int64_t c : p.children[q]) {
      if (c < 0) continue;
      if (t.nodes[size_t(c)].leaf()) (last ? blocks : seq).push_back({false, uint32_t(c)});
      else next.push_back(p.quad_index[size_t(c)]);
    }
  };
  if (order == NodeOrder::BreadthFirst || order == NodeOrder::BreadthFirstTrianglesLast) {
    std::vector<uint32_t> level{0};
    while (!level.empty()) {
      std::vector<uint32_t> next;
      for (uint32_t q : level) emit(q, next);
      level.swap(next);
    }
  } else {
    std::function<void(uint32_t)> visit = [&](uint32_t q) {
      std::vector<uint32_t> next;
      emit(q, next);
      for (uint32_t c : next) visit(c);
    };
    visit(0);
  }
  seq.insert(seq.end(), blocks.begin(), blocks.end());
  return seq;
}

template <class Bounds>
void write_quadtree(Writer& w, QuadPlan& p, NodeOrder order) {
  uint64_t at = 0, nodes = uint64_t(p.binary_of.size()) * Bounds::kNodeBytes;
  p.node_offset.assign(p.binary_of.size(), 0);
  for (auto [is_node, id] : quad_sequence(w.tree, p, order)) {
    if (is_node) {
      p.node_offset[id] = uint32_t(std::min<uint64_t>(at, MC_QUAD_OFFSET_MASK));
      at += Bounds::kNodeBytes;
    } else {
      p.leaves.push_back(id);
      p.leaf_offset[id] = uint32_t(std::min<uint64_t>(at, MC_QUAD_OFFSET_MASK));
      at += w.leaf_bytes[id];
    }
  }
  if (at > MC_QUAD_OFFSET_MASK)
    throw InputError("the " + std::string(layout::tree_format_name(Bounds::kFormat)) + " section of " +
                     std::to_string(at) + " bytes exceeds its 27-bit child offsets (seed 000 5.6)");
  const bool last = order == NodeOrder::DepthFirstTrianglesLast || order == NodeOrder::BreadthFirstTrianglesLast;
  w.h.tree_size = uint32_t(at);
  w.h.node_bytes = uint32_t(nodes);
  w.h.node_count = uint32_t(p.binary_of.size());
  w.h.triangle_base = last ? uint32_t(nodes) : 0;  // interleaved blocks: slots count from the section start
}

template <class Bounds>
void fill_quadtree(Writer& w, QuadPlan& p) {
  const BuildTree& t = w.tree;
  for (uint32_t leaf : p.leaves) w.write_leaf(leaf, p.leaf_offset[leaf]);
  w.refit();
  auto props = [&](uint32_t n) {
    return t.nodes[n].leaf() ? layout::quad_properties(t.nodes[n].count, p.leaf_offset[n])
                             : layout::quad_properties(0, p.node_offset[p.quad_index[n]]);
  };
  for (size_t q = 0; q < p.binary_of.size(); ++q) {
    layout::QuadChild c[4];
    for (int k = 0; k < 4; ++k) {
      if (p.children[q][k] < 0) continue;
      uint32_t n = uint32_t(p.children[q][k]);
      for (int a = 0; a < 3; ++a) c[k].min[a] = t.nodes[n].box.min[a], c[k].max[a] = t.nodes[n].box.max[a];
      c[k].properties = props(n);
    }
    uint8_t* out = w.bytes.data() + w.h.tree_offset + p.node_offset[q];
    Bounds::encode(c, w.h, out);
    for (int k = 0; k < 4; ++k) std::memcpy(out + Bounds::kPropertiesAt + 4 * k, &c[k].properties, 4);
  }
  w.h.root = props(0);
}

}  // namespace

std::string node_order_refusal(uint32_t tree, NodeOrder order) {
  if (order == NodeOrder::Default || tree == MC_TREE_QUADTREE || tree == MC_TREE_QUADTREEHALFFLOAT) return "";
  // What each other format's bits fix (seed 000 5.1-5.5, seed 001).
  NodeOrder fixed = NodeOrder::DepthFirst;
  const char* why = "its first child and its leaves' blocks sit right behind their node";
  if (tree == MC_TREE_AABBTREEPNS) fixed = NodeOrder::DepthFirstTrianglesLast, why = "it addresses nodes by depth-first index";
  if (tree == MC_TREE_STACKLESSLBVH) fixed = NodeOrder::BreadthFirstTrianglesLast, why = "its nodes are a heap";
  if (tree == MC_TREE_BRUTEFORCE) return "BruteForce has no tree, so no node order";
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

std::vector<uint8_t> build_blob(const Mesh& mesh, const BuildOptions& o, const std::string& name,
                                BuildReport* report) {
  auto start = std::chrono::steady_clock::now();
  check_mesh(mesh, name);
  if (o.leaf_size < 1 || o.leaf_size > MC_QUAD_MAX_COUNT)
    throw InputError(name + ": leaf size " + std::to_string(o.leaf_size) + " is outside 1.." +
                     std::to_string(MC_QUAD_MAX_COUNT) + " (5-bit triangle counts, seed 000 5.6)");
  if (layout::tree_format_name(o.tree_format).empty()) throw InputError(name + ": unknown tree format");
  CodecOps codec = codec_ops(o.triangle_format);
  if (std::string why = node_order_refusal(o.tree_format, o.node_order); !why.empty())
    throw InputError(name + ": " + why);

  BlobHeader h{};
  h.magic = MC_BLOB_MAGIC, h.version = MC_BLOB_VERSION;
  h.tree_format = o.tree_format, h.triangle_format = o.triangle_format;
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
  if (o.tree_format == MC_TREE_STACKLESSLBVH) {
    uint32_t d = o.lbvh_depth ? o.lbvh_depth : uint32_t(std::bit_width(mesh.triangles.size())) + 1;
    if (d > MC_LBVH_MAX_DEPTH + 1)
      throw InputError(name + ": StacklessLBVH depth limit " + std::to_string(d) + " exceeds " +
                       std::to_string(MC_LBVH_MAX_DEPTH + 1) + " (2^26 node slots)");
    depth_limit = d - 1;
  }
  BuildTree tree;
  try {
    tree = o.tree_format == MC_TREE_BRUTEFORCE ? chunk_tree(boxes, layout::brute_chunk(codec.lanes))
                                               : build_tree(boxes, o.splitter, o.leaf_size, depth_limit);
  } catch (const InputError& e) {
    throw InputError(name + ": " + std::string(layout::tree_format_name(o.tree_format)) + ": " + e.what());
  }
  std::vector<uint8_t> split_axes;
  if (o.tree_format == MC_TREE_AABBTREESPLITAXIS) split_axes = order_by_split_axis(tree);
  uint32_t lattice_shift = codec.nested ? snap_to_block_lattices(tree, corners, codec.lanes, h.quant_scale) : 0;
  Writer writer{corners, tree, codec, h, {}, {}, {}, {}, {}, {}};
  BlobHeader& hd = writer.h;
  writer.measure_leaves();

  QuadPlan plan;
  PnsPlan pns_plan;
  uint32_t depth = tree.depth;
  std::unique_ptr<TreeWriter> tree_writer;
  if (o.tree_format == MC_TREE_AABBTREECOMPRESSED) tree_writer = make_compressed_writer();
  if (o.tree_format == MC_TREE_SKDTREE) tree_writer = make_skd_writer();
  if (o.tree_format == MC_TREE_STACKLESSLBVH) tree_writer = make_lbvh_writer(o.lbvh_near_first);
  if (tree_writer) {
    tree_writer->plan(writer);
  } else if (o.tree_format == MC_TREE_BRUTEFORCE) {
    write_bruteforce(writer);
    depth = 0;
  } else if (o.tree_format == MC_TREE_AABBTREEPNS) {
    pns_plan = plan_pns(writer);
  } else if (o.tree_format == MC_TREE_AABBTREE || o.tree_format == MC_TREE_AABBTREESPLITAXIS) {
    write_aabbtree(writer);
    if (o.tree_format == MC_TREE_AABBTREESPLITAXIS && hd.tree_size > MC_SPLITAXIS_OFFSET_MASK)
      throw InputError(name + ": the AABBTreeSplitAxis section of " + std::to_string(hd.tree_size) +
                       " bytes exceeds its 29-bit child offsets (seed 000 5.2)");
  } else {
    plan = plan_quadtree(tree);
    depth = plan.depth;
    NodeOrder order = o.node_order == NodeOrder::Default ? NodeOrder::DepthFirstTrianglesLast : o.node_order;
    if (o.tree_format == MC_TREE_QUADTREE) write_quadtree<layout::QuadBoundsFloat>(writer, plan, order);
    else write_quadtree<layout::QuadBoundsHalf>(writer, plan, order);
  }
  if (depth > MC_MAX_DEPTH)
    throw InputError(name + ": the tree is " + std::to_string(depth) + " levels deep, beyond the walkers' limit of " +
                     std::to_string(MC_MAX_DEPTH));
  hd.max_depth = depth;
  hd.leaf_count = tree.leaf_count();  // BruteForce: the records
  hd.tree_offset = align(MC_BLOB_HEADER_BYTES, 64);  // 64-byte nodes start on a cache line
  hd.vertex_offset = align(uint64_t(hd.tree_offset) + hd.tree_size, 8);
  writer.bytes.assign(hd.vertex_offset, 0);
  try {
    if (tree_writer) tree_writer->fill(writer);
    else if (o.tree_format == MC_TREE_BRUTEFORCE) fill_bruteforce(writer);
    else if (o.tree_format == MC_TREE_AABBTREE) fill_aabbtree(writer, false, {});
    else if (o.tree_format == MC_TREE_AABBTREESPLITAXIS) fill_aabbtree(writer, true, split_axes);
    else if (o.tree_format == MC_TREE_AABBTREEPNS) fill_pns(writer, pns_plan);
    else if (o.tree_format == MC_TREE_QUADTREE) fill_quadtree<layout::QuadBoundsFloat>(writer, plan);
    else fill_quadtree<layout::QuadBoundsHalf>(writer, plan);
  } catch (const std::length_error& e) {  // a codec's own limit (index width)
    throw InputError(name + ": " + layout_name(o.tree_format, o.triangle_format) + ": " + e.what());
  }
  // Vertices and remap at most 8 + 12 bytes a triangle on top of this.
  if (uint64_t(hd.vertex_offset) + writer.pool.size() + 12ull * mesh.triangles.size() + 4096 > 0xF0000000ull)
    throw InputError(name + ": the blob would exceed the 4 GiB its 32-bit offsets reach");

  hd.vertex_size = uint32_t(writer.pool.size());
  hd.max_block_shift = std::max(writer.max_block_shift, lattice_shift);
  writer.bytes.resize(hd.vertex_offset + hd.vertex_size);
  if (hd.vertex_size) std::memcpy(writer.bytes.data() + hd.vertex_offset, writer.pool.data(), hd.vertex_size);

  // Remap: slot -> input triangle, as few bits as the triangle count needs.
  hd.remap_bits = std::max(1u, uint32_t(std::bit_width(hd.triangle_count - 1u)));
  hd.remap_slots = uint32_t(writer.remap.size());
  hd.remap_offset = align(writer.bytes.size(), 8);
  const uint32_t words = layout::remap_words(hd);
  hd.remap_size = align(12ull * words + (uint64_t(hd.triangle_count) * hd.remap_bits + 7) / 8 + 8, 8);
  writer.bytes.resize(uint64_t(hd.remap_offset) + hd.remap_size, 0);
  uint8_t* used = writer.bytes.data() + hd.remap_offset;
  uint8_t* rank = used + 8ull * words;
  uint8_t* entries = rank + 4ull * words;
  uint32_t index = 0;
  for (uint32_t s = 0; s < hd.remap_slots; ++s) {
    if (s % 64 == 0) std::memcpy(rank + 4ull * (s / 64), &index, 4);
    if (writer.remap[s] == MC_NO_HIT) continue;
    used[s / 8] |= uint8_t(1u << (s % 8));
    uint64_t bit = uint64_t(index++) * hd.remap_bits;
    uint64_t word;
    std::memcpy(&word, entries + (bit >> 3), 8);
    word |= uint64_t(writer.remap[s]) << (bit & 7);
    std::memcpy(entries + (bit >> 3), &word, 8);
  }
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

bool moves_vertices(uint32_t triangle_format) {
  CodecOps c = codec_ops(triangle_format);
  return c.grid != layout::kGridNone || c.moves_floats;
}

std::vector<std::string> layout_names() {
  std::vector<std::string> names;
  for (uint32_t t : tree_formats())
    for (uint32_t c : triangle_formats())
      names.push_back(layout_name(t, c));
  return names;
}

std::string layout_name(uint32_t tree, uint32_t triangles) {
  return std::string(layout::tree_format_name(tree)) + "/" + std::string(layout::triangle_format_name(triangles));
}

BuildOptions parse_layout(const std::string& text) {
  auto lower = [](std::string s) {
    for (char& ch : s) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return s;
  };
  for (uint32_t t : tree_formats())
    for (uint32_t c : triangle_formats())
      if (lower(layout_name(t, c)) == lower(text)) {
        BuildOptions o;
        o.tree_format = t, o.triangle_format = c;
        // The seed 001 heap is built by Morton-code middle split.
        if (t == MC_TREE_STACKLESSLBVH) o.splitter = Splitter::Morton;
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
