// The walk of OctTreeCompressed (layout/tree/octtree.h) with cluster leaves
// (ClusterBitPackSOA8 or ClusterFloat3SOA8, layout/triangles/cluster.h), one ray a thread: cpu/walk_octtree.cpp's (8
// child boxes decoded and tested, the hit ones pushed farthest first,
// popped entries dropped once the closest hit is nearer). A child bound is
// Origin + q * 2^e, exact in float, so a plain product and sum (precise)
// give the CPU's bits; a grid cluster's vertex is BitPack's decode of its
// grid code (fma_exact), the CPU's std::fma. The blob method (octtree_cluster)
// and the scene method (scene_octtree) walk with it.
#ifndef MESHCAST_OCTTREE_WALK_GLSL
#define MESHCAST_OCTTREE_WALK_GLSL

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/walk.glsl"
#include "shaders/exact.glsl"

uint blob_u8(uint byte) { return (blob_u32(byte & ~3u) >> ((byte & 3u) * 8u)) & 0xFFu; }
uint blob_u16(uint byte) { return (blob_u32(byte & ~3u) >> ((byte & 2u) * 8u)) & 0xFFFFu; }  // 2-aligned
uint blob_u32_at2(uint byte) { return blob_u16(byte) | (blob_u16(byte + 2u) << 16); }       // 2-aligned

// Child k's box in the node at blob offset `at`.
void oct_child_box(uint at, uint k, out vec3 mn, out vec3 mx) {
  for (uint a = 0u; a < 3u; ++a) {
    const float origin = blob_f32(at + MC_OCT_ORIGIN_AT + 4u * a);
    const float scale = uintBitsToFloat(blob_u8(at + MC_OCT_EXPONENTS_AT + a) << 23);
    precise float lo = float(blob_u8(at + MC_OCT_QLO_AT + 8u * a + k)) * scale + origin;
    precise float hi = float(blob_u8(at + MC_OCT_QHI_AT + 8u * a + k)) * scale + origin;
    mn[a] = lo, mx[a] = hi;
  }
}

// Vertex k of the cluster at blob offset `at`, whose vertex rows start at
// `rows`: a float of ClusterFloat3SOA8 (4-aligned) as stored, or
// ClusterBitPackSOA8's grid offset decoded.
vec3 cluster_vertex(bool exact, uint at, uint rows, uint vertices, bool wide, uint k) {
  if (exact) return vec3(blob_f32(rows + 4u * k), blob_f32(rows + 4u * (vertices + k)), blob_f32(rows + 4u * (2u * vertices + k)));
  const uint64_t origin = uint64_t(blob_u32_at2(at)) | (uint64_t(blob_u32_at2(at + 4u)) << 32);  // clusters are 2-aligned
  vec3 v;
  for (uint a = 0u; a < 3u; ++a) {
    const uint base = uint((origin >> (MC_BITPACK_BITS * a)) & uint64_t(MC_BITPACK_MAX));
    const uint offset = wide ? blob_u32_at2(rows + 4u * (a * vertices + k)) : blob_u16(rows + 2u * (a * vertices + k));
    v[a] = fma_exact(float(base + offset), uintBitsToFloat(header(MC_HDR_QUANT_SCALE + a)),
                     uintBitsToFloat(header(MC_HDR_QUANT_OFFSET + a)));
  }
  return v;
}

// A leaf of either cluster format (the blob's header says which; the
// layouts differ only in the header's size and the vertex rows).
void test_cluster_leaf(GpuRay r, uint block, uint count, uint slot0, inout Closest c) {
  const bool exact = header(MC_HDR_TRIANGLE_FORMAT) == MC_TRI_CLUSTERFLOAT3SOA8;
  const uint counts_at = exact ? 0u : 8u;
  const uint header_bytes = exact ? MC_CLUSTER_FLOAT_HEADER_BYTES : MC_CLUSTER_HEADER_BYTES;
  uint at = block, made = 0u;
  while (made < count) {
    const uint flags = blob_u8(at + counts_at), vertices = flags & 31u, triangles = blob_u8(at + counts_at + 1u);
    const bool wide = !exact && (flags & MC_CLUSTER_WIDE) != 0u;
    const uint index = at + header_bytes;
    const uint rows = index + (triangles + 7u) / 8u * MC_CLUSTER_INDEX_BLOCK_BYTES;
    for (uint i = 0u; i < triangles; ++i) {
      const uint word = index + (i / 8u) * MC_CLUSTER_INDEX_BLOCK_BYTES, shift = 4u * (i % 8u);
      const uint k0 = (blob_u32_at2(word) >> shift) & 15u;
      const uint k1 = (blob_u32_at2(word + 4u) >> shift) & 15u;
      const uint k2 = (blob_u32_at2(word + 8u) >> shift) & 15u;
      consider(r, cluster_vertex(exact, at, rows, vertices, wide, k0), cluster_vertex(exact, at, rows, vertices, wide, k1),
               cluster_vertex(exact, at, rows, vertices, wide, k2), slot0 + made + i, c);
    }
    made += triangles;
    at = rows + (exact || wide ? 12u * vertices : 2u * (3u * vertices + (vertices & 1u)));
    at = max(at, index - header_bytes + 4u * triangles);  // the 4-bytes-a-triangle floor (cluster_bytes)
  }
}

#define MC_OCT_STACK_SIZE (7u * MC_MAX_DEPTH + 8u)

// The walk of a walkable ray through the blob's tree into c.
void walk_octtree(GpuRay r, inout Closest c) {
  const uint tree = header(MC_HDR_TREE_OFFSET);
  uint node_stack[MC_OCT_STACK_SIZE];
  float entry_stack[MC_OCT_STACK_SIZE];
  node_stack[0] = header(MC_HDR_ROOT);
  entry_stack[0] = 0.0;
  int top = 0;
  do {
    const uint props = node_stack[top];
    const uint count = props >> MC_OCT_COUNT_SHIFT, offset = (props & MC_OCT_OFFSET_MASK) * MC_OCT_OFFSET_UNIT;
    if (count == 0u) {
      const uint at = tree + offset;
      const int base = top;
      for (uint k = 0u; k < MC_OCT_WIDTH; ++k) {
        const uint p = blob_u32(at + MC_OCT_PROPERTIES_AT + 4u * k);
        if (p == 0u) continue;  // an unused child
        vec3 mn, mx;
        oct_child_box(at, k, mn, mx);
        const float f = box_test(r, mn, mx, c.t);
        if (f == kInfinity) continue;
        int j = top++;  // insertion above the popped entry, farthest first
        while (j > base && entry_stack[j - 1] < f) entry_stack[j] = entry_stack[j - 1], node_stack[j] = node_stack[j - 1], --j;
        entry_stack[j] = f, node_stack[j] = p;
      }
    } else {
      test_cluster_leaf(r, tree + offset, count, slot_of(offset), c);
    }
    do --top;
    while (top >= 0 && entry_stack[top] > c.t * kFarScale);
  } while (top >= 0);
}

#endif
