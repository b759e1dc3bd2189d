// Zero-byte trees (seed 004): the builder. Each interior node takes the (at
// most 6) triangles that define its box out of the set, and the rest is
// split in two (the SAH binning step of every other tree); a set of 7 or
// fewer is a leaf. Nodes are then spread over the triangle array so node
// P starts at triangle P (M = N): the root at 0, the two children of a
// node side by side wherever the depth-first walk of the layout has got to.
// ZeroByteHybrid: an SAH tree with leaves of up to hybrid_leaf triangles,
// each leaf one zero-byte tree with positions counted from its root.
#include "builder/write_zerobyte.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "builder/build_topdown.h"
#include "builder/writer.h"
#include "layout/tree/aabbtree.h"
#include "layout/tree/zerobyte.h"

namespace meshcast {

namespace {

using layout::BlobHeader;

struct ZbtNodeBuild {
  uint32_t first = 0, count = 0;  // triangles at the node: items[first, first + count)
  int32_t left = -1, right = -1;
  Box3 box;                       // of the whole subtree
  bool shuffled = false;
  uint32_t corners = 0;           // shuffled: 2 bits a extreme, the corner that gives it
};

// One zero-byte tree over `items` (input triangle indices).
class ZbtBuilder {
 public:
  ZbtBuilder(const Mesh& mesh, const std::vector<Box3>& boxes, const std::vector<Vec3>& centres, bool shuffle)
      : mesh_(mesh), boxes_(boxes), centres_(centres), shuffle_(shuffle) {}

  // Appends the tree's triangles to `order` and their 32-bit index words to
  // `words` (positions counted from the tree's root); depth0: levels above.
  void build(std::vector<uint32_t> items, uint32_t depth0, std::vector<uint32_t>& order, std::vector<uint32_t>& words,
             ZeroByteStats& stats) {
    items_ = std::move(items);
    nodes_.clear();
    depth0_ = depth0;
    node(0, uint32_t(items_.size()), depth0, stats);
    lay_out(order, words, stats);
  }

 private:
  float coord(uint32_t t, int c, int a) const { return mesh_.vertices[mesh_.triangles[t][c]][a]; }
  // Whether triangle t reaches extreme j (min x, y, z, max x, y, z) of `box`
  // with corner c (-1: any corner).
  bool gives(uint32_t t, int j, const Box3& box, int c) const {
    int a = j % 3;
    float want = j < 3 ? box.min[a] : box.max[a];
    for (int k = 0; k < 3; ++k)
      if ((c < 0 || c == k) && coord(t, k, a) == want) return true;
    return false;
  }

