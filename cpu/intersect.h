// Rays, hits, and the two tests every walker is built from:
//  - a conservative ray/box test (Ize 2013, "Robust BVH Ray Traversal"): the
//    far distance is widened by 1 + 2*gamma(3) so rounding in the slab
//    arithmetic never culls a box the exact ray touches;
//  - the watertight ray/triangle test (Woop, Benthin, Wald 2013): the ray is
//    sheared so it runs along +z, edge functions are evaluated in 2D with the
//    same operands for both triangles of a shared edge, and an edge function
//    that rounds to exactly zero is recomputed in double, so a ray through a
//    shared edge or vertex always hits at least one of its triangles. So is
//    a lane whose determinant or T overflowed or fell below kSettleTiny
//    (coordinates near the +-2^100 limit, tiny meshes, tiny or huge
//    directions): float cannot settle it, double always can. A hit's t,
//    u and v are then worked out in double from the stored corners
//    (hit_in_double): the float t only picks the lanes near the segment.
// Both are two-sided and accept t in [t_min, t_max] (the float t they
// report, both ends included); a hit whose t exceeds the largest float is
// a miss (the hit record carries t as a float).
#pragma once
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "cpu/counters.h"
#include "cpu/simd.h"
#include "cpu/which_triangle_test.h"
#include "layout/formats.h"
#include "layout/ray_record.h"
#include "meshcast/ray.h"

namespace meshcast {

static_assert(kNoHit == MC_NO_HIT && uint32_t(HitOutputs::Uv) == MC_HIT_UV &&
                  uint32_t(HitOutputs::Point) == MC_HIT_POINT,
              "the public names are layout/formats.h's values, which the shaders read");

// What every instruction set shares (cpu/isa.h): compiled once, outside
// the per-set namespace.
// Closest accepted lane of four triangles, corners v[corner][axis].
struct LaneHit {
  int lane = -1;
  float t = 0, u = 0, v = 0;
};

// Every accepted lane of one test (Query::All), with its t and, when asked
// for, u and v.
struct LaneSet {
  int mask = 0;
  float t[8], u[8], v[8];
  void add(int lane, const LaneHit& h) { mask |= 1 << lane, t[lane] = h.t, u[lane] = h.u, v[lane] = h.v; }
  // Only the lanes of `mask` are ever read: the arrays are left unset.
};

// The determinant's sign a culling query keeps, times the determinant, is
// never negative: +1 keeps det > 0 (the front faces: corners counter-
// clockwise seen from the origin), -1 det < 0, 0 both (no culling).
inline float cull_sign(uint32_t flags) {
  return (flags & MC_CULL_BACK) ? 1.0f : (flags & MC_CULL_FRONT) ? -1.0f : 0.0f;
}

// Whether a lane float could not settle lies inside the triangle, on a
// face the query keeps (`cull`: cull_sign() of the query): its edge
// functions in double from the corners in ray space (sheared x, y), where
// every product of two floats is exact.
bool watertight_inside_double(float ax, float ay, float bx, float by, float cx, float cy, float cull);

// A hit's t, u and v worked out in double from the stored corners a, b, c
// and the ray's origin o and walked direction d (all in one axis order):
// t to within an ulp of the exact distance to the stored triangle's plane
// (correctly rounded but where the origin lies far closer to the plane
// than to the corner a), an origin on the plane to double's rounding at
// t = 0. Whether the ray meets the triangle is the watertight test's call;
// this takes the hit when tmin <= t <= min(limit, FLT_MAX) on the float t
// reported. u and v only when `uv`, else 0.
bool hit_in_double(const float o[3], const float d[3], const float a[3], const float b[3], const float c[3],
                   float tmin, float limit, bool uv, LaneHit* out);

MC_ISA_BEGIN

// 1 + 2 * gamma(3), gamma(n) = n u / (1 - n u), u = 2^-24 (Ize 2013).
constexpr float kFarScale = 1.0f + 2.0f * (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f);

// Per-ray constants, computed once.
struct RayPre {
  float org[3], dir[3], inv[3];
  // Box test: the near plane of each axis is the min plane for a direction
  // with a clear sign bit and the max plane otherwise (-0 counts as negative,
  // matching inv = -inf).
  int near_is_max[3];
  // Watertight test: kz = the dominant axis, kx/ky the others (swapped to
  // keep the winding), shear constants S.
  int axis[3];  // {kx, ky, kz}: loaders fetch corners in this order
  float sx, sy, sz;
  uint32_t outputs;  // MC_HIT_* asked for: the triangle tests skip u, v unless asked
  float cull;        // cull_sign() of the query's MC_CULL_* bits
  // The nearest t a triangle test accepts. The box tests keep entering at
  // 0: a box the ray enters before tmin may still hold hits past it, and
  // the conservative test needs no second bound to stay conservative.
  float tmin;

