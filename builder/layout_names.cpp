// A layout's build defaults, and node orders by name: parsed, listed, and
// which ones a tree format can be written in.
#include "builder/layout_names.h"

#include <vector>

#include "layout/blob_format.h"
#include "layout/catalog.h"

namespace meshcast {

// The catalog's columns (layout/catalog.h).
uint32_t default_leaf_size(Layout layout) { return layout::tree_format_info(uint32_t(layout.tree)).default_leaf_size; }

BuildOptions parse_layout(const std::string& text) {
  BuildOptions o;
  o.layout = parse_layout_name(text);
  o.leaf_size = default_leaf_size(o.layout);
  o.splitter = layout::tree_format_info(uint32_t(o.layout.tree)).default_splitter;
  return o;
}

std::string node_order_refusal(uint32_t tree, NodeOrder order) {
  const layout::TreeFormatInfo info = layout::tree_format_info(tree);
  if (order == NodeOrder::Default || info.order == layout::TreeOrder::AnyOrder) return "";
  // What each other format's bits fix (seed 000 5.1-5.5, seed 001).
  NodeOrder fixed = NodeOrder::DepthFirst;
  const char* why = "its first child and its leaves' blocks sit right behind their node";
  switch (info.order) {
    case layout::TreeOrder::NoTree:
      return std::string(info.name) + (info.id == MC_TREE_AABBLIST ? " is a list of batches" : " has no tree") +
             ", so no node order";
    case layout::TreeOrder::DepthFirstIndex:
      fixed = NodeOrder::DepthFirstTrianglesLast, why = "it addresses nodes by depth-first index";
      break;
    case layout::TreeOrder::Heap: fixed = NodeOrder::BreadthFirstTrianglesLast, why = "its nodes are a heap"; break;
    default: break;
  }
  if (order == fixed) return "";
  return std::string(info.name) + " is always " + node_order_name(fixed) + ": " + why +
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
