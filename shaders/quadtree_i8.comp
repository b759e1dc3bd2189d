// Method 6 of seed 000 §7: QuadTreeHalfFloat (§5.7) with Indexed8BitPackSOA4
// (§3.9), the CPU's recommended layout, one ray a thread: the walk of
// cpu/walk_quadtree.cpp (four child boxes tested, the hit ones pushed
// farthest first, popped entries dropped once the closest hit is nearer).
// Half bounds decode as half * node_scale + node_origin: node_scale is a
// power of two, so the product is exact and the sum the CPU's fused one.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/walk.glsl"
#include "shaders/exact.glsl"

#include "shaders/batch_counters.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

// Bound `row` (MinX MinY MinZ MaxX MaxY MaxZ) of child k of the node at `at`.
float half_bound(uint at, uint row, uint k, uint axis) {
  const uint byte = at + row * 8u + k * 2u;
  const uint h = (blob_u32(byte & ~3u) >> ((byte & 2u) * 8u)) & 0xFFFFu;
  precise float v = half_to_float_exact(h) * uintBitsToFloat(header(MC_HDR_NODE_SCALE)) +
                    uintBitsToFloat(header(MC_HDR_NODE_ORIGIN + axis));
  return v;
}

// Vertex `index` of the Indexed8BitPackSOA4 leaf at blob offset `block`.
vec3 i8_vertex(uint block, uint index) {
  const uint at = block + blob_u32(block) + 8u * index;
  const uint64_t w = uint64_t(blob_u32(at)) | (uint64_t(blob_u32(at + 4u)) << 32);
  vec3 v;
  for (uint a = 0u; a < 3u; ++a) {
    const float q = float(uint((w >> (MC_BITPACK_BITS * a)) & uint64_t(MC_BITPACK_MAX)));
    v[a] = fma_exact(q, uintBitsToFloat(header(MC_HDR_QUANT_SCALE + a)), uintBitsToFloat(header(MC_HDR_QUANT_OFFSET + a)));
  }
  return v;
}

uint i8_index(uint block, uint i, uint corner) {
  const uint byte = block + MC_I8_HEADER_BYTES + (i / 4u) * MC_I8_BLOCK_BYTES + corner * 4u + (i % 4u);
  return (blob_u32(byte & ~3u) >> ((byte & 3u) * 8u)) & 0xFFu;
}

void test_i8_leaf(GpuRay r, uint block, uint count, uint slot0, inout Closest c) {
  for (uint i = 0u; i < count; ++i) {
    const vec3 a = i8_vertex(block, i8_index(block, i, 0u));
    const vec3 b = i8_vertex(block, i8_index(block, i, 1u));
    const vec3 d = i8_vertex(block, i8_index(block, i, 2u));
    consider(r, a, b, d, slot0 + i, c);
  }
}

#define STACK_SIZE (3u * MC_MAX_DEPTH + 8u)

void main() {
  const uint ray = pc.ray_base + gl_GlobalInvocationID.x;
  if (ray >= pc.ray_count) return;
  const GpuRay r = load_ray(ray);
  count_unwalkable(r.walkable);
  Closest c = closest_start(ray, r);
  if (r.walkable) {
    const uint tree = header(MC_HDR_TREE_OFFSET);
    uint node_stack[STACK_SIZE];
    float fraction_stack[STACK_SIZE];
    node_stack[0] = header(MC_HDR_ROOT);
    fraction_stack[0] = 0.0;
    int top = 0;
    do {
      const uint props = node_stack[top];
      const uint count = props >> MC_QUAD_COUNT_SHIFT, offset = props & MC_QUAD_OFFSET_MASK;
      if (count == 0u) {
        const uint at = tree + offset;
        float sf[4];
        uint sp[4];
        int m = 0;
        for (uint k = 0u; k < 4u; ++k) {
          const uint p = blob_u32(at + MC_QUADHALF_PROPERTIES_AT + 4u * k);
          if (p == 0u) continue;  // an unused child
          const vec3 mn = vec3(half_bound(at, 0u, k, 0u), half_bound(at, 1u, k, 1u), half_bound(at, 2u, k, 2u));
          const vec3 mx = vec3(half_bound(at, 3u, k, 0u), half_bound(at, 4u, k, 1u), half_bound(at, 5u, k, 2u));
          const float f = box_test(r, mn, mx, c.t);
          if (f == kInfinity) continue;
          int j = m++;  // insertion, farthest first
          while (j > 0 && sf[j - 1] < f) sf[j] = sf[j - 1], sp[j] = sp[j - 1], --j;
          sf[j] = f, sp[j] = p;
        }
        for (int k = 0; k < m; ++k) fraction_stack[top + k] = sf[k], node_stack[top + k] = sp[k];
        top += m;
      } else {
        test_i8_leaf(r, tree + offset, count, slot_of(offset), c);
      }
      do --top;
      while (top >= 0 && fraction_stack[top] > c.t * kFarScale);
    } while (top >= 0);
  }
  write_closest(ray, c);
}
