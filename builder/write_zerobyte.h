// Zero-byte trees (seed 004) and the hybrid: the statistics of their
// builder (builder/write_zerobyte.cpp, whose make_writer overloads
// builder/writer.h declares). The walkers are in
// cpu/walk_zerobyte.cpp, the bits in layout/tree/zerobyte.h.
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

}  // namespace meshcast
