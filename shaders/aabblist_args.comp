// Method 2 of seed 000 §7, AABBList, the tiny pass between the two: the
// appended count becomes pass 2's workgroup counts (x capped at the
// device's limit; pass 2 strides over the rest) and the counter is reset
// for the next chunk of rays.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require

#include "shaders/aabblist.glsl"

layout(local_size_x = 1) in;

// records: the largest workgroup count x the device takes.
layout(push_constant) uniform Push { uint ray_base, ray_count, records; } pc;

void main() {
  const uint n = min(control.counter, uint(pairs.length()));
  control.pair_count = n;
  control.groups[0] = min(n, pc.records);
  control.groups[1] = MC_LIST_GROUPS_Y;
  control.groups[2] = 1u;
  control.counter = 0u;
}
