// The catalog: the one list of tree formats, with what the code needs of
// each. Every switch on a tree format is generated from it (validation,
// leaf descent, the writers, the walkers' dispatch, names), so a new tree
// format is one line here and one file per room:
//   layout/tree/  its bits, validator and leaf descent (validate_tree and
//              for_each_leaf_of overloads on its tag),
//   builder/   its writer (a make_writer overload on its tag),
//   cpu/       its walker (a walk overload on its tag, instantiated for
//              every triangle codec),
//   shaders/   its compute shader, if a GPU method reads it, with a line in
//              gpu/method_table.cpp (the one table of what the GPU reads).
// docs/adding-formats.md walks through it file by file.
// The triangle formats' list is MC_FOR_EACH_TRIANGLE_CODEC (layout/triangles/codecs.h).
#pragma once
#include <cstdint>
#include <string_view>

#include "layout/formats.h"
#include "meshcast/build.h"

// X(Name, id, smallest node in bytes, triangles, order, leaf size, splitter)
//   triangles  AllCodecs: every codec of layout/triangles/codecs.h; Indexed24: the
//              mesh's own indices only (the zero-byte trees)
//   order      the node order its bits allow (seed 000 §4.3): AnyOrder,
//              NoTree, or the one its addressing fixes
//   leaf size  the largest leaf it is built with unless the caller says
//              (meshcast/build.h's default_leaf_size): OctTreeCompressed's
//              8-wide nodes fill best from leaves of 16; the zero-byte
//              trees' leaves are fixed by their bits (or hybrid_leaf)
//   splitter   the binary tree's splitter unless the caller says: the seed
//              001 heap is built by Morton-code middle split, the rest by SAH
#define MC_FOR_EACH_TREE_FORMAT(X)                                                                            \
  X(AABBTree, MC_TREE_AABBTREE, MC_AABB_NODE_BYTES, AllCodecs, BehindTheNode, 8, Binning)                     \
  X(AABBTreeSplitAxis, MC_TREE_AABBTREESPLITAXIS, MC_AABB_NODE_BYTES, AllCodecs, BehindTheNode, 8, Binning)   \
  X(AABBTreePNS, MC_TREE_AABBTREEPNS, MC_AABB_NODE_BYTES, AllCodecs, DepthFirstIndex, 8, Binning)             \
  X(AABBTreeCompressed, MC_TREE_AABBTREECOMPRESSED, MC_COMPRESSED_NODE_BYTES, AllCodecs, BehindTheNode, 8, Binning)\
  X(SKDTree, MC_TREE_SKDTREE, MC_SKD_LEAF_BYTES, AllCodecs, BehindTheNode, 8, Binning)                        \
  X(StacklessLBVH, MC_TREE_STACKLESSLBVH, MC_LBVH_NODE_BYTES, AllCodecs, Heap, 8, Morton)                     \
  X(QuadTree, MC_TREE_QUADTREE, MC_QUAD_NODE_BYTES, AllCodecs, AnyOrder, 8, Binning)                          \
  X(QuadTreeHalfFloat, MC_TREE_QUADTREEHALFFLOAT, MC_QUADHALF_NODE_BYTES, AllCodecs, AnyOrder, 8, Binning)    \
  X(OctTreeCompressed, MC_TREE_OCTTREECOMPRESSED, MC_OCT_NODE_BYTES, AllCodecs, AnyOrder, 16, Binning)        \
  X(BruteForce, MC_TREE_BRUTEFORCE, MC_BRUTE_RECORD_BYTES, AllCodecs, NoTree, 8, Binning)                     \
  X(AABBList, MC_TREE_AABBLIST, MC_LIST_ENTRY_BYTES, AllCodecs, NoTree, 8, Binning)                           \
  X(ZeroByteTree, MC_TREE_ZEROBYTE, MC_BRUTE_RECORD_BYTES, Indexed24, BehindTheNode, 8, Binning)              \
  X(ZeroByteHybrid, MC_TREE_ZEROBYTEHYBRID, MC_BRUTE_RECORD_BYTES, Indexed24, BehindTheNode, 8, Binning)

namespace meshcast::layout {

enum class TreeTriangles { AllCodecs, Indexed24 };

// What a format's bits let the writer choose of seed 000 §4.3's node orders.
enum class TreeOrder {
  AnyOrder,         // nodes address every child and block by offset: all four
  NoTree,           // no nodes at all
  BehindTheNode,    // depth first: the first child and a leaf's block sit right behind their node
  DepthFirstIndex,  // depth first, triangles last: nodes addressed by depth-first index
  Heap,             // breadth first, triangles last: the nodes are a heap
};

// One tag type a tree format, for the overloads each room defines.
namespace tree {
#define MC_TREE_TAG(Name, id, node_bytes, triangles, order, leaf_size, splitter) \
  struct Name {                                                       \
    static constexpr uint32_t kId = id;                               \
    static constexpr std::string_view kName = #Name;                  \
    static constexpr uint32_t kSmallestNode = node_bytes;             \
    static constexpr TreeTriangles kTriangles = TreeTriangles::triangles; \
    static constexpr TreeOrder kOrder = TreeOrder::order;             \
    static constexpr uint32_t kDefaultLeafSize = leaf_size;           \
    static constexpr Splitter kDefaultSplitter = Splitter::splitter;  \
  };
MC_FOR_EACH_TREE_FORMAT(MC_TREE_TAG)
#undef MC_TREE_TAG
}  // namespace tree

// The catalog's line for a tree format id, by value (no pointer into a table
// a static initialiser might not have made yet).
struct TreeFormatInfo {
  uint32_t id = 0;
  std::string_view name;  // "" for an unknown id
  uint32_t smallest_node = 0;
  TreeTriangles triangles = TreeTriangles::AllCodecs;
  TreeOrder order = TreeOrder::AnyOrder;
  uint32_t default_leaf_size = 0;
  Splitter default_splitter = Splitter::Binning;
};

constexpr TreeFormatInfo tree_format_info(uint32_t id) {
#define MC_TREE_INFO(Name, ...) \
  if (id == tree::Name::kId)    \
    return {tree::Name::kId,    tree::Name::kName,            tree::Name::kSmallestNode,   tree::Name::kTriangles, \
            tree::Name::kOrder, tree::Name::kDefaultLeafSize, tree::Name::kDefaultSplitter};
  MC_FOR_EACH_TREE_FORMAT(MC_TREE_INFO)
#undef MC_TREE_INFO
  return {};
}

// Calls f(Tag{}) for the tree format `id`'s tag; returns f's answer, or
// `otherwise` for an unknown id. The generated switch every room uses.
template <class R, class F>
R with_tree_format(uint32_t id, R otherwise, F&& f) {
  switch (id) {
#define MC_TREE_CASE(Name, ...) \
  case tree::Name::kId: return f(tree::Name{});
    MC_FOR_EACH_TREE_FORMAT(MC_TREE_CASE)
#undef MC_TREE_CASE
  }
  return otherwise;
}

// The public names (meshcast/build.h) are the ids a blob stores.
#define MC_TREE_PUBLIC_ID(Name, ...) static_assert(uint32_t(TreeFormat::Name) == tree::Name::kId);
MC_FOR_EACH_TREE_FORMAT(MC_TREE_PUBLIC_ID)
#undef MC_TREE_PUBLIC_ID

}  // namespace meshcast::layout
