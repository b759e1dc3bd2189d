// Box and triangle tests, counted per thread for the tables that report
// them (seed 003's pairing table, `bench peers` beside Embree's own
// counters), with the inner nodes whose children a walk tested together (a
// 4- or 8-wide test: the quad and oct trees) and the leaves it tested.
// Compiled in only with the CMake option
// MESHCAST_COUNT_TESTS (the scalar test build has it), so a timed build
// does no extra work; elsewhere kCountTests is false and the counts stay 0.
#pragma once
#include <cstdint>

#include "cpu/isa.h"

namespace meshcast {

struct TestCounts {
  uint64_t boxes = 0, triangles = 0, nodes = 0, leaves = 0;
};

#ifdef MESHCAST_COUNT_TESTS
inline constexpr bool kCountTests = true;
inline thread_local TestCounts test_counts;
#else
inline constexpr bool kCountTests = false;
inline TestCounts test_counts;  // never written
#endif

MC_ISA_BEGIN
inline void count_boxes(uint64_t n) {
  if constexpr (kCountTests) test_counts.boxes += n;
}
inline void count_triangles(uint64_t n) {
  if constexpr (kCountTests) test_counts.triangles += n;
}
// One node's children tested together (`width` boxes).
inline void count_node(uint64_t width) {
  if constexpr (kCountTests) test_counts.boxes += width, ++test_counts.nodes;
}
inline void count_leaves(uint64_t n) {
  if constexpr (kCountTests) test_counts.leaves += n;
}
MC_ISA_END

}  // namespace meshcast