  explicit RayPre(const Ray& r, uint32_t hit_outputs = 0)
      : outputs(hit_outputs), cull(cull_sign(hit_outputs)), tmin(r.tmin) {
    for (int a = 0; a < 3; ++a) {
      org[a] = r.org[a];
      dir[a] = walked_direction(r.dir[a]);
      near_is_max[a] = std::signbit(dir[a]) ? 1 : 0;
    }
    const layout::RayConstants c = layout::ray_constants(dir);  // +-inf in inv for a zero component: see box_test
    for (int a = 0; a < 3; ++a) inv[a] = c.inv[a], axis[a] = c.axis[a];
    sx = c.sx, sy = c.sy, sz = c.sz;
  }
};

// Slab distances of one axis; a zero direction makes inv infinite, and a slab
// plane through the origin then gives 0 * inf = NaN. The max/min below keep
// their second operand on NaN, and that operand is never NaN, so such a slab
// constrains nothing: the ray lies in the plane, on the closed box.
inline float max_keep(float a, float b) { return a > b ? a : b; }
inline float min_keep(float a, float b) { return a < b ? a : b; }

// The ray's interval [tn, tf] inside the box, before the closest-hit cut.
[[gnu::always_inline]] inline void box_interval(const RayPre& r, const float mn[3], const float mx[3], float* tn, float* tf) {
  *tn = 0.0f, *tf = INFINITY;
  for (int a = 0; a < 3; ++a) {
    float nearp = r.near_is_max[a] ? mx[a] : mn[a];
    float farp = r.near_is_max[a] ? mn[a] : mx[a];
    *tn = max_keep((nearp - r.org[a]) * r.inv[a], *tn);
    *tf = min_keep((farp - r.org[a]) * r.inv[a], *tf);
  }
}

// Whether [tn, tf] is open before the closest hit. The cut-off is widened
// too, so a box whose entry rounds a few ulps past a hit it may still
// improve on is not dropped.
inline bool interval_open(float tn, float tf, float closest) { return tn <= min_keep(tf, closest) * kFarScale; }

// Scalar box test; returns the entry distance, or +inf for a miss.
[[gnu::always_inline]] inline float box_test(const RayPre& r, const float mn[3], const float mx[3], float closest) {
  count_boxes(1);
  float tn, tf;
  box_interval(r, mn, mx, &tn, &tf);
  return interval_open(tn, tf, closest) ? tn : INFINITY;
}

// Four boxes at once; `nearp[a]`/`farp[a]` are the near and far planes of axis a.
[[gnu::always_inline]] inline simd::F4 box_test4(const RayPre& r, const simd::F4 nearp[3], const simd::F4 farp[3], float closest) {
  count_node(4);
  using simd::F4;
  F4 tn = F4::splat(0.0f), tf = F4::splat(INFINITY);
  for (int a = 0; a < 3; ++a) {
    F4 o = F4::splat(r.org[a]), inv = F4::splat(r.inv[a]);
    tn = simd::max((nearp[a] - o) * inv, tn);
    tf = simd::min((farp[a] - o) * inv, tf);
  }
  tf = simd::min(tf, F4::splat(closest)) * F4::splat(kFarScale);
  return simd::select(tn <= tf, tn, F4::splat(INFINITY));
}


// Below this a determinant or T has lost bits to underflow (products of
// coordinates near 1e-20 and smaller): such lanes are settled in double.
// Every ray-space value the double redo forms stays inside double's normal
// range: sheared coordinates are floats within +-2^102, sz within 2^-126..2^126,
// so products lie between 2^-575 and 2^433.
constexpr float kSettleTiny = 0x1p-100f;
// A determinant from this up is settled in double too: Vulkan bounds a float
// division's error only for divisors below 2^126 (see float_settles).
constexpr float kSettleHuge = 0x1p126f;

// Lanes whose float det and T can be trusted: T finite (no overflow, no
// inf - inf), det below 2^126 (Vulkan bounds a float division's error only
// for divisors up to 2^126; a GPU's reciprocal of a larger one may flush to
// 0 and give t = 0), both at least kSettleTiny in magnitude (no underflow).
// A lane inside all three edges that fails this is settled in double, as
// are the lanes with an edge function of exactly 0. The shaders test the
// same (watertight.glsl), so both sides settle the same lanes alike.
template <class F4>
inline auto float_settles(const F4& det, const F4& T) {
  const F4 tiny = F4::splat(kSettleTiny), huge = F4::splat(kSettleHuge), inf = F4::splat(INFINITY);
  const F4 d = simd::abs(det), a = simd::abs(T);
  return (d >= tiny) & (d < huge) & (a >= tiny) & (a < inf);
}

// Every hit's t, u and v are worked out in double (hit_in_double): the
// float t only chooses the lanes to work out. It is off by a few ulps of
// the largest |sz z| of the lane's corners (t is their weighted mean), by
// more on rays that graze the triangle, so a lane whose float t lies just
// past either end may lie inside it exactly: every lane within this
// fraction of that |sz z| of [tmin, closest] is worked out too (thousands
// of ulps; the lanes in it past the ends are rare, and each costs one
// double-precision test).
constexpr float kFloatWindow = 0x1p-10f;

// The lanes of `near` (inside the triangle by the float test, t within the
// window) and of `redo` (float could not settle them: inside tested again
// in double) get their t, u, v in double from their corners `a`, `b`, `c`
// (the ray's axis order; `xy`: the sheared x, y of the three, which redo
// reads); those between tmin and limit() go to take(lane, hit), lowest lane
// first.
template <class F4, class Limit, class Take>
[[gnu::noinline]] void take_in_double(const RayPre& r, int near, int redo, const F4 (&a)[3], const F4 (&b)[3],
                                      const F4 (&c)[3], const F4 (&xy)[6], Limit&& limit, Take&& take) {
  constexpr int kW = F4::kLanes;
  float k[3][3][kW], l[6][kW];
  for (int j = 0; j < 3; ++j) a[j].store(k[0][j]), b[j].store(k[1][j]), c[j].store(k[2][j]);
  if (redo)
    for (int j = 0; j < 6; ++j) xy[j].store(l[j]);
  float o[3], d[3];
  for (int j = 0; j < 3; ++j) o[j] = r.org[r.axis[j]], d[j] = r.dir[r.axis[j]];
  const bool uv = (r.outputs & MC_HIT_UV) != 0;
  for (int m = near | redo; m; m &= m - 1) {
    const int i = __builtin_ctz(m);
    if ((redo >> i & 1) && !watertight_inside_double(l[0][i], l[1][i], l[2][i], l[3][i], l[4][i], l[5][i], r.cull))
      continue;
    const float pa[3] = {k[0][0][i], k[0][1][i], k[0][2][i]}, pb[3] = {k[1][0][i], k[1][1][i], k[1][2][i]},
                pc[3] = {k[2][0][i], k[2][1][i], k[2][2][i]};
    LaneHit h;
    if (hit_in_double(o, d, pa, pb, pc, r.tmin, limit(), uv, &h)) take(i, h);
  }
}

// The lanes a float test settled inside the triangle, on a face the query
// keeps, whose t lies within the window of [tmin, closest] (zs: the
// corners' z relative to the origin, scaled by sz).
template <class F4, class M4>
[[gnu::always_inline]] inline M4 near_lanes(const RayPre& r, M4 settled_inside, const F4& det, const F4& t,
                                            const F4 (&zs)[3], float closest) {
  const F4 slack = simd::max(simd::max(simd::abs(zs[0]), simd::abs(zs[1])), simd::abs(zs[2])) * F4::splat(kFloatWindow);
  return settled_inside & (det * F4::splat(r.cull) >= F4::splat(0.0f)) & (t + slack >= F4::splat(r.tmin)) &
         (t - slack <= F4::splat(std::min(closest, FLT_MAX)));
}

// The plain Möller–Trumbore test (1997), kept only so `meshcast bench
// robustness` can show what the watertight test costs: not watertight (a
// ray through a shared edge or vertex can fall between the triangles), no
// double-precision fallback, no epsilon (a triangle with det = 0 is missed,
// as by the watertight test). Corners in the ray's axis order, as below;
// the permutation flips both crosses' signs together, so u, v, t do not
// change. Only in walkers instantiated with TriangleTest::MollerTrumbore
// (cpu/which_triangle_test.h).
template <class F4, class M4>
inline LaneHit moller_trumbore_test(const RayPre& r, const F4 v[3][3], M4 valid, float closest, LaneSet* every) {
  constexpr int kW = F4::kLanes;
  F4 d[3], o[3], e1[3], e2[3], s[3], p[3], q[3];
  for (int j = 0; j < 3; ++j) {
    d[j] = F4::splat(r.dir[r.axis[j]]), o[j] = F4::splat(r.org[r.axis[j]]);
    e1[j] = v[1][j] - v[0][j], e2[j] = v[2][j] - v[0][j], s[j] = o[j] - v[0][j];
  }
  auto cross = [](const F4 a[3], const F4 b[3], F4 out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1], out[1] = a[2] * b[0] - a[0] * b[2], out[2] = a[0] * b[1] - a[1] * b[0];
  };
  auto dot = [](const F4 a[3], const F4 b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  cross(d, e2, p);
  cross(s, e1, q);
  const F4 zero = F4::splat(0.0f), one = F4::splat(1.0f);
  F4 det = dot(e1, p);
  F4 inv = one / det;
  F4 u = dot(s, p) * inv, w = dot(d, q) * inv, t = dot(e2, q) * inv;
  // Culling: this det is the triple product in the ray's axis order, whose
  // sign an odd permutation (kx, ky swapped: dir[kz] < 0) flips.
  const float cull = r.dir[r.axis[2]] < 0 ? -r.cull : r.cull;
  M4 accept = valid & (det != zero) & (det * F4::splat(cull) >= zero) & (u >= zero) & (w >= zero) & (u + w <= one) &
              (t >= zero) & (t >= F4::splat(r.tmin)) & (t <= F4::splat(closest));
  LaneHit best;
  float tl[kW], ul[kW], wl[kW];
  t.store(tl), u.store(ul), w.store(wl);
  for (int m = simd::bits(accept); m; m &= m - 1) {
    int i = __builtin_ctz(m);
    if (every) every->add(i, {i, tl[i], (r.outputs & MC_HIT_UV) ? ul[i] : 0.0f, (r.outputs & MC_HIT_UV) ? wl[i] : 0.0f});
    if (best.lane < 0 || tl[i] < best.t) best = {i, tl[i], ul[i], wl[i]};
  }
  return best;
}


// Corners come in the ray's axis order, v[corner][j] = axis r.axis[j], so the
// test indexes registers with constants. One source for every width: F4 (SSE,
// 4 triangles) and F8 (AVX2, 8 triangles).
//
// Returns the closest accepted lane; with `every` (Query::All), every
// accepted lane goes there too, and the double redo is limited by `closest`
// alone. `kTest`: the walker's test (cpu/which_triangle_test.h), the
// watertight one below unless it names the plain one.
template <TriangleTest kTest, class F4, class M4>
[[gnu::always_inline]] inline LaneHit triangle_test(const RayPre& r, const F4 v[3][3], M4 valid, float closest,
                                                    LaneSet* every = nullptr) {
  if constexpr (kCountTests) count_triangles(uint64_t(__builtin_popcount(unsigned(simd::bits(valid)))));
  if constexpr (kTest == TriangleTest::MollerTrumbore) return moller_trumbore_test(r, v, valid, closest, every);
  const F4 ox = F4::splat(r.org[r.axis[0]]), oy = F4::splat(r.org[r.axis[1]]), oz = F4::splat(r.org[r.axis[2]]);
  const F4 sx = F4::splat(r.sx), sy = F4::splat(r.sy), sz = F4::splat(r.sz);
  F4 ax = v[0][0] - ox, ay = v[0][1] - oy, az = v[0][2] - oz;
  F4 bx = v[1][0] - ox, by = v[1][1] - oy, bz = v[1][2] - oz;
  F4 cx = v[2][0] - ox, cy = v[2][1] - oy, cz = v[2][2] - oz;
  ax = ax - sx * az, ay = ay - sy * az;
  bx = bx - sx * bz, by = by - sy * bz;
  cx = cx - sx * cz, cy = cy - sy * cz;
  F4 U = cx * by - cy * bx;
  F4 V = ax * cy - ay * cx;
  F4 W = bx * ay - by * ax;
  const F4 zero = F4::splat(0.0f);
  M4 neg = (U < zero) | (V < zero) | (W < zero);
  M4 pos = (U > zero) | (V > zero) | (W > zero);
  M4 inside = simd::andnot(neg & pos, valid);
  M4 edge_zero = (U == zero) | (V == zero) | (W == zero);
  F4 det = U + V + W;
  const F4 zs[3] = {sz * az, sz * bz, sz * cz};
  F4 T = U * zs[0] + V * zs[1] + W * zs[2];
  F4 Ts = simd::xor_sign(T, det), dets = simd::abs(det);
  F4 t = Ts / dets;
  // Lanes float cannot settle go to double; the others inside, near the
  // segment, get their t there too.
  M4 redo = valid & (edge_zero | simd::andnot(float_settles(det, T), inside));
  M4 near = near_lanes(r, simd::andnot(redo, inside), det, t, zs, closest);
  LaneHit best;
  if (const int n = simd::bits(near), d = simd::bits(redo); n | d) [[unlikely]]
    take_in_double(r, n, d, v[0], v[1], v[2], {ax, ay, bx, by, cx, cy},
                   [&] { return best.lane >= 0 && !every ? best.t : closest; },
                   [&](int i, const LaneHit& h) {
                     if (every) every->add(i, h);
                     if (best.lane < 0 || h.t < best.t) best = h, best.lane = i;
                   });
  return best;
}

// Seed 003's pair test: 4 lanes of triangle pairs, corners v[0..3] = A, B,
// C, D (ray's axis order); the first triangle is (A, B, C), the second
// (B, A, D). The 4 corners are moved into ray space once (8 where two
// triangles would take 12... 6 moves for 3), and the shared edge's function
// once: the second's W is minus the first's, exactly the value a separate
// test would compute for (B, A), so the pair stays watertight along it.
// `second` lanes hold a pair; the others test their first triangle alone.
struct PairHit {
  int lane = -1;
  bool second = false;
  float t = 0, u = 0, v = 0;
};

// With `every` (Query::All): every accepted lane of the first triangles in
// every[0], of the second in every[1].
template <class F4, class M4>
inline PairHit pair_test(const RayPre& r, const F4 v[4][3], M4 used, M4 second, float closest,
                         LaneSet* every = nullptr) {
  if constexpr (kCountTests)
    count_triangles(uint64_t(__builtin_popcount(unsigned(simd::bits(used))) + __builtin_popcount(unsigned(simd::bits(second)))));
  const F4 ox = F4::splat(r.org[r.axis[0]]), oy = F4::splat(r.org[r.axis[1]]), oz = F4::splat(r.org[r.axis[2]]);
  const F4 sx = F4::splat(r.sx), sy = F4::splat(r.sy), sz = F4::splat(r.sz);
  F4 x[4], y[4], z[4], zs[4];  // z: relative to the origin; zs: scaled by sz
  for (int k = 0; k < 4; ++k) {
    z[k] = v[k][2] - oz;
    x[k] = (v[k][0] - ox) - sx * z[k], y[k] = (v[k][1] - oy) - sy * z[k];
    zs[k] = sz * z[k];
  }
  // Edge functions as triangle_test writes them: E(P, Q) = Q.x P.y - Q.y P.x.
  auto edge = [&](int p, int q) { return x[q] * y[p] - y[q] * x[p]; };
  const F4 zero = F4::splat(0.0f);
  F4 E[2][3] = {{edge(1, 2), edge(2, 0), edge(0, 1)}, {edge(0, 3), edge(3, 1), zero - edge(0, 1)}};
  const int corner[2][3] = {{0, 1, 2}, {1, 0, 3}};
  PairHit best;
  for (int tri = 0; tri < 2; ++tri) {
    M4 valid = tri == 0 ? used : second;
    const F4 &U = E[tri][0], &V = E[tri][1], &W = E[tri][2];
    M4 neg = (U < zero) | (V < zero) | (W < zero);
    M4 pos = (U > zero) | (V > zero) | (W > zero);
    M4 inside = simd::andnot(neg & pos, valid);
    M4 edge_zero = (U == zero) | (V == zero) | (W == zero);
    F4 det = U + V + W;
    F4 T = U * zs[corner[tri][0]] + V * zs[corner[tri][1]] + W * zs[corner[tri][2]];
    F4 Ts = simd::xor_sign(T, det), dets = simd::abs(det);
    F4 t = Ts / dets;
    M4 redo = valid & (edge_zero | simd::andnot(float_settles(det, T), inside));
    const int* k = corner[tri];
    const F4 zk[3] = {zs[k[0]], zs[k[1]], zs[k[2]]};
    M4 near = near_lanes(r, simd::andnot(redo, inside), det, t, zk, closest);
    if (const int n = simd::bits(near), d = simd::bits(redo); n | d)
      take_in_double(r, n, d, v[k[0]], v[k[1]], v[k[2]], {x[k[0]], y[k[0]], x[k[1]], y[k[1]], x[k[2]], y[k[2]]},
                     [&] { return best.lane >= 0 && !every ? best.t : closest; },
                     [&](int i, const LaneHit& h) {
                       if (every) every[tri].add(i, h);
                       if (best.lane < 0 || h.t < best.t) best = {i, tri == 1, h.t, h.u, h.v};
                     });
  }
  return best;
}

MC_ISA_END
}  // namespace meshcast