  // Picks the node's bound triangles and moves them to the front of
  // items[begin, end); returns how many.
  uint32_t take_bounds(uint32_t begin, uint32_t end, const Box3& box, bool* shuffled, std::array<uint32_t, 6>* corners) {
    std::vector<uint32_t> chosen;  // positions in items_
    *shuffled = false;
    if (shuffle_) {
      // Extreme j from one corner of a triangle of its own, the corner named
      // in the node (2 bits): 6 vertex fetches for the box instead of 18.
      // Extremes with the fewest candidates choose first.
      std::array<std::vector<std::pair<uint32_t, uint32_t>>, 6> cand;  // (position, corner)
      for (uint32_t i = begin; i < end; ++i)
        for (int j = 0; j < 6; ++j)
          for (int k = 0; k < 3 && cand[j].size() < 8; ++k)
            if (gives(items_[i], j, box, k)) {
              cand[j].push_back({i, uint32_t(k)});
              break;
            }
      std::array<int, 6> by_need{0, 1, 2, 3, 4, 5};
      std::stable_sort(by_need.begin(), by_need.end(), [&](int a, int b) { return cand[a].size() < cand[b].size(); });
      std::array<uint32_t, 6> pick;
      bool ok = true;
      std::vector<uint32_t> taken;
      for (int j : by_need) {
        auto it = std::find_if(cand[j].begin(), cand[j].end(), [&](const auto& pc) {
          return std::find(taken.begin(), taken.end(), pc.first) == taken.end();
        });
        if (it == cand[j].end()) { ok = false; break; }
        pick[j] = it->first, corners->at(j) = it->second;
        taken.push_back(it->first);
      }
      if (ok) {
        chosen.assign(pick.begin(), pick.end());
        *shuffled = true;
      }
    }
    if (!*shuffled)
      for (int j = 0; j < 6; ++j) {
        if (std::any_of(chosen.begin(), chosen.end(), [&](uint32_t i) { return gives(items_[i], j, box, -1); })) continue;
        for (uint32_t i = begin; i < end; ++i)
          if (gives(items_[i], j, box, -1)) {
            chosen.push_back(i);
            break;
          }
      }
    // Chosen first (in extreme order when shuffled), the rest after in order.
    std::vector<uint32_t> front, rest;
    for (uint32_t i : chosen) front.push_back(items_[i]);
    std::vector<bool> is_chosen(end - begin, false);
    for (uint32_t i : chosen) is_chosen[i - begin] = true;
    for (uint32_t i = begin; i < end; ++i)
      if (!is_chosen[i - begin]) rest.push_back(items_[i]);
    std::copy(front.begin(), front.end(), items_.begin() + begin);
    std::copy(rest.begin(), rest.end(), items_.begin() + begin + front.size());
    return uint32_t(front.size());
  }

  int32_t node(uint32_t begin, uint32_t end, uint32_t depth, ZeroByteStats& stats) {
    if (depth > MC_MAX_DEPTH)
      throw InputError("zero-byte tree deeper than the walkers' " + std::to_string(MC_MAX_DEPTH) + " levels");
    stats.depth = std::max(stats.depth, depth);
    int32_t id = int32_t(nodes_.size());
    nodes_.push_back({});
    Box3 box;
    for (uint32_t i = begin; i < end; ++i) box.grow(boxes_[items_[i]]);
    nodes_[id].box = box;
    nodes_[id].first = begin;
    if (end - begin <= MC_ZBT_MAX_COUNT) {
      nodes_[id].count = end - begin;
      ++stats.leaves;
      return id;
    }
    bool shuffled;
    std::array<uint32_t, 6> corners{};
    uint32_t k = take_bounds(begin, end, box, &shuffled, &corners);
    nodes_[id].count = k, nodes_[id].shuffled = shuffled;
    for (int j = 0; j < 6; ++j) nodes_[id].corners |= corners[j] << (2 * j);
    stats.interior += 1, stats.shuffled += shuffled, stats.bound_triangles += k;
    // The rest (at least 2) in two: the SAH step, else the median of the
    // longest centre axis (as build_topdown.h).
    uint32_t lo = begin + k;
    Box3 cbox;
    for (uint32_t i = lo; i < end; ++i) cbox.grow(centres_[items_[i]]);
    uint32_t left = depth - depth0_ < kSplitterDepth ? split_step(lo, end, cbox) : 0;
    if (left == 0 || left >= end - lo) {
      int axis = 0;
      Vec3 e = cbox.extent();
      if (e.y > e[axis]) axis = 1;
      if (e.z > e[axis]) axis = 2;
      left = (end - lo) / 2;
      std::nth_element(items_.begin() + lo, items_.begin() + lo + left, items_.begin() + end,
                       [&](uint32_t a, uint32_t b) { return centres_[a][axis] < centres_[b][axis]; });
    }
    int32_t l = node(lo, lo + left, depth + 1, stats);
    int32_t r = node(lo + left, end, depth + 1, stats);
    nodes_[id].left = l, nodes_[id].right = r;
    return id;
  }

  uint32_t split_step(uint32_t lo, uint32_t end, const Box3& cbox) {
    BinningSplit split{boxes_, centres_};
    return split(items_.data() + lo, items_.data() + end, cbox);
  }

