// Four-lane float and int types for the walkers. With AVX2 they are SSE/AVX
// registers; with MESHCAST_SCALAR they are plain arrays, so one walker source
// serves both builds and both are tested the same way.
//
// min/max keep the *second* operand when either is NaN (the SSE rule), and the
// scalar path copies that rule: the box test relies on it to drop the NaN of
// 0 * inf from a slab the ray lies in (see cpu/intersect.h).
#pragma once
#include <bit>
#include <cstdint>
#include <cstring>

#include "cpu/isa.h"
#include "layout/triangles/block.h"
#include "layout/tree/half.h"

#if MC_ISA_SIMD
#include <immintrin.h>
#endif

namespace meshcast {
MC_ISA_BEGIN
namespace simd {

#if MC_ISA_SIMD

struct F4 {
  static constexpr int kLanes = 4;
  __m128 v;
  static F4 splat(float f) { return {_mm_set1_ps(f)}; }
  static F4 load(const void* p) { return {_mm_loadu_ps(static_cast<const float*>(p))}; }
  void store(float* p) const { _mm_storeu_ps(p, v); }
};
struct I4 {
  __m128i v;
  static I4 load(const void* p) { return {_mm_loadu_si128(static_cast<const __m128i*>(p))}; }
  void store(uint32_t* p) const { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
};
struct M4 { __m128 v; };  // lane mask

inline F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
inline F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
inline F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
inline F4 operator/(F4 a, F4 b) { return {_mm_div_ps(a.v, b.v)}; }
inline F4 min(F4 a, F4 b) { return {_mm_min_ps(a.v, b.v)}; }
inline F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
inline F4 fma(F4 a, F4 b, F4 c) { return {_mm_fmadd_ps(a.v, b.v, c.v)}; }
inline F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }
inline F4 xor_sign(F4 a, F4 sign_of) {  // a with its sign flipped where sign_of is negative
  return {_mm_xor_ps(a.v, _mm_and_ps(sign_of.v, _mm_set1_ps(-0.0f)))};
}
inline M4 operator<(F4 a, F4 b) { return {_mm_cmplt_ps(a.v, b.v)}; }
inline M4 operator<=(F4 a, F4 b) { return {_mm_cmple_ps(a.v, b.v)}; }
inline M4 operator>(F4 a, F4 b) { return {_mm_cmpgt_ps(a.v, b.v)}; }
inline M4 operator>=(F4 a, F4 b) { return {_mm_cmpge_ps(a.v, b.v)}; }
inline M4 operator==(F4 a, F4 b) { return {_mm_cmpeq_ps(a.v, b.v)}; }
inline M4 operator!=(F4 a, F4 b) { return {_mm_cmpneq_ps(a.v, b.v)}; }
inline M4 operator&(M4 a, M4 b) { return {_mm_and_ps(a.v, b.v)}; }
inline M4 operator|(M4 a, M4 b) { return {_mm_or_ps(a.v, b.v)}; }
inline M4 andnot(M4 a, M4 b) { return {_mm_andnot_ps(a.v, b.v)}; }  // b & ~a
inline int bits(M4 m) { return _mm_movemask_ps(m.v); }
inline M4 lanes_of(uint32_t bits) {  // lane i set when bit i is
  const __m128i b = _mm_setr_epi32(1, 2, 4, 8);
  return {_mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(int(bits)), b), b))};
}
inline M4 lanes_below(uint32_t n) {  // lanes 0..n-1 set
  return {_mm_castsi128_ps(_mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(int(n))))};
}
inline F4 select(M4 m, F4 a, F4 b) { return {_mm_blendv_ps(b.v, a.v, m.v)}; }  // m ? a : b
inline M4 nonzero(I4 a) { return {_mm_castsi128_ps(_mm_xor_si128(_mm_cmpeq_epi32(a.v, _mm_setzero_si128()), _mm_set1_epi32(-1)))}; }
inline F4 from_u16(const uint8_t* p) {  // 4 uint16 -> 4 floats
  int64_t x;
  std::memcpy(&x, p, 8);
  return {_mm_cvtepi32_ps(_mm_cvtepu16_epi32(_mm_cvtsi64_si128(x)))};
}
inline F4 from_half(const uint8_t* p) {  // 4 half floats -> 4 floats (F16C)
  int64_t x;
  std::memcpy(&x, p, 8);
  return {_mm_cvtph_ps(_mm_cvtsi64_si128(x))};
}
// Four BitPack words (seed 000 §3.4) at base + 8 * index[i], decoded with the
// same fma as layout::bitpack_decode; out[j] is axis `axis[j]`.
inline I4 from_u8_index(const uint8_t* p) {  // 4 bytes -> 4 ints
  int32_t x;
  std::memcpy(&x, p, 4);
  return {_mm_cvtepu8_epi32(_mm_cvtsi32_si128(x))};
}
inline void bitpack_gather(const uint8_t* base, I4 index, const float offset[3], const float scale[3],
                           const int axis[3], F4 out[3]) {
  __m256i w = _mm256_i32gather_epi64(reinterpret_cast<const long long*>(base), index.v, 8);
  const __m256i mask = _mm256_set1_epi64x(MC_BITPACK_MAX);
  const __m256i even = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6);
  for (int j = 0; j < 3; ++j) {
    int a = axis[j];
    __m256i q = _mm256_and_si256(_mm256_srl_epi64(w, _mm_cvtsi32_si128(int(MC_BITPACK_BITS) * a)), mask);
    __m128i q32 = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(q, even));
    out[j] = {_mm_fmadd_ps(_mm_cvtepi32_ps(q32), _mm_set1_ps(scale[a]), _mm_set1_ps(offset[a]))};
  }
}
// Gather: base + 4 * idx[i] (floats).
inline F4 gather(const float* base, I4 idx) { return {_mm_i32gather_ps(base, idx.v, 4)}; }
inline I4 iconst(int a, int b, int c, int d) { return {_mm_setr_epi32(a, b, c, d)}; }
inline I4 operator+(I4 a, int b) { return {_mm_add_epi32(a.v, _mm_set1_epi32(b))}; }
inline I4 operator+(I4 a, I4 b) { return {_mm_add_epi32(a.v, b.v)}; }
inline I4 from_u16_index(const uint8_t* p) {  // 4 uint16 -> 4 ints
  int64_t x;
  std::memcpy(&x, p, 8);
  return {_mm_cvtepu16_epi32(_mm_cvtsi64_si128(x))};
}


