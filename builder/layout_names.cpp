// Layouts and node orders by name: the names the seeds write, parsed and
// listed, and which node orders a tree format can be written in.
#include "builder/layout_names.h"

#include <cctype>

#include "cpu/pairs.h"
#include "layout/blob_format.h"
#include "layout/codecs.h"

namespace meshcast {

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

}  // namespace

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