  // M = N: node P at triangle P, a node's children side by side.
  void lay_out(std::vector<uint32_t>& order, std::vector<uint32_t>& words, ZeroByteStats& stats) {
    const size_t base = order.size();
    order.resize(base + items_.size());
    words.resize((base + items_.size()) * 3);
    std::vector<uint32_t> pos(nodes_.size());
    uint32_t cursor = nodes_[0].count;
    std::vector<int32_t> stack{0};
    while (!stack.empty()) {
      const ZbtNodeBuild& n = nodes_[size_t(stack.back())];
      uint32_t p = pos[size_t(stack.back())];
      stack.pop_back();
      uint32_t child = 0;
      if (n.left >= 0) {
        pos[size_t(n.left)] = child = cursor;
        cursor += nodes_[size_t(n.left)].count;
        pos[size_t(n.right)] = cursor;
        cursor += nodes_[size_t(n.right)].count;
        stack.push_back(n.right);
        stack.push_back(n.left);
      }
      for (uint32_t i = 0; i < n.count; ++i) {
        uint32_t t = items_[n.first + i];
        order[base + p + i] = t;
        for (int c = 0; c < 3; ++c) words[(base + p + i) * 3 + c] = mesh_.triangles[t][c];
      }
      uint32_t bits = child | n.count << MC_ZBT_CHILD_BITS;
      for (int c = 0; c < 3; ++c) words[(base + p) * 3 + c] |= (bits >> (8 * c) & 0xFF) << 24;
      if (n.left >= 0 && n.count >= 2) {
        // Seed 002's sorting byte and the shuffled flag in triangle P + 1.
        uint32_t pns = pns_code(nodes_[size_t(n.left)].box, nodes_[size_t(n.right)].box);
        words[(base + p + 1) * 3 + 0] |= pns << 24;
        words[(base + p + 1) * 3 + 1] |= (uint32_t(n.shuffled) | (n.corners & 0x3F) << 1) << 24;
        words[(base + p + 1) * 3 + 2] |= (n.corners >> 6 & 0x3F) << 24;
      }
    }
    stats.nodes += uint32_t(nodes_.size());
  }

  const Mesh& mesh_;
  const std::vector<Box3>& boxes_;
  const std::vector<Vec3>& centres_;
  bool shuffle_;
  std::vector<uint32_t> items_;
  std::vector<ZbtNodeBuild> nodes_;
  uint32_t depth0_ = 0;
};

// The hybrid's nodes: AABBTree layout (first child behind its parent, the
// second's offset in the node), a leaf's value the position of its
// zero-byte tree's root.
uint32_t write_hybrid_nodes(const BuildTree& t, uint32_t n, const std::vector<uint32_t>& leaf_root,
                            const std::vector<Box3>& leaf_box, std::vector<uint8_t>& out, Box3* box) {
  const BuildNode& b = t.nodes[n];
  uint32_t at = uint32_t(out.size());
  out.resize(at + MC_AABB_NODE_BYTES);
  layout::AABBNode node{};
  if (b.leaf()) {
    *box = leaf_box[n];
    node.properties = MC_AABB_LEAF_BIT | leaf_root[n];
  } else {
    Box3 lb, rb;
    write_hybrid_nodes(t, b.left, leaf_root, leaf_box, out, &lb);
    uint32_t right = write_hybrid_nodes(t, b.right, leaf_root, leaf_box, out, &rb);
    *box = lb;
    box->grow(rb);
    node.properties = right;
  }
  for (int a = 0; a < 3; ++a) node.min[a] = box->min[a], node.max[a] = box->max[a];
  std::memcpy(out.data() + at, &node, sizeof node);
  return at;
}

}  // namespace

std::string ZeroByteStats::describe() const {
  char text[200];
  std::snprintf(text, sizeof text, "%u zero-byte nodes (%u leaves), %.2f bound triangles an interior node, %.1f%% shuffled",
                nodes, leaves, interior ? double(bound_triangles) / interior : 0.0,
                interior ? 100.0 * shuffled / interior : 0.0);
  return text;
}

namespace {

// ZeroByteTree (seed 004) and ZeroByteHybrid (an SAH tree of zero-byte
// trees): the writer of both. They store the mesh's own indices (24 bits
// each) and its float vertices, and lay out trees of their own, not the
// binary tree the others are written from: build() builds them and hands
// build_blob the triangle order alone, and the leaf size and node order
// options, which they do not use, are not checked.
class ZeroByteWriter : public TreeWriter {
 public:
  ZeroByteWriter(std::string_view tree_name, bool hybrid, const BuildOptions& o)
      : tree_name_(tree_name), hybrid_(hybrid), shuffle_(o.zbt_shuffle), box_cache_(o.zbt_box_cache),
        hybrid_leaf_(o.hybrid_leaf) {}