// Eight lanes (AVX2), for the 8-wide triangle formats (Float3SOA8).
struct F8 {
  static constexpr int kLanes = 8;
  __m256 v;
  static F8 splat(float f) { return {_mm256_set1_ps(f)}; }
  static F8 load(const void* p) { return {_mm256_loadu_ps(static_cast<const float*>(p))}; }
  void store(float* p) const { _mm256_storeu_ps(p, v); }
};
struct M8 { __m256 v; };
inline F8 operator+(F8 a, F8 b) { return {_mm256_add_ps(a.v, b.v)}; }
inline F8 operator-(F8 a, F8 b) { return {_mm256_sub_ps(a.v, b.v)}; }
inline F8 operator*(F8 a, F8 b) { return {_mm256_mul_ps(a.v, b.v)}; }
inline F8 operator/(F8 a, F8 b) { return {_mm256_div_ps(a.v, b.v)}; }
inline F8 abs(F8 a) { return {_mm256_andnot_ps(_mm256_set1_ps(-0.0f), a.v)}; }
inline F8 xor_sign(F8 a, F8 s) { return {_mm256_xor_ps(a.v, _mm256_and_ps(s.v, _mm256_set1_ps(-0.0f)))}; }
inline M8 operator<(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LT_OQ)}; }
inline M8 operator<=(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_LE_OQ)}; }
inline M8 operator>(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GT_OQ)}; }
inline M8 operator>=(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_GE_OQ)}; }
inline M8 operator==(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_EQ_OQ)}; }
inline M8 operator!=(F8 a, F8 b) { return {_mm256_cmp_ps(a.v, b.v, _CMP_NEQ_UQ)}; }
inline M8 operator&(M8 a, M8 b) { return {_mm256_and_ps(a.v, b.v)}; }
inline M8 operator|(M8 a, M8 b) { return {_mm256_or_ps(a.v, b.v)}; }
inline M8 andnot(M8 a, M8 b) { return {_mm256_andnot_ps(a.v, b.v)}; }
inline int bits(M8 m) { return _mm256_movemask_ps(m.v); }
inline M8 lanes_below8(uint32_t n) {
  return {_mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(int(n)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)))};
}
inline F8 min(F8 a, F8 b) { return {_mm256_min_ps(a.v, b.v)}; }  // NaN -> b, as F4's
inline F8 max(F8 a, F8 b) { return {_mm256_max_ps(a.v, b.v)}; }
inline F8 fma(F8 a, F8 b, F8 c) { return {_mm256_fmadd_ps(a.v, b.v, c.v)}; }
inline F8 select(M8 m, F8 a, F8 b) { return {_mm256_blendv_ps(b.v, a.v, m.v)}; }  // m ? a : b
inline F8 from_u8x8(const uint8_t* p) {  // 8 bytes -> 8 floats
  int64_t x;
  std::memcpy(&x, p, 8);
  return {_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_cvtsi64_si128(x)))};
}
// A cluster's vertex coordinates of one axis (layout/triangles/cluster.h), lanes 0-7
// and 8-15: the row's `count` offsets (uint16, or uint32 when wide) plus the
// origin's code, decoded with BitPack's fma (lanes past count: the origin);
// and a row of 8 corners picked from them by 4-bit vertex numbers (nibble i:
// lane i), by permutes.
struct V16 { F8 lo, hi; };
inline V16 cluster_decode(const uint8_t* row, uint32_t count, bool wide, uint32_t origin, float scale, float offset) {
  // Only the row's own words are read (masked loads never touch the others).
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const int* p = reinterpret_cast<const int*>(row);
  __m256i lo, hi;
  if (wide) {
    lo = _mm256_maskload_epi32(p, _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count)), lane));
    hi = _mm256_maskload_epi32(p + 8, _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count) - 8), lane));
  } else {
    const __m256i w = _mm256_maskload_epi32(p, _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count + 1) / 2), lane));
    lo = _mm256_cvtepu16_epi32(_mm256_castsi256_si128(w));
    hi = _mm256_cvtepu16_epi32(_mm256_extracti128_si256(w, 1));
  }
  const __m256i o = _mm256_set1_epi32(int(origin));
  const __m256 s = _mm256_set1_ps(scale), b = _mm256_set1_ps(offset);
  return {{_mm256_fmadd_ps(_mm256_cvtepi32_ps(_mm256_add_epi32(lo, o)), s, b)},
          {_mm256_fmadd_ps(_mm256_cvtepi32_ps(_mm256_add_epi32(hi, o)), s, b)}};
}
// ClusterFloat3SOA8's row: the `count` floats themselves (lanes past it 0).
inline V16 cluster_load(const uint8_t* row, uint32_t count) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const float* p = reinterpret_cast<const float*>(row);
  return {{_mm256_maskload_ps(p, _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count)), lane))},
          {_mm256_maskload_ps(p + 8, _mm256_cmpgt_epi32(_mm256_set1_epi32(int(count) - 8), lane))}};
}
inline F8 cluster_pick(const V16& v, uint32_t nibbles) {
  const __m256i idx = _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(int(nibbles)), _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                                       _mm256_set1_epi32(15));
