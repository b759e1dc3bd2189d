// Writes a mesh into a blob: quantize (if the triangle format does), build
// the binary tree from the stored triangles, lay it out in the tree format,
// encode each leaf with the triangle format, then the remap and the header.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "cpu/build.h"
#include "meshcast/mesh.h"

namespace meshcast {


// Node orders (meshcast/build.h's NodeOrder).
const char* node_order_name(NodeOrder order);
NodeOrder parse_node_order(const std::string& name);  // throws InputError listing the valid names
std::vector<NodeOrder> all_node_orders();             // the four of §4.3
// "" when the tree format can be written in that order, else why not.
std::string node_order_refusal(uint32_t tree_format, NodeOrder order);

// BuildOptions for the layout named "AABBTree/Float3" etc. (the layout's
// own defaults: StacklessLBVH builds by Morton middle split), case-insensitive.
// Throws InputError listing the valid names for anything else.
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
