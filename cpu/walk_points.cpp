// The point walk (cpu/walk_points.h): nearest child first, depth first,
// as the ray walk of OctTreeCompressed (cpu/walk_octtree.cpp) takes its
// children, with a box's squared distance from the point in place of the
// ray's entry distance: one node decoded and measured 8 children at once,
// the near ones pushed farthest first (simd::order_hits) and popped only
// while still within the cut. A cluster leaf's vertices are decoded into
// registers once a cluster, as the ray walk does, and each block of 8
// triangles' corner boxes measured at once; other triangle formats are
// decoded whole (layout::decode_leaf) and measured one by one.
#include "cpu/walk_points.h"

#include <algorithm>
#include <bit>
#include <cstring>

#include "cpu/oct_children.h"
#include "cpu/walk.h"
#include "layout/tree/leaves.h"
#include "layout/tree/octtree.h"

namespace meshcast {
MC_ISA_BEGIN

namespace {

using simd::F8;

// 7 entries a level at most stay behind on the stack (8 near, 1 walked on).
constexpr int kStackSize = 7 * MC_MAX_DEPTH + 8;

// Squared distances from the point to 8 boxes, a box a lane (0 inside).
// No fused multiply-add: the scalar set would call the library's.
[[gnu::always_inline]] inline F8 box_d2(const F8 lo[3], const F8 hi[3], const F8 p[3]) {
  const F8 zero = F8::splat(0.0f);
  F8 d2 = zero;
  for (int a = 0; a < 3; ++a) {
    const F8 d = simd::max(simd::max(lo[a] - p[a], p[a] - hi[a]), zero);
    d2 = d2 + d * d;
  }
  return d2;
}

// A triangle joins `near`, its order kept by insertion (8-byte keys moved,
// not its corners).
inline void add_near(NearTriangles& near, uint32_t index, float d2, const float (&corners)[3][3]) {
  const uint32_t entry = near.n++;
  near.index[entry] = index, near.box_d2[entry] = d2;
  std::memcpy(near.corners[entry], corners, sizeof near.corners[entry]);
  const uint64_t key = uint64_t(std::bit_cast<uint32_t>(d2)) << 32 | entry;
  uint32_t j = entry;
  for (; j > 0 && near.order[j - 1] > key; --j) near.order[j] = near.order[j - 1];
  near.order[j] = key;
}

// A cluster leaf's triangles within the cut: each cluster's vertices
// decoded (or loaded) into registers, each block of 8 triangles' corner
// rows permuted out of them, their boxes' distances taken at once.
template <class Codec>
void near_cluster_triangles(const uint8_t* blob, const layout::BlobHeader& h, uint32_t block, uint32_t count,
                            const float*, const F8 p[3], float cut, NearTriangles& near) {
  const F8 cut8 = F8::splat(cut);
  uint32_t at = block, made = 0;
  while (made < count) {
    const simd::V16 axis[3] = {decode_cluster_axis<Codec>(blob, h, at, 0), decode_cluster_axis<Codec>(blob, h, at, 1),
                               decode_cluster_axis<Codec>(blob, h, at, 2)};
    const uint32_t triangles = Codec::triangle_count(blob, at);
    const uint8_t* index = blob + Codec::index_at(at);
    for (uint32_t first = 0; first < triangles; first += 8, index += MC_CLUSTER_INDEX_BLOCK_BYTES) {
      F8 v[3][3];  // [corner][axis]
      for (int k = 0; k < 3; ++k) {
        const uint32_t nibbles = layout::load<uint32_t>(index + 4 * k);
        for (int a = 0; a < 3; ++a) v[k][a] = simd::cluster_pick(axis[a], nibbles);
      }
      F8 lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = simd::min(simd::min(v[0][a], v[1][a]), v[2][a]);
        hi[a] = simd::max(simd::max(v[0][a], v[1][a]), v[2][a]);
      }
      const F8 d2 = box_d2(lo, hi, p);
      int within = simd::bits((d2 <= cut8) & simd::lanes_below8(triangles - first));
      if (!within) continue;
      float rows[3][3][8], distance[8];
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a) v[k][a].store(rows[k][a]);
      d2.store(distance);
      for (; within; within &= within - 1) {
        const int lane = __builtin_ctz(unsigned(within));
        float corners[3][3];
        for (int k = 0; k < 3; ++k)
          for (int a = 0; a < 3; ++a) corners[k][a] = rows[k][a][lane];
        add_near(near, made + first + uint32_t(lane), distance[lane], corners);
      }
    }
    made += triangles;
    at += Codec::bytes_of(blob, at);
  }
}

