// Zero-byte trees (seed 004) and the hybrid: the builder's entry point
// (builder/write_zerobyte.cpp) and its statistics. The walkers are in
// cpu/walk_zerobyte.cpp, the bits in layout/zerobyte.h.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "builder/error_bounds.h"
#include "builder/layout_names.h"

namespace meshcast {

struct ZeroByteStats {
  uint32_t nodes = 0, leaves = 0, interior = 0, shuffled = 0, depth = 0;
  uint64_t bound_triangles = 0;  // over interior nodes
  std::string describe() const;
};

// build_blob() for MC_TREE_ZEROBYTE and MC_TREE_ZEROBYTEHYBRID. Throws
// InputError naming `name` and the limit a mesh exceeds (2^21 triangles
// for one zero-byte tree, 2^24 vertices).
std::vector<uint8_t> build_zerobyte_blob(const Mesh& mesh, const BuildOptions& o, const std::string& name,
                                         BuildReport* report);

}  // namespace meshcast
