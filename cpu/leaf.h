// One leaf test for every triangle format: the codec's loader (below) turns a
// group of 4 triangles into corners, triangle_test does the rest. Adding a
// triangle format means adding a loader, not another walker.
#pragma once
#include <algorithm>
#include <bit>

#include "cpu/intersect.h"
#include "layout/triangles/codecs.h"
#include "layout/tree/zerobyte.h"

namespace meshcast {
MC_ISA_BEGIN

// Query::All's hits of one ray so far, triangles still slots: the nearest
// `cap` (at least 1) in hits[0, min(found, cap)) sorted by t, `found`
// counting every hit taken. Nothing past min(found, cap) is read, so the
// row needs no filling before the walk.
struct HitList {
  Hit* hits;
  uint32_t cap;
  uint32_t found = 0;
  void add(float t, uint32_t slot, float u, float v) {
    uint32_t i = std::min(found, cap);
    ++found;
    if (i == cap) {
      if (!(t < hits[cap - 1].t)) return;  // farther than the nearest cap: only counted
      --i;
    }
    for (; i > 0 && hits[i - 1].t > t; --i) hits[i] = hits[i - 1];
    hits[i] = Hit{t, slot, u, v};
  }
};

// A walk's answer so far and its cut. `t` is what every box test, stack
// pop and triangle test compares against: the closest hit's t, so nothing
// farther is walked. Query::Any (`any`) takes the first triangle a walk
// accepts and sets the cut below 0, which no box entry or hit distance
// reaches: every walker culls what is left and ends, through the culling
// it already has (no walker of its own). Query::All (`list`) keeps the cut
// at t_max and gives every accepted triangle to the list. `hit_t` is the
// taken hit's t.
struct Closest {
  float t;
  uint32_t slot = MC_NO_HIT;
  float u = 0, v = 0;
  float hit_t = INFINITY;
  bool any = false;
  HitList* list = nullptr;
  void take(float hit, uint32_t s, float hu, float hv) {
    hit_t = hit, slot = s, u = hu, v = hv;
    t = any ? -1.0f : hit;
  }
  // Where a triangle test puts every accepted lane: only for Query::All.
  LaneSet* every(LaneSet& scratch) const { return list ? &scratch : nullptr; }
  // One test's answer: its closest lane `h`, or with a list every lane of
  // `lanes`; slot_of(lane) names a lane's slot.
  template <class SlotOf>
  [[gnu::always_inline]] void offer(const LaneHit& h, const LaneSet& lanes, SlotOf&& slot_of) {
    if (list) [[unlikely]] {
      for (int m = lanes.mask; m; m &= m - 1) {
        const int i = __builtin_ctz(m);
        list->add(lanes.t[i], slot_of(uint32_t(i)), lanes.u[i], lanes.v[i]);
      }
    } else if (h.lane >= 0 && h.t <= t) {
      // Equal t (a ray through an edge both triangles share): the lower
      // slot, whichever the walk met first, so a ray's answer does not
      // depend on the order its walk takes the leaves in (a packet walk
      // takes them in another). Within one test the lowest lane, the lowest
      // slot, already wins.
      const uint32_t s = slot_of(uint32_t(h.lane));
      if (h.t < t || s < slot) take(h.t, s, h.u, h.v);
    }
  }
};

template <class Codec>
struct Loader;

// A loader fills v[corner][j] with axis `axis[j]` of 4 triangles starting at
// triangle `first` of the block (the ray's axis order, see triangle_test).
//
// Float3: triangles side by side, 9 floats each; gather lane i from triangle
// first + i (clamped, so no lane reads past the block).
template <>
struct Loader<layout::Float3> {
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t count, const int axis[3],
                   simd::F4 v[3][3]) {
    const float* base = reinterpret_cast<const float*>(blob + block);
    int i0 = int(first) * 9;
    int last = int(count - 1) * 9;
    simd::I4 idx = simd::iconst(i0, std::min(i0 + 9, last), std::min(i0 + 18, last), std::min(i0 + 27, last));
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j) v[c][j] = simd::gather(base, idx + (c * 3 + axis[j]));
  }
};