#if defined(__AVX512VL__)
  return {_mm256_permutex2var_ps(v.lo.v, idx, v.hi.v)};  // one permute over both halves
#else
  const __m256 from_lo = _mm256_permutevar8x32_ps(v.lo.v, idx), from_hi = _mm256_permutevar8x32_ps(v.hi.v, idx);
  return {_mm256_blendv_ps(from_lo, from_hi, _mm256_castsi256_ps(_mm256_cmpgt_epi32(idx, _mm256_set1_epi32(7))))};
#endif
}
inline int nonzero_bits8(const uint8_t* p) {  // bit i: the i-th of 8 uint32 at p is not 0
  const __m256i w = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
  return _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(w, _mm256_setzero_si256()))) ^ 0xFF;
}
// An 8-wide node's hit children in the order a walk takes them, from its
// entry distances (>= 0 in the hit lanes) and `bits`: entries and child
// properties (8 uint32 at `properties`) written farthest first, all 8 lanes
// (the lanes past the hits hold nothing of use); returns the properties of
// the nearest hit child, the last of the popcount(bits) written. The order
// is by a key of the entry's bits with its 3 low bits replaced by the lane,
// so the written entries are rounded down by up to 7 ulps (a stack entry
// is only ever compared to cull: rounded down, it culls no more; -0 reads
// as +0), sorted in
// registers by Batcher's network of 19 comparators in 6 layers; the nearest
// comes from a separate 3-step reduction, off the sort's longer chain.
[[gnu::always_inline]] inline uint32_t order_hits(F8 entry, int bits, const uint8_t* properties, float* entries, uint32_t* children) {
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  // Lane i of the result set where bit i of `b` is.
  auto lanes_of8 = [](int b) {
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(b), bit), bit);
  };
  const __m256i hit = lanes_of8(bits);
  const __m256i key = _mm256_or_si256(_mm256_and_si256(_mm256_castps_si256(entry.v), _mm256_set1_epi32(0x7FFFFFF8)), lane);
  const __m256i props = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(properties));
  // The nearest: the least key over the hit lanes (others INT_MAX).
  __m256i m = _mm256_blendv_epi8(_mm256_set1_epi32(0x7FFFFFFF), key, hit);
  m = _mm256_min_epi32(m, _mm256_shuffle_epi32(m, 0x4E));
  m = _mm256_min_epi32(m, _mm256_shuffle_epi32(m, 0xB1));
  m = _mm256_min_epi32(m, _mm256_permute2x128_si256(m, m, 1));
  const uint32_t nearest = uint32_t(_mm256_cvtsi256_si32(m)) & 7;
  // All of them, farthest first (misses as -1, last).
  __m256i v = _mm256_blendv_epi8(_mm256_set1_epi32(-1), key, hit);
  auto layer = [&v, &lanes_of8](__m256i partner, int take_max) {
    const __m256i p = _mm256_permutevar8x32_epi32(v, partner);
    const __m256i lo = _mm256_min_epi32(v, p), hi = _mm256_max_epi32(v, p);
    v = _mm256_blendv_epi8(lo, hi, lanes_of8(take_max));
  };
  layer(_mm256_setr_epi32(1, 0, 3, 2, 5, 4, 7, 6), 0x55);
  layer(_mm256_setr_epi32(2, 3, 0, 1, 6, 7, 4, 5), 0x33);
  layer(_mm256_setr_epi32(0, 2, 1, 3, 4, 6, 5, 7), 0x22);
  layer(_mm256_setr_epi32(4, 5, 6, 7, 0, 1, 2, 3), 0x0F);
  layer(_mm256_setr_epi32(0, 1, 4, 5, 2, 3, 6, 7), 0x0C);
  layer(_mm256_setr_epi32(0, 2, 1, 4, 3, 6, 5, 7), 0x2A);
  _mm256_storeu_ps(entries, _mm256_castsi256_ps(_mm256_and_si256(v, _mm256_set1_epi32(~7))));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(children),
                      _mm256_permutevar8x32_epi32(props, _mm256_and_si256(v, _mm256_set1_epi32(7))));
  uint32_t first;
  std::memcpy(&first, properties + 4 * nearest, 4);
  return first;
}

