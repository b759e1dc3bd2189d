// Method 3 of seed 000 §7: AABBTree with Float3 triangles.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/blob.glsl"
#include "shaders/ray.glsl"
#include "shaders/watertight.glsl"
#include "shaders/hits.glsl"
#include "shaders/walk.glsl"

void test_leaf(GpuRay r, uint block, uint count, uint slot0, inout Closest c) { test_float3_leaf(r, block, count, slot0, c); }

#include "shaders/aabbtree_walk.glsl"