// BitPack: three words a triangle; gather corner c of 4 triangles.
template <>
struct Loader<layout::BitPack> {
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t count, const int axis[3],
                   simd::F4 v[3][3]) {
    const layout::BlobHeader& h = layout::header_of(blob);
    int last = int(count - 1) * 3, i0 = int(first) * 3;
    simd::I4 idx = simd::iconst(i0, std::min(i0 + 3, last), std::min(i0 + 6, last), std::min(i0 + 9, last));
    for (int c = 0; c < 3; ++c)
      simd::bitpack_gather(blob + block, idx + c, h.quant_offset, h.quant_scale, axis, v[c]);
  }
};

// SOA blocks of N lanes: 4 consecutive lanes of a row are one load.
template <uint32_t N, uint32_t kId>
struct Loader<layout::Float3SOA<N, kId>> {
  using Codec = layout::Float3SOA<N, kId>;
  // Blocks of 8 or more lanes are tested 8 at a time (AVX2, seed 000 §3.3).
  static constexpr int kWidth = N % 8 == 0 ? 8 : 4;
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t, const int axis[3],
                   simd::F8 v[3][3]) {
    const uint8_t* p = blob + block + (first / N) * Codec::kBlockBytes;
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j) v[c][j] = simd::F8::load(p + Codec::row(c, axis[j], first % N));
  }
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t, const int axis[3],
                   simd::F4 v[3][3]) {
    const uint8_t* p = blob + block + (first / N) * Codec::kBlockBytes;
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j) v[c][j] = simd::F4::load(p + Codec::row(c, axis[j], first % N));
  }
};

template <uint32_t N, uint32_t kId>
struct Loader<layout::BitPackSOA<N, kId>> {
  using Codec = layout::BitPackSOA<N, kId>;
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t, const int axis[3],
                   simd::F4 v[3][3]) {
    const uint8_t* p = blob + block + (first / N) * Codec::kBlockBytes;
    for (int j = 0; j < 3; ++j) {
      simd::F4 scale = simd::F4::splat(layout::load<float>(p + Codec::kRowsBytes + 4 * axis[j]));
      simd::F4 offset = simd::F4::splat(layout::load<float>(p + Codec::kRowsBytes + 12 + 4 * axis[j]));
      for (int c = 0; c < 3; ++c) v[c][j] = simd::fma(simd::from_u16(p + Codec::row(c, axis[j], first % N)), scale, offset);
    }
  }
};

template <>
struct Loader<layout::Indexed8BitPackSOA4> {
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t, const int axis[3],
                   simd::F4 v[3][3]) {
    const layout::BlobHeader& h = layout::header_of(blob);
    const uint8_t* vertices = blob + block + layout::load<uint32_t>(blob + block);
    const uint8_t* idx = blob + block + MC_I8_HEADER_BYTES + (first / 4) * MC_I8_BLOCK_BYTES;
    for (int c = 0; c < 3; ++c)
      simd::bitpack_gather(vertices, simd::from_u8_index(idx + c * 4), h.quant_offset, h.quant_scale, axis, v[c]);
  }
};

// Indexed formats: the 4 lanes' indices of each corner, then a gather of
// float vertices (3 floats a record) or of BitPack words.
template <class IndexT, bool kBitPack, bool kSoa, uint32_t kId>
struct Loader<layout::Indexed<IndexT, kBitPack, kSoa, kId>> {
  using Codec = layout::Indexed<IndexT, kBitPack, kSoa, kId>;
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t count, const int axis[3],
                   simd::F4 v[3][3]) {
    const layout::BlobHeader& h = layout::header_of(blob);
    const uint8_t* vertices = blob + h.vertex_offset;
    uint32_t last = Codec::lanes(count) - 1;
    for (int c = 0; c < 3; ++c) {
      simd::I4 idx;
      if constexpr (kSoa) {  // the 4 lanes' indices side by side: one load (§3.7)
        const uint8_t* p = blob + block + Codec::slot(first, c) * Codec::kIndexBytes;
        if constexpr (sizeof(IndexT) == 2) idx = simd::from_u16_index(p);
        else idx = simd::I4::load(p);
      } else {
        idx = simd::iconst(int(Codec::index(blob, block, first, c)),
                           int(Codec::index(blob, block, std::min(first + 1, last), c)),
                           int(Codec::index(blob, block, std::min(first + 2, last), c)),
                           int(Codec::index(blob, block, std::min(first + 3, last), c)));
      }
      if constexpr (kBitPack) {
        simd::bitpack_gather(vertices, idx, h.quant_offset, h.quant_scale, axis, v[c]);
      } else {
        simd::I4 idx3 = idx + idx + idx;
        for (int j = 0; j < 3; ++j) v[c][j] = simd::gather(reinterpret_cast<const float*>(vertices), idx3 + axis[j]);
      }
    }
  }
};

