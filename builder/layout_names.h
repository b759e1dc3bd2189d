// Layouts and node orders by name (meshcast/build.h has the public
// parse_layout_name and layout_name of a Layout).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "builder/binary_tree.h"
#include "meshcast/build.h"

namespace meshcast {

// Node orders (meshcast/build.h's NodeOrder).
const char* node_order_name(NodeOrder order);
NodeOrder parse_node_order(const std::string& name);  // throws InputError listing the valid names
std::vector<NodeOrder> all_node_orders();             // the four of §4.3
// "" when the tree format can be written in that order, else why not.
std::string node_order_refusal(uint32_t tree_format, NodeOrder order);

// BuildOptions for the layout named "AABBTree/Float3" etc. (the layout's
// own defaults: StacklessLBVH builds by Morton middle split), case-insensitive.
// Throws InputError offering the closest names for anything else.
BuildOptions parse_layout(const std::string& text);
// The three layout names nearest `text` ("A, B or C"): a tree or triangle
// format typed in part ("OctTree") counts as near its whole name.
std::string closest_layouts(const std::string& text);
std::string layout_name(uint32_t tree_format, uint32_t triangle_format);
std::vector<std::string> layout_names();

}  // namespace meshcast
