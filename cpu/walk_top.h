// The walk of a scene's top level (layout/top_level.h), compiled once an
// instruction set like the walkers (cpu/isa.h), its node test inlined. The
// scene's walk (cpu/scene_trace.cpp) calls the chosen set's (walk_top_fn(),
// cpu/trace.cpp) and walks each instance it is handed.
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

// The top level's walk for one ray: every instance whose box the ray
// enters before the cut (boxes widened by r.pad, the cut by MC_TOP_BOX_SLACK
// of itself), nearest entry first, whose mask shares a bit with `mask`,
// goes to visit(context, its index in top.placed, the cut), which returns
// the cut from then on (a nearer hit's t, or the same), or a negative
// number to end the walk. A node's 8 slots are tested at once (8 lanes),
// the entered ones ordered by the walkers' order_hits, one without a sort.
using VisitInstanceFn = float (*)(void* context, uint32_t placed, float cut);
using WalkTopFn = void (*)(const layout::TopLevel& top, const TopRay& r, float tmax, uint8_t mask,
                           VisitInstanceFn visit, void* context);

MC_ISA_BEGIN
void walk_top(const layout::TopLevel& top, const TopRay& r, float tmax, uint8_t mask, VisitInstanceFn visit,
              void* context);
MC_ISA_END
#if MESHCAST_HAS_ISA_SCALAR && MC_ISA_ID != 0
namespace isa_scalar { void walk_top(const layout::TopLevel&, const TopRay&, float, uint8_t, VisitInstanceFn, void*); }
#endif
#if MESHCAST_HAS_ISA_AVX2 && MC_ISA_ID != 1
namespace isa_avx2 { void walk_top(const layout::TopLevel&, const TopRay&, float, uint8_t, VisitInstanceFn, void*); }
#endif
#if MESHCAST_HAS_ISA_AVX512 && MC_ISA_ID != 2
namespace isa_avx512 { void walk_top(const layout::TopLevel&, const TopRay&, float, uint8_t, VisitInstanceFn, void*); }
#endif

// The chosen instruction set's walk_top (the walkers' choice).
WalkTopFn walk_top_fn();

}  // namespace meshcast
