// Method 3 of seed 000 §7: AABBTree with UncompressedStrip triangles
// (§3.10): a leaf's strip is decoded vertex after vertex, the flag bits in
// the floats' lowest bits, by the state machine of layout/triangles/strip.h, and each
// triangle tested as it is made (slots in decode order, as on the CPU).
// Validation proved every leaf's strip makes its count of triangles inside
// the block.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/walk.glsl"

#define MC_STRIP_START_V1 3u
#define MC_STRIP_START_V2 7u

void test_leaf(GpuRay r, uint block, uint count, uint slot0, inout Closest c) {
  vec3 p[3] = vec3[3](vec3(0.0), vec3(0.0), vec3(0.0));
  uint made = 0u, at = block;
  while (made < count) {
    uint flag = 0u;
    vec3 v;
    for (uint a = 0u; a < 3u; ++a) {
      const uint bits = blob_u32(at + 4u * a);
      flag |= (bits & 1u) << a;
      v[a] = uintBitsToFloat(bits & ~1u);
    }
    at += 12u;
    if (flag == MC_STRIP_START_V1) {
      p[0] = v;
      continue;
    }
    if (flag == MC_STRIP_START_V2) {
      p[1] = v;
      continue;
    }
    const uint a = flag & 3u, b = (a + 1u + ((flag >> 2) & 1u)) % 3u;
    const vec3 A = p[a], B = p[b];
    p[0] = A, p[1] = B, p[2] = v;
    consider(r, p[0], p[1], p[2], slot0 + made, c);
    ++made;
  }
}

#include "shaders/aabbtree_walk.glsl"
