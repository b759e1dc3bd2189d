// The walk of a scene's top level (layout/tree/top_level.h), compiled once an
// instruction set like the walkers (cpu/isa.h), its node test inlined. The
// scene's walk (cpu/scene_trace.cpp) calls the chosen set's (walk_top_fn(),
// cpu/isa_choice.cpp) and walks each instance it is handed.
#pragma once
#include <cstdint>

#include "cpu/isa.h"
#include "layout/tree/top_level.h"

namespace meshcast {

// A world ray as the top level's float boxes read it, made once a ray:
// per axis 1 / dir (+-inf for a zero component), where the
// plane the ray meets first sits in a node (its lo row, or its hi row for a
// negative component) and the other, and what each is shifted by: the
// origin relative to the anchor, widened by the pad (the box grows by it on
// both sides). A node's test then reads its rows at fixed offsets and
// branches on no sign.
struct TopRay {
  float inv[3];
  float near_shift[3], far_shift[3];  // rel -+ pad: t = (plane - shift) * inv
  uint32_t near_at[3], far_at[3];     // byte offsets of the rows in a layout::TopWideNode

  // `rel` the origin relative to the top level's anchor (rounded to float),
  // `dir` the direction, `pad` what every box is widened by. A negative
  // component (-0 too, whose inverse is -inf) meets the hi plane first.
  // (A constructor, not a function returning one: gcc built a returned
  // copy from narrower stores than it read, a stall a ray. Defined out of
  // line, in a file compiled once: an inline one made by a walker file of
  // one instruction set could be the copy the linker keeps.)
  TopRay(const float rel[3], const float dir[3], float pad);  // cpu/scene_trace.cpp
};

// The top level's walk for one ray: every instance whose box the ray
// enters before the cut (boxes widened by the pad TopRay was made with,
// the cut by MC_TOP_BOX_SLACK of itself), nearest entry first, whose mask
// shares a bit with `mask`, goes to visit(context, its index in
// top.placed, the cut), which returns the cut from then on (a nearer hit's
// t, or the same), or a negative number to end the walk. A node's 8 slots
// are tested at once (8 lanes), the entered ones ordered by the walkers'
// order_hits; one entered slot is walked next, without the stack.
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
