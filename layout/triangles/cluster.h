// Cluster leaves (formats.h gives the bytes): a leaf's triangles in
// clusters of at most 16 triangles over at most 16 vertices, each vertex
// stored once a cluster, corners as 4-bit vertex numbers. A walker decodes
// a cluster's 16 vertices into registers once and builds each block of 8
// triangles' corner rows by permutes (cpu/simd.h). Two kinds of vertex rows,
// one mechanism:
//
// ClusterBitPackSOA8 stores a vertex as offsets from the cluster's origin
// on the mesh grid (kGridPowerOfTwo, as BitPack). The mesh grid here has 18
// bits an axis (not BitPack's 21), so that a cluster of a coarse mesh still
// fits 16-bit offsets (a cluster spanning up to 1/4 of the mesh; wider ones
// take 32-bit rows): a vertex moves to the nearest grid point, at most half
// a step (2^-18 to 2^-19 of the mesh extent), plus one rounding of the
// decode; shared vertices decode to the same bits everywhere, so the
// watertight test stays watertight across clusters and leaves. (At 21 bits
// the dragon's clusters went wide: 20.8 bytes a triangle against 14.4.)
//
// ClusterFloat3SOA8 stores the mesh's float vertices themselves, 12 bytes a
// vertex instead of 6: nothing moves, so every answer is the float mesh's.
// A vertex shared by two clusters is the same float in both.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "layout/triangles/block.h"

namespace meshcast::layout {

enum class ClusterVertices { GridOffsets, Floats };

template <ClusterVertices kVertices>
struct Cluster {
  static constexpr bool kExact = kVertices == ClusterVertices::Floats;
  static constexpr uint32_t kFormat = kExact ? MC_TRI_CLUSTERFLOAT3SOA8 : MC_TRI_CLUSTERBITPACKSOA8;
  static constexpr bool kIndependentBlocks = true;  // encode writes its block alone (block.h)
  static constexpr uint32_t kSlotDivisor = 4;  // see cluster_bytes
  static constexpr uint32_t kLanes = MC_CLUSTER_BLOCK_LANES;
  static constexpr GridKind kGrid = kExact ? kGridNone : kGridPowerOfTwo;
  static constexpr bool kClusters = true;  // cpu/leaf.h: tested cluster by cluster
  static constexpr uint32_t kGridBits = 18;  // grid offsets: see above
  // Where a cluster's two count bytes sit, and its index rows.
  static constexpr uint32_t kCountsAt = kExact ? 0 : 8;
  static constexpr uint32_t kHeaderBytes = kExact ? MC_CLUSTER_FLOAT_HEADER_BYTES : MC_CLUSTER_HEADER_BYTES;

  // A list of at most N in place: a leaf is planned twice (measured, then
  // encoded), and heap lists here cost a tenth of the build.
  template <class T, uint32_t N>
  struct Small {
    T item[N];
    uint32_t n = 0;
    const T* begin() const { return item; }
    const T* end() const { return item + n; }
    uint32_t size() const { return n; }
    void push_back(T v) { item[n++] = v; }
    const T& operator[](uint32_t i) const { return item[i]; }
  };
  // What makes two corners one vertex: the same grid word, or the same
  // float bits on every axis.
  using Key = std::conditional_t<kExact, std::array<uint32_t, 3>, uint64_t>;
  static Key key_of(const TriCorners& t, int c) {
    if constexpr (kExact) {
      Key k;
      std::memcpy(k.data(), t.v[c], 12);
      return k;
    } else {
      return t.packed[c];
    }
  }
  // One cluster's place in a leaf, as the encoder plans it.
  struct Plan {
    uint32_t first, count;                                  // triangles of the leaf
    Small<Key, MC_CLUSTER_MAX_VERTICES> vertices;           // in vertex-number order
    Small<uint8_t, 3 * MC_CLUSTER_MAX_TRIANGLES> corner;    // 3 a triangle: vertex numbers
    uint64_t origin;                // grid offsets: grid word of the smallest codes
    bool wide;                      // grid offsets: an offset above 16 bits
  };
  // Greedy, in the leaf's order: a cluster takes triangles while it keeps
  // within 16 triangles and 16 vertices.
  static std::vector<Plan> plan(const TriCorners* tris, uint32_t count);