  void check(const Mesh& mesh, const BuildOptions& o) const override {
    const std::string what(tree_name_);
    if (uint32_t(o.layout.triangles) != MC_TRI_INDEXED24) throw InputError(what + " stores the mesh's own indices: Indexed24 only");
    if (o.pairing) throw InputError(what + ": pairing builds the other trees; a zero-byte tree picks its own order");
    if (!hybrid_ && mesh.triangles.size() > MC_ZBT_MAX_TRIANGLES)
      throw InputError(what + " holds at most " + std::to_string(MC_ZBT_MAX_TRIANGLES) +
                       " triangles (21-bit node positions, seed 004); this mesh has " + std::to_string(mesh.triangles.size()) +
                       " (ZeroByteHybrid takes more)");
    if (hybrid_ && (hybrid_leaf_ < 8 || hybrid_leaf_ > MC_ZBT_MAX_TRIANGLES))
      throw InputError(what + ": hybrid leaf of " + std::to_string(hybrid_leaf_) + " triangles is outside 8.." +
                       std::to_string(MC_ZBT_MAX_TRIANGLES));
    if (mesh.vertices.size() > MC_ZBT_MAX_VERTICES)
      throw InputError(what + " keeps 24 bits of each vertex index: at most " + std::to_string(MC_ZBT_MAX_VERTICES) +
                       " vertices; this mesh has " + std::to_string(mesh.vertices.size()));
    if (12ull * (mesh.triangles.size() + mesh.vertices.size()) + 4096 > 0xF0000000ull)
      throw InputError(what + ": the blob would exceed the 4 GiB its 32-bit offsets reach");
  }

  // Indexed24 as build_blob sees it: float corners, 12 bytes a triangle
  // slot, and no blocks for it to encode (fill writes the index words).
  CodecOps codec(const BuildOptions&) const override {
    return {MC_TRI_INDEXED24, layout::Indexed24::kSlotDivisor, layout::kGridNone, 0, false, false, false, 1, nullptr, nullptr};
  }

  BuildTree build(const TreeInput& in, uint32_t) override {
    refuse_given_tree(in);
    const Mesh& mesh = *(mesh_ = &in.mesh);
    const std::vector<Box3>& boxes = in.boxes;
    std::vector<Vec3> centres(boxes.size());
    bounds_ = Box3{};
    for (size_t t = 0; t < boxes.size(); ++t) {
      centres[t] = boxes[t].centre();
      bounds_.grow(boxes[t]);
    }
    stats_ = ZeroByteStats{};
    ZbtBuilder zbt(mesh, boxes, centres, shuffle_);
    BuildTree order_only;
    std::vector<uint32_t>& order = order_only.order;
    words_.clear(), nodes_.clear(), top_nodes_ = 0;
    if (!hybrid_) {
      std::vector<uint32_t> all(mesh.triangles.size());
      std::iota(all.begin(), all.end(), 0u);
      zbt.build(std::move(all), 0, order, words_, stats_);
    } else {
      BuildTree top = build_tree(boxes, Splitter::Binning, hybrid_leaf_);
      const uint32_t top_depth = top.depth + 1;  // a leaf's zero-byte root lies one below it
      std::vector<uint32_t> leaf_root(top.nodes.size(), 0);
      std::vector<Box3> leaf_box(top.nodes.size());
      for (size_t n = 0; n < top.nodes.size(); ++n) {
        const BuildNode& b = top.nodes[n];
        if (!b.leaf()) continue;
        leaf_root[n] = uint32_t(order.size());
        std::vector<uint32_t> items(top.order.begin() + b.first, top.order.begin() + b.first + b.count);
        for (uint32_t t : items) leaf_box[n].grow(boxes[t]);
        zbt.build(std::move(items), top_depth, order, words_, stats_);
      }
      Box3 root_box;
      write_hybrid_nodes(top, 0, leaf_root, leaf_box, nodes_, &root_box);
      top_nodes_ = uint32_t(top.nodes.size());
    }
    if (in.report) in.report->zerobyte = stats_.describe() + (box_cache_ ? "; box cache on" : "; box cache off");
    return order_only;
  }

