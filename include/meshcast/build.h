// Building a blob: a mesh (the caller's arrays, or a Mesh) in, one byte
// buffer out, laid out as a tree format x triangle format (the layout). The
// bytes are read unchanged by the CPU walkers (meshcast/blob.h), the host
// Caster and the Vulkan methods. Builds are independent: several threads may
// build at once.
//
//   meshcast::BuildOptions options;                       // the recommended layout
//   std::vector<uint8_t> blob = meshcast::build_blob(view, options, "level");
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/mesh.h"

namespace meshcast {

// The tree formats (ids as stored in a blob's header; docs/design.md
// describes each).
enum class TreeFormat : uint32_t {
  AABBTree = 1,
  QuadTree = 2,
  QuadTreeHalfFloat = 3,
  BruteForce = 4,
  AABBTreeSplitAxis = 5,
  AABBTreePNS = 6,
  AABBTreeCompressed = 7,
  SKDTree = 8,
  StacklessLBVH = 9,
  AABBList = 10,
  ZeroByteTree = 11,
  ZeroByteHybrid = 12,
  OctTreeCompressed = 13,  // 8 children a node, boxes in 8 bits on power-of-two scales
};

// The triangle formats (docs/design.md describes each). The BitPack ones
// store vertices on a 21-bit grid (moved by at most a stated bound).
enum class TriangleFormat : uint32_t {
  Float3 = 1,
  Float3SOA4 = 2,
  Indexed8BitPackSOA4 = 3,
  Indexed16 = 4,
  Indexed32 = 5,
  Indexed16SOA4 = 6,
  Indexed32SOA4 = 7,
  Indexed16BitPackSOA4 = 8,
  Indexed32BitPackSOA4 = 9,
  Float3SOA8 = 10,
  Float3SOA128 = 11,
  BitPackSOA4 = 12,
  BitPackSOA128 = 13,
  BitPack = 14,
  UncompressedStrip = 15,
  CompressedStrip = 16,
  Indexed24 = 17,
  Float3PairSOA4 = 18,
  ClusterBitPackSOA8 = 19,  // clusters of up to 16 mesh-grid vertices stored once, 4-bit indices
  ClusterFloat3SOA8 = 20,   // the same clusters over the mesh's float vertices: exact
};

// A tree format with a triangle format. The default is the recommended
// layout: the fastest CPU walker of bench peers at 15-21 bytes a triangle,
// all included (leaves of 16), read by the Vulkan method octtree too.
struct Layout {
  TreeFormat tree = TreeFormat::OctTreeCompressed;
  TriangleFormat triangles = TriangleFormat::ClusterBitPackSOA8;
  bool operator==(const Layout&) const = default;
};

// "QuadTreeHalfFloat/Indexed8BitPackSOA4", and back (case-insensitive;
// InputError listing the valid names for anything else).
std::string layout_name(Layout layout);
Layout parse_layout_name(const std::string& name);
// Every layout that builds.
std::vector<Layout> all_layouts();
// The leaf size a layout is built with unless told: 16 for
// OctTreeCompressed (its clusters and 8-wide nodes fill best, bench peers),
// 8 for the others (the source's).
uint32_t default_leaf_size(Layout layout);

// The splitters of the binary tree every layout is written from; SAH
// binning is the default.
enum class Splitter { Binning, LongestAxis, Mean, Morton, FixedLeafSize };
// Node orders in the blob; Default is the format's own. Only the quad
// trees, whose nodes address every child and block by offset, take all four.
enum class NodeOrder { Default, DepthFirst, DepthFirstTrianglesLast, BreadthFirst, BreadthFirstTrianglesLast };
// AABBList batches: how triangles are grouped, 256 a batch.
//   ClosestCentroid  the unused triangle with the lowest centre x and the
//                    255 unused triangles whose centres lie nearest to it
//   Morton           consecutive runs of the Morton order
enum class Grouping { ClosestCentroid, Morton };

struct BuildOptions {
  Layout layout;
  // Largest triangle count of a leaf, 1..31 (4, 8 or 16 in the source); 0:
  // the layout's own (default_leaf_size).
  uint32_t leaf_size = 0;
  Splitter splitter = Splitter::Binning;
  // StacklessLBVH: the depth limit D (leaves at depth D - 1 at most; 0:
  // bit_width(triangles) + 1), and whether interior nodes carry 8 sorting
  // bits (one a ray octant) so each ray visits the nearer child first
  // (false: left first).
  uint32_t lbvh_depth = 0;
  bool lbvh_near_first = true;
  NodeOrder node_order = NodeOrder::Default;
  Grouping grouping = Grouping::ClosestCentroid;
  // Triangles paired across shared edges become the builder's
  // primitives, so every leaf holds whole pairs (at most leaf_size
  // triangles a leaf).
  bool pairing = false;
  // Zero-byte trees: interior nodes bounded by 6 triangles whose
  // first corners give the 6 extremes where the mesh allows it; the
  // walkers' per-thread box cache; the hybrid's largest leaf (each leaf one
  // zero-byte tree).
  bool zbt_shuffle = true;
  bool zbt_box_cache = true;
  uint32_t hybrid_leaf = 256;
  // The remap section, which turns a hit's slot into the caller's triangle
  // number. false: left out, hits name triangles by their slot in the blob.
  bool triangle_ids = true;
  // Threads the build may use at once, the caller's among them, at most
  // 1024 (0: one a hardware thread). The blob is the same bytes on any
  // number: the tree is split into parts that are put together in one
  // order. Meshes under 16,384 triangles build on the caller's thread
  // alone; a caller running several builds at once may give each 1.
  uint32_t threads = 0;
};

// What a build did, for those who ask.
struct BuildReport {
  double sah_cost = 0;
  double build_ms = 0;
  std::string pairing;      // the pairing pass's decision ("" without pairing)
  double paired_ratio = 0;  // share of triangles in a pair
  std::string zerobyte;     // zero-byte trees: nodes, shuffled share, cache ("" otherwise)
};

// The blob of `mesh` in the options' layout. InputError, naming `name`, for a
// mesh the layout cannot hold (its limit named) or a bad mesh (check_mesh).
std::vector<uint8_t> build_blob(const Mesh& mesh, const BuildOptions& options, const std::string& name,
                                BuildReport* report = nullptr);
// The same from the caller's arrays, read in place (MeshView).
std::vector<uint8_t> build_blob(const MeshView& mesh, const BuildOptions& options, const std::string& name,
                                BuildReport* report = nullptr);

}  // namespace meshcast
