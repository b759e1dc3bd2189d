// Layouts by name: "OctTreeCompressed/ClusterBitPackSOA8" and back, every
// layout the catalog (layout/catalog.h) and the codecs (layout/triangles/codecs.h)
// make, and the names nearest a mistyped one. meshcast/build.h declares the
// public part (layout_name of a Layout, parse_layout_name, all_layouts).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "meshcast/build.h"

namespace meshcast {

// The name of the layout a blob header states (ids, not a Layout: an
// unknown id is named as such rather than cast to an enum).
std::string layout_name(uint32_t tree_format, uint32_t triangle_format);
std::vector<std::string> layout_names();
// The three layout names nearest `text` ("A, B or C"): a tree or triangle
// format typed in part ("OctTree") counts as near its whole name.
std::string closest_layouts(const std::string& text);
// The same for any list of names (the generated meshes'): the `count`
// nearest `text`, nearest first, case folded, a name typed in part near
// its whole, as "A, B or C".
std::string closest_names(const std::string& text, const std::vector<std::string>& names, size_t count = 3);

}  // namespace meshcast