  // Bytes of a vertex row (one axis).
  static uint32_t row_bytes(uint32_t vertices, bool wide) { return (kExact || wide ? 4 : 2) * vertices; }
  // A cluster's bytes: at least 4 a triangle (only a cluster of many
  // triangles over very few vertices pads to reach it), so slot numbers of
  // 4 bytes never collide. A 16-bit Z row pads to 4 bytes.
  static uint32_t cluster_bytes(uint32_t vertices, uint32_t triangles, bool wide) {
    const uint32_t rows = 3 * row_bytes(vertices, wide) + (kExact || wide ? 0 : 2 * (vertices & 1));
    return std::max(4 * triangles, kHeaderBytes + (triangles + 7) / 8 * MC_CLUSTER_INDEX_BLOCK_BYTES + rows);
  }
  // The most a leaf of `count` takes (each triangle a wide cluster of its own).
  static uint64_t block_bytes(uint32_t count) { return (uint64_t(cluster_bytes(3, 1, true)) * count + 3) / 4 * 4; }
  static uint32_t measure(TriCorners* tris, uint32_t count);
  static void encode(TriCorners* tris, uint32_t count, BlockContext& ctx, uint8_t* out);

  // A cluster's fields at blob offset `at`.
  static uint32_t vertex_count(const uint8_t* blob, uint32_t at) { return blob[at + kCountsAt] & 31; }
  static bool wide(const uint8_t* blob, uint32_t at) { return !kExact && (blob[at + kCountsAt] & MC_CLUSTER_WIDE) != 0; }
  static uint32_t triangle_count(const uint8_t* blob, uint32_t at) { return blob[at + kCountsAt + 1]; }
  static uint32_t index_at(uint32_t at) { return at + kHeaderBytes; }
  static uint32_t rows_at(const uint8_t* blob, uint32_t at) {
    return index_at(at) + (triangle_count(blob, at) + 7) / 8 * MC_CLUSTER_INDEX_BLOCK_BYTES;
  }
  static uint32_t bytes_of(const uint8_t* blob, uint32_t at) {
    return cluster_bytes(vertex_count(blob, at), triangle_count(blob, at), wide(blob, at));
  }
  // Vertex number of corner c of triangle i (< 16) of the cluster at `at`.
  static uint32_t corner(const uint8_t* blob, uint32_t at, uint32_t i, int c) {
    const uint32_t word = load<uint32_t>(blob + index_at(at) + (i / 8) * MC_CLUSTER_INDEX_BLOCK_BYTES + 4 * uint32_t(c));
    return word >> (4 * (i % 8)) & 15;
  }
  // Grid offsets: the grid code of vertex k on axis a of the cluster at `at`.
  static uint32_t code(const uint8_t* blob, uint32_t at, uint32_t k, int a) {
    const uint64_t origin = load<uint64_t>(blob + at);
    const uint32_t rows = rows_at(blob, at), v = vertex_count(blob, at);
    const uint32_t offset = wide(blob, at) ? load<uint32_t>(blob + rows + 4 * (uint32_t(a) * v + k))
                                           : load<uint16_t>(blob + rows + 2 * (uint32_t(a) * v + k));
    return bitpack_component(origin, a) + offset;
  }
  // Vertex k's coordinate on axis a, as every walker decodes it.
  static float vertex(const uint8_t* blob, const BlobHeader& h, uint32_t at, uint32_t k, int a) {
    if constexpr (kExact) {
      return load<float>(blob + rows_at(blob, at) + 4 * (uint32_t(a) * vertex_count(blob, at) + k));
    } else {
      return std::fma(float(code(blob, at, k, a)), h.quant_scale[a], h.quant_offset[a]);
    }
  }

  // Bytes of the leaf's clusters (padded to 4), or 0 when they are broken,
  // do not hold exactly `count` triangles, or end past `limit`.
  static uint64_t stored_bytes(const uint8_t* blob, uint32_t block, uint32_t count, uint64_t limit);
  static void decode(const uint8_t* blob, uint32_t block, uint32_t i, float out[3][3]);
  // The leaf's `count` triangles, each cluster's vertices decoded once.
  static void decode_leaf(const uint8_t* blob, uint32_t block, uint32_t count, float (*out)[3][3]);
  // Every corner number of every lane (padding too: walkers decode them)
  // names a vertex of its cluster, and every vertex is finite (floats) or
  // stays on the 21-bit grid (grid offsets).
  static bool check(const uint8_t* blob, uint32_t block, uint32_t count, std::string* why);
};

using ClusterBitPackSOA8 = Cluster<ClusterVertices::GridOffsets>;
using ClusterFloat3SOA8 = Cluster<ClusterVertices::Floats>;
extern template struct Cluster<ClusterVertices::GridOffsets>;
extern template struct Cluster<ClusterVertices::Floats>;

}  // namespace meshcast::layout