// Indexed24 (seed 004): 32-bit index words whose top byte belongs to the
// tree; the 1..7 triangles of a zero-byte node side by side, tested 8 at a
// time so a node is one test (its corners gathered into rows first).
template <>
struct Loader<layout::Indexed24> {
  static constexpr int kWidth = 8;
  static void load(const uint8_t* blob, uint32_t block, uint32_t first, uint32_t count, const int axis[3],
                   simd::F8 v[3][3]) {
    const float* vertices = reinterpret_cast<const float*>(blob + layout::header_of(blob).vertex_offset);
    alignas(32) float rows[3][3][8];
    for (uint32_t i = 0; i < 8; ++i) {
      uint32_t t = std::min(first + i, count - 1);
      for (int c = 0; c < 3; ++c) {
        const float* p = vertices + 3ull * layout::Indexed24::index(blob, block, t, c);
        for (int j = 0; j < 3; ++j) rows[c][j][i] = p[axis[j]];
      }
    }
    for (int c = 0; c < 3; ++c)
      for (int j = 0; j < 3; ++j) v[c][j] = simd::F8::load(rows[c][j]);
  }
};

// Triangles a test takes at once: the loader's kWidth, or 4.
template <class L>
constexpr int width_of() {
  if constexpr (requires { L::kWidth; }) return L::kWidth;
  return 4;
}

// Strips decode vertex after vertex: the whole leaf into SOA rows first
// (at most 31 triangles, MC_QUAD_MAX_COUNT), then the same 4-wide test.
// Returns the block's bytes (what the decode read).
template <class Codec, TriangleTest kTest>
inline uint64_t test_sequential_leaf(const uint8_t* blob, const RayPre& r, uint32_t block, uint32_t count,
                                     uint32_t slot0, Closest& c) {
  alignas(16) float rows[9][32];
  for (auto& row : rows)  // padding lanes: masked, but kept finite
    for (uint32_t i = count; i < (count + 3) / 4 * 4; ++i) row[i] = 0.0f;
  uint64_t bytes = Codec::read(blob, block, count, ~0ull, [&](uint32_t i, const float (*p)[3]) {
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) rows[k * 3 + a][i] = p[k][a];
  });
  for (uint32_t first = 0; first < count; first += 4) {
    simd::F4 v[3][3];
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) v[k][j] = simd::F4::load(&rows[k * 3 + r.axis[j]][first]);
    LaneSet lanes;
    LaneHit h = triangle_test<kTest>(r, v, simd::lanes_below(count - first), c.t, c.every(lanes));
    c.offer(h, lanes, [&](uint32_t lane) { return slot0 + first + lane; });
  }
  return bytes;
}

// Pair blocks (layout/triangles/pairsoa.h): 4 lanes of pairs a pass, the leaf's
// triangles numbered lane by lane. Returns the blocks' bytes.
template <class Codec>
inline uint64_t test_pair_leaf(const uint8_t* blob, const RayPre& r, uint32_t block, uint32_t count, uint32_t slot0,
                               Closest& c) {
  uint32_t made = 0;
  uint64_t at = 0;
  while (made < count) {
    const uint8_t* p = blob + block + at;
    uint32_t header = layout::load<uint32_t>(p), used = header & 15, paired = header >> 4 & 15;
    simd::F4 v[4][3];
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 3; ++j) v[k][j] = simd::F4::load(p + Codec::row(k, r.axis[j]));
    LaneSet lanes[2];  // Query::All: the first triangles' lanes, the second's
    PairHit h = pair_test(r, v, simd::lanes_of(used), simd::lanes_of(paired), c.t, c.every(lanes[0]));
    // A lane's triangles are numbered after those of the lanes below it.
    auto slot_of = [&](uint32_t lane, bool second) {
      uint32_t below = (1u << lane) - 1;
      return slot0 + made + uint32_t(std::popcount(used & below) + std::popcount(paired & below)) + second;
    };
    for (int tri = 0; tri < (c.list ? 2 : 1); ++tri)
      c.offer(LaneHit{h.lane, h.t, h.u, h.v}, lanes[tri],
              [&](uint32_t lane) { return slot_of(lane, c.list ? tri == 1 : h.second); });
    made += uint32_t(std::popcount(used) + std::popcount(paired));
    at += Codec::kBlockBytes;
  }
  return at;
}

