// The walkers' dispatch table, one a instruction set (cpu/walk_table.cpp is
// compiled for each, cpu/isa.h): every (tree, triangle format) pair of the
// catalog with its walker.
#pragma once
#include <cstdint>
#include <span>

#include "cpu/walk.h"

namespace meshcast {

struct WalkEntry {
  uint32_t tree, triangles;
  WalkFn walk;
};

// This translation unit's set's table (the one cpu/walk.h's inline
// namespace names), and by name the others a multi-set build has (not the
// unit's own again: clang warns when an inline namespace is reopened as a
// plain one).
MC_ISA_BEGIN
std::span<const WalkEntry> walk_table();
MC_ISA_END
#if MESHCAST_HAS_ISA_SCALAR && MC_ISA_ID != 0
namespace isa_scalar { std::span<const WalkEntry> walk_table(); }
#endif
#if MESHCAST_HAS_ISA_AVX2 && MC_ISA_ID != 1
namespace isa_avx2 { std::span<const WalkEntry> walk_table(); }
#endif
#if MESHCAST_HAS_ISA_AVX512 && MC_ISA_ID != 2
namespace isa_avx512 { std::span<const WalkEntry> walk_table(); }
#endif

// The chosen instruction set's walker (walker_isa()) for a tree and
// triangle format, or nullptr where the catalog has none.
WalkFn walker_for(uint32_t tree_format, uint32_t triangle_format);

}  // namespace meshcast
