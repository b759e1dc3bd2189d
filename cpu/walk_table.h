// The walkers' dispatch table, one a instruction set (cpu/walk_table.cpp is
// compiled for each, cpu/isa.h) and triangle test (cpu/which_triangle_test.h):
// every (tree, triangle format) pair of the catalog with its walker.
#pragma once
#include <cstdint>
#include <span>

#include "cpu/which_triangle_test.h"
#include "cpu/walk.h"
#include "meshcast/blob.h"

namespace meshcast {

struct WalkEntry {
  uint32_t tree, triangles;
  WalkFn walk;
};

// This translation unit's set's table (the one cpu/walk.h's inline
// namespace names), and by name the others a multi-set build has (not the
// unit's own again: clang warns when an inline namespace is reopened as a
// plain one). Each is instantiated for the test its walkers were compiled
// with alone (kWalkersTriangleTest): the library's objects for the
// watertight test, meshcast_triangle_tests' for the plain one.
MC_ISA_BEGIN
template <TriangleTest kTest>
std::span<const WalkEntry> walk_table();
MC_ISA_END
#if MESHCAST_HAS_ISA_SCALAR && MC_ISA_ID != 0
namespace isa_scalar { template <TriangleTest kTest> std::span<const WalkEntry> walk_table(); }
#endif
#if MESHCAST_HAS_ISA_AVX2 && MC_ISA_ID != 1
namespace isa_avx2 { template <TriangleTest kTest> std::span<const WalkEntry> walk_table(); }
#endif
#if MESHCAST_HAS_ISA_AVX512 && MC_ISA_ID != 2
namespace isa_avx512 { template <TriangleTest kTest> std::span<const WalkEntry> walk_table(); }
#endif

// The table of `isa`, a set this build has (MESHCAST_HAS_ISA_*: the
// baseline code that picks one, never a walker's own file), for walkers
// instantiated with `kTest`.
template <TriangleTest kTest>
std::span<const WalkEntry> walk_table_of(WalkerIsa isa) {
#if MESHCAST_HAS_ISA_AVX512
  if (isa == WalkerIsa::Avx512) return isa_avx512::walk_table<kTest>();
#endif
#if MESHCAST_HAS_ISA_AVX2
  if (isa == WalkerIsa::Avx2) return isa_avx2::walk_table<kTest>();
#endif
  (void)isa;
#if MESHCAST_HAS_ISA_SCALAR
  return isa_scalar::walk_table<kTest>();
#else
  return {};  // not reached: the set is one this build has
#endif
}

// The chosen instruction set's walker (walker_isa()) for a tree and
// triangle format, or nullptr where the catalog has none.
WalkFn walker_for(uint32_t tree_format, uint32_t triangle_format);

}  // namespace meshcast
