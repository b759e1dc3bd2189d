// The tree walk of a point query (cpu/closest_points.cpp) on an
// OctTreeCompressed blob, compiled once an instruction set like the ray
// walkers (cpu/isa.h): a node's 8 child boxes measured at once (8 lanes),
// a cluster leaf's triangle boxes 8 at once from its vertices in registers.
// The walk keeps no answer of its own: it hands each leaf's triangles near
// enough to its caller, who works out their nearest points (in double) and
// narrows the cut.
//
// Distances here are squared and in float, from the point rounded to float
// to boxes whose bounds are floats (a node's decode is exact, a leaf's
// corners are its stored ones): each difference, square and sum rounds by
// 2^-24 of itself, so a computed distance is at most 2^-21 of itself (and
// 2^-140 for what underflow loses) above the true one. The caller's cut
// carries that slack (cut_above), so a box is dropped only where it is
// truly farther than the caller's limit.
#pragma once
#include <cstdint>

#include "cpu/isa.h"
#include "cpu/point_triangle.h"
#include "meshcast/blob.h"
#include "layout/formats.h"

namespace meshcast {

// A leaf's triangles whose corner boxes are within the cut: their numbers
// in the leaf (decode order, layout::slot_of's lane), their boxes' squared
// distances and their corners as stored, in the order met; and `order`,
// nearest box first: (the distance's bits << 32) | the entry (a distance
// is never negative, so its bits order as it does).
struct NearTriangles {
  uint32_t n = 0;
  uint32_t index[MC_OCT_MAX_COUNT];
  float box_d2[MC_OCT_MAX_COUNT];
  float corners[MC_OCT_MAX_COUNT][3][3];
  uint64_t order[MC_OCT_MAX_COUNT];
  uint32_t entry(uint32_t j) const { return uint32_t(order[j]); }
};

// Hands a leaf's near triangles (its offset in the tree, as oct_offset
// gives it) to the caller, who tests them in order while their box is
// within `cut` and returns the cut from then on (the same or less).
using VisitLeafFn = float (*)(void* context, uint32_t leaf_offset, const NearTriangles& near, float cut);

// Walks a validated OctTreeCompressed blob for `point` (its frame, float),
// dropping every box whose squared distance exceeds `cut`: nearest child
// first, depth first, each popped box measured against the cut of then.
using WalkPointsFn = void (*)(const uint8_t* blob, const float point[3], float cut, VisitLeafFn visit, void* context);

// The squared distance a float walk may compute for a box no farther than
// sqrt(limit2) + widen from the point (widen: how far the float point may
// lie from the true one, 0 where it is the true one): limit2 grown by the
// walk's rounding and rounded up to float; +inf for no limit.
float cut_above(double limit2, double widen);

// The nearest points of n triangles (corners in double) to p, into
// out[0, n): each as nearest_on_triangle (cpu/point_triangle.h) gives it,
// bit for bit, 8 triangles side by side (cpu/point_triangle_lanes.cpp).
using NearestOnTrianglesFn = void (*)(const double p[3], const double (*corners)[3][3], uint32_t n,
                                      PointOnTriangle* out);

#define MC_DECLARE_POINT_WALK                                                                   \
  void walk_points(const uint8_t* blob, const float point[3], float cut, VisitLeafFn visit, void* context); \
  void nearest_on_triangles(const double p[3], const double (*corners)[3][3], uint32_t n, PointOnTriangle* out);
MC_ISA_BEGIN
MC_DECLARE_POINT_WALK
MC_ISA_END
#if MESHCAST_HAS_ISA_SCALAR && MC_ISA_ID != 0
namespace isa_scalar { MC_DECLARE_POINT_WALK }
#endif
#if MESHCAST_HAS_ISA_AVX2 && MC_ISA_ID != 1
namespace isa_avx2 { MC_DECLARE_POINT_WALK }
#endif
#if MESHCAST_HAS_ISA_AVX512 && MC_ISA_ID != 2
namespace isa_avx512 { MC_DECLARE_POINT_WALK }
#endif
#undef MC_DECLARE_POINT_WALK

// The chosen instruction set's (cpu/isa_choice.cpp).
WalkPointsFn walk_points_fn();
NearestOnTrianglesFn nearest_on_triangles_fn();
// A given set's (nullptr where this build or processor lacks it): the
// tests hold each set's to nearest_on_triangle's bits.
NearestOnTrianglesFn nearest_on_triangles_of(WalkerIsa isa);

}  // namespace meshcast
