// The test of a scene's 8-wide top-level node (layout/top_level.h),
// compiled once an instruction set like the walkers (cpu/isa.h): the 8
// slots' boxes at once, the entered ones ordered for the walk. The scene's
// walk (cpu/scene_trace.cpp) calls the chosen set's (enter_top_fn(),
// cpu/trace.cpp).
#pragma once
#include <cstdint>

#include "cpu/isa.h"
#include "layout/top_level.h"

namespace meshcast {

// A world ray as the top level's float boxes read it: the origin relative
// to the top level's anchor, 1 / dir (+-inf for a zero component), the pad
// every box is widened by, and the direction's sign bits (a negative
// component meets a box's hi plane first).
struct TopRay {
  float rel[3], inv[3], pad;
  bool negative[3];
};

// Tests node `n`'s 8 slots against [0, cut]. The entered slots' contents
// and entry distances go to children[] and entries[] farthest first, the
// nearest last (up to 8 of each are written; those past the count hold
// nothing of use); returns how many were entered. An entry may be rounded
// down by a few ulps (it only ever culls, so it culls no more).
using EnterTopFn = int (*)(const TopRay& r, const layout::TopWideNode& n, float cut, float* entries,
                           uint32_t* children);

MC_ISA_BEGIN
int enter_top(const TopRay& r, const layout::TopWideNode& n, float cut, float* entries, uint32_t* children);
MC_ISA_END
#if MESHCAST_HAS_ISA_SCALAR && MC_ISA_ID != 0
namespace isa_scalar { int enter_top(const TopRay&, const layout::TopWideNode&, float, float*, uint32_t*); }
#endif
#if MESHCAST_HAS_ISA_AVX2 && MC_ISA_ID != 1
namespace isa_avx2 { int enter_top(const TopRay&, const layout::TopWideNode&, float, float*, uint32_t*); }
#endif
#if MESHCAST_HAS_ISA_AVX512 && MC_ISA_ID != 2
namespace isa_avx512 { int enter_top(const TopRay&, const layout::TopWideNode&, float, float*, uint32_t*); }
#endif

// The chosen instruction set's enter_top (the walkers' choice).
EnterTopFn enter_top_fn();

}  // namespace meshcast
