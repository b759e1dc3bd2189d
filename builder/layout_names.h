// Build options by name: a layout's own defaults, and node orders
// (layout/names.h names the layouts themselves).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "builder/binary_tree.h"
#include "layout/names.h"
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

}  // namespace meshcast