#else  // scalar

// One template for both widths: N plain lanes.
template <int N>
struct FN {
  static constexpr int kLanes = N;
  float v[N];
  static FN splat(float f) { FN r; for (float& x : r.v) x = f; return r; }
  static FN load(const void* p) { FN r; std::memcpy(r.v, p, sizeof r.v); return r; }
  void store(float* p) const { std::memcpy(p, v, sizeof v); }
};
template <int N>
struct MN { bool v[N]; };
using F4 = FN<4>;
using M4 = MN<4>;
using F8 = FN<8>;
using M8 = MN<8>;
struct I4 {
  uint32_t v[4];
  static I4 load(const void* p) { I4 r; std::memcpy(r.v, p, 16); return r; }
  void store(uint32_t* p) const { std::memcpy(p, v, 16); }
};

#define MC_LANES(R, expr) { R r; for (int i = 0; i < int(sizeof r.v / sizeof r.v[0]); ++i) r.v[i] = (expr); return r; }
#define MC_FLOAT_OP(op) \
  template <int N> inline FN<N> operator op(FN<N> a, FN<N> b) MC_LANES(FN<N>, a.v[i] op b.v[i])
#define MC_COMPARE(op) \
  template <int N> inline MN<N> operator op(FN<N> a, FN<N> b) MC_LANES(MN<N>, a.v[i] op b.v[i])
