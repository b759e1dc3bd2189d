// Writes a mesh into a blob: quantize (if the triangle format does), build
// the binary tree from the stored triangles, lay it out in the tree format,
// encode each leaf with the triangle format, then the remap and the header.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "cpu/build.h"
#include "cpu/mesh.h"

namespace meshcast {


// Node orders of seed 000 §4.3; Default is the format's own. Only the quad
// trees, whose nodes address every child and block by offset, take all four.
enum class NodeOrder { Default, DepthFirst, DepthFirstTrianglesLast, BreadthFirst, BreadthFirstTrianglesLast };
const char* node_order_name(NodeOrder order);
NodeOrder parse_node_order(const std::string& name);  // throws InputError listing the valid names
std::vector<NodeOrder> all_node_orders();             // the four of §4.3
// "" when the tree format can be written in that order, else why not.
std::string node_order_refusal(uint32_t tree_format, NodeOrder order);

struct BuildOptions {
  uint32_t tree_format = 3;      // MC_TREE_*
  uint32_t triangle_format = 3;  // MC_TRI_*
  uint32_t leaf_size = 8;        // 4, 8 or 16 in the source; 1..31 accepted
  Splitter splitter = Splitter::Binning;  // seed 000 §4.1
  // StacklessLBVH (seed 001): the depth limit D (leaves at depth D - 1 at
  // most; 0: bit_width(triangles) + 1, the seed's choice for its meshes),
  // and whether interior nodes carry seed 002's bits so each ray visits the
  // nearer child first (false: left first, as the seed).
  uint32_t lbvh_depth = 0;
  bool lbvh_near_first = true;
  NodeOrder node_order = NodeOrder::Default;
  Grouping grouping = Grouping::ClosestCentroid;  // AABBList's batches (seed 000 §7)
  // Seed 003: triangles paired across shared edges (cpu/pairing.h) become
  // the builder's primitives, so every leaf holds whole pairs, each pair's
  // two triangles side by side (at most leaf_size triangles a leaf).
  bool pairing = false;
  // Zero-byte trees (seed 004): interior nodes bounded by 6 triangles whose
  // first corners give the 6 extremes where the mesh allows it (a box from
  // 6 vertices, not 18); the walkers' per-thread box cache; the hybrid's
  // largest leaf (each leaf one zero-byte tree).
  bool zbt_shuffle = true;
  bool zbt_box_cache = true;
  uint32_t hybrid_leaf = 256;
  // The remap section, which turns a hit's slot into the caller's triangle
  // number. false: left out, hits name triangles by slot number (see
  // layout/blob.h has_remap; stored_mesh gives their corners). When the
  // build kept the input order it is only the used-slot bitmap and ranks.
  bool triangle_ids = true;
};

struct BuildReport {
  double sah_cost = 0;
  double build_ms = 0;
  std::string pairing;      // the pairing pass's decision ("" without pairing)
  double paired_ratio = 0;  // share of triangles in a pair
  std::string zerobyte;     // zero-byte trees: nodes, shuffled share, cache ("" otherwise)
};

// Throws InputError (naming `name`) for a mesh the layout cannot hold.
std::vector<uint8_t> build_blob(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                BuildReport* report = nullptr);

// "AABBTree/Float3" etc., case-insensitive. Throws InputError listing the
// valid names for anything else.
BuildOptions parse_layout(const std::string& text);
std::string layout_name(uint32_t tree_format, uint32_t triangle_format);

// True for the triangle formats that store moved vertices (grids, cleared
// flag bits): they are judged against stored_mesh(), not the input mesh.
bool moves_vertices(uint32_t triangle_format);
std::vector<std::string> layout_names();

// Worst-case distance, per axis, between an input vertex and the position the
// 21-bit BitPack grid of seed 000 §3.4 stores for it.
void quantization_bound(const float offset[3], const float scale[3], float bound[3]);

// The stated worst-case displacement, per axis, of any stored corner from
// its input vertex, for the blob's triangle format (0 for the float ones).
void displacement_bound(const std::vector<uint8_t>& blob, float bound[3]);
// The same as one length (the per-axis bounds' Euclidean norm) over the
// mesh diagonal `diagonal`: the error the error report states and the
// automatic layout's --max-error limits.
double relative_error_bound(const std::vector<uint8_t>& blob, double diagonal);

}  // namespace meshcast