// One cluster's triangles against one ray, 8 a test: a row of 8 corners
// permuted out of the decoded vertices (`corner_axis`, in the ray's axis
// order) per corner and axis; `slot` is the cluster's first triangle's.
template <TriangleTest kTest>
[[gnu::always_inline]] inline void test_cluster_triangles(const RayPre& r, Closest& c, const simd::V16* const corner_axis[3],
                                                          const uint8_t* index, uint32_t triangles, uint32_t slot) {
  for (uint32_t first = 0; first < triangles && c.t >= 0; first += 8, index += MC_CLUSTER_INDEX_BLOCK_BYTES) {
    simd::F8 v[3][3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t nibbles = layout::load<uint32_t>(index + 4 * k);
      for (int j = 0; j < 3; ++j) v[k][j] = simd::cluster_pick(*corner_axis[j], nibbles);
    }
    LaneSet lanes;
    LaneHit hit = triangle_test<kTest>(r, v, simd::lanes_below8(triangles - first), c.t, c.every(lanes));
    c.offer(hit, lanes, [&](uint32_t lane) { return slot + first + lane; });
  }
}

// A cluster's vertices along axis `a`, decoded (or loaded) into registers.
template <class Codec>
[[gnu::always_inline]] inline simd::V16 decode_cluster_axis(const uint8_t* blob, const layout::BlobHeader& h, uint32_t at, int a) {
  const uint32_t vertices = Codec::vertex_count(blob, at);
  const bool wide = Codec::wide(blob, at);
  const uint8_t* row = blob + Codec::rows_at(blob, at) + uint32_t(a) * Codec::row_bytes(vertices, wide);
  if constexpr (Codec::kExact) {
    return simd::cluster_load(row, vertices);
  } else {
    const uint64_t origin = layout::load<uint64_t>(blob + at);
    return simd::cluster_decode(row, vertices, wide, layout::bitpack_component(origin, a), h.quant_scale[a], h.quant_offset[a]);
  }
}

// Cluster leaves (layout/triangles/cluster.h): each cluster's 16 vertices
// decoded into registers once (in the ray's axis order), then its
// triangles 8 a test. The leaf's triangles are numbered cluster by cluster.
// Returns the leaf's bytes (what the decode read, padded to 4).
template <class Codec, TriangleTest kTest>
inline uint64_t test_cluster_leaf(const uint8_t* blob, const RayPre& r, uint32_t block, uint32_t count, uint32_t slot0,
                              Closest& c) {
  const layout::BlobHeader& h = layout::header_of(blob);
  uint32_t at = block, made = 0;
  // c.t below 0: an any-hit query has its hit, the rest of the leaf is moot
  // (not even decoded).
  while (made < count && c.t >= 0) {
    const simd::V16 x = decode_cluster_axis<Codec>(blob, h, at, r.axis[0]), y = decode_cluster_axis<Codec>(blob, h, at, r.axis[1]),
                    z = decode_cluster_axis<Codec>(blob, h, at, r.axis[2]);
    const simd::V16* const corner_axis[3] = {&x, &y, &z};
    const uint32_t triangles = Codec::triangle_count(blob, at);
    test_cluster_triangles<kTest>(r, c, corner_axis, blob + Codec::index_at(at), triangles, slot0 + made);
    made += triangles;
    at += Codec::bytes_of(blob, at);
  }
  return (at - block + 3) / 4 * 4;
}