MC_FLOAT_OP(+) MC_FLOAT_OP(-) MC_FLOAT_OP(*) MC_FLOAT_OP(/)
MC_COMPARE(<) MC_COMPARE(<=) MC_COMPARE(>) MC_COMPARE(>=) MC_COMPARE(==) MC_COMPARE(!=)
#undef MC_FLOAT_OP
#undef MC_COMPARE
template <int N> inline FN<N> min(FN<N> a, FN<N> b) MC_LANES(FN<N>, a.v[i] < b.v[i] ? a.v[i] : b.v[i])  // NaN -> b
template <int N> inline FN<N> max(FN<N> a, FN<N> b) MC_LANES(FN<N>, a.v[i] > b.v[i] ? a.v[i] : b.v[i])
template <int N> inline FN<N> fma(FN<N> a, FN<N> b, FN<N> c) MC_LANES(FN<N>, __builtin_fmaf(a.v[i], b.v[i], c.v[i]))
template <int N> inline FN<N> abs(FN<N> a) MC_LANES(FN<N>, __builtin_fabsf(a.v[i]))
template <int N> inline FN<N> xor_sign(FN<N> a, FN<N> s) MC_LANES(FN<N>, __builtin_signbit(s.v[i]) ? -a.v[i] : a.v[i])
template <int N> inline MN<N> operator&(MN<N> a, MN<N> b) MC_LANES(MN<N>, a.v[i] && b.v[i])
template <int N> inline MN<N> operator|(MN<N> a, MN<N> b) MC_LANES(MN<N>, a.v[i] || b.v[i])
template <int N> inline MN<N> andnot(MN<N> a, MN<N> b) MC_LANES(MN<N>, !a.v[i] && b.v[i])
template <int N> inline FN<N> select(MN<N> m, FN<N> a, FN<N> b) MC_LANES(FN<N>, m.v[i] ? a.v[i] : b.v[i])
template <int N> inline int bits(MN<N> m) { int b = 0; for (int i = 0; i < N; ++i) b |= int(m.v[i]) << i; return b; }
inline M4 lanes_below(uint32_t n) MC_LANES(M4, uint32_t(i) < n)
inline M4 lanes_of(uint32_t bits) MC_LANES(M4, (bits >> i & 1) != 0)
inline M8 lanes_below8(uint32_t n) MC_LANES(M8, uint32_t(i) < n)
inline F8 from_u8x8(const uint8_t* p) MC_LANES(F8, float(p[i]))
inline M4 nonzero(I4 a) MC_LANES(M4, a.v[i] != 0)
inline F4 from_u16(const uint8_t* p) MC_LANES(F4, float(uint32_t(p[2 * i] | p[2 * i + 1] << 8)))
inline F4 from_half(const uint8_t* p) MC_LANES(F4, layout::half_to_float(uint16_t(p[2 * i] | p[2 * i + 1] << 8)))
inline I4 from_u8_index(const uint8_t* p) MC_LANES(I4, uint32_t(p[i]))
inline I4 from_u16_index(const uint8_t* p) MC_LANES(I4, uint32_t(p[2 * i] | p[2 * i + 1] << 8))
inline I4 iconst(int a, int b, int c, int d) { return {{uint32_t(a), uint32_t(b), uint32_t(c), uint32_t(d)}}; }
inline I4 operator+(I4 a, int b) MC_LANES(I4, a.v[i] + uint32_t(b))
inline I4 operator+(I4 a, I4 b) MC_LANES(I4, a.v[i] + b.v[i])
#undef MC_LANES
inline void bitpack_gather(const uint8_t* base, I4 index, const float offset[3], const float scale[3],
                           const int axis[3], F4 out[3]) {
  for (int i = 0; i < 4; ++i) {
    uint64_t w;
    std::memcpy(&w, base + 8ull * index.v[i], 8);
    float v[3];
    layout::bitpack_decode(w, offset, scale, v);
    for (int j = 0; j < 3; ++j) out[j].v[i] = v[axis[j]];
  }
}
inline int nonzero_bits8(const uint8_t* p) {
  int b = 0;
  for (int i = 0; i < 8; ++i) {
    uint32_t w;
    std::memcpy(&w, p + 4 * i, 4);
    b |= int(w != 0) << i;
  }
  return b;
}
[[gnu::always_inline]] inline uint32_t order_hits(F8 entry, int bits, const uint8_t* properties, float* entries, uint32_t* children) {
  uint32_t keys[8];
  int n = 0;
  for (int k = 0; k < 8; ++k) {  // insertion, largest key (farthest) first
    if (!(bits >> k & 1)) continue;
    const uint32_t key = (std::bit_cast<uint32_t>(entry.v[k]) & 0x7FFFFFF8u) | uint32_t(k);
    int j = n++;
    for (; j > 0 && keys[j - 1] < key; --j) keys[j] = keys[j - 1];
    keys[j] = key;
  }
  for (int j = 0; j < n; ++j) {
    entries[j] = std::bit_cast<float>(keys[j] & ~7u);
    std::memcpy(&children[j], properties + 4 * (keys[j] & 7), 4);
  }
  return children[n - 1];
}
struct V16 { float v[16]; };
inline V16 cluster_decode(const uint8_t* row, uint32_t count, bool wide, uint32_t origin, float scale, float offset) {
  V16 r;
  for (uint32_t i = 0; i < 16; ++i) {
    uint32_t q = 0;
    if (i < count) std::memcpy(&q, row + (wide ? 4 : 2) * i, wide ? 4 : 2);
    r.v[i] = __builtin_fmaf(float(q + origin), scale, offset);
  }
  return r;
}
inline V16 cluster_load(const uint8_t* row, uint32_t count) {
  V16 r;
  for (uint32_t i = 0; i < 16; ++i) {
    r.v[i] = 0.0f;
    if (i < count) std::memcpy(&r.v[i], row + 4 * i, 4);
  }
  return r;
}
inline F8 cluster_pick(const V16& v, uint32_t nibbles) {
  F8 r;
  for (int i = 0; i < 8; ++i) r.v[i] = v.v[nibbles >> (4 * i) & 15];
  return r;
}
inline F4 gather(const float* base, I4 idx) {
  F4 r;
  for (int i = 0; i < 4; ++i) std::memcpy(&r.v[i], reinterpret_cast<const uint8_t*>(base) + 4 * idx.v[i], 4);
  return r;
}

#endif

}  // namespace simd
MC_ISA_END
}  // namespace meshcast
