// A blob's closest hits with either triangle test, for the comparison
// `meshcast bench robustness` makes (bench/robustness.cpp) and its test:
// the watertight test is the view's own walk; the plain Möller–Trumbore
// test walks the same layout's walker compiled with it, for the instruction
// set the view's walkers run on (walker_isa()). Those walkers live in
// meshcast_triangle_tests (CMakeLists.txt), which only the benchmark and
// the tests link: the library carries no trace of the plain test.
#pragma once
#include <cstdint>
#include <span>

#include "cpu/which_triangle_test.h"
#include "meshcast/blob.h"

namespace meshcast {

// As view.trace(rays, hits): closest hits, no u, v or point, no culling;
// returns the rays not walkable. UsageError when hits is shorter than rays.
uint64_t trace_with_triangle_test(const BlobView& view, TriangleTest test, std::span<const Ray> rays,
                                  std::span<Hit> hits);

}  // namespace meshcast