// The same leaf for the rays of a packet (bit i of `rays`: pre[i] and
// c[i]): each cluster decoded once for all of them, on every axis; each
// ray takes the axes in its own order. Each ray's answer is what
// test_cluster_leaf gives it alone.
template <class Codec, TriangleTest kTest>
inline void test_cluster_leaf_rays(const uint8_t* blob, const RayPre* pre, Closest* c, uint32_t rays, uint32_t block,
                                   uint32_t count, uint32_t slot0) {
  const layout::BlobHeader& h = layout::header_of(blob);
  uint32_t at = block, made = 0;
  while (made < count) {
    for (uint32_t m = rays; m; m &= m - 1)  // an any-hit ray with its hit is done
      if (c[__builtin_ctz(m)].t < 0) rays &= ~(1u << __builtin_ctz(m));
    if (!rays) return;
    const simd::V16 axes[3] = {decode_cluster_axis<Codec>(blob, h, at, 0), decode_cluster_axis<Codec>(blob, h, at, 1),
                               decode_cluster_axis<Codec>(blob, h, at, 2)};
    const uint32_t triangles = Codec::triangle_count(blob, at);
    const uint8_t* index = blob + Codec::index_at(at);
    for (uint32_t m = rays; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      const simd::V16* const corner_axis[3] = {&axes[pre[i].axis[0]], &axes[pre[i].axis[1]], &axes[pre[i].axis[2]]};
      test_cluster_triangles<kTest>(pre[i], c[i], corner_axis, index, triangles, slot0 + made);
    }
    made += triangles;
    at += Codec::bytes_of(blob, at);
  }
}

// Tests the `count` triangles of the block at blob offset `block`, the
// leaf's slots from `slot0`, the way its codec's kind of leaf is tested: the
// one place that tells the kinds apart. Returns the block's bytes, which a
// BruteForce or AABBList walk steps over (cpu/records.h) and a tree walk
// drops: strips, pair blocks and clusters measure theirs as they decode it,
// fixed-size blocks take block_bytes(count). Indexed24 has none: its
// triangles are words of a zero-byte tree's nodes, never records.
template <class Codec, TriangleTest kTest>
inline uint64_t test_leaf(const uint8_t* blob, const RayPre& r, uint32_t block, uint32_t count, uint32_t slot0,
                          Closest& c) {
  count_leaves(1);
  if constexpr (requires { Codec::kClusters; }) {
    return test_cluster_leaf<Codec, kTest>(blob, r, block, count, slot0, c);
  } else if constexpr (requires { Codec::kSequential; }) {  // strips have no loader
    return test_sequential_leaf<Codec, kTest>(blob, r, block, count, slot0, c);
  } else if constexpr (requires { Codec::kPairLanes; }) {  // the pair test is watertight alone, whatever kTest
    return test_pair_leaf<Codec>(blob, r, block, count, slot0, c);
  } else {
    constexpr int kWidth = width_of<Loader<Codec>>();
    for (uint32_t first = 0; first < count && c.t >= 0; first += kWidth) {  // below 0: any's hit taken
      LaneHit h;
      LaneSet lanes;
      if constexpr (kWidth == 8) {
        simd::F8 v[3][3];
        Loader<Codec>::load(blob, block, first, count, r.axis, v);
        h = triangle_test<kTest>(r, v, simd::lanes_below8(count - first), c.t, c.every(lanes));
      } else {
        simd::F4 v[3][3];
        Loader<Codec>::load(blob, block, first, count, r.axis, v);
        h = triangle_test<kTest>(r, v, simd::lanes_below(count - first), c.t, c.every(lanes));
      }
      c.offer(h, lanes, [&](uint32_t lane) { return slot0 + first + lane; });
    }
    if constexpr (requires { Codec::block_bytes(count); }) return Codec::block_bytes(count);
    else return 0;
  }
}

// The leaf for several rays (a packet; bit i of `rays`: pre[i] and c[i]):
// a cluster leaf decoded once for all of them, any other leaf tested ray by
// ray. Each ray's answer is what test_leaf gives it alone.
template <class Codec, TriangleTest kTest>
inline void test_leaf_rays(const uint8_t* blob, const RayPre* pre, Closest* c, uint32_t rays, uint32_t block,
                           uint32_t count, uint32_t slot0) {
  if constexpr (requires { Codec::kClusters; }) {
    count_leaves(uint64_t(std::popcount(rays)));
    test_cluster_leaf_rays<Codec, kTest>(blob, pre, c, rays, block, count, slot0);
  } else {
    for (uint32_t m = rays; m; m &= m - 1) {
      const int i = __builtin_ctz(m);
      test_leaf<Codec, kTest>(blob, pre[i], block, count, slot0, c[i]);
    }
  }
}

MC_ISA_END
}  // namespace meshcast