// Any other triangle format's leaf: decoded whole, measured one by one
// with the same float arithmetic.
void near_decoded_triangles(const uint8_t* blob, const layout::BlobHeader&, uint32_t block, uint32_t count,
                            const float point[3], const F8*, float cut, NearTriangles& near) {
  float corners[MC_OCT_MAX_COUNT][3][3];
  layout::decode_leaf(blob, block, count, corners);
  for (uint32_t i = 0; i < count; ++i) {
    const float(&v)[3][3] = corners[i];
    float d2 = 0;
    for (int a = 0; a < 3; ++a) {
      const float lo = std::min({v[0][a], v[1][a], v[2][a]}), hi = std::max({v[0][a], v[1][a], v[2][a]});
      const float d = std::max(std::max(lo - point[a], point[a] - hi), 0.0f);
      d2 = d2 + d * d;
    }
    if (d2 <= cut) add_near(near, i, d2, v);
  }
}

template <void (*NearOf)(const uint8_t*, const layout::BlobHeader&, uint32_t, uint32_t, const float*, const F8*,
                         float, NearTriangles&)>
void walk(const uint8_t* blob, const float point[3], float cut, VisitLeafFn visit, void* context) {
  const layout::BlobHeader& h = layout::header_of(blob);
  const uint8_t* tree = blob + h.tree_offset;
  const F8 p[3] = {F8::splat(point[0]), F8::splat(point[1]), F8::splat(point[2])};
  uint32_t node_stack[kStackSize];
  float entry_stack[kStackSize];
  int top = 0;
  uint32_t properties = h.root;
  NearTriangles near;
  for (;;) {
    const uint32_t count = layout::oct_count(properties), offset = layout::oct_offset(properties);
    if (count == 0) {
      const uint8_t* node = tree + offset;
      F8 lo[3], hi[3];
      decode_oct_children(node, lo, hi);
      const F8 d2 = box_d2(lo, hi, p);
      const int within = simd::bits(d2 <= F8::splat(cut)) & simd::nonzero_bits8(node + MC_OCT_PROPERTIES_AT);
      if (within) {
        for (int m = within; m; m &= m - 1)
          __builtin_prefetch(tree + layout::oct_offset(layout::oct_child_properties(node, __builtin_ctz(unsigned(m)))));
        if ((within & (within - 1)) == 0) {  // one child: walked next, no stack traffic
          properties = layout::oct_child_properties(node, __builtin_ctz(unsigned(within)));
          continue;
        }
        properties = simd::order_hits(d2, within, node + MC_OCT_PROPERTIES_AT, entry_stack + top, node_stack + top);
        top += std::popcount(unsigned(within)) - 1;
        continue;
      }
    } else {
      near.n = 0;
      NearOf(blob, h, h.tree_offset + offset, count, point, p, cut, near);
      if (near.n) cut = visit(context, offset, near, cut);
    }
    do {
      if (top == 0) return;
      --top;
    } while (entry_stack[top] > cut);
    properties = node_stack[top];
  }
}

}  // namespace

void walk_points(const uint8_t* blob, const float point[3], float cut, VisitLeafFn visit, void* context) {
  switch (layout::header_of(blob).triangle_format) {
    case MC_TRI_CLUSTERBITPACKSOA8: return walk<near_cluster_triangles<layout::ClusterBitPackSOA8>>(blob, point, cut, visit, context);
    case MC_TRI_CLUSTERFLOAT3SOA8: return walk<near_cluster_triangles<layout::ClusterFloat3SOA8>>(blob, point, cut, visit, context);
    default: return walk<near_decoded_triangles>(blob, point, cut, visit, context);
  }
}

MC_ISA_END
}  // namespace meshcast