  // The hybrid's nodes, then 12 bytes a triangle: its three index words.
  void plan(Writer& w) override {
    // Everything the blob holds, counted in 64 bits before any header field
    // narrows to 32: header, the hybrid's nodes, indices, vertices, and the
    // remap (at most 8 bytes a triangle with its bitmap and ranks).
    const uint64_t triangles = mesh_->triangles.size(), vertices = mesh_->vertices.size();
    const uint64_t total = 256 + uint64_t(nodes_.size()) + 12ull * triangles + 12ull * vertices + 8ull * triangles + 64;
    if (total > 0xF0000000ull)
      throw InputError(std::string(tree_name_) + ": the blob would take about " + std::to_string(total >> 20) +
                       " MiB, beyond the 4 GiB its 32-bit offsets reach");
    w.h.node_count = stats_.nodes + top_nodes_;
    w.h.leaf_size = hybrid_ ? hybrid_leaf_ : MC_ZBT_MAX_COUNT;
    w.h.root = box_cache_ ? MC_ZBT_FLAG_BOX_CACHE : 0;
    w.h.node_bytes = w.h.triangle_base = uint32_t(nodes_.size());
    w.h.tree_size = uint32_t(nodes_.size() + 12ull * triangles);
  }

  // The words in place, the mesh's vertices as the vertex pool, the
  // triangle order as the remap.
  void fill(Writer& w) override {
    uint8_t* tree = w.bytes.data() + w.h.tree_offset;
    if (!nodes_.empty()) std::memcpy(tree, nodes_.data(), nodes_.size());
    std::memcpy(tree + w.h.triangle_base, words_.data(), 4ull * words_.size());
    w.pool.resize(12 * mesh_->vertices.size());
    for (size_t v = 0; v < mesh_->vertices.size(); ++v) {
      float p[3] = {mesh_->vertices[v].x, mesh_->vertices[v].y, mesh_->vertices[v].z};
      std::memcpy(w.pool.data() + 12 * v, p, 12);
    }
    w.remap = w.tree.order;
    w.frame(bounds_);
  }

  uint32_t depth(const BuildTree&) const override { return stats_.depth; }
  uint32_t leaf_count(const BuildTree&) const override { return stats_.leaves; }

 private:
  std::string_view tree_name_;
  const Mesh* mesh_ = nullptr;  // build's
  bool hybrid_, shuffle_, box_cache_;
  uint32_t hybrid_leaf_;
  ZeroByteStats stats_;
  Box3 bounds_;
  std::vector<uint32_t> words_;
  std::vector<uint8_t> nodes_;  // the hybrid's
  uint32_t top_nodes_ = 0;
};

}  // namespace

std::unique_ptr<TreeWriter> make_writer(layout::tree::ZeroByteTree tag, const BuildOptions& o) {
  return std::make_unique<ZeroByteWriter>(tag.kName, false, o);
}
std::unique_ptr<TreeWriter> make_writer(layout::tree::ZeroByteHybrid tag, const BuildOptions& o) {
  return std::make_unique<ZeroByteWriter>(tag.kName, true, o);
}

}  // namespace meshcast
